//! STL reader (ASCII and binary), as used by LIGGGHTS `fix mesh/surface file F`.
//!
//! The format is detected from the content, not the extension: a file whose
//! length is exactly `84 + 50 * n` (n = the little-endian count at byte 80)
//! is binary, even if its header starts with `solid` (many exporters write
//! that); otherwise a file starting with `solid` is ASCII. ASCII accepts CRLF
//! line ends, any solid name, several solids per file and any case of the
//! keywords. The stored facet normal is ignored: normals are recomputed from
//! the vertex order (right-hand rule), as LIGGGHTS does.

use super::mesh::Triangle;
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::Span;
use std::path::Path;

fn file_err(span: Span, path: &str, line: Option<usize>, msg: impl Into<String>) -> Error {
    let what = match line {
        Some(l) => format!("STL file '{path}' line {l}"),
        None => format!("STL file '{path}'"),
    };
    Error::Io { span, what, err: msg.into() }
}

/// Read an STL file; `span` is where the deck named it (for errors).
pub fn read_stl(path: &Path, span: Span) -> Result<Vec<Triangle>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(span, format!("cannot read STL file '{}'", path.display()), &e))?;
    read_stl_bytes(&bytes, &path.display().to_string(), span)
}

/// Parse STL content; `name` labels errors.
pub fn read_stl_bytes(bytes: &[u8], name: &str, span: Span) -> Result<Vec<Triangle>> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if n.checked_mul(50).and_then(|x| x.checked_add(84)) == Some(bytes.len()) {
            return read_binary(bytes, n, name, span);
        }
    }
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    if bytes.len() - start >= 5 && bytes[start..start + 5].eq_ignore_ascii_case(b"solid") {
        return read_ascii(bytes, name, span);
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        return Err(file_err(
            span,
            name,
            None,
            format!(
                "not ASCII STL (no 'solid') and not binary STL ({} bytes, header says {n} triangles = {} bytes)",
                bytes.len(),
                84u128 + 50 * n as u128
            ),
        ));
    }
    Err(file_err(span, name, None, "file too short to be STL"))
}

fn read_binary(bytes: &[u8], n: usize, name: &str, span: Span) -> Result<Vec<Triangle>> {
    let f = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]) as f64;
    let mut out = Vec::with_capacity(n);
    for t in 0..n {
        let base = 84 + 50 * t + 12;
        let mut v = [V3::zeros(); 3];
        for (k, vk) in v.iter_mut().enumerate() {
            let o = base + 12 * k;
            *vk = V3::new(f(o), f(o + 4), f(o + 8));
        }
        if v.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(file_err(span, name, None, format!("triangle {} has a non-finite coordinate", t + 1)));
        }
        out.push(Triangle::new(v[0], v[1], v[2]));
    }
    Ok(out)
}

fn read_ascii(bytes: &[u8], name: &str, span: Span) -> Result<Vec<Triangle>> {
    let text = String::from_utf8_lossy(bytes);
    let mut out = Vec::new();
    // states: 0 outside solid, 1 in solid, 2 in facet, 3 in loop
    let mut state = 0;
    let mut verts: Vec<V3> = Vec::new();
    let mut last_line = 0;
    for (ln, raw) in text.lines().enumerate() {
        let lineno = ln + 1;
        last_line = lineno;
        let line = raw.trim_end_matches('\r');
        let mut toks = line.split_whitespace();
        let Some(kw) = toks.next() else { continue };
        let kw = kw.to_ascii_lowercase();
        let err = |m: String| file_err(span, name, Some(lineno), m);
        match (state, kw.as_str()) {
            (0, "solid") => state = 1,
            (1, "facet") => state = 2,
            (1, "endsolid") => state = 0,
            (2, "outer") => {
                verts.clear();
                state = 3
            }
            (3, "vertex") => {
                let mut c = [0.0; 3];
                for ck in c.iter_mut() {
                    let t = toks.next().ok_or_else(|| err("vertex needs three coordinates".into()))?;
                    *ck = t.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| err(format!("bad vertex coordinate '{t}'")))?;
                }
                if verts.len() == 3 {
                    return Err(err("more than three vertices in a facet".into()));
                }
                verts.push(V3::new(c[0], c[1], c[2]));
            }
            (3, "endloop") => {
                if verts.len() != 3 {
                    return Err(err(format!("facet has {} vertices, expected 3", verts.len())));
                }
                state = 2
            }
            (2, "endfacet") => {
                if verts.len() != 3 {
                    return Err(err("endfacet before a complete 'outer loop'".into()));
                }
                out.push(Triangle::new(verts[0], verts[1], verts[2]));
                verts.clear();
                state = 1
            }
            _ => {
                let expected = match state {
                    0 => "'solid'",
                    1 => "'facet' or 'endsolid'",
                    2 => "'outer loop' or 'endfacet'",
                    _ => "'vertex' or 'endloop'",
                };
                return Err(err(format!("unexpected '{}' (expected {expected})", kw)));
            }
        }
    }
    if state != 0 {
        return Err(file_err(span, name, Some(last_line), "file ends inside a solid (missing 'endsolid')"));
    }
    Ok(out)
}
