//! The Debian LIGGGHTS tutorials (packing, cohesion, insert_stream) and the
//! LAMMPS pour examples, shortened (tests/decks/tutorials/), run to the end
//! in demx with the particle counts the real engines print on the same
//! decks. The engines' numbers are stored beside each deck
//! (`<deck>.engine.txt`, made by tests/decks/tutorials/engines.sh, whose
//! command line is the file's first line); when `liggghts`/`lmp` is on PATH
//! the test reruns it and uses its fresh numbers.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// (step, atoms, ke) of every thermo line.
type Thermo = Vec<(i64, i64, f64)>;

fn deck_dir(dir: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/decks/tutorials").join(dir)
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

/// Thermo lines between a `Step` header and `Loop time` (both engines' layout).
fn parse_thermo(text: &str) -> Thermo {
    let mut on = false;
    let mut out = Vec::new();
    for l in text.lines() {
        let t = l.trim_start();
        if t.starts_with("Step") {
            on = true;
            continue;
        }
        if t.starts_with("Loop time") {
            on = false;
        }
        if on {
            let w: Vec<&str> = t.split_whitespace().collect();
            if w.len() >= 3 {
                if let (Ok(s), Ok(n), Ok(ke)) = (w[0].parse::<i64>(), w[1].parse::<i64>(), w[2].parse::<f64>()) {
                    out.push((s, n, ke));
                }
            }
        }
    }
    out
}

fn on_path(exe: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(exe).is_file()))
}

/// Run `exe` (demx or an engine) on a copy of the deck folder; returns the
/// temp dir, exit success and screen output.
fn run_in_copy(dir: &str, deck: &str, exe: &str, engine: bool, vars: &[(&str, &str)]) -> (tempfile::TempDir, bool, String) {
    let tmp = tempfile::tempdir().unwrap();
    copy_dir(&deck_dir(dir), tmp.path());
    std::fs::create_dir_all(tmp.path().join("post")).unwrap();
    let mut c = Command::new(exe);
    if engine {
        c.args(["-in", deck, "-log", "none"]);
    } else {
        c.args(["run", deck]);
    }
    for (k, v) in vars {
        c.args(["-var", k, v]);
    }
    let out = c.current_dir(tmp.path()).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (tmp, out.status.success(), text)
}

/// The engine's thermo: fresh if the engine is on PATH, else the stored file.
fn engine_thermo(dir: &str, deck: &str, engine: &str, vars: &[(&str, &str)]) -> Thermo {
    let stored = std::fs::read_to_string(deck_dir(dir).join(format!("{deck}.engine.txt"))).unwrap();
    let stored: Thermo = stored
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w[0].parse().unwrap(), w[1].parse().unwrap(), w[2].parse().unwrap())
        })
        .collect();
    let first = std::fs::read_to_string(deck_dir(dir).join(format!("{deck}.engine.txt"))).unwrap();
    let want_cmd: Vec<String> = vars.iter().map(|(k, v)| format!("-var {k} {v}")).collect();
    assert!(first.lines().next().unwrap().contains(&want_cmd.join(" ")), "stored {deck}.engine.txt was made with other settings");
    if on_path(engine) {
        let (_t, ok, text) = run_in_copy(dir, deck, engine, true, vars);
        assert!(ok, "{engine} failed on {deck}:\n{text}");
        let fresh = parse_thermo(&text);
        let counts = |t: &Thermo| t.iter().map(|x| (x.0, x.1)).collect::<Vec<_>>();
        assert_eq!(counts(&fresh), counts(&stored), "{engine} now prints other counts than stored for {deck}");
        return fresh;
    }
    stored
}

/// Run demx and the engine; assert exit 0, the engine's particle counts at
/// every thermo step, and finite kinetic energy. Returns (demx, engine) thermo.
fn check_deck(dir: &str, deck: &str, engine: &str, vars: &[(&str, &str)]) -> (Thermo, Thermo, tempfile::TempDir) {
    let (tmp, ok, text) = run_in_copy(dir, deck, env!("CARGO_BIN_EXE_demx"), false, vars);
    assert!(ok, "demx run {deck} failed:\n{text}");
    let ours = parse_thermo(&text);
    let theirs = engine_thermo(dir, deck, engine, vars);
    let map = |t: &Thermo| t.iter().map(|x| (x.0, x.1)).collect::<BTreeMap<i64, i64>>();
    assert_eq!(map(&ours), map(&theirs), "particle counts per thermo step differ from {engine} on {deck}\ndemx output:\n{text}");
    assert!(ours.iter().all(|x| x.2.is_finite()), "non-finite kinetic energy in {deck}: {ours:?}");
    (ours, theirs, tmp)
}

fn ke_at(t: &Thermo, step: i64) -> f64 {
    t.iter().rev().find(|x| x.0 == step).map(|x| x.2).unwrap()
}

#[test]
fn insert_stream_counts_release_and_vtk() {
    let vars = [("nrun", "3000"), ("nthermo", "500"), ("ndump", "1000")];
    let (ours, theirs, tmp) = check_deck("insert_stream", "in.insert_stream", "liggghts", &vars);
    // free flight and release at the face: kinetic energy as LIGGGHTS to 1e-6
    for &(s, _, ke) in &theirs {
        let k = ke_at(&ours, s);
        assert!((k - ke).abs() <= 1e-6 * ke.abs().max(1e-12), "step {s}: ke {k} vs liggghts {ke}");
    }
    // one legacy VTK file per frame, as LIGGGHTS: none at the step-1 start of the run
    let post = tmp.path().join("post");
    assert!(!post.join("stream_1.vtk").exists());
    for step in [1000, 2000, 3000] {
        let v = std::fs::read_to_string(post.join(format!("stream_{step}.vtk"))).unwrap();
        assert!(v.starts_with("# vtk DataFile Version 5.1\nGenerated by LIGGGHTS\nASCII\nDATASET POLYDATA\nPOINTS 300 float\n"));
        assert!(!v.contains("nan") && !v.contains("inf"));
        assert!(post.join(format!("stream_boundingBox_{step}.vtk")).exists());
    }
}

#[test]
fn packing_grows_and_settles() {
    let vars = [("growts_n", "400"), ("relaxts_n", "400"), ("nthermo", "100")];
    let (ours, theirs, _tmp) = check_deck("packing", "in.packing", "liggghts", &vars);
    // relaxation after growth: kinetic energy falls (liggghts: 2.678 -> 0.246)
    assert!(ke_at(&theirs, 801) < 0.2 * ke_at(&theirs, 401));
    let (k0, k1) = (ke_at(&ours, 401), ke_at(&ours, 801));
    assert!(k0 > 0.0 && k1 < 0.5 * k0, "packing does not settle: ke {k0} at step 401, {k1} at step 801");
}

#[test]
fn cohesion_tutorials_insert_and_fall() {
    let vars = [("nins", "3100"), ("nend", "3200"), ("nthermo", "500")];
    for deck in ["in.cohesion", "in.noCohesion"] {
        check_deck("cohesion", deck, "liggghts", &vars);
    }
}

#[test]
fn lammps_pour_3d() {
    check_deck("pour", "in.pour", "lmp", &[("nrun1", "4000"), ("nrun2", "500"), ("nthermo", "500")]);
}

#[test]
fn lammps_pour_2d() {
    check_deck("pour", "in.pour.2d", "lmp", &[("nrun1", "4000"), ("nthermo", "500")]);
}
