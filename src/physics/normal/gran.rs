//! LAMMPS `pair_style gran/hooke`, `gran/hooke/history`, `gran/hertz/history`
//! and `fix wall/gran` with the same names: normal parts (source
//! `pair_gran_hooke_history.cpp`, `pair_gran_hertz_history.cpp`, doc
//! `pair_gran.rst`).
//!
//! Hooke: F_n = k_n delta_n - m* gamma_n v_n. Hertz: both terms times
//! sqrt(delta_n R*) (LAMMPS `polyhertz`), and the tangential constants are
//! scaled by the same factor. m* is the effective mass (the mobile particle's
//! mass against walls and frozen particles). `limit_damping` clamps the
//! total at zero.

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, Contact, ContactL, ContactOut, NormalLaw, OutL, PairParams};

/// LAMMPS `gran/hooke` and `gran/hooke/history` normal force. Reads `kn`,
/// `kt`, `gamma_n`, `gamma_t` (already 0 with dampflag 0), `limit_damping`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsGranHooke;

impl NormalLaw for LammpsGranHooke {
    const HISTORY: usize = 0;
    const LANES: bool = true;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.normal_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        let (kn, kt) = (p.get(|q| q.kn), p.get(|q| q.kt));
        let gamma_n = c.m_eff * p.get(|q| q.gamma_n);
        super::store_normal_lanes(out, kn * c.delta, -gamma_n * c.vn, p.get(|q| q.limit_damping));
        out.kn = kn;
        out.kt = kt;
        out.a = (c.r_eff * c.delta).sqrt();
        out.gamma_n = gamma_n;
        out.gamma_t = c.m_eff * p.get(|q| q.gamma_t);
    }
}

/// LAMMPS `gran/hertz/history` normal force: Hooke form times
/// sqrt(delta_n R*). Reads the same fields as [`LammpsGranHooke`]
/// (`kn`, `kt` in pressure units).
#[derive(Clone, Copy, Debug, Default)]
pub struct LammpsGranHertz;

impl NormalLaw for LammpsGranHertz {
    const HISTORY: usize = 0;
    const LANES: bool = true;
    #[inline(always)]
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.normal_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        let (kn, kt) = (p.get(|q| q.kn), p.get(|q| q.kt));
        let polyhertz = (c.delta * c.r_eff).sqrt();
        let gamma_n = polyhertz * c.m_eff * p.get(|q| q.gamma_n);
        super::store_normal_lanes(out, polyhertz * kn * c.delta, -gamma_n * c.vn, p.get(|q| q.limit_damping));
        out.kn = polyhertz * kn;
        out.kt = polyhertz * kt;
        out.a = polyhertz;
        out.gamma_n = gamma_n;
        out.gamma_t = polyhertz * c.m_eff * p.get(|q| q.gamma_t);
    }
}
