//! LAMMPS `pair_style granular` (29 Sep 2021) normal sub-models `hooke`,
//! `hertz`, `hertz/material` and the `damping` variants (source
//! `pair_granular.cpp`, doc `pair_granular.rst`).
//!
//! With a = sqrt(delta_n R*): hooke F_ne = k_n delta_n; hertz and
//! hertz/material F_ne = k_n a delta_n (hertz/material's k_n is
//! 4/3 E_eff, filled by [`crate::physics::mixing`]). Damping
//! F_damp = -eta_n v_n with eta_n = eta * {1 (velocity), m* (mass_velocity),
//! a m* (viscoelastic), sqrt(m* k_n a) (tsuji, hertz-type; k_n for hooke)},
//! where eta for tsuji is alpha(e) (converted at pair_coeff time). The
//! friction cap uses |F_ne + F_damp| after `limit_damping`.

use crate::physics::{Contact, ContactOut, NormalLaw, PairParams};

/// Normal sub-model of `pair_style granular`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GranularNormal {
    /// `hooke kn damp`.
    Hooke,
    /// `hertz kn damp`.
    Hertz,
    /// `hertz/material E damp poisson`.
    HertzMaterial,
}

/// Damping sub-model of `pair_style granular` (default `viscoelastic`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GranularDamping {
    /// `damping velocity`: eta_n = eta.
    Velocity,
    /// `damping mass_velocity`: eta_n = eta m*.
    MassVelocity,
    /// `damping viscoelastic`: eta_n = eta a m*.
    Viscoelastic,
    /// `damping tsuji`: eta_n = alpha(e) sqrt(m* k_n(a)).
    Tsuji,
}

/// LAMMPS `pair_style granular` normal force. Reads `kn` (normal_coeffs[0]),
/// `gamma_n` (damping coefficient eta, or alpha(e) for tsuji) and
/// `limit_damping` from [`PairParams`].
#[derive(Clone, Copy, Debug)]
pub struct LammpsGranular {
    /// Normal sub-model.
    pub model: GranularNormal,
    /// Damping sub-model.
    pub damping: GranularDamping,
}

impl NormalLaw for LammpsGranular {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let delta_n = c.delta;
        let a = (delta_n * c.r_eff).sqrt();
        let k_n = match self.model {
            GranularNormal::Hooke => p.kn,
            GranularNormal::Hertz | GranularNormal::HertzMaterial => p.kn * a,
        };
        let damp_normal = match self.damping {
            GranularDamping::Velocity => 1.0,
            GranularDamping::MassVelocity => c.m_eff,
            GranularDamping::Viscoelastic => a * c.m_eff,
            GranularDamping::Tsuji => (c.m_eff * k_n).sqrt(),
        };
        let eta_n = p.gamma_n * damp_normal;
        super::store_normal(out, k_n * delta_n, -eta_n * c.vn, p.limit_damping);
        out.kn = k_n;
        out.kt = p.kt;
        out.a = a;
        out.gamma_n = eta_n;
        out.gamma_t = p.gamma_t * eta_n;
    }
}
