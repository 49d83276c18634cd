//! LIGGGHTS `cohesion sjkr` (source `cohesion_model_sjkr.h`, doc
//! `gran_cohesion_sjkr.txt`): F = -k A with k = `cohesionEnergyDensity`;
//! pair contact area A = pi/4 (d-Ri-Rj)(d+Ri-Rj)(d-Ri+Rj)(d+Ri+Rj) / d^2
//! (the circle where the two spheres intersect, sign flipped), wall
//! A = pi (R^2 - d^2), d the centre distance.

use crate::physics::lanes::{Coeffs, Real};
use crate::physics::{on_one, CohesionLaw, Contact, ContactL, ContactOut, OutL, PairParams};

/// LIGGGHTS `cohesion sjkr`. Reads `cohesion` (energy density, J/m^3).
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsSjkr {
    /// `tangential_reduce on`: the cohesive force also lowers the normal
    /// force of the Coulomb and rolling caps.
    pub tangential_reduce: bool,
}

impl CohesionLaw for LiggghtsSjkr {
    const HISTORY: usize = 0;
    const NONCONTACT: bool = false;
    #[inline(always)]
    fn cohesion(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut) {
        on_one(c, out, |c, o| self.cohesion_lanes(c, p, hist, o));
    }
    const LANES: bool = true;
    #[inline(always)]
    fn cohesion_lanes<R: Real, P: Coeffs<R>>(&self, c: &ContactL<R>, p: &P, _hist: &mut [R], out: &mut OutL<R>) {
        use std::f64::consts::PI;
        let d = c.r;
        let a_cont = if c.wall {
            (c.ri * c.ri - d * d) * PI
        } else {
            let (ri, rj) = (c.ri, c.rj);
            ((d - ri - rj) * (d + ri - rj) * (d - ri + rj) * (d + ri + rj)) * (-PI / 4.0) / (d * d)
        };
        let f_coh = -p.get(|q| q.cohesion) * a_cont;
        out.fn_coh += f_coh;
        if self.tangential_reduce {
            out.fn_for_friction += f_coh;
        }
    }
}
