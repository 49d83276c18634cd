//! LIGGGHTS `tangential history` (source `tangential_model_history.h`):
//! Cundall-Strack spring with Coulomb cap on the elastic part only.
//!
//! xi += v_t dt; xi -= (xi . n) n (projection, no magnitude rescale);
//! F_el = -k_t xi; if k_t |xi| > mu |F_n|: F_t = F_el mu |F_n| / (k_t |xi|),
//! xi = -F_t / k_t (computed as xi mu |F_n| / (k_t |xi|)), and no damping while sliding; else
//! F_t = F_el - gamma_t v_t. At a run's setup (dt = 0) xi is used as stored
//! and kept (the engine's `update_history` is false there). Relative velocity and torque use the
//! contact-point distance R - delta/2 of each sphere (`surface_model_default.h`).

use super::{add_tangential_torque_lanes, get3_lanes, liggghts_levers_lanes, put3_lanes, rel_tangential_velocity_lanes};
use crate::physics::lanes::{Coeffs, Mask, Real, Vec3};
use crate::physics::{on_one, Contact, ContactL, ContactOut, OutL, PairParams, TangentialLaw};

/// LIGGGHTS `tangential history`. History: the shear displacement xi (3).
/// Reads `mu`; `out.kt`, `out.gamma_t`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsHistory;

impl TangentialLaw for LiggghtsHistory {
    const HISTORY: usize = 3;
    /// The shear displacement xi sums v_t dt, v_t the relative tangential
    /// velocity of the contact points, which turns with the pair (v_i - v_j
    /// and n flip, (l_i w_i + l_j w_j) x n flips with n): -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    const LANES: bool = true;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.tangential_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn tangential_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, hist: &mut [R], out: &mut OutL<R>) {
        let (cri, crj) = liggghts_levers_lanes(c);
        let vtr = rel_tangential_velocity_lanes(c, cri, crj);
        let old = get3_lanes(hist);
        let mut xi = old + vtr * R::splat(c.dt);
        xi -= c.n * xi.dot(&c.n);
        // a run's setup (dt = 0) leaves the history as it was: the engine
        // neither adds to it nor projects it nor resets it to the cap
        // without `update_history` (a sliding contact across two runs)
        let setup = R::splat(c.dt).equal(R::splat(0.0));
        xi = Vec3::select(setup, old, xi);
        let k_t = out.kt;
        let shrmag = xi.norm();
        let ft_el = -xi * k_t;
        let ft_shear = k_t * shrmag;
        let ft_friction = p.get(|q| q.mu) * out.fn_for_friction.abs();
        // sliding: the elastic force scaled onto the cap, the spring reset to
        // it, no damping; sticking: elastic plus damping
        let slide = ft_shear.gt(ft_friction);
        let moved = shrmag.ne(R::splat(0.0));
        let ratio = ft_friction / ft_shear;
        let ft_slide = ft_el * ratio;
        let ft_stick = ft_el - vtr * out.gamma_t;
        let ft = Vec3::select(slide, Vec3::select(moved, ft_slide, Vec3::zeros()), ft_stick);
        // the spring reset to the cap, xi = -F_t / k_t = xi mu |F_n| / (k_t |xi|):
        // one multiply by the ratio, not three divisions by k_t (the
        // divider is the batch's scarcest unit; the two differ by rounding)
        xi = Vec3::select(slide.and(moved), xi * ratio, xi);
        put3_lanes(hist, &Vec3::select(setup, old, xi));
        out.ft = ft;
        add_tangential_torque_lanes(c, &ft, cri, crj, out);
    }
}
