//! demx against the real engines: runs `demx run` on the decks of
//! templates/{two_sphere,drop,settle} and compares its dumps, particle by id
//! and frame by timestep, with the LIGGGHTS 3.8 / LAMMPS 29Sep2021 dumps
//! stored in reference/<engine>/<case>/ (made by scripts/reference.sh).
//! Tolerances live beside the data in tolerance.json.
//!
//! The default run uses the stored references only. With
//! `DEMX_REFRESH_REFERENCE=1` each test first reruns the engine
//! (scripts/reference.sh CASE), which needs `liggghts` and `lmp` on PATH.

use demx::io::dump::{DumpReader, Frame};
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

static REFRESH: Mutex<()> = Mutex::new(());

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn deck(engine: &str, case: &str) -> PathBuf {
    let dir = match case {
        "headon" | "oblique" => "two_sphere",
        other => other,
    };
    let ext = if engine == "liggghts" { "liggghts" } else { "lammps" };
    root().join("templates").join(dir).join(format!("in.{case}.{ext}"))
}

fn ref_dir(engine: &str, case: &str) -> PathBuf {
    root().join("reference").join(engine).join(case)
}

/// Rerun the engines on `case` when DEMX_REFRESH_REFERENCE=1.
fn maybe_refresh(case: &str) {
    if std::env::var("DEMX_REFRESH_REFERENCE").map(|v| v == "1").unwrap_or(false) {
        let _g = REFRESH.lock().unwrap_or_else(|e| e.into_inner());
        let st = Command::new(root().join("scripts/reference.sh")).arg(case).status().expect("run scripts/reference.sh");
        assert!(st.success(), "scripts/reference.sh {case} failed");
    }
}

fn read_frames(path: &Path) -> Vec<Frame> {
    DumpReader::open(path)
        .unwrap_or_else(|e| panic!("open {}: {e}", path.display()))
        .collect::<Result<Vec<_>, _>>()
        .unwrap_or_else(|e| panic!("read {}: {e}", path.display()))
}

fn tolerance(engine: &str, case: &str) -> Value {
    let p = ref_dir(engine, case).join("tolerance.json");
    let t = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&t).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn tol(t: &Value, key: &str) -> f64 {
    t[key].as_f64().unwrap_or_else(|| panic!("tolerance.json: missing number '{key}'"))
}

/// Output of one demx run: its frames and the thermo (step, ke) pairs.
struct DemxRun {
    frames: Vec<Frame>,
    thermo: Vec<(i64, f64)>,
    _dir: tempfile::TempDir,
}

fn run_demx(engine: &str, case: &str) -> DemxRun {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", "--quiet", "--log", "log.demx"])
        .arg(deck(engine, case))
        .output()
        .expect("run demx");
    assert!(out.status.success(), "demx run {case} ({engine}) failed: {}", String::from_utf8_lossy(&out.stderr));
    let frames = read_frames(&dir.path().join(format!("dump.{case}")));
    let log = std::fs::read_to_string(dir.path().join("log.demx")).expect("demx log");
    DemxRun { frames, thermo: thermo_ke(&log), _dir: dir }
}

/// (step, KinEng) rows of the `thermo_style custom step atoms ke` blocks of a log.
fn thermo_ke(log: &str) -> Vec<(i64, f64)> {
    let mut rows = vec![];
    let mut inside = false;
    for line in log.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.first() == Some(&"Step") {
            inside = true;
            continue;
        }
        if inside {
            match (w.len(), w.first().and_then(|s| s.parse::<i64>().ok()), w.get(2).and_then(|s| s.parse::<f64>().ok())) {
                (3, Some(s), Some(ke)) => rows.push((s, ke)),
                _ => inside = false,
            }
        }
    }
    rows
}

