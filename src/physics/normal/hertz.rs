//! LIGGGHTS `model hertz` (source `normal_model_hertz.h`, doc
//! `gran_model_hertz.txt`): Hertz stiffness with the Tsuji-type damping that
//! gives a velocity-independent restitution coefficient.
//!
//! With s = sqrt(R* delta_n): S_n = 2 Y* s, S_t = 8 G* s, k_n = 4/3 Y* s,
//! k_t = S_t, gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*),
//! gamma_t = -2 sqrt(5/6) beta sqrt(S_t m*) (0 with `tangential_damping off`),
//! F_n = k_n delta_n - gamma_n v_n.

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, Contact, ContactL, ContactOut, NormalLaw, OutL, PairParams};

/// sqrt(5/6), the LIGGGHTS Hertz damping prefactor.
pub(crate) const SQRT_FIVE_SIXTHS: f64 = 0.912_870_929_175_276_9;

/// LIGGGHTS `model hertz`. Reads `y_eff`, `g_eff`, `beta`,
/// `tangential_damping` (1 = on, the LIGGGHTS default) and `limit_damping`
/// (`limitForce`) from [`PairParams`].
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsHertz;

impl NormalLaw for LiggghtsHertz {
    const HISTORY: usize = 0;
    const LANES: bool = true;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.normal_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        let delta_n = c.delta;
        let (y_eff, g_eff, beta) = (p.get(|q| q.y_eff), p.get(|q| q.g_eff), p.get(|q| q.beta));
        let s = (c.r_eff * delta_n).sqrt();
        let s_n = y_eff * 2.0 * s;
        let s_t = g_eff * 8.0 * s;
        let k_n = y_eff * (4.0 / 3.0) * s;
        let k_t = s_t;
        let gamma_n = beta * (-2.0 * SQRT_FIVE_SIXTHS) * (s_n * c.m_eff).sqrt();
        let gamma_t = beta * (-2.0 * SQRT_FIVE_SIXTHS) * (s_t * c.m_eff).sqrt() * p.get(|q| q.tangential_damping);
        super::store_normal_lanes(out, k_n * delta_n, -gamma_n * c.vn, p.get(|q| q.limit_damping));
        out.kn = k_n;
        out.kt = k_t;
        out.a = s;
        out.gamma_n = gamma_n;
        out.gamma_t = gamma_t;
    }
}
