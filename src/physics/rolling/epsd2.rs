//! LIGGGHTS `rolling_friction epsd2` (source `rolling_model_epsd2.h`,
//! Iwashita & Oda): k_r = k_t R^2, cap mu_r R |F_n|, no dashpot.

use super::{epsd_torque_lanes, liggghts_rotation_lanes};
use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, Contact, ContactL, ContactOut, OutL, PairParams, RollingLaw};

/// LIGGGHTS `rolling_friction epsd2`. Reads `mu_r`; `out.kt`,
/// `out.fn_for_friction`. History: the spring torque (3).
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsEpsd2 {
    /// `torsionTorque on`.
    pub torsion_torque: bool,
}

impl RollingLaw for LiggghtsEpsd2 {
    const HISTORY: usize = 3;
    /// The spring torque sums k_r w dt with w = w_i - w_j (its rolling part
    /// w - (w . n) n, or all of it with torsionTorque), which turns with the
    /// pair: -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.rolling_lanes(c, p, hist, o));
    }
    const LANES: bool = true;
    #[inline(always)]
    fn rolling_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, hist: &mut [R], out: &mut OutL<R>) {
        let (w, r) = liggghts_rotation_lanes(c);
        let k_r = out.kt * r * r;
        epsd_torque_lanes(c, p, hist, out, k_r, R::splat(0.0), self.torsion_torque, r, w);
    }
}
