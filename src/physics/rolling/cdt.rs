//! LIGGGHTS `rolling_friction cdt` (source `rolling_model_cdt.h`): constant
//! directional torque M = mu_r k_n delta_n L w_hat, its normal (torsion) part
//! then removed; L = R* and w = w_i - w_j for pairs, L = R - delta/2 and
//! w = w_i for walls.

use crate::physics::{Contact, ContactOut, PairParams, RollingLaw};

/// LIGGGHTS `rolling_friction cdt`. Reads `mu_r`; `out.kn`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsCdt;

impl RollingLaw for LiggghtsCdt {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let (w, lever) = if c.is_wall() { (c.wi, c.ri - 0.5 * c.delta) } else { (c.wi - c.wj, c.r_eff) };
        let w_mag = w.norm();
        if w_mag > 0.0 {
            let mut m = w * (p.mu_r * out.kn * c.delta * lever / w_mag);
            m -= c.n * m.dot(&c.n);
            out.torque_i -= m;
            if !c.is_wall() {
                out.torque_j += m;
            }
        }
    }
}
