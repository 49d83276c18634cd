//! The simulation state and the run loop (LAMMPS `Verlet::run` order).

use super::compute::Compute;
use super::domain::Domain;
use super::fix::{Chunk, Fix, Hole, Hook, Local, Stage};
use super::kernel::{cross_gather, cross_gather_chunk, ContactKernel, Forces, ParamTable, PassState, Shared, Virial};
use super::neighbor::{Due, NeighSettings, PairList, Travel};
use super::output::{Dump, Logger, Thermo};
use super::particles::Particles;
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{EvalContext, Variables};
use std::time::Instant;

/// Particles per chunk of the step's fused head and tail ([`Sim::fused`]): small enough
/// that a chunk's entries stay in cache from one stage to the next, and that
/// two threads get equal shares of a 30,000-particle bed.
const TAIL_CHUNK: usize = 1024;

super::switch::switch!(
    /// Tests switch it on to call every hook of the step's head and tail on
    /// its own, as one pass per hook, to check that fusing gives the same
    /// bits.
    UNFUSED
);

/// Run `f` with the step's head and tail unfused on this thread (tests).
pub fn with_unfused_tail<T>(f: impl FnOnce() -> T) -> T {
    UNFUSED.on_during(f)
}

/// The stages of a fused run on one chunk, then its travel when `measure`
/// ([`PairList::travel`] with `lim`).
fn finish(mut c: Chunk<'_>, stages: &[Box<dyn Stage>], pairs: &PairList, measure: bool, lim: Option<f64>) -> Travel {
    for st in stages {
        st.apply(&mut c);
    }
    if measure {
        pairs.travel(c.x, c.lo, lim)
    } else {
        Travel::default()
    }
}

/// Which engine's conventions a deck follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Dialect {
    /// LIGGGHTS 3.x (`pair_style gran model ...`).
    Liggghts,
    /// LAMMPS (`pair_style granular`, `gran/hooke/history`, ...).
    Lammps,
}

/// The contact model of the scene, ready to run.
pub struct PairModel {
    /// The monomorphised kernel.
    pub kernel: Box<dyn ContactKernel>,
    /// Coefficients per type pair.
    pub table: ParamTable,
    /// Human summary, e.g. `hertz + tangential history`.
    pub summary: String,
}

/// Everything a run needs.
pub struct Sim {
    /// Deck dialect.
    pub dialect: Dialect,
    /// The box (None before create_box / read_data).
    pub domain: Option<Domain>,
    /// Number of atom types.
    pub ntypes: usize,
    /// The particles.
    pub particles: Particles,
    /// Group names; index = bit.
    pub groups: Vec<String>,
    /// Neighbour settings.
    pub neigh: NeighSettings,
    /// Pair list with history.
    pub pairs: PairList,
    /// Deferred shares of cross-block pairs (scratch of the force pass).
    pub pair_defer: Vec<[V3; 2]>,
    /// Pair virial of the last force evaluation: the trace always, the
    /// tensor where that pass summed it ([`Sim::tensor_at`]).
    pub pair_virial: Virial,
    /// The step whose force pass summed the virial tensor last.
    pub tensor_at: Option<i64>,
    /// Sum the virial tensor on every step, not only where thermo prints
    /// it: a variable reads a tensor keyword (set at each run's start).
    pub tensor_every_step: bool,
    /// The contact model (None: no pair interactions).
    pub model: Option<PairModel>,
    /// Fixes in definition order.
    pub fixes: Vec<Box<dyn Fix>>,
    /// Computes.
    pub computes: Vec<Compute>,
    /// Thermo settings.
    pub thermo: Thermo,
    /// Dumps.
    pub dumps: Vec<Box<dyn Dump>>,
    /// Screen and log output.
    pub log: Logger,
    /// Current step.
    pub step: i64,
    /// Step at the start of the current run (`elapsed`).
    pub run_start: i64,
    /// Atoms counted for the temperature's degrees of freedom: LAMMPS's
    /// `compute temp` counts them when a run is set up, so atoms inserted
    /// during a run do not change its dof (None until the first run's setup).
    pub dof_natoms: Option<usize>,
    /// `compute_modify thermo_temp dynamic/dof yes`: count them every time.
    pub dof_dynamic: bool,
    /// Last step of the current run.
    pub run_end: i64,
    /// `run ... start S stop E` bounds for ramp() and friends.
    pub run_bounds: Option<(i64, i64)>,
    /// Time step size.
    pub dt: f64,
    /// Simulated time.
    pub time: f64,
    /// Particles lost through fixed boundaries so far.
    pub lost: u64,
    /// A rebuild is wanted at the next step (particles added/removed).
    pub force_rebuild: bool,
    /// Wall-clock start of the current run.
    pub clock: Instant,
    /// Whether to actually integrate (false for `demx check`).
    pub dry: bool,
    /// The setup force evaluation of a run is in progress ([`Sim::setup`]):
    /// walls leave their contact histories where they are.
    pub setup_pass: bool,
    /// Boltzmann constant of the unit system.
    pub boltz: f64,
    /// Steps per second of the last run.
    pub last_rate: f64,
    /// Particle-steps integrated by this process: over its runs, steps times
    /// the atoms at the run's end, as each run's "Loop time" line counts them
    /// (also for runs with `post no`, which print no such line).
    pub particle_steps: f64,
    /// Time spent per section of the last run: pair, neigh, modify, output.
    pub timing: [f64; 4],
    /// Time the current step's pair pass took (part of its tail when the
    /// two run fused; see [`Sim::fused_pass`]).
    pass_secs: f64,
    /// Pairs the force passes of the current run walked, summed over steps.
    pub walked: u64,
    /// The state came from a restart file: the next run starts from the
    /// saved pair list and forces instead of recomputing them, so it continues
    /// bitwise as the uninterrupted run would have.
    pub resume: bool,
    /// Sort particles in space at the first build unless 0 (LAMMPS
    /// `atom_modify sort N`, default 1000; demx sorts once).
    pub sort_every: i64,
    /// Bin size of the sort (0: half the neighbour cutoff, as LAMMPS).
    pub sort_bin: f64,
    /// Stability guards (`demx_guard`): checks every few steps, last good state.
    pub guard: super::guard::Guard,
}

