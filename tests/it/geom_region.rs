//! Regions: membership, analytic wall distances/normals, union/intersect,
//! volumes, motion, errors.

use demx::geom::region::{parse_region, Region, RegionParseCtx};
use demx::physics::V3;
use demx::script::{Command, Span, Word};

fn cmd(s: &str) -> Command {
    Command { words: s.split_whitespace().map(|w| Word::new(w, Span::DUMMY)).collect(), span: Span::DUMMY }
}
fn bx() -> Option<(V3, V3)> {
    Some((V3::new(-10.0, -10.0, -10.0), V3::new(10.0, 10.0, 10.0)))
}
fn reg(s: &str, existing: &[Region]) -> Region {
    let ctx = RegionParseCtx { lattice: V3::new(1.0, 1.0, 1.0), box_bounds: bx(), regions: existing };
    parse_region(&cmd(s), &ctx).unwrap()
}
fn close(a: V3, b: V3) -> bool {
    (a - b).norm() < 1e-12
}

#[test]
fn block_interior_faces_and_open() {
    let r = reg("region b block 0 1 0 2 0 3 units box", &[]);
    assert!(r.contains(V3::new(0.0, 2.0, 1.0))); // surface inclusive
    assert!(!r.contains(V3::new(1.1, 1.0, 1.0)));
    // near the xlo face and the ylo face
    let c = r.surface_contacts(V3::new(0.1, 0.2, 1.5), 0.25);
    assert_eq!(c.len(), 2);
    assert!((c[0].distance - 0.1).abs() < 1e-15 && close(c[0].normal, V3::new(1.0, 0.0, 0.0)) && close(c[0].point, V3::new(0.0, 0.2, 1.5)));
    assert!((c[1].distance - 0.2).abs() < 1e-15 && close(c[1].normal, V3::new(0.0, 1.0, 0.0)));
    // outside the block: nothing for side in
    assert!(r.surface_contacts(V3::new(-0.1, 0.2, 1.5), 0.25).is_empty());
    // open xlo face (face 1)
    let o = reg("region b block 0 1 0 2 0 3 units box open 1", &[]);
    let c = o.surface_contacts(V3::new(0.1, 0.2, 1.5), 0.25);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.2).abs() < 1e-15);
    assert_eq!(r.volume(), Some(6.0));
    assert_eq!(r.bbox(), Some((V3::zeros(), V3::new(1.0, 2.0, 3.0))));
}

#[test]
fn block_exterior_closest_point_edge() {
    let r = reg("region b block 0 1 0 1 0 1 side out units box", &[]);
    assert!(r.contains(V3::new(2.0, 0.5, 0.5)));
    assert!(!r.contains(V3::new(0.5, 0.5, 0.5)));
    // diagonal from the edge x=1,y=1
    let p = V3::new(1.3, 1.4, 0.5);
    let c = r.surface_contacts(p, 1.0);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.5).abs() < 1e-12);
    assert!(close(c[0].point, V3::new(1.0, 1.0, 0.5)));
    assert!(close(c[0].normal, V3::new(0.6, 0.8, 0.0)));
    assert!(r.surface_contacts(p, 0.4).is_empty());
    assert_eq!(r.volume(), Some(8000.0 - 1.0));
}

#[test]
fn cylinder_inside_lateral_and_caps_inf() {
    let r = reg("region c cylinder z 1 2 0.5 0 INF units box", &[]);
    let p = V3::new(1.3, 2.4, 0.05);
    assert!(r.contains(p));
    let c = r.surface_contacts(p, 0.1);
    // rho = 0.5 exactly -> lateral distance 0 is dropped? no: rho = sqrt(0.09+0.16)=0.5 on surface
    assert!(c.iter().all(|c| c.distance > 0.0));
    let p = V3::new(1.24, 2.32, 0.05); // rho = 0.4
    let c = r.surface_contacts(p, 0.2);
    assert_eq!(c.len(), 2);
    let lat = c.iter().find(|c| (c.distance - 0.1).abs() < 1e-12).unwrap();
    assert!(close(lat.normal, V3::new(-0.6, -0.8, 0.0)));
    assert!(close(lat.point, V3::new(1.3, 2.4, 0.05)));
    let cap = c.iter().find(|c| (c.distance - 0.05).abs() < 1e-12).unwrap();
    assert!(close(cap.normal, V3::new(0.0, 0.0, 1.0)));
    // INF hi clipped to the box in bbox and volume
    let (lo, hi) = r.bbox().unwrap();
    assert!(close(lo, V3::new(0.5, 1.5, 0.0)) && close(hi, V3::new(1.5, 2.5, 10.0)));
    assert!((r.volume().unwrap() - std::f64::consts::PI * 0.25 * 10.0).abs() < 1e-12);
    // open lateral face (3)
    let o = reg("region c cylinder z 1 2 0.5 0 INF units box open 3", &[]);
    assert_eq!(o.surface_contacts(p, 0.2).len(), 1);
}

