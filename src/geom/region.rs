//! `region ID style args keyword value ...` (LAMMPS 29 Sep 2021 / LIGGGHTS 3.8).
//!
//! Styles: block, cylinder, sphere, cone, plane, prism, union, intersect.
//! Keywords: `side in|out`, `units box|lattice` (default lattice, as both
//! engines), `open F` (LAMMPS open faces), `move v_x v_y v_z` and
//! `rotate v_theta Px Py Pz Rx Ry Rz` (equal-style variables, evaluated by the
//! caller's closure in [`Region::update`]). LIGGGHTS `mesh/tet` is unsupported.
//!
//! Membership is inclusive on the surface (LAMMPS `inside()`), `side out`
//! inverts it. [`Region::surface_contacts`] follows LAMMPS
//! `surface_interior()` (side in: the particle is inside and touches each
//! nearby non-open face separately) and `surface_exterior()` (side out: the
//! particle is outside and touches the single closest point of the closed
//! faces). Union/intersect keep only contacts whose point lies on the
//! combined surface, as LAMMPS `RegUnion`/`RegIntersect`.
//!
//! Motion: the region at time t is `x = R(theta)(x0 - P) + P + d`, where `d`
//! is the `move` displacement and R the `rotate` rotation about the point P
//! (LAMMPS `Region::forward_transform`).

use super::{need, parse_f64, rotate_about};
use crate::error::{did_you_mean, Error, Result};
use crate::physics::V3;
use crate::script::{Command, Word};

/// LAMMPS `BIG` used for INF bounds.
pub const BIG: f64 = 1.0e20;

/// What the region parser needs from the scene.
#[derive(Clone, Copy)]
pub struct RegionParseCtx<'a> {
    /// Lattice spacings (xlattice, ylattice, zlattice) in SI, for `units
    /// lattice` (the default); `lattice none 1.0` gives (1, 1, 1).
    pub lattice: V3,
    /// Simulation box (lo, hi) if it exists (needed for INF/EDGE).
    pub box_bounds: Option<(V3, V3)>,
    /// Regions defined so far (for union/intersect), looked up by id.
    pub regions: &'a [Region],
}

/// One point of contact between a sphere centre and a region surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceContact {
    /// Distance from the particle centre to the surface point (> 0).
    pub distance: f64,
    /// Unit normal from the wall point into the particle side: (p - point) / distance.
    pub normal: V3,
    /// Closest point of the surface.
    pub point: V3,
}

/// Geometric shape of a region, in its own (unmoved) frame, SI units.
#[derive(Clone, Debug)]
pub enum Shape {
    /// Axis-aligned box (bounds may be +-[`BIG`] for INF).
    Block {
        /// Lower corner.
        lo: V3,
        /// Upper corner.
        hi: V3,
    },
    /// Cylinder or truncated cone along a coordinate axis (cylinder: rlo == rhi).
    Axisym {
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// Centre: the two other coordinates in cyclic order (x: y z; y: x z as LAMMPS region; z: x y).
        c1: f64,
        /// Second centre coordinate.
        c2: f64,
        /// Radius at `lo`.
        rlo: f64,
        /// Radius at `hi`.
        rhi: f64,
        /// Lower end along the axis.
        lo: f64,
        /// Upper end along the axis.
        hi: f64,
        /// Whether this was `cone` (else `cylinder`).
        cone: bool,
    },
    /// Sphere.
    Sphere {
        /// Centre.
        center: V3,
        /// Radius.
        radius: f64,
    },
    /// Half-space on the side the normal points to.
    Plane {
        /// A point of the plane.
        point: V3,
        /// Unit normal (into the region).
        normal: V3,
    },
    /// Parallelepiped: origin `lo`, edges a=(lx,0,0), b=(xy,ly,0), c=(xz,yz,lz).
    Prism {
        /// Lower corner (xlo, ylo, zlo).
        lo: V3,
        /// (xhi, yhi, zhi).
        hi: V3,
        /// Tilts (xy, xz, yz).
        tilt: V3,
    },
    /// Union of sub-regions.
    Union(Vec<Region>),
    /// Intersection of sub-regions.
    Intersect(Vec<Region>),
}

/// Time-dependent motion from `move`/`rotate`.
#[derive(Clone, Debug, Default)]
pub struct RegionMotion {
    /// Variable names of the x, y, z displacement (`NULL` -> None).
    pub move_vars: Option<[Option<String>; 3]>,
    /// Variable name of the angle (radians), the point P and the unit axis.
    pub rotate: Option<(String, V3, V3)>,
    /// Lattice scale applied to displacements (1,1,1 for `units box`).
    pub scale: V3,
}

/// A parsed region.
#[derive(Clone, Debug)]
pub struct Region {
    /// Region ID.
    pub id: String,
    /// Shape in its own frame.
    pub shape: Shape,
    /// `side in` (true) or `side out`.
    pub interior: bool,
    /// Open faces (LAMMPS `open`, 1-based in the deck, 0-based here).
    pub open: [bool; 6],
    /// Motion, if `move` or `rotate` was given.
    pub motion: Option<RegionMotion>,
    /// Current displacement (from the last [`Region::update`]).
    pub disp: V3,
    /// Current rotation angle (radians).
    pub angle: f64,
    /// Simulation box at parse time, used to clip INF bounds.
    pub box_bounds: Option<(V3, V3)>,
}

