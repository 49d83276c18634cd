//! Triangle meshes: transforms of `fix mesh/surface`, sphere-triangle
//! contact, a uniform bin grid over triangles, and rigid motion of
//! `fix move/mesh`.
//!
//! LIGGGHTS 3.8 `fix mesh/surface file F ... move dx dy dz rotate axis ax ay
//! az angle deg scale s` applies each transform immediately as it is read,
//! so the ORDER WRITTEN in the deck is the order applied. `rotate` turns
//! about the origin (0,0,0) with angle `deg * 3.14159265 / 180` (LIGGGHTS'
//! truncated pi, reproduced here); `scale` multiplies coordinates about the
//! origin. Keywords `type`, `verbose`, `heal`, `precision`,
//! `element_exclusion_list` must come before the transforms in LIGGGHTS.

use super::{closest_on_segment, need, parse_f64, rotate_about};
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{Command, Word};

/// One triangle with precomputed edges and normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertices in file order.
    pub v: [V3; 3],
    /// Edges v1-v0, v2-v1, v0-v2.
    pub e: [V3; 3],
    /// Unit normal (v1-v0) x (v2-v0), normalised (zero for a degenerate triangle).
    pub n: V3,
}

impl Triangle {
    /// A triangle from three vertices.
    pub fn new(a: V3, b: V3, c: V3) -> Triangle {
        let n = (b - a).cross(&(c - a));
        let l = n.norm();
        Triangle { v: [a, b, c], e: [b - a, c - b, a - c], n: if l > 0.0 { n / l } else { V3::zeros() } }
    }
    /// Area.
    pub fn area(&self) -> f64 {
        0.5 * self.e[0].cross(&(self.v[2] - self.v[0])).norm()
    }
    /// Axis-aligned bounds.
    pub fn bounds(&self) -> (V3, V3) {
        (self.v[0].inf(&self.v[1]).inf(&self.v[2]), self.v[0].sup(&self.v[1]).sup(&self.v[2]))
    }
}

/// Which feature of a triangle the closest point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactKind {
    /// Interior of the face.
    Face,
    /// Edge i (from v\[i\] to v\[(i+1)%3\]).
    Edge(u8),
    /// Vertex i.
    Vertex(u8),
}

/// Closest point of triangle `t` to `p` and the feature it lies on
/// (Voronoi-region test on the barycentric coordinates).
pub fn closest_point_on_triangle(p: V3, t: &Triangle) -> (V3, ContactKind) {
    let [a, b, c] = t.v;
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, ContactKind::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, ContactKind::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let s = d1 / (d1 - d3);
        return (a + ab * s, ContactKind::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, ContactKind::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let s = d2 / (d2 - d6);
        return (a + ac * s, ContactKind::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * s, ContactKind::Edge(1));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        // degenerate triangle: closest of its three edges
        let cands = [closest_on_segment(p, a, b).0, closest_on_segment(p, b, c).0, closest_on_segment(p, c, a).0];
        let mut best = 0;
        for k in 1..3 {
            if (p - cands[k]).norm() < (p - cands[best]).norm() {
                best = k;
            }
        }
        return (cands[best], ContactKind::Edge(best as u8));
    }
    let v = vb / denom;
    let w = vc / denom;
    (a + ab * v + ac * w, ContactKind::Face)
}

/// Contact of a sphere with a triangle: `(delta, normal, point, kind)` with
/// overlap `delta = radius - distance > 0`, unit normal from the triangle
/// into the sphere centre, and the closest point; None without overlap.
/// A centre lying on the triangle gets the face normal.
pub fn sphere_triangle_contact(center: V3, radius: f64, tri: &Triangle) -> Option<(f64, V3, V3, ContactKind)> {
    let (q, kind) = closest_point_on_triangle(center, tri);
    let d = (center - q).norm();
    if d >= radius {
        return None;
    }
    let n = if d > 0.0 { (center - q) / d } else { tri.n };
    Some((radius - d, n, q, kind))
}

/// A static transform of `fix mesh/surface`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshTransform {
    /// `move dx dy dz`.
    Move(V3),
    /// `rotate axis ax ay az angle deg` (about the origin).
    Rotate {
        /// Axis (not necessarily unit).
        axis: V3,
        /// Angle in degrees.
        deg: f64,
    },
    /// `scale s`.
    Scale(f64),
}

