//! `fix mesh/surface/stress` (LIGGGHTS 3.8): the force and torque the
//! grains put on a mesh, `f_ID[1..9]`, against `liggghts` on the same deck.

use crate::common;

/// The plate at z = 0.
fn plate() -> String {
    common::plate_stl("0")
}

/// [`common::plate_deck`] printing the force, torque and reference point of
/// the plate every 20 steps, then `runs`.
fn deck(stress: &str, runs: &str) -> String {
    let thermo = "thermo_style custom step ke f_cad[1] f_cad[2] f_cad[3] f_cad[4] f_cad[5] f_cad[6] f_cad[7] f_cad[8] f_cad[9]\n\
thermo_modify format float %.15g\nthermo 20\n";
    common::plate_deck(stress, "", &format!("{thermo}{runs}"))
}

fn rows(out: &str) -> Vec<Vec<f64>> {
    common::thermo_runs(out).concat().iter().map(|r| r.iter().map(|w| w.parse().unwrap()).collect()).collect()
}

/// Every printed force and torque component within 1e-12 of its scale;
/// the second run starts in contact, where the engine's first line adds
/// the setup's contacts to the last step's sums.
#[test]
fn force_and_torque_on_a_plate_follow_liggghts() {
    let d = deck(" reference_point 0.001 0.0015 0", "run 1130\nrun 400\n");
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &d), ("plate.stl", &plate())]);
    let (theirs, ours) = (rows(&b.theirs_out), rows(&b.ours_out));
    assert_eq!(theirs.len(), ours.len());
    let mut hits = 0;
    for (t, o) in theirs.iter().zip(&ours) {
        assert_eq!(t[0], o[0]);
        if t[4] != 0.0 {
            hits += 1;
        }
        for k in 2..11 {
            let scale = if k < 5 {
                0.1
            } else if k < 8 {
                1e-4
            } else {
                1e-3
            };
            assert!((t[k] - o[k]).abs() <= 1e-12 * scale, "step {}: f_cad[{}] liggghts {} demx {}", t[0], k - 1, t[k], o[k]);
        }
    }
    // both columns' impacts were seen, the reference point printed as given
    assert!(hits >= 8, "{hits} rows with a force: the deck is not the scene meant");
    assert_eq!(&ours[0][8..11], &[0.001, 0.0015, 0.0]);
    // the second run's first line (step 1130) sums the setup's contacts on
    // top of the step before's: about twice that step's force (the setup
    // pass does not advance the tangential history)
    let at = |rows: &[Vec<f64>], step: f64| rows.iter().filter(|r| r[0] == step).map(|r| r[4]).collect::<Vec<_>>();
    let again = at(&ours, 1130.0);
    assert!(again.len() == 2 && again[0] != 0.0 && (again[1] - 2.0 * again[0]).abs() < 0.01 * again[0].abs(), "{again:?}");
}

/// `stress off` sums nothing; the keywords of mesh/surface/stress on a
/// plain mesh/surface are deck errors, and so is wear without k_finnie.
#[test]
fn stress_off_and_bad_keywords() {
    let run = |deck: &str| common::demx_deck(deck, &[("plate.stl", &plate())]);
    let (code, out) = run(&deck(" stress off", "run 1300\n"));
    assert_eq!(code, Some(0), "{out}");
    assert!(rows(&out).iter().all(|r| r[2..8].iter().all(|&v| v == 0.0)) && rows(&out).iter().any(|r| r[1] < 1.0e-6), "{out}");
    let plain = deck("", "run 10\n").replace("mesh/surface/stress file plate.stl type 1", "mesh/surface file plate.stl type 1 stress on");
    let line = plain.lines().position(|l| l.starts_with("fix cad")).unwrap() + 1;
    let (code, out) = run(&plain);
    assert!(code == Some(2) && out.contains(&format!("in.deck:{line}:")) && out.contains("belongs to fix mesh/surface/stress"), "{out}");
    let (code, out) = run(&deck(" wear finnie", "run 10\n"));
    assert!(code == Some(2) && out.contains("wear finnie needs the property k_finnie") && out.contains("peratomtypepair 1"), "{out}");
}
