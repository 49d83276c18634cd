//! Lattice points of create_atoms vs real LAMMPS (29 Sep 2021, 1 proc) dumps
//! in tests/data/geom (deck: tests/data/geom/in.lattice).

use demx::geom::parse_lattice;
use demx::geom::region::{parse_region, RegionParseCtx};
use demx::physics::V3;
use demx::script::{Command, Span, Word};

fn cmd(s: &str) -> Command {
    Command { words: s.split_whitespace().map(|w| Word::new(w, Span::DUMMY)).collect(), span: Span::DUMMY }
}

fn read_dump(name: &str) -> Vec<(u64, V3)> {
    let path = format!("{}/tests/data/geom/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let mut out: Vec<(u64, V3)> = text
        .lines()
        .skip_while(|l| !l.starts_with("ITEM: ATOMS"))
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f[0].parse().unwrap(), V3::new(f[1].parse().unwrap(), f[2].parse().unwrap(), f[3].parse().unwrap()))
        })
        .collect();
    out.sort_by_key(|a| a.0);
    out
}

fn check(points: &[(V3, usize)], dump: &str) {
    let reference = read_dump(dump);
    assert_eq!(points.len(), reference.len(), "{dump}: number of atoms");
    for (k, (id, x)) in reference.iter().enumerate() {
        assert_eq!(*id as usize, k + 1);
        assert_eq!(points[k].0, *x, "{dump}: atom id {id}");
    }
}

#[test]
fn fcc_box_matches_lammps_order_and_boundary_rule() {
    let lat = parse_lattice(&cmd("lattice fcc 1.0"), false, 3).unwrap();
    assert_eq!(lat.spacing(), V3::new(1.0, 1.0, 1.0));
    let pts = lat.create_points(V3::zeros(), V3::new(2.0, 2.0, 1.5), [true, false, true], None).unwrap();
    check(&pts, "fcc_box.dump");
}

#[test]
fn hcp_oriented_with_origin_in_sphere_region_matches_lammps() {
    let lat = parse_lattice(&cmd("lattice hcp 0.7 origin 0.1 0.2 0.3 orient x 1 1 0 orient y -1 1 0 orient z 0 0 1"), false, 3).unwrap();
    let ctx = RegionParseCtx { lattice: lat.spacing(), box_bounds: Some((V3::zeros(), V3::new(2.0, 2.0, 1.5))), regions: &[] };
    let ball = parse_region(&cmd("region ball sphere 1.0 1.0 0.75 1.0 units box"), &ctx).unwrap();
    let f = |p: V3| ball.contains(p);
    let pts = lat.create_points(V3::zeros(), V3::new(2.0, 2.0, 1.5), [true, false, true], Some(&f)).unwrap();
    check(&pts, "hcp_sphere.dump");
}

#[test]
fn sc_block_in_lattice_units_matches_lammps() {
    let lat = parse_lattice(&cmd("lattice sc 0.25"), false, 3).unwrap();
    let ctx = RegionParseCtx { lattice: lat.spacing(), box_bounds: Some((V3::zeros(), V3::new(2.0, 2.0, 1.5))), regions: &[] };
    let blk = parse_region(&cmd("region blk block 1 6 2 8 0 4 units lattice"), &ctx).unwrap();
    let f = |p: V3| blk.contains(p);
    let pts = lat.create_points(V3::zeros(), V3::new(2.0, 2.0, 1.5), [false; 3], Some(&f)).unwrap();
    check(&pts, "sc_block.dump");
}

#[test]
fn lattice_spacings_as_lammps_prints_them() {
    // lmp: "Lattice spacing in x,y,z = 1.9318517 1.9318517 1.6329932"
    let l = parse_lattice(&cmd("lattice hcp 1.0 orient x 1 1 0 orient y -1 1 0 orient z 0 0 1"), false, 3).unwrap();
    let s = l.spacing();
    assert!((s.x - 1.9318517).abs() < 1e-7 && (s.y - 1.9318517).abs() < 1e-7 && (s.z - 1.6329932).abs() < 1e-7, "{s}");
    // spacing keyword is multiplied by the scale: "2.0000000 2.0000000 2.0000000"
    let l = parse_lattice(&cmd("lattice fcc 2.0 spacing 1 1 1"), false, 3).unwrap();
    assert_eq!(l.spacing(), V3::new(2.0, 2.0, 2.0));
    // lj: scale = (4 / 0.8)^(1/3) for fcc with reduced density 0.8
    let l = parse_lattice(&cmd("lattice fcc 0.8"), true, 3).unwrap();
    assert!((l.scale - 5.0f64.powf(1.0 / 3.0)).abs() < 1e-14);
    let l = parse_lattice(&cmd("lattice none 0.5"), false, 3).unwrap();
    assert_eq!(l.spacing(), V3::repeat(0.5));
}

#[test]
fn lattice_errors() {
    assert!(parse_lattice(&cmd("lattice fcc 1.0 orient x 1 1 0 orient y 1 0 0 orient z 0 0 1"), false, 3).is_err());
    assert!(parse_lattice(&cmd("lattice sq 1.0"), false, 3).is_err());
    assert!(parse_lattice(&cmd("lattice fcc -1"), false, 3).is_err());
    assert!(parse_lattice(&cmd("lattice fcc 1.0 basis 0 0 0"), false, 3).is_err());
    assert!(parse_lattice(&cmd("lattice fcc"), false, 3).is_err());
    assert!(parse_lattice(&cmd("lattice fcc 1.0 origin 1.0 0 0"), false, 3).is_err());
    let e = parse_lattice(&cmd("lattice fcx 1.0"), false, 3).unwrap_err();
    assert_eq!(e.exit_code(), 2);
}

#[test]
fn sq_2d_creates_z_layers_like_lammps() {
    // lmp (dimension 2, boundary p p p, lattice sq 0.1, box 0..0.3 x 0..0.2 x -0.5..0.5):
    // 60 atoms; ids 1..6 at z = -0.5, id 7 at (0, 0, -0.4).
    let lat = parse_lattice(&cmd("lattice sq 0.1"), false, 2).unwrap();
    let pts = lat.create_points(V3::new(0.0, 0.0, -0.5), V3::new(0.3, 0.2, 0.5), [true; 3], None).unwrap();
    assert_eq!(pts.len(), 60);
    assert_eq!(pts[1].0, V3::new(0.1, 0.0, -0.5));
    assert_eq!(pts[5].0, V3::new(0.2, 0.1, -0.5));
    assert_eq!(pts[6].0, V3::new(0.0, 0.0, -0.4));
}
