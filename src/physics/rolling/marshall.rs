//! LAMMPS `pair_style granular` `twisting marshall` (29 Sep 2021; doc
//! `pair_granular.rst`, "twisting" section; Marshall 2009 eqs. 32-33),
//! alone ([`LammpsTwistMarshall`]) or after `rolling sds`
//! ([`LammpsSdsMarshall`]).
//!
//! A spring-dashpot-slider on the relative spin w_t = (w_i - w_j) . n with
//! coefficients from the tangential model: k_twist = 1/2 k_t a^2 (k_t the
//! tangential stiffness as the tangential model applies it, i.e. times a for
//! the mindlin models; 0 for linear_nohistory), eta_twist = 1/2 eta_t a^2
//! (eta_t = x_gamma_t eta_n), mu_twist = 2/3 a mu_t. phi += w_t dt;
//! M = -k_twist phi - eta_twist w_t; if |M| > mu_twist F_n0: M = -mu_twist
//! F_n0 sgn(w_t) and phi = (mu_twist F_n0 sgn(w_t) - eta_twist w_t) / k_twist.
//! torque_i += M n, torque_j -= M n.
//!
//! Verified with `lmp`: after one step of spin 10 rad/s about n (no damping,
//! no slip), torque = 1/2 k_t a^2 w dt for linear_history (k_t = 1000) and
//! for mindlin NULL with k_t = 8 G_eff a, with dmt and jkr contacts.

use super::sds::LammpsSds;
use crate::physics::{Contact, ContactOut, PairParams, RollingLaw};

/// One Marshall twisting step on history `phi` (one value).
#[inline(always)]
fn twist(c: &Contact, p: &PairParams, phi: &mut f64, out: &mut ContactOut) {
    let a = out.a;
    let k_twist = 0.5 * out.kt * a * a;
    let damp_twist = 0.5 * p.gamma_t * out.gamma_n * a * a;
    let mu_twist = 2.0 / 3.0 * a * p.mu;
    let relrot = if c.is_wall() { c.wi } else { c.wi - c.wj };
    let w_t = relrot.dot(&c.n);
    *phi += w_t * c.dt;
    let mut m = -k_twist * *phi - damp_twist * w_t;
    let m_crit = mu_twist * out.fn_for_friction.abs();
    if m.abs() > m_crit {
        let sign = if w_t > 0.0 {
            1.0
        } else if w_t < 0.0 {
            -1.0
        } else {
            0.0
        };
        if k_twist != 0.0 {
            *phi = (m_crit * sign - damp_twist * w_t) / k_twist;
        }
        m = -m_crit * sign;
    }
    out.torque_i += c.n * m;
    if !c.is_wall() {
        out.torque_j -= c.n * m;
    }
}

/// `twisting marshall` without rolling resistance. Reads `gamma_t`
/// (x_gamma_t), `mu`; `out.kt`, `out.a`, `out.gamma_n`,
/// `out.fn_for_friction`. History: the twist angle.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsTwistMarshall;

impl RollingLaw for LammpsTwistMarshall {
    const HISTORY: usize = 1;
    /// The twist angle sums (w_i - w_j) . n dt, a product of two factors
    /// that both flip with the pair: +1 (the torque M n still turns, through n).
    const FLIP: &'static [f64] = &[1.0];
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        twist(c, p, &mut hist[0], out);
    }
}

/// `rolling sds ... twisting marshall`: the rolling torque of
/// [`LammpsSds`], then the Marshall twisting torque. History: rolling
/// displacement (3), unused (1), twist angle (1).
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsSdsMarshall;

impl RollingLaw for LammpsSdsMarshall {
    const HISTORY: usize = <LammpsSds as RollingLaw>::HISTORY + 1;
    /// [`LammpsSds`]'s factors for its slots, then the twist angle's (+1, as
    /// in [`LammpsTwistMarshall`]).
    const FLIP: &'static [f64] = &{
        let sds = <LammpsSds as RollingLaw>::FLIP;
        let mut f = [1.0; <LammpsSds as RollingLaw>::HISTORY + 1];
        let mut k = 0;
        while k < sds.len() {
            f[k] = sds[k];
            k += 1;
        }
        f
    };
    #[inline(always)]
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        let (hr, ht) = hist.split_at_mut(<LammpsSds as RollingLaw>::HISTORY);
        LammpsSds { twisting: false }.rolling(c, p, hr, out);
        twist(c, p, &mut ht[0], out);
    }
}
