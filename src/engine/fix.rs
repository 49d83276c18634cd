//! Fixes: per-pass trait objects hooked into the time step in LAMMPS order
//! (initial_integrate, pre_exchange, post_force, final_integrate,
//! end_of_step).

use super::sim::Sim;
use crate::error::Result;
use crate::physics::V3;
use crate::script::Variables;

/// The hooks that may run particle by particle, fused into one pass over
/// the particles (see [`Fix::local`]): the step's head (before the pair
/// pass) and its tail (after it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hook {
    /// [`Fix::initial_integrate`] (the head).
    InitialIntegrate,
    /// [`Fix::post_force`].
    PostForce,
    /// [`Fix::final_integrate`].
    FinalIntegrate,
}

/// How a fix takes part in a hook at this step.
pub enum Local {
    /// The hook does nothing at this step.
    Nothing,
    /// The hook changes each particle from that particle's own entries
    /// alone, so the step may run it chunk by chunk, fused with the stages
    /// around it: every particle still meets the stages in the fixes' order,
    /// so each particle's sums are the same bits as with one pass per hook.
    Stage(Box<dyn Stage>),
    /// The hook needs the whole simulation: it is called as it is.
    Whole,
}

/// A hook's per-particle form.
pub trait Stage: Send + Sync {
    /// Apply to the particles of `c`.
    fn apply(&self, c: &mut Chunk<'_>);

    /// One stage doing this stage and then `next`, particle by particle,
    /// with the same operations in the same order, where that saves work
    /// (the integration's two halves share their divisions); `None` where
    /// the two stay apart.
    fn then(&self, _next: &dyn Stage) -> Option<Box<dyn Stage>> {
        None
    }

    /// The integration's first half, when this stage is one (for [`Stage::then`]).
    fn initial_half(&self) -> Option<&super::integrate::InitialHalf> {
        None
    }
}

/// The particles `lo..lo + v.len()` of a fused pass: their own entries to
/// change, and the whole arrays that no stage changes, to read (indexed by
/// particle).
pub struct Chunk<'a> {
    /// Index of the chunk's first particle.
    pub lo: usize,
    /// The chunk's positions.
    pub x: &'a mut [V3],
    /// Radii (all particles).
    pub radius: &'a [f64],
    /// Masses (all particles).
    pub mass: &'a [f64],
    /// Types (all particles).
    pub kind: &'a [u32],
    /// Group bits (all particles).
    pub mask: &'a [u32],
    /// The chunk's velocities.
    pub v: &'a mut [V3],
    /// The chunk's angular velocities.
    pub omega: &'a mut [V3],
    /// The chunk's forces.
    pub f: &'a mut [V3],
    /// The chunk's torques.
    pub torque: &'a mut [V3],
    /// The chunk's frozen flags (fix freeze).
    pub frozen: &'a mut [bool],
    /// The chunk's entries of each extra per-atom column (`width` values per
    /// particle, in the order of `Particles::extra`).
    pub extra: Vec<&'a mut [f64]>,
}