/// Parse the transform keywords of `fix mesh/surface` found in `words`
/// (any position); returns them in deck order plus the indices of the words
/// they used, so the caller can parse the remaining keywords itself.
pub fn parse_mesh_transforms(cmd: &Command, words: &[Word]) -> Result<(Vec<MeshTransform>, Vec<usize>)> {
    let mut out = Vec::new();
    let mut used = Vec::new();
    let mut i = 0;
    while i < words.len() {
        match words[i].text.as_str() {
            "move" => {
                let v = super::need_v3(cmd, words, i + 1, "move dx dy dz")?;
                out.push(MeshTransform::Move(v));
                used.extend(i..i + 4);
                i += 4;
            }
            "rotate" => {
                let ax = need(cmd, words, i + 1, "rotate axis ax ay az angle deg")?;
                if ax.text != "axis" {
                    return Err(Error::deck(ax.span, "expected keyword 'axis' after 'rotate'"));
                }
                let axis = super::need_v3(cmd, words, i + 2, "rotation axis")?;
                let an = need(cmd, words, i + 5, "angle deg")?;
                if an.text != "angle" {
                    return Err(Error::deck(an.span, "expected keyword 'angle' after the axis"));
                }
                let deg = parse_f64(need(cmd, words, i + 6, "angle in degrees")?, "rotation angle")?;
                if axis.norm() < 1e-5 {
                    return Err(Error::deck(words[i + 2].span, "illegal magnitude of rotation axis"));
                }
                out.push(MeshTransform::Rotate { axis, deg });
                used.extend(i..i + 7);
                i += 7;
            }
            "scale" => {
                let s = parse_f64(need(cmd, words, i + 1, "scale factor")?, "scale")?;
                out.push(MeshTransform::Scale(s));
                used.extend(i..i + 2);
                i += 2;
            }
            _ => i += 1,
        }
    }
    Ok((out, used))
}

/// LIGGGHTS' value of pi in `fix mesh` rotations.
#[allow(clippy::approx_constant)] // LIGGGHTS's own 9-digit value, on purpose
pub const LIGGGHTS_PI: f64 = 3.14159265;

impl MeshTransform {
    /// Apply to one point.
    pub fn apply(&self, p: V3) -> V3 {
        match *self {
            MeshTransform::Move(d) => p + d,
            MeshTransform::Rotate { axis, deg } => rotate_about(p, axis.normalize(), deg * LIGGGHTS_PI / 180.0),
            MeshTransform::Scale(s) => p * s,
        }
    }
}

/// A triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Triangles.
    pub tris: Vec<Triangle>,
}

impl Mesh {
    /// A mesh from triangles.
    pub fn new(tris: Vec<Triangle>) -> Mesh {
        Mesh { tris }
    }
    /// Apply transforms in order (deck order).
    pub fn transformed(&self, ts: &[MeshTransform]) -> Mesh {
        let tris = self
            .tris
            .iter()
            .map(|t| {
                let mut v = t.v;
                for tr in ts {
                    for p in v.iter_mut() {
                        *p = tr.apply(*p);
                    }
                }
                Triangle::new(v[0], v[1], v[2])
            })
            .collect();
        Mesh { tris }
    }
    /// Bounds of all vertices (None if empty).
    pub fn bounds(&self) -> Option<(V3, V3)> {
        let mut it = self.tris.iter().map(|t| t.bounds());
        let first = it.next()?;
        Some(it.fold(first, |(a, b), (c, d)| (a.inf(&c), b.sup(&d))))
    }
    /// The mesh after rigid motion `m` at time `t` (from this reference position).
    pub fn moved(&self, m: &MeshMotion, t: f64) -> Mesh {
        Mesh { tris: self.tris.iter().map(|tr| Triangle::new(m.position(tr.v[0], t), m.position(tr.v[1], t), m.position(tr.v[2], t))).collect() }
    }
}

/// Rigid motion of `fix move/mesh` (LIGGGHTS): time `t` is measured from the
/// start of the fix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshMotion {
    /// `linear vx vy vz`: x(t) = x0 + v t.
    Linear(V3),
    /// `rotate origin Px Py Pz axis ax ay az period T`: angle 2 pi t / T about
    /// the axis through P (right-hand rule).
    Rotate {
        /// Point on the axis.
        origin: V3,
        /// Unit axis.
        axis: V3,
        /// Period (s).
        period: f64,
    },
}