impl Default for Sim {
    fn default() -> Self {
        Sim {
            dialect: Dialect::Lammps,
            domain: None,
            ntypes: 0,
            particles: Particles::default(),
            groups: vec!["all".into()],
            neigh: NeighSettings::default(),
            pairs: PairList::default(),
            pair_defer: vec![],
            pair_virial: Virial::default(),
            tensor_at: None,
            tensor_every_step: false,
            model: None,
            fixes: vec![],
            computes: vec![],
            thermo: Thermo::default(),
            dumps: vec![],
            log: Logger::default(),
            step: 0,
            run_start: 0,
            dof_natoms: None,
            dof_dynamic: false,
            run_end: 0,
            run_bounds: None,
            dt: 1e-5,
            time: 0.0,
            lost: 0,
            force_rebuild: true,
            clock: Instant::now(),
            dry: false,
            setup_pass: false,
            boltz: 1.3806504e-23,
            last_rate: 0.0,
            particle_steps: 0.0,
            timing: [0.0; 4],
            pass_secs: 0.0,
            walked: 0,
            resume: false,
            sort_every: 1000,
            sort_bin: 0.0,
            guard: super::guard::Guard::default(),
        }
    }
}

impl Sim {
    /// Bit of a group by name.
    pub fn group_bit(&self, name: &str) -> Option<u32> {
        self.groups.iter().position(|g| g == name).map(|k| 1u32 << k)
    }

    /// Run `hook` on every fix in order, each taken out of the list while it runs.
    pub fn each_fix(&mut self, mut hook: impl FnMut(&mut dyn Fix, &mut Sim) -> Result<()>) -> Result<()> {
        for k in 0..self.fixes.len() {
            let mut f = std::mem::replace(&mut self.fixes[k], Box::new(Hole));
            let r = hook(f.as_mut(), self);
            self.fixes[k] = f;
            r?;
        }
        Ok(())
    }

    /// Index of a fix by id.
    pub fn fix_index(&self, id: &str) -> Option<usize> {
        self.fixes.iter().position(|f| f.id() == id)
    }

