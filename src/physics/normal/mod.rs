//! Normal force laws, one file per deck keyword.
//!
//! LIGGGHTS `pair_style gran model ...`: [`hooke`], [`hooke_stiffness`],
//! [`hertz`], [`hertz_stiffness`]. LAMMPS `pair_style gran/hooke`,
//! `gran/hooke/history`, `gran/hertz/history`: [`gran`]. LAMMPS
//! `pair_style granular` normal sub-models hooke, hertz, hertz/material with
//! the damping variants: [`granular`]; the cohesive sub-models `dmt` and
//! `jkr`: [`dmt`], [`jkr`].
//!
//! Every law fills `fn_elastic`, `fn_damp`, `fn_for_friction` (the signed
//! normal force the friction cap takes the absolute value of), `kn`, `kt`,
//! `a`, `gamma_n` and `gamma_t` (the absolute tangential damping coefficient
//! the tangential laws of the same engine read).

pub mod dmt;
pub mod gran;
pub mod granular;
pub mod hertz;
pub mod hertz_stiffness;
pub mod hooke;
pub mod hooke_stiffness;
pub mod jkr;
pub mod viscoelastic;

use super::lanes::{Mask, Real};
use super::{ContactOut, OutL};

/// Store elastic and damping parts, clamping the sum at zero when
/// `limit` (LIGGGHTS `limitForce on`, LAMMPS `limit_damping`) is set and the
/// damping would make the total attractive. The clamp moves into `fn_damp`.
#[inline(always)]
pub(crate) fn store_normal(out: &mut ContactOut, fn_elastic: f64, fn_damp: f64, limit: f64) {
    let mut damp = fn_damp;
    if limit != 0.0 && fn_elastic + damp < 0.0 {
        damp = -fn_elastic;
    }
    out.fn_elastic = fn_elastic;
    out.fn_damp = damp;
    out.fn_for_friction = fn_elastic + damp;
}

/// [`store_normal`] on lanes.
#[inline(always)]
pub(crate) fn store_normal_lanes<R: Real>(out: &mut OutL<R>, fn_elastic: R, fn_damp: R, limit: R) {
    let zero = R::splat(0.0);
    let clamp = limit.ne(zero).and((fn_elastic + fn_damp).lt(zero));
    let damp = R::select(clamp, -fn_elastic, fn_damp);
    out.fn_elastic = fn_elastic;
    out.fn_damp = damp;
    out.fn_for_friction = fn_elastic + damp;
}
