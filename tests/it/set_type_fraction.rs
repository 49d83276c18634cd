//! `set ... type/fraction` against the real LAMMPS: each selected atom draws
//! from a Park-Miller generator seeded by the seed and its position (Jenkins'
//! one-at-a-time hash, `RanPark::reset`), so the types are the same as
//! lmp's atom by atom, not only in proportion.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

const DECK: &str = "units lj\natom_style sphere\nboundary p p f\nregion box block 0 8 0 6 0 5\ncreate_box 3 box\n\
lattice fcc 1.0\ncreate_atoms 1 region box\nregion half block 0 4 INF INF INF INF\ngroup left region half\n\
set group all type/fraction 2 0.5 12393\nset group left type/fraction 3 0.25 876543\n\
dump d all custom 1 types.dump id type x y z\ndump_modify d sort id format line \"%d %d %.17g %.17g %.17g\"\nrun 0\n";

/// id -> type of the dump's one frame.
fn types(dir: &Path) -> BTreeMap<i64, i64> {
    let text = std::fs::read_to_string(dir.join("types.dump")).expect("types.dump written");
    let rows = text.split_once("ITEM: ATOMS").expect("an atoms section").1.lines().skip(1);
    rows.map(|l| {
        let w: Vec<i64> = l.split_whitespace().take(2).map(|v| v.parse().unwrap()).collect();
        (w[0], w[1])
    })
    .collect()
}

#[test]
fn types_follow_lammps_atom_by_atom() {
    let b = common::engine_and_demx("lmp", "in.deck", &[("in.deck", DECK)]);
    let (want, got) = (types(b.theirs.path()), types(b.ours.path()));
    assert_eq!(want.len(), 308, "lmp's fcc lattice");
    let count = |t: i64| want.values().filter(|&&v| v == t).count();
    // both draws took about their fractions: all three types are there
    assert!(count(1) > 80 && count(2) > 80 && count(3) > 30, "{} {} {}", count(1), count(2), count(3));
    let differ: Vec<_> = want.iter().filter(|(id, t)| got.get(id) != Some(t)).collect();
    assert!(differ.is_empty(), "{} of {} atoms got another type than in lmp: {:?}", differ.len(), want.len(), &differ[..differ.len().min(5)]);
}

#[test]
fn bad_fraction_is_a_deck_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.deck"), DECK.replace("type/fraction 2 0.5", "type/fraction 2 1.5")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).args(["check", "in.deck"]).current_dir(dir.path()).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("in.deck:10:") && err.contains("fraction 1.5 is not between 0 and 1"), "{err}");
}
