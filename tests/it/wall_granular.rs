//! LAMMPS `fix wall/gran granular` and `fix wall/gran/region granular`
//! (29 Sep 2021): the wall runs the `pair_style granular` sub-models.
//!
//! Engine agreement: small decks (1-3 spheres dropping onto, sliding along
//! and spinning against a zplane, a zcylinder and a region block) run by the
//! real `lmp` and by demx from the same deck text; every dumped position,
//! velocity and spin compared over thousands of steps (failing when `lmp`,
//! which scripts/setup.sh installs, is missing). Analytic: the restitution of a Tsuji-damped
//! Hertz wall impact equals the deck's e.
//!
//! Facts these decks pin down (measured with lmp, a sphere pressed into a
//! zplane): the wall is the particle's own material with the effective
//! modulus E / (2 (1 - nu)) (pairs: E / (2 (1 - nu^2))); `mindlin NULL`
//! gives k_t = E / 4 (2 - nu)(1 + nu); R* is the particle radius for planes
//! and r rwall / (r + rwall) with rwall = -2 R_c inside a zcylinder; m* is
//! the particle mass; DMT pulls with 4 pi gamma R*.

use demx::io::dump::{read_all, Frame};
use std::path::Path;
use std::process::Command;

/// Spheres (id diameter x y z vx vy vz wx wy wz) near the floor z = -0.01:
/// dropping with spin, sliding, spinning about the normal.
fn floor() -> Vec<[f64; 11]> {
    vec![
        [1.0, 0.002, 0.0, 0.0, -0.0085, 0.0, 0.0, -0.5, 0.0, 30.0, 0.0],
        [2.0, 0.002, 0.004, 0.0, -0.0089, 0.3, 0.1, -0.2, 0.0, 0.0, 50.0],
        [3.0, 0.0016, -0.004, 0.003, -0.0088, -0.1, 0.2, -0.3, 40.0, 0.0, -20.0],
    ]
}

/// Spheres moving out against a zcylinder of radius 8 mm, sliding along it.
fn cylinder() -> Vec<[f64; 11]> {
    vec![
        [1.0, 0.002, 0.0069, 0.0, 0.0, 0.2, 0.3, 0.0, 0.0, 0.0, 20.0],
        [2.0, 0.002, 0.0, -0.00695, 0.002, 0.1, -0.1, 0.05, 30.0, 0.0, 0.0],
        [3.0, 0.0016, -0.005, 0.005, -0.003, -0.2, 0.2, 0.0, 0.0, 0.0, -40.0],
    ]
}

/// Head-on drops (no sliding, no spin) at 0.3, 0.02 and 0.005 m/s.
fn headon() -> Vec<[f64; 11]> {
    vec![
        [1.0, 0.002, 0.0, 0.0, -0.0089, 0.0, 0.0, -0.3, 0.0, 0.0, 0.0],
        [2.0, 0.002, 0.004, 0.0, -0.00899, 0.0, 0.0, -0.02, 0.0, 0.0, 0.0],
        [3.0, 0.0016, -0.004, 0.003, -0.00919, 0.0, 0.0, -0.005, 0.0, 0.0, 0.0],
    ]
}

fn data(spheres: &[[f64; 11]]) -> String {
    let mut s =
        format!("walls\n\n{} atoms\n1 atom types\n\n-0.01 0.01 xlo xhi\n-0.01 0.01 ylo yhi\n-0.01 0.01 zlo zhi\n\nAtoms # sphere\n\n", spheres.len());
    for r in spheres {
        s += &format!("{} 1 {} 2500 {} {} {}\n", r[0], r[1], r[2], r[3], r[4]);
    }
    s += "\nVelocities\n\n";
    for r in spheres {
        s += &format!("{} {} {} {} {} {} {}\n", r[0], r[5], r[6], r[7], r[8], r[9], r[10]);
    }
    s
}

/// The deck: pair and wall share the coefficients; `wall` is the whole
/// fix after `all` (style, coefficients, wall style).
fn deck(coeff: &str, wall: &str, steps: u32, gravity: bool) -> String {
    format!(
        "units si
atom_style sphere
atom_modify map array
boundary f f f
newton off
comm_modify vel yes
read_data data.w
neighbor 0.0005 bin
neigh_modify delay 0
pair_style granular
pair_coeff * * {coeff}
timestep 1e-6
fix 1 all nve/sphere
{g}region rb block -0.0095 0.0095 -0.0095 0.0095 -0.0095 0.0095
fix w all {wall}
dump d all custom 100 dump.w id x y z vx vy vz omegax omegay omegaz
dump_modify d format float %20.15g
run {steps}
",
        g = if gravity { "fix g all gravity 9.81 vector 0 0 -1\n" } else { "" }
    )
}

