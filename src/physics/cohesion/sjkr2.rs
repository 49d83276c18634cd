//! LIGGGHTS `cohesion sjkr2` (source `cohesion_model_sjkr2.h`): F = -k A with
//! the linearised area A = 2 pi (2 R*) delta_n for pairs and
//! A = 2 pi R delta_n for walls (R, not 2R: as the source writes it).

use crate::physics::{CohesionLaw, Contact, ContactOut, PairParams};

/// LIGGGHTS `cohesion sjkr2`. Reads `cohesion` (energy density, J/m^3).
#[derive(Clone, Copy, Debug, Default)]
pub struct LiggghtsSjkr2 {
    /// `tangential_reduce on` (see [`super::sjkr::LiggghtsSjkr`]).
    pub tangential_reduce: bool,
}

impl CohesionLaw for LiggghtsSjkr2 {
    const HISTORY: usize = 0;
    const NONCONTACT: bool = false;
    #[inline(always)]
    fn cohesion(&self, c: &Contact, p: &PairParams, _hist: &mut [f64], out: &mut ContactOut) {
        let two_pi = 2.0 * std::f64::consts::PI;
        let a_cont = if c.is_wall() { two_pi * c.ri * c.delta } else { two_pi * (2.0 * c.r_eff) * c.delta };
        let f_coh = -p.cohesion * a_cont;
        out.fn_coh += f_coh;
        if self.tangential_reduce {
            out.fn_for_friction += f_coh;
        }
    }
}
