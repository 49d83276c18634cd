//! VTK and STL output against LIGGGHTS 3.8 `dump custom/vtk` and
//! `dump mesh/stl` files (tests/data/io/in.liggghts).
use demx::io::dump::{BoxBounds, Frame};
use demx::io::vtk::{format_bounding_box_vtk, format_particles_vtk, format_stl};
use std::collections::BTreeMap;

const D: &str = "tests/data/io";

/// Split a LIGGGHTS particle VTK file into (geometry text, array name -> block text).
fn split(text: &str) -> (String, BTreeMap<String, String>) {
    let (geo, rest) = text.split_once("FIELD FieldData").unwrap();
    let rest = rest.split_once('\n').unwrap().1;
    let mut blocks = BTreeMap::new();
    let mut cur: Option<(String, String)> = None;
    for line in rest.split_inclusive('\n') {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() == 4 && (w[3] == "int" || w[3] == "double") && w[0].chars().all(|c| c.is_ascii_alphabetic()) {
            if let Some((n, b)) = cur.take() {
                blocks.insert(n, b);
            }
            cur = Some((w[0].to_string(), line.to_string()));
        } else if let Some((_, b)) = cur.as_mut() {
            b.push_str(line);
        }
    }
    if let Some((n, b)) = cur {
        blocks.insert(n, b);
    }
    (geo.to_string(), blocks)
}

/// Rebuild the dump columns of the deck from a LIGGGHTS VTK file.
fn frame_from_vtk(text: &str) -> Frame {
    let toks: Vec<&str> = text.split_whitespace().collect();
    let n: usize = toks[toks.iter().position(|t| *t == "POINTS").unwrap() + 1].parse().unwrap();
    let num = |start: usize, count: usize| -> Vec<f64> { toks[start..start + count].iter().map(|t| t.parse().unwrap()).collect() };
    let pstart = toks.iter().position(|t| *t == "POINTS").unwrap() + 3;
    let pts = num(pstart, 3 * n);
    let mut arrays: BTreeMap<String, (usize, Vec<f64>)> = BTreeMap::new();
    let fd = toks.iter().position(|t| *t == "FieldData").unwrap();
    let k: usize = toks[fd + 1].parse().unwrap();
    let mut at = fd + 2;
    for _ in 0..k {
        let name = toks[at].to_string();
        let nc: usize = toks[at + 1].parse().unwrap();
        arrays.insert(name, (nc, num(at + 4, nc * n)));
        at += 4 + nc * n;
    }
    let cols = ["id", "type", "x", "y", "z", "ix", "iy", "iz", "vx", "vy", "vz", "fx", "fy", "fz", "omegax", "omegay", "omegaz", "radius", "mass"];
    let mut values = Vec::new();
    for r in 0..n {
        for c in cols {
            let v = match c {
                "x" | "y" | "z" => pts[3 * r + (c.as_bytes()[0] - b'x') as usize],
                _ if arrays.contains_key(c) => arrays[c].1[r],
                _ => {
                    let (p, s) = c.split_at(c.len() - 1);
                    let (nc, a) = &arrays[p];
                    a[nc * r + (s.as_bytes()[0] - b'x') as usize]
                }
            };
            values.push(v);
        }
    }
    Frame {
        timestep: 0,
        time: None,
        natoms: n,
        bounds: BoxBounds::orthogonal([-0.02, -0.02, 0.0], [0.02, 0.02, 0.04], "pp pp ff"),
        columns: cols.iter().map(|s| s.to_string()).collect(),
        values,
    }
}

#[test]
fn particle_vtk_matches_liggghts() {
    for name in ["lig_vtk_0.vtk", "lig_vtk_1500.vtk", "lig_vtk_3000.vtk"] {
        let want = std::fs::read_to_string(format!("{D}/{name}")).unwrap();
        let frame = frame_from_vtk(&want);
        let got = format_particles_vtk(&frame).unwrap();
        let (wg, wb) = split(&want);
        let (gg, gb) = split(&got);
        assert_eq!(gg, wg, "{name}: geometry");
        assert_eq!(gb, wb, "{name}: arrays");
        assert_eq!(got.len(), want.len());
    }
    // Values straight from the file text: lig_vtk_3000.vtk "v 3 7 double" first triple.
    let want = std::fs::read_to_string(format!("{D}/lig_vtk_3000.vtk")).unwrap();
    let f = frame_from_vtk(&want);
    assert_eq!(f.get(0, f.col("vx").unwrap()), Some(0.071339458805));
}

#[test]
fn vtk_needs_points() {
    let f = Frame {
        timestep: 0,
        time: None,
        natoms: 1,
        bounds: BoxBounds::orthogonal([0.0; 3], [1.0; 3], "pp pp pp"),
        columns: vec!["id".into(), "x".into()],
        values: vec![1.0, 0.5],
    };
    assert!(format_particles_vtk(&f).is_err());
}

#[test]
fn bounding_box_and_stl_match_liggghts() {
    let bb = std::fs::read_to_string(format!("{D}/lig_vtk_boundingBox_0.vtk")).unwrap();
    assert_eq!(format_bounding_box_vtk([-0.02, -0.02, 0.0], [0.02, 0.02, 0.04]), bb);
    // lig_tri.stl is the mesh the deck loads; LIGGGHTS dumped it as lig_mesh_3000.stl.
    let tris = [
        [[-0.01, -0.01, 0.001], [0.01, -0.01, 0.001], [0.01, 0.01, 0.001]],
        [[-0.01, -0.01, 0.001], [0.01, 0.01, 0.001], [-0.01, 0.01, 0.001]],
    ];
    let want = std::fs::read_to_string(format!("{D}/lig_mesh_3000.stl")).unwrap();
    assert_eq!(format_stl(&tris), want);
}