#[test]
fn cylinder_outside_rim() {
    let r = reg("region c cylinder x 0 0 1 0 2 side out units box", &[]);
    // beyond the hi cap and radially outside: closest point is the rim
    let p = V3::new(2.3, 0.0, 1.4);
    let c = r.surface_contacts(p, 1.0);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.5).abs() < 1e-12);
    assert!(close(c[0].point, V3::new(2.0, 0.0, 1.0)));
    assert!(close(c[0].normal, V3::new(0.6, 0.0, 0.8)));
}

#[test]
fn sphere_in_and_out() {
    let s = reg("region s sphere 1 1 1 2 units box", &[]);
    let p = V3::new(1.0, 1.0, 2.5);
    let c = s.surface_contacts(p, 1.0);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.5).abs() < 1e-15);
    assert!(close(c[0].normal, V3::new(0.0, 0.0, -1.0)));
    assert!(close(c[0].point, V3::new(1.0, 1.0, 3.0)));
    let so = reg("region s sphere 1 1 1 2 side out units box", &[]);
    let c = so.surface_contacts(V3::new(1.0, 4.0, 1.0), 1.5);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 1.0).abs() < 1e-15 && close(c[0].normal, V3::new(0.0, 1.0, 0.0)));
    assert!((s.volume().unwrap() - 32.0 / 3.0 * std::f64::consts::PI).abs() < 1e-12);
}

#[test]
fn cone_lateral_distance() {
    // cone along z from r=1 at z=0 to r=0 at z=1 (45 degrees)
    let k = reg("region k cone z 0 0 1 0 0 1 units box", &[]);
    assert!(k.contains(V3::new(0.2, 0.0, 0.5)));
    assert!(!k.contains(V3::new(0.6, 0.0, 0.5)));
    let p = V3::new(0.2, 0.0, 0.5);
    let c = k.surface_contacts(p, 0.3);
    // lateral: distance from (0.2, 0.5) to the line r + z = 1 is 0.3/sqrt2
    let lat = c.iter().find(|c| c.normal.z < 0.0 && c.normal.x < 0.0).unwrap();
    assert!((lat.distance - 0.3 / 2f64.sqrt()).abs() < 1e-12);
    assert!(close(lat.normal, V3::new(-1.0, 0.0, -1.0) / 2f64.sqrt()));
    assert!((k.volume().unwrap() - std::f64::consts::PI / 3.0).abs() < 1e-12);
}

#[test]
fn plane_sides() {
    let pl = reg("region p plane 0 0 1 0 0 2 units box", &[]);
    assert!(pl.contains(V3::new(5.0, 5.0, 1.0)));
    assert!(!pl.contains(V3::new(5.0, 5.0, 0.9)));
    let c = pl.surface_contacts(V3::new(3.0, 4.0, 1.25), 0.5);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.25).abs() < 1e-15 && close(c[0].normal, V3::new(0.0, 0.0, 1.0)));
    let po = reg("region p plane 0 0 1 0 0 1 side out units box", &[]);
    let c = po.surface_contacts(V3::new(3.0, 4.0, 0.75), 0.5);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.25).abs() < 1e-15 && close(c[0].normal, V3::new(0.0, 0.0, -1.0)));
    assert!(pl.bbox().is_none() && pl.volume().is_none());
}

#[test]
fn prism_membership_and_faces() {
    // tilt xy = 1: the x range at height y is [y, 2 + y]
    let r = reg("region p prism 0 2 0 1 0 1 1 0 0 units box", &[]);
    assert!(r.contains(V3::new(2.5, 0.9, 0.5)));
    assert!(!r.contains(V3::new(0.5, 0.9, 0.5)));
    assert_eq!(r.volume(), Some(2.0));
    // distance to the slanted xlo face (plane x - y = 0) from (1.0, 0.5, 0.5)
    let c = r.surface_contacts(V3::new(1.0, 0.5, 0.5), 0.4);
    let f = c.iter().find(|c| c.normal.x > 0.0).unwrap();
    assert!((f.distance - 0.5 / 2f64.sqrt()).abs() < 1e-12);
    assert!(close(f.normal, V3::new(1.0, -1.0, 0.0) / 2f64.sqrt()));
}

