//! Fixes: per-pass trait objects hooked into the time step in LAMMPS order
//! (initial_integrate, pre_exchange, post_force, final_integrate,
//! end_of_step).

use super::sim::Sim;
use crate::error::Result;
use crate::script::Variables;

/// A fix (LAMMPS `fix ID group style ...`). Hooks get the whole simulation
/// with this fix taken out of it for the call.
pub trait Fix: Send {
    /// The fix id.
    fn id(&self) -> &str;
    /// The style name as written in the deck.
    fn style(&self) -> &str;
    /// Called at the start of every run (after the scene is complete).
    fn setup(&mut self, _sim: &mut Sim) -> Result<()> {
        Ok(())
    }
    /// Integration, first half.
    fn initial_integrate(&mut self, _sim: &mut Sim) {}
    /// Before neighbour lists are rebuilt (insertion, deletion).
    fn pre_exchange(&mut self, _sim: &mut Sim, _vars: &Variables) -> Result<()> {
        Ok(())
    }
    /// The step at which this fix needs a rebuild (insertion steps).
    fn next_reneighbor(&self) -> Option<i64> {
        None
    }
    /// After pair forces (gravity, walls, addforce, freeze, viscous).
    fn post_force(&mut self, _sim: &mut Sim, _vars: &Variables) -> Result<()> {
        Ok(())
    }
    /// Output at the start of a run, after the setup forces (LAMMPS fix
    /// print prints at the first step of a run when it is a multiple of N).
    fn setup_output(&mut self, _sim: &mut Sim, _vars: &Variables) -> Result<()> {
        Ok(())
    }
    /// Integration, second half.
    fn final_integrate(&mut self, _sim: &mut Sim) {}
    /// End of step (print, ave/time, checks).
    fn end_of_step(&mut self, _sim: &mut Sim, _vars: &Variables) -> Result<()> {
        Ok(())
    }
    /// Global scalar `f_ID`.
    fn scalar(&self, _sim: &Sim) -> Option<f64> {
        None
    }
    /// Global vector element `f_ID[i]` (1-based).
    fn vector(&self, _sim: &Sim, _i: usize) -> Option<f64> {
        None
    }
    /// One line for `demx check`.
    fn summary(&self) -> String {
        format!("fix {} {}", self.id(), self.style())
    }
    /// Whether this fix integrates particles (for the "no integrator" warning).
    fn integrates(&self) -> bool {
        false
    }
    /// The deepest overlap of any particle with this fix's surfaces (walls),
    /// as (particle index, overlap / particle radius); None when the fix has
    /// no surfaces or nothing touches them. Read by the stability guard every
    /// few steps, so it must not change any state.
    fn max_surface_overlap(&self, _sim: &Sim) -> Option<(usize, f64)> {
        None
    }
    /// Overlap depth (length) of particle `i` with this fix's surfaces, if
    /// it touches one (the stability guard's diagnosis).
    fn surface_overlap(&self, _sim: &Sim, _i: usize) -> Option<f64> {
        None
    }
    /// Downcasting hook (insertion templates, gravity, ...).
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
}

/// The deepest surface overlap among the particles of `group`, as
/// (particle index, overlap / radius): [`Fix::max_surface_overlap`] for a
/// wall fix that knows each particle's overlap (`overlap(i)`).
pub fn deepest_overlap(sim: &Sim, group: u32, overlap: impl Fn(usize) -> Option<f64>) -> Option<(usize, f64)> {
    let p = &sim.particles;
    let mut worst: Option<(usize, f64)> = None;
    for i in 0..p.len() {
        if p.mask[i] & group == 0 {
            continue;
        }
        if let Some(d) = overlap(i) {
            let f = d / p.radius[i];
            if worst.is_none_or(|w| f > w.1) {
                worst = Some((i, f));
            }
        }
    }
    worst
}

/// Placeholder put in a fix's slot while its hook runs.
pub struct Hole;
impl Fix for Hole {
    fn id(&self) -> &str {
        ""
    }
    fn style(&self) -> &str {
        ""
    }
}
