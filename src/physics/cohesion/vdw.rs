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
//! contacts.
//!
//! The caps: Eqs. 11 and 15 bound friction and rolling by the contact force
//! |F^c_n| alone, and so does demx by default (as LIGGGHTS 3.8's cohesion
//! models by default: `tangential_reduce off`). With `tangential_reduce on`
//! the caps use the net normal force |F^c_n + F^a_n|, as LIGGGHTS's cohesion
//! did unconditionally before 3.8 (its 2.x pair styles and early 3.x
//! cohesion models add the cohesive force to the normal force that the
//! tangential and rolling models read); the paper's code extended LIGGGHTS
//! of that time (its ref. 15). A bonded contact at rest then has a net
//! normal force near zero, so it can roll and slide while it holds.

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, CohesionLaw, Contact, ContactL, ContactOut, OutL, PairParams};

/// Hamaker van der Waals attraction with D_min and cut-off D_max. Reads
/// `hamaker` (A_H), `d_min`, `d_max`; the scene sets `extra_range = d_max` so
/// the neighbour list includes pairs up to D_max apart.
#[derive(Clone, Copy, Debug, Default)]
pub struct Hamaker {
    /// `tangential_reduce on`: the attraction lowers the normal force of the
    /// Coulomb and rolling caps (in contact only; apart pairs have no caps).
    pub tangential_reduce: bool,
}

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
        let f_coh = R::select(c.delta.lt(-d_max), zero, f);
        out.fn_coh -= f_coh;
        if self.tangential_reduce {
            out.fn_for_friction -= f_coh;
        }
    }
}
