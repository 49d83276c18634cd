//! Tangential (friction) laws, one file per deck keyword, each with its
//! engine's lever arm and slip convention.
//!
//! LIGGGHTS `tangential no_history` / `history`: [`no_history`],
//! [`history`] (lever arm R - delta/2 for relative velocity and torque, cap on
//! the elastic part only). LAMMPS `gran/*`: [`gran`] (lever R, cap on the
//! total force, history rescaled with the damping term on slip). LAMMPS
//! `pair_style granular`: [`granular`] (velocity lever R, torque lever
//! R - delta/2, history rotated with magnitude kept).
//!
//! All laws read `out.fn_for_friction`, `out.kt` and `out.gamma_t` (or
//! `out.gamma_n` for LAMMPS granular) written by the normal law.

pub mod gran;
pub mod granular;
pub mod history;
pub mod no_history;
pub mod off;
pub mod paper;

use super::lanes::{Real, Vec3};
use super::{Contact, ContactL, ContactOut, OutL, V3};

/// Relative tangential velocity of the contact points,
/// `v_t - (l_i w_i + l_j w_j) x n`, with lever radii `l_i`, `l_j` (the wall
/// side has no rotation term).
#[inline(always)]
pub fn rel_tangential_velocity(c: &Contact, lever_i: f64, lever_j: f64) -> V3 {
    let vt = c.vr - c.n * c.vn;
    let mut wr = c.wi * lever_i;
    if !c.is_wall() {
        wr += c.wj * lever_j;
    }
    vt - wr.cross(&c.n)
}

/// Add the torques of tangential force `ft` (acting on i; -ft on j) applied
/// at distances `lever_i`, `lever_j` from the centres:
/// torque_i = -l_i n x ft, torque_j = -l_j n x ft (walls: none on j).
#[inline(always)]
pub fn add_tangential_torque(c: &Contact, ft: &V3, lever_i: f64, lever_j: f64, out: &mut ContactOut) {
    let tor = c.n.cross(ft);
    out.torque_i -= tor * lever_i;
    if !c.is_wall() {
        out.torque_j -= tor * lever_j;
    }
}

/// LIGGGHTS contact-point distances (`surface_model_default.h`): each sphere's
/// radius minus half the overlap, `cri = ri - delta/2`, `crj = rj - delta/2`.
#[inline(always)]
pub fn liggghts_levers(c: &Contact) -> (f64, f64) {
    (c.ri - 0.5 * c.delta, c.rj - 0.5 * c.delta)
}

/// Store a 3-vector into a history slice.
#[inline(always)]
pub(crate) fn put3(h: &mut [f64], v: &V3) {
    h[0] = v.x;
    h[1] = v.y;
    h[2] = v.z;
}

/// Read a 3-vector from a history slice.
#[inline(always)]
pub(crate) fn get3(h: &[f64]) -> V3 {
    V3::new(h[0], h[1], h[2])
}

/// [`rel_tangential_velocity`] on lanes.
#[inline(always)]
pub fn rel_tangential_velocity_lanes<R: Real>(c: &ContactL<R>, lever_i: R, lever_j: R) -> Vec3<R> {
    let vt = c.vr - c.n * c.vn;
    let mut wr = c.wi * lever_i;
    if !c.wall {
        wr += c.wj * lever_j;
    }
    vt - wr.cross(&c.n)
}

/// [`add_tangential_torque`] on lanes.
#[inline(always)]
pub fn add_tangential_torque_lanes<R: Real>(c: &ContactL<R>, ft: &Vec3<R>, lever_i: R, lever_j: R, out: &mut OutL<R>) {
    let tor = c.n.cross(ft);
    out.torque_i -= tor * lever_i;
    if !c.wall {
        out.torque_j -= tor * lever_j;
    }
}

/// [`liggghts_levers`] on lanes.
#[inline(always)]
pub fn liggghts_levers_lanes<R: Real>(c: &ContactL<R>) -> (R, R) {
    let half = c.delta * 0.5;
    (c.ri - half, c.rj - half)
}

/// Read a 3-vector of lanes from history lanes.
#[inline(always)]
pub(crate) fn get3_lanes<R: Real>(h: &[R]) -> Vec3<R> {
    Vec3::new(h[0], h[1], h[2])
}

/// Store a 3-vector of lanes into history lanes.
#[inline(always)]
pub(crate) fn put3_lanes<R: Real>(h: &mut [R], v: &Vec3<R>) {
    h[0] = v.x;
    h[1] = v.y;
    h[2] = v.z;
}
