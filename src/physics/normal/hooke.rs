//! LIGGGHTS `model hooke` (source `normal_model_hooke.h`, doc
//! `gran_model_hooke.txt`): a linear spring whose stiffness is chosen so that
//! a Hertzian contact at the `characteristicVelocity` V has the same maximum
//! overlap:
//! k_n = 16/15 sqrt(R*) Y* (15 m* V^2 / (16 sqrt(R*) Y*))^(1/5),
//! gamma_n = sqrt(4 m* k_n / (1 + (pi / ln e)^2)) (= 2 sqrt(m* k_n) |beta|),
//! k_t = k_n (2/7 k_n with `ktToKnUser on`), gamma_t = gamma_n
//! (0 with `tangential_damping off`); F_n = k_n delta_n - gamma_n v_n.
//! The `viscous` (Stokes-number restitution) option is not implemented.

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, Contact, ContactL, ContactOut, NormalLaw, OutL, PairParams};

/// LIGGGHTS `model hooke`. Reads `y_eff`, `beta`, `char_vel`,
/// `tangential_damping`, `limit_damping` from [`PairParams`].
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsHooke {
    /// `ktToKnUser on`: k_t = 2/7 k_n instead of k_t = k_n.
    pub kt_to_kn: bool,
}

/// LIGGGHTS hooke stiffness k_n from Y*, R*, m* and the characteristic
/// velocity V (doc `gran_model_hooke.txt`).
#[inline(always)]
pub fn liggghts_hooke_kn<R: Real>(y_eff: R, r_eff: R, m_eff: R, char_vel: R) -> R {
    let sqrt_r = r_eff.sqrt();
    sqrt_r * (16.0 / 15.0) * y_eff * (m_eff * 15.0 * char_vel * char_vel / (sqrt_r * 16.0 * y_eff)).powf(0.2)
}

impl NormalLaw for LiggghtsHooke {
    const HISTORY: usize = 0;
    const LANES: bool = true;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.normal_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        let delta_n = c.delta;
        let k_n = liggghts_hooke_kn(p.get(|q| q.y_eff), c.r_eff, c.m_eff, p.get(|q| q.char_vel));
        // LIGGGHTS multiplies by the literal 0.285714286.
        let k_t = if self.kt_to_kn { k_n * 0.285714286 } else { k_n };
        let gamma_n = (c.m_eff * k_n).sqrt() * 2.0 * p.get(|q| q.beta).abs();
        let gamma_t = gamma_n * p.get(|q| q.tangential_damping);
        super::store_normal_lanes(out, k_n * delta_n, -gamma_n * c.vn, p.get(|q| q.limit_damping));
        out.kn = k_n;
        out.kt = k_t;
        out.a = (c.r_eff * delta_n).sqrt();
        out.gamma_n = gamma_n;
        out.gamma_t = gamma_t;
    }
}
