//! LIGGGHTS `rolling_friction epsd2` (source `rolling_model_epsd2.h`,
//! Iwashita & Oda): k_r = k_t R^2, cap mu_r R |F_n|, no dashpot.

use super::{epsd_torque, liggghts_rotation};
use crate::physics::{Contact, ContactOut, PairParams, RollingLaw};

/// LIGGGHTS `rolling_friction epsd2`. Reads `mu_r`; `out.kt`,
/// `out.fn_for_friction`. History: the spring torque (3).
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsEpsd2 {
    /// `torsionTorque on`.
    pub torsion_torque: bool,
}

impl RollingLaw for LiggghtsEpsd2 {
    const HISTORY: usize = 3;
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let (w, r) = liggghts_rotation(c);
        let k_r = out.kt * r * r;
        epsd_torque(c, p, hist, out, k_r, 0.0, self.torsion_torque, r, w);
    }
}