impl<'a> Chunk<'a> {
    /// `p` cut into chunks of `size` particles (the last one shorter).
    pub fn split(p: &'a mut super::particles::Particles, size: usize) -> Vec<Chunk<'a>> {
        let super::particles::Particles { x, radius, mass, kind, mask, v, omega, f, torque, frozen, extra, .. } = p;
        let n = x.len();
        let (radius, mass, kind, mask) = (&radius[..], &mass[..], &kind[..], &mask[..]);
        // each extra column cut at the chunks
        let mut cols: Vec<std::slice::ChunksMut<'_, f64>> =
            extra.iter_mut().map(|e| e.data[..n * e.width].chunks_mut(size * e.width.max(1))).collect();
        x.chunks_mut(size)
            .zip(v.chunks_mut(size))
            .zip(omega.chunks_mut(size))
            .zip(f.chunks_mut(size))
            .zip(torque.chunks_mut(size))
            .zip(frozen.chunks_mut(size))
            .enumerate()
            .map(|(c, (((((x, v), omega), f), torque), frozen))| Chunk {
                lo: c * size,
                x,
                radius,
                mass,
                kind,
                mask,
                v,
                omega,
                f,
                torque,
                frozen,
                extra: cols.iter_mut().map(|it| it.next().unwrap_or_default()).collect(),
            })
            .collect()
    }
}

/// A fix (LAMMPS `fix ID group style ...`). Hooks get the whole simulation
/// with this fix taken out of it for the call.
pub trait Fix: Send {
    /// The fix id.
    fn id(&self) -> &str;
    /// The style name as written in the deck.
    fn style(&self) -> &str;
    /// The region this fix looks up by name at each run's start (as LAMMPS's
    /// `fix wall/gran/region`).
    fn region(&self) -> Option<&str> {
        None
    }
    /// The region of [`Fix::region`] was deleted and defined again: use the
    /// new definition from now on.
    fn replace_region(&mut self, _region: &crate::geom::Region) {}
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
    /// How this fix's `hook` acts at this step: not at all, particle by
    /// particle (a [`Stage`], run fused with its neighbours instead of the
    /// hook), or on the whole simulation (the hook is called). Called in the
    /// hooks' order, but before earlier fixes' stages have run, so a stage
    /// must not depend on what they change; and for the tail's hooks before
    /// the step's pair forces are computed (a stage's `apply` sees them,
    /// this call must not read them). The default calls the hook.
    fn local(&mut self, _hook: Hook, _sim: &Sim, _vars: &Variables) -> Result<Local> {
        Ok(Local::Whole)
    }
    /// End of step (print, ave/time, checks).
    fn end_of_step(&mut self, _sim: &mut Sim, _vars: &Variables) -> Result<()> {
        Ok(())
    }
    /// Whether `end_of_step` may do anything at `step`. When no fix's is
    /// due and no output is, the step's tail runs fused with the next
    /// step's head, and `end_of_step` is not called at that step. The
    /// default says yes; a fix without an end_of_step says no.
    fn end_of_step_due(&self, _step: i64) -> bool {
        true
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
    /// What a checkpoint must keep of this fix beyond what its command sets
    /// up again (`demx run --checkpoint`). The default says a checkpoint
    /// cannot be taken while the fix exists, so that a fix added later
    /// without this never resumes wrong.
    fn save_state(&self) -> FixState {
        FixState::Unsupported
    }
    /// Put back what [`Fix::save_state`] kept.
    fn load_state(&mut self, _state: &serde_json::Value) -> std::result::Result<(), String> {
        Ok(())
    }
}

/// A fix's part of a checkpoint ([`Fix::save_state`]).
pub enum FixState {
    /// Everything it holds is set by its command or lives in the particles
    /// and the pair list, or is a cache that gives the same bits when
    /// rebuilt.
    Stateless,
    /// Its changing state.
    Saved(serde_json::Value),
    /// It holds state a checkpoint cannot keep yet.
    Unsupported,
}

/// [`Fix::save_state`] for a fix whose command sets everything it holds.
#[macro_export]
macro_rules! stateless_fix {
    () => {
        fn save_state(&self) -> $crate::engine::fix::FixState {
            $crate::engine::fix::FixState::Stateless
        }
    };
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

/// [`Fix::local`] for a fix that has none of initial_integrate, post_force
/// and final_integrate: nothing at any of those hooks, so it does not split
/// the step's fused head or tail.
#[macro_export]
macro_rules! no_step_hooks {
    () => {
        fn local(
            &mut self,
            _hook: $crate::engine::fix::Hook,
            _sim: &$crate::engine::sim::Sim,
            _vars: &$crate::script::Variables,
        ) -> $crate::error::Result<$crate::engine::fix::Local> {
            Ok($crate::engine::fix::Local::Nothing)
        }
    };
}

/// `Fix::local` for a fix whose only step hook is `post_force` (a whole
/// pass): it has nothing to do at the head or the end of the tail, so the
/// fused stages around it are not split there; nor at the end of the step.
#[macro_export]
macro_rules! post_force_only {
    () => {
        fn local(
            &mut self,
            hook: $crate::engine::fix::Hook,
            _sim: &$crate::engine::sim::Sim,
            _vars: &$crate::script::Variables,
        ) -> $crate::error::Result<$crate::engine::fix::Local> {
            Ok(if hook == $crate::engine::fix::Hook::PostForce { $crate::engine::fix::Local::Whole } else { $crate::engine::fix::Local::Nothing })
        }
        fn end_of_step_due(&self, _step: i64) -> bool {
            false
        }
    };
}

/// Placeholder put in a fix's slot while its hook runs.
pub struct Hole;
impl Fix for Hole {
    crate::no_step_hooks!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        ""
    }
    fn style(&self) -> &str {
        ""
    }
}
