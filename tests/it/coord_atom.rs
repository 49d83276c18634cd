//! `compute coord/atom` against LIGGGHTS 3.8 (the jordantcox decks of the
//! corpus stopped at it): 320 beads of two types fall onto a floor and
//! settle, periodic in x and y; each atom's neighbours closer than the
//! cutoff, in all types and per type range, for the whole group and for a
//! group of half the beads, and their mean (`compute reduce ave`) must be
//! the engine's frame by frame. `compute stress/atom` defined and unread
//! does not stop the deck (as there).

use crate::common;

/// The outputs after the beads' setup; line 1 is the deck's line 25.
const TAIL: &str = "\
region half block 0 0.003 INF INF INF INF units box
group left region half
set region half type 2
compute co all coord/atom 0.00105
compute ct all coord/atom 0.00105 1 2*2
compute cl left coord/atom 0.001
compute st all stress/atom
compute ave all reduce ave c_co
thermo_style custom step atoms c_ave
thermo 1000
dump d all custom 1000 dump.co id c_co c_ct[1] c_ct[2] c_cl
run 6000
";

#[test]
fn coordination_matches_liggghts_frame_by_frame() {
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &common::settling_beads(2, TAIL))]);
    let theirs = common::same_dump_frames(&b, "dump.co");
    // settled beads have neighbours; the type columns add up to the whole;
    // the half-group's column is 0 outside it
    let last = theirs.values().last().unwrap();
    let total: f64 = last.values().map(|v| v[0]).sum();
    assert!(total > 1000.0, "{total}");
    assert!(last.values().all(|v| v[0] == v[1] + v[2]), "per type sums to all");
    assert!(last.values().any(|v| v[3] == 0.0 && v[0] > 0.0) && last.values().any(|v| v[3] > 0.0), "group column");
    let t = common::thermo_runs(&b.theirs_out);
    let o = common::thermo_runs(&b.ours_out);
    assert_eq!(t, o, "thermo rows (step atoms mean coordination)");
}

#[test]
fn a_stress_atom_that_is_read_is_not_run_yet() {
    let deck = common::settling_beads(2, &TAIL.replace("dump.co id c_co c_ct[1] c_ct[2] c_cl", "dump.co id c_st[1]"));
    let (code, out) = common::demx_deck(&deck, &[]);
    assert_eq!(code, Some(3), "{out}");
    assert!(out.contains("in.deck:35:") && out.contains("compute stress/atom is not computed yet"), "{out}");
    let bad = common::settling_beads(2, &TAIL.replace("compute cl left coord/atom 0.001", "compute cl left coord/atom 0.001 3"));
    let (code, out) = common::demx_deck(&bad, &[]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("atom type '3' out of range 1..2"), "{out}");
}