    /// Wrap, drop lost particles, shrink-wrap and rebuild the pair list.
    pub fn rebuild(&mut self) -> Result<()> {
        let Some(dom) = self.domain.as_mut() else { return Ok(()) };
        let p = &mut self.particles;
        for i in 0..p.len() {
            dom.wrap(&mut p.x[i], &mut p.image[i]);
        }
        let lost: Vec<bool> = p.x.iter().map(|x| dom.outside_fixed(x) || !x.iter().all(|c| c.is_finite())).collect();
        let nlost = lost.iter().filter(|&&l| l).count();
        if nlost > 0 {
            // particles leaving in a blow-up: the guard's diagnosis comes first
            if let Some(e) = super::guard::on_lost(self) {
                return Err(e);
            }
            let p = &mut self.particles;
            match self.thermo.lost {
                super::output::LostPolicy::Error => {
                    let i = lost.iter().position(|&l| l).unwrap_or(0);
                    return Err(Error::runtime(format!(
                        "Lost atoms: original {} current {} at step {} (atom {} at {:?}); use `thermo_modify lost ignore` to delete them",
                        p.len(),
                        p.len() - nlost,
                        self.step,
                        p.tag[i],
                        [p.x[i].x, p.x[i].y, p.x[i].z]
                    )));
                }
                _ => {
                    p.remove_where(&lost);
                    self.lost += nlost as u64;
                }
            }
        }
        let p = &mut self.particles;
        let dom = self.domain.as_mut().ok_or_else(|| Error::runtime("no box"))?;
        dom.shrink_wrap(&p.x);
        // spatial sort (LAMMPS `Atom::sort`), at the first build only: a
        // later sort would need a rebuild at fixed steps (a restarted run does
        // not rebuild when the uninterrupted one does, and a sort reorders the
        // sums), and that rebuild would wrap positions at steps where LAMMPS
        // does not, which its dumps show
        if self.sort_every > 0 && self.pairs.builds == 0 {
            let bin = if self.sort_bin > 0.0 { self.sort_bin } else { 0.5 * (2.0 * p.radius.iter().cloned().fold(0.0, f64::max) + self.neigh.skin) };
            let order = super::neighbor::spatial_order(p, bin);
            if order.iter().enumerate().any(|(k, &o)| k != o) {
                p.permute(&order);
            }
        }
        let signs = self.model.as_ref().map_or(vec![], |m| m.kernel.history_signs());
        // chosen from the travel since the last build or prune, before the build
        let buffer = self.pairs.next_buffer(&self.neigh, self.step);
        let table = self.model.as_ref().map(|m| &m.table);
        let p = &self.particles;
        let dom = self.domain.as_ref().ok_or_else(|| Error::runtime("no box"))?;
        match table {
            Some(t) if t.max_extra_range() > 0.0 => {
                let kinds = &p.kind;
                self.pairs.build(p, dom, &self.neigh, self.step, &signs, |i, j| t.get(kinds[i], kinds[j]).extra_range)
            }
            Some(_) => self.pairs.build(p, dom, &self.neigh, self.step, &signs, |_, _| 0.0),
            None => {
                // no pair style: no pairs, but keep the skin bookkeeping
                self.pairs = PairList { x_built: p.x.clone(), last_build: self.step, ..Default::default() };
                self.pairs.index(p.len());
            }
        }
        self.prune(buffer);
        self.force_rebuild = false;
        Ok(())
    }

    /// Prune the pair list from its last build ([`PairList::prune`]) with
    /// `buffer`; `one_step` checks the travel against it.
    fn prune(&mut self, buffer: f64) {
        let Some(m) = &self.model else { return };
        let (t, p, step) = (&m.table, &self.particles, self.step);
        if t.max_extra_range() > 0.0 {
            let kinds = &p.kind;
            self.pairs.prune(p, &self.neigh, buffer, step, &|i: usize, j: usize| t.get(kinds[i], kinds[j]).extra_range)
        } else {
            self.pairs.prune(p, &self.neigh, buffer, step, &|_: usize, _: usize| 0.0)
        }
    }

    /// Clear forces and compute pair forces.
    pub fn pair_forces(&mut self) {
        self.pair_forces_dt(self.dt);
    }

    /// Clear forces and compute pair forces, advancing contact history by
    /// `dt` (0 in the setup pass: LAMMPS and LIGGGHTS do not update shear
    /// history while `update->setupflag` is set).
    fn pair_forces_dt(&mut self, dt: f64) {
        self.pair_pass(dt);
        let p = &mut self.particles;
        cross_gather(&self.pairs, &self.pair_defer, &mut p.f, &mut p.torque);
    }

    /// The force pass of [`Sim::pair_forces_dt`] without its cross pass,
    /// which the step's fused tail runs (`one_step`).
    fn pair_pass(&mut self, dt: f64) {
        self.pair_virial = Virial::default();
        let tensor = self.tensor_due();
        // a pass without pairs sums a tensor of zeros
        self.tensor_at = tensor.then_some(self.step);
        let p = &mut self.particles;
        let Some(m) = &self.model else {
            p.f.fill(V3::zeros());
            p.torque.fill(V3::zeros());
            return;
        };
        // the force pass clears the forces block by block
        let (mut f, mut torque) = (std::mem::take(&mut p.f), std::mem::take(&mut p.torque));
        let (mut hist, mut live) = self.pairs.take_history();
        let force = Forces { f: &mut f, torque: &mut torque, defer: &mut self.pair_defer, tensor };
        self.pair_virial = m.kernel.force_pass(&PassState::of(&self.particles), &self.pairs, &mut hist, &mut live, &m.table, dt, force, None);
        self.pairs.put_history(hist, live);
        let p = &mut self.particles;
        (p.f, p.torque) = (f, torque);
    }

    /// What a fused run measures ([`Sim::fused`]'s `measure`): whether it
    /// measures the travel at all, and the skin check's limit when it checks
    /// since the last build.
    fn measuring(&self, measure: Option<bool>) -> (bool, Option<f64>) {
        let check = measure == Some(true);
        (check || (measure.is_some() && self.pairs.pruned()), check.then(|| self.neigh.skin_limit()))
    }

    /// Whether the step's pair pass may run fused with its tail
    /// ([`Sim::fused_pass`]).
    fn fusable(&self) -> bool {
        let n = self.particles.len();
        // one block gains nothing: its tail follows its pass either way
        let blocks = n.div_ceil(self.pairs.block_size());
        self.model.is_some() && blocks > 1 && self.pairs.forward && self.pairs.indexed(n) && !UNFUSED.is_on()
    }

