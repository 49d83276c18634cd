//! LIGGGHTS `rolling_friction epsd` (source `rolling_model_epsd.h`, Ai et al.
//! 2011): k_r = 2.25 k_n mu_r^2 R^2; M += k_r w_t dt; |M| <= mu_r R |F_n|
//! (stored capped, no dashpot at the cap); below the cap a dashpot
//! eta_r 2 sqrt(I_r k_r) w_t is added (not stored).

use super::{epsd_torque, liggghts_rolling_inertia, liggghts_rotation};
use crate::physics::{Contact, ContactOut, PairParams, RollingLaw};

/// LIGGGHTS `rolling_friction epsd`. Reads `mu_r`
/// (`coefficientRollingFriction`), `eta_r` (`coefficientRollingViscousDamping`);
/// `out.kn`, `out.fn_for_friction`. History: the spring torque (3).
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsEpsd {
    /// `torsionTorque on`: keep the twisting part of the relative rotation.
    pub torsion_torque: bool,
}

impl RollingLaw for LiggghtsEpsd {
    const HISTORY: usize = 3;
    /// The spring torque sums k_r w dt with w = w_i - w_j (its rolling part
    /// w - (w . n) n, or all of it with torsionTorque), which turns with the
    /// pair: -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let (w, r) = liggghts_rotation(c);
        let k_r = 2.25 * out.kn * p.mu_r * p.mu_r * r * r;
        let r_coef = p.eta_r * 2.0 * (liggghts_rolling_inertia(c) * k_r).sqrt();
        epsd_torque(c, p, hist, out, k_r, r_coef, self.torsion_torque, r, w);
    }
}
