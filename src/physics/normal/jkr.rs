//! LAMMPS `pair_style granular` (29 Sep 2021) normal sub-model
//! `jkr E eta_n0 nu gamma` (Johnson-Kendall-Roberts; doc
//! `pair_granular.rst`, "jkr" and "tangential" sections).
//!
//! The contact radius `a` follows from the overlap through
//! delta = a^2/R* - 2 sqrt(pi gamma a / E_eff), solved here for the larger
//! (stable) root; the elastic force is
//! F_ne = 4 E_eff a^3 / (3 R*) - 2 pi a^2 sqrt(4 gamma E_eff / (pi a)).
//! Damping as for the other models with this `a` (viscoelastic eta a m*,
//! tsuji alpha sqrt(m* 4/3 E_eff a)). Hysteresis: a pair interacts only once
//! its surfaces have touched (delta > 0); from then on it stays in contact,
//! also at negative overlap, until delta falls to the pull-off overlap
//! delta_c = a_c^2/R* - 2 sqrt(pi gamma a_c / E_eff) with
//! a_c = (9 pi gamma R*^2 / (4 E_eff))^(1/3), where F_ne reaches its minimum
//! -3 pi gamma R* (the JKR pull-off force, = 3/2 pi w R* with the work of
//! adhesion w = 2 gamma). The friction, rolling and twisting caps use
//! F_n0 = |F_ne + 2 F_pulloff| with F_pulloff = 3 pi gamma R*.
//! `limit_damping` is rejected by LAMMPS for this model (verified).
//!
//! Verified with `lmp` (29 Sep 2021): E = 1e7, nu = 0.3, gamma = 0.1,
//! R_i = R_j = 1 mm, delta = 10 um gives F = 4.8479169452017579e-3 N, equal
//! to the formula above to 1e-15.

use super::dmt::damp_normal;
use super::granular::GranularDamping;
use crate::physics::{Contact, ContactOut, NormalLaw, PairParams};
use std::f64::consts::PI;

/// JKR pull-off force 3 pi gamma R* (`gamma` the LAMMPS surface energy).
#[inline(always)]
pub fn jkr_pulloff_force(gamma: f64, r_eff: f64) -> f64 {
    3.0 * PI * gamma * r_eff
}

/// Contact radius at the force minimum, a_c = (9 pi gamma R*^2 / (4 E))^(1/3).
#[inline(always)]
pub fn jkr_pulloff_radius(r_eff: f64, e_eff: f64, gamma: f64) -> f64 {
    (9.0 * PI * gamma * r_eff * r_eff / (4.0 * e_eff)).cbrt()
}

/// Overlap at which a JKR contact breaks, delta_c <= 0 (0 without cohesion).
#[inline(always)]
pub fn jkr_pulloff_overlap(r_eff: f64, e_eff: f64, gamma: f64) -> f64 {
    if !(gamma > 0.0) || !(e_eff > 0.0) || !(r_eff > 0.0) {
        return 0.0;
    }
    let a = jkr_pulloff_radius(r_eff, e_eff, gamma);
    a * a / r_eff - 2.0 * (PI * gamma * a / e_eff).sqrt()
}

/// Contact radius for overlap `delta`: the larger root of
/// delta = a^2/R - 2 sqrt(pi gamma a / E). With s = sqrt(a) this is the
/// quartic s^4 - c s - R delta = 0, c = 2 R sqrt(pi gamma / E), which is
/// convex for s > 0; Newton's method started to the right of the root
/// descends monotonically onto it (to rounding). Returns 0 when there is no
/// root (delta below the displacement-controlled minimum).
pub fn jkr_contact_radius(delta: f64, r_eff: f64, e_eff: f64, gamma: f64) -> f64 {
    let c = 2.0 * r_eff * (PI * gamma.max(0.0) / e_eff).sqrt();
    let rd = r_eff * delta;
    // (c^(1/3) + (R delta)^(1/4))^4 >= c s0 + R delta: s0 lies right of the root
    let mut s = c.cbrt() + rd.max(0.0).sqrt().sqrt();
    if !(s > 0.0) || !s.is_finite() {
        return 0.0;
    }
    for _ in 0..100 {
        let s3 = s * s * s;
        let f = s3 * s - c * s - rd;
        if f <= 0.0 {
            break;
        }
        let fp = 4.0 * s3 - c;
        if !(fp > 0.0) {
            // left of the minimum of the quartic: no root above it
            return 0.0;
        }
        let next = s - f / fp;
        if !(next < s) {
            break;
        }
        s = next;
    }
    let check = s * s * s * s - c * s - rd;
    if check > 1e-9 * (rd.abs() + c * s) {
        return 0.0;
    }
    s * s
}

/// Elastic JKR force for contact radius `a`:
/// 4 E a^3 / (3 R) - 2 pi a^2 sqrt(4 gamma E / (pi a)).
#[inline(always)]
pub fn jkr_force(a: f64, r_eff: f64, e_eff: f64, gamma: f64) -> f64 {
    if !(a > 0.0) {
        return 0.0;
    }
    4.0 * e_eff * a * a * a / (3.0 * r_eff) - 2.0 * PI * a * a * (4.0 * gamma * e_eff / (PI * a)).sqrt()
}

/// LAMMPS granular `jkr`. Reads `y_eff` (E_eff), `kn` (4/3 E_eff),
/// `gamma_n` (eta_n0, or alpha(e) for tsuji), `cohesion` (gamma), `kt`,
/// `gamma_t` (x_gamma_t). History: one flag, set once the surfaces touched.
#[derive(Clone, Copy, Debug)]
pub struct LammpsJkr {
    /// Damping sub-model.
    pub damping: GranularDamping,
}

impl NormalLaw for LammpsJkr {
    const HISTORY: usize = 1;
    /// The flag "the surfaces have touched" is the pair's, the same from both
    /// sides: +1.
    const FLIP: &'static [f64] = &[1.0];
    const CONTACT_ONLY: bool = false;
    #[inline(always)]
    fn active(&self, c: &Contact, p: &PairParams, hist: &[f64]) -> bool {
        c.delta > 0.0 || (hist[0] != 0.0 && c.delta > jkr_pulloff_overlap(c.r_eff, p.y_eff, p.cohesion))
    }
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        hist[0] = 1.0;
        let e = p.y_eff;
        let a = jkr_contact_radius(c.delta, c.r_eff, e, p.cohesion);
        let k_n = p.kn * a;
        let f_ne = jkr_force(a, c.r_eff, e, p.cohesion);
        let eta_n = p.gamma_n * damp_normal(self.damping, a, c.m_eff, k_n);
        out.fn_elastic = f_ne;
        out.fn_damp = -eta_n * c.vn;
        out.fn_for_friction = f_ne + 2.0 * jkr_pulloff_force(p.cohesion, c.r_eff);
        out.kn = k_n;
        out.kt = p.kt;
        out.a = a;
        out.gamma_n = eta_n;
        out.gamma_t = p.gamma_t * eta_n;
    }
}
