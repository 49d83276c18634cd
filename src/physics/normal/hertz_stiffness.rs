//! LIGGGHTS `model hertz/stiffness` (source `normal_model_hertz_stiffness.h`):
//! user constants `kn`, `kt`, `gamman`, `gammat` (fix property/global
//! peratomtypepair), all scaled by s = sqrt(R* delta_n), damping also by m*:
//! k_n = s kn, k_t = s kt, gamma_n = s m* gamman, gamma_t = s m* gammat;
//! F_n = k_n delta_n - gamma_n v_n (the LAMMPS `gran/hertz/history` form).

use crate::physics::{Contact, ContactOut, NormalLaw, PairParams};

/// LIGGGHTS `model hertz/stiffness`. Reads `kn`, `kt`, `gamma_n`, `gamma_t`,
/// `tangential_damping`, `limit_damping` from [`PairParams`].
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsHertzStiffness;

impl NormalLaw for LiggghtsHertzStiffness {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let delta_n = c.delta;
        let s = (c.r_eff * delta_n).sqrt();
        let k_n = s * p.kn;
        let k_t = s * p.kt;
        let gamma_n = s * c.m_eff * p.gamma_n;
        let gamma_t = s * c.m_eff * p.gamma_t * p.tangential_damping;
        super::store_normal(out, k_n * delta_n, -gamma_n * c.vn, p.limit_damping);
        out.kn = k_n;
        out.kt = k_t;
        out.a = s;
        out.gamma_n = gamma_n;
        out.gamma_t = gamma_t;
    }
}
