//! `fix freeze` against the real LAMMPS (`lmp`): a bed of 512 overlapping
//! spheres bursts apart over a frozen bottom layer whose own spheres
//! overlap each other, under gravity, with gran/hooke/history. LAMMPS gives
//! a contact with a frozen sphere the other sphere's mass as effective mass,
//! and a contact of two frozen spheres the first one's
//! (`pair_gran_hooke_history.cpp`: meff = mj if i is frozen, then mi if j
//! is); demx gave the latter an infinite one, whose damping of a contact at
//! rest is inf * 0, so the force the fix removes (f_ID) and the pressure
//! were NaN. Both, printed every 50 steps by `fix print`, must now follow
//! LAMMPS's.

use crate::common;

use std::path::Path;

/// 8 x 8 x 8 spheres of 2 mm diameter, 1.98 mm apart.
fn data() -> String {
    let k = 8;
    let n = k * k * k;
    let mut s =
        format!("overlapping spheres\n\n{n} atoms\n1 atom types\n\n-0.008 0.008 xlo xhi\n-0.008 0.008 ylo yhi\n0.0 0.04 zlo zhi\n\nAtoms\n\n");
    for i in 0..n {
        let (x, y, z) = (-0.0069 + 0.00198 * (i % k) as f64, -0.0069 + 0.00198 * ((i / k) % k) as f64, 0.0012 + 0.00198 * (i / (k * k)) as f64);
        s += &format!("{} 1 0.002 2500 {x} {y} {z}\n", i + 1);
    }
    s
}

const DECK: &str = "atom_style sphere\natom_modify map array\nboundary p p f\nnewton off\ncomm_modify vel yes\nunits si\n\
read_data data.spheres\nneighbor 0.0003 bin\nneigh_modify delay 0\n\
pair_style gran/hooke/history 2000.0 NULL 5000.0 NULL 0.5 1\npair_coeff * *\ntimestep 5e-6\n\
fix grav all gravity 9.81 vector 0.0 0.0 -1.0\ngroup low id <= 64\nfix integr all nve/sphere\nfix fr low freeze\n\
variable fz equal f_fr[3]\nvariable p equal press\nthermo 50\n\
fix pr all print 50 \"$(step) ${fz} ${p}\" file print.txt screen no\nrun 300\n";

/// The rows of `print.txt` (step, removed force z, pressure), after the
/// title line, which must be LAMMPS's default.
fn printed(dir: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(dir.join("print.txt")).expect("print.txt written");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("# Fix print output for fix pr"), "fix print's title line");
    lines
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap_or(f64::NAN)).collect();
            assert_eq!(v.len(), 3, "row {l:?}");
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn frozen_layer_forces_and_pressure_follow_lammps() {
    let data = data();
    let both = common::engine_and_demx("lmp", "in.deck", &[("data.spheres", &data), ("in.deck", DECK)]);
    let (a, b) = (printed(both.ours.path()), printed(both.theirs.path()));
    assert_eq!(a.len(), 7, "rows at steps 0, 50, ..., 300");
    assert_eq!(a.len(), b.len());
    for (r, s) in a.iter().zip(&b) {
        assert_eq!(r[0], s[0], "steps");
        for k in 1..3 {
            // the sums' order differs (LAMMPS adds by neighbour list), not
            // the physics: ~1e-14 apart where finite
            let tol = 1e-9 * s[k].abs().max(1e-3);
            assert!((r[k] - s[k]).abs() <= tol, "step {}: demx {} against LAMMPS {} (column {k})", r[0], r[k], s[k]);
        }
    }
    // the layer bore the spheres' weight, then they burst off it
    assert!(b[0][1] < -1.0 && b[0][2] > 1000.0, "LAMMPS's rows are not the scene meant: {b:?}");
}
