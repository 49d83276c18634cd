//! Primitive walls of fix wall/gran (LIGGGHTS and LAMMPS semantics), wiggle/shear.

use demx::geom::{PrimitiveWall, WallMotion};
use demx::physics::V3;
use demx::script::{Command, Span, Word};
use std::f64::consts::PI;

fn cmd(s: &str) -> Command {
    Command { words: s.split_whitespace().map(|w| Word::new(w, Span::DUMMY)).collect(), span: Span::DUMMY }
}

#[test]
fn liggghts_plane_both_sides() {
    let c = cmd("fix w all wall/gran model hertz tangential history primitive type 1 zplane 0.5");
    let (w, n) = PrimitiveWall::parse_liggghts(&c, &c.args()[10..]).unwrap();
    assert_eq!(n, 2);
    let (d, nrm, p) = w.contact(V3::new(1.0, 2.0, 0.6), 0.25, 0.0).unwrap();
    assert!((d - 0.15).abs() < 1e-15);
    assert_eq!(nrm, V3::new(0.0, 0.0, 1.0));
    assert_eq!(p, V3::new(1.0, 2.0, 0.5));
    let (d, nrm, _) = w.contact(V3::new(1.0, 2.0, 0.4), 0.25, 0.0).unwrap();
    assert!((d - 0.15).abs() < 1e-15);
    assert_eq!(nrm, V3::new(0.0, 0.0, -1.0));
    assert!(w.contact(V3::new(1.0, 2.0, 0.8), 0.25, 0.0).is_none());
}

#[test]
fn liggghts_cylinder_centre_order_and_sides() {
    // ycylinder r c1 c2: c1 is z, c2 is x (cyclic order)
    let c = cmd("ycylinder 1.0 2.0 3.0");
    let (w, _) = PrimitiveWall::parse_liggghts(&c, &c.words).unwrap();
    // a particle at x = 3, z = 2 + 0.9 is 0.9 from the axis (inside)
    let (d, n, p) = w.contact(V3::new(3.0, 7.0, 2.9), 0.2, 0.0).unwrap();
    assert!((d - 0.1).abs() < 1e-12);
    assert!((n - V3::new(0.0, 0.0, -1.0)).norm() < 1e-15);
    assert!((p - V3::new(3.0, 7.0, 3.0)).norm() < 1e-12);
    // outside at x = 3 + 1.1
    let (d, n, _) = w.contact(V3::new(4.1, 0.0, 2.0), 0.2, 0.0).unwrap();
    assert!((d - 0.1).abs() < 1e-12);
    assert!((n - V3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
}

#[test]
fn lammps_planes_nearest_wall_and_null() {
    let c = cmd("zplane 0.0 1.0");
    let (w, m, n) = PrimitiveWall::parse_lammps(&c, &c.words).unwrap();
    assert_eq!((m, n), (WallMotion::None, 3));
    let (d, nrm, p) = w.contact(V3::new(0.3, 0.3, 0.1), 0.15, 0.0).unwrap();
    assert!((d - 0.05).abs() < 1e-15);
    assert_eq!(nrm, V3::new(0.0, 0.0, 1.0));
    assert_eq!(p, V3::new(0.3, 0.3, 0.0));
    let (_, nrm, p) = w.contact(V3::new(0.3, 0.3, 0.95), 0.15, 0.0).unwrap();
    assert_eq!(nrm, V3::new(0.0, 0.0, -1.0));
    assert_eq!(p, V3::new(0.3, 0.3, 1.0));
    let c = cmd("xplane NULL 2.0");
    let (w, _, _) = PrimitiveWall::parse_lammps(&c, &c.words).unwrap();
    assert!(w.contact(V3::new(0.01, 0.0, 0.0), 0.1, 0.0).is_none());
    assert!(w.contact(V3::new(1.95, 0.0, 0.0), 0.1, 0.0).is_some());
}

#[test]
fn lammps_zcylinder_from_inside() {
    let c = cmd("zcylinder 2.0");
    let (w, _, _) = PrimitiveWall::parse_lammps(&c, &c.words).unwrap();
    let (d, n, p) = w.contact(V3::new(1.14, 1.52, 5.0), 0.2, 0.0).unwrap(); // rho = 1.9
    assert!((d - 0.1).abs() < 1e-12);
    assert!((n - V3::new(-0.6, -0.8, 0.0)).norm() < 1e-12);
    assert!((p - V3::new(1.2, 1.6, 5.0)).norm() < 1e-12);
    assert!(w.contact(V3::new(0.3, 0.0, 0.0), 0.2, 0.0).is_none());
}

#[test]
fn lammps_wiggle_and_shear() {
    let c = cmd("zplane 0.0 NULL wiggle z 0.1 2.0");
    let (w, m, n) = PrimitiveWall::parse_lammps(&c, &c.words).unwrap();
    assert_eq!(n, 7);
    // quarter period: wall at A - A cos(pi/2) = A, velocity A w sin(pi/2)
    let t = 0.5;
    let s = m.shift(w.axis(), t);
    assert!((s - 0.1).abs() < 1e-15);
    assert!((m.velocity(t) - V3::new(0.0, 0.0, 0.1 * PI)).norm() < 1e-15);
    let (d, _, p) = w.contact(V3::new(0.0, 0.0, 0.15), 0.1, s).unwrap();
    assert!((d - 0.05).abs() < 1e-12 && (p.z - 0.1).abs() < 1e-15);
    // wiggle along x of a z wall: no displacement, only velocity
    let c = cmd("zplane 0.0 NULL wiggle x 0.1 2.0");
    let (w, m, _) = PrimitiveWall::parse_lammps(&c, &c.words).unwrap();
    assert_eq!(m.shift(w.axis(), 0.5), 0.0);
    assert!((m.velocity(1.0) - V3::zeros()).norm() < 1e-15); // sin(pi) ~ 0
    let c = cmd("zplane 0.0 NULL shear x 0.3");
    let (_, m, _) = PrimitiveWall::parse_lammps(&c, &c.words).unwrap();
    assert_eq!(m.velocity(7.0), V3::new(0.3, 0.0, 0.0));
    let c = cmd("zplane 0.0 NULL shear z 0.3");
    assert!(PrimitiveWall::parse_lammps(&c, &c.words).is_err());
    let c = cmd("zplane 1.0 0.0");
    assert!(PrimitiveWall::parse_lammps(&c, &c.words).is_err());
}
