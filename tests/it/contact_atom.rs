//! `compute contact/atom` against LIGGGHTS 3.8: 320 beads on an fcc lattice
//! fall onto a floor and settle, periodic in x and y; each atom's contact
//! count in the dump and their sum (`compute reduce`) in the thermo output
//! must be the engine's, frame by frame (the trajectories are the same to
//! rounding, so a count can differ only for a pair at exactly touching
//! distance).

use crate::common;

const DECK: &str = "\
atom_style granular
atom_modify map array
boundary p p f
newton off
communicate single vel yes
units si
region box block 0 0.006 0 0.006 0 0.02 units box
create_box 1 box
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5.e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.3
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.000005
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
lattice fcc 0.0015
region pts block 0 0.006 0 0.006 0.0006 0.008 units box
create_atoms 1 region pts
set group all diameter 0.001 density 2500
fix integr all nve/sphere
compute ca all contact/atom
compute nc all reduce sum c_ca
thermo_style custom step atoms c_nc
thermo 1000
dump d all custom 1000 dump.ca id c_ca
run 6000
";

#[test]
fn contact_counts_match_liggghts_frame_by_frame() {
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", DECK)]);
    let theirs = common::dump_frames(&b.theirs.path().join("dump.ca"));
    let ours = common::dump_frames(&b.ours.path().join("dump.ca"));
    assert_eq!(theirs.keys().collect::<Vec<_>>(), ours.keys().collect::<Vec<_>>(), "the same frames");
    for (step, rows) in &theirs {
        assert_eq!(rows, &ours[step], "step {step}: contact counts per atom differ");
    }
    // the beads touch at the end (the comparison is not one of zeros), and
    // every contact is counted at both its atoms
    let last = theirs.values().last().unwrap();
    let total: f64 = last.values().map(|v| v[0]).sum();
    assert!(total > 1000.0 && total % 2.0 == 0.0, "{total}");
    let t = common::thermo_runs(&b.theirs_out);
    let o = common::thermo_runs(&b.ours_out);
    assert_eq!(t, o, "thermo rows (step atoms sum of counts)");
    assert_eq!(t[0].last().unwrap()[2].parse::<f64>().unwrap(), total, "the reduce is the dump's sum");
}
