//! LAMMPS `pair_style granular` `rolling sds k_roll gamma_roll mu_roll` and
//! `twisting sds k_twist gamma_twist mu_twist` (source `pair_granular.cpp`,
//! 29 Sep 2021; Luding 2008, Wang et al. 2015 eq. 31).
//!
//! Rolling: v_roll = R* (w_i - w_j) x n; history rotated into the tangent
//! plane keeping its magnitude (when |xi . n| k_roll > 1e-10 F_rcrit), then
//! xi += v_roll dt; pseudo-force F_r = -k_roll xi - gamma_roll v_roll capped
//! at mu_roll F_ncrit (history reset consistently); torque_i += R* n x F_r,
//! torque_j -= it. Twisting: w_t = (w_i - w_j) . n; phi += w_t dt;
//! M = -k phi - gamma w_t capped at mu F_ncrit; torque_i += M n.

use crate::physics::tangential::{get3, put3};
use crate::physics::{Contact, ContactOut, PairParams, RollingLaw, V3};

const EPSILON: f64 = 1e-10;

/// LAMMPS granular `rolling sds` (and optionally `twisting sds`). Reads
/// `k_roll`, `gamma_roll`, `mu_r` (mu_roll) and, with twisting, `k_twist`,
/// `gamma_twist`, `mu_twist`; `out.fn_for_friction`. History: rolling
/// displacement (3) and twist angle (1).
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsSds {
    /// Also apply `twisting sds`.
    pub twisting: bool,
}

impl RollingLaw for LammpsSds {
    const HISTORY: usize = 4;
    /// The rolling displacement sums v_roll dt, v_roll = R* (w_i - w_j) x n,
    /// a product of two factors that both flip with the pair: +1 each (the
    /// torque R* n x F_r still turns, through n). The twist angle sums
    /// (w_i - w_j) . n dt, also a product of two flipping factors: +1.
    /// Debian's LAMMPS (29 Sep 2021) transfers these with its default
    /// factor, -1 (`PairGranular::transfer_history`; a later source of its
    /// granular sub-models gives the SDS rolling history +1, for the same
    /// reason as here), so there a contact's rolling
    /// displacement changes sign when its pair changes order (an atom sort,
    /// a migration); demx does not follow that.
    const FLIP: &'static [f64] = &[1.0, 1.0, 1.0, 1.0];
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let relrot = if c.is_wall() { c.wi } else { c.wi - c.wj };
        let f_ncrit = out.fn_for_friction.abs();
        let v_roll: V3 = relrot.cross(&c.n) * c.r_eff;
        let f_rcrit = p.mu_r * f_ncrit;
        let mut xi = get3(hist);
        let dot = xi.dot(&c.n);
        if dot.abs() * p.k_roll > EPSILON * f_rcrit {
            let mag = xi.norm();
            xi -= c.n * dot;
            let prj = xi.norm();
            xi *= if prj > 0.0 { mag / prj } else { 0.0 };
        }
        xi += v_roll * c.dt;
        let mut fr: V3 = -xi * p.k_roll - v_roll * p.gamma_roll;
        let fr_mag = fr.norm();
        if fr_mag > f_rcrit {
            if xi.norm() != 0.0 {
                if p.k_roll != 0.0 {
                    xi = -(fr * (f_rcrit / fr_mag) + v_roll * p.gamma_roll) / p.k_roll;
                }
                fr *= f_rcrit / fr_mag;
            } else {
                fr = V3::zeros();
            }
        }
        put3(&mut hist[0..3], &xi);
        let torroll = c.n.cross(&fr) * c.r_eff;
        out.torque_i += torroll;
        if !c.is_wall() {
            out.torque_j -= torroll;
        }
        if self.twisting {
            let w_t = relrot.dot(&c.n);
            hist[3] += w_t * c.dt;
            let mut m = -p.k_twist * hist[3] - p.gamma_twist * w_t;
            let m_crit = p.mu_twist * f_ncrit;
            if m.abs() > m_crit {
                let sign = if w_t > 0.0 {
                    1.0
                } else if w_t < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                if p.k_twist != 0.0 {
                    hist[3] = (m_crit * sign - p.gamma_twist * w_t) / p.k_twist;
                }
                m = -m_crit * sign;
            }
            out.torque_i += c.n * m;
            if !c.is_wall() {
                out.torque_j -= c.n * m;
            }
        }
    }
}
