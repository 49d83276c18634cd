//! LAMMPS `pair_style granular` (29 Sep 2021) normal sub-model
//! `dmt E eta_n0 nu gamma` (Derjaguin-Muller-Toporov; doc
//! `pair_granular.rst`, "dmt" and "tangential" sections).
//!
//! Hertz plus a constant attraction while the surfaces overlap:
//! F_ne = 4/3 E_eff sqrt(R* delta) delta - 4 pi gamma R* (a = sqrt(R* delta)),
//! damping F_damp = -eta_n v_n with eta_n as for the non-cohesive models
//! (velocity, mass_velocity, viscoelastic eta a m*, tsuji alpha sqrt(m* k a)).
//! The contact exists only while delta > 0 (the attraction switches on and
//! off with the overlap); the DMT pull-off force is 4 pi gamma R*
//! (= 2 pi w R* with the work of adhesion w = 2 gamma). The friction,
//! rolling and twisting caps use F_n0 = |F_ne| (cohesion included, damping
//! not): measured with the 29 Sep 2021 `lmp` on a sliding DMT contact,
//! |F_t| / mu = |4/3 E_eff a delta - 4 pi gamma R*| to 7 digits over 20
//! steps, **not** the |F_ne + 2 F_pulloff| the documentation states (that
//! rule holds for `jkr` in this build, and for both in later versions).
//! `limit_damping` is rejected by LAMMPS for this model ("Cannot limit
//! damping with DMT model", verified).
//!
//! Verified with `lmp` (29 Sep 2021): E = 1e7, nu = 0.3, gamma = 0.1,
//! R_i = R_j = 1 mm, delta = 10 um gives F = 4.5519509285241681e-3 N, equal
//! to the formula above with E_eff = E / (2 (1 - nu^2)).

use super::granular::GranularDamping;
use crate::physics::{Contact, ContactOut, NormalLaw, PairParams};
use std::f64::consts::PI;

/// DMT pull-off force 4 pi gamma R* (`gamma` the LAMMPS surface energy).
#[inline(always)]
pub fn dmt_pulloff_force(gamma: f64, r_eff: f64) -> f64 {
    4.0 * PI * gamma * r_eff
}

/// Damping prefactor eta_n of `pair_style granular` for contact radius `a`
/// and the harmonic stiffness `k_nd` = F/delta of the elastic part (tsuji).
#[inline(always)]
pub(crate) fn damp_normal(damping: GranularDamping, a: f64, m_eff: f64, k_nd: f64) -> f64 {
    match damping {
        GranularDamping::Velocity => 1.0,
        GranularDamping::MassVelocity => m_eff,
        GranularDamping::Viscoelastic => a * m_eff,
        GranularDamping::Tsuji => (m_eff * k_nd).sqrt(),
    }
}

/// LAMMPS granular `dmt`. Reads `kn` (4/3 E_eff), `gamma_n` (eta_n0, or
/// alpha(e) for tsuji), `cohesion` (gamma), `kt`, `gamma_t` (x_gamma_t).
#[derive(Clone, Copy, Debug)]
pub struct LammpsDmt {
    /// Damping sub-model.
    pub damping: GranularDamping,
}

impl NormalLaw for LammpsDmt {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let delta_n = c.delta;
        let a = (delta_n * c.r_eff).sqrt();
        let k_n = p.kn * a;
        let f_pulloff = dmt_pulloff_force(p.cohesion, c.r_eff);
        let f_ne = k_n * delta_n - f_pulloff;
        let eta_n = p.gamma_n * damp_normal(self.damping, a, c.m_eff, k_n);
        out.fn_elastic = f_ne;
        out.fn_damp = -eta_n * c.vn;
        // LAMMPS 29 Sep 2021 behaviour (measured), see the module doc
        out.fn_for_friction = f_ne;
        out.kn = k_n;
        out.kt = p.kt;
        out.a = a;
        out.gamma_n = eta_n;
        out.gamma_t = p.gamma_t * eta_n;
    }
}
