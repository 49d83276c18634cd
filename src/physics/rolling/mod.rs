//! Rolling (and twisting) resistance laws, one file per deck keyword:
//! LIGGGHTS `rolling_friction cdt`, `epsd`, `epsd2`, `epsd3`
//! ([`cdt`], [`epsd`], [`epsd2`], [`epsd3`]) and LAMMPS granular
//! `rolling sds` / `twisting sds` ([`sds`]) and `twisting marshall`
//! ([`marshall`]).
//!
//! LIGGGHTS conventions (sources `rolling_model_*.h`): the relative rotation
//! is w_i - w_j for pairs with R*; for walls it is the surface model's
//! (R - delta/2)/d w_i (d = centre-to-contact distance) with R. The torque M
//! is applied as torque_i -= M, torque_j += M. The EPSD spring torque is kept
//! in the history and **not** rotated with the contact frame.

pub mod cdt;
pub mod epsd;
pub mod epsd2;
pub mod epsd3;
pub mod sds;
pub mod marshall;
pub mod paper;

use super::{Contact, ContactOut, PairParams, V3};
use super::tangential::{get3, put3};

/// LIGGGHTS relative rotation and rolling radius of a contact:
/// (w_i - w_j, R*) for pairs, ((R - delta/2)/d w_i, R) for walls.
#[inline(always)]
pub(crate) fn liggghts_rotation(c: &Contact) -> (V3, f64) {
    if c.is_wall() {
        (c.wi * ((c.ri - 0.5 * c.delta) / c.r), c.ri)
    } else {
        (c.wi - c.wj, c.r_eff)
    }
}

/// LIGGGHTS rolling inertia I_r (3D): 1.4 m R^2 for walls, else
/// 1.4 (mi ri^2)(mj rj^2)/(mi ri^2 + mj rj^2).
#[inline(always)]
pub(crate) fn liggghts_rolling_inertia(c: &Contact) -> f64 {
    let ii = c.mi * c.ri * c.ri;
    if c.is_wall() || c.mj.is_infinite() {
        1.4 * ii
    } else {
        let ij = c.mj * c.rj * c.rj;
        1.4 * ii * ij / (ii + ij)
    }
}

/// Shared EPSD-family spring-dashpot with the cap |M| <= mu_r R |F_n|.
/// `k_r` rolling stiffness, `r_coef` dashpot coefficient (0 = none),
/// `torsion` keeps the normal part of the relative rotation.
#[inline(always)]
pub(crate) fn epsd_torque(
    c: &Contact,
    p: &PairParams,
    hist: &mut [f64],
    out: &mut ContactOut,
    k_r: f64,
    r_coef: f64,
    torsion: bool,
    r_roll: f64,
    w_rel: V3,
) {
    let w = if torsion { w_rel } else { w_rel - c.n * w_rel.dot(&c.n) };
    let mut m = get3(hist) + w * (c.dt * k_r);
    let m_max = out.fn_for_friction.abs() * r_roll * p.mu_r;
    let m_mag = m.norm();
    if m_mag > m_max {
        m *= m_max / m_mag;
        put3(hist, &m);
    } else {
        put3(hist, &m);
        m += w * r_coef;
    }
    out.torque_i -= m;
    if !c.is_wall() {
        out.torque_j += m;
    }
}
