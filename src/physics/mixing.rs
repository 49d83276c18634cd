//! Material mixing rules and the functions that turn material tables (LIGGGHTS
//! `fix property/global`, LAMMPS `pair_style`/`pair_coeff` arguments) into
//! per-type-pair [`PairParams`].
//!
//! LIGGGHTS (source `global_properties.cpp`): 1/Y* = (1-nu_i^2)/Y_i +
//! (1-nu_j^2)/Y_j; 1/G* = 2(2-nu_i)(1+nu_i)/Y_i + 2(2-nu_j)(1+nu_j)/Y_j;
//! beta = ln e / sqrt(ln^2 e + pi^2). Walls carry a material type and mix the
//! same way. LAMMPS granular (source `pair_granular.cpp`, 29 Sep 2021):
//! `hertz/material E eta nu` on a pair gives k_n = 4/3 E_eff with
//! E_eff = E / (2 (1 - nu^2)) (the material mixed with itself); mindlin
//! `NULL` gives k_t = 8 G_eff = 8 E / (4 (2 - nu)(1 + nu)).

use super::lanes::{Mask, Real};
use super::normal::granular::{GranularDamping, GranularNormal};
use super::tangential::granular::GranularTangential;
use super::PairParams;
use crate::error::{Error, Result};
use crate::script::source::Span;

/// LIGGGHTS effective Young's modulus Y* of two materials.
pub fn liggghts_y_eff(y_i: f64, nu_i: f64, y_j: f64, nu_j: f64) -> f64 {
    1.0 / ((1.0 - nu_i * nu_i) / y_i + (1.0 - nu_j * nu_j) / y_j)
}

/// LIGGGHTS effective shear modulus G* of two materials.
pub fn liggghts_g_eff(y_i: f64, nu_i: f64, y_j: f64, nu_j: f64) -> f64 {
    1.0 / (2.0 * (2.0 - nu_i) * (1.0 + nu_i) / y_i + 2.0 * (2.0 - nu_j) * (1.0 + nu_j) / y_j)
}

/// Effective radius R* = ri rj / (ri + rj); `rj = INFINITY` (wall) gives ri.
pub fn r_eff(ri: f64, rj: f64) -> f64 {
    if rj.is_infinite() {
        ri
    } else {
        ri * rj / (ri + rj)
    }
}

/// Effective mass m* = mi mj / (mi + mj); `mj = INFINITY` (wall, frozen) gives mi.
pub fn m_eff(mi: f64, mj: f64) -> f64 {
    if mj.is_infinite() {
        mi
    } else if mi.is_infinite() {
        mj
    } else {
        mi * mj / (mi + mj)
    }
}

/// LIGGGHTS damping parameter beta = ln e / sqrt(ln^2 e + pi^2) (<= 0).
pub fn liggghts_beta(e: f64) -> f64 {
    let l = e.ln();
    l / (l * l + std::f64::consts::PI * std::f64::consts::PI).sqrt()
}

/// LIGGGHTS material tables, 0-based types (type 1 of the deck is index 0);
/// pair tables are row-major `n x n`. `None` = the property was not given.
#[derive(Clone, Debug, Default)]
pub struct LiggghtsMaterials {
    /// Number of atom types.
    pub n_types: usize,
    /// `youngsModulus` per type.
    pub youngs: Option<Vec<f64>>,
    /// `poissonsRatio` per type.
    pub poisson: Option<Vec<f64>>,
    /// `coefficientRestitution` per type pair.
    pub restitution: Option<Vec<f64>>,
    /// `coefficientFriction` per type pair.
    pub friction: Option<Vec<f64>>,
    /// `coefficientRollingFriction` per type pair.
    pub rolling_friction: Option<Vec<f64>>,
    /// `coefficientRollingViscousDamping` per type pair.
    pub rolling_damping: Option<Vec<f64>>,
    /// `cohesionEnergyDensity` per type pair.
    pub cohesion_energy_density: Option<Vec<f64>>,
    /// `characteristicVelocity` scalar.
    pub char_vel: Option<f64>,
    /// `rollingStiffness` scalar (epsd3).
    pub rolling_stiffness: Option<f64>,
    /// `kn` per type pair (…/stiffness).
    pub kn: Option<Vec<f64>>,
    /// `kt` per type pair.
    pub kt: Option<Vec<f64>>,
    /// `gamman` (or `gamman_abs`) per type pair.
    pub gamman: Option<Vec<f64>>,
    /// `gammat` (or `gammat_abs`) per type pair.
    pub gammat: Option<Vec<f64>>,
}

