//! `lattice STYLE scale keyword values ...` and the lattice points of
//! `create_atoms TYPE box|region ID`.
//!
//! Transformation (LAMMPS `Lattice::lattice2box`, same floating-point order):
//! `x_box = Rrow * (scale * P * x_lat) + (xlattice, ylattice, zlattice) * origin`,
//! with P the primitive vectors a1 a2 a3 as columns and Rrow the normalised
//! `orient` vectors as rows. In units other than lj `scale` is the lattice
//! constant; in lj it is the reduced density and the constant is
//! `(nbasis / (V_cell * rho*))^(1/dim)`. Spacings are the extent of the
//! transformed unit cell, or `spacing` values times scale.
//!
//! create_atoms order on one processor: loop k (z cells), then j, then i,
//! then the basis atoms m, ascending; a point is created when it is in the
//! region (if any) and in `[lo, hi)` in every dimension, where for a periodic
//! dimension lo is lowered by `eps` and hi lowered by `2 eps`,
//! `eps = 1e-6 * (hi - lo)` (so points exactly on the periodic upper face
//! are not created, points on the lower face are). In 2d LAMMPS 29 Sep 2021
//! does not restrict k: with a z extent larger than the z spacing it
//! creates several z layers (checked with `lmp`); this is reproduced.
//! Shrink-wrapped boundaries: LAMMPS `create_box` has already widened the box
//! by 1e-4 of its length at each shrink-wrapped face, which is why points on
//! the upper face are then created; pass that widened box.

use super::{need, parse_f64, parse_i64};
use crate::error::{did_you_mean, Error, Result};
use crate::physics::V3;
use crate::script::Command;

/// Lattice style keyword.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LatticeStyle {
    /// `none`: only a length scale for `units lattice`.
    None,
    /// Simple cubic.
    Sc,
    /// Body-centred cubic.
    Bcc,
    /// Face-centred cubic.
    Fcc,
    /// Hexagonal close-packed.
    Hcp,
    /// Diamond.
    Diamond,
    /// 2d square.
    Sq,
    /// 2d square with a centred atom.
    Sq2,
    /// 2d hexagonal.
    Hex,
    /// User a1 a2 a3 and basis.
    Custom,
}

/// A parsed lattice.
#[derive(Clone, Debug)]
pub struct Lattice {
    /// Style.
    pub style: LatticeStyle,
    /// Lattice constant in box length units (after the lj conversion).
    pub scale: f64,
    /// Basis atoms in fractional cell coordinates, in definition order.
    pub basis: Vec<[f64; 3]>,
    /// Primitive vectors a1, a2, a3.
    pub a: [[f64; 3]; 3],
    /// Orientation vectors (integers) for x, y, z.
    pub orient: [[i64; 3]; 3],
    /// Normalised orient vectors as rows.
    pub rotaterow: [[f64; 3]; 3],
    /// Origin in fractions of the spacings.
    pub origin: [f64; 3],
    /// Lattice spacings (xlattice, ylattice, zlattice), box length units.
    pub spacing: V3,
}

const STYLES: [&str; 10] = ["none", "sc", "bcc", "fcc", "hcp", "diamond", "sq", "sq2", "hex", "custom"];

