//! LIGGGHTS `model hooke/stiffness` (source `normal_model_hooke_stiffness.h`):
//! user `kn`, `kt`; damping gamma_n = m* gamman, gamma_t = m* gammat, or with
//! `absolute_damping on` the properties `gamman_abs`, `gammat_abs` used as
//! they are. F_n = kn delta_n - gamma_n v_n.

use crate::physics::{Contact, ContactOut, NormalLaw, PairParams};

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
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let delta_n = c.delta;
        let scale = if self.absolute_damping { 1.0 } else { c.m_eff };
        let gamma_n = scale * p.gamma_n;
        let gamma_t = scale * p.gamma_t * p.tangential_damping;
        super::store_normal(out, p.kn * delta_n, -gamma_n * c.vn, p.limit_damping);
        out.kn = p.kn;
        out.kt = p.kt;
        out.a = (c.r_eff * delta_n).sqrt();
        out.gamma_n = gamma_n;
        out.gamma_t = gamma_t;
    }
}