    /// The step's pair pass fused with the tail that follows it (the cross
    /// shares, then `stages`, then with `Some(check)` the travel, as
    /// [`Sim::fused`]): each force block is finished as soon as every pass
    /// that touches its particles is done, so on one thread a block's
    /// particles pass through the cache once per step instead of twice (the
    /// pairs reach only later blocks: [`PairList::forward`]). Each particle
    /// meets the same operations in the same order as in the pass and then
    /// the tail, so the bits are theirs.
    fn fused_pass(&mut self, stages: &mut Vec<Box<dyn Stage>>, measure: Option<bool>) -> Travel {
        use std::sync::atomic::{AtomicU64, Ordering};
        use std::sync::{Mutex, PoisonError};
        let start = Instant::now();
        let (measure, lim) = self.measuring(measure);
        let tensor = self.tensor_due();
        let (mut hist, mut live) = self.pairs.take_history();
        let Some(m) = &self.model else { unreachable!("fused pass without a pair model") };
        let Particles { x, radius, mass, kind, mask, v, omega, f, torque, extra, frozen, .. } = &mut self.particles;
        let n = x.len();
        let (mut fv, mut tv) = (std::mem::take(f), std::mem::take(torque));
        let (xp, vp, wp, zp) = (Shared(x.as_mut_ptr()), Shared(v.as_mut_ptr()), Shared(omega.as_mut_ptr()), Shared(frozen.as_mut_ptr()));
        let cols: Vec<(Shared<f64>, usize)> = extra.iter_mut().map(|e| (Shared(e.data.as_mut_ptr()), e.width)).collect();
        let (radius, mass, kind, mask) = (&radius[..], &mass[..], &kind[..], &mask[..]);
        // SAFETY: while the pass runs, positions, velocities, angular
        // velocities and frozen flags are read through these and written
        // only by `tail`,
        // each block's after every pass that reads them is over (the
        // dependency counts of `kernel::fused_blocks`), and by no one else
        let state = unsafe {
            PassState {
                x: std::slice::from_raw_parts(xp.ptr(), n),
                v: std::slice::from_raw_parts(vp.ptr(), n),
                omega: std::slice::from_raw_parts(wp.ptr(), n),
                radius,
                mass,
                kind,
                frozen: std::slice::from_raw_parts(zp.ptr(), n),
                any_frozen: super::kernel::any(std::slice::from_raw_parts(zp.ptr(), n)),
            }
        };
        let bs = self.pairs.block_size();
        let nblocks = n.div_ceil(bs);
        let moved: Vec<Mutex<Travel>> = (0..nblocks).map(|_| Mutex::new(Travel::default())).collect();
        let tail_ns = AtomicU64::new(0);
        let (pairs, pending) = (&self.pairs, &*stages);
        let tail = |s: usize, f: &mut [V3], torque: &mut [V3]| {
            let t = Instant::now();
            let (lo, len) = (s * bs, f.len());
            // SAFETY: block s's entries, which no pass reads any more and no
            // other finish touches (see `state`)
            let (x, v, omega, frozen, extra) = unsafe {
                (
                    std::slice::from_raw_parts_mut(xp.ptr().add(lo), len),
                    std::slice::from_raw_parts_mut(vp.ptr().add(lo), len),
                    std::slice::from_raw_parts_mut(wp.ptr().add(lo), len),
                    std::slice::from_raw_parts_mut(zp.ptr().add(lo), len),
                    cols.iter().map(|&(c, w)| std::slice::from_raw_parts_mut(c.ptr().add(lo * w), len * w)).collect(),
                )
            };
            let travel = finish(Chunk { lo, x, radius, mass, kind, mask, v, omega, f, torque, frozen, extra }, pending, pairs, measure, lim);
            *moved[s].lock().unwrap_or_else(PoisonError::into_inner) = travel;
            tail_ns.fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        };
        let force = Forces { f: &mut fv, torque: &mut tv, defer: &mut self.pair_defer, tensor };
        let virial = m.kernel.force_pass(&state, pairs, &mut hist, &mut live, &m.table, self.dt, force, Some(&tail));
        self.pair_virial = virial;
        self.tensor_at = if tensor { Some(self.step) } else { None };
        self.pairs.put_history(hist, live);
        (self.particles.f, self.particles.torque) = (fv, tv);
        stages.clear();
        // the pass's share of the time: the whole less the finishes' (their
        // time summed over the threads, which ran them side by side)
        let tails = tail_ns.load(Ordering::Relaxed) as f64 * 1e-9 / rayon::current_num_threads() as f64;
        self.pass_secs += (start.elapsed().as_secs_f64() - tails).max(0.0);
        // maxima over the blocks: the same on any thread count
        moved.into_iter().map(|m| m.into_inner().unwrap_or_else(PoisonError::into_inner)).fold(Travel::default(), Travel::max)
    }

