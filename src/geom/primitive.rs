//! Primitive wall shapes of `fix wall/gran`.
//!
//! LIGGGHTS `fix wall/gran ... primitive type T xplane|yplane|zplane pos`
//! and `xcylinder|ycylinder|zcylinder r c1 c2`: particles touch from either
//! side. The cylinder centre coordinates are in cyclic order of the axis
//! (LIGGGHTS `primitive_wall_definitions.h`): xcylinder (c1, c2) = (y, z),
//! ycylinder (z, x), zcylinder (x, y).
//!
//! LAMMPS `fix wall/gran ... xplane|yplane|zplane lo hi` (either may be
//! NULL): the particle meets only the nearer of the two walls, the lo wall
//! from above and the hi wall from below; `zcylinder r` is centred on the z
//! axis (x = y = 0) and met from inside. LAMMPS motion: `wiggle dim A T`
//! moves the wall when dim is its own axis to `lo + A - A cos(w t)` with wall
//! velocity `A w sin(w t)` along dim (w = 2 pi / T), and for any other dim
//! only gives that velocity; `shear dim v` gives the wall velocity v along
//! dim. t is `(step - step_at_fix_creation) * dt`.

use super::{need, parse_f64};
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{Command, Word};

/// A primitive wall shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PrimitiveWall {
    /// LIGGGHTS plane normal to `axis` at `pos` (both sides).
    Plane {
        /// 0, 1, 2.
        axis: usize,
        /// Position along the axis.
        pos: f64,
    },
    /// LIGGGHTS cylinder along `axis` (both sides).
    Cylinder {
        /// 0, 1, 2.
        axis: usize,
        /// Radius.
        radius: f64,
        /// First centre coordinate (cyclic order: x->y, y->z, z->x).
        c1: f64,
        /// Second centre coordinate.
        c2: f64,
    },
    /// LAMMPS pair of planes normal to `axis`.
    LammpsPlanes {
        /// 0, 1, 2.
        axis: usize,
        /// Lower wall (None for NULL).
        lo: Option<f64>,
        /// Upper wall (None for NULL).
        hi: Option<f64>,
    },
    /// LAMMPS `zcylinder r`: axis along z through x = y = 0, touched from inside.
    LammpsZCylinder {
        /// Radius.
        radius: f64,
    },
}

/// LAMMPS wall motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WallMotion {
    /// Static.
    None,
    /// `wiggle dim amplitude period`.
    Wiggle {
        /// 0, 1, 2.
        axis: usize,
        /// Amplitude.
        amplitude: f64,
        /// Period.
        period: f64,
    },
    /// `shear dim vshear`.
    Shear {
        /// 0, 1, 2.
        axis: usize,
        /// Velocity.
        v: f64,
    },
}

fn dim_of(w: &Word) -> Result<usize> {
    match w.text.as_str() {
        "x" => Ok(0),
        "y" => Ok(1),
        "z" => Ok(2),
        _ => Err(Error::deck(w.span, "expected x, y or z")),
    }
}

impl PrimitiveWall {
    /// Parse a LIGGGHTS primitive: `words` start at the style
    /// (`zplane 0.0`, `zcylinder 0.05 0 0`). Returns the shape and the
    /// number of words used.
    pub fn parse_liggghts(cmd: &Command, words: &[Word]) -> Result<(PrimitiveWall, usize)> {
        let s = need(cmd, words, 0, "primitive wall style")?;
        let axis = |c: char| -> usize { (c as u8 - b'x') as usize };
        match s.text.as_str() {
            "xplane" | "yplane" | "zplane" => {
                let pos = parse_f64(need(cmd, words, 1, "plane position")?, "plane position")?;
                Ok((PrimitiveWall::Plane { axis: axis(s.text.as_bytes()[0] as char), pos }, 2))
            }
            "xcylinder" | "ycylinder" | "zcylinder" => {
                let rw = need(cmd, words, 1, "cylinder radius")?;
                let radius = parse_f64(rw, "cylinder radius")?;
                if radius <= 0.0 {
                    return Err(Error::deck(rw.span, "cylinder radius must be > 0"));
                }
                let c1 = parse_f64(need(cmd, words, 2, "cylinder centre c1")?, "cylinder centre")?;
                let c2 = parse_f64(need(cmd, words, 3, "cylinder centre c2")?, "cylinder centre")?;
                Ok((PrimitiveWall::Cylinder { axis: axis(s.text.as_bytes()[0] as char), radius, c1, c2 }, 4))
            }
            other => Err(Error::unsupported(s.span, format!("primitive wall '{other}'"))),
        }
    }

