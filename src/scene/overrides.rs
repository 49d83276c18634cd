//! Command-line overrides of a deck's accuracy settings (`demx run
//! --dt-fraction F --youngs-scale S`), used by `demx tradeoff` to trade
//! accuracy for speed without editing the deck.
//!
//! - `youngs_scale S`: every stiffness of the scene is divided by S: the
//!   effective Young's and shear moduli of LIGGGHTS materials (`fix
//!   property/global youngsModulus`, hence also LIGGGHTS walls, which share
//!   the table), `kn`/`kt` of LIGGGHTS `.../stiffness` models, LAMMPS
//!   `gran/*` Kn and Kt, LAMMPS `granular` E (hertz/material), kn and kt,
//!   and the same coefficients of LAMMPS walls. Damping constants that the
//!   laws derive from the stiffness (LIGGGHTS restitution, Tsuji) follow;
//!   absolute damping constants (LAMMPS gamma_n) do not. The modulus bounds
//!   LIGGGHTS checks (`hard_particles`, Y >= 5e6 Pa in SI) apply to the deck's
//!   values, before the scale.
//! - `dt_fraction F`: the time step becomes F times the Hertz collision time
//!   that `demx check` reports ([`super::summary::timestep_check`]: two equal
//!   spheres of the smallest/stiffest kind at the fastest particle speed, or
//!   the free-fall speed over the box height; the collision period for linear
//!   springs). It replaces the value of each `timestep` command where that
//!   time is computable (contact model, materials and particles or particle
//!   templates defined), otherwise it is applied at the start of the next
//!   `run`. Run lengths stay the deck's step counts: a deck that derives its
//!   step counts from its own time step (as templates/heap/in.heap does)
//!   should vary its own variables instead (`var:dtfrac`).

use super::Session;
use crate::error::{Error, Result};
use crate::script::Span;

/// The overrides of one session (none by default).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Time step as a fraction of the Hertz collision time.
    pub dt_fraction: Option<f64>,
    /// Divide every stiffness by this.
    pub youngs_scale: Option<f64>,
    /// The time step override still has to be applied (set until a
    /// `timestep` command or a run could compute it).
    pub dt_pending: bool,
}

impl Overrides {
    /// Overrides from the command-line values; error unless positive and finite.
    pub fn new(dt_fraction: Option<f64>, youngs_scale: Option<f64>) -> Result<Overrides> {
        for (name, v) in [("--dt-fraction", dt_fraction), ("--youngs-scale", youngs_scale)] {
            if let Some(v) = v {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(Error::usage(format!("{name} must be a positive number (got {v})")));
                }
            }
        }
        Ok(Overrides { dt_fraction, youngs_scale, dt_pending: dt_fraction.is_some() })
    }

    /// The stiffness divisor (1 without override).
    pub fn stiffness_divisor(&self) -> f64 {
        self.youngs_scale.unwrap_or(1.0)
    }
}

/// Divide the stiffnesses of a coefficient table by the `youngs_scale`
/// override (no-op without it).
pub fn scale_table(s: &Session, table: &mut crate::engine::kernel::ParamTable) {
    let k = s.overrides.stiffness_divisor();
    if k == 1.0 {
        return;
    }
    for p in table.params.iter_mut() {
        p.y_eff /= k;
        p.g_eff /= k;
        p.kn /= k;
        p.kt /= k;
    }
}

/// After a `timestep` command: replace the time step when the Hertz time is
/// computable, else leave the override pending for the next run.
pub fn after_timestep(s: &mut Session) {
    if s.overrides.dt_fraction.is_some() {
        s.overrides.dt_pending = true;
        let _ = apply_dt(s);
    }
}

/// At the start of a run: apply a pending time step override; error when the
/// Hertz time cannot be computed.
pub fn before_run(s: &mut Session, span: Span) -> Result<()> {
    if s.overrides.dt_pending && !apply_dt(s) {
        return Err(Error::deck(
            span,
            "--dt-fraction: cannot compute the Hertz collision time here (it needs a contact model with materials, and particles or particle templates)",
        ));
    }
    Ok(())
}

/// Set dt = dt_fraction * Hertz time if computable; true when applied.
fn apply_dt(s: &mut Session) -> bool {
    let Some(f) = s.overrides.dt_fraction else { return true };
    let Some(tc) = super::summary::timestep_check(s) else { return false };
    if !(tc.hertz_time > 0.0 && tc.hertz_time.is_finite()) {
        return false;
    }
    let old = s.sim.dt;
    s.sim.dt = f * tc.hertz_time;
    s.overrides.dt_pending = false;
    let msg = format!(
        "demx: --dt-fraction {f}: timestep {:.6e} s replaces {old:.6e} s (Hertz time {:.6e} s at {:.4} m/s; run lengths stay the deck's steps)",
        s.sim.dt, tc.hertz_time, tc.impact_speed
    );
    s.sim.log.line(&msg);
    true
}