const STYLES: [&str; 9] = ["block", "cylinder", "sphere", "cone", "plane", "prism", "union", "intersect", "mesh/tet"];

/// Parse `region ID style args keyword value ...`.
pub fn parse_region(cmd: &Command, ctx: &RegionParseCtx) -> Result<Region> {
    let args = cmd.args();
    let idw = need(cmd, args, 0, "region ID")?;
    let sw = need(cmd, args, 1, "region style")?;
    let style = sw.text.as_str();
    let nargs = match style {
        "block" => 6,
        "cylinder" => 6,
        "sphere" => 4,
        "cone" => 7,
        "plane" => 6,
        "prism" => 9,
        "union" | "intersect" => {
            let nw = need(cmd, args, 2, "number of sub-regions")?;
            let n = super::parse_i64(nw, "number of sub-regions")?;
            if n < 1 {
                return Err(Error::deck(nw.span, "region union/intersect needs at least one sub-region"));
            }
            1 + n as usize
        }
        "mesh/tet" => return Err(Error::unsupported(sw.span, "region mesh/tet")),
        _ => {
            let e = Error::deck(sw.span, format!("unknown region style '{style}'"));
            return Err(match did_you_mean(style, STYLES) {
                Some(s) => e.with_hint(format!("did you mean '{s}'?")),
                None => e,
            });
        }
    };
    let shape_args = &args[2..];
    if shape_args.len() < nargs {
        return Err(need(cmd, args, 2 + nargs - 1, &format!("arguments of region {style}")).unwrap_err());
    }
    // keywords first: units affects the shape arguments
    let mut interior = true;
    let mut lattice_units = true;
    let mut open = [false; 6];
    let mut any_open = false;
    let mut move_vars: Option<[Option<String>; 3]> = None;
    let mut rotate: Option<(String, V3, V3)> = None;
    let mut rotate_point_word: Option<[Word; 3]> = None;
    let kw = &shape_args[nargs..];
    let mut i = 0;
    while i < kw.len() {
        let w = &kw[i];
        match w.text.as_str() {
            "side" => {
                let v = need(cmd, kw, i + 1, "side in|out")?;
                interior = match v.text.as_str() {
                    "in" => true,
                    "out" => false,
                    _ => return Err(Error::deck(v.span, "expected 'in' or 'out' after side")),
                };
                i += 2;
            }
            "units" => {
                let v = need(cmd, kw, i + 1, "units box|lattice")?;
                lattice_units = match v.text.as_str() {
                    "lattice" => true,
                    "box" => false,
                    _ => return Err(Error::deck(v.span, "expected 'box' or 'lattice' after units")),
                };
                i += 2;
            }
            "open" => {
                let v = need(cmd, kw, i + 1, "face number after open")?;
                let f = super::parse_i64(v, "open face")?;
                let nfaces = match style {
                    "block" | "prism" => 6,
                    "cylinder" | "cone" => 3,
                    _ => return Err(Error::deck(w.span, format!("region {style} does not support open faces"))),
                };
                if f < 1 || f > nfaces {
                    return Err(Error::deck(v.span, format!("open face must be 1..{nfaces} for region {style}")));
                }
                open[(f - 1) as usize] = true;
                any_open = true;
                i += 2;
            }
            "move" => {
                let mut vs: [Option<String>; 3] = [None, None, None];
                for (k, slot) in vs.iter_mut().enumerate() {
                    let v = need(cmd, kw, i + 1 + k, "move v_x v_y v_z")?;
                    *slot = var_name(v)?;
                }
                move_vars = Some(vs);
                i += 4;
            }
            "rotate" => {
                let v = need(cmd, kw, i + 1, "rotate v_theta Px Py Pz Rx Ry Rz")?;
                let name = var_name(v)?.ok_or_else(|| Error::deck(v.span, "rotate needs an equal-style variable v_name"))?;
                let p = super::need_v3(cmd, kw, i + 2, "rotation point")?;
                let ax = super::need_v3(cmd, kw, i + 5, "rotation axis")?;
                if ax.norm() == 0.0 {
                    return Err(Error::deck(kw[i + 5].span, "region rotate axis has zero length"));
                }
                rotate_point_word = Some([kw[i + 2].clone(), kw[i + 3].clone(), kw[i + 4].clone()]);
                rotate = Some((name, p, ax.normalize()));
                i += 8;
            }
            _ => {
                let e = Error::deck(w.span, format!("unknown region keyword '{}'", w.text));
                return Err(match did_you_mean(&w.text, ["side", "units", "open", "move", "rotate"]) {
                    Some(s) => e.with_hint(format!("did you mean '{s}'?")),
                    None => e,
                });
            }
        }
    }
    let _ = rotate_point_word;
    let scale = if lattice_units { ctx.lattice } else { V3::new(1.0, 1.0, 1.0) };
    if let Some((_, p, _)) = rotate.as_mut() {
        *p = p.component_mul(&scale);
    }
    let sa = &shape_args[..nargs];
    let bound = |w: &Word, dim: usize, is_lo: bool, s: f64| -> Result<f64> {
        match w.text.as_str() {
            "INF" | "EDGE" => {
                let (blo, bhi) = ctx.box_bounds.ok_or_else(|| Error::deck(w.span, "cannot use region INF or EDGE when the box does not exist"))?;
                let _ = (blo, bhi);
                Ok(match (w.text.as_str(), is_lo) {
                    ("INF", true) => -BIG,
                    ("INF", false) => BIG,
                    (_, true) => blo[dim],
                    (_, false) => bhi[dim],
                })
            }
            _ => Ok(s * parse_f64(w, "region bound")?),
        }
    };
    let num = |w: &Word, s: f64| -> Result<f64> {
        if w.text.starts_with("v_") {
            return Err(Error::unsupported(w.span, "variable region geometry (v_name)"));
        }
        Ok(s * parse_f64(w, "region argument")?)
    };
    let shape = match style {
        "block" | "prism" => {
            let mut lo = V3::zeros();
            let mut hi = V3::zeros();
            for d in 0..3 {
                lo[d] = bound(&sa[2 * d], d, true, scale[d])?;
                hi[d] = bound(&sa[2 * d + 1], d, false, scale[d])?;
                if lo[d] > hi[d] {
                    return Err(Error::deck(sa[2 * d].span.to(sa[2 * d + 1].span), "region lower bound is above upper bound"));
                }
            }
            if style == "block" {
                Shape::Block { lo, hi }
            } else {
                let tilt = V3::new(num(&sa[6], scale[0])?, num(&sa[7], scale[0])?, num(&sa[8], scale[1])?);
                Shape::Prism { lo, hi, tilt }
            }
        }
        "cylinder" | "cone" => {
            let axis = match sa[0].text.as_str() {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                _ => return Err(Error::deck(sa[0].span, "region cylinder/cone axis must be x, y or z")),
            };
            let (d1, d2) = perp_dims(axis);
            let c1 = num(&sa[1], scale[d1])?;
            let c2 = num(&sa[2], scale[d2])?;
            // LAMMPS scales the radius by yscale for an x axis, xscale otherwise
            let rs = if axis == 0 { scale[1] } else { scale[0] };
            let (rlo, rhi, k) = if style == "cylinder" {
                let r = num(&sa[3], rs)?;
                (r, r, 4)
            } else {
                (num(&sa[3], rs)?, num(&sa[4], rs)?, 5)
            };
            if rlo < 0.0 || rhi < 0.0 || (style == "cylinder" && rlo == 0.0) || (rlo == 0.0 && rhi == 0.0) {
                return Err(Error::deck(sa[3].span, format!("illegal radius in region {style}")));
            }
            let lo = bound(&sa[k], axis, true, scale[axis])?;
            let hi = bound(&sa[k + 1], axis, false, scale[axis])?;
            if lo > hi {
                return Err(Error::deck(sa[k].span.to(sa[k + 1].span), "region lower bound is above upper bound"));
            }
            Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, cone: style == "cone" }
        }
        "sphere" => {
            let center = V3::new(num(&sa[0], scale[0])?, num(&sa[1], scale[1])?, num(&sa[2], scale[2])?);
            let radius = num(&sa[3], scale[0])?;
            if radius < 0.0 {
                return Err(Error::deck(sa[3].span, "region sphere radius must be >= 0"));
            }
            Shape::Sphere { center, radius }
        }
        "plane" => {
            let point = V3::new(num(&sa[0], scale[0])?, num(&sa[1], scale[1])?, num(&sa[2], scale[2])?);
            let n = V3::new(num(&sa[3], scale[0])?, num(&sa[4], scale[1])?, num(&sa[5], scale[2])?);
            if n.norm() == 0.0 {
                return Err(Error::deck(sa[3].span.to(sa[5].span), "region plane normal has zero length"));
            }
            Shape::Plane { point, normal: n.normalize() }
        }
        _ => {
            // union / intersect
            let mut subs = Vec::new();
            for w in &sa[1..] {
                let r = ctx
                    .regions
                    .iter()
                    .rev()
                    .find(|r| r.id == w.text)
                    .ok_or_else(|| Error::deck(w.span, format!("region '{}' does not exist", w.text)))?;
                subs.push(r.clone());
            }
            if style == "union" {
                Shape::Union(subs)
            } else {
                Shape::Intersect(subs)
            }
        }
    };
    let _ = any_open;
    let motion = if move_vars.is_some() || rotate.is_some() { Some(RegionMotion { move_vars, rotate, scale }) } else { None };
    Ok(Region { id: idw.text.clone(), shape, interior, open, motion, disp: V3::zeros(), angle: 0.0, box_bounds: ctx.box_bounds })
}

