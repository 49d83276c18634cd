//! `compute contact/atom` against LIGGGHTS 3.8: 320 beads on an fcc lattice
//! fall onto a floor and settle, periodic in x and y; each atom's contact
//! count in the dump and their sum (`compute reduce`) in the thermo output
//! must be the engine's, frame by frame (the trajectories are the same to
//! rounding, so a count can differ only for a pair at exactly touching
//! distance).

use crate::common;

fn deck() -> String {
    common::settling_beads(
        1,
        "compute ca all contact/atom\ncompute nc all reduce sum c_ca\nthermo_style custom step atoms c_nc\nthermo 1000\n\
dump d all custom 1000 dump.ca id c_ca\nrun 6000\n",
    )
}

#[test]
fn contact_counts_match_liggghts_frame_by_frame() {
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &deck())]);
    let theirs = common::same_dump_frames(&b, "dump.ca");
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