/// Model settings of `pair_style gran` that go into [`PairParams`].
#[derive(Clone, Copy, Debug)]
pub struct LiggghtsSettings {
    /// `tangential_damping` (default on).
    pub tangential_damping: bool,
    /// `limitForce` (default off).
    pub limit_force: bool,
    /// `units si` (enables LIGGGHTS' Y >= 5e6 and characteristicVelocity >= 1e-2 checks).
    pub units_si: bool,
}

impl Default for LiggghtsSettings {
    fn default() -> Self {
        LiggghtsSettings { tangential_damping: true, limit_force: false, units_si: true }
    }
}

fn check_len(v: &Option<Vec<f64>>, want: usize, name: &str, span: Span) -> Result<()> {
    match v {
        Some(x) if x.len() != want => Err(Error::deck(span, format!("{name} needs {want} values for this number of atom types, got {}", x.len()))),
        _ => Ok(()),
    }
}

/// Build the `n x n` (row-major, 0-based) [`PairParams`] table from
/// LIGGGHTS properties, with LIGGGHTS' own sanity checks
/// (0.05 < e <= 1, 0 <= nu <= 0.5, SI: Y >= 5e6, V >= 1e-2). Properties that
/// are absent leave their fields zero; the scene checks which the chosen
/// models require. `span` is where errors point (the pair_style command).
pub fn liggghts_pair_params(m: &LiggghtsMaterials, s: &LiggghtsSettings, span: Span) -> Result<Vec<PairParams>> {
    let n = m.n_types;
    check_len(&m.youngs, n, "youngsModulus", span)?;
    check_len(&m.poisson, n, "poissonsRatio", span)?;
    for (v, name) in [
        (&m.restitution, "coefficientRestitution"),
        (&m.friction, "coefficientFriction"),
        (&m.rolling_friction, "coefficientRollingFriction"),
        (&m.rolling_damping, "coefficientRollingViscousDamping"),
        (&m.cohesion_energy_density, "cohesionEnergyDensity"),
        (&m.kn, "kn"),
        (&m.kt, "kt"),
        (&m.gamman, "gamman"),
        (&m.gammat, "gammat"),
    ] {
        check_len(v, n * n, name, span)?;
    }
    if let Some(y) = &m.youngs {
        for &yi in y {
            if !(yi > 0.0) || (s.units_si && yi < 5e6) {
                return Err(Error::deck(span, format!("youngsModulus {yi} invalid (LIGGGHTS requires >= 5e6 for SI units)")));
            }
        }
    }
    if let Some(nu) = &m.poisson {
        for &v in nu {
            if !(0.0..=0.5).contains(&v) {
                return Err(Error::deck(span, format!("poissonsRatio {v} invalid: 0 <= poissonsRatio <= 0.5 required")));
            }
        }
    }
    if let Some(e) = &m.restitution {
        for &v in e {
            if !(v > 0.05 && v <= 1.0) {
                return Err(Error::deck(span, format!("coefficientRestitution {v} invalid: 0.05 < coefficientRestitution <= 1 required")));
            }
        }
    }
    if let Some(v) = m.char_vel {
        if !(v > 0.0) || (s.units_si && v < 1e-2) {
            return Err(Error::deck(span, format!("characteristicVelocity {v} invalid: >= 1e-2 required for SI units")));
        }
    }
    let at = |v: &Option<Vec<f64>>, k: usize| v.as_ref().map_or(0.0, |x| x[k]);
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let k = i * n + j;
            let mut p = PairParams::default();
            if let (Some(y), Some(nu)) = (&m.youngs, &m.poisson) {
                p.y_eff = liggghts_y_eff(y[i], nu[i], y[j], nu[j]);
                p.g_eff = liggghts_g_eff(y[i], nu[i], y[j], nu[j]);
            }
            if let Some(e) = &m.restitution {
                p.restitution = e[k];
                p.beta = liggghts_beta(e[k]);
            }
            p.mu = at(&m.friction, k);
            p.mu_r = at(&m.rolling_friction, k);
            p.eta_r = at(&m.rolling_damping, k);
            p.k_r_coeff = m.rolling_stiffness.unwrap_or(2.25);
            p.cohesion = at(&m.cohesion_energy_density, k);
            p.char_vel = m.char_vel.unwrap_or(0.0);
            p.kn = at(&m.kn, k);
            p.kt = at(&m.kt, k);
            p.gamma_n = at(&m.gamman, k);
            p.gamma_t = at(&m.gammat, k);
            p.tangential_damping = if s.tangential_damping { 1.0 } else { 0.0 };
            p.limit_damping = if s.limit_force { 1.0 } else { 0.0 };
            out.push(p);
        }
    }
    Ok(out)
}

