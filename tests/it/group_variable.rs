//! `group ID variable NAME` (LAMMPS): the atoms whose atom-style variable is
//! non-zero, against `lmp` on the same deck.

use crate::common;

/// A 6 x 6 x 6 lattice, a group by a variable mixing coordinates, types
/// and ids, and what LAMMPS prints of it.
const DECK: &str = "units lj\natom_style sphere\nboundary p p p\nlattice sc 1.0\nregion box block 0 6 0 6 0 6\n\
create_box 2 box\ncreate_atoms 1 box\nregion r block INF 2.5 INF INF INF INF\ngroup left region r\nset group left type 2\n\
variable sel atom \"(x > 2.5 && y < 3.5) || (z >= 5 && type == 2) || id == 7\"\n\
group g variable sel\nvariable n equal count(g)\nvariable c equal xcm(g,x)+2*xcm(g,y)+3*xcm(g,z)\n\
group t2 type 2\ngroup both intersect g t2\nvariable b equal count(both)\n\
print \"GROUP ${n} ${c} ${b}\"\n";

fn printed(out: &str) -> Vec<f64> {
    let line = out.lines().find(|l| l.starts_with("GROUP ")).unwrap_or_else(|| panic!("no GROUP line: {out}"));
    line.split_whitespace().skip(1).map(|w| w.parse().unwrap()).collect()
}

/// The group's size, centre and overlap with a type group are LAMMPS's.
#[test]
fn group_by_variable_follows_lmp() {
    let b = common::engine_and_demx("lmp", "in.deck", &[("in.deck", DECK)]);
    let (theirs, ours) = (printed(&b.theirs_out), printed(&b.ours_out));
    assert_eq!(theirs.len(), 3);
    assert_eq!(theirs[0], ours[0], "count");
    assert!((theirs[1] - ours[1]).abs() < 1e-4, "xcm: {theirs:?} {ours:?}");
    assert_eq!(theirs[2], ours[2], "count of type 2 in g");
    // the deck is the one meant: a part of the lattice, some of type 2
    assert!(ours[0] > 50.0 && ours[0] < 216.0 && ours[2] > 0.0, "{ours:?}");
}

/// An unknown variable is a deck error at its name.
#[test]
fn group_by_unknown_variable_is_a_deck_error() {
    let deck = DECK.replace("group g variable sel", "group g variable sell");
    let out = common::deck_error(&deck);
    let line = deck.lines().position(|l| l.starts_with("group g")).unwrap() + 1;
    assert!(out.contains(&format!("in.deck:{line}:18:")) && out.contains("sell"), "{out}");
}
