//! LAMMPS `pair_style gran/hooke` (no history) and `gran/hooke/history`,
//! `gran/hertz/history` tangential parts (source
//! `pair_gran_hooke_history.cpp`, `pair_gran_hertz_history.cpp`,
//! `pair_gran_hooke.cpp`).
//!
//! History: xi += v_t dt; xi -= (xi . n) n (no rescale);
//! F_t = -(k_t xi + gamma_t v_t) (k_t, gamma_t already times m* and the Hertz
//! factor, from the normal law); cap on the **total** |F_t| <= mu |F_n|; on
//! slip xi = (F_c/|F_t|)(xi + gamma_t/k_t v_t) - gamma_t/k_t v_t. Lever arm
//! and relative rotation use the full radii R_i, R_j.

use super::no_history::capped_viscous;
use super::{add_tangential_torque, add_tangential_torque_lanes, get3_lanes, put3_lanes, rel_tangential_velocity, rel_tangential_velocity_lanes};
use crate::physics::lanes::{Coeffs, Mask, Real, Vec3};
use crate::physics::{on_one, Contact, ContactL, ContactOut, OutL, PairParams, TangentialLaw};

/// LAMMPS `gran/hooke/history` and `gran/hertz/history` shear history.
/// Reads `mu`; `out.kt`, `out.gamma_t`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsGranHistory;

/// The lever radius of sphere j (infinite for walls; unused there).
#[inline(always)]
fn rj_lever(c: &Contact) -> f64 {
    c.rj
}

impl TangentialLaw for LammpsGranHistory {
    const HISTORY: usize = 3;
    /// The shear displacement xi sums v_t dt, v_t the relative tangential
    /// velocity of the contact points, which turns with the pair (v_i - v_j
    /// and n flip, (R_i w_i + R_j w_j) x n flips with n): -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    const LANES: bool = true;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.tangential_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn tangential_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, hist: &mut [R], out: &mut OutL<R>) {
        let vtr = rel_tangential_velocity_lanes(c, c.ri, c.rj);
        let mut xi = get3_lanes(hist) + vtr * R::splat(c.dt);
        // LAMMPS takes the magnitude before the projection (zero test only).
        let shrmag = xi.norm();
        xi -= c.n * xi.dot(&c.n);
        let k_t = out.kt;
        let g_t = out.gamma_t;
        let fs = -(xi * k_t + vtr * g_t);
        let fs_mag = fs.norm();
        let f_cap = p.get(|q| q.mu) * out.fn_for_friction.abs();
        // slip: the total force scaled onto the cap and the spring set so that
        // spring and damping give it
        let zero = R::splat(0.0);
        let slide = fs_mag.gt(f_cap);
        let moved = shrmag.ne(zero);
        let ratio = f_cap / fs_mag;
        let mgkt = g_t / k_t;
        let xi_slip = (xi + vtr * mgkt) * ratio - vtr * mgkt;
        xi = Vec3::select(slide.and(moved).and(k_t.ne(zero)), xi_slip, xi);
        let fs = Vec3::select(slide, Vec3::select(moved, fs * ratio, Vec3::zeros()), fs);
        put3_lanes(hist, &xi);
        out.ft = fs;
        add_tangential_torque_lanes(c, &fs, c.ri, c.rj, out);
    }
}

/// LAMMPS `gran/hooke` (no history): F_t = -min(mu |F_n|, m* gamma_t |v_t|)
/// v_t/|v_t|, lever R. Reads `mu`; `out.gamma_t`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsGranNoHistory;

impl TangentialLaw for LammpsGranNoHistory {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let vtr = rel_tangential_velocity(c, c.ri, rj_lever(c));
        let ft = capped_viscous(&vtr, out.gamma_t, p.mu * out.fn_for_friction.abs());
        out.ft = ft;
        add_tangential_torque(c, &ft, c.ri, rj_lever(c), out);
    }
}