    /// Forces at the start of a run (LAMMPS `Verlet::setup`).
    ///
    /// As in LAMMPS (`update->setupflag`), computing the setup forces does not
    /// advance contact history (dt = 0 for pairs; walls do the same in the
    /// post_force that follows their `setup`).
    /// After `read_restart` the saved pair list and forces are used as they are.
    pub fn setup(&mut self, vars: &Variables) -> Result<()> {
        self.each_fix(|f, s| f.setup(s))?;
        if self.resume && self.model.as_ref().map_or(0, |m| m.kernel.history_width()) == self.pairs.width {
            self.resume = false;
            return Ok(());
        }
        self.resume = false;
        self.rebuild()?;
        // the setup force evaluation (LAMMPS/LIGGGHTS `update->setupflag`):
        // contact histories do not advance. A flag of the pass, not of each
        // wall: a run resumed from a restart skips this pass, and its first
        // step must advance the walls' histories as the uninterrupted run's does.
        self.setup_pass = true;
        self.pair_forces_dt(0.0);
        let r = self.each_fix(|f, s| f.post_force(s, vars));
        self.setup_pass = false;
        r?;
        self.each_fix(|f, s| f.setup_output(s, vars))?;
        Ok(())
    }

    /// Run `n` steps. Thermo and dumps are written at step 0 of the run, every
    /// N steps, and at the last step, as LAMMPS does.
    pub fn run(&mut self, n: i64, vars: &Variables, pre: bool, post: bool) -> Result<()> {
        self.run_start = self.step;
        self.run_end = self.step + n;
        self.tensor_every_step = vars.reads_thermo(&super::output::TENSOR_KEYWORDS);
        self.clock = Instant::now();
        self.timing = [0.0; 4];
        self.walked = 0;
        if pre {
            self.dof_natoms = Some(self.particles.len());
        }
        if pre || self.pairs.x_built.len() != self.particles.len() {
            self.setup(vars)?;
        }
        super::guard::check(self, true)?;
        self.output(vars, true)?;
        if self.dry {
            self.step += n;
            self.time += n as f64 * self.dt;
            return Ok(());
        }
        // the other threads stay awake between the step's parallel loops
        let _awake = super::awake::Awake::start();
        let t0 = Instant::now();
        let mut carried = None;
        for _ in 0..n {
            carried = self.one_step(vars, carried)?;
            super::output::show_progress(self, t0, n);
        }
        let secs = t0.elapsed().as_secs_f64();
        self.last_rate = if secs > 0.0 { n as f64 / secs } else { 0.0 };
        self.particle_steps += n as f64 * self.particles.len() as f64;
        if post {
            self.log.line(&self.run_summary(n, secs));
        }
        Ok(())
    }

    /// One step. `carried`: the previous step's tail already ran this
    /// step's head (and advanced the clock), which measured this travel.
    /// Returns the same for the next step when this step's tail runs its
    /// head ([`Sim::fuse_next`]).
    fn one_step(&mut self, vars: &Variables, carried: Option<Travel>) -> Result<Option<Travel>> {
        // one clock reading between sections (each costs ~50 ns here, a
        // tenth of a step of a few hundred particles)
        let t0 = Instant::now();
        let (moved, due) = match carried {
            Some(moved) => (moved, self.due()),
            None => {
                let due = self.advance();
                (self.head(vars, due == Due::Check)?, due)
            }
        };
        let step = self.step;
        let wanted = self.fixes.iter().any(|f| f.next_reneighbor() == Some(step));
        let t1 = Instant::now();
        let build = self.force_rebuild
            || wanted
            || match due {
                Due::Build => true,
                Due::Skip => false,
                Due::Check => self.pairs.checked(self.pairs.beyond_skin(&moved, &self.neigh), &self.neigh, step),
            };
        self.pairs.travel = moved;
        if build {
            self.each_fix(|f, s| f.pre_exchange(s, vars))?;
            self.rebuild()?;
        } else if self.pairs.prune_due(&moved) {
            self.prune(self.pairs.next_buffer(&self.neigh, step));
        }
        let t2 = Instant::now();
        self.walked += self.pairs.a.len() as u64;
        self.pass_secs = 0.0;
        // the step's tail: the pair pass (at the first hook that needs the
        // forces, or fused with the stages before it), the cross-block shares of the pair forces, then
        // every fix's post_force, then every fix's final_integrate, in
        // LAMMPS order. Hooks that act particle by particle ([`Fix::local`])
        // run fused, chunk by chunk, so a bed's forces and velocities pass
        // through the cache once instead of once per hook; each particle
        // meets the same operations in the same order, so the bits are those
        // of one pass per hook. A hook that needs the whole simulation ends
        // the fused run before it and is called as it is.
        let mut gather = true;
        let mut stages = vec![];
        self.hooks(&[Hook::PostForce, Hook::FinalIntegrate], vars, &mut gather, &mut stages)?;
        let next = if self.fuse_next() {
            // nothing reads the state between this tail and the next head:
            // run them as one pass (each particle meets the same operations
            // in the same order, so the bits are those of two passes)
            let due = self.advance();
            self.hooks(&[Hook::InitialIntegrate], vars, &mut gather, &mut stages)?;
            Some(self.fused(&mut stages, gather, Some(due == Due::Check)))
        } else {
            self.fused(&mut stages, gather, None);
            self.each_fix(|f, s| f.end_of_step(s, vars))?;
            if self.guard.due(self.step) {
                super::guard::check(self, false)?;
            }
            None
        };
        let t4 = Instant::now();
        if next.is_none() {
            self.output(vars, false)?;
        }
        let secs = |a: Instant, b: Instant| b.duration_since(a).as_secs_f64();
        self.timing[0] += self.pass_secs;
        self.timing[1] += secs(t1, t2);
        self.timing[2] += secs(t0, t1) + (secs(t2, t4) - self.pass_secs).max(0.0);
        if next.is_none() {
            self.timing[3] += t4.elapsed().as_secs_f64();
        }
        Ok(next)
    }

