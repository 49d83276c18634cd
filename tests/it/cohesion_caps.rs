//! Which normal force bounds friction when a cohesion model pulls the
//! surfaces together, checked against the real LIGGGHTS 3.8: a 2 mm sphere
//! held on a floor by `cohesion sjkr` (the bond ~100 times its weight), with
//! gravity tilted 60 degrees. With the Coulomb cap on the contact force alone
//! (`tangential_reduce off`, the default) friction can hold the contact
//! point and the sphere rolls without slipping (omega R = v, as
//! tan 60 < 3.5 mu (1 + F_coh/W) for a solid sphere); with the net force
//! (`tangential_reduce on`: contact minus cohesion, about the weight's
//! normal part) the cap is below the 2/7 W sin 60 that rolling asks for, and
//! it slips (omega R < v). The keyword stands after the wall's geometry, where
//! LIGGGHTS' fix wall/gran takes it.

use std::path::Path;
use std::process::Command;

const DECK: &str = "atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region reg block -0.05 0.05 -0.01 0.01 -0.001 0.01 units box
create_box 1 reg
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 1.e7
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.3
fix m5 all property/global cohesionEnergyDensity peratomtypepair 1 1.e5
pair_style gran model hertz tangential history cohesion sjkr
pair_coeff * *
timestep 1e-6
fix floor all wall/gran model hertz tangential history cohesion sjkr primitive type 1 zplane 0.0 tangential_reduce ${reduce}
create_atoms 1 single 0.0 0.0 0.000995 units box
set atom 1 diameter 0.002
set atom 1 density 2500
fix g all gravity 9.81 vector 0.8660254 0.0 -0.5
fix integr all nve/sphere
dump d all custom 20000 state.dump id x z vx omegay
dump_modify d format \"%d %.17g %.17g %.17g %.17g\"
run 20000
";

/// Run the deck in `dir` with `exe` (`liggghts -in` or `demx run`); the
/// last frame's (x, z, vx, omega_y).
fn final_state(exe: &[&str], dir: &Path, reduce: &str) -> [f64; 4] {
    std::fs::write(dir.join("in.deck"), DECK).expect("write deck");
    let out = Command::new(exe[0])
        .args(&exe[1..])
        .arg("in.deck")
        .args(["-var", "reduce", reduce])
        .args(["-log", "none"])
        .current_dir(dir)
        .output()
        .expect("run engine");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success() && !text.contains("ERROR"), "{exe:?} failed:\n{text}");
    let dump = std::fs::read_to_string(dir.join("state.dump")).expect("dump");
    let last = dump.lines().last().expect("a row");
    let v: Vec<f64> = last.split_whitespace().skip(1).map(|x| x.parse().expect("number")).collect();
    [v[0], v[1], v[2], v[3]]
}

#[test]
fn sjkr_tangential_reduce_matches_liggghts_rolling_and_slipping() {
    assert!(
        Command::new("sh").arg("-c").arg("command -v liggghts").output().map(|o| o.status.success()).unwrap_or(false),
        "liggghts is not installed: run `bash scripts/setup.sh` (the README's test command does)"
    );
    let demx = env!("CARGO_BIN_EXE_demx");
    for reduce in ["off", "on"] {
        let (ld, dd) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let lig = final_state(&["liggghts", "-in"], ld.path(), reduce);
        let dem = final_state(&[demx, "run"], dd.path(), reduce);
        // the same trajectory: x, z, v and omega to 1e-6 of their size
        for (k, name) in ["x", "z", "vx", "omega_y"].iter().enumerate() {
            assert!((lig[k] - dem[k]).abs() <= 1e-6 * lig[k].abs(), "{reduce}: {name} liggghts {} vs demx {}", lig[k], dem[k]);
        }
        // the physics each cap gives: the contact point held, or sliding
        let (v, w_r) = (dem[2], dem[3] * 1e-3);
        assert!(v > 0.05, "{reduce}: the sphere should move down the slope, v = {v}");
        if reduce == "off" {
            assert!((w_r - v).abs() < 0.01 * v, "off: rolls without slipping, omega R = {w_r} vs v = {v}");
        } else {
            assert!(w_r < 0.7 * v, "on: slips, omega R = {w_r} vs v = {v}");
        }
    }
}