impl MeshMotion {
    /// Parse the arguments after `fix ID group move/mesh mesh MESHID`:
    /// `linear vx vy vz` or `rotate origin Px Py Pz axis ax ay az period T`.
    pub fn parse(cmd: &Command, words: &[Word]) -> Result<MeshMotion> {
        let s = need(cmd, words, 0, "motion style (linear or rotate)")?;
        match s.text.as_str() {
            "linear" => Ok(MeshMotion::Linear(super::need_v3(cmd, words, 1, "linear vx vy vz")?)),
            "rotate" => {
                let expect = |i: usize, kw: &str| -> Result<()> {
                    let w = need(cmd, words, i, kw)?;
                    if w.text != kw {
                        return Err(Error::deck(w.span, format!("expected keyword '{kw}'")));
                    }
                    Ok(())
                };
                expect(1, "origin")?;
                let origin = super::need_v3(cmd, words, 2, "origin Px Py Pz")?;
                expect(5, "axis")?;
                let axis = super::need_v3(cmd, words, 6, "axis ax ay az")?;
                expect(9, "period")?;
                let pw = need(cmd, words, 10, "period T")?;
                let period = parse_f64(pw, "period")?;
                if axis.norm() == 0.0 {
                    return Err(Error::deck(words[6].span, "rotation axis has zero length"));
                }
                if period == 0.0 {
                    return Err(Error::deck(pw.span, "rotation period must be non-zero"));
                }
                Ok(MeshMotion::Rotate { origin, axis: axis.normalize(), period })
            }
            other => Err(Error::unsupported(s.span, format!("fix move/mesh style '{other}'"))),
        }
    }
    /// Position at time t of the point that was at `p0` at t = 0.
    pub fn position(&self, p0: V3, t: f64) -> V3 {
        match *self {
            MeshMotion::Linear(v) => p0 + v * t,
            MeshMotion::Rotate { origin, axis, period } => origin + rotate_about(p0 - origin, axis, 2.0 * std::f64::consts::PI * t / period),
        }
    }
    /// Wall velocity at the current point `p` (any t for these motions).
    pub fn velocity(&self, p: V3, _t: f64) -> V3 {
        match *self {
            MeshMotion::Linear(v) => v,
            MeshMotion::Rotate { origin, axis, period } => (axis * (2.0 * std::f64::consts::PI / period)).cross(&(p - origin)),
        }
    }
}

/// Uniform grid of cells over the mesh bounds; each cell lists the
/// triangles whose bounding box overlaps it.
#[derive(Clone, Debug)]
pub struct TriangleBins {
    lo: V3,
    cell: f64,
    dims: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl TriangleBins {
    /// Build with cubic cells of edge `cell` (> 0; grown so the grid has at
    /// most ~4 million cells).
    pub fn new(mesh: &Mesh, cell: f64) -> TriangleBins {
        let (lo, hi) = mesh.bounds().unwrap_or((V3::zeros(), V3::zeros()));
        let ext = hi - lo;
        let mut cell = if cell > 0.0 && cell.is_finite() { cell } else { ext.max().max(1e-12) };
        loop {
            let n: f64 = ext.iter().map(|e| (e / cell).floor() + 1.0).product();
            if n <= 4.0e6 {
                break;
            }
            cell *= 1.5;
        }
        let dims = [0, 1, 2].map(|d| (ext[d] / cell).floor() as usize + 1);
        let mut cells = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        let mut b = TriangleBins { lo, cell, dims, cells: Vec::new() };
        for (i, t) in mesh.tris.iter().enumerate() {
            let (a, z) = t.bounds();
            let (c0, c1) = (b.coord(a), b.coord(z));
            for kz in c0[2]..=c1[2] {
                for ky in c0[1]..=c1[1] {
                    for kx in c0[0]..=c1[0] {
                        cells[b.index(kx, ky, kz)].push(i as u32);
                    }
                }
            }
        }
        b.cells = cells;
        b
    }
    fn coord(&self, p: V3) -> [usize; 3] {
        [0, 1, 2].map(|d| {
            let c = ((p[d] - self.lo[d]) / self.cell).floor();
            if c.is_nan() || c < 0.0 {
                0
            } else {
                (c as usize).min(self.dims[d] - 1)
            }
        })
    }
    fn index(&self, x: usize, y: usize, z: usize) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }
    /// Sorted, de-duplicated indices of triangles that may touch the sphere
    /// (`center`, `radius`).
    pub fn candidates(&self, center: V3, radius: f64) -> Vec<usize> {
        let r = V3::repeat(radius);
        let (a, z) = (center - r, center + r);
        let hi = self.lo + V3::from([0, 1, 2].map(|d| self.dims[d] as f64 * self.cell));
        if (0..3).any(|d| z[d] < self.lo[d] || a[d] > hi[d]) {
            return Vec::new();
        }
        let (c0, c1) = (self.coord(a), self.coord(z));
        let mut out = Vec::new();
        for kz in c0[2]..=c1[2] {
            for ky in c0[1]..=c1[1] {
                for kx in c0[0]..=c1[0] {
                    out.extend(self.cells[self.index(kx, ky, kz)].iter().map(|i| *i as usize));
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}
