//! `demx convert --to lammps` of LIGGGHTS insertions, run in the real
//! engines: `insert/pack ... insert_every once` becomes a random sequential
//! packing (create_atoms random + delete_atoms overlap), which must give
//! LIGGGHTS' count, no overlaps, centres inside the region shrunk by the
//! radius (all_in yes) and the deck's velocity; `insert_every E` becomes a
//! fix pour of N per insertion x the insertions before `unfix`.

use demx::convert::{convert, Target};
use std::path::Path;
use std::process::Command;

fn on_path(exe: &str) -> bool {
    Command::new("sh").arg("-c").arg(format!("command -v {exe}")).output().map(|o| o.status.success()).unwrap_or(false)
}

/// Run `exe -in deck` in `dir`; (success, output).
fn run(exe: &str, deck: &str, dir: &Path, vars: &[(&str, &str)]) -> (bool, String) {
    std::fs::write(dir.join("in.deck"), deck).expect("write deck");
    let mut cmd = Command::new("timeout");
    cmd.arg("300").arg(exe).arg("-in").arg("in.deck").arg("-log").arg("none").current_dir(dir);
    for (k, v) in vars {
        cmd.arg("-var").arg(k).arg(v);
    }
    let out = cmd.output().expect("engine");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    (out.status.success() && !text.contains("ERROR"), text)
}

/// Rows of a text dump's last frame (columns as written).
fn last_frame(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).expect("dump");
    let frame = text.rsplit("ITEM: TIMESTEP").next().unwrap_or("");
    let mut rows = Vec::new();
    let mut atoms = false;
    for l in frame.lines() {
        if l.starts_with("ITEM: ATOMS") {
            atoms = true;
        } else if atoms && !l.trim().is_empty() {
            rows.push(l.split_whitespace().filter_map(|x| x.parse().ok()).collect());
        }
    }
    rows
}

/// A LIGGGHTS 3.x deck inserting once into a box region: `TARGET` is
/// `particles_in_region 300` or `volumefraction_region 0.2`.
fn pack_deck(target: &str) -> String {
    format!(
        "atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region reg block -0.01 0.01 -0.01 0.01 0 0.03 units box
create_box 1 reg
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5.e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.00001
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
region ins block -0.004 0.004 -0.004 0.004 0.01 0.025 units box
fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.0005
fix pdd all particledistribution/discrete 15485867 1 pts 1.0
fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0.1 0.0 -0.3 insert_every once overlapcheck yes all_in yes {target} region ins
fix integr all nve/sphere
run 1
write_dump all custom state.dump id x y z vx vy vz radius mass
"
    )
}

fn check_packing(target: &str) {
    if !on_path("lmp") || !on_path("liggghts") {
        panic!("lmp or liggghts is not on PATH (bash scripts/setup.sh installs them)");
    }
    let deck = pack_deck(target);
    let c = convert(&deck, Target::Lammps);
    assert!(c.text.contains("create_atoms 1 random"), "once -> random packing:\n{}", c.text);
    let lmp_dir = tempfile::tempdir().expect("tmp");
    let (ok, out) = run("lmp", &c.text, lmp_dir.path(), &[]);
    assert!(ok, "lmp rejected the converted deck:\n{out}\n{}", c.text);
    let lig_dir = tempfile::tempdir().expect("tmp");
    // write_dump in LIGGGHTS 3.8 takes the same form
    let (ok, out) = run("liggghts", &deck, lig_dir.path(), &[]);
    assert!(ok, "liggghts failed:\n{out}");
    let a = last_frame(&lmp_dir.path().join("state.dump"));
    let b = last_frame(&lig_dir.path().join("state.dump"));
    // the count: particles_in_region exactly; a volume fraction up to the
    // rounding LIGGGHTS adds (a uniform draw) and its Monte Carlo volume
    let tol = if target.starts_with("particles") { 0 } else { 2 };
    assert!((a.len() as i64 - b.len() as i64).abs() <= tol, "{target}: lmp {} vs liggghts {}", a.len(), b.len());
    // no overlaps between the new particles (one step of motion is far below 1e-6 d)
    let d = 0.001;
    for (i, p) in a.iter().enumerate() {
        for q in &a[i + 1..] {
            let r = ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2) + (p[3] - q[3]).powi(2)).sqrt();
            assert!(r >= d * (1.0 - 1e-6), "{target}: atoms {} and {} overlap ({r})", p[0], q[0]);
        }
        // all_in yes: the whole sphere inside the region (one step of motion allowed)
        let slack = 1e-6;
        assert!(p[1].abs() <= 0.004 - 0.0005 + slack && p[2].abs() <= 0.004 - 0.0005 + slack, "{target}: centre outside the shrunk region: {p:?}");
        assert!(p[3] >= 0.0105 - slack && p[3] <= 0.0245 + slack, "{target}: centre outside the shrunk region: {p:?}");
        // the deck's velocity after one step of gravity (LAMMPS: one step later)
        assert!((p[4] - 0.1).abs() < 1e-9 && p[5].abs() < 1e-9 && (p[6] + 0.3).abs() < 2e-4, "{target}: velocity {p:?}");
        // diameter and mass: rho pi d^3 / 6 (the dump prints 6 digits)
        assert!((p[7] - 0.0005).abs() < 1e-15 && (p[8] / (2500.0 * std::f64::consts::PI * d * d * d / 6.0) - 1.0).abs() < 1e-5, "{target}: {p:?}");
    }
}

