//! demx `rolling_friction epsd/paper`: the paper's elastic-plastic rolling
//! resistance (Elekes & Parteli 2021, Eq. 15; Iwashita & Oda's spring as in
//! LIGGGHTS epsd2):
//!
//! M(t+dt) = min(mu_r R* |F^c_n|, |M(t) - k_r w dt|) (M(t) - k_r w dt)/|...|,
//! k_r = k_t sqrt(delta) R*^2, w = w_i - w_j,
//!
//! with k_t sqrt(delta) the current tangential stiffness of the normal law
//! (`out.kt`). By default only the rolling part of w (normal component
//! removed) is resisted, as in LIGGGHTS epsd2 (the paper's simulations
//! neglect torsion); `torsionTorque on` keeps the whole w. Walls (infinite
//! radius) use R* = R_i and w = w_i. The stored torque is not rotated with
//! the contact frame.

use super::epsd_torque_lanes;
use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, Contact, ContactL, ContactOut, OutL, PairParams, RollingLaw};

/// The paper's rolling resistance. Reads `mu_r`; `out.kt`,
/// `out.fn_for_friction`. History: the spring torque (3).
#[derive(Clone, Copy, Debug, Default)]
pub struct PaperEpsd {
    /// `torsionTorque on`: resist the twisting part of w as well.
    pub torsion_torque: bool,
}

impl RollingLaw for PaperEpsd {
    const HISTORY: usize = 3;
    /// The spring torque sums k_r w dt with w = w_i - w_j (its rolling part
    /// w - (w . n) n, or all of it with torsionTorque), which turns with the
    /// pair: -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    const LANES: bool = true;
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.rolling_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn rolling_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, hist: &mut [R], out: &mut OutL<R>) {
        let w = if c.wall { c.wi } else { c.wi - c.wj };
        let r = c.r_eff;
        let k_r = out.kt * r * r;
        epsd_torque_lanes(c, p, hist, out, k_r, R::splat(0.0), self.torsion_torque, r, w);
    }
}