fn var_name(w: &Word) -> Result<Option<String>> {
    if w.text == "NULL" {
        Ok(None)
    } else if let Some(n) = w.text.strip_prefix("v_") {
        Ok(Some(n.to_string()))
    } else {
        Err(Error::deck(w.span, format!("expected v_name or NULL, found '{}'", w.text)))
    }
}

/// The two coordinates perpendicular to `axis` (x: y,z; y: x,z; z: x,y — LAMMPS region order).
pub fn perp_dims(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

fn v3_axis(axis: usize) -> V3 {
    let mut v = V3::zeros();
    v[axis] = 1.0;
    v
}

fn contact(p: V3, q: V3) -> Option<SurfaceContact> {
    let d = (p - q).norm();
    if d > 0.0 && d.is_finite() {
        Some(SurfaceContact { distance: d, normal: (p - q) / d, point: q })
    } else {
        None
    }
}

impl Region {
    /// Whether the region moves (`move` or `rotate`).
    pub fn is_dynamic(&self) -> bool {
        self.motion.is_some()
            || match &self.shape {
                Shape::Union(s) | Shape::Intersect(s) => s.iter().any(|r| r.is_dynamic()),
                _ => false,
            }
    }

    /// Variable names the region's motion reads (for validation by the scene).
    pub fn variables(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(m) = &self.motion {
            if let Some(vs) = &m.move_vars {
                out.extend(vs.iter().flatten().cloned());
            }
            if let Some((n, _, _)) = &m.rotate {
                out.push(n.clone());
            }
        }
        if let Shape::Union(s) | Shape::Intersect(s) = &self.shape {
            for r in s {
                out.extend(r.variables());
            }
        }
        out
    }

    /// Set the region's position at time `t`: `eval(name, t)` returns the
    /// value of equal-style variable `name`. Displacements are multiplied by
    /// the lattice scale when the region uses `units lattice` (as LAMMPS).
    pub fn update(&mut self, t: f64, eval: &dyn Fn(&str, f64) -> Result<f64>) -> Result<()> {
        if let Some(m) = &self.motion {
            let mut d = V3::zeros();
            if let Some(vs) = &m.move_vars {
                for k in 0..3 {
                    if let Some(n) = &vs[k] {
                        d[k] = m.scale[k] * eval(n, t)?;
                    }
                }
            }
            self.disp = d;
            if let Some((n, _, _)) = &m.rotate {
                self.angle = eval(n, t)?;
            }
        }
        if let Shape::Union(s) | Shape::Intersect(s) = &mut self.shape {
            for r in s.iter_mut() {
                r.update(t, eval)?;
            }
        }
        Ok(())
    }

    fn rot(&self) -> Option<(V3, V3)> {
        self.motion.as_ref().and_then(|m| m.rotate.as_ref()).map(|(_, p, a)| (*p, *a))
    }

    /// Current frame -> region's own frame.
    fn to_local(&self, x: V3) -> V3 {
        if self.motion.is_none() {
            return x;
        }
        let mut y = x - self.disp;
        if let Some((p, a)) = self.rot() {
            y = rotate_about(y - p, a, -self.angle) + p;
        }
        y
    }

    /// Own frame -> current frame (points).
    #[allow(clippy::wrong_self_convention)] // "from the local frame", not a constructor
    fn from_local(&self, x: V3) -> V3 {
        if self.motion.is_none() {
            return x;
        }
        let mut y = x;
        if let Some((p, a)) = self.rot() {
            y = rotate_about(y - p, a, self.angle) + p;
        }
        y + self.disp
    }

    /// Own frame -> current frame (directions).
    fn dir_from_local(&self, v: V3) -> V3 {
        match self.rot() {
            Some((_, a)) => rotate_about(v, a, self.angle),
            None => v,
        }
    }

    /// Whether `p` belongs to the region (inclusive surface; `side out` inverts).
    pub fn contains(&self, p: V3) -> bool {
        self.inside(self.to_local(p)) == self.interior
    }

    /// Geometric inside test in the own frame (ignores `side`).
    fn inside(&self, q: V3) -> bool {
        match &self.shape {
            Shape::Block { lo, hi } => (0..3).all(|d| q[d] >= lo[d] && q[d] <= hi[d]),
            Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, .. } => {
                let (d1, d2) = perp_dims(*axis);
                let a = q[*axis];
                if a < *lo || a > *hi {
                    return false;
                }
                let rr = ((q[d1] - c1).powi(2) + (q[d2] - c2).powi(2)).sqrt();
                let r = if hi > lo { rlo + (rhi - rlo) * (a - lo) / (hi - lo) } else { rlo.max(*rhi) };
                rr <= r
            }
            Shape::Sphere { center, radius } => (q - center).norm_squared() <= radius * radius,
            Shape::Plane { point, normal } => (q - point).dot(normal) >= 0.0,
            Shape::Prism { lo, hi, tilt } => {
                let f = prism_frac(*lo, *hi, *tilt, q);
                (0..3).all(|d| f[d] >= 0.0 && f[d] <= 1.0)
            }
            Shape::Union(s) => s.iter().any(|r| r.contains(q)),
            Shape::Intersect(s) => s.iter().all(|r| r.contains(q)),
        }
    }

    /// Axis-aligned bounding box of the region (clipped to the box for INF
    /// bounds), or None if unbounded (`side out`, plane, moving region).
    pub fn bbox(&self) -> Option<(V3, V3)> {
        if !self.interior || self.is_dynamic() {
            return None;
        }
        let raw = match &self.shape {
            Shape::Block { lo, hi } => Some((*lo, *hi)),
            Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, .. } => {
                let (d1, d2) = perp_dims(*axis);
                let r = rlo.max(*rhi);
                let mut a = V3::zeros();
                let mut b = V3::zeros();
                a[*axis] = *lo;
                b[*axis] = *hi;
                a[d1] = c1 - r;
                b[d1] = c1 + r;
                a[d2] = c2 - r;
                b[d2] = c2 + r;
                Some((a, b))
            }
            Shape::Sphere { center, radius } => {
                let r = V3::repeat(*radius);
                Some((center - r, center + r))
            }
            Shape::Plane { .. } => None,
            Shape::Prism { lo, hi, tilt } => {
                let mut a = V3::repeat(f64::INFINITY);
                let mut b = V3::repeat(f64::NEG_INFINITY);
                for c in prism_corners(*lo, *hi, *tilt) {
                    a = a.inf(&c);
                    b = b.sup(&c);
                }
                Some((a, b))
            }
            Shape::Union(s) => {
                let mut acc: Option<(V3, V3)> = None;
                for r in s {
                    let (a, b) = r.bbox()?;
                    acc = Some(match acc {
                        None => (a, b),
                        Some((x, y)) => (x.inf(&a), y.sup(&b)),
                    });
                }
                acc
            }
            Shape::Intersect(s) => {
                let mut acc: Option<(V3, V3)> = None;
                for r in s {
                    if let Some((a, b)) = r.bbox() {
                        acc = Some(match acc {
                            None => (a, b),
                            Some((x, y)) => (x.sup(&a), y.inf(&b)),
                        });
                    }
                }
                acc
            }
        }?;
        Some(match self.box_bounds {
            Some((blo, bhi)) => {
                let mut a = raw.0;
                let mut b = raw.1;
                for d in 0..3 {
                    if a[d] <= -BIG {
                        a[d] = blo[d];
                    }
                    if b[d] >= BIG {
                        b[d] = bhi[d];
                    }
                }
                (a, b)
            }
            None => raw,
        })
    }

    /// Volume: exact for simple shapes (INF bounds clipped to the box),
    /// `side out` = box volume minus the inside; Monte Carlo (fixed seed,
    /// 200000 samples over the bounding box) for union/intersect. None when
    /// unbounded.
    pub fn volume(&self) -> Option<f64> {
        let boxvol = self.box_bounds.map(|(a, b)| (b - a).product());
        let inner = match &self.shape {
            Shape::Block { .. } => {
                let mut r = self.clone();
                r.interior = true;
                r.motion = None;
                let (a, b) = r.bbox()?;
                (b - a).product()
            }
            Shape::Axisym { rlo, rhi, lo, hi, .. } => {
                let (lo, hi) = self.clip_axis(*lo, *hi);
                std::f64::consts::PI * (hi - lo) / 3.0 * (rlo * rlo + rlo * rhi + rhi * rhi)
            }
            Shape::Sphere { radius, .. } => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
            Shape::Plane { .. } => return None,
            Shape::Prism { lo, hi, .. } => {
                let mut r = self.clone();
                r.shape = Shape::Block { lo: *lo, hi: *hi };
                r.interior = true;
                r.motion = None;
                let (a, b) = r.bbox()?;
                (b - a).product()
            }
            Shape::Union(_) | Shape::Intersect(_) => {
                let mut r = self.clone();
                r.interior = true;
                r.motion = None;
                r.disp = V3::zeros();
                r.angle = 0.0;
                let (a, b) = r.bbox().or(self.box_bounds)?;
                let ext = b - a;
                if ext.iter().any(|e| !e.is_finite() || *e < 0.0) {
                    return None;
                }
                let n = 200_000u32;
                let mut rng = SplitMix(0x5eed_1234_abcd_0001);
                let mut hits = 0u32;
                for _ in 0..n {
                    let q = V3::new(a.x + ext.x * rng.unit(), a.y + ext.y * rng.unit(), a.z + ext.z * rng.unit());
                    if r.contains(q) {
                        hits += 1;
                    }
                }
                ext.product() * hits as f64 / n as f64
            }
        };
        if self.interior {
            Some(inner)
        } else {
            boxvol.map(|v| v - inner)
        }
    }

    fn clip_axis(&self, lo: f64, hi: f64) -> (f64, f64) {
        let Shape::Axisym { axis, .. } = &self.shape else { return (lo, hi) };
        match self.box_bounds {
            Some((a, b)) => (if lo <= -BIG { a[*axis] } else { lo }, if hi >= BIG { b[*axis] } else { hi }),
            None => (lo, hi),
        }
    }

    /// Wall contacts of a sphere centred at `p` with the region surface
    /// within `cutoff` (LAMMPS `Region::surface`): side in -> every
    /// non-open face closer than `cutoff` while `p` is strictly inside;
    /// side out -> the closest point of the non-open faces while `p` is
    /// strictly outside. Zero-distance contacts are dropped.
    pub fn surface_contacts(&self, p: V3, cutoff: f64) -> Vec<SurfaceContact> {
        self.surface_side(p, cutoff, self.interior)
    }

    fn surface_side(&self, p: V3, cutoff: f64, interior: bool) -> Vec<SurfaceContact> {
        let q = self.to_local(p);
        let mut out = match &self.shape {
            Shape::Union(s) | Shape::Intersect(s) => {
                let is_union = matches!(self.shape, Shape::Union(_));
                let mut v = Vec::new();
                for (i, r) in s.iter().enumerate() {
                    let side = if interior { r.interior } else { !r.interior };
                    for c in r.surface_side(q, cutoff, side) {
                        // a union drops a contact inside another closed member
                        // (LAMMPS `RegUnion::surface_interior`: match and not
                        // openflag); the open test first, as the strict inside
                        // test measures the distance to every face
                        let keep = s.iter().enumerate().filter(|(j, _)| *j != i).all(|(_, o)| {
                            if is_union {
                                o.open.iter().any(|f| *f) || !o.contains_strict(c.point)
                            } else {
                                o.contains(c.point)
                            }
                        });
                        if keep {
                            v.push(c);
                        }
                    }
                }
                v
            }
            _ => {
                if interior {
                    self.interior_contacts(q, cutoff, self.open)
                } else {
                    self.exterior_contacts(q, cutoff, self.open).into_iter().collect()
                }
            }
        };
        if self.motion.is_some() {
            for c in out.iter_mut() {
                c.point = self.from_local(c.point);
                c.normal = self.dir_from_local(c.normal);
            }
        }
        out
    }

    /// Membership excluding points within a tiny tolerance of the surface,
    /// so contact points on a shared surface are not discarded by round-off.
    fn contains_strict(&self, p: V3) -> bool {
        if !self.contains(p) {
            return false;
        }
        // a point on this region's own surface is not "inside" for union filtering
        let tol = 1e-12 * (1.0 + p.norm());
        let q = self.to_local(p);
        let d = self.surface_distance_local(q);
        d > tol
    }

    /// Distance from q (own frame) to the closed surface, ignoring open faces.
    fn surface_distance_local(&self, q: V3) -> f64 {
        // every face closed; q is in the own frame already
        const CLOSED: [bool; 6] = [false; 6];
        let c = if self.inside(q) {
            self.interior_contacts(q, f64::INFINITY, CLOSED)
        } else {
            self.exterior_contacts(q, f64::INFINITY, CLOSED).into_iter().collect()
        };
        if c.is_empty() {
            return 0.0;
        }
        c.iter().map(|c| c.distance).fold(f64::INFINITY, f64::min)
    }

    /// The closed faces of a block or prism (none for other shapes), in
    /// LAMMPS's face order; an array, not a Vec: region walls ask for them
    /// for every particle at every step.
    fn faces(&self, open: [bool; 6]) -> impl Iterator<Item = Face> {
        let mut f = [None; 6];
        match &self.shape {
            Shape::Block { lo, hi } => {
                for d in 0..3 {
                    for (k, v) in [lo[d], hi[d]].into_iter().enumerate() {
                        f[2 * d + k] = Some(Face::AxisRect { dim: d, at: v, lo: *lo, hi: *hi });
                    }
                }
            }
            Shape::Prism { lo, hi, tilt } => {
                let [o, a, b, c] = prism_edges(*lo, *hi, *tilt);
                // face order as LAMMPS prism: xlo xhi ylo yhi zlo zhi
                let faces = [(o, b, c), (o + a, b, c), (o, a, c), (o + b, a, c), (o, a, b), (o + c, a, b)];
                for (i, (o, e1, e2)) in faces.into_iter().enumerate() {
                    f[i] = Some(Face::Para { o, e1, e2 });
                }
            }
            _ => {}
        }
        f.into_iter().zip(open).filter_map(|(f, open)| f.filter(|_| !open))
    }

    fn interior_contacts(&self, q: V3, cutoff: f64, open: [bool; 6]) -> Vec<SurfaceContact> {
        let mut out = Vec::new();
        match &self.shape {
            Shape::Block { lo, hi } => {
                if (0..3).any(|d| q[d] <= lo[d] || q[d] >= hi[d]) {
                    return out;
                }
                for f in self.faces(open) {
                    let c = f.closest(q);
                    if (q - c).norm() < cutoff {
                        out.extend(contact(q, c));
                    }
                }
            }
            Shape::Prism { lo, hi, tilt } => {
                let f = prism_frac(*lo, *hi, *tilt, q);
                if (0..3).any(|d| f[d] <= 0.0 || f[d] >= 1.0) {
                    return out;
                }
                for face in self.faces(open) {
                    let c = face.plane_projection(q);
                    if (q - c).norm() < cutoff {
                        out.extend(contact(q, c));
                    }
                }
            }
            Shape::Sphere { center, radius } => {
                let r = (q - center).norm();
                if r > *radius || r == 0.0 {
                    return out;
                }
                if radius - r < cutoff {
                    out.extend(contact(q, center + (q - center) * (radius / r)));
                }
            }
            Shape::Plane { point, normal } => {
                let d = (q - point).dot(normal);
                if d >= 0.0 && d < cutoff {
                    out.extend(contact(q, q - normal * d));
                }
            }
            Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, .. } => {
                if !self.inside(q) {
                    return out;
                }
                // far from every face (a lower bound on the distance to the
                // side: the radial gap times the cosine of the half-angle, with
                // a margin for rounding): no contact, no face points
                let (d1, d2) = perp_dims(*axis);
                let a = q[*axis];
                let rr = ((q[d1] - c1).powi(2) + (q[d2] - c2).powi(2)).sqrt();
                let (len, dr) = (hi - lo, rhi - rlo);
                if len > 0.0 && len < BIG {
                    let r = rlo + dr * (a - lo) / len;
                    let side = (r - rr) * len / (len * len + dr * dr).sqrt();
                    let margin = cutoff * (1.0 + 1e-9) + 1e-12 * (1.0 + q.norm());
                    if side > margin && a - lo > margin && hi - a > margin {
                        return out;
                    }
                }
                for (k, c) in self.axisym_face_points(q).into_iter().enumerate() {
                    if let Some(c) = c {
                        if !open[k] && (q - c).norm() < cutoff {
                            out.extend(contact(q, c));
                        }
                    }
                }
            }
            Shape::Union(_) | Shape::Intersect(_) => {}
        }
        out
    }

    fn exterior_contacts(&self, q: V3, cutoff: f64, open: [bool; 6]) -> Option<SurfaceContact> {
        // the first closest candidate, compared by squared distance (one
        // square root for the winner, not two for every comparison)
        let best = |cands: &mut dyn Iterator<Item = V3>| -> Option<SurfaceContact> {
            let mut win: Option<(V3, f64)> = None;
            for c in cands {
                let d2 = (q - c).norm_squared();
                if win.is_none_or(|(_, w)| d2 < w) {
                    win = Some((c, d2));
                }
            }
            let (c, _) = win?;
            if (q - c).norm() < cutoff {
                contact(q, c)
            } else {
                None
            }
        };
        match &self.shape {
            Shape::Block { lo, hi } => {
                if (0..3).all(|d| q[d] > lo[d] && q[d] < hi[d]) {
                    return None;
                }
                if !open.iter().any(|o| *o) {
                    // outside a closed box, the closest surface point is q clamped to it
                    return best(&mut std::iter::once(V3::new(q.x.clamp(lo.x, hi.x), q.y.clamp(lo.y, hi.y), q.z.clamp(lo.z, hi.z))));
                }
                best(&mut self.faces(open).map(|f| f.closest(q)))
            }
            Shape::Prism { lo, hi, tilt } => {
                let f = prism_frac(*lo, *hi, *tilt, q);
                if (0..3).all(|d| f[d] > 0.0 && f[d] < 1.0) {
                    return None;
                }
                best(&mut self.faces(open).map(|f| f.closest(q)))
            }
            Shape::Sphere { center, radius } => {
                let r = (q - center).norm();
                if r < *radius || r == 0.0 {
                    return None;
                }
                best(&mut std::iter::once(center + (q - center) * (radius / r)))
            }
            Shape::Plane { point, normal } => {
                let d = -(q - point).dot(normal);
                if d >= 0.0 && d < cutoff {
                    contact(q, q + normal * d)
                } else {
                    None
                }
            }
            Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, .. } => {
                let (d1, d2) = perp_dims(*axis);
                let a = q[*axis];
                let rr = ((q[d1] - c1).powi(2) + (q[d2] - c2).powi(2)).sqrt();
                let r = if hi > lo { rlo + (rhi - rlo) * (a - lo) / (hi - lo) } else { rlo.max(*rhi) };
                if a > *lo && a < *hi && rr < r {
                    return None;
                }
                let pts = self.axisym_face_points(q);
                best(&mut pts.iter().enumerate().filter(|(k, _)| !open[*k]).filter_map(|(_, c)| *c))
            }
            Shape::Union(_) | Shape::Intersect(_) => None,
        }
    }

    /// Closest points of the lo cap, hi cap and lateral surface of a
    /// cylinder/cone (faces 1, 2, 3 of LAMMPS `open`). None for a face that
    /// is degenerate (zero-radius cap) or when q is on the axis (lateral).
    fn axisym_face_points(&self, q: V3) -> [Option<V3>; 3] {
        let Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, .. } = &self.shape else { return [None; 3] };
        let (d1, d2) = perp_dims(*axis);
        let mut radial = V3::zeros();
        radial[d1] = q[d1] - c1;
        radial[d2] = q[d2] - c2;
        let rr = radial.norm();
        let u = if rr > 0.0 { Some(radial / rr) } else { None };
        let a = q[*axis];
        // 2D profile (axial, radial); caps are segments from the axis
        let seg = |a0: f64, r0: f64, a1: f64, r1: f64| -> (f64, f64) {
            let (p, _) = super::closest_on_segment(V3::new(a, rr, 0.0), V3::new(a0, r0, 0.0), V3::new(a1, r1, 0.0));
            (p.x, p.y)
        };
        let to3 = |pa: f64, pr: f64| -> Option<V3> {
            let mut base = V3::zeros();
            base[*axis] = pa;
            base[d1] = *c1;
            base[d2] = *c2;
            if pr == 0.0 {
                return Some(base);
            }
            u.map(|u| base + u * pr)
        };
        let cap_lo = if *rlo > 0.0 && *lo > -BIG {
            let (x, y) = seg(*lo, 0.0, *lo, *rlo);
            to3(x, y)
        } else {
            None
        };
        let cap_hi = if *rhi > 0.0 && *hi < BIG {
            let (x, y) = seg(*hi, 0.0, *hi, *rhi);
            to3(x, y)
        } else {
            None
        };
        let lat = if u.is_some() {
            let (x, y) = seg(*lo, *rlo, *hi, *rhi);
            to3(x, y)
        } else {
            None
        };
        let _ = v3_axis;
        [cap_lo, cap_hi, lat]
    }
}