/// LAMMPS `pair_style gran/hooke|gran/hooke/history|gran/hertz/history
/// Kn Kt gamma_n gamma_t xmu dampflag [limit_damping]` (also `fix wall/gran`
/// with those styles): `kt = None` (NULL) gives 2/7 Kn, `gamma_t = None`
/// gives gamma_n / 2, dampflag 0 gives gamma_t = 0. Same for all type pairs.
pub fn lammps_gran_params(kn: f64, kt: Option<f64>, gamma_n: f64, gamma_t: Option<f64>, xmu: f64, dampflag: bool, limit_damping: bool) -> PairParams {
    let mut p = PairParams {
        kn,
        kt: kt.unwrap_or(kn * 2.0 / 7.0),
        gamma_n,
        gamma_t: if dampflag { gamma_t.unwrap_or(0.5 * gamma_n) } else { 0.0 },
        mu: xmu,
        ..Default::default()
    };
    p.tangential_damping = if dampflag { 1.0 } else { 0.0 };
    p.limit_damping = if limit_damping { 1.0 } else { 0.0 };
    p
}

/// LAMMPS granular E_eff of a pair mixed from two materials,
/// 1/E_eff = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j (`mix_stiffnessE`).
pub fn lammps_mix_e(e_i: f64, nu_i: f64, e_j: f64, nu_j: f64) -> f64 {
    1.0 / ((1.0 - nu_i * nu_i) / e_i + (1.0 - nu_j * nu_j) / e_j)
}

/// LAMMPS granular G_eff (`mix_stiffnessG`),
/// 1/G_eff = 2(2-nu_i)(1+nu_i)/E_i + 2(2-nu_j)(1+nu_j)/E_j.
pub fn lammps_mix_g(e_i: f64, nu_i: f64, e_j: f64, nu_j: f64) -> f64 {
    1.0 / (2.0 * (2.0 - nu_i) * (1.0 + nu_i) / e_i + 2.0 * (2.0 - nu_j) * (1.0 + nu_j) / e_j)
}

/// LAMMPS `fix wall/gran granular hertz/material E eta nu` effective modulus
/// as the 29 Sep 2021 build computes it: E / (2 (1 - nu)) (verified with
/// `lmp`: nu = 0.3 and 0.1 give forces 4/3 E/(2(1-nu)) sqrt(R delta) delta;
/// not the E/(2(1-nu^2)) of a particle pair).
pub fn lammps_wall_e_eff_2021(e: f64, nu: f64) -> f64 {
    e / (2.0 * (1.0 - nu))
}

