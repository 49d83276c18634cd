//! LIGGGHTS `tangential no_history` (source `tangential_model_no_history.h`):
//! viscous friction capped by Coulomb, F_t = -min(mu |F_n|, gamma_t |v_t|)
//! v_t / |v_t|, with v_t and the torque lever at R - delta/2.

use super::{add_tangential_torque, liggghts_levers, rel_tangential_velocity};
use crate::physics::{Contact, ContactOut, PairParams, TangentialLaw, V3};

/// LIGGGHTS `tangential no_history`. Reads `mu`; `out.gamma_t`,
/// `out.fn_for_friction` from the normal law.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsNoHistory;

/// Shared viscous-capped friction of LIGGGHTS no_history and LAMMPS
/// gran/hooke and granular linear_nohistory: `-min(f_cap, gamma |v|) v/|v|`.
#[inline(always)]
pub(crate) fn capped_viscous(vtr: &V3, gamma_t: f64, f_cap: f64) -> V3 {
    let vrel = vtr.norm();
    if vrel != 0.0 {
        let ft = f_cap.min(gamma_t * vrel) / vrel;
        -vtr * ft
    } else {
        V3::zeros()
    }
}

impl TangentialLaw for LiggghtsNoHistory {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let (cri, crj) = liggghts_levers(c);
        let vtr = rel_tangential_velocity(c, cri, crj);
        let ft = capped_viscous(&vtr, out.gamma_t, p.mu * out.fn_for_friction.abs());
        out.ft = ft;
        add_tangential_torque(c, &ft, cri, crj, out);
    }
}
