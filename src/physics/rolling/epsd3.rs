//! LIGGGHTS `rolling_friction epsd3` (source `rolling_model_epsd3.h`): as
//! epsd with the user stiffness factor `rollingStiffness` in place of
//! 2.25: k_r = c k_n mu_r^2 R^2.

use super::{epsd_torque, liggghts_rolling_inertia, liggghts_rotation};
use crate::physics::{Contact, ContactOut, PairParams, RollingLaw};

/// LIGGGHTS `rolling_friction epsd3`. Reads `mu_r`, `eta_r`, `k_r_coeff`;
/// `out.kn`, `out.fn_for_friction`. History: the spring torque (3).
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsEpsd3 {
    /// `torsionTorque on`.
    pub torsion_torque: bool,
}

impl RollingLaw for LiggghtsEpsd3 {
    const HISTORY: usize = 3;
    /// The spring torque sums k_r w dt with w = w_i - w_j (its rolling part
    /// w - (w . n) n, or all of it with torsionTorque), which turns with the
    /// pair: -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let (w, r) = liggghts_rotation(c);
        let k_r = p.k_r_coeff * out.kn * p.mu_r * p.mu_r * r * r;
        let r_coef = p.eta_r * 2.0 * (liggghts_rolling_inertia(c) * k_r).sqrt();
        epsd_torque(c, p, hist, out, k_r, r_coef, self.torsion_torque, r, w);
    }
}