/// LAMMPS Tsuji damping coefficient alpha(e) (pair_granular.cpp polynomial).
pub fn tsuji_alpha(e: f64) -> f64 {
    1.2728 - 4.2783 * e + 11.087 * e.powi(2) - 22.348 * e.powi(3) + 27.467 * e.powi(4) - 18.022 * e.powi(5) + 4.8218 * e.powi(6)
}

/// Geometric mixing sqrt(a b) (LAMMPS `mix_geom`).
pub fn mix_geom(a: f64, b: f64) -> f64 {
    (a * b).sqrt()
}

/// Tangential choice of one LAMMPS granular `pair_coeff`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GranularTangentialChoice {
    /// `linear_nohistory`.
    NoHistory,
    /// A history model.
    History(GranularTangential),
}

/// One LAMMPS `pair_style granular` `pair_coeff` (or `fix wall/gran
/// granular`) as parsed.
#[derive(Clone, Copy, Debug)]
pub struct GranularCoeff {
    /// Normal sub-model.
    pub normal: GranularNormal,
    /// Damping sub-model.
    pub damping: GranularDamping,
    /// First normal argument: kn (hooke, hertz) or E (hertz/material).
    pub kn_or_e: f64,
    /// Damping argument eta (for tsuji: the restitution e).
    pub damp: f64,
    /// Poisson ratio (hertz/material), else 0.
    pub poisson: f64,
    /// Tangential sub-model.
    pub tangential: GranularTangentialChoice,
    /// Tangential stiffness (`None` = NULL, mindlin from the material).
    pub kt: Option<f64>,
    /// Tangential damping multiplier x_gamma_t.
    pub x_gamma_t: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// `rolling sds k_roll gamma_roll mu_roll`.
    pub rolling: Option<(f64, f64, f64)>,
    /// `twisting sds k gamma mu`.
    pub twisting: Option<(f64, f64, f64)>,
    /// `limit_damping` given.
    pub limit_damping: bool,
}

/// [`PairParams`] of an explicitly given LAMMPS granular `pair_coeff I J`
/// (`* *` included): hertz/material k_n = 4/3 E/(2(1-nu^2)); mindlin NULL
/// k_t = 8 E/(4(2-nu)(1+nu)); tsuji damping converted to alpha(e).
/// For `fix wall/gran granular` pass `wall = true`: E_eff = E/(2(1-nu)) as
/// the 2021 build does ([`lammps_wall_e_eff_2021`]).
pub fn lammps_granular_params(c: &GranularCoeff, wall: bool, span: Span) -> Result<PairParams> {
    let mut p = PairParams::default();
    let material = c.normal == GranularNormal::HertzMaterial;
    if material {
        if !(c.kn_or_e > 0.0) || !(c.poisson > -1.0 && c.poisson < 0.5) {
            return Err(Error::deck(span, "hertz/material needs E > 0 and -1 < poisson < 0.5"));
        }
        let e_eff = if wall { lammps_wall_e_eff_2021(c.kn_or_e, c.poisson) } else { lammps_mix_e(c.kn_or_e, c.poisson, c.kn_or_e, c.poisson) };
        p.y_eff = e_eff;
        p.kn = 4.0 / 3.0 * e_eff;
        p.g_eff = lammps_mix_g(c.kn_or_e, c.poisson, c.kn_or_e, c.poisson);
        p.poisson = c.poisson;
    } else {
        p.kn = c.kn_or_e;
    }
    p.gamma_n = if c.damping == GranularDamping::Tsuji { tsuji_alpha(c.damp) } else { c.damp };
    if c.damping == GranularDamping::Tsuji {
        p.restitution = c.damp;
    }
    p.kt = match c.kt {
        Some(k) => k,
        None => {
            if !material {
                return Err(Error::deck(span, "tangential stiffness NULL needs a material normal model (hertz/material)"));
            }
            8.0 * p.g_eff
        }
    };
    p.gamma_t = c.x_gamma_t;
    p.mu = c.mu;
    p.tangential_damping = 1.0;
    if let Some((k, g, mu)) = c.rolling {
        p.k_roll = k;
        p.gamma_roll = g;
        p.mu_r = mu;
    }
    if let Some((k, g, mu)) = c.twisting {
        p.k_twist = k;
        p.gamma_twist = g;
        p.mu_twist = mu;
    }
    p.limit_damping = if c.limit_damping { 1.0 } else { 0.0 };
    Ok(p)
}