/// Parse a `lattice` command. `units_lj` selects the reduced-density meaning
/// of scale; `dimension` is 2 or 3.
pub fn parse_lattice(cmd: &Command, units_lj: bool, dimension: usize) -> Result<Lattice> {
    let args = cmd.args();
    let sw = need(cmd, args, 0, "lattice style")?;
    let style = match sw.text.as_str() {
        "none" => LatticeStyle::None,
        "sc" => LatticeStyle::Sc,
        "bcc" => LatticeStyle::Bcc,
        "fcc" => LatticeStyle::Fcc,
        "hcp" => LatticeStyle::Hcp,
        "diamond" => LatticeStyle::Diamond,
        "sq" => LatticeStyle::Sq,
        "sq2" => LatticeStyle::Sq2,
        "hex" => LatticeStyle::Hex,
        "custom" => LatticeStyle::Custom,
        s => {
            let e = Error::deck(sw.span, format!("unknown lattice style '{s}'"));
            return Err(match did_you_mean(s, STYLES) {
                Some(h) => e.with_hint(format!("did you mean '{h}'?")),
                None => e,
            });
        }
    };
    let scw = need(cmd, args, 1, "lattice scale")?;
    let scale_in = parse_f64(scw, "lattice scale")?;
    if scale_in <= 0.0 {
        return Err(Error::deck(scw.span, "lattice scale must be > 0"));
    }
    let ident = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if style == LatticeStyle::None {
        if args.len() != 2 {
            return Err(Error::deck(args[2].span, "lattice none takes exactly one argument"));
        }
        return Ok(Lattice {
            style,
            scale: scale_in,
            basis: Vec::new(),
            a: ident,
            orient: [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
            rotaterow: ident,
            origin: [0.0; 3],
            spacing: V3::repeat(scale_in),
        });
    }
    let is3d = matches!(style, LatticeStyle::Sc | LatticeStyle::Bcc | LatticeStyle::Fcc | LatticeStyle::Hcp | LatticeStyle::Diamond);
    let is2d = matches!(style, LatticeStyle::Sq | LatticeStyle::Sq2 | LatticeStyle::Hex);
    if (dimension == 2 && is3d) || (dimension == 3 && is2d) {
        return Err(Error::deck(sw.span, "lattice style incompatible with simulation dimension"));
    }
    let mut basis: Vec<[f64; 3]> = match style {
        LatticeStyle::Sc | LatticeStyle::Sq => vec![[0.0, 0.0, 0.0]],
        LatticeStyle::Bcc => vec![[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]],
        LatticeStyle::Fcc => vec![[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]],
        LatticeStyle::Hcp => vec![[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 5.0 / 6.0, 0.5], [0.0, 1.0 / 3.0, 0.5]],
        LatticeStyle::Sq2 | LatticeStyle::Hex => vec![[0.0, 0.0, 0.0], [0.5, 0.5, 0.0]],
        LatticeStyle::Diamond => vec![
            [0.0, 0.0, 0.0],
            [0.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
            [0.5, 0.5, 0.0],
            [0.25, 0.25, 0.25],
            [0.25, 0.75, 0.75],
            [0.75, 0.25, 0.75],
            [0.75, 0.75, 0.25],
        ],
        _ => Vec::new(),
    };
    let mut a = ident;
    if matches!(style, LatticeStyle::Hex | LatticeStyle::Hcp) {
        a[1][1] = 3.0f64.sqrt();
    }
    if style == LatticeStyle::Hcp {
        a[2][2] = (8.0f64 / 3.0).sqrt();
    }
    let mut origin = [0.0; 3];
    let mut orient = [[1i64, 0, 0], [0, 1, 0], [0, 0, 1]];
    let mut spacing_in: Option<V3> = None;
    let mut i = 2;
    while i < args.len() {
        let w = &args[i];
        match w.text.as_str() {
            "origin" => {
                for d in 0..3 {
                    let v = need(cmd, args, i + 1 + d, "origin x y z")?;
                    origin[d] = parse_f64(v, "lattice origin")?;
                    if !(0.0..1.0).contains(&origin[d]) {
                        return Err(Error::deck(v.span, "lattice origin must be in [0, 1)"));
                    }
                }
                i += 4;
            }
            "orient" => {
                let dw = need(cmd, args, i + 1, "orient x|y|z i j k")?;
                let d = match dw.text.as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    _ => return Err(Error::deck(dw.span, "lattice orient dimension must be x, y or z")),
                };
                for k in 0..3 {
                    orient[d][k] = parse_i64(need(cmd, args, i + 2 + k, "orient i j k")?, "orient component")?;
                }
                i += 5;
            }
            "spacing" => {
                let v = super::need_v3(cmd, args, i + 1, "spacing x y z")?;
                if v.iter().any(|x| *x <= 0.0) {
                    return Err(Error::deck(w.span, "lattice spacings must be > 0"));
                }
                spacing_in = Some(v);
                i += 4;
            }
            "a1" | "a2" | "a3" | "basis" => {
                if style != LatticeStyle::Custom {
                    return Err(Error::deck(w.span, format!("lattice {} is only valid for style custom", w.text)));
                }
                let v = super::need_v3(cmd, args, i + 1, &w.text)?;
                match w.text.as_str() {
                    "a1" => a[0] = [v.x, v.y, v.z],
                    "a2" => a[1] = [v.x, v.y, v.z],
                    "a3" => a[2] = [v.x, v.y, v.z],
                    _ => {
                        if v.iter().any(|x| !(0.0..1.0).contains(x)) {
                            return Err(Error::deck(w.span, "lattice basis coordinates must be in [0, 1)"));
                        }
                        basis.push([v.x, v.y, v.z]);
                    }
                }
                i += 4;
            }
            "triclinic/general" => return Err(Error::unsupported(w.span, "lattice triclinic/general")),
            _ => {
                let e = Error::deck(w.span, format!("unknown lattice keyword '{}'", w.text));
                return Err(match did_you_mean(&w.text, ["origin", "orient", "spacing", "a1", "a2", "a3", "basis"]) {
                    Some(h) => e.with_hint(format!("did you mean '{h}'?")),
                    None => e,
                });
            }
        }
    }
    if basis.is_empty() {
        return Err(Error::deck(sw.span, "no basis atoms in lattice"));
    }
    let dot = |u: [i64; 3], v: [i64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    if dot(orient[0], orient[1]) != 0 || dot(orient[1], orient[2]) != 0 || dot(orient[0], orient[2]) != 0 {
        return Err(Error::deck(cmd.span, "lattice orient vectors are not orthogonal"));
    }
    let (ox, oy, oz) = (orient[0], orient[1], orient[2]);
    let cx = [ox[1] * oy[2] - ox[2] * oy[1], ox[2] * oy[0] - ox[0] * oy[2], ox[0] * oy[1] - ox[1] * oy[0]];
    if dot(cx, oz) <= 0 {
        return Err(Error::deck(cmd.span, "lattice orient vectors are not right-handed"));
    }
    let av = |k: usize| V3::new(a[k][0], a[k][1], a[k][2]);
    if av(0).cross(&av(1)).norm() == 0.0 || av(1).cross(&av(2)).norm() == 0.0 || av(0).cross(&av(2)).norm() == 0.0 {
        return Err(Error::deck(cmd.span, "lattice primitive vectors are collinear"));
    }
    if dimension == 2 {
        if origin[2] != 0.0 || a[0][2] != 0.0 || a[1][2] != 0.0 || a[2][0] != 0.0 || a[2][1] != 0.0 {
            return Err(Error::deck(cmd.span, "lattice is not compatible with a 2d simulation"));
        }
        if ox[2] != 0 || oy[2] != 0 || oz[0] != 0 || oz[1] != 0 || basis.iter().any(|b| b[2] != 0.0) {
            return Err(Error::deck(cmd.span, "lattice is not compatible with a 2d simulation"));
        }
    }
    let scale = if units_lj {
        let volume = av(0).dot(&av(1).cross(&av(2))).abs();
        (basis.len() as f64 / volume / scale_in).powf(1.0 / dimension as f64)
    } else {
        scale_in
    };
    let mut rotaterow = [[0.0; 3]; 3];
    for d in 0..3 {
        let o = orient[d];
        let len = ((o[0] * o[0] + o[1] * o[1] + o[2] * o[2]) as f64).sqrt();
        if len == 0.0 {
            return Err(Error::deck(cmd.span, "zero-length lattice orient vector"));
        }
        for k in 0..3 {
            rotaterow[d][k] = o[k] as f64 / len;
        }
    }
    let mut lat = Lattice { style, scale, basis, a, orient, rotaterow, origin, spacing: V3::zeros() };
    lat.spacing = match spacing_in {
        Some(s) => s * scale,
        None => {
            let mut lo = V3::repeat(f64::INFINITY);
            let mut hi = V3::repeat(f64::NEG_INFINITY);
            for c in 0..8 {
                let p = lat.cell_to_box_no_origin([(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]);
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
            hi - lo
        }
    };
    Ok(lat)
}

impl Lattice {
    /// Lattice spacings (x, y, z), the length scale of `units lattice`.
    pub fn spacing(&self) -> V3 {
        self.spacing
    }

    fn cell_to_box_no_origin(&self, x: [f64; 3]) -> V3 {
        let p = &self.a;
        // primitive[r][c] = a_c[r]
        let mut x1 = p[0][0] * x[0] + p[1][0] * x[1] + p[2][0] * x[2];
        let mut y1 = p[0][1] * x[0] + p[1][1] * x[1] + p[2][1] * x[2];
        let mut z1 = p[0][2] * x[0] + p[1][2] * x[1] + p[2][2] * x[2];
        x1 *= self.scale;
        y1 *= self.scale;
        z1 *= self.scale;
        let r = &self.rotaterow;
        V3::new(r[0][0] * x1 + r[0][1] * y1 + r[0][2] * z1, r[1][0] * x1 + r[1][1] * y1 + r[1][2] * z1, r[2][0] * x1 + r[2][1] * y1 + r[2][2] * z1)
    }

    /// Lattice coordinates -> box coordinates (LAMMPS `lattice2box`).
    pub fn lattice_to_box(&self, x: [f64; 3]) -> V3 {
        let v = self.cell_to_box_no_origin(x);
        V3::new(v.x + self.spacing.x * self.origin[0], v.y + self.spacing.y * self.origin[1], v.z + self.spacing.z * self.origin[2])
    }

    /// Box coordinates -> lattice coordinates (inverse transform, used for loop bounds).
    pub fn box_to_lattice(&self, x: V3) -> Option<V3> {
        let y = x - self.spacing.component_mul(&V3::from(self.origin));
        let r = nalgebra::Matrix3::from_fn(|i, j| self.rotaterow[i][j]);
        let p = nalgebra::Matrix3::from_fn(|i, j| self.a[j][i]) * self.scale;
        let m = r * p;
        m.try_inverse().map(|inv| inv * y)
    }

    /// Points of `create_atoms TYPE box` (or `region ID` when `filter` is
    /// given: the region's `contains`) in the exact LAMMPS one-processor
    /// order, with the basis index (0-based) of each point. `periodic` gives
    /// the periodicity of x, y, z. Errors for `lattice none` and when more
    /// than 1e8 lattice sites would be visited.
    pub fn create_points(&self, box_lo: V3, box_hi: V3, periodic: [bool; 3], filter: Option<&dyn Fn(V3) -> bool>) -> Result<Vec<(V3, usize)>> {
        if self.style == LatticeStyle::None || self.basis.is_empty() {
            return Err(Error::runtime("cannot create atoms with undefined lattice"));
        }
        let mut sublo = box_lo;
        let mut subhi = box_hi;
        for d in 0..3 {
            if periodic[d] {
                let eps = (box_hi[d] - box_lo[d]) * 1.0e-6;
                sublo[d] -= eps;
                subhi[d] -= 2.0 * eps;
            }
        }
        // loop bounds from the lattice coordinates of the 8 box corners
        let mut lmin = V3::repeat(f64::INFINITY);
        let mut lmax = V3::repeat(f64::NEG_INFINITY);
        for c in 0..8 {
            let p = V3::new(
                if c & 1 == 0 { box_lo.x } else { box_hi.x },
                if c & 2 == 0 { box_lo.y } else { box_hi.y },
                if c & 4 == 0 { box_lo.z } else { box_hi.z },
            );
            let l = self.box_to_lattice(p).ok_or_else(|| Error::runtime("singular lattice transform"))?;
            lmin = lmin.inf(&l);
            lmax = lmax.sup(&l);
        }
        if lmin.iter().chain(lmax.iter()).any(|v| !v.is_finite() || v.abs() > 1e9) {
            return Err(Error::runtime("create_atoms: lattice too fine for the box"));
        }
        let lo: Vec<i64> = lmin.iter().map(|v| v.floor() as i64 - 1).collect();
        let hi: Vec<i64> = lmax.iter().map(|v| v.ceil() as i64 + 1).collect();
        let (klo, khi) = (lo[2], hi[2]);
        let sites = (hi[0] - lo[0] + 1) as f64 * (hi[1] - lo[1] + 1) as f64 * (khi - klo + 1) as f64 * self.basis.len() as f64;
        if sites > 1e8 {
            return Err(Error::runtime(format!("create_atoms would visit {sites:.3e} lattice sites (limit 1e8)")));
        }
        let mut out = Vec::new();
        for k in klo..=khi {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    for (m, b) in self.basis.iter().enumerate() {
                        let x = self.lattice_to_box([i as f64 + b[0], j as f64 + b[1], k as f64 + b[2]]);
                        if let Some(f) = filter {
                            if !f(x) {
                                continue;
                            }
                        }
                        if (0..3).any(|d| x[d] < sublo[d] || x[d] >= subhi[d]) {
                            continue;
                        }
                        out.push((x, m));
                    }
                }
            }
        }
        Ok(out)
    }
}
