//! demx `cohesion vdw`: the paper's Hamaker van der Waals attraction
//! (Elekes & Parteli 2021, Eqs. 13-14), acting in contact and across gaps up
//! to D_max:
//!
//! F = A_H R* / (6 D_min^2)             if delta > 0,
//! F = A_H R* / (6 (D_min - delta)^2)   if -D_max <= delta <= 0,
//! F = 0                                if delta < -D_max,
//!
//! attractive, with A_H = 24 pi D_min^2 gamma (Eq. 14, gamma the surface
//! energy) and R* = R_i R_j / (R_i + R_j) (Derjaguin; d/4 for equal spheres).
//! Walls are cohesionless (paper, Model Parameters): no force on wall
//! contacts. The force does not enter the Coulomb or rolling caps (they use
//! the contact force F^c_n only).

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, CohesionLaw, Contact, ContactL, ContactOut, OutL, PairParams};

/// Hamaker van der Waals attraction with D_min and cut-off D_max. Reads
/// `hamaker` (A_H), `d_min`, `d_max`; the scene sets `extra_range = d_max` so
/// the neighbour list includes pairs up to D_max apart.
#[derive(Clone, Copy, Debug, Default)]
pub struct Hamaker;

impl CohesionLaw for Hamaker {
    const HISTORY: usize = 0;
    const NONCONTACT: bool = true;
    const LANES: bool = true;
    #[inline(always)]
    fn cohesion(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.cohesion_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn cohesion_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        if c.wall {
            return;
        }
        let zero = R::splat(0.0);
        let (d_min, d_max) = (p.get(|q| q.d_min), p.get(|q| q.d_max));
        // Eq. 13: D_min in contact, the gap D_min - delta across it, nothing
        // beyond D_max
        let dist = R::select(c.delta.gt(zero), d_min, d_min - c.delta);
        let f = p.get(|q| q.hamaker) * c.r_eff / (dist * 6.0 * dist);
        out.fn_coh -= R::select(c.delta.lt(-d_max), zero, f);
    }
}
