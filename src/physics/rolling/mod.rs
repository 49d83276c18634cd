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
pub mod marshall;
pub mod paper;
pub mod sds;

use super::lanes::{Coeffs, Real, Vec3};
use super::tangential::{get3_lanes, put3_lanes};
use super::{on_one, Contact, ContactL, ContactOut, OutL, PairParams, V3};

/// LIGGGHTS relative rotation and rolling radius of a contact:
/// (w_i - w_j, R*) for pairs, ((R - delta/2)/d w_i, R) for walls.
#[inline(always)]
pub(crate) fn liggghts_rotation(c: &Contact) -> (V3, f64) {
    let (w, r) = liggghts_rotation_lanes(&ContactL::one(c));
    (w.into(), r)
}

/// [`liggghts_rotation`] on lanes.
#[inline(always)]
pub(crate) fn liggghts_rotation_lanes<R: Real>(c: &ContactL<R>) -> (Vec3<R>, R) {
    if c.wall {
        (c.wi * ((c.ri - c.delta * 0.5) / c.r), c.ri)
    } else {
        (c.wi - c.wj, c.r_eff)
    }
}

/// LIGGGHTS rolling inertia I_r (3D): 1.4 m R^2 for walls, else
/// 1.4 (mi ri^2)(mj rj^2)/(mi ri^2 + mj rj^2); a frozen particle (infinite
/// mass) on either side leaves the other's 1.4 m R^2, as a wall does.
#[inline(always)]
pub(crate) fn liggghts_rolling_inertia(c: &Contact) -> f64 {
    let ii = c.mi * c.ri * c.ri;
    if c.is_wall() || c.mj.is_infinite() {
        1.4 * ii
    } else if c.mi.is_infinite() {
        1.4 * (c.mj * c.rj * c.rj)
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
    on_one(c, out, |c, o| epsd_torque_lanes(c, p, hist, o, k_r, r_coef, torsion, r_roll, w_rel.into()));
}

/// [`epsd_torque`] on lanes: the one implementation.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn epsd_torque_lanes<R: Real, P: Coeffs<R>>(
    c: &ContactL<R>,
    p: &P,
    hist: &mut [R],
    out: &mut OutL<R>,
    k_r: R,
    r_coef: R,
    torsion: bool,
    r_roll: R,
    w_rel: Vec3<R>,
) {
    let w = if torsion { w_rel } else { w_rel - c.n * w_rel.dot(&c.n) };
    let m = get3_lanes(hist) + w * (k_r * c.dt);
    let m_max = out.fn_for_friction.abs() * r_roll * p.get(|q| q.mu_r);
    let m_mag = m.norm();
    // over the cap: the spring torque scaled onto it and no dashpot
    let capped = m_mag.gt(m_max);
    let m_cap = m * (m_max / m_mag);
    put3_lanes(hist, &Vec3::select(capped, m_cap, m));
    let m = Vec3::select(capped, m_cap, m + w * r_coef);
    out.torque_i -= m;
    if !c.wall {
        out.torque_j += m;
    }
}
