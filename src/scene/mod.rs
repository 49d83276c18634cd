//! Commands -> a validated simulation. The [`Session`] is the interpreter's
//! host: it executes every command that is not script-level, building the
//! scene (units, box, regions, materials, contact model, walls, sources,
//! outputs) and running it. In check mode (`demx check`) runs are recorded
//! but not integrated.

pub mod args;
pub mod checkpoint;
pub mod commands;
pub mod fix_styles;
pub mod fixes;
pub mod heat;
pub mod insert;
pub mod massflow;
pub mod mesh;
pub mod model;
pub mod outputs;
pub mod overrides;
pub mod restart;
pub mod setup;
pub mod shell;
pub mod summary;
pub mod velocity;
pub mod walls;
pub mod wind;

use crate::engine::sim::{Dialect, Sim};
use crate::error::{did_you_mean, Error, Result};
use crate::script::{Command, EvalContext, Host, Span, Variables};
use args::Args;
use std::collections::BTreeMap;

/// Unit system (`units`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Units {
    /// SI.
    Si,
    /// Lennard-Jones reduced units.
    Lj,
    /// cgs.
    Cgs,
}

/// One `run` of the schedule (for `demx check`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunRecord {
    /// Steps.
    pub steps: i64,
    /// Step at the start.
    pub start: i64,
    /// Particles when the run began.
    pub particles: usize,
}

/// The host of the interpreter: scene under construction plus the engine.
pub struct Session {
    /// The simulation.
    pub sim: Sim,
    /// Unit system.
    pub units: Units,
    /// `atom_style` as written.
    pub atom_style: Option<String>,
    /// `fix property/global` values by name: (style, values).
    pub props: BTreeMap<String, (String, Vec<f64>)>,
    /// The contact model as declared.
    pub pair: Option<model::PairSpec>,
    /// Regions in definition order.
    pub regions: Vec<crate::geom::Region>,
    /// Boundary given before the box exists.
    pub pending_sides: Option<[[crate::engine::domain::Side; 2]; 3]>,
    /// `dimension`.
    pub dimension: u8,
    /// The current lattice.
    pub lattice: Option<crate::geom::Lattice>,
    /// Notes for commands accepted but meaningless in demx.
    pub notes: Vec<(Span, String)>,
    /// Runs made (or recorded, in check mode).
    pub schedule: Vec<RunRecord>,
    /// Whether the dialect was fixed by a command.
    pub dialect_known: bool,
    /// The dialect the deck's `pair_style` lines tell ([`sniff_dialect`]),
    /// for commands that differ between the engines and come before any
    /// command that fixes the dialect (`set diameter`).
    pub dialect_hint: Option<Dialect>,
    /// Regions deleted (`region ID delete`) since the last run.
    pub deleted_regions: Vec<String>,
    /// `hard_particles yes` (LIGGGHTS: moduli above 1 GPa allowed).
    pub hard_particles: bool,
    /// `soft_particles yes` (LIGGGHTS: moduli below 5 MPa allowed).
    pub soft_particles: bool,
    /// Check mode: validate, do not integrate.
    pub check: bool,
    /// Number of threads asked for (for notes only).
    pub threads: usize,
    /// Cap on the steps of every `run` command (`demx run --max-steps`).
    pub max_steps: Option<i64>,
    /// `demx run --perturb SEED:AMP`: before the first run, move every
    /// particle by AMP of its radius in a direction drawn from SEED and its
    /// id (an ensemble member of a chaotic scene; `demx compare` uses it).
    pub perturb: Option<(u64, f64)>,
    /// Wall descriptions for the summary.
    pub walls: Vec<String>,
    /// Particle sources for the summary.
    pub sources: Vec<String>,
    /// Commands that define units, materials and the contact model, replayed
    /// by `read_restart`.
    pub replay: Vec<String>,
    /// Command-line accuracy overrides (`demx run --dt-fraction/--youngs-scale`).
    pub overrides: overrides::Overrides,
    /// `demx run --checkpoint`: where and how often.
    pub checkpoints: Option<checkpoint::Checkpoints>,
    /// Every command executed so far (words and whether quoted), for a
    /// checkpoint's replay.
    pub journal: Vec<Vec<(String, bool)>>,
    /// A checkpoint's journal is being replayed.
    pub replaying: bool,
}

