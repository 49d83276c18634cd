//! LAMMPS `pair_style granular` (29 Sep 2021) tangential sub-models
//! (source `pair_granular.cpp`, doc `pair_granular.rst`):
//! `linear_nohistory x_gamma_t mu`, `linear_history kt x_gamma_t mu`,
//! `mindlin kt|NULL x_gamma_t mu`, `mindlin_rescale`, `mindlin/force`,
//! `mindlin_rescale/force`.
//!
//! Damping eta_t = x_gamma_t eta_n (eta_n = the normal damping coefficient).
//! Mindlin stiffness k_t a (a = sqrt(delta R*)). Per step: (rescale models)
//! if a < a_prev, history *= a / a_prev; if the history has a normal part
//! (|xi . n| k > 1e-10 F_crit, force models |xi . n| > 1e-10 F_crit) it is
//! projected onto the tangent plane and rescaled to its old magnitude (Luding
//! 2008 eq. 17); displacement models add v_t dt, force models subtract
//! k_t v_t dt (Thornton 2013 eq. 18); F_t = -k xi - eta_t v_t (force models
//! xi - eta_t v_t); if |F_t| > mu F_ncrit, F_t is scaled to the cap and the
//! history set consistently including the damping term. Relative velocity
//! uses the full radii, torque the lever R - delta/2 (pairs) or R (walls).

use super::no_history::capped_viscous;
use super::{add_tangential_torque, get3, put3, rel_tangential_velocity};
use crate::physics::{Contact, ContactOut, PairParams, TangentialLaw, V3};

/// EPSILON of pair_granular.cpp for the frame-update test.
const EPSILON: f64 = 1e-10;

/// History-carrying tangential sub-model of `pair_style granular`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GranularTangential {
    /// `linear_history kt x_gamma_t mu`.
    LinearHistory,
    /// `mindlin`: stiffness k_t a, history is a displacement.
    Mindlin,
    /// `mindlin_rescale`: as mindlin, displacement rescaled on unloading.
    MindlinRescale,
    /// `mindlin/force`: history is the elastic force.
    MindlinForce,
    /// `mindlin_rescale/force`: force history rescaled on unloading.
    MindlinRescaleForce,
}

impl GranularTangential {
    fn mindlin(self) -> bool {
        !matches!(self, GranularTangential::LinearHistory)
    }
    fn rescale(self) -> bool {
        matches!(self, GranularTangential::MindlinRescale | GranularTangential::MindlinRescaleForce)
    }
    fn force_history(self) -> bool {
        matches!(self, GranularTangential::MindlinForce | GranularTangential::MindlinRescaleForce)
    }
}

/// The torque lever of LAMMPS granular: R - delta/2 for particle pairs
/// (`pair_style granular`), but the full radius R for `fix wall/gran
/// granular` (both verified with the 29 Sep 2021 `lmp`: torque / tangential
/// force = 0.95 mm and 1.45 mm for R = 1 and 1.5 mm at delta = 0.1 mm, and
/// 1.0 mm against a wall).
#[inline(always)]
fn torque_levers(c: &Contact) -> (f64, f64) {
    if c.is_wall() {
        (c.ri, c.rj)
    } else {
        (c.ri - 0.5 * c.delta, c.rj - 0.5 * c.delta)
    }
}

/// LAMMPS granular tangential laws with history. History: xi (3) and the
/// previous contact radius a (1, rescale models only, kept for all).
/// Reads `kt` (kt, or 8 G_eff for `mindlin NULL`), `gamma_t` (x_gamma_t),
/// `mu`; `out.gamma_n`, `out.a`, `out.fn_for_friction`.
#[derive(Clone, Copy, Debug)]
pub struct LammpsGranularHistory {
    /// Sub-model.
    pub model: GranularTangential,
}

impl TangentialLaw for LammpsGranularHistory {
    const HISTORY: usize = 4;
    /// xi (a displacement summing v_t dt, or an elastic force summing
    /// -k_t v_t dt) turns with v_t, the relative tangential velocity of the
    /// contact points (v_i - v_j and n flip): -1 each; the previous contact
    /// radius a, a magnitude, is the same from both sides: +1.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0, 1.0];
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let m = self.model;
        let vtr = rel_tangential_velocity(c, c.ri, c.rj);
        let a = out.a;
        let f_scrit = p.mu * out.fn_for_friction.abs();
        let damp_t = p.gamma_t * out.gamma_n;
        let mut k_t = p.kt;
        let mut xi = get3(hist);
        if m.mindlin() {
            k_t *= a;
        }
        if m.rescale() && a < hist[3] {
            xi *= a / hist[3];
        }
        let rsht = xi.dot(&c.n);
        let frame_update = if m.force_history() { rsht.abs() > EPSILON * f_scrit } else { rsht.abs() * k_t > EPSILON * f_scrit };
        if frame_update {
            let shrmag = xi.norm();
            xi -= c.n * rsht;
            let prjmag = xi.norm();
            let scalefac = if prjmag > 0.0 { shrmag / prjmag } else { 0.0 };
            xi *= scalefac;
        }
        if m.force_history() {
            xi -= vtr * (k_t * c.dt);
        } else {
            xi += vtr * c.dt;
        }
        if m.rescale() {
            hist[3] = a;
        }
        let mut fs: V3 = if m.force_history() { xi - vtr * damp_t } else { -xi * k_t - vtr * damp_t };
        let fs_mag = fs.norm();
        if fs_mag > f_scrit {
            if xi.norm() != 0.0 {
                let el = fs * (f_scrit / fs_mag) + vtr * damp_t;
                if m.force_history() {
                    xi = el;
                } else if k_t != 0.0 {
                    xi = -el / k_t;
                }
                fs *= f_scrit / fs_mag;
            } else {
                fs = V3::zeros();
            }
        }
        put3(hist, &xi);
        out.ft = fs;
        out.kt = k_t;
        let (li, lj) = torque_levers(c);
        add_tangential_torque(c, &fs, li, lj, out);
    }
}

/// LAMMPS granular `linear_nohistory x_gamma_t mu`:
/// F_t = -min(mu F_ncrit, eta_t |v_t|) v_t/|v_t|. Reads `gamma_t`, `mu`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsLinearNoHistory;

impl TangentialLaw for LammpsLinearNoHistory {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let vtr = rel_tangential_velocity(c, c.ri, c.rj);
        let damp_t = p.gamma_t * out.gamma_n;
        let ft = capped_viscous(&vtr, damp_t, p.mu * out.fn_for_friction.abs());
        out.ft = ft;
        let (li, lj) = torque_levers(c);
        add_tangential_torque(c, &ft, li, lj, out);
    }
}
