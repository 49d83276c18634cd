//! demx `tangential history/paper`: the paper's modified Cundall-Strack
//! friction (Elekes & Parteli 2021, Eq. 11):
//!
//! F_t = -min(mu |F^c_n|, |int k_t sqrt(delta) ds + A_t sqrt(delta) v_t|) e_t
//!
//! The spring is the path integral of k_t sqrt(delta(t)) ds, accumulated
//! incrementally (each step adds the normal law's current stiffness
//! k_t sqrt(delta) times v_t dt), so it differs from LIGGGHTS `history`
//! (current stiffness times total displacement) when delta changes during
//! the contact. The damping A_t sqrt(delta) v_t comes from the normal law
//! (`out.gamma_t`). The cap is on the total (spring + damping), as Eq. 11
//! writes it; on slip the stored spring is set to the cap along the force
//! (Cundall-Strack). The spring is kept in the tangent plane (normal part
//! projected out each step). Relative velocity and torque use the
//! LIGGGHTS contact-point distance R - delta/2 (the paper writes the torque
//! lever as d/2 - delta; the difference is delta/2 << d).

use super::{add_tangential_torque_lanes, get3_lanes, liggghts_levers_lanes, put3_lanes, rel_tangential_velocity_lanes};
use crate::physics::lanes::{Coeffs, Real, Vec3};
use crate::physics::{on_one, Contact, ContactL, ContactOut, OutL, PairParams, TangentialLaw};

/// The paper's Cundall-Strack friction. Reads `mu`; `out.kt`, `out.gamma_t`,
/// `out.fn_for_friction`. History: the spring force (3, N).
#[derive(Clone, Copy, Debug, Default)]
pub struct PaperCundallStrack;

impl TangentialLaw for PaperCundallStrack {
    const HISTORY: usize = 3;
    /// The spring force is built from v_t, the relative tangential velocity of
    /// the contact points, which turns with the pair (v_i - v_j and n flip,
    /// the spin part (l_i w_i + l_j w_j) x n flips with n): -1 each.
    const FLIP: &'static [f64] = &[-1.0, -1.0, -1.0];
    const LANES: bool = true;
    #[inline(always)]
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.tangential_lanes(c, p, hist, o));
    }
    #[inline(always)]
    fn tangential_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, hist: &mut [R], out: &mut OutL<R>) {
        let (cri, crj) = liggghts_levers_lanes(c);
        let v_t = rel_tangential_velocity_lanes(c, cri, crj);
        let mut spring = get3_lanes(hist);
        spring -= c.n * spring.dot(&c.n);
        spring += v_t * (out.kt * c.dt);
        let total = spring + v_t * out.gamma_t;
        let cap = p.get(|q| q.mu) * out.fn_for_friction.abs();
        let mag = total.norm();
        // slip: the total scaled onto the cap, and the spring set to it
        let slip = mag.gt(cap);
        let capped = total * (cap / mag);
        spring = Vec3::select(slip, capped, spring);
        let ft = -Vec3::select(slip, capped, total);
        put3_lanes(hist, &spring);
        out.ft = ft;
        add_tangential_torque_lanes(c, &ft, cri, crj, out);
    }
}