    /// Parse a LAMMPS `fix wall/gran` wall: `xplane lo hi` (NULL allowed) or
    /// `zcylinder r`; then the optional `wiggle dim A T` / `shear dim v`.
    /// Returns shape, motion and words used.
    pub fn parse_lammps(cmd: &Command, words: &[Word]) -> Result<(PrimitiveWall, WallMotion, usize)> {
        let s = need(cmd, words, 0, "wall style")?;
        let opt = |w: &Word| -> Result<Option<f64>> {
            if w.text == "NULL" {
                Ok(None)
            } else {
                parse_f64(w, "wall position").map(Some)
            }
        };
        let (shape, mut n) = match s.text.as_str() {
            "xplane" | "yplane" | "zplane" => {
                let lo = opt(need(cmd, words, 1, "lo")?)?;
                let hi = opt(need(cmd, words, 2, "hi")?)?;
                if let (Some(a), Some(b)) = (lo, hi) {
                    if a >= b {
                        return Err(Error::deck(words[1].span.to(words[2].span), "wall lo must be below hi"));
                    }
                }
                (PrimitiveWall::LammpsPlanes { axis: (s.text.as_bytes()[0] - b'x') as usize, lo, hi }, 3)
            }
            "zcylinder" => {
                let rw = need(cmd, words, 1, "cylinder radius")?;
                let radius = parse_f64(rw, "cylinder radius")?;
                if radius <= 0.0 {
                    return Err(Error::deck(rw.span, "cylinder radius must be > 0"));
                }
                (PrimitiveWall::LammpsZCylinder { radius }, 2)
            }
            "region" => return Err(Error::deck(s.span, "use fix wall/gran/region for region walls")),
            other => return Err(Error::unsupported(s.span, format!("fix wall/gran style '{other}'"))),
        };
        let mut motion = WallMotion::None;
        match words.get(n).map(|w| w.text.as_str()) {
            Some("wiggle") => {
                let axis = dim_of(need(cmd, words, n + 1, "wiggle dim")?)?;
                let amplitude = parse_f64(need(cmd, words, n + 2, "wiggle amplitude")?, "amplitude")?;
                let pw = need(cmd, words, n + 3, "wiggle period")?;
                let period = parse_f64(pw, "period")?;
                if period <= 0.0 {
                    return Err(Error::deck(pw.span, "wiggle period must be > 0"));
                }
                motion = WallMotion::Wiggle { axis, amplitude, period };
                n += 4;
            }
            Some("shear") => {
                let aw = need(cmd, words, n + 1, "shear dim")?;
                let axis = dim_of(aw)?;
                let v = parse_f64(need(cmd, words, n + 2, "shear velocity")?, "shear velocity")?;
                if let PrimitiveWall::LammpsPlanes { axis: a, .. } = shape {
                    if a == axis {
                        return Err(Error::deck(aw.span, "invalid shear direction for fix wall/gran"));
                    }
                }
                motion = WallMotion::Shear { axis, v };
                n += 3;
            }
            _ => {}
        }
        Ok((shape, motion, n))
    }

    /// The shape's own axis (plane normal or cylinder axis).
    pub fn axis(&self) -> usize {
        match *self {
            PrimitiveWall::Plane { axis, .. } | PrimitiveWall::Cylinder { axis, .. } | PrimitiveWall::LammpsPlanes { axis, .. } => axis,
            PrimitiveWall::LammpsZCylinder { .. } => 2,
        }
    }

