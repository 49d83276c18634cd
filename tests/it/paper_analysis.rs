//! `demx repose` and `demx packing` on synthetic sphere sets with known
//! answers: a cone of spheres of known slope, a simple-cubic column of known
//! packing fraction.

use demx::analysis::packing::packing;
use demx::analysis::repose::{bond_number, projection_angle, repose};
use demx::io::dump::read_all;
use std::fmt::Write;

fn dump(atoms: &[[f64; 4]], lo: [f64; 3], hi: [f64; 3]) -> demx::io::dump::Frame {
    let mut s = String::new();
    write!(s, "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS ff ff ff\n", atoms.len()).unwrap();
    for k in 0..3 {
        writeln!(s, "{} {}", lo[k], hi[k]).unwrap();
    }
    s.push_str("ITEM: ATOMS id type radius x y z\n");
    for (i, a) in atoms.iter().enumerate() {
        writeln!(s, "{} 1 {} {} {} {}", i + 1, a[0], a[1], a[2], a[3]).unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("dump.test");
    std::fs::write(&p, s).unwrap();
    read_all(&p).unwrap().remove(0)
}

/// Spheres of diameter 1 covering a cone of slope `alpha` (degrees) and
/// base radius `rc` on z = 0: centres on a 0.5-spaced grid, each sphere
/// tangent to the cone surface from below (centre r / cos(alpha) under it),
/// never below the plate (a flat toe of one layer at the rim).
fn cone(alpha: f64, rc: f64) -> Vec<[f64; 4]> {
    let t = alpha.to_radians().tan();
    let h = rc * t;
    let r = 0.5;
    let n = (2.0 * rc) as i64 + 2;
    let mut v = vec![];
    for i in -n..=n {
        for j in -n..=n {
            let (x, y) = (0.5 * i as f64, 0.5 * j as f64);
            let rho = (x * x + y * y).sqrt();
            if rho > rc {
                continue;
            }
            let z = (h - t * rho - r / alpha.to_radians().cos()).max(r);
            v.push([r, x, y, z]);
        }
    }
    v
}

#[test]
fn cone_of_known_slope_gives_its_angle() {
    for alpha in [25.0, 35.0] {
        let atoms = cone(alpha, 50.0);
        assert!(atoms.len() > 5000);
        let f = dump(&atoms, [-60.0; 3], [60.0; 3]);
        let r = repose(&f).unwrap();
        assert!((r.theta - alpha).abs() < 1.5, "alpha {alpha}: {r:?}");
        // axisymmetric: both projections agree
        assert!(r.sd < 0.5, "{r:?}");
    }
}

#[test]
fn triangle_profile_area_angle() {
    // a single sphere (r = 1, centre 1 above the plate): area 2 + pi/2 over base 2
    // -> atan(4 (2 + pi/2) / 4)
    let a = projection_angle(&[0.0], &[1.0], &[1.0], 1e-4).unwrap();
    assert!((a - (2.0 + std::f64::consts::FRAC_PI_2).atan().to_degrees()).abs() < 0.01, "{a}");
    // an isolated sphere far from the heap does not widen the base
    let b = projection_angle(&[0.0, 10.0], &[1.0, 1.0], &[1.0, 1.0], 1e-4).unwrap();
    assert!((a - b).abs() < 1e-9);
}

#[test]
fn simple_cubic_column_gives_its_packing_fraction() {
    let mut atoms = vec![];
    for k in 0..100 {
        for j in 0..17 {
            for i in 0..17 {
                atoms.push([0.5, i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5]);
            }
        }
    }
    let f = dump(&atoms, [0.0, 0.0, 0.0], [17.0, 17.0, 120.0]);
    let p = packing(&f).unwrap();
    // z_max = 99.5; band [29.85, 69.65] holds layers k = 30..69 (40 layers)
    let band = 0.4 * 99.5;
    let want = 40.0 * std::f64::consts::PI / 6.0 / band;
    assert!((p.phi - want).abs() < 1e-12, "{p:?}");
    assert_eq!(p.counted, 40 * 17 * 17);
    // sub-columns: 8 or 9 lattice columns per half-width of 8.5
    let q = want / 8.5;
    let sub = [8.0 * 8.0, 9.0 * 8.0, 8.0 * 9.0, 9.0 * 9.0].map(|c| q * c / 8.5);
    for (a, b) in p.sub.iter().zip(sub) {
        assert!((a - b).abs() < 1e-12, "{:?} vs {sub:?}", p.sub);
    }
    assert!((p.phi_mean - want).abs() < 1e-12);
}

#[test]
fn bond_number_of_the_paper() {
    // d = 1 mm glass on Earth: 12 * 0.05 / (1e-6 * 9.81 * 2500)
    assert!((bond_number(0.05, 1e-3, 9.81, 2500.0) - 24.464831804281346).abs() < 1e-9);
}