    /// Start the next step: advance the step and the clock; returns what
    /// that step owes the pair list.
    fn advance(&mut self) -> Due {
        self.step += 1;
        self.time += self.dt;
        self.due()
    }

    /// What this step owes the pair list.
    fn due(&self) -> Due {
        self.pairs.due(self.particles.len(), &self.neigh, self.step)
    }

    /// Whether nothing reads or changes the state between this step's tail
    /// and the next step's head: the run goes on, no fix has an end_of_step
    /// to do ([`Fix::end_of_step_due`]), and neither the guard nor any
    /// output is due. Then the two run as one pass over the particles, so a
    /// bed beyond the cache streams its arrays from memory once per step
    /// instead of twice.
    fn fuse_next(&self) -> bool {
        let step = self.step;
        let every = self.thermo.every;
        step < self.run_end
            && !UNFUSED.is_on()
            && !(every > 0 && step % every == 0)
            && !self.guard.due(step)
            && !self.dumps.iter().any(|d| d.due(step, false))
            && !self.fixes.iter().any(|f| f.end_of_step_due(step))
    }

    /// The step's head: every fix's initial_integrate, fused chunk by chunk
    /// where the fixes act particle by particle (as the tail); the same
    /// pass then measures how far the particles moved ([`PairList::travel`]:
    /// since the last build with `check`, since the last prune while the
    /// list is pruned), at the positions after every fix's
    /// initial_integrate.
    fn head(&mut self, vars: &Variables, check: bool) -> Result<Travel> {
        let mut stages = vec![];
        self.hooks(&[Hook::InitialIntegrate], vars, &mut false, &mut stages)?;
        if UNFUSED.is_on() {
            // the check on its own, as tests compare
            return Ok(self.pairs.travel_all(&self.particles.x, check.then(|| self.neigh.skin_limit())));
        }
        Ok(self.fused(&mut stages, false, Some(check)))
    }

    /// Every fix's `hooks`, in order: a fix's stage joins the pending
    /// `stages`, a whole hook first runs them (and the cross pass, while
    /// `gather`) and is then called. Leaves the stages still pending.
    fn hooks(&mut self, hooks: &[Hook], vars: &Variables, gather: &mut bool, stages: &mut Vec<Box<dyn Stage>>) -> Result<()> {
        let fuse = !UNFUSED.is_on();
        for &hook in hooks {
            for k in 0..self.fixes.len() {
                let mut fix = std::mem::replace(&mut self.fixes[k], Box::new(Hole));
                let local = if fuse { fix.local(hook, self, vars) } else { Ok(Local::Whole) };
                let local = match local {
                    Ok(Local::Whole) => {
                        self.fused(stages, std::mem::take(gather), None);
                        match hook {
                            Hook::PostForce => fix.post_force(self, vars).map(|_| Local::Nothing),
                            Hook::InitialIntegrate => {
                                fix.initial_integrate(self);
                                Ok(Local::Nothing)
                            }
                            Hook::FinalIntegrate => {
                                fix.final_integrate(self);
                                Ok(Local::Nothing)
                            }
                        }
                    }
                    other => other,
                };
                self.fixes[k] = fix;
                if let Local::Stage(st) = local? {
                    match stages.last().and_then(|last| last.then(&*st)) {
                        Some(both) => *stages.last_mut().expect("a last stage") = both,
                        None => stages.push(st),
                    }
                }
            }
        }
        Ok(())
    }

