//! demx `model hertz/viscoelastic`: the paper's normal law (Elekes & Parteli
//! 2021, PNAS 118 e2107965118, Materials and Methods Eqs. 10 and 12), Hertz
//! elasticity with Brilliantov et al. (1996) viscoelastic damping:
//!
//! F_n = max(0, k_n delta^{3/2} + 3/2 A_n k_n sqrt(delta) d(delta)/dt)   (Eq. 10)
//!
//! with k_n = 4/3 Y* sqrt(R*) and k_t = 8 G* sqrt(R*) (Eq. 12). For identical
//! materials the LIGGGHTS mixing rules give Y* = Y / (2 (1 - nu^2)) and
//! G* = Y / (4 (2 - nu)(1 + nu)), so k_n = 2Y/(3(1-nu^2)) sqrt(R*) and
//! k_t = 4G/(2-nu) sqrt(R*) with G = Y/(2+2nu): exactly Eq. 12. Unequal radii
//! use R* = R_i R_j / (R_i + R_j) (the paper's d/4 for equal spheres); a wall
//! has infinite radius and mass, so R* = R_i and m* = m_i.
//!
//! A_n is not a deck input: `fill_table` turns the restitution coefficient at
//! a reference impact speed into the Müller-Pöschel beta
//! (`PairParams::beta`, see [`crate::physics::mixing::mp_beta`]) and this law
//! computes A_n = 2 beta / (3 (k_n/m*)^{2/5}) once per contact (it depends on
//! the pair's radii and masses), caching it in its history slot.
//!
//! The law also hands the paper's tangential and rolling laws their
//! current stiffness k_t sqrt(delta) (`out.kt`) and the tangential damping
//! A_t sqrt(delta) with A_t = 3/2 A_n k_n (`out.gamma_t`, Eq. 11).

use crate::physics::lanes::{Coeffs, Mask, Real};
use crate::physics::mixing::viscoelastic_a_n;
use crate::physics::{on_one, Contact, ContactL, ContactOut, NormalLaw, OutL, PairParams};

/// The paper's Hertz + Brilliantov normal law. Reads `y_eff`, `g_eff` and
/// `beta` (Müller-Pöschel beta from the reference restitution). History: the
/// contact's A_n (1 value, computed at first touch).
#[derive(Clone, Copy, Debug, Default)]
pub struct PaperViscoelastic;

impl NormalLaw for PaperViscoelastic {
    const HISTORY: usize = 1;
    /// A_n, a coefficient of the pair (from m* and R*, symmetric in i and
    /// j), is the same from both sides: +1.
    const FLIP: &'static [f64] = &[1.0];
    const LANES: bool = true;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.normal_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, hist: &mut [R], out: &mut OutL<R>) {
        let sqrt_r = c.r_eff.sqrt();
        // Eq. 12
        let k_n = p.get(|q| q.y_eff) * (4.0 / 3.0) * sqrt_r;
        let k_t = p.get(|q| q.g_eff) * 8.0 * sqrt_r;
        // A_n at first touch (a new contact's history is zero); the power is
        // costly, so a batch without a new contact skips it
        let zero = R::splat(0.0);
        let beta = p.get(|q| q.beta);
        let fresh = hist[0].equal(zero).and(beta.ne(zero));
        if fresh.any() {
            hist[0] = R::select(fresh, viscoelastic_a_n(beta, k_n, c.m_eff), hist[0]);
        }
        let a_n = hist[0];
        let sqrt_delta = c.delta.sqrt();
        // Eq. 10 with d(delta)/dt = -vn; the max(0, .) becomes the damping clamp
        let gamma_n = a_n * 1.5 * k_n * sqrt_delta;
        super::store_normal_lanes(out, k_n * c.delta * sqrt_delta, -gamma_n * c.vn, R::splat(1.0));
        out.kn = k_n * sqrt_delta;
        out.kt = k_t * sqrt_delta;
        out.a = (c.r_eff * c.delta).sqrt();
        out.gamma_n = gamma_n;
        // Eq. 11: A_t sqrt(delta) with A_t = 3/2 A_n k_n
        out.gamma_t = gamma_n;
    }
}