fn ref_thermo(engine: &str, case: &str) -> Vec<(i64, f64)> {
    use std::io::Read;
    let p = ref_dir(engine, case).join("log.gz");
    let f = std::fs::File::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut s = String::new();
    flate2::read::GzDecoder::new(f).read_to_string(&mut s).expect("read log.gz");
    thermo_ke(&s)
}

/// The stored deck copy must be the deck in templates/, or the reference is stale.
fn check_fresh(engine: &str, case: &str) {
    let d = deck(engine, case);
    let stored = ref_dir(engine, case).join(d.file_name().unwrap());
    let a = std::fs::read_to_string(&d).expect("template deck");
    let b = std::fs::read_to_string(&stored).expect("stored deck copy");
    assert_eq!(a, b, "{} changed since the reference was made: rerun with DEMX_REFRESH_REFERENCE=1", d.display());
}

/// Largest deviations of one frame: position / max(|x_ref|, diameter),
/// velocity, angular velocity and force each relative to the frame's
/// largest reference magnitude of that quantity.
#[derive(Default, Debug, Clone, Copy)]
struct Dev {
    pos: f64,
    vel: f64,
    omega: f64,
    force: f64,
}

fn vec3(f: &Frame, row: usize, cols: [usize; 3]) -> [f64; 3] {
    [f.get(row, cols[0]).unwrap(), f.get(row, cols[1]).unwrap(), f.get(row, cols[2]).unwrap()]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn frame_dev(r: &Frame, d: &Frame) -> Dev {
    assert_eq!(r.natoms, d.natoms, "atom count at step {}", r.timestep);
    let c = |f: &Frame, n: [&str; 3]| [f.col(n[0]).unwrap(), f.col(n[1]).unwrap(), f.col(n[2]).unwrap()];
    let names = [["x", "y", "z"], ["vx", "vy", "vz"], ["omegax", "omegay", "omegaz"], ["fx", "fy", "fz"]];
    let rc: Vec<[usize; 3]> = names.iter().map(|n| c(r, *n)).collect();
    let dc: Vec<[usize; 3]> = names.iter().map(|n| c(d, *n)).collect();
    let (rid, did, rrad) = (r.col("id").unwrap(), d.col("id").unwrap(), r.col("radius").unwrap());
    let drow: HashMap<i64, usize> = (0..d.natoms).map(|k| (d.get(k, did).unwrap() as i64, k)).collect();
    let mut scale = [0.0f64; 4];
    for k in 0..r.natoms {
        for q in 1..4 {
            scale[q] = scale[q].max(norm(vec3(r, k, rc[q])));
        }
    }
    let mut dev = Dev::default();
    for k in 0..r.natoms {
        let id = r.get(k, rid).unwrap() as i64;
        let j = *drow.get(&id).unwrap_or_else(|| panic!("atom {id} missing from demx at step {}", r.timestep));
        let mut e = [0.0; 4];
        for q in 0..4 {
            let (a, b) = (vec3(r, k, rc[q]), vec3(d, j, dc[q]));
            e[q] = norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]]);
        }
        let xs = norm(vec3(r, k, rc[0])).max(2.0 * r.get(k, rrad).unwrap());
        dev.pos = dev.pos.max(e[0] / xs);
        let rel = |e: f64, s: f64| if s > 0.0 { e / s } else { e };
        dev.vel = dev.vel.max(rel(e[1], scale[1]));
        dev.omega = dev.omega.max(rel(e[2], scale[2]));
        dev.force = dev.force.max(rel(e[3], scale[3]));
    }
    dev
}

fn frame_ke(f: &Frame, density: f64) -> f64 {
    let (r, v) = (f.col("radius").unwrap(), [f.col("vx").unwrap(), f.col("vy").unwrap(), f.col("vz").unwrap()]);
    (0..f.natoms)
        .map(|k| {
            let rad = f.get(k, r).unwrap();
            let m = density * 4.0 / 3.0 * std::f64::consts::PI * rad * rad * rad;
            0.5 * m * norm(vec3(f, k, v)).powi(2)
        })
        .sum()
}