    /// Run the step's pair pass and its cross pass (when `gather`; fused
    /// with what follows where [`Sim::fusable`]), then `stages`, then, with
    /// `Some(check)`, measure the travel (since the last build when
    /// `check`, since the last prune while the list is pruned; returned)
    /// over the particles in fixed chunks, in parallel from two chunks up;
    /// empties `stages`.
    fn fused(&mut self, stages: &mut Vec<Box<dyn Stage>>, gather: bool, measure: Option<bool>) -> Travel {
        if gather {
            // the step's pair pass is still to run
            if self.fusable() {
                return self.fused_pass(stages, measure);
            }
            let t = Instant::now();
            self.pair_pass(self.dt);
            self.pass_secs += t.elapsed().as_secs_f64();
        }
        let (measure, lim) = self.measuring(measure);
        if stages.is_empty() && !gather && !measure {
            return Travel::default();
        }
        let cross = gather && !self.pairs.cross.is_empty();
        let (pairs, defer) = (&self.pairs, &self.pair_defer[..]);
        let jobs = Chunk::split(&mut self.particles, TAIL_CHUNK);
        let pending = &*stages;
        let run = |c: Chunk<'_>| -> Travel {
            if cross {
                cross_gather_chunk(pairs, defer, c.lo, c.f, c.torque);
            }
            finish(c, pending, pairs, measure, lim)
        };
        // maxima over the chunks: the same on any thread count
        let moved = if jobs.len() > 1 {
            use rayon::prelude::*;
            jobs.into_par_iter().map(run).reduce(Travel::default, Travel::max)
        } else {
            jobs.into_iter().fold(Travel::default(), |a, c| a.max(run(c)))
        };
        stages.clear();
        moved
    }

    /// Thermo and dumps due at this step.
    fn output(&mut self, vars: &Variables, first: bool) -> Result<()> {
        let last = self.step == self.run_end;
        let every = self.thermo.every;
        if first || last || (every > 0 && self.step % every == 0) {
            if first {
                let h = self.thermo.header(self);
                self.log.line(&h);
            }
            let line = self.thermo.line(self, vars)?;
            self.log.line(&line);
        }
        for k in 0..self.dumps.len() {
            let due = self.dumps[k].due(self.step, first);
            if due {
                let mut d = std::mem::replace(&mut self.dumps[k], Box::new(super::output::NoDump));
                let r = d.write(self);
                self.dumps[k] = d;
                r?;
            }
        }
        Ok(())
    }

    fn run_summary(&self, n: i64, secs: f64) -> String {
        let np = self.particles.len();
        let mut s = format!("Loop time of {} on 1 procs for {} steps with {} atoms\n", crate::io::cfmt::fmt_g(secs, 6), n, np);
        let total = secs.max(1e-300);
        let names = ["Pair", "Neigh", "Modify", "Output"];
        s.push_str("\nSection |  time (s)  | %total\n");
        for (k, name) in names.iter().enumerate() {
            s.push_str(&format!("{:<7} | {:<10.4e} | {:6.2}\n", name, self.timing[k], 100.0 * self.timing[k] / total));
        }
        let ps = if secs > 0.0 { np as f64 * n as f64 / secs } else { 0.0 };
        s.push_str(&format!("\nPerformance: {:.4e} particle-steps/s, {:.1} steps/s\n", ps, if secs > 0.0 { n as f64 / secs } else { 0.0 }));
        s.push_str(&format!("Neighbor list builds = {}\nDangerous builds = {}\n", self.pairs.builds, self.pairs.dangerous));
        if self.pairs.prunes > 0 {
            s.push_str(&format!("Pair list prunes = {} (last buffer {:.3e})\n", self.pairs.prunes, self.pairs.buffer));
        }
        if n > 0 && np > 0 {
            let per = |m: f64| m / np as f64;
            s.push_str(&format!(
                "Pairs per particle = {:.3} walked per step; {:.3} interacting and {:.3} within the skin at the end\n",
                per(self.walked as f64 / n as f64),
                per(self.pairs.interacting() as f64),
                per(self.pairs.listed() as f64)
            ));
        }
        s
    }

    /// Kinetic energy (translational) of a group.
    pub fn kinetic_energy(&self, bit: u32) -> f64 {
        let p = &self.particles;
        (0..p.len()).filter(|&i| p.mask[i] & bit != 0).map(|i| 0.5 * p.mass[i] * p.v[i].norm_squared()).sum()
    }

    /// Rotational kinetic energy of a group.
    pub fn rotational_energy(&self, bit: u32) -> f64 {
        let p = &self.particles;
        (0..p.len()).filter(|&i| p.mask[i] & bit != 0).map(|i| 0.5 * p.inertia(i) * p.omega[i].norm_squared()).sum()
    }

    /// Degrees of freedom of LAMMPS's `compute temp`: dim N - dim, N counted
    /// at the run's setup unless `dynamic/dof` is set (`compute_temp.cpp`
    /// `dof_compute`, called from `init`/`setup`).
    pub fn temp_dof(&self) -> f64 {
        let n = match self.dof_natoms {
            Some(n) if !self.dof_dynamic => n,
            _ => self.particles.len(),
        } as f64;
        let dim = self.domain.as_ref().map_or(3, |d| d.dimension) as f64;
        dim * n - dim
    }

    /// Temperature as LAMMPS `compute temp`: sum m v^2 / (dof kB), 0 when
    /// dof <= 0 ([`Sim::temp_dof`]).
    pub fn temperature(&self) -> f64 {
        let dof = self.temp_dof();
        if dof <= 0.0 {
            return 0.0;
        }
        let mv2: f64 = (0..self.particles.len()).map(|i| self.particles.mass[i] * self.particles.v[i].norm_squared()).sum();
        mv2 / (dof * self.boltz)
    }

    /// Pair virial trace sum r_ij . F_ij of the last force evaluation.
    pub fn virial(&self) -> f64 {
        self.pair_virial.trace
    }

    /// The pair virial tensor sum r_ij (x) F_ij of the last force
    /// evaluation (xx, yy, zz, xy, xz, yz), if that pass summed it.
    pub fn virial_tensor(&self) -> Option<[f64; 6]> {
        (self.tensor_at == Some(self.step)).then_some(self.pair_virial.tensor)
    }

    /// Whether this step's force pass sums the virial tensor: on every
    /// step while a variable may read a tensor keyword
    /// ([`Sim::tensor_every_step`]); else, while thermo reads one, on the
    /// steps it prints (the run's first and last steps and every N, as
    /// [`Sim::output`]) and those where a fix writes at the end of the step
    /// (a restart file keeps the tensor for the resumed run's first line).
    /// Other steps do not pay for it.
    fn tensor_due(&self) -> bool {
        if self.tensor_every_step {
            return true;
        }
        if !self.thermo.reads_tensor() {
            return false;
        }
        let (step, every) = (self.step, self.thermo.every);
        step == self.run_start || step == self.run_end || (every > 0 && step % every == 0) || self.fixes.iter().any(|f| f.end_of_step_due(step))
    }
}

