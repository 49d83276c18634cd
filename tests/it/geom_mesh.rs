//! STL reading (ASCII vs binary), transforms, sphere-triangle contact, bins, mesh motion.

use demx::geom::mesh::{closest_point_on_triangle, parse_mesh_transforms};
use demx::geom::{read_stl, read_stl_bytes, sphere_triangle_contact, ContactKind, Mesh, MeshMotion, MeshTransform, Triangle, TriangleBins};
use demx::physics::V3;
use demx::script::{Command, Span, Word};

fn cmd(s: &str) -> Command {
    Command { words: s.split_whitespace().map(|w| Word::new(w, Span::DUMMY)).collect(), span: Span::DUMMY }
}

// a unit square in z = 0 split in two, plus a slanted triangle; coordinates exact in f32
const VERTS: [[[f32; 3]; 3]; 3] = [
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
    [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    [[0.5, 0.25, 1.0], [-0.125, 2.5, 0.75], [3.0, -1.5, 0.0625]],
];

fn ascii(crlf: bool) -> String {
    let nl = if crlf { "\r\n" } else { "\n" };
    let mut s = format!("solid my part name{nl}");
    for t in VERTS {
        s += &format!("  facet normal 0 0 0{nl}    outer loop{nl}");
        for v in t {
            s += &format!("      vertex {:e} {} {}{nl}", v[0], v[1], v[2]);
        }
        s += &format!("    endloop{nl}  endfacet{nl}");
    }
    s += &format!("endsolid my part name{nl}");
    s
}

fn binary() -> Vec<u8> {
    let mut b = Vec::new();
    let mut header = b"solid this header starts with solid".to_vec();
    header.resize(80, b' ');
    b.extend(header);
    b.extend((VERTS.len() as u32).to_le_bytes());
    for t in VERTS {
        b.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
        for v in t {
            b.extend(v.iter().flat_map(|x| x.to_le_bytes()));
        }
        b.extend([0u8, 0u8]);
    }
    b
}

fn expected() -> Vec<Triangle> {
    VERTS
        .iter()
        .map(|t| {
            let p = |k: usize| V3::new(t[k][0] as f64, t[k][1] as f64, t[k][2] as f64);
            Triangle::new(p(0), p(1), p(2))
        })
        .collect()
}

#[test]
fn ascii_and_binary_give_identical_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let pa = dir.path().join("part.bin"); // extensions deliberately misleading
    let pb = dir.path().join("part.stl");
    std::fs::write(&pa, ascii(true)).unwrap();
    std::fs::write(&pb, binary()).unwrap();
    let a = read_stl(&pa, Span::DUMMY).unwrap();
    let b = read_stl(&pb, Span::DUMMY).unwrap();
    assert_eq!(a, expected());
    assert_eq!(a, b);
    let lf = read_stl_bytes(ascii(false).as_bytes(), "lf", Span::DUMMY).unwrap();
    assert_eq!(lf, a);
    // normal from vertex order
    assert_eq!(a[0].n, V3::new(0.0, 0.0, 1.0));
}

#[test]
fn stl_errors_name_file_and_line() {
    let bad = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 zero\n";
    let e = read_stl_bytes(bad.as_bytes(), "bad.stl", Span::DUMMY).unwrap_err();
    let m = e.message();
    assert!(m.contains("bad.stl") && m.contains("line 4") && m.contains("zero"), "{m}");
    let trunc = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n  endloop\n";
    let m = read_stl_bytes(trunc.as_bytes(), "t.stl", Span::DUMMY).unwrap_err().message();
    assert!(m.contains("line 5"), "{m}");
    let mut b = binary();
    b.pop();
    assert!(read_stl_bytes(&b, "b.stl", Span::DUMMY).is_err());
    assert!(read_stl(std::path::Path::new("/nonexistent/x.stl"), Span::DUMMY).is_err());
}

#[test]
fn sphere_triangle_face_edge_vertex() {
    let t = Triangle::new(V3::zeros(), V3::new(2.0, 0.0, 0.0), V3::new(0.0, 2.0, 0.0));
    // face
    let (d, n, p, k) = sphere_triangle_contact(V3::new(0.5, 0.5, 0.3), 0.5, &t).unwrap();
    assert!((d - 0.2).abs() < 1e-15);
    assert_eq!((n, p, k), (V3::new(0.0, 0.0, 1.0), V3::new(0.5, 0.5, 0.0), ContactKind::Face));
    // below the face: normal points down, towards the centre
    let (_, n, _, _) = sphere_triangle_contact(V3::new(0.5, 0.5, -0.3), 0.5, &t).unwrap();
    assert_eq!(n, V3::new(0.0, 0.0, -1.0));
    // hypotenuse edge (v1 -> v2): centre beyond it in-plane and above
    let c = V3::new(1.0 + 0.3, 1.0 + 0.3, 0.4);
    let (d, n, p, k) = sphere_triangle_contact(c, 0.6, &t).unwrap();
    let dist = (0.18f64 + 0.16).sqrt();
    assert!((d - (0.6 - dist)).abs() < 1e-12);
    assert!((p - V3::new(1.0, 1.0, 0.0)).norm() < 1e-12);
    assert!((n - (c - p) / dist).norm() < 1e-12);
    assert_eq!(k, ContactKind::Edge(1));
    // vertex v0
    let c = V3::new(-0.3, -0.4, 0.0);
    let (d, n, p, k) = sphere_triangle_contact(c, 0.6, &t).unwrap();
    assert!((d - 0.1).abs() < 1e-12);
    assert_eq!(p, V3::zeros());
    assert!((n - V3::new(-0.6, -0.8, 0.0)).norm() < 1e-12);
    assert_eq!(k, ContactKind::Vertex(0));
    // no contact
    assert!(sphere_triangle_contact(c, 0.5, &t).is_none());
    // edges 0 and 2, vertices 1 and 2
    assert_eq!(closest_point_on_triangle(V3::new(1.0, -1.0, 0.0), &t).1, ContactKind::Edge(0));
    assert_eq!(closest_point_on_triangle(V3::new(-1.0, 1.0, 0.0), &t).1, ContactKind::Edge(2));
    assert_eq!(closest_point_on_triangle(V3::new(3.0, -1.0, 0.0), &t).1, ContactKind::Vertex(1));
    assert_eq!(closest_point_on_triangle(V3::new(-1.0, 3.0, 0.0), &t).1, ContactKind::Vertex(2));
}