/// A planar face used for closest-point queries.
#[derive(Clone, Copy)]
enum Face {
    /// Face of an axis-aligned box: coordinate `dim` == `at`, others within lo..hi.
    AxisRect { dim: usize, at: f64, lo: V3, hi: V3 },
    /// Parallelogram o + s e1 + t e2, s, t in [0, 1].
    Para { o: V3, e1: V3, e2: V3 },
}

impl Face {
    fn closest(&self, q: V3) -> V3 {
        match self {
            Face::AxisRect { dim, at, lo, hi } => {
                let mut c = V3::zeros();
                for d in 0..3 {
                    c[d] = if d == *dim { *at } else { q[d].clamp(lo[d], hi[d]) };
                }
                c
            }
            Face::Para { o, e1, e2 } => {
                // solve in the face basis; if inside, the projection; else the closest edge point
                let (s, t) = para_coords(*o, *e1, *e2, q);
                if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
                    return o + e1 * s + e2 * t;
                }
                let corners = [*o, o + e1, o + e1 + e2, o + e2];
                (0..4)
                    .map(|i| super::closest_on_segment(q, corners[i], corners[(i + 1) % 4]).0)
                    .min_by(|a, b| (q - a).norm().total_cmp(&(q - b).norm()))
                    .unwrap_or(*o)
            }
        }
    }
    fn plane_projection(&self, q: V3) -> V3 {
        match self {
            Face::AxisRect { dim, at, .. } => {
                let mut c = q;
                c[*dim] = *at;
                c
            }
            Face::Para { o, e1, e2 } => {
                let n = e1.cross(e2);
                let n2 = n.norm_squared();
                if n2 == 0.0 {
                    return *o;
                }
                q - n * ((q - o).dot(&n) / n2)
            }
        }
    }
}