#[test]
fn insert_once_particles_in_region_gives_the_liggghts_count_without_overlaps() {
    check_packing("particles_in_region 300");
}

#[test]
fn insert_once_volume_fraction_gives_the_liggghts_count_without_overlaps() {
    check_packing("volumefraction_region 0.2");
}

#[test]
fn insert_every_counts_the_insertions_until_unfix() {
    // refills every 3000 steps: runs of 1 and 10000 steps (steps 1..10001)
    // see insertions at steps 1, 3001, 6001 and 9001, then `unfix`
    let deck = pack_deck("particles_in_region 250")
        .replace("insert_every once", "insert_every 3000")
        .replace("run 1\n", "thermo_modify lost ignore\nrun 1\nrun 10000\nunfix ins\nrun 5000\n");
    let c = convert(&deck, Target::Lammps);
    // a packing pass now, and the runs split before the insertion steps 3001,
    // 6001 and 9001, each followed by a pass; `unfix ins` ends them
    let cmds: Vec<String> = c
        .text
        .lines()
        .filter(|l| l.starts_with("run") || l.starts_with("label demx_rsa") && !l.ends_with("_end") || l.starts_with("unfix"))
        .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect();
    assert_eq!(
        cmds,
        [
            "label demx_rsa1_1",
            "run 1",
            "run 2999",
            "label demx_rsa1_2",
            "run 3000",
            "label demx_rsa1_3",
            "run 3000",
            "label demx_rsa1_4",
            "run 1001",
            "run 5000"
        ],
        "{}",
        c.text
    );
    // each pass tops the region up to 250 particles
    assert_eq!(c.text.matches("variable demx_nins equal (250)-count(all,ins)").count(), 4, "{}", c.text);
    // no fix pour is left, and the deck runs in the real lmp
    assert!(!c.text.lines().any(|l| l.contains(" pour ")), "{}", c.text);
    if on_path("lmp") {
        let dir = tempfile::tempdir().expect("tmp");
        let (ok, out) = run("lmp", &c.text, dir.path(), &[]);
        assert!(ok, "{out}");
    }
    // a polydisperse or looped insertion keeps the fix pour of N x the insertions
    let plain = convert(&deck.replace("pair_style gran model hertz tangential history\npair_coeff * *\n", ""), Target::Lammps);
    let pour = plain.text.lines().find(|l| l.contains(" pour ")).unwrap_or_else(|| panic!("no fix pour:\n{}", plain.text));
    let w: Vec<&str> = pour.split_whitespace().collect();
    assert_eq!(w[4], "1000", "4 insertions x 250: {pour}");
    // vol: 250 particles of d = 1 mm in the 8 x 8 x 15 mm region
    let vol: f64 = w[w.iter().position(|x| *x == "vol").expect("vol") + 1].parse().expect("number");
    let expect = 250.0 * std::f64::consts::PI / 6.0 * 1e-9 / (0.008 * 0.008 * 0.015);
    assert!((vol / expect - 1.0).abs() < 1e-9, "{vol} vs {expect}");
    // the run lengths are not known in a loop: one batch, said so
    let looped = deck.replace("run 10000\n", "label again\nrun 10000\njump SELF again\n");
    let c = convert(&looped, Target::Lammps);
    assert!(c.text.lines().any(|l| l.contains(" pour 250 ")), "{}", c.text);
    assert!(c.notes.iter().any(|n| n.message.contains("not constant")), "{:?}", c.notes.iter().map(|n| &n.message).collect::<Vec<_>>());
}