#[test]
fn union_and_intersect() {
    let a = reg("region a sphere 0 0 0 1 units box", &[]);
    let b = reg("region b sphere 1.5 0 0 1 units box", &[]);
    let subs = vec![a, b];
    let u = reg("region u union 2 a b", &subs);
    let i = reg("region i intersect 2 a b", &subs);
    assert!(u.contains(V3::new(-0.9, 0.0, 0.0)) && u.contains(V3::new(2.4, 0.0, 0.0)));
    assert!(!u.contains(V3::new(0.75, 0.9, 0.0)));
    assert!(i.contains(V3::new(0.75, 0.0, 0.0)) && !i.contains(V3::new(-0.5, 0.0, 0.0)));
    // inside the union near the overlap: the part of sphere a's surface inside b is not a wall
    let p = V3::new(0.9, 0.0, 0.0);
    let c = u.surface_contacts(p, 0.2);
    assert!(c.is_empty(), "{c:?}");
    let c = u.surface_contacts(V3::new(-0.9, 0.0, 0.0), 0.2);
    assert_eq!(c.len(), 1);
    // intersect: lens; from (0.75, 0, 0) the walls are a's surface at x=1 (d 0.25) and b's at x=0.5
    let c = i.surface_contacts(V3::new(0.75, 0.0, 0.0), 0.3);
    assert_eq!(c.len(), 2);
    // lens volume of two unit spheres at distance d: pi (4 + d)(2 - d)^2 / 12
    let d: f64 = 1.5;
    let lens = std::f64::consts::PI * (4.0 + d) * (2.0 - d).powi(2) / 12.0;
    let vi = i.volume().unwrap();
    assert!((vi - lens).abs() < 0.02 * lens, "{vi} vs {lens}");
    let vu = u.volume().unwrap();
    let exact = 2.0 * 4.0 / 3.0 * std::f64::consts::PI - lens;
    assert!((vu - exact).abs() < 0.01 * exact, "{vu} vs {exact}");
    assert_eq!(vu, u.volume().unwrap()); // fixed seed
}

