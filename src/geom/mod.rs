//! Geometry: regions, lattices, triangle meshes and primitive wall shapes.
//!
//! Responsibility: parse the geometric commands of LAMMPS/LIGGGHTS decks
//! (`region`, `lattice`, the mesh file and transforms of `fix mesh/surface`,
//! the shapes of `fix wall/gran`) into SI-valued shapes, and answer geometric
//! questions about them: membership, bounding boxes, volumes, the ordered
//! points of `create_atoms`, and sphere-surface contacts (distance, normal
//! pointing from the wall into the particle, contact point).
//!
//! Everything here is pure geometry; forces belong to `physics`, stepping
//! and neighbour bookkeeping to `engine`.

pub mod lattice;
pub mod mesh;
pub mod primitive;
pub mod region;
pub mod stl;

pub use lattice::{parse_lattice, Lattice, LatticeStyle};
pub use mesh::{sphere_triangle_contact, ContactKind, Mesh, MeshMotion, MeshTransform, Triangle, TriangleBins};
pub use primitive::{PrimitiveWall, WallMotion};
pub use region::{parse_region, Region, RegionParseCtx, SurfaceContact};
pub use stl::{read_stl, read_stl_bytes};

use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{Command, Span, Word};

/// Parse a floating-point number the way LAMMPS `utils::numeric` accepts it
/// (digits, sign, `.`, exponent; no `inf`/`nan`).
pub(crate) fn parse_f64(w: &Word, what: &str) -> Result<f64> {
    let t = w.text.trim();
    let ok_chars =
        !t.is_empty() && t.chars().all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-')) && t.chars().any(|c| c.is_ascii_digit());
    match t.parse::<f64>() {
        Ok(v) if ok_chars && v.is_finite() => Ok(v),
        _ => Err(Error::deck(w.span, format!("expected a number for {what}, found '{}'", w.text))),
    }
}

/// Parse an integer (LAMMPS `utils::inumeric`).
pub(crate) fn parse_i64(w: &Word, what: &str) -> Result<i64> {
    w.text.trim().parse::<i64>().map_err(|_| Error::deck(w.span, format!("expected an integer for {what}, found '{}'", w.text)))
}

/// The word at `i` of `args`, or an error at the end of the command saying what is missing.
pub(crate) fn need<'a>(cmd: &Command, args: &'a [Word], i: usize, what: &str) -> Result<&'a Word> {
    args.get(i).ok_or_else(|| {
        let span = args.last().map(|w| w.span).unwrap_or(cmd.span);
        Error::deck(span, format!("{}: missing {what}", cmd.name()))
    })
}

/// Three numbers at `args[i..i+3]`.
pub(crate) fn need_v3(cmd: &Command, args: &[Word], i: usize, what: &str) -> Result<V3> {
    let x = parse_f64(need(cmd, args, i, what)?, what)?;
    let y = parse_f64(need(cmd, args, i + 1, what)?, what)?;
    let z = parse_f64(need(cmd, args, i + 2, what)?, what)?;
    Ok(V3::new(x, y, z))
}

/// Span of a word or the command if absent.
#[allow(dead_code)]
pub(crate) fn span_of(cmd: &Command, args: &[Word], i: usize) -> Span {
    args.get(i).map(|w| w.span).unwrap_or(cmd.span)
}

/// Rotate `v` by `angle` (radians) about the unit axis `axis` (Rodrigues).
pub fn rotate_about(v: V3, axis: V3, angle: f64) -> V3 {
    let (s, c) = angle.sin_cos();
    rotate_sc(v, axis, s, c)
}

/// [`rotate_about`] with the angle's sine and cosine given (Rodrigues'
/// formula): the same bits, for a rotation applied to many vectors.
pub fn rotate_sc(v: V3, axis: V3, s: f64, c: f64) -> V3 {
    v * c + axis.cross(&v) * s + axis * (axis.dot(&v) * (1.0 - c))
}

/// Closest point on segment `a`-`b` to `p`, with the segment parameter in [0, 1].
pub fn closest_on_segment(p: V3, a: V3, b: V3) -> (V3, f64) {
    let ab = b - a;
    let l2 = ab.norm_squared();
    if l2 == 0.0 {
        return (a, 0.0);
    }
    let t = ((p - a).dot(&ab) / l2).clamp(0.0, 1.0);
    (a + ab * t, t)
}