#[test]
fn heap_template_converts_and_lammps_pours_the_liggghts_charges() {
    if !on_path("lmp") || !on_path("liggghts") {
        panic!("lmp or liggghts is not on PATH (bash scripts/setup.sh installs them)");
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let deck = std::fs::read_to_string(root.join("templates/heap/in.heap")).expect("heap deck");
    let c = convert(&deck, Target::Lammps);
    // fix pour has no output: f_ins${k}[1] becomes the count variable
    assert!(!c.text.lines().any(|l| !l.trim_start().starts_with('#') && l.contains("f_ins")), "{}", c.text);
    let vars = [("model", "stock"), ("N", "150"), ("relax", "1")];
    let lmp_dir = tempfile::tempdir().expect("tmp");
    let (ok, lmp_out) = run("lmp", &c.text, lmp_dir.path(), &vars);
    assert!(ok, "lmp:\n{lmp_out}");
    let lig_dir = tempfile::tempdir().expect("tmp");
    let (ok, lig_out) = run("liggghts", &deck, lig_dir.path(), &vars);
    assert!(ok, "liggghts:\n{lig_out}");
    let charges = |out: &str| -> Vec<i64> {
        out.lines().filter(|l| l.starts_with("heap: chunk")).filter_map(|l| l.split(": ").nth(2)?.split_whitespace().next()?.parse().ok()).collect()
    };
    let (a, b) = (charges(&lmp_out), charges(&lig_out));
    assert!(a.len() >= 2 && b.len() >= 2, "lmp {a:?} liggghts {b:?}");
    // the first charge fills the empty column: the same count up to LIGGGHTS' rounding draw
    assert!((a[0] - b[0]).abs() <= 1, "first charge: lmp {} vs liggghts {}", a[0], b[0]);
    // both stop at N
    assert_eq!(a.last(), Some(&150), "{a:?}");
    assert_eq!(b.last(), Some(&150), "{b:?}");
}

/// `delete_atoms` renumbers ids 1..N unless `compress no`, as in LAMMPS.
#[test]
fn delete_atoms_compress_renumbers_ids_like_lammps() {
    let deck = "atom_style sphere
units si
boundary f f f
region box block -0.01 0.01 -0.01 0.01 0 0.02 units box
create_box 1 box
create_atoms 1 single 0 0 0.001 units box
create_atoms 1 single 0 0 0.003 units box
create_atoms 1 single 0 0 0.005 units box
create_atoms 1 single 0 0 0.007 units box
group two id 2
delete_atoms group two compress ${c}
write_dump all custom ids.txt id z
";
    let ids = |exe: &str, c: &str| -> Vec<(i64, f64)> {
        let dir = tempfile::tempdir().expect("tmp");
        let (ok, out) = run(exe, deck, dir.path(), &[("c", c)]);
        assert!(ok, "{exe}: {out}");
        sorted(last_frame(&dir.path().join("ids.txt")))
    };
    // rows by id: storage order is each engine's own
    fn sorted(rows: Vec<Vec<f64>>) -> Vec<(i64, f64)> {
        let mut v: Vec<(i64, f64)> = rows.iter().map(|r| (r[0] as i64, r[1])).collect();
        v.sort_by_key(|r| r.0);
        v
    }
    let demx = env!("CARGO_BIN_EXE_demx");
    let run_demx = |c: &str| -> Vec<(i64, f64)> {
        let dir = tempfile::tempdir().expect("tmp");
        std::fs::write(dir.path().join("in.deck"), deck).expect("write");
        let out = Command::new(demx).args(["run", "in.deck", "--log", "none", "-var", "c", c]).current_dir(dir.path()).output().expect("demx");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        sorted(last_frame(&dir.path().join("ids.txt")))
    };
    assert_eq!(run_demx("yes"), vec![(1, 0.001), (2, 0.005), (3, 0.007)]);
    assert_eq!(run_demx("no"), vec![(1, 0.001), (3, 0.005), (4, 0.007)]);
    if on_path("lmp") {
        // compress no: the same ids; compress yes: the same contiguous ids 1..N
        // over the same atoms (LAMMPS hands them out in storage order after
        // moving the last atom into the hole, demx in the old id order)
        assert_eq!(run_demx("no"), ids("lmp", "no"));
        let (a, b) = (run_demx("yes"), ids("lmp", "yes"));
        assert_eq!(a.iter().map(|r| r.0).collect::<Vec<_>>(), b.iter().map(|r| r.0).collect::<Vec<_>>());
        let z = |v: &[(i64, f64)]| {
            let mut z: Vec<f64> = v.iter().map(|r| r.1).collect();
            z.sort_by(f64::total_cmp);
            z
        };
        assert_eq!(z(&a), z(&b));
    }
}

/// demx runs the converted packing too (create_atoms random, group clear,
/// delete_atoms overlap, jump SELF loop, reset_timestep).
#[test]
fn demx_runs_the_converted_random_packing() {
    let deck =
        pack_deck("particles_in_region 300").replace("fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n", "");
    let c = convert(&deck, Target::Lammps);
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("in.deck"), &c.text).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", "in.deck", "--log", "none"]).current_dir(dir.path()).output().expect("demx");
    assert!(out.status.success(), "{}\n{}", String::from_utf8_lossy(&out.stderr), c.text);
    let a = last_frame(&dir.path().join("state.dump"));
    assert_eq!(a.len(), 300);
    for (i, p) in a.iter().enumerate() {
        for q in &a[i + 1..] {
            let r = ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2) + (p[3] - q[3]).powi(2)).sqrt();
            assert!(r >= 0.001 * (1.0 - 1e-6), "atoms {} and {} overlap ({r})", p[0], q[0]);
        }
    }
}

