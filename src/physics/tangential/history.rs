//! LIGGGHTS `tangential history` (source `tangential_model_history.h`):
//! Cundall-Strack spring with Coulomb cap on the elastic part only.
//!
//! xi += v_t dt; xi -= (xi . n) n (projection, no magnitude rescale);
//! F_el = -k_t xi; if k_t |xi| > mu |F_n|: F_t = F_el mu |F_n| / (k_t |xi|),
//! xi = -F_t / k_t, and no damping while sliding; else
//! F_t = F_el - gamma_t v_t. Relative velocity and torque use the
//! contact-point distance R - delta/2 of each sphere (`surface_model_default.h`).

use super::{add_tangential_torque, get3, liggghts_levers, put3, rel_tangential_velocity};
use crate::physics::{Contact, ContactOut, PairParams, TangentialLaw, V3};

/// LIGGGHTS `tangential history`. History: the shear displacement xi (3).
/// Reads `mu`; `out.kt`, `out.gamma_t`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsHistory;

impl TangentialLaw for LiggghtsHistory {
    const HISTORY: usize = 3;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let (cri, crj) = liggghts_levers(c);
        let vtr = rel_tangential_velocity(c, cri, crj);
        let mut xi = get3(hist) + vtr * c.dt;
        xi -= c.n * xi.dot(&c.n);
        let k_t = out.kt;
        let shrmag = xi.norm();
        let mut ft: V3 = -xi * k_t;
        let ft_shear = k_t * shrmag;
        let ft_friction = p.mu * out.fn_for_friction.abs();
        if ft_shear > ft_friction {
            if shrmag != 0.0 {
                ft *= ft_friction / ft_shear;
                xi = -ft / k_t;
            } else {
                ft = V3::zeros();
            }
        } else {
            ft -= vtr * out.gamma_t;
        }
        put3(hist, &xi);
        out.ft = ft;
        add_tangential_torque(c, &ft, cri, crj, out);
    }
}