/// Pair frames by timestep; every reference frame must have a demx twin.
fn paired<'a>(reference: &'a [Frame], demx: &'a [Frame]) -> Vec<(&'a Frame, &'a Frame)> {
    let by_step: HashMap<u64, &Frame> = demx.iter().map(|f| (f.timestep, f)).collect();
    assert_eq!(reference.len(), demx.len(), "frame counts differ");
    reference.iter().map(|r| (r, *by_step.get(&r.timestep).unwrap_or_else(|| panic!("demx has no frame at step {}", r.timestep)))).collect()
}

/// A collision case: every frame agrees to the stored tolerances.
fn trajectory_case(engine: &str, case: &str) {
    maybe_refresh(case);
    check_fresh(engine, case);
    let t = tolerance(engine, case);
    let reference = read_frames(&ref_dir(engine, case).join("dump.gz"));
    let run = run_demx(engine, case);
    let mut worst = Dev::default();
    for (r, d) in paired(&reference, &run.frames) {
        let e = frame_dev(r, d);
        worst = Dev { pos: worst.pos.max(e.pos), vel: worst.vel.max(e.vel), omega: worst.omega.max(e.omega), force: worst.force.max(e.force) };
        assert!(e.pos <= tol(&t, "position_rel"), "{engine}/{case} step {}: position deviation {:e}", r.timestep, e.pos);
        assert!(e.vel <= tol(&t, "velocity_rel"), "{engine}/{case} step {}: velocity deviation {:e}", r.timestep, e.vel);
        assert!(e.omega <= tol(&t, "omega_rel"), "{engine}/{case} step {}: omega deviation {:e}", r.timestep, e.omega);
        assert!(e.force <= tol(&t, "force_rel"), "{engine}/{case} step {}: force deviation {:e}", r.timestep, e.force);
    }
    eprintln!("{engine}/{case}: {} frames, worst deviations {worst:?}", reference.len());
    // the collision really happened: some particle turned around or spun up
    let first = &reference[0];
    let last = reference.last().unwrap();
    assert!(frame_dev(first, last).vel > 0.1, "{engine}/{case}: nothing happened in the reference");
    if t["thermo_ke"].as_bool() != Some(false) {
        check_thermo_ke(engine, case, &run);
    }
}

fn check_thermo_ke(engine: &str, case: &str, run: &DemxRun) {
    let ke_ref = ref_thermo(engine, case);
    assert_eq!(ke_ref.len(), run.thermo.len(), "{engine}/{case}: thermo rows");
    for (a, b) in ke_ref.iter().zip(&run.thermo) {
        assert_eq!(a.0, b.0);
        assert!((a.1 - b.1).abs() <= 1e-6 * a.1.abs().max(1e-300), "{engine}/{case} step {}: thermo ke {} vs {}", a.0, a.1, b.1);
    }
}

/// LIGGGHTS prints the full sum m v^2 / 2 as thermo `ke` even for a single
/// atom, where LAMMPS' temperature-based `ke` (dof = 3N - 3 = 0) is 0.
/// demx follows each engine's definition by dialect.
#[test]
fn liggghts_single_atom_thermo_ke() {
    let run = run_demx("liggghts", "drop");
    check_thermo_ke("liggghts", "drop", &run);
}

/// LAMMPS' thermo `ke` for one atom is 0 (temperature with no degrees of freedom).
#[test]
fn lammps_single_atom_thermo_ke_is_zero() {
    let ke = ref_thermo("lammps", "drop");
    assert!(!ke.is_empty() && ke.iter().all(|r| r.1 == 0.0));
    check_thermo_ke("lammps", "drop", &run_demx("lammps", "drop"));
}