impl Session {
    /// A session; `check` = validate only.
    pub fn new(check: bool) -> Session {
        let mut sim = Sim::default();
        sim.dry = check;
        // LAMMPS's default units are lj, whose thermo output is per atom
        sim.thermo.norm = true;
        Session {
            sim,
            units: Units::Lj,
            atom_style: None,
            props: BTreeMap::new(),
            pair: None,
            regions: vec![],
            pending_sides: None,
            dimension: 3,
            lattice: None,
            notes: vec![],
            schedule: vec![],
            dialect_known: false,
            dialect_hint: None,
            deleted_regions: vec![],
            hard_particles: false,
            soft_particles: false,
            check,
            threads: 1,
            max_steps: None,
            perturb: None,
            walls: vec![],
            sources: vec![],
            replay: vec![],
            overrides: overrides::Overrides::default(),
            checkpoints: None,
            journal: vec![],
            replaying: false,
        }
    }

    /// Fix the dialect (first command that tells wins; a later contradicting
    /// one is fine: decks mix harmless commands).
    pub fn set_dialect(&mut self, d: Dialect) {
        if !self.dialect_known {
            self.sim.dialect = d;
            self.sim.thermo.dialect = d;
            self.dialect_known = true;
        }
    }

    /// The dialect as far as it is known: fixed by a command, else the
    /// deck's hint, else LIGGGHTS.
    pub fn dialect_now(&self) -> Dialect {
        if self.dialect_known {
            self.sim.dialect
        } else {
            self.dialect_hint.unwrap_or(Dialect::Liggghts)
        }
    }

    /// Group bit by name, error at `w` if unknown.
    pub fn group(&self, w: &crate::script::Word) -> Result<u32> {
        self.sim.group_bit(&w.text).ok_or_else(|| {
            let mut e = Error::deck(w.span, format!("group '{}' does not exist", w.text));
            if let Some(s) = did_you_mean(&w.text, self.sim.groups.iter().map(|s| s.as_str())) {
                e = e.with_hint(format!("did you mean '{s}'?"));
            }
            e
        })
    }

    /// The box must exist for this command.
    pub fn need_box(&self, cmd: &Command) -> Result<()> {
        if self.sim.domain.is_none() {
            return Err(Error::deck(cmd.words[0].span, format!("{} command before simulation box is defined", cmd.name()))
                .with_hint("create the box first with create_box or read_data"));
        }
        Ok(())
    }

    /// `atom_modify keyword value ...`: `sort Nfreq binsize` sets the spatial
    /// sort (0 switches it off); `map`, `first`, `id` change nothing here.
    fn atom_modify(&mut self, cmd: &Command, _vars: &mut Variables) -> Result<()> {
        let mut a = Args::new(cmd);
        while a.more() {
            let k = a.word("keyword")?;
            match k.text.as_str() {
                "sort" => {
                    let every = a.i64("sort frequency")?;
                    let bin = a.f64("sort bin size")?;
                    if every < 0 || bin < 0.0 {
                        return Err(Error::deck(k.span, "atom_modify sort: frequency and bin size must be >= 0"));
                    }
                    self.sim.sort_every = every;
                    self.sim.sort_bin = bin;
                }
                "map" | "first" | "id" => {
                    a.word("value")?;
                }
                _ => return Err(args::bad_keyword(k, "atom_modify keyword", &["sort", "map", "first", "id"])),
            }
        }
        Ok(())
    }