fn have_lmp() -> bool {
    Command::new("lmp").arg("-h").output().is_ok()
}

fn run_in(dir: &Path, lmp: bool) {
    let o = if lmp {
        Command::new("lmp").current_dir(dir).args(["-in", "in.deck", "-log", "none", "-screen", "none"]).output().expect("run lmp")
    } else {
        Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(["run", "in.deck"]).output().expect("run demx")
    };
    assert!(
        o.status.success(),
        "{} failed: {}{}",
        if lmp { "lmp" } else { "demx" },
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Largest difference over all frames, atoms and columns, relative to the
/// column's largest magnitude in the reference; NaN anywhere fails.
fn max_rel_diff(a: &[Frame], b: &[Frame]) -> f64 {
    assert_eq!(a.len(), b.len(), "frame counts differ");
    let cols = &a[0].columns;
    let mut scale = vec![0.0f64; cols.len()];
    for f in a {
        for r in 0..f.natoms {
            for (k, s) in scale.iter_mut().enumerate() {
                let v = f.get(r, k).unwrap();
                assert!(v.is_finite(), "non-finite {} in the reference at step {}", cols[k], f.timestep);
                *s = s.max(v.abs());
            }
        }
    }
    let mut worst: f64 = 0.0;
    for (fa, fb) in a.iter().zip(b) {
        assert_eq!(fa.timestep, fb.timestep);
        for r in 0..fa.natoms {
            let id = fa.get(r, fa.col("id").unwrap()).unwrap() as u64;
            let rb = fb.row_of_id(id).unwrap();
            for (k, name) in cols.iter().enumerate() {
                let kb = fb.col(name).unwrap();
                let (x, y) = (fa.get(r, k).unwrap(), fb.get(rb, kb).unwrap());
                assert!(y.is_finite(), "demx: non-finite {name} at step {}", fa.timestep);
                if scale[k] > 0.0 {
                    worst = worst.max((x - y).abs() / scale[k]);
                }
            }
        }
    }
    worst
}

/// Run both engines; returns (max relative difference, lmp frames).
fn compare(name: &str, spheres: &[[f64; 11]], coeff: &str, wall: &str, steps: u32, gravity: bool) -> Option<(f64, Vec<Frame>)> {
    if !have_lmp() {
        panic!("{name}: 'lmp' is not on PATH (bash scripts/setup.sh installs it)");
    }
    let dir = tempfile::tempdir().unwrap();
    let mut frames = vec![];
    for eng in ["lmp", "demx"] {
        let d = dir.path().join(eng);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("in.deck"), deck(coeff, wall, steps, gravity)).unwrap();
        std::fs::write(d.join("data.w"), data(spheres)).unwrap();
        run_in(&d, eng == "lmp");
        frames.push(read_all(d.join("dump.w")).unwrap());
    }
    let worst = max_rel_diff(&frames[0], &frames[1]);
    eprintln!("{name}: {} frames, max difference / column scale = {worst:.3e}", frames[0].len());
    Some((worst, frames.swap_remove(0)))
}

const TOL: f64 = 1e-10;

const HERTZ_TSUJI: &str = "hertz/material 1e7 0.2 0.3 tangential mindlin NULL 1.0 0.5 damping tsuji rolling sds 100 1e-4 0.1";

/// The value of `col` for sphere `id` in the last frame.
fn last(frames: &[Frame], id: u64, col: &str) -> f64 {
    let f = frames.last().unwrap();
    f.get(f.row_of_id(id).unwrap(), f.col(col).unwrap()).unwrap()
}

#[test]
fn zplane_hertz_material_tsuji_mindlin_rolling_like_lmp() {
    let wall = format!("wall/gran granular {HERTZ_TSUJI} zplane -0.01 NULL");
    if let Some((worst, frames)) = compare("zplane hertz/material tsuji mindlin rolling sds", &floor(), HERTZ_TSUJI, &wall, 4000, true) {
        assert!(worst < TOL, "{worst}");
        // the wall acted: every sphere is above the floor, none falls through
        for id in 1..=3 {
            assert!(last(&frames, id, "z") > -0.01, "sphere {id} below the floor");
        }
        // friction and rolling resistance changed sphere 2's spin (50 about z only at start)
        assert!(last(&frames, 2, "omegay").abs() > 1.0);
    }
}

#[test]
fn zplane_twisting_marshall_and_sds_like_lmp() {
    for tw in ["twisting marshall", "twisting sds 1e-5 1e-9 0.05"] {
        let coeff = format!("{HERTZ_TSUJI} {tw}");
        let wall = format!("wall/gran granular {coeff} zplane -0.01 NULL");
        if let Some((worst, _)) = compare(tw, &floor(), &coeff, &wall, 4000, true) {
            assert!(worst < TOL, "{tw}: {worst}");
        }
    }
}

#[test]
fn zcylinder_hertz_material_like_lmp() {
    for tw in ["", "twisting marshall"] {
        let coeff = format!("{HERTZ_TSUJI} {tw}");
        let wall = format!("wall/gran granular {coeff} zcylinder 0.008");
        if let Some((worst, frames)) = compare("zcylinder hertz/material", &cylinder(), &coeff, &wall, 4000, true) {
            assert!(worst < TOL, "{tw}: {worst}");
            for id in 1..=3 {
                let rho = last(&frames, id, "x").hypot(last(&frames, id, "y"));
                assert!(rho < 0.008, "sphere {id} outside the cylinder: {rho}");
            }
        }
    }
}

#[test]
fn hooke_linear_history_and_nohistory_like_lmp() {
    for (name, coeff, sph) in [
        ("hooke linear_history zplane", "hooke 1000 0.3 tangential linear_history 300 1.0 0.3 damping mass_velocity", floor()),
        ("hooke linear_history zcylinder", "hooke 1000 0.3 tangential linear_history 300 1.0 0.3 damping mass_velocity", cylinder()),
        ("hooke linear_nohistory zplane", "hooke 1000 0.3 tangential linear_nohistory 1.0 0.3 damping velocity", floor()),
    ] {
        let style = if name.ends_with("zcylinder") { "zcylinder 0.008" } else { "zplane -0.01 NULL" };
        let wall = format!("wall/gran granular {coeff} {style}");
        if let Some((worst, _)) = compare(name, &sph, coeff, &wall, 4000, true) {
            assert!(worst < TOL, "{name}: {worst}");
        }
    }
}

/// DMT at the wall, head-on (no sliding: lmp's friction cap of an attracting
/// DMT wall contact differs from |F_ne| by ~2.5e-8 N, see the module notes
/// in src/scene/walls.rs): the fast sphere rebounds, the slow ones stick.
#[test]
fn dmt_headon_like_lmp() {
    let coeff = "dmt 1e7 0.2 0.3 0.05 tangential linear_history 300 1.0 0.3 damping mass_velocity";
    let wall = format!("wall/gran granular {coeff} zplane -0.01 NULL");
    if let Some((worst, frames)) = compare("dmt head-on", &headon(), coeff, &wall, 4000, true) {
        assert!(worst < TOL, "{worst}");
        assert!(last(&frames, 1, "vz") > 0.0, "the 0.3 m/s sphere rebounds");
    }
}

/// JKR at the wall while the contact holds (lmp 29 Sep 2021 gives NaN once a
/// sphere leaves a JKR wall, so only sticking spheres are compared).
#[test]
fn jkr_sticking_like_lmp() {
    let coeff = "jkr 1e7 0.5 0.3 0.05 tangential mindlin NULL 1.0 0.3 damping mass_velocity";
    let wall = format!("wall/gran granular {coeff} zplane -0.01 NULL");
    let sph = vec![
        [1.0, 0.002, 0.0, 0.0, -0.008999, 0.0, 0.0, -0.002, 0.0, 0.0, 0.0],
        [2.0, 0.0016, 0.004, 0.0, -0.0091995, 0.001, 0.0, -0.001, 0.0, 0.0, 10.0],
    ];
    if let Some((worst, frames)) = compare("jkr sticking", &sph, coeff, &wall, 4000, true) {
        assert!(worst < TOL, "{worst}");
        assert!(last(&frames, 1, "z") < -0.009, "sphere 1 stays on the wall");
    }
}

#[test]
fn region_block_granular_like_lmp() {
    let wall = format!("wall/gran/region granular {HERTZ_TSUJI} region rb");
    if let Some((worst, _)) = compare("wall/gran/region block", &floor(), HERTZ_TSUJI, &wall, 3000, true) {
        assert!(worst < TOL, "{worst}");
    }
}

/// LAMMPS's Tsuji fit alpha(e) (pair_granular documentation).
fn tsuji_alpha(e: f64) -> f64 {
    1.2728 - 4.2783 * e + 11.087 * e.powi(2) - 22.348 * e.powi(3) + 27.467 * e.powi(4) - 18.022 * e.powi(5) + 4.8218 * e.powi(6)
}

/// Restitution of m x'' = -k x^(3/2) - alpha sqrt(m k) x^(1/4) x' (Hertz
/// with Tsuji damping; in units where k = m = v0 = 1 only alpha is left),
/// integrated with RK4 until the overlap closes.
fn tsuji_restitution(alpha: f64) -> f64 {
    let f = |x: f64, v: f64| -x.max(0.0).powf(1.5) - alpha * x.max(0.0).powf(0.25) * v;
    let (mut x, mut v, mut t, h) = (0.0f64, 1.0f64, 0.0, 1e-5);
    loop {
        let (k1x, k1v) = (v, f(x, v));
        let (k2x, k2v) = (v + 0.5 * h * k1v, f(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
        let (k3x, k3v) = (v + 0.5 * h * k2v, f(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
        let (k4x, k4v) = (v + h * k3v, f(x + h * k3x, v + h * k3v));
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        t += h;
        if x < 0.0 && t > 0.1 {
            return -v;
        }
    }
}

/// Tsuji damping at the wall: the rebound speed ratio is the restitution of
/// the damped Hertz oscillator with LAMMPS's alpha(e), independent of
/// stiffness and mass. Note: that is not the deck's e (e = 0.2 rebounds
/// with 0.343, 0.5 with 0.616, 0.8 with 0.853): LAMMPS's fit does not
/// invert its own damping law; lmp does the same (the engine tests above).
#[test]
fn tsuji_wall_restitution_matches_the_damped_hertz_oscillator() {
    for (e, expected_far_from_e) in [(0.2, true), (0.5, true), (0.8, false)] {
        let coeff = format!("hertz/material 1e7 {e} 0.3 tangential linear_history 1000 0 0.5 damping tsuji");
        let wall = format!("wall/gran granular {coeff} zplane -0.01 NULL");
        let sph = vec![[1.0, 0.002, 0.0, 0.0, -0.0089, 0.0, 0.0, -0.5, 0.0, 0.0, 0.0]];
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("in.deck"), deck("hooke 0 0 tangential linear_nohistory 0 0", &wall, 3000, false)).unwrap();
        std::fs::write(dir.path().join("data.w"), data(&sph)).unwrap();
        run_in(dir.path(), false);
        let frames = read_all(dir.path().join("dump.w")).unwrap();
        let z = last(&frames, 1, "z");
        assert!(z > -0.009, "still on the wall: z = {z}");
        let got = last(&frames, 1, "vz") / 0.5;
        let want = tsuji_restitution(tsuji_alpha(e));
        // contact time ~ 100 steps: the step error is well below 1e-3
        assert!((got - want).abs() < 1e-3, "e = {e}: measured {got}, oscillator {want}");
        if expected_far_from_e {
            assert!((got - e).abs() > 0.05, "e = {e}: {got}");
        }
    }
}

#[test]
fn deck_errors() {
    for (wall, code, msg) in [
        (
            "wall/gran granular dmt 1e7 0.5 0.3 0.1 tangential mindlin NULL 1.0 0.5 limit_damping zplane -0.01 NULL",
            2,
            "Cannot limit damping with DMT model",
        ),
        ("wall/gran granular hertz/material 1e7 0.5 0.3 tangential mindlin NULL 1.0 0.5", 2, "missing the wall style"),
        ("wall/gran granular tangential mindlin NULL 1.0 0.5 zplane -0.01 NULL", 2, "missing the normal model"),
        ("wall/gran granular hertz 1000 0.5 tangential mindlin NULL 1.0 0.5 zplane -0.01 NULL", 2, "kt NULL needs a material normal model"),
        (
            "wall/gran granular hertz/material 1e7 0.5 0.3 tangential mindlin NULL 1.0 0.5 damping foo zplane -0.01 NULL",
            2,
            "unknown damping model 'foo'",
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("in.deck"), deck("hooke 1000 0 tangential linear_nohistory 0 0", wall, 10, false)).unwrap();
        std::fs::write(dir.path().join("data.w"), data(&headon())).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir.path()).args(["check", "in.deck"]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{wall}: {err}");
        assert!(err.contains(msg), "{wall}: {err}");
    }
}