    /// Contact of a sphere (`p`, `r`) with the wall displaced by `shift`
    /// along the wall's own axis (0 for static walls; use
    /// [`WallMotion::shift`]): `(delta > 0 overlap, unit normal from the wall
    /// into the particle, contact point on the wall)`.
    pub fn contact(&self, p: V3, r: f64, shift: f64) -> Option<(f64, V3, V3)> {
        let unit = |d: usize, s: f64| {
            let mut v = V3::zeros();
            v[d] = s;
            v
        };
        match *self {
            PrimitiveWall::Plane { axis, pos } => {
                let pos = pos + shift;
                let d = p[axis] - pos;
                let delta = r - d.abs();
                if delta <= 0.0 {
                    return None;
                }
                let mut q = p;
                q[axis] = pos;
                let s = if d >= 0.0 { 1.0 } else { -1.0 };
                Some((delta, unit(axis, s), q))
            }
            PrimitiveWall::Cylinder { axis, radius, c1, c2 } => {
                let (d1, d2) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut radial = V3::zeros();
                radial[d1] = p[d1] - c1;
                radial[d2] = p[d2] - c2;
                let rho = radial.norm();
                let delta = r - (rho - radius).abs();
                if delta <= 0.0 || rho == 0.0 {
                    return None;
                }
                let u = radial / rho;
                let q = p - radial + u * radius;
                let n = if rho > radius { u } else { -u };
                Some((delta, n, q))
            }
            PrimitiveWall::LammpsPlanes { axis, lo, hi } => {
                let del1 = lo.map(|l| p[axis] - (l + shift)).unwrap_or(f64::INFINITY);
                let del2 = hi.map(|h| (h + shift) - p[axis]).unwrap_or(f64::INFINITY);
                let (dx, s) = if del1 < del2 { (del1, 1.0) } else { (del2, -1.0) };
                if !dx.is_finite() {
                    return None;
                }
                let delta = r - dx.abs();
                if delta <= 0.0 {
                    return None;
                }
                let mut q = p;
                q[axis] = p[axis] - s * dx;
                // normal is along (p - q); dx < 0 means the centre is beyond the wall
                let n = if dx >= 0.0 { unit(axis, s) } else { unit(axis, -s) };
                Some((delta, n, q))
            }
            PrimitiveWall::LammpsZCylinder { radius } => {
                let radial = V3::new(p.x, p.y, 0.0);
                let rho = radial.norm();
                let delr = radius - rho;
                if delr > r || rho == 0.0 {
                    return None;
                }
                let delta = r - delr.abs();
                if delta <= 0.0 {
                    return None;
                }
                let u = radial / rho;
                let q = V3::new(u.x * radius, u.y * radius, p.z);
                let n = if delr >= 0.0 { -u } else { u };
                Some((delta, n, q))
            }
        }
    }
}

impl WallMotion {
    /// Displacement of the wall along its own axis `wall_axis` at time t
    /// (LAMMPS: only a wiggle along the wall's own axis moves it).
    pub fn shift(&self, wall_axis: usize, t: f64) -> f64 {
        match *self {
            WallMotion::Wiggle { axis, amplitude, period } if axis == wall_axis => {
                let w = 2.0 * std::f64::consts::PI / period;
                amplitude - amplitude * (w * t).cos()
            }
            _ => 0.0,
        }
    }
    /// Wall velocity at time t.
    pub fn velocity(&self, t: f64) -> V3 {
        let mut v = V3::zeros();
        match *self {
            WallMotion::None => {}
            WallMotion::Wiggle { axis, amplitude, period } => {
                let w = 2.0 * std::f64::consts::PI / period;
                v[axis] = amplitude * w * (w * t).sin();
            }
            WallMotion::Shear { axis, v: s } => v[axis] = s,
        }
        v
    }
}
