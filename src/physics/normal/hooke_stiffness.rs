//! LIGGGHTS `model hooke/stiffness` (source `normal_model_hooke_stiffness.h`):
//! user `kn`, `kt`; damping gamma_n = m* gamman, gamma_t = m* gammat, or with
//! `absolute_damping on` the properties `gamman_abs`, `gammat_abs` used as
//! they are. F_n = kn delta_n - gamma_n v_n.

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, Contact, ContactL, ContactOut, NormalLaw, OutL, PairParams};

/// LIGGGHTS `model hooke/stiffness`. Reads `kn`, `kt`, `gamma_n`, `gamma_t`
/// (holding `gamman`/`gammat`, or `gamman_abs`/`gammat_abs` when
/// `absolute_damping`), `tangential_damping`, `limit_damping`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsHookeStiffness {
    /// `absolute_damping on`: damping constants are not multiplied by m*.
    pub absolute_damping: bool,
}

impl NormalLaw for LiggghtsHookeStiffness {
    const HISTORY: usize = 0;
    const LANES: bool = true;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.normal_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        let delta_n = c.delta;
        let (kn, kt) = (p.get(|q| q.kn), p.get(|q| q.kt));
        let scale = if self.absolute_damping { R::splat(1.0) } else { c.m_eff };
        let gamma_n = scale * p.get(|q| q.gamma_n);
        let gamma_t = scale * p.get(|q| q.gamma_t) * p.get(|q| q.tangential_damping);
        super::store_normal_lanes(out, kn * delta_n, -gamma_n * c.vn, p.get(|q| q.limit_damping));
        out.kn = kn;
        out.kt = kt;
        out.a = (c.r_eff * delta_n).sqrt();
        out.gamma_n = gamma_n;
        out.gamma_t = gamma_t;
    }
}
