//! LAMMPS fix pour: atom count vs step and the first insertion's particles
//! against lmp (29 Sep 2021). lmp is run when on PATH; otherwise the numbers
//! stored beside the deck (with the command that produced them) are used.

use demx::scene::Session;
use demx::script::{Interpreter, SourceMap};
use std::path::{Path, PathBuf};
use std::process::Command;

fn deck(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/decks/insert").join(name)
}

/// (step, atoms) at each step where the thermo atom count changes.
fn changes(thermo: &str) -> Vec<(i64, usize)> {
    let mut out: Vec<(i64, usize)> = Vec::new();
    let mut on = false;
    for l in thermo.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.first() == Some(&"Step") {
            on = true;
            continue;
        }
        if on && w.len() == 2 {
            if let (Ok(s), Ok(n)) = (w[0].parse::<i64>(), w[1].parse::<usize>()) {
                if out.last().is_none_or(|l| l.1 != n) {
                    out.push((s, n));
                }
            }
        }
    }
    out
}

fn lmp_reference() -> Vec<(i64, usize)> {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    if let Ok(o) = Command::new("lmp").arg("-in").arg(deck("in.pour_small")).args(["-log", "none"]).current_dir(dir.path()).output() {
        if o.status.success() {
            let c = changes(&String::from_utf8_lossy(&o.stdout));
            if !c.is_empty() {
                return c;
            }
        }
    }
    let text = std::fs::read_to_string(deck("pour_small_counts.txt")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w[0].parse().unwrap(), w[1].parse().unwrap())
        })
        .collect()
}

#[test]
fn pour_counts_and_steps_match_lmp() {
    let out = Command::new(env!("CARGO_BIN_EXE_demx")).arg("run").arg(deck("in.pour_small")).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("Particle insertion: 73 every 2449 steps, 250 by step 7348"), "{stdout}");
    assert_eq!(changes(&stdout), lmp_reference());
}

#[test]
fn pour_first_insertion_matches_lmp_particles() {
    // stored lmp dump of step 1 (id x y z radius vx vy vz mass, 6 digits)
    let text = std::fs::read_to_string(deck("pour_small_step1.txt")).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().filter(|l| !l.starts_with('#')).map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 73);
    let mut s = Session::new(false);
    s.sim.log.screen = false;
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let p = dir.path().join("in.pour1");
    let body = std::fs::read_to_string(deck("in.pour_small")).unwrap().replace("run\t\t7000", "run 1");
    std::fs::write(&p, body).unwrap();
    Interpreter::new(SourceMap::new(), vec![]).run_file(&p, &mut s).unwrap();
    let q = &s.sim.particles;
    assert_eq!(q.len(), 73);
    for r in rows {
        let i = q.tag.iter().position(|&t| t == r[0] as i64).unwrap();
        let rel = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b.abs().max(1e-3);
        assert!(rel(q.x[i].x, r[1]) && rel(q.x[i].y, r[2]) && rel(q.x[i].z, r[3]), "atom {}: {:?} vs {:?}", r[0], q.x[i], &r[1..4]);
        assert!(rel(q.radius[i], r[4]) && rel(q.v[i].z, r[7]) && rel(q.mass[i], r[8]), "atom {}", r[0]);
    }
    // no overlaps among the poured particles
    for i in 0..q.len() {
        for j in i + 1..q.len() {
            assert!((q.x[i] - q.x[j]).norm() > q.radius[i] + q.radius[j]);
        }
    }
}

#[test]
fn pour_needs_gravity_and_region() {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let base = std::fs::read_to_string(deck("in.pour_small")).unwrap();
    for (edit, want) in [
        (base.replace("fix\t\t2 all gravity 1.0 spherical 0.0 -180.0\n", ""), "No fix gravity defined for fix pour"),
        (base.replace(" region slab", ""), "Must specify a region in fix pour"),
        (base.replace("vol 0.2 50", "vol 0.001 50"), "Fix pour insertion count per timestep is 0"),
    ] {
        let p = dir.path().join("in.bad");
        std::fs::write(&p, edit).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_demx")).arg("check").arg(&p).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains(want), "{}", String::from_utf8_lossy(&out.stderr));
    }
}

/// The 2012-era `diam lo hi` of fix pour (LAMMPS 29 Sep 2021 takes `diam
/// one|range|poly`) is a deck error pointing at the word, with a hint to the
/// current form and to `demx convert`.
#[test]
fn pour_old_diam_form_gets_a_hint() {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let base = std::fs::read_to_string(deck("in.pour_small")).unwrap();
    let edit = base.replace(" region slab", " diam 0.5 1.0 region slab");
    assert_ne!(edit, base);
    let p = dir.path().join("in.bad");
    std::fs::write(&p, edit).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx")).arg("check").arg(&p).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("unknown diam style '0.5'"), "{err}");
    assert!(err.contains("`diam range lo hi`") && err.contains("demx convert --to lammps"), "{err}");
}
