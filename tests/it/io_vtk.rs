//! VTK and STL output against LIGGGHTS 3.8 `dump custom/vtk` and
//! `dump mesh/stl` files (tests/data/io/in.liggghts), and its XML `.vtp`,
//! `.vtu` and `.vtr` files (tests/data/io/in.liggghts_xml).
use demx::io::dump::{BoxBounds, Frame};
use demx::io::vtk::{
    fmt_vtk_xml, format_bounding_box_vtk, format_bounding_box_vtr, format_particles_vtk, format_particles_vtk_xml, format_stl, VtkFormat,
};
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
fn vtk_frame_needs_points() {
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
    let tris =
        [[[-0.01, -0.01, 0.001], [0.01, -0.01, 0.001], [0.01, 0.01, 0.001]], [[-0.01, -0.01, 0.001], [0.01, 0.01, 0.001], [-0.01, 0.01, 0.001]]];
    let want = std::fs::read_to_string(format!("{D}/lig_mesh_3000.stl")).unwrap();
    assert_eq!(format_stl(&tris), want);
}

/// The arrays of a LIGGGHTS XML particle file: name -> (components, values),
/// the points under `Points`. The values are VTK's shortest round-trip text,
/// so they read back to the doubles LIGGGHTS wrote.
fn xml_arrays(text: &str) -> BTreeMap<String, (usize, Vec<f64>)> {
    let mut out = BTreeMap::new();
    let mut cur: Option<(String, usize, Vec<f64>)> = None;
    let attr = |line: &str, key: &str| line.split(&format!("{key}=\"")).nth(1).map(|r| r.split('"').next().unwrap().to_string());
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with("<DataArray") {
            let name = attr(t, "Name").unwrap();
            let nc = attr(t, "NumberOfComponents").map_or(1, |v| v.parse().unwrap());
            cur = Some((name, nc, vec![]));
        } else if t.starts_with("</DataArray") {
            let (n, nc, v) = cur.take().unwrap();
            out.entry(n).or_insert((nc, v));
        } else if let Some((_, _, v)) = cur.as_mut() {
            if !t.starts_with('<') && !t.is_empty() && !line.starts_with("              ") {
                v.extend(t.split_whitespace().map(|w| w.parse::<f64>().unwrap()));
            }
        }
    }
    out
}

/// A frame with `columns` (x y z from the points, `<p>x <p>y <p>z` and
/// `c_d[k]` from the grouped arrays) built from a LIGGGHTS XML file.
fn frame_from_xml(text: &str, columns: &[&str]) -> Frame {
    let a = xml_arrays(text);
    let n = a["Points"].1.len() / 3;
    let value = |c: &str, r: usize| -> f64 {
        if let Some((nc, v)) = a.get(c) {
            assert_eq!(*nc, 1);
            return v[r];
        }
        let (name, k) = match c {
            "x" | "y" | "z" => ("Points".to_string(), (c.as_bytes()[0] - b'x') as usize),
            _ if c.starts_with("c_d[") => ("c_d[1-3]".to_string(), c[4..5].parse::<usize>().unwrap() - 1),
            _ => (c[..c.len() - 1].to_string(), (c.as_bytes()[c.len() - 1] - b'x') as usize),
        };
        a[&name].1[3 * r + k]
    };
    let mut values = vec![];
    for r in 0..n {
        for c in columns {
            values.push(value(c, r));
        }
    }
    Frame {
        timestep: 0,
        time: None,
        natoms: n,
        bounds: BoxBounds::orthogonal([-0.02, -0.02, 0.0], [0.02, 0.02, 0.04], "pp pp ff"),
        columns: columns.iter().map(|s| s.to_string()).collect(),
        values,
    }
}

/// The columns of in.liggghts_xml's three VTK dumps, with the x y z demx adds
/// when a deck leaves them out.
const VTP_COLS: &[&str] = &["id", "type", "ix", "iy", "iz", "vx", "vy", "vz", "radius", "c_d[1]", "c_d[2]", "c_d[3]", "c_d[4]", "x", "y", "z"];
const VTU_COLS: &[&str] = &["id", "type", "vx", "vy", "vz", "omegax", "omegay", "omegaz", "c_d[1]", "c_d[2]", "c_d[3]", "x", "y", "z"];
const VTK_COLS: &[&str] = &["id", "type", "vx", "vy", "vz", "c_d[1]", "c_d[2]", "c_d[3]", "c_d[4]", "x", "y", "z"];

#[test]
fn xml_particle_files_match_liggghts() {
    for step in [0, 1500, 3000] {
        for (ext, cols, format) in [("vtp", VTP_COLS, VtkFormat::PolyData), ("vtu", VTU_COLS, VtkFormat::UnstructuredGrid)] {
            let name = format!("lig_xml_{step}.{ext}");
            let want = std::fs::read_to_string(format!("{D}/{name}")).unwrap();
            let frame = frame_from_xml(&want, cols);
            let got = format_particles_vtk_xml(&frame, format).unwrap();
            for (k, (g, w)) in got.lines().zip(want.lines()).enumerate() {
                assert_eq!(g, w, "{name}: line {}", k + 1);
            }
            assert_eq!(got, want, "{name}");
        }
    }
    // the vector built from c_d[1] c_d[2] c_d[3] is one array named as LIGGGHTS names it
    let want = std::fs::read_to_string(format!("{D}/lig_xml_1500.vtp")).unwrap();
    assert!(want.contains("Name=\"c_d[1-3]\" NumberOfComponents=\"3\""));
    assert_eq!(VtkFormat::of("post/dump*.vtk"), VtkFormat::Legacy);
}

#[test]
fn legacy_vtk_groups_compute_vectors_and_takes_points_without_xyz() {
    // same step, same particles: the legacy file's arrays from the .vtp's exact values
    let xml = std::fs::read_to_string(format!("{D}/lig_xml_1500.vtp")).unwrap();
    let frame = frame_from_xml(&xml, VTK_COLS);
    let got = format_particles_vtk(&frame).unwrap();
    let want = std::fs::read_to_string(format!("{D}/lig_xml_1500.vtk")).unwrap();
    assert_eq!(got, want);
}

#[test]
fn vtk_xml_numbers_as_vtk_writes_them() {
    // VTK 9.1 vtkNumberToString (ECMAScript shortest): fixed from 1e-6 up to 1e21
    for (x, want) in [
        (0.0, "0"),
        (-0.0, "0"),
        (5850.0, "5850"),
        (0.14805094999999163, "0.14805094999999163"),
        (3.081180558738227e-05, "0.00003081180558738227"),
        (1e-6, "0.000001"),
        (5.3623961824775246e-17, "5.3623961824775246e-17"),
        (1e299, "1e+299"),
        (-1e299, "-1e+299"),
        (1e20, "100000000000000000000"),
        (1.5e21, "1.5e+21"),
    ] {
        assert_eq!(fmt_vtk_xml(x), want, "{x:e}");
    }
}

#[test]
fn xml_bounding_box_matches_liggghts_but_for_array_names() {
    let want = std::fs::read_to_string(format!("{D}/lig_xml_boundingBox_1500.vtr")).unwrap();
    let got = format_bounding_box_vtr([-0.02, -0.02, 0.0], [0.02, 0.02, 0.04]);
    // VTK names the coordinate arrays after their address in memory
    let unname = |t: &str| {
        t.lines()
            .map(|l| match l.split_once(" Name=\"") {
                Some((a, b)) => format!("{a}{}", &b[b.find('"').unwrap() + 1..]),
                None => l.to_string(),
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(unname(&got), unname(&want));
}