#[test]
fn liggghts_headon() {
    trajectory_case("liggghts", "headon");
}
#[test]
fn lammps_headon() {
    trajectory_case("lammps", "headon");
}
#[test]
fn liggghts_oblique() {
    trajectory_case("liggghts", "oblique");
}
#[test]
fn lammps_oblique() {
    trajectory_case("lammps", "oblique");
}
#[test]
fn liggghts_drop() {
    trajectory_case("liggghts", "drop");
}
#[test]
fn lammps_drop() {
    trajectory_case("lammps", "drop");
}

/// The settling column: trajectories agree to `position_rel` until the
/// divergence frame (which must come no earlier than `min_divergence_step`),
/// and the kinetic-energy curve (dump frames and every thermo row) stays
/// within `ke_rel` up to `ke_until_step`.
fn settle_case(engine: &str) {
    let case = "settle";
    maybe_refresh(case);
    check_fresh(engine, case);
    let t = tolerance(engine, case);
    let reference = read_frames(&ref_dir(engine, case).join("dump.gz"));
    let run = run_demx(engine, case);
    let density = tol(&t, "density");
    let mut diverged: Option<u64> = None;
    let mut report = String::new();
    for (r, d) in paired(&reference, &run.frames) {
        let e = frame_dev(r, d);
        let (kr, kd) = (frame_ke(r, density), frame_ke(d, density));
        let rel = (kr - kd).abs() / kr;
        report.push_str(&format!("  step {:6}: pos {:9.2e} vel {:9.2e} ke {:9.2e}\n", r.timestep, e.pos, e.vel, rel));
        if diverged.is_none() && e.pos > tol(&t, "position_rel") {
            diverged = Some(r.timestep);
        }
        if diverged.is_none() {
            assert!(rel <= tol(&t, "ke_rel_before_divergence"), "{engine}/settle step {}: ke {kd} vs {kr}", r.timestep);
        }
        if (r.timestep as f64) <= tol(&t, "ke_until_step") {
            assert!(rel <= tol(&t, "ke_rel"), "{engine}/settle step {}: ke {kd} vs {kr} ({rel:e})", r.timestep);
        }
    }
    let div = diverged.map_or(i64::MAX, |s| s as i64);
    eprintln!("{engine}/settle: trajectories diverge (pos > {:e}) at step {div}\n{report}", tol(&t, "position_rel"));
    assert!(div as f64 >= tol(&t, "min_divergence_step"), "{engine}/settle: diverged at step {div}\n{report}");
    // the thermo KE curve at every thermo step
    let ke_ref = ref_thermo(engine, case);
    assert_eq!(ke_ref.len(), run.thermo.len(), "thermo rows");
    let mut first_off = None;
    for (a, b) in ke_ref.iter().zip(&run.thermo) {
        assert_eq!(a.0, b.0);
        let rel = (a.1 - b.1).abs() / a.1;
        if first_off.is_none() && rel > tol(&t, "ke_rel_before_divergence") {
            first_off = Some(a.0);
        }
        if (a.0 as f64) <= tol(&t, "ke_until_step") {
            assert!(rel <= tol(&t, "ke_rel"), "{engine}/settle thermo step {}: ke {} vs {} ({rel:e})", a.0, b.1, a.1);
        }
    }
    let first_off = first_off.unwrap_or(i64::MAX);
    eprintln!("{engine}/settle: thermo ke first differs by > ke_rel_before_divergence at step {first_off}");
    assert!(first_off as f64 >= tol(&t, "min_divergence_step"), "{engine}/settle: thermo ke diverged at step {first_off}");
    // the column really settled onto the floor: KE fell from its peak
    let peak = ke_ref.iter().map(|r| r.1).fold(0.0, f64::max);
    assert!(ke_ref.last().unwrap().1 < 0.5 * peak, "{engine}/settle: reference did not settle");
}

#[test]
fn liggghts_settle() {
    settle_case("liggghts");
}
#[test]
fn lammps_settle() {
    settle_case("lammps");
}
