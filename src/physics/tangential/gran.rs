//! LAMMPS `pair_style gran/hooke` (no history) and `gran/hooke/history`,
//! `gran/hertz/history` tangential parts (source
//! `pair_gran_hooke_history.cpp`, `pair_gran_hertz_history.cpp`,
//! `pair_gran_hooke.cpp`).
//!
//! History: xi += v_t dt; xi -= (xi . n) n (no rescale);
//! F_t = -(k_t xi + gamma_t v_t) (k_t, gamma_t already times m* and the Hertz
//! factor, from the normal law); cap on the **total** |F_t| <= mu |F_n|; on
//! slip xi = (F_c/|F_t|)(xi + gamma_t/k_t v_t) - gamma_t/k_t v_t. Lever arm
//! and relative rotation use the full radii R_i, R_j.

use super::no_history::capped_viscous;
use super::{add_tangential_torque, get3, put3, rel_tangential_velocity};
use crate::physics::{Contact, ContactOut, PairParams, TangentialLaw, V3};

/// LAMMPS `gran/hooke/history` and `gran/hertz/history` shear history.
/// Reads `mu`; `out.kt`, `out.gamma_t`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsGranHistory;

/// The lever radius of sphere j (infinite for walls; unused there).
#[inline(always)]
fn rj_lever(c: &Contact) -> f64 {
    c.rj
}

impl TangentialLaw for LammpsGranHistory {
    const HISTORY: usize = 3;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let vtr = rel_tangential_velocity(c, c.ri, rj_lever(c));
        let mut xi = get3(hist) + vtr * c.dt;
        // LAMMPS takes the magnitude before the projection (zero test only).
        let shrmag = xi.norm();
        xi -= c.n * xi.dot(&c.n);
        let k_t = out.kt;
        let g_t = out.gamma_t;
        let mut fs: V3 = -(xi * k_t + vtr * g_t);
        let fs_mag = fs.norm();
        let f_cap = p.mu * out.fn_for_friction.abs();
        if fs_mag > f_cap {
            if shrmag != 0.0 {
                let ratio = f_cap / fs_mag;
                if k_t != 0.0 {
                    let mgkt = g_t / k_t;
                    xi = (xi + vtr * mgkt) * ratio - vtr * mgkt;
                }
                fs *= ratio;
            } else {
                fs = V3::zeros();
            }
        }
        put3(hist, &xi);
        out.ft = fs;
        add_tangential_torque(c, &fs, c.ri, rj_lever(c), out);
    }
}

/// LAMMPS `gran/hooke` (no history): F_t = -min(mu |F_n|, m* gamma_t |v_t|)
/// v_t/|v_t|, lever R. Reads `mu`; `out.gamma_t`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsGranNoHistory;

impl TangentialLaw for LammpsGranNoHistory {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let vtr = rel_tangential_velocity(c, c.ri, rj_lever(c));
        let ft = capped_viscous(&vtr, out.gamma_t, p.mu * out.fn_for_friction.abs());
        out.ft = ft;
        add_tangential_torque(c, &ft, c.ri, rj_lever(c), out);
    }
}