    fn dispatch(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()> {
        let name = cmd.name();
        match commands::find(name).map(|c| c.kind) {
            Some(commands::Kind::Scene(run)) => run(self, cmd, vars),
            Some(commands::Kind::Noop) => {
                if name == "newton" {
                    let a = Args::new(cmd);
                    if let Some(w) = a.peek() {
                        if !["on", "off"].contains(&w.text.as_str()) {
                            return Err(args::bad_keyword(w, "newton setting", &["on", "off"]));
                        }
                    }
                }
                self.notes.push((cmd.span, format!("{name}: accepted; changes nothing in demx (single process, deterministic threads)")));
                Ok(())
            }
            Some(commands::Kind::Unsupported) => Err(Error::unsupported(cmd.words[0].span, format!("command '{name}'"))),
            // the interpreter runs these itself; one that reaches the scene
            // came from a replay list or an `if` body, where it is the deck's own error
            Some(commands::Kind::Script) => Err(Error::deck(cmd.words[0].span, format!("'{name}' is a script command and cannot appear here"))),
            None => {
                let mut e = Error::deck(cmd.words[0].span, format!("unknown command '{name}'"));
                if let Some(s) = did_you_mean(name, commands::COMMANDS.iter().map(|c| c.name)) {
                    e = e.with_hint(format!("did you mean '{s}'?"));
                }
                Err(e)
            }
        }
    }

    /// `timestep dt`; `demx run --dt-fraction` replaces the deck's value.
    fn timestep_command(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()> {
        setup::execute(self, cmd, vars)?;
        overrides::after_timestep(self);
        Ok(())
    }

    /// `run_style verlet` (LAMMPS and LIGGGHTS: the velocity-Verlet
    /// integrator, their default and demx's only one); `respa` and the
    /// others are not supported.
    fn run_style(&mut self, cmd: &Command, _vars: &mut Variables) -> Result<()> {
        let mut a = Args::new(cmd);
        let w = a.word("run style")?;
        match w.text.as_str() {
            "verlet" => {
                if let Some(x) = a.peek() {
                    return Err(Error::deck(x.span, format!("run_style verlet: unexpected '{}'", x.text)));
                }
                Ok(())
            }
            "respa" | "verlet/split" | "respa/omp" | "verlet/kk" => Err(Error::unsupported(w.span, format!("run_style {}", w.text))),
            _ => Err(args::bad_keyword(w, "run style", &["verlet", "respa", "verlet/split"])),
        }
    }

    /// `compute_modify ID dynamic/dof yes` (`dynamic` before 2019 and in LIGGGHTS): the
    /// temperature counts the atoms at every use instead of at the run's setup. Read for
    /// `thermo_temp` and computes of style temp; demx keeps one flag for all of them. The
    /// other keywords (`extra/dof`, `dynamic/dof` of other computes) are accepted with a note.
    fn compute_modify(&mut self, cmd: &Command) -> Result<()> {
        let w = &cmd.words;
        let Some(id) = w.get(1) else {
            return Err(Error::deck(cmd.words[0].span, "compute_modify needs a compute ID and keywords"));
        };
        let is_temp = id.text == "thermo_temp" || self.sim.computes.iter().any(|c| c.id == id.text && c.style == "temp");
        let mut used = false;
        for k in 2..w.len().saturating_sub(1) {
            if is_temp && matches!(w[k].text.as_str(), "dynamic/dof" | "dynamic") {
                self.sim.dof_dynamic = matches!(w[k + 1].text.as_str(), "yes" | "on");
                used = true;
            }
        }
        if !used {
            self.notes.push((cmd.span, "compute_modify: accepted; changes nothing in demx".to_string()));
        }
        Ok(())
    }

    fn fix_command(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()> {
        let mut a = Args::new(cmd);
        if cmd.name() == "unfix" {
            let w = a.word("fix id")?;
            match self.sim.fix_index(&w.text) {
                Some(k) => {
                    self.sim.fixes.remove(k);
                    Ok(())
                }
                None => Err(Error::deck(w.span, format!("unfix: fix '{}' does not exist", w.text))),
            }
        } else {
            let id = a.word("fix id")?;
            let gw = a.word("group")?;
            let style = a.word("fix style")?;
            let group = self.group(gw)?;
            fix_styles::dispatch(self, &fix_styles::FixCall { cmd, id: &id.text, group, style }, &mut a, vars)
        }
    }

    /// Before a run: fixes that look their region up by name (LAMMPS
    /// `FixWallGranRegion::init`) take the new definition of a region deleted
    /// since the last run, or stop the run if it was not defined again.
    fn refresh_regions(&mut self, cmd: &Command) -> Result<()> {
        for id in std::mem::take(&mut self.deleted_regions) {
            let new = self.regions.iter().find(|r| r.id == id);
            for f in self.sim.fixes.iter_mut().filter(|f| f.region() == Some(id.as_str())) {
                match new {
                    Some(r) => f.replace_region(r),
                    None => {
                        return Err(Error::deck(
                            cmd.words[0].span,
                            format!("fix {} ({}): its region '{id}' was deleted and not defined again", f.id(), f.style()),
                        ))
                    }
                }
            }
        }
        Ok(())
    }

    /// Add (or replace, same id, as LAMMPS does) a fix.
    pub fn add_fix(&mut self, f: Box<dyn crate::engine::fix::Fix>) -> Result<()> {
        match self.sim.fix_index(f.id()) {
            Some(k) => self.sim.fixes[k] = f,
            None => self.sim.fixes.push(f),
        }
        Ok(())
    }

    /// `demx_guard off | on | [on] keyword value ...` (demx only): tune the
    /// stability guards (engine/guard.rs). Keywords: `overlap F|off`,
    /// `travel F|off`, `speed V|off`, `every K`, `file NAME|none`.
    fn guard_command(&mut self, cmd: &Command) -> Result<()> {
        const KEYWORDS: &[&str] = &["on", "off", "overlap", "travel", "speed", "every", "file"];
        let mut a = Args::new(cmd);
        let mut g = self.sim.guard.settings.clone();
        if !a.more() {
            return Err(Error::deck(a.end_span(), "demx_guard: missing setting").with_hint(format!("expected one of {}", KEYWORDS.join(", "))));
        }
        // a positive number, or `off`
        fn limit(a: &mut Args, what: &str) -> Result<Option<f64>> {
            if a.peek().is_some_and(|w| w.text == "off") {
                a.pos += 1;
                return Ok(None);
            }
            let v = a.f64(what)?;
            if !(v > 0.0) || !v.is_finite() {
                return Err(a.err_prev(format!("demx_guard: {what} must be a positive number or off, not {v}")));
            }
            Ok(Some(v))
        }
        while a.more() {
            let k = a.choice("demx_guard keyword", KEYWORDS)?;
            match k.text.as_str() {
                "on" => g.enabled = true,
                "off" => {
                    if a.more() {
                        return Err(Error::deck(a.peek().map_or(k.span, |w| w.span), "demx_guard off takes no further settings"));
                    }
                    g.enabled = false;
                }
                "overlap" => {
                    g.overlap = limit(&mut a, "overlap (fraction of the radius)")?;
                    // a limit the deck sets stops the run (engine/guard.rs)
                    g.overlap_set = true;
                }
                "travel" => g.travel = limit(&mut a, "travel (fraction of the radius per step)")?,
                "speed" => g.speed = limit(&mut a, "speed")?,
                "every" => {
                    let n = a.i64("every (steps)")?;
                    if n < 1 {
                        return Err(a.err_prev(format!("demx_guard: every must be at least 1, not {n}")));
                    }
                    g.every = n;
                }
                _ => {
                    let w = a.word("file name")?;
                    g.file = if w.text == "none" { None } else { Some(w.text.clone()) };
                }
            }
            // tuning a check turns the guard on
            if k.text != "off" {
                g.enabled = true;
            }
        }
        self.sim.guard.settings = g;
        Ok(())
    }

    fn run_command(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()> {
        if self.sim.thermo.one {
            let mut ks = crate::engine::output::one_style(self.dialect_now());
            // both engines' thermo init: a style other than custom gains a
            // Volume column when the box can change (shrink-wrapped sides;
            // checked with lmp and liggghts on `boundary m m m`)
            let shrinks = self.sim.domain.as_ref().is_some_and(|d| {
                d.sides.iter().flatten().any(|s| matches!(s, crate::engine::domain::Side::Shrink | crate::engine::domain::Side::ShrinkMin))
            });
            if shrinks {
                ks.push("vol".to_string());
            }
            self.sim.thermo.keywords = ks;
        }
        let mut a = Args::new(cmd);
        let n = a.i64("number of steps")?;
        let mut upto = false;
        let (mut pre, mut post) = (true, true);
        let (mut start, mut stop) = (None, None);
        while a.more() {
            let k = a.choice("run keyword", &["upto", "start", "stop", "pre", "post", "every"])?;
            match k.text.as_str() {
                "upto" => upto = true,
                "start" => start = Some(a.i64("step")?),
                "stop" => stop = Some(a.i64("step")?),
                "pre" => pre = a.yes_no("pre")?,
                "post" => post = a.yes_no("post")?,
                _ => return Err(Error::deck(k.span, "run ... every is handled by the interpreter; this form is malformed")),
            }
        }
        // LAMMPS 29 Sep 2021 and LIGGGHTS 3.8 take N (and, with upto, the
        // steps left) as a 32-bit count: `run 2147483648` or `run -1` stop
        // there with "Invalid run command N value"
        let max = i64::from(i32::MAX);
        if !upto && !(0..=max).contains(&n) {
            return Err(Error::deck(cmd.args()[0].span, format!("run: N must be between 0 and {max}, not {n}"))
                .with_hint("LAMMPS and LIGGGHTS: Invalid run command N value"));
        }
        if upto && n.checked_sub(self.sim.step).is_some_and(|d| d > max) {
            return Err(Error::deck(
                cmd.args()[0].span,
                format!("run upto {n}: {} steps from step {} is more than {max}", n - self.sim.step, self.sim.step),
            )
            .with_hint("LAMMPS and LIGGGHTS: Invalid run command upto value"));
        }
        let mut steps = if upto { n - self.sim.step } else { n };
        if let Some(m) = self.max_steps {
            steps = steps.min(m);
        }
        if steps < 0 {
            return Err(Error::deck(cmd.args()[0].span, "run upto: target step is before the current step"));
        }
        self.need_box(cmd)?;
        model::finalize(self, cmd)?;
        self.refresh_regions(cmd)?;
        // compute displace/atom: the originals of atoms created from now on
        // follow the dialect the deck has settled by now
        for c in &self.sim.computes {
            if let crate::engine::compute::ComputeKind::DisplaceAtom { column } = &c.kind {
                if let Some(e) = self.sim.particles.extra_index(column) {
                    self.sim.particles.extra[e].from_position = self.sim.dialect == crate::engine::Dialect::Lammps;
                }
            }
        }
        if let Some((seed, amp)) = self.perturb.take().filter(|_| !self.check) {
            perturb_positions(&mut self.sim.particles, seed, amp);
        }
        // demx run --dt-fraction, when no `timestep` command could apply it
        overrides::before_run(self, cmd.words[0].span)?;
        // where the physics is known to break: say so once, before the first run
        if self.schedule.is_empty() && !self.check && !self.replaying {
            for w in summary::physics_warnings(self) {
                let line = format!("WARNING (demx): {w}");
                if !self.sim.log.screen {
                    eprintln!("{line}");
                }
                self.sim.log.line(&line);
            }
        }
        self.schedule.push(RunRecord { steps, start: self.sim.step, particles: self.sim.particles.len() });
        self.sim.run_bounds = Some((start.unwrap_or(self.sim.step), stop.unwrap_or(self.sim.step + steps)));
        if !self.sim.fixes.iter().any(|f| f.integrates()) && !self.check {
            self.sim.log.line("WARNING: No fixes defined, atoms won't move");
        }
        self.sim.guard.timestep = if self.sim.guard.settings.enabled && !self.check {
            summary::timestep_check(self).map(|t| crate::engine::guard::TimestepFractions { hertz: t.fraction_hertz, rayleigh: t.fraction_rayleigh })
        } else {
            None
        };
        let r = self.sim.run(steps, vars, pre || self.schedule.len() == 1, post);
        match r {
            // in check mode a run-time failure is a fault of the deck: say where
            Err(Error::Runtime { msg }) if self.check => Err(Error::deck(cmd.words[0].span, format!("this run would fail: {msg}"))),
            other => other,
        }
    }
}

/// Displace each particle by `amp` x its radius along a unit direction that
/// depends only on `seed` and the particle's id (not on order or threads).
fn perturb_positions(p: &mut crate::engine::particles::Particles, seed: u64, amp: f64) {
    // splitmix64: a well-mixed 64-bit hash of (seed, id)
    fn mix(mut z: u64) -> u64 {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    let unit = |h: u64| (h >> 11) as f64 / (1u64 << 53) as f64;
    for i in 0..p.len() {
        let h1 = mix(seed ^ mix(p.tag[i] as u64));
        let h2 = mix(h1);
        // uniform direction on the sphere (Archimedes: z uniform in [-1, 1])
        let z = 2.0 * unit(h1) - 1.0;
        let phi = 2.0 * std::f64::consts::PI * unit(h2);
        let s = (1.0 - z * z).max(0.0).sqrt();
        let d = [s * phi.cos(), s * phi.sin(), z];
        for k in 0..3 {
            p.x[i][k] += amp * p.radius[i] * d[k];
        }
    }
}

impl Session {
    /// Execute a replayed command (from a restart file) without recording it again.
    pub fn execute_replay(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()> {
        self.dispatch(cmd, vars)
    }
}

/// Whether a command belongs in a restart file's replay list.
pub(crate) fn replayed(cmd: &Command) -> bool {
    match cmd.name() {
        "units" | "atom_style" | "pair_style" | "pair_coeff" | "hard_particles" | "dimension" => true,
        "fix" => cmd.words.get(3).is_some_and(|w| w.text == "property/global"),
        _ => false,
    }
}

impl EvalContext for Session {
    fn thermo(&self, name: &str) -> Option<f64> {
        self.sim.thermo(name)
    }
    fn compute(&self, id: &str, i: Option<usize>, j: Option<usize>) -> std::result::Result<f64, String> {
        self.sim.compute(id, i, j)
    }
    fn fix(&self, id: &str, i: Option<usize>, j: Option<usize>) -> std::result::Result<f64, String> {
        self.sim.fix(id, i, j)
    }
    fn atom_value(&self, k: &str, id: i64) -> std::result::Result<f64, String> {
        self.sim.atom_value(k, id)
    }
    fn group_function(&self, name: &str, args: &[&str]) -> std::result::Result<f64, String> {
        // the optional last argument is a region (LAMMPS: count(g,R),
        // mass(g,R), ke(g,R), xcm(g,dim,R), vcm, fcm, bound(g,dir,R))
        let plain = match name {
            "count" | "mass" | "ke" => 1,
            "xcm" | "vcm" | "fcm" | "bound" => 2,
            _ => usize::MAX,
        };
        if args.len() == plain + 1 {
            let rid = args[plain];
            let r = self.regions.iter().find(|r| r.id == rid).ok_or_else(|| format!("region {rid} does not exist"))?;
            let x = &self.sim.particles.x;
            return crate::engine::compute::group_function_in(&self.sim, name, &args[..plain], &|i| r.contains(x[i]));
        }
        self.sim.group_function(name, args)
    }
    fn natoms(&self) -> usize {
        self.sim.natoms()
    }
    fn run_bounds(&self) -> Option<(i64, i64)> {
        self.sim.run_bounds()
    }
    fn atom_vector(&self, k: &str) -> std::result::Result<Vec<f64>, String> {
        self.sim.atom_vector(k)
    }
    fn peratom(&self, p: char, id: &str, col: Option<usize>) -> std::result::Result<Vec<f64>, String> {
        self.sim.peratom(p, id, col)
    }
}

impl Host for Session {
    fn execute(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()> {
        self.dispatch(cmd, vars)?;
        if replayed(cmd) {
            self.replay.push(cmd.text());
        }
        if self.checkpoints.is_some() && !self.replaying {
            self.journal.push(cmd.words.iter().map(|w| (w.text.clone(), w.quoted)).collect());
        }
        Ok(())
    }
    fn checkpoint_due(&mut self) -> bool {
        !self.check && self.checkpoints.as_ref().is_some_and(|c| c.due(self.journal.len()))
    }
    fn checkpoint(&mut self, saved: &crate::script::interp::SavedInterpreter) -> Result<bool> {
        checkpoint::write(self, saved)
    }
    fn output(&mut self, text: &str) {
        self.sim.log.line(text);
    }
    fn set_log(&mut self, path: Option<&str>, append: bool, span: Span) -> Result<()> {
        match path {
            None => {
                self.sim.log.file = None;
                Ok(())
            }
            Some(p) => {
                if self.check {
                    return Ok(());
                }
                self.sim.log.open(p, append).map_err(|e| Error::io(span, format!("cannot open log file '{p}'"), &e))
            }
        }
    }
}

/// The dialect a deck's text tells before it is run, from its `pair_style`
/// lines as `pair_style` itself decides: `gran` is LIGGGHTS 3.x; `granular`
/// and `gran/...` are LAMMPS, unless the deck also defines `fix ...
/// property/global`, which only LIGGGHTS (2.x with the old styles) has.
pub fn sniff_dialect(text: &str) -> Option<Dialect> {
    let mut lammps = false;
    let mut liggghts_fix = false;
    for line in text.lines() {
        let mut w = line.split('#').next().unwrap_or("").split_whitespace();
        match (w.next(), w.next()) {
            (Some("pair_style"), Some("gran")) => return Some(Dialect::Liggghts),
            (Some("pair_style"), Some(st)) if st == "granular" || st.starts_with("gran/") => lammps = true,
            (Some("fix"), Some(_)) => liggghts_fix |= w.nth(1) == Some("property/global"),
            _ => {}
        }
    }
    match (lammps, liggghts_fix) {
        (true, false) => Some(Dialect::Lammps),
        (true, true) => Some(Dialect::Liggghts),
        _ => None,
    }
}
