//! `compute displace/atom` against the real engines. Both take an atom's
//! original position, unwrapped, when the compute is defined; they differ for
//! atoms created afterwards: LAMMPS (`set_arrays`) takes their position at
//! creation, LIGGGHTS 3.8 leaves the original at 0, so their displacement is
//! their position. Each deck creates atoms before and after the compute,
//! lets them fall and fly (one through a periodic side), and dumps
//! `c_d[1..4]` every 1500 steps; demx's dumps must agree atom by atom.

use crate::common;

use std::collections::BTreeMap;

const LAMMPS_DECK: &str = "units si\natom_style sphere\nboundary p p f\nnewton off\ncomm_modify vel yes\n\
region reg block -0.02 0.02 -0.02 0.02 0 0.04 units box\ncreate_box 2 reg\nneighbor 0.001 bin\n\
pair_style gran/hertz/history 1e6 NULL 0 NULL 0.5 0\npair_coeff * *\ntimestep 0.00001\n\
fix g all gravity 9.81 vector 0.0 0.0 -1.0\nfix w all wall/gran hertz/history 1e6 NULL 0 NULL 0.5 0 zplane 0.0 NULL\n\
create_atoms 1 single 0.0 0.0 0.010 units box\ncreate_atoms 2 single 0.005 0.0 0.012 units box\n\
create_atoms 1 single 0.019 -0.010 0.020 units box\nset type 1 diameter 0.004\nset type 2 diameter 0.003\n\
set group all density 2500\nvelocity all set 0.3 -0.2 0.0 units box\ncompute d all displace/atom\n\
create_atoms 1 single -0.012 0.011 0.007 units box\ncreate_atoms 2 single -0.019 0.0 0.035 units box\n\
set atom 4 diameter 0.004 density 2500\nset atom 5 diameter 0.003 density 2500\n\
velocity all set 0.3 -0.2 0.0 units box\nfix integr all nve/sphere\n\
dump t all custom 1500 displace.dump id type x y z ix iy iz c_d[1] c_d[2] c_d[3] c_d[4]\n\
dump_modify t format line \"%d %d %.17g %.17g %.17g %d %d %d %.17g %.17g %.17g %.17g\" sort id\nrun 3000\n";

/// Runs `deck` in the engine and in demx; returns (engine's frames, demx's).
fn both(engine: &str, deck: &str, dump: &str) -> (BTreeMap<i64, BTreeMap<i64, Vec<f64>>>, BTreeMap<i64, BTreeMap<i64, Vec<f64>>>) {
    let b = common::engine_and_demx(engine, "in.deck", &[("in.deck", deck)]);
    (common::dump_frames(&b.theirs.path().join(dump)), common::dump_frames(&b.ours.path().join(dump)))
}

/// Every row of every frame within 1e-12 m of the engine's; returns the
/// displacement (c_d[1..3]) of each atom at the last frame.
fn agree(theirs: &BTreeMap<i64, BTreeMap<i64, Vec<f64>>>, ours: &BTreeMap<i64, BTreeMap<i64, Vec<f64>>>) -> BTreeMap<i64, Vec<f64>> {
    assert_eq!(theirs.keys().collect::<Vec<_>>(), vec![&0, &1500, &3000], "the engine's frames");
    assert_eq!(ours.keys().collect::<Vec<_>>(), theirs.keys().collect::<Vec<_>>(), "demx's frames");
    for (step, rows) in theirs {
        assert_eq!(ours[step].len(), rows.len(), "atoms at step {step}");
        for (id, want) in rows {
            let got = &ours[step][id];
            for (k, (g, w)) in got.iter().zip(want).enumerate() {
                assert!((g - w).abs() <= 1e-12, "step {step} atom {id} column {}: demx {g}, engine {w}", k + 2);
            }
        }
    }
    theirs[&3000].iter().map(|(id, v)| (*id, v[7..10].to_vec())).collect()
}

#[test]
fn displace_atom_follows_lammps() {
    let (theirs, ours) = both("lmp", LAMMPS_DECK, "displace.dump");
    let d = agree(&theirs, &ours);
    // all five fly alike (same velocity, no contact), atoms 4 and 5 from where they were created
    for id in 2..=5 {
        for k in 0..3 {
            assert!((d[&id][k] - d[&1][k]).abs() < 1e-9, "atom {id} moved as atom 1: {:?} {:?}", d[&id], d[&1]);
        }
    }
    // atom 3 left through the periodic x side, and its displacement is unwrapped
    assert_eq!(theirs[&3000][&3][4], 1.0, "image flag ix of atom 3");
    assert!(d[&3][0] > 0.008, "{:?}", d[&3]);
}

#[test]
fn displace_atom_follows_liggghts() {
    let deck = std::fs::read_to_string("tests/data/io/in.liggghts_xml").unwrap();
    let (theirs, ours) = both("liggghts", &deck, "lig_xml_displace.dump");
    let d = agree(&theirs, &ours);
    // atoms 6 and 7 were created after the compute: LIGGGHTS's displacement is their position
    let pos = &theirs[&3000];
    for id in [6, 7] {
        for k in 0..3 {
            assert_eq!(d[&id][k], pos[&id][1 + k], "atom {id}, component {k}");
        }
    }
    assert!(d[&1].iter().map(|x| x * x).sum::<f64>().sqrt() < 0.01, "{:?}", d[&1]);
}
