//! Issue 4: the paper's contact model through a deck. The van der Waals
//! force reaches a pair that does not touch (the neighbour list includes it
//! through the law's extra range, even with a skin smaller than the gap),
//! and `demx check` says the paper keywords run in demx only.

use demx::io::dump::DumpReader;
use std::process::Command;

fn deck(model: &str, skin: f64) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\nhard_particles yes\n\
         region reg block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box\ncreate_box 1 reg\nneighbor {skin:e} bin\nneigh_modify delay 0\n\
         fix m1 all property/global youngsModulus peratomtype 63e9\nfix m2 all property/global poissonsRatio peratomtype 0.24\n\
         fix m3 all property/global coefficientRestitution peratomtypepair 1 0.2\nfix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
         fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.05\n\
         fix m6 all property/global restitutionReferenceVelocity scalar 1.0\nfix m7 all property/global surfaceEnergy peratomtypepair 1 0.05\n\
         fix m8 all property/global vdwMinDistance scalar 1.65e-10\nfix m9 all property/global vdwCutoff scalar 1e-6\n\
         pair_style gran {model}\npair_coeff * *\ntimestep 1e-9\n\
         create_atoms 1 single -0.00050025 0 0 units box\ncreate_atoms 1 single 0.00050025 0 0 units box\n\
         set type 1 diameter 0.001\nset type 1 density 2500\nfix integr all nve/sphere\n\
         dump d all custom 1 dump.out id x fx\ndump_modify d format \"%d %.17g %.17g\"\nrun 0\n"
    )
}

const PAPER: &str = "model hertz/viscoelastic tangential history/paper cohesion vdw rolling_friction epsd/paper";

fn demx(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(args).output().expect("run demx")
}

#[test]
fn vdw_attracts_across_a_gap_smaller_than_d_max() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.deck"), deck(PAPER, 1e-8)).unwrap();
    let out = demx(dir.path(), &["run", "--quiet", "--log", "none", "in.deck"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let f = DumpReader::open(dir.path().join("dump.out")).unwrap().next().unwrap().unwrap();
    let fx = |id| f.get(f.row_of_id(id).unwrap(), f.col("fx").unwrap()).unwrap();
    // gap 0.5 um: A_H R* / (6 (D_min + gap)^2), A_H = 24 pi D_min^2 gamma, R* = d/4
    let want = 1.709468764334034e-11;
    assert!(((fx(1) - want) / want).abs() < 1e-6, "fx = {}", fx(1));
    assert!((fx(1) + fx(2)).abs() < 1e-20);
}

#[test]
fn vdw_is_zero_beyond_the_cutoff() {
    let dir = tempfile::tempdir().unwrap();
    let d = deck(PAPER, 1e-8).replace("0.00050025", "0.000501");
    std::fs::write(dir.path().join("in.deck"), d).unwrap();
    let out = demx(dir.path(), &["run", "--quiet", "--log", "none", "in.deck"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let f = DumpReader::open(dir.path().join("dump.out")).unwrap().next().unwrap().unwrap();
    assert_eq!(f.get(f.row_of_id(1).unwrap(), f.col("fx").unwrap()).unwrap(), 0.0);
}

#[test]
fn check_says_paper_keywords_run_in_demx_only() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.deck"), deck(PAPER, 1e-4)).unwrap();
    let out = demx(dir.path(), &["check", "in.deck"]);
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("runs in demx only"), "{text}");
    assert!(text.contains("cohesion vdw"), "{text}");
    // the stock model has no such note
    std::fs::write(dir.path().join("in.deck"), deck("model hertz tangential history rolling_friction epsd2", 1e-4)).unwrap();
    let out = demx(dir.path(), &["check", "in.deck"]);
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(!text.contains("demx only"), "{text}");
}

#[test]
fn missing_paper_property_is_a_deck_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = deck(PAPER, 1e-4).replace("fix m9 all property/global vdwCutoff scalar 1e-6\n", "");
    std::fs::write(dir.path().join("in.deck"), d).unwrap();
    let out = demx(dir.path(), &["run", "--quiet", "--log", "none", "in.deck"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("vdwCutoff"));
}
