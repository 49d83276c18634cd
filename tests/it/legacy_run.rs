//! `demx run` on a LIGGGHTS 1.x/2.x deck (which LIGGGHTS 3.8 rejects): the
//! deck runs as `demx convert --to liggghts` rewrites it, with a note, so it
//! must write the same dump, byte for byte, as the converted deck run
//! explicitly. A legacy line whose conversion is only approximate stops the
//! run at that line (exit 3) with a hint to convert and edit.

use std::path::Path;
use std::process::{Command, Output};

/// 2.x syntax: `pair_style gran/hertz/history` with flags, `fix
/// wall/gran/hertz/history ... primitive`, and non-prime seeds.
const LEGACY: &str = "atom_style granular\natom_modify map array\nboundary m m m\nnewton off\n\
communicate single vel yes\nunits si\nregion reg block -0.02 0.02 -0.02 0.02 0. 0.05 units box\ncreate_box 1 reg\n\
neighbor 0.002 bin\nneigh_modify delay 0\n\
fix m1 all property/global youngsModulus peratomtype 5.e6\nfix m2 all property/global poissonsRatio peratomtype 0.45\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.9\n\
fix m4 all property/global coefficientFriction peratomtypepair 1 0.05\n\
fix m5 all property/global characteristicVelocity scalar 2.\n\
fix m6 all property/global cohesionEnergyDensity peratomtypepair 1 300000\n\
pair_style gran/hertz/history cohesion sjkr\npair_coeff * *\ntimestep 0.00001\n\
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0\n\
fix zwalls1 all wall/gran/hertz/history primitive type 1 zplane 0.0\n\
fix cylwalls all wall/gran/hertz/history primitive type 1 zcylinder 0.02 0. 0.\n\
region bc cylinder z 0. 0. 0.015 0.01 0.04 units box\n\
fix pts1 all particletemplate/sphere 5330 atom_type 1 density constant 2500 radius constant 0.0015\n\
fix pdd1 all particledistribution/discrete 5331 1 pts1 1.0\n\
fix ins all insert/pack seed 5332 distributiontemplate pdd1 maxattempt 100 insert_every once overlapcheck yes \
all_in yes vel constant 0.0 0.0 -0.2 region bc particles_in_region 60 ntry_mc 10000\n\
fix integr all nve/sphere\nthermo 500\n\
dump d all custom 1000 pile.dump id x y z vx vy vz\ndump_modify d sort id\nrun 3000\n";

fn demx(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_demx")).args(args).current_dir(dir).output().unwrap()
}

#[test]
fn legacy_deck_runs_as_its_conversion() {
    let (legacy, converted) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    std::fs::write(legacy.path().join("in.legacy"), LEGACY).unwrap();
    std::fs::write(converted.path().join("in.legacy"), LEGACY).unwrap();
    let c = demx(converted.path(), &["convert", "in.legacy", "--to", "liggghts", "-o", "in.converted"]);
    assert_eq!(c.status.code(), Some(0), "an exact conversion: {}", String::from_utf8_lossy(&c.stderr));
    let text = std::fs::read_to_string(converted.path().join("in.converted")).unwrap();
    assert!(text.contains("pair_style gran model hertz tangential history cohesion sjkr"), "{text}");

    let a = demx(legacy.path(), &["run", "in.legacy", "--log", "none"]);
    assert_eq!(a.status.code(), Some(0), "{}", String::from_utf8_lossy(&a.stderr));
    let screen = String::from_utf8_lossy(&a.stdout);
    assert!(screen.starts_with("note: in.legacy: LIGGGHTS 1.x/2.x syntax"), "{screen}");
    let b = demx(converted.path(), &["run", "in.converted", "--log", "none"]);
    assert_eq!(b.status.code(), Some(0), "{}", String::from_utf8_lossy(&b.stderr));

    let (ours, theirs) =
        (std::fs::read_to_string(legacy.path().join("pile.dump")).unwrap(), std::fs::read_to_string(converted.path().join("pile.dump")).unwrap());
    assert_eq!(ours.matches("ITEM: TIMESTEP").count(), 4, "frames at 0, 1000, 2000, 3000");
    assert!(ours.contains("ITEM: NUMBER OF ATOMS\n60\n"), "the pack inserted its 60 grains");
    assert!(ours == theirs, "the legacy run's dump differs from the converted deck's");
}

#[test]
fn approximate_legacy_line_stops_the_run() {
    let dir = tempfile::tempdir().unwrap();
    // LIGGGHTS 1.x's pour/dev has no exact 3.x form
    let deck = LEGACY.replace(
        "fix ins all insert/pack seed 5332 distributiontemplate pdd1 maxattempt 100 insert_every once overlapcheck yes \
all_in yes vel constant 0.0 0.0 -0.2 region bc particles_in_region 60 ntry_mc 10000",
        "fix ins all pour/dev mass 0.1 1 distributiontemplate pdd1 vol 0.25 200 massflowrate 0.1 vel uniform 0. 0. 0. 0. -1.0 region bc",
    );
    std::fs::write(dir.path().join("in.legacy"), &deck).unwrap();
    let line = deck.lines().position(|l| l.contains("pour/dev")).unwrap() + 1;
    let o = demx(dir.path(), &["run", "in.legacy", "--log", "none"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains(&format!("in.legacy:{line}:1: unsupported")) && err.contains("pour/dev"), "{err}");
    assert!(err.contains("hint: `demx convert in.legacy --to liggghts`"), "{err}");
    assert!(!dir.path().join("pile.dump").exists(), "nothing ran");
}
