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

use crate::physics::mixing::viscoelastic_a_n;
use crate::physics::{Contact, ContactOut, NormalLaw, PairParams};

/// The paper's Hertz + Brilliantov normal law. Reads `y_eff`, `g_eff` and
/// `beta` (Müller-Pöschel beta from the reference restitution). History: the
/// contact's A_n (1 value, computed at first touch).
#[derive(Clone, Copy, Debug, Default)]
pub struct PaperViscoelastic;

impl NormalLaw for PaperViscoelastic {
    const HISTORY: usize = 1;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let sqrt_r = c.r_eff.sqrt();
        // Eq. 12
        let k_n = 4.0 / 3.0 * p.y_eff * sqrt_r;
        let k_t = 8.0 * p.g_eff * sqrt_r;
        let mut a_n = hist[0];
        if a_n == 0.0 && p.beta != 0.0 {
            a_n = viscoelastic_a_n(p.beta, k_n, c.m_eff);
            hist[0] = a_n;
        }
        let sqrt_delta = c.delta.sqrt();
        // Eq. 10 with d(delta)/dt = -vn; the max(0, .) becomes the damping clamp
        let gamma_n = 1.5 * a_n * k_n * sqrt_delta;
        super::store_normal(out, k_n * c.delta * sqrt_delta, -gamma_n * c.vn, 1.0);
        out.kn = k_n * sqrt_delta;
        out.kt = k_t * sqrt_delta;
        out.a = (c.r_eff * c.delta).sqrt();
        out.gamma_n = gamma_n;
        // Eq. 11: A_t sqrt(delta) with A_t = 3/2 A_n k_n
        out.gamma_t = gamma_n;
    }
}
