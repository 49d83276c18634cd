//! The simulation box and its boundaries (LAMMPS `boundary`, `create_box`).

use crate::physics::V3;

/// One side of the box along one axis (LAMMPS `boundary` letters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Side {
    /// `p`: periodic.
    Periodic,
    /// `f`: fixed; particles leaving are lost.
    Fixed,
    /// `s`: shrink-wrapped to the particles.
    Shrink,
    /// `m`: shrink-wrapped, but never smaller than the initial box.
    ShrinkMin,
}

impl Side {
    /// Parse one boundary letter.
    pub fn from_char(c: char) -> Option<Side> {
        Some(match c {
            'p' => Side::Periodic,
            'f' => Side::Fixed,
            's' => Side::Shrink,
            'm' => Side::ShrinkMin,
            _ => return None,
        })
    }
    /// The letter.
    pub fn letter(self) -> char {
        match self {
            Side::Periodic => 'p',
            Side::Fixed => 'f',
            Side::Shrink => 's',
            Side::ShrinkMin => 'm',
        }
    }
}

/// An orthogonal box.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Domain {
    /// Lower corner.
    pub lo: [f64; 3],
    /// Upper corner.
    pub hi: [f64; 3],
    /// Lower corner at creation (for `m` boundaries).
    pub lo0: [f64; 3],
    /// Upper corner at creation.
    pub hi0: [f64; 3],
    /// Boundary of the lower and upper side per axis.
    pub sides: [[Side; 2]; 3],
    /// 2 or 3.
    pub dimension: u8,
}

impl Domain {
    /// A box with the given corners and boundaries.
    pub fn new(lo: [f64; 3], hi: [f64; 3], sides: [[Side; 2]; 3], dimension: u8) -> Domain {
        Domain { lo, hi, lo0: lo, hi0: hi, sides, dimension }
    }
    /// Whether axis d is periodic.
    #[inline(always)]
    pub fn periodic(&self, d: usize) -> bool {
        self.sides[d][0] == Side::Periodic
    }
    /// Box length along d.
    #[inline(always)]
    pub fn len(&self, d: usize) -> f64 {
        self.hi[d] - self.lo[d]
    }
    /// Box lengths.
    pub fn lengths(&self) -> V3 {
        V3::new(self.len(0), self.len(1), self.len(2))
    }
    /// Volume (area in 2d).
    pub fn volume(&self) -> f64 {
        if self.dimension == 2 {
            self.len(0) * self.len(1)
        } else {
            self.len(0) * self.len(1) * self.len(2)
        }
    }
    /// Wrap a position into the periodic box, updating image counts
    /// (LAMMPS `Domain::remap`). A coordinate that cannot be wrapped (not
    /// finite, or so far out that its image count or its offset in the box
    /// is lost to rounding: `velocity set 1e300` with the guard off looped
    /// here forever) becomes infinite, so that the lost-atom check after the
    /// wrap takes the particle (LAMMPS loses such atoms: "Lost atoms").
    pub fn wrap(&self, x: &mut V3, image: &mut [i32; 3]) {
        for d in 0..3 {
            if !self.periodic(d) {
                continue;
            }
            let l = self.len(d);
            let periods = ((x[d] - self.lo[d]) / l).floor();
            if !periods.is_finite() || periods.abs() > 1e9 || (image[d] as f64 + periods).abs() > i32::MAX as f64 {
                x[d] = if x[d].is_nan() { x[d] } else { f64::INFINITY.copysign(x[d]) };
                continue;
            }
            if periods.abs() > 2.0 {
                // far out: one step instead of one subtraction per period
                x[d] -= periods * l;
                image[d] += periods as i32;
            }
            while x[d] < self.lo[d] {
                x[d] += l;
                image[d] -= 1;
            }
            while x[d] >= self.hi[d] {
                x[d] -= l;
                image[d] += 1;
                if x[d] < self.lo[d] {
                    // rounding right at the edge
                    x[d] = self.lo[d];
                }
            }
        }
    }
    /// Whether a position lies outside a fixed (`f`) side: such particles are lost.
    pub fn outside_fixed(&self, x: &V3) -> bool {
        for d in 0..3 {
            if self.sides[d][0] == Side::Fixed && x[d] < self.lo[d] {
                return true;
            }
            if self.sides[d][1] == Side::Fixed && x[d] >= self.hi[d] {
                return true;
            }
        }
        false
    }
    /// Shrink-wrap `s`/`m` sides to the particle extent (LAMMPS
    /// `Domain::reset_box`), with a small margin as LAMMPS does.
    pub fn shrink_wrap(&mut self, xs: &[V3]) {
        if xs.is_empty() {
            return;
        }
        for d in 0..3 {
            let (s0, s1) = (self.sides[d][0], self.sides[d][1]);
            if !matches!(s0, Side::Shrink | Side::ShrinkMin) && !matches!(s1, Side::Shrink | Side::ShrinkMin) {
                continue;
            }
            let mut mn = f64::INFINITY;
            let mut mx = f64::NEG_INFINITY;
            for x in xs {
                mn = mn.min(x[d]);
                mx = mx.max(x[d]);
            }
            // LAMMPS SMALL = 1e-4 of the box size as margin
            let margin = 1e-4 * (self.hi0[d] - self.lo0[d]).abs().max(1e-300);
            match s0 {
                Side::Shrink => self.lo[d] = mn - margin,
                Side::ShrinkMin => self.lo[d] = (mn - margin).min(self.lo0[d]),
                _ => {}
            }
            match s1 {
                Side::Shrink => self.hi[d] = mx + margin,
                Side::ShrinkMin => self.hi[d] = (mx + margin).max(self.hi0[d]),
                _ => {}
            }
        }
    }
    /// Boundary letters as LAMMPS prints them in dumps, e.g. `["pp", "pp", "ff"]`.
    pub fn boundary_strings(&self) -> [String; 3] {
        let f = |d: usize| format!("{}{}", self.sides[d][0].letter(), self.sides[d][1].letter());
        [f(0), f(1), f(2)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_counts_images() {
        let s = [[Side::Periodic; 2], [Side::Fixed; 2], [Side::Periodic; 2]];
        let d = Domain::new([0.0; 3], [1.0, 2.0, 3.0], s, 3);
        let mut x = V3::new(2.25, 1.5, -0.5);
        let mut im = [0; 3];
        d.wrap(&mut x, &mut im);
        assert_eq!(im, [2, 0, -1]);
        assert!((x - V3::new(0.25, 1.5, 2.5)).norm() < 1e-15);
        assert!(!d.outside_fixed(&x));
        assert!(d.outside_fixed(&V3::new(0.5, 2.0, 0.5)));
    }

    #[test]
    fn wrap_gives_up_on_what_it_cannot_wrap() {
        let d = Domain::new([0.0; 3], [0.01; 3], [[Side::Periodic; 2]; 3], 3);
        let mut im = [0; 3];
        let mut x = V3::new(1e300, f64::NEG_INFINITY, f64::NAN);
        d.wrap(&mut x, &mut im);
        assert_eq!((x.x, x.y), (f64::INFINITY, f64::NEG_INFINITY));
        assert!(x.z.is_nan());
        // far but wrappable: one step, and the image count follows
        let mut x = V3::new(1000.005, -999.995, 0.005);
        let mut im = [0; 3];
        d.wrap(&mut x, &mut im);
        assert_eq!(im, [100000, -100000, 0]);
        assert!((x - V3::new(0.005, 0.005, 0.005)).norm() < 1e-9, "{x:?}");
    }
}