fn para_coords(o: V3, e1: V3, e2: V3, q: V3) -> (f64, f64) {
    let w = q - o;
    let (a, b, c) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let (d, e) = (w.dot(&e1), w.dot(&e2));
    let det = a * c - b * b;
    if det == 0.0 {
        return (f64::NAN, f64::NAN);
    }
    ((c * d - b * e) / det, (a * e - b * d) / det)
}

fn prism_edges(lo: V3, hi: V3, tilt: V3) -> [V3; 4] {
    let a = V3::new(hi.x - lo.x, 0.0, 0.0);
    let b = V3::new(tilt.x, hi.y - lo.y, 0.0);
    let c = V3::new(tilt.y, tilt.z, hi.z - lo.z);
    [lo, a, b, c]
}

fn prism_corners(lo: V3, hi: V3, tilt: V3) -> Vec<V3> {
    let [o, a, b, c] = prism_edges(lo, hi, tilt);
    let mut v = Vec::with_capacity(8);
    for i in 0..8 {
        let mut p = o;
        if i & 1 != 0 {
            p += a;
        }
        if i & 2 != 0 {
            p += b;
        }
        if i & 4 != 0 {
            p += c;
        }
        v.push(p);
    }
    v
}

/// Fractional coordinates of q in the prism (0..1 inside).
fn prism_frac(lo: V3, hi: V3, tilt: V3, q: V3) -> V3 {
    let (lx, ly, lz) = (hi.x - lo.x, hi.y - lo.y, hi.z - lo.z);
    let u = (q.z - lo.z) / lz;
    let t = (q.y - lo.y - u * tilt.z) / ly;
    let s = (q.x - lo.x - t * tilt.x - u * tilt.y) / lx;
    V3::new(s, t, u)
}

/// Small deterministic generator for Monte Carlo volumes.
struct SplitMix(u64);
impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}