#[test]
fn transforms_apply_in_deck_order() {
    let c = cmd("fix m all mesh/surface file a.stl type 1 move 1 0 0 rotate axis 0 0 1 angle 90 scale 2");
    let (ts, used) = parse_mesh_transforms(&c, &c.args()[5..]).unwrap();
    assert_eq!(ts.len(), 3);
    assert_eq!(used, (2..15).collect::<Vec<_>>());
    let m = Mesh::new(vec![Triangle::new(V3::zeros(), V3::new(1.0, 0.0, 0.0), V3::new(0.0, 1.0, 0.0))]);
    let out = m.transformed(&ts);
    // (0,0,0): move -> (1,0,0), rotate 90 -> (0,1,0), scale -> (0,2,0) (LIGGGHTS pi = 3.14159265)
    assert!((out.tris[0].v[0] - V3::new(0.0, 2.0, 0.0)).norm() < 1e-8);
    // the other order gives a different place: scale first
    let rev = m.transformed(&[MeshTransform::Scale(2.0), MeshTransform::Move(V3::new(1.0, 0.0, 0.0))]);
    assert_eq!(rev.tris[0].v[0], V3::new(1.0, 0.0, 0.0));
}

#[test]
fn bins_find_all_touching_triangles() {
    // 20x20 grid of triangle pairs on z = 0 over [0, 10]^2
    let mut tris = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let (x, y) = (i as f64 * 0.5, j as f64 * 0.5);
            tris.push(Triangle::new(V3::new(x, y, 0.0), V3::new(x + 0.5, y, 0.0), V3::new(x + 0.5, y + 0.5, 0.0)));
            tris.push(Triangle::new(V3::new(x, y, 0.0), V3::new(x + 0.5, y + 0.5, 0.0), V3::new(x, y + 0.5, 0.0)));
        }
    }
    let mesh = Mesh::new(tris);
    let bins = TriangleBins::new(&mesh, 0.7);
    for (c, r) in [(V3::new(3.1, 4.2, 0.2), 0.5), (V3::new(0.0, 0.0, 0.1), 0.3), (V3::new(9.9, 5.0, -0.05), 0.8)] {
        let brute: Vec<usize> = (0..mesh.tris.len()).filter(|&i| sphere_triangle_contact(c, r, &mesh.tris[i]).is_some()).collect();
        let cands = bins.candidates(c, r);
        assert!(!brute.is_empty());
        assert!(brute.iter().all(|i| cands.contains(i)));
        assert!(cands.len() < mesh.tris.len() / 4);
    }
    assert!(bins.candidates(V3::new(50.0, 50.0, 0.0), 1.0).is_empty());
}

#[test]
fn mesh_motion_linear_and_rotate() {
    let c = cmd("fix mv all move/mesh mesh cad linear 0.5 0 -1");
    let m = MeshMotion::parse(&c, &c.args()[5..]).unwrap();
    assert_eq!(m.position(V3::new(1.0, 1.0, 1.0), 2.0), V3::new(2.0, 1.0, -1.0));
    assert_eq!(m.velocity(V3::zeros(), 0.0), V3::new(0.5, 0.0, -1.0));
    let c = cmd("fix mv all move/mesh mesh cad rotate origin 1 0 0 axis 0 0 2 period 4");
    let m = MeshMotion::parse(&c, &c.args()[5..]).unwrap();
    // quarter period: (2,0,0) about (1,0,0) -> (1,1,0)
    assert!((m.position(V3::new(2.0, 0.0, 0.0), 1.0) - V3::new(1.0, 1.0, 0.0)).norm() < 1e-12);
    // v = omega x r, omega = 2 pi / 4 about z
    let v = m.velocity(V3::new(1.0, 1.0, 0.0), 1.0);
    assert!((v - V3::new(-std::f64::consts::FRAC_PI_2, 0.0, 0.0)).norm() < 1e-12);
    let c = cmd("fix mv all move/mesh mesh cad rotate origin 1 0 0 axis 0 0 1 period");
    assert!(MeshMotion::parse(&c, &c.args()[5..]).is_err());
}
