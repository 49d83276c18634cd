//! Debian's LAMMPS granregion examples against the real `lmp`, cut short:
//! - in.granregion.mixer: `fix balance` (accepted, nothing to balance in one
//!   process), fix pour into a rotating mixer of region walls, `units lj`, whose
//!   thermo output is per atom by default; and LAMMPS's `ke` keyword takes the
//!   temperature's degrees of freedom from the run's setup, so the pouring run,
//!   set up with no atoms, prints `-0` throughout.
//! - in.granregion.funnel: `region ID delete` of the regions a wall uses, which
//!   are defined again and the wall fixed again before the next run.
//!
//! The thermo rows of every run must agree: exactly while nothing touches, to
//! 1e-5 relative once the grains pile up (rounding grows in a heap).

use crate::common;

const EXAMPLES: &str = "/usr/share/lammps/examples/granregion";

/// Runs Debian's deck `name` in lmp and demx, its runs cut to `steps` and
/// thermo every 500 steps; returns both thermo tables.
fn both(name: &str, steps: &[i64]) -> (Vec<Vec<Vec<String>>>, Vec<Vec<Vec<String>>>) {
    let text = std::fs::read_to_string(format!("{EXAMPLES}/{name}")).expect("lammps-examples installed (scripts/setup.sh)");
    let mut runs = steps.iter();
    let deck: String = text
        .lines()
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            match w.as_slice() {
                ["run", _] => format!("run {}\n", runs.next().expect("more run commands than expected")),
                ["variable", "logfreq", "equal", _] => "variable logfreq equal 500\n".to_string(),
                _ => format!("{l}\n"),
            }
        })
        .collect();
    assert!(runs.next().is_none(), "{name}: fewer run commands than expected");
    let b = common::engine_and_demx("lmp", name, &[(name, &deck)]);
    (common::thermo_runs(&b.theirs_out), common::thermo_runs(&b.ours_out))
}

/// Rows equal in step and atoms; the other columns (but cpu, column 1) within
/// `rel` of LAMMPS's, or equal as text when `rel` is 0.
fn agree(theirs: &[Vec<String>], ours: &[Vec<String>], rel: f64, what: &str) {
    assert_eq!(ours.len(), theirs.len(), "{what}: rows");
    for (t, o) in theirs.iter().zip(ours) {
        assert_eq!(o.len(), t.len(), "{what}: {o:?} against {t:?}");
        assert_eq!(o[0], t[0], "{what}: step");
        for k in 2..t.len() {
            if rel == 0.0 {
                assert_eq!(o[k], t[k], "{what}, step {}: column {k}", t[0]);
            } else {
                let (a, b): (f64, f64) = (o[k].parse().unwrap(), t[k].parse().unwrap());
                assert!((a - b).abs() <= rel * b.abs().max(1e-300), "{what}, step {}: column {k}: demx {a}, lmp {b}", t[0]);
            }
        }
    }
}

#[test]
fn mixer_follows_lammps() {
    let (theirs, ours) = both("in.granregion.mixer", &[3000, 3000]);
    assert_eq!(theirs.len(), 2, "lmp ran both runs: {theirs:?}");
    assert_eq!(theirs[0].len(), 7, "{:?}", theirs[0]);
    assert_eq!(ours.len(), 2, "demx ran both runs: {ours:?}");
    // the pouring run: KinEng -0 as LAMMPS prints it, theta exact
    assert!(theirs[0].iter().all(|r| r[3] == "-0"), "{:?}", theirs[0]);
    agree(&theirs[0], &ours[0], 0.0, "pouring run");
    // the mixing run: KinEng per atom (units lj)
    let ke: f64 = theirs[1][0][3].parse().unwrap();
    assert!(ke > 0.5 && ke < 5.0, "per-atom KinEng {ke}");
    agree(&theirs[1], &ours[1], 1e-7, "mixing run");
}

#[test]
fn funnel_with_deleted_regions_follows_lammps() {
    let (theirs, ours) = both("in.granregion.funnel", &[2000, 1000, 1000]);
    assert_eq!(theirs.len(), 3, "lmp ran three runs: {theirs:?}");
    assert_eq!(ours.len(), 3, "demx ran three runs (the last after region delete): {ours:?}");
    for (k, rel) in [(0, 1e-9), (1, 1e-5), (2, 1e-5)] {
        agree(&theirs[k], &ours[k], rel, &format!("run {}", k + 1));
    }
}