#[test]
fn moving_and_rotating_region() {
    let mut r = reg("region m block 0 1 0 1 0 1 units box move v_dx NULL NULL rotate v_th 0 0 0 0 0 1", &[]);
    assert!(r.is_dynamic());
    assert_eq!(r.variables(), vec!["dx".to_string(), "th".to_string()]);
    let eval = |name: &str, t: f64| -> demx::Result<f64> {
        Ok(match name {
            "dx" => 2.0 * t,
            _ => std::f64::consts::FRAC_PI_2 * t,
        })
    };
    r.update(1.0, &eval).unwrap();
    // rotated 90 deg about z through the origin -> x in [-1, 0], y in [0, 1]; then moved +2 in x
    assert!(r.contains(V3::new(1.5, 0.5, 0.5)));
    assert!(!r.contains(V3::new(0.5, 0.5, 0.5)));
    let c = r.surface_contacts(V3::new(1.9, 0.5, 0.5), 0.2);
    assert_eq!(c.len(), 1);
    assert!((c[0].distance - 0.1).abs() < 1e-12);
    assert!((c[0].normal - V3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
    assert!((c[0].point - V3::new(2.0, 0.5, 0.5)).norm() < 1e-12);
}

#[test]
fn lattice_units_scale_and_errors() {
    let ctx = RegionParseCtx { lattice: V3::new(2.0, 3.0, 4.0), box_bounds: bx(), regions: &[] };
    let r = parse_region(&cmd("region b block 0 1 0 1 0 1"), &ctx).unwrap();
    assert_eq!(r.bbox(), Some((V3::zeros(), V3::new(2.0, 3.0, 4.0))));
    let e = parse_region(&cmd("region t mesh/tet file a.vtk scale 1 move 0 0 0 rotate 0 0 0"), &ctx).unwrap_err();
    assert_eq!(e.exit_code(), 3);
    let e = parse_region(&cmd("region b blok 0 1 0 1 0 1"), &ctx).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(parse_region(&cmd("region b block 0 1 0 1 0"), &ctx).is_err());
    assert!(parse_region(&cmd("region b block 1 0 0 1 0 1"), &ctx).is_err());
    assert!(parse_region(&cmd("region u union 2 a b"), &ctx).is_err());
    assert!(parse_region(&cmd("region s sphere 0 0 0 1 open 1"), &ctx).is_err());
    let noctx = RegionParseCtx { lattice: V3::new(1.0, 1.0, 1.0), box_bounds: None, regions: &[] };
    assert!(parse_region(&cmd("region b block INF 1 0 1 0 1"), &noctx).is_err());
    let r = parse_region(&cmd("region b block EDGE 1 0 1 0 1 units box"), &ctx).unwrap();
    assert_eq!(r.bbox().unwrap().0.x, -10.0);
}

/// The face-by-face answer: every closed face's closest point, the first
/// nearest of them for side out, each one within `cutoff` for side in.
fn by_faces(r: &Region, q: V3, cutoff: f64, faces: &[V3], inside: bool) -> Vec<(f64, V3)> {
    let within = |c: &V3| (q - c).norm() < cutoff && (q - c).norm() > 0.0;
    if inside {
        faces.iter().filter(|c| within(c)).map(|c| ((q - c).norm(), *c)).collect()
    } else {
        let c = faces.iter().copied().fold(None::<V3>, |b, c| match b {
            Some(b) if (q - b).norm() <= (q - c).norm() => Some(b),
            _ => Some(c),
        });
        let _ = r;
        c.filter(within).map(|c| vec![((q - c).norm(), c)]).unwrap_or_default()
    }
}

#[test]
fn shortcuts_agree_with_the_face_by_face_search() {
    // region walls ask for contacts at every particle and step: outside a
    // closed block demx clamps the point, inside a cylinder or cone it skips
    // the face points when a bound puts every face beyond the cutoff. Both
    // must give what every face tried one by one gives.
    let mut seed = 0x9e3779b97f4a7c15u64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let out = reg("region b block -1 2 -0.5 1.5 0 3 side out units box", &[]);
    let cone = reg("region c cone z 0.5 0.5 0.3 2.0 0 4 units box", &[]);
    let cyl = reg("region y cylinder z 0.5 0.5 1.5 0 4 units box", &[]);
    let (mut outside, mut near, mut far) = (0, 0, 0);
    for _ in 0..20_000 {
        let q = V3::new(-3.0 + 7.0 * unit(), -3.0 + 6.0 * unit(), -1.0 + 6.0 * unit());
        let cutoff = 0.05 + 0.6 * unit();
        // block, side out: the six faces' closest points
        let (lo, hi) = (V3::new(-1.0, -0.5, 0.0), V3::new(2.0, 1.5, 3.0));
        if !(0..3).all(|d| q[d] >= lo[d] && q[d] <= hi[d]) {
            outside += 1;
            let faces: Vec<V3> = (0..6)
                .map(|f| {
                    let (d, at) = (f / 2, if f % 2 == 0 { lo[f / 2] } else { hi[f / 2] });
                    let mut c = V3::new(q.x.clamp(lo.x, hi.x), q.y.clamp(lo.y, hi.y), q.z.clamp(lo.z, hi.z));
                    c[d] = at;
                    c
                })
                .collect();
            let want = by_faces(&out, q, cutoff, &faces, false);
            let got: Vec<(f64, V3)> = out.surface_contacts(q, cutoff).iter().map(|c| (c.distance, c.point)).collect();
            assert_eq!(got.len(), want.len(), "block, q {q:?}, cutoff {cutoff}");
            for (g, w) in got.iter().zip(&want) {
                assert!((g.0 - w.0).abs() <= 1e-12 && close(g.1, w.1), "block, q {q:?}: {g:?} against {w:?}");
            }
        }
        // cone and cylinder, side in: the contacts must be the same with
        // the shortcut as with a cutoff so large that it never applies
        for r in [&cone, &cyl] {
            if !r.contains(q) {
                continue;
            }
            let all = r.surface_contacts(q, 1e3);
            let want: Vec<_> = all.iter().filter(|c| c.distance < cutoff).collect();
            let got = r.surface_contacts(q, cutoff);
            if want.is_empty() {
                far += 1;
            } else {
                near += 1;
            }
            assert_eq!(got.len(), want.len(), "{}, q {q:?}, cutoff {cutoff}", r.id);
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(g, *w, "{}, q {q:?}", r.id);
            }
        }
    }
    assert!(outside > 5_000 && near > 1_000 && far > 1_000, "cases: {outside} outside, {near} near, {far} far");
}