/// [`PairParams`] LAMMPS 2021 computes for a type pair I != J that has no
/// `pair_coeff` of its own (`init_one`): every coefficient is the geometric
/// mean of the I I and J J values (k_n of hertz/material included, i.e. of
/// the 4/3 E_eff values). Warning, verified with `lmp` (29 Sep 2021): such a
/// pair is then computed with the **Hooke** normal law (its model index is
/// left at 0), so F = sqrt(k_n,II k_n,JJ) delta; per the source the damping
/// and tangential indices likewise stay `velocity` and `linear_nohistory`.
pub fn lammps_granular_mix_2021(ii: &PairParams, jj: &PairParams) -> PairParams {
    let mut p = PairParams {
        kn: mix_geom(ii.kn, jj.kn),
        gamma_n: mix_geom(ii.gamma_n, jj.gamma_n),
        kt: mix_geom(ii.kt, jj.kt),
        gamma_t: mix_geom(ii.gamma_t, jj.gamma_t),
        mu: mix_geom(ii.mu, jj.mu),
        ..Default::default()
    };
    p.k_roll = mix_geom(ii.k_roll, jj.k_roll);
    p.gamma_roll = mix_geom(ii.gamma_roll, jj.gamma_roll);
    p.mu_r = mix_geom(ii.mu_r, jj.mu_r);
    p.k_twist = mix_geom(ii.k_twist, jj.k_twist);
    p.gamma_twist = mix_geom(ii.gamma_twist, jj.gamma_twist);
    p.mu_twist = mix_geom(ii.mu_twist, jj.mu_twist);
    p.tangential_damping = 1.0;
    p
}

// ---------------------------------------------------------------- the angle-of-repose paper

/// Numerator coefficients of the Müller & Pöschel (2011) [1/4] Padé
/// approximant of the restitution coefficient of viscoelastic spheres,
/// eps(x) = (1 + a1 x) / (1 + b1 x + b2 x^2 + b3 x^3 + b4 x^4) with
/// x = beta^{1/2} v^{1/10} and beta = 3/2 A (k_n/m*)^{2/5}
/// (P. Müller, T. Pöschel, Phys. Rev. E 84, 021302 (2011), the [1/4]
/// approximant of the Schwager-Pöschel series eps = 1 + sum h_k x^k; its
/// expansion reproduces h_2 = -1.15345, h_3 = 0, h_4 = 0.7983).
pub const MP_PADE_NUM: [f64; 2] = [1.0, 0.501086];
/// Denominator coefficients of the same approximant (powers 0..4 of x).
pub const MP_PADE_DEN: [f64; 5] = [1.0, 0.501086, 1.15345, 0.577977, 0.532178];

/// eps(x) of the Müller-Pöschel [1/4] Padé approximant (x = beta^{1/2} v^{1/10}).
pub fn mp_pade_restitution(x: f64) -> f64 {
    let num = MP_PADE_NUM[0] + MP_PADE_NUM[1] * x;
    let den = MP_PADE_DEN.iter().rev().fold(0.0, |acc, &b| acc * x + b);
    num / den
}

