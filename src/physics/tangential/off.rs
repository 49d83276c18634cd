//! LIGGGHTS `tangential off` (source `tangential_model_off.h`): no
//! tangential force and no torque from one; a contact pushes along its
//! normal only (frictionless grains).

use crate::physics::lanes::Real;
use crate::physics::{Coeffs, Contact, ContactL, ContactOut, OutL, PairParams, TangentialLaw};

/// LIGGGHTS `tangential off`: leaves `ft` and the torques at zero.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsOff;

impl TangentialLaw for LiggghtsOff {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn tangential(&self, _c: &Contact, _p: &PairParams, _hist: &mut [f64], _out: &mut ContactOut) {}
    const LANES: bool = true;
    #[inline(always)]
    fn tangential_lanes<R: Real, P: Coeffs<R>>(&self, _c: &ContactL<R>, _p: &P, _hist: &mut [R], _out: &mut OutL<R>) {}
}