impl EvalContext for Sim {
    fn thermo(&self, name: &str) -> Option<f64> {
        super::output::thermo_keyword(self, name)
    }
    fn compute(&self, id: &str, i: Option<usize>, _j: Option<usize>) -> std::result::Result<f64, String> {
        let c = self.computes.iter().find(|c| c.id == id).ok_or_else(|| format!("compute {id} does not exist"))?;
        c.global(self, i)
    }
    fn fix(&self, id: &str, i: Option<usize>, _j: Option<usize>) -> std::result::Result<f64, String> {
        let f = self.fixes.iter().find(|f| f.id() == id).ok_or_else(|| format!("fix {id} does not exist"))?;
        let v = match i {
            None => f.scalar(self),
            Some(i) => f.vector(self, i),
        };
        v.ok_or_else(|| format!("fix {id} ({}) has no such global value", f.style()))
    }
    fn atom_value(&self, keyword: &str, id: i64) -> std::result::Result<f64, String> {
        let i = self.particles.tag.iter().position(|&t| t == id).ok_or_else(|| format!("atom {id} does not exist"))?;
        super::compute::atom_property(self, keyword, i).ok_or_else(|| format!("unknown atom value {keyword}"))
    }
    fn group_function(&self, name: &str, args: &[&str]) -> std::result::Result<f64, String> {
        super::compute::group_function(self, name, args)
    }
    fn natoms(&self) -> usize {
        self.particles.len()
    }
    fn run_bounds(&self) -> Option<(i64, i64)> {
        Some(self.run_bounds.unwrap_or((self.run_start, self.run_end)))
    }
    fn atom_vector(&self, keyword: &str) -> std::result::Result<Vec<f64>, String> {
        (0..self.particles.len())
            .map(|i| super::compute::atom_property(self, keyword, i).ok_or_else(|| format!("unknown per-atom value {keyword}")))
            .collect()
    }
    fn peratom(&self, prefix: char, id: &str, col: Option<usize>) -> std::result::Result<Vec<f64>, String> {
        if prefix == 'c' {
            let c = self.computes.iter().find(|c| c.id == id).ok_or_else(|| format!("compute {id} does not exist"))?;
            c.peratom(self, col)
        } else if prefix == 'f' && self.particles.extra_index(id).is_some() {
            let (e, k) = self.extra_column(id, col)?;
            let e = &self.particles.extra[e];
            Ok((0..self.particles.len()).map(|i| e.data[i * e.width + k]).collect())
        } else {
            Err(format!("per-atom fix values f_{id} are not available"))
        }
    }
}

impl Sim {
    /// The extra per-atom column `name` and which of its values `f_name`
    /// (`col` None) or `f_name[col]` reads: as LIGGGHTS's dump custom, a
    /// one-value property as `f_name` or `f_name[0]`, a vector's values
    /// as `[1]`...`[width]`.
    pub fn extra_column(&self, name: &str, col: Option<usize>) -> std::result::Result<(usize, usize), String> {
        let e = self.particles.extra_index(name).ok_or_else(|| format!("no per-atom property {name}"))?;
        let width = self.particles.extra[e].width;
        match (width, col) {
            (1, None | Some(0)) => Ok((e, 0)),
            (1, Some(c)) => Err(format!("f_{name} has one value per atom: f_{name}[{c}] does not exist (use f_{name}[0])")),
            (w, Some(c)) if (1..=w).contains(&c) => Ok((e, c - 1)),
            (w, _) => Err(format!("f_{name} has {w} values per atom: use f_{name}[1]..f_{name}[{w}]")),
        }
    }
}