/// Invert a decreasing restitution curve eps(x) (eps(0) = 1) by bisection.
fn invert_restitution(e: f64, f: impl Fn(f64) -> f64) -> Option<f64> {
    if !(e > 0.0 && e <= 1.0) {
        return None;
    }
    if e == 1.0 {
        return Some(0.0);
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    while f(hi) > e {
        hi *= 2.0;
        if hi > 1e6 {
            return None;
        }
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > e {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// x = beta^{1/2} v^{1/10} for which the Padé approximant gives `e`
/// (None unless 0 < e <= 1).
pub fn mp_pade_x(e: f64) -> Option<f64> {
    invert_restitution(e, mp_pade_restitution)
}

/// Restitution of the viscoelastic (Brilliantov) Hertz collision with the
/// force clamped at zero, as a function of x = beta^{1/2} v^{1/10}, by
/// integrating the dimensionless equation d'' = -max(0, d^{3/2} +
/// x^2 sqrt(d) d') (k_n/m* = 1, v = 1, so A = 2 x^2 / 3) with RK4 until the
/// spheres separate. Exact up to the integration error (~1e-6).
pub fn viscoelastic_restitution_exact(x: f64) -> f64 {
    let c = x * x; // 3/2 A with A = 2 x^2 / 3
    let acc = |d: f64, dd: f64| if d <= 0.0 { 0.0 } else { -(d * d.sqrt() + c * d.sqrt() * dd).max(0.0) };
    let h = 2e-4;
    let (mut d, mut dd) = (0.0_f64, 1.0_f64);
    for _ in 0..200_000 {
        let (k1x, k1v) = (dd, acc(d, dd));
        let (k2x, k2v) = (dd + 0.5 * h * k1v, acc(d + 0.5 * h * k1x, dd + 0.5 * h * k1v));
        let (k3x, k3v) = (dd + 0.5 * h * k2v, acc(d + 0.5 * h * k2x, dd + 0.5 * h * k2v));
        let (k4x, k4v) = (dd + h * k3v, acc(d + h * k3x, dd + h * k3v));
        d += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        dd += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if d < 0.0 {
            break;
        }
    }
    -dd
}

/// x for which [`viscoelastic_restitution_exact`] gives `e`.
pub fn exact_x(e: f64) -> Option<f64> {
    invert_restitution(e, viscoelastic_restitution_exact)
}

/// Müller-Pöschel beta = x^2 / v_ref^{1/5} for restitution `e` at reference
/// impact speed `v_ref`, from the Padé approximant (the paper's way) or,
/// with `exact`, from the integrated collision. None for bad inputs.
pub fn mp_beta(e: f64, v_ref: f64, exact: bool) -> Option<f64> {
    if !(v_ref > 0.0) || !v_ref.is_finite() {
        return None;
    }
    let x = if exact { exact_x(e)? } else { mp_pade_x(e)? };
    Some(x * x / v_ref.powf(0.2))
}

/// Dissipative constant A_n = 2 beta / (3 (k_n/m*)^{2/5}) of the paper's
/// Eq. 10 for a pair with k_n (N/m^{3/2}) and m* (0 for infinite m*).
/// On lanes: each lane its own pair.
#[inline(always)]
pub fn viscoelastic_a_n<R: Real>(beta: R, k_n: R, m_eff: R) -> R {
    let zero = R::splat(0.0);
    let valid = m_eff.gt(zero).and(k_n.gt(zero));
    let a_n = beta * 2.0 / ((k_n / m_eff).powf(0.4) * 3.0);
    R::select(m_eff.is_inf(), zero, R::select(valid, a_n, zero))
}

/// Hamaker constant from the surface energy, A_H = 24 pi D_min^2 gamma (paper Eq. 14).
pub fn hamaker_constant(gamma: f64, d_min: f64) -> f64 {
    24.0 * std::f64::consts::PI * d_min * d_min * gamma
}