/// A sphere dropped on a primitive wall: the LAMMPS conversion must give
/// LIGGGHTS' wall force (Hertz stiffness from Y* = Y/(2(1-nu^2)), damping
/// from e), although LAMMPS' wall/gran granular derives its modulus as
/// E/(2(1-nu)) and tsuji damping from another e.
#[test]
fn converted_wall_bounces_like_the_liggghts_wall() {
    if !on_path("lmp") || !on_path("liggghts") {
        panic!("lmp or liggghts is not on PATH (bash scripts/setup.sh installs them)");
    }
    let deck = "atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region reg block -0.01 0.01 -0.01 0.01 0 0.02 units box
create_box 1 reg
neighbor 0.0002 bin
fix m1 all property/global youngsModulus peratomtype 1e7
fix m2 all property/global poissonsRatio peratomtype 0.24
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-6
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
create_atoms 1 single 0 0 0.0006 units box
set atom 1 diameter 0.001 density 2500
velocity all set 0 0 -0.5 units box
fix integr all nve/sphere
variable z equal z[1]
variable vz equal vz[1]
thermo_style custom step v_z v_vz
thermo_modify format float %.12g
thermo 20
run 400
";
    let c = convert(deck, Target::Lammps);
    let series = |exe: &str, text: &str| -> Vec<(f64, f64)> {
        let dir = tempfile::tempdir().expect("tmp");
        let (ok, out) = run(exe, text, dir.path(), &[]);
        assert!(ok, "{exe}: {out}\n{text}");
        out.lines()
            .filter_map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().ok()).collect::<Option<_>>()?;
                (v.len() == 3).then(|| (v[1], v[2]))
            })
            .collect()
    };
    let (a, b) = (series("lmp", &c.text), series("liggghts", deck));
    assert!(a.len() >= 20 && a.len() == b.len(), "{} vs {} rows", a.len(), b.len());
    // the contact starts at step 200 (0.1 mm at 0.5 m/s) and lasts ~80 steps
    let rebound = b.last().map(|r| r.1).unwrap_or(0.0);
    assert!(rebound > 0.1, "the sphere bounced: {rebound}");
    for (k, (p, q)) in a.iter().zip(&b).enumerate() {
        assert!((p.0 - q.0).abs() < 1e-9 && (p.1 - q.1).abs() < 1e-6 * 0.5, "row {k}: lmp {p:?} liggghts {q:?}");
    }
}
