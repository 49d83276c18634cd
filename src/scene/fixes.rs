//! Simple fixes: nve/sphere, gravity, freeze, addforce, viscous, print,
//! setforce. Each holds its group bit and parsed arguments.

use super::args::Args;
use crate::engine::fix::{Chunk, Fix, Hook, Local, Stage};
use crate::engine::integrate;
use crate::engine::sim::Sim;
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{Command, EvalContext, Variables};
use std::sync::{Arc, Mutex, PoisonError};

/// A fix that only tunes how MPI ranks share the work (`fix balance`):
/// kept under its id so that `unfix` and a later fix of the same id find it,
/// and does nothing in demx, which runs one process with deterministic threads.
pub struct Noop {
    /// Id.
    pub id: String,
    /// Style as written.
    pub style: String,
}

impl Fix for Noop {
    crate::stateless_fix!();
    crate::no_step_hooks!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        &self.style
    }
}

/// `fix ID group nve/sphere`.
pub struct NveSphere {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
}

impl Fix for NveSphere {
    crate::stateless_fix!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "nve/sphere"
    }
    fn initial_integrate(&mut self, sim: &mut Sim) {
        integrate::initial_integrate(&mut sim.particles, self.group, sim.dt);
    }
    fn final_integrate(&mut self, sim: &mut Sim) {
        integrate::final_integrate(&mut sim.particles, self.group, sim.dt);
    }
    fn local(&mut self, hook: Hook, sim: &Sim, _vars: &Variables) -> Result<Local> {
        Ok(match hook {
            Hook::InitialIntegrate => Local::Stage(Box::new(integrate::InitialHalf { group: self.group, dt: sim.dt, rotate: true })),
            Hook::PostForce => Local::Nothing,
            Hook::FinalIntegrate => Local::Stage(Box::new(integrate::FinalHalf { group: self.group, dt: sim.dt, rotate: true })),
        })
    }
    fn integrates(&self) -> bool {
        true
    }
}

/// `fix ID group nve`: translation only (the particles do not rotate).
pub struct Nve {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
}

impl Fix for Nve {
    crate::stateless_fix!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "nve"
    }
    fn initial_integrate(&mut self, sim: &mut Sim) {
        integrate::initial_integrate_nve(&mut sim.particles, self.group, sim.dt);
    }
    fn final_integrate(&mut self, sim: &mut Sim) {
        integrate::final_integrate_nve(&mut sim.particles, self.group, sim.dt);
    }
    fn local(&mut self, hook: Hook, sim: &Sim, _vars: &Variables) -> Result<Local> {
        Ok(match hook {
            Hook::InitialIntegrate => Local::Stage(Box::new(integrate::InitialHalf { group: self.group, dt: sim.dt, rotate: false })),
            Hook::PostForce => Local::Nothing,
            Hook::FinalIntegrate => Local::Stage(Box::new(integrate::FinalHalf { group: self.group, dt: sim.dt, rotate: false })),
        })
    }
    fn integrates(&self) -> bool {
        true
    }
}

/// `fix ID group gravity magnitude vector x y z` (also `spherical`, `chute`).
pub struct Gravity {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
    /// Acceleration vector (magnitude times unit direction).
    pub acc: V3,
    /// Magnitude, possibly a variable name.
    pub magnitude: Magnitude,
    /// Direction: unit up to the rounding of the engines' arithmetic.
    pub dir: V3,
}

/// A number or an equal-style variable.
#[derive(Clone, Debug)]
pub enum Magnitude {
    /// Constant.
    Const(f64),
    /// `v_name`, evaluated every step.
    Var(String),
}

impl Magnitude {
    fn parse(a: &mut Args, what: &str) -> Result<Magnitude> {
        let w = a.word(what)?;
        if let Some(v) = w.text.strip_prefix("v_") {
            Ok(Magnitude::Var(v.to_string()))
        } else {
            Ok(Magnitude::Const(super::args::parse_f64(w)?))
        }
    }
    fn value(&self, vars: &Variables, ctx: &dyn EvalContext) -> Result<f64> {
        match self {
            Magnitude::Const(v) => Ok(*v),
            Magnitude::Var(n) => vars.eval_equal(n, ctx).map_err(Error::runtime),
        }
    }
}

impl Fix for Gravity {
    crate::stateless_fix!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "gravity"
    }
    fn post_force(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        if let Magnitude::Var(_) = self.magnitude {
            let m = self.magnitude.value(vars, sim)?;
            self.acc = self.dir * m;
        }
        let p = &mut sim.particles;
        let pull = |f: &mut [V3], mask: &[u32], mass: &[f64]| Pull { acc: self.acc, group: self.group }.pull(f, mask, mass);
        let chunk = integrate::CHUNK;
        if p.len() >= 2 * chunk {
            use rayon::prelude::*;
            p.f.par_chunks_mut(chunk).zip(p.mask.par_chunks(chunk)).zip(p.mass.par_chunks(chunk)).for_each(|((f, mask), mass)| pull(f, mask, mass));
        } else {
            pull(&mut p.f, &p.mask, &p.mass);
        }
        Ok(())
    }
    fn local(&mut self, hook: Hook, _sim: &Sim, _vars: &Variables) -> Result<Local> {
        Ok(match (hook, &self.magnitude) {
            (Hook::PostForce, Magnitude::Const(_)) => Local::Stage(Box::new(Pull { acc: self.acc, group: self.group })),
            (Hook::PostForce, Magnitude::Var(_)) => Local::Whole,
            (Hook::InitialIntegrate | Hook::FinalIntegrate, _) => Local::Nothing,
        })
    }
    fn summary(&self) -> String {
        format!("gravity {:?} (fix {})", [self.acc.x, self.acc.y, self.acc.z], self.id)
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

/// Gravity's pull on each particle of a group (the post_force of
/// [`Gravity`], and its stage in the step's fused tail).
struct Pull {
    acc: V3,
    group: u32,
}

impl Pull {
    /// Each particle on its own: the same bits on any thread count.
    #[inline(always)]
    fn pull(&self, f: &mut [V3], mask: &[u32], mass: &[f64]) {
        let acc = self.acc;
        // the whole chunk in the group (the common case): every force
        // written, plain vector loads and stores; the conditional form below
        // compiles, where AVX-512 is enabled, to masked scatters, microcoded
        // on AMD Zen 4 (2.4% of bed (a)'s run)
        if crate::engine::integrate::all_in_group(mask, self.group) {
            for (f, &m) in f.iter_mut().zip(mass) {
                *f += V3::new(m * acc.x, m * acc.y, m * acc.z);
            }
            return;
        }
        for ((f, &bits), &m) in f.iter_mut().zip(mask).zip(mass) {
            if bits & self.group != 0 {
                // LAMMPS FixGravity: f += rmass * xacc (per component)
                *f += V3::new(m * acc.x, m * acc.y, m * acc.z);
            }
        }
    }
}

impl Stage for Pull {
    fn apply(&self, c: &mut Chunk<'_>) {
        let r = c.lo..c.lo + c.f.len();
        self.pull(c.f, &c.mask[r.clone()], &c.mass[r]);
    }
}

/// `fix ID group freeze`: zero force and torque; contact partners see
/// infinite mass.
pub struct Freeze {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
    /// This step's frozen particles and the force each had (f_ID[1..3] is
    /// their sum, taken in particle order: the bits of one serial pass,
    /// however the step's chunks ran).
    removed: Arc<Mutex<Vec<(usize, V3)>>>,
}

impl Freeze {
    /// The fix, with nothing removed yet.
    pub fn new(id: String, group: u32) -> Freeze {
        Freeze { id, group, removed: Arc::default() }
    }

    fn removed(&self) -> std::sync::MutexGuard<'_, Vec<(usize, V3)>> {
        self.removed.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The force removed this step: the frozen particles' forces added in
    /// particle order, whatever order the chunks took them in.
    fn removed_sum(&self) -> V3 {
        let mut took = self.removed().clone();
        took.sort_unstable_by_key(|&(k, _)| k);
        took.iter().fold(V3::zeros(), |s, &(_, f)| s + f)
    }
}

/// Freeze's post_force on the particles of one chunk (the fix's stage in
/// the step's fused tail, and its whole pass): each particle on its own.
struct Hold {
    group: u32,
    removed: Arc<Mutex<Vec<(usize, V3)>>>,
}

impl Hold {
    fn hold(&self, lo: usize, mask: &[u32], frozen: &mut [bool], f: &mut [V3], torque: &mut [V3]) {
        let mut took = Vec::new();
        for (k, (((&bits, fz), f), t)) in mask.iter().zip(frozen).zip(f).zip(torque).enumerate() {
            if bits & self.group != 0 {
                *fz = true;
                took.push((lo + k, *f));
                *f = V3::zeros();
                *t = V3::zeros();
            }
        }
        if !took.is_empty() {
            self.removed.lock().unwrap_or_else(PoisonError::into_inner).extend(took);
        }
    }
}

impl Stage for Hold {
    fn apply(&self, c: &mut Chunk<'_>) {
        let r = c.lo..c.lo + c.f.len();
        self.hold(c.lo, &c.mask[r], c.frozen, c.f, c.torque);
    }
}

impl Fix for Freeze {
    crate::stateless_fix!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "freeze"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        let p = &mut sim.particles;
        for i in 0..p.len() {
            if p.mask[i] & self.group != 0 {
                p.frozen[i] = true;
            }
        }
        Ok(())
    }
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        self.removed().clear();
        let p = &mut sim.particles;
        Hold { group: self.group, removed: self.removed.clone() }.hold(0, &p.mask, &mut p.frozen, &mut p.f, &mut p.torque);
        Ok(())
    }
    /// A stage of the step's fused tail: before, its whole pass split the
    /// tail of every deck that freezes a group (the LAMMPS chute), so the
    /// integration after it ran as a pass of its own, out of cache.
    fn local(&mut self, hook: Hook, _sim: &Sim, _vars: &Variables) -> Result<Local> {
        Ok(if hook == Hook::PostForce {
            self.removed().clear();
            Local::Stage(Box::new(Hold { group: self.group, removed: self.removed.clone() }))
        } else {
            Local::Nothing
        })
    }
    fn vector(&self, _sim: &Sim, i: usize) -> Option<f64> {
        (1..=3).contains(&i).then(|| self.removed_sum()[i - 1])
    }
}

/// One component of addforce/setforce: constant, equal- or atom-style variable, or NULL.
#[derive(Clone, Debug)]
pub enum Component {
    /// A constant.
    Const(f64),
    /// `v_name` (equal or atom style).
    Var(String),
    /// `NULL` (setforce: leave alone).
    Null,
}

pub(crate) fn component(a: &mut Args, what: &str) -> Result<Component> {
    let w = a.word(what)?;
    if w.text == "NULL" {
        return Ok(Component::Null);
    }
    if let Some(v) = w.text.strip_prefix("v_") {
        return Ok(Component::Var(v.to_string()));
    }
    Ok(Component::Const(super::args::parse_f64(w)?))
}

/// Per-particle values of a component: a constant for all, an atom-style
/// variable, or an equal-style variable for all; None for NULL. An error is
/// the evaluator's message; the caller says which command it concerns.
pub(crate) fn component_values(c: &Component, vars: &Variables, sim: &Sim) -> std::result::Result<Option<Vec<f64>>, String> {
    let n = sim.particles.len();
    Ok(match c {
        Component::Null => None,
        Component::Const(v) => Some(vec![*v; n]),
        Component::Var(name) => match vars.eval_atom(name, sim) {
            Ok(v) => Some(v),
            Err(_) => Some(vec![vars.eval_equal(name, sim)?; n]),
        },
    })
}

/// `fix ID group addforce fx fy fz` and `setforce`.
pub struct AddForce {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
    /// Components.
    pub comp: [Component; 3],
    /// setforce instead of addforce.
    pub set: bool,
    /// Sum of the group's force before the fix (f_ID[1..3]).
    pub total: V3,
}

impl Fix for AddForce {
    crate::stateless_fix!();
    crate::post_force_only!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        if self.set {
            "setforce"
        } else {
            "addforce"
        }
    }
    fn post_force(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        let value = |c: &Component| component_values(c, vars, sim).map_err(|e| Error::runtime(format!("fix addforce: {e}")));
        let vals = [value(&self.comp[0])?, value(&self.comp[1])?, value(&self.comp[2])?];
        let p = &mut sim.particles;
        self.total = V3::zeros();
        for i in 0..p.len() {
            if p.mask[i] & self.group == 0 {
                continue;
            }
            self.total += p.f[i];
            for d in 0..3 {
                if let Some(v) = &vals[d] {
                    if self.set {
                        p.f[i][d] = v[i];
                    } else {
                        p.f[i][d] += v[i];
                    }
                }
            }
        }
        Ok(())
    }
    fn vector(&self, _sim: &Sim, i: usize) -> Option<f64> {
        (1..=3).contains(&i).then(|| self.total[i - 1])
    }
}

/// `fix ID group viscous gamma [scale type ratio]`: F = -gamma v.
pub struct Viscous {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
    /// gamma per type (index = type).
    pub gamma: Vec<f64>,
}

impl Fix for Viscous {
    crate::stateless_fix!();
    crate::post_force_only!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "viscous"
    }
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        let p = &mut sim.particles;
        for i in 0..p.len() {
            if p.mask[i] & self.group != 0 {
                let g = self.gamma.get(p.kind[i] as usize).copied().unwrap_or(self.gamma[0]);
                p.f[i] -= p.v[i] * g;
            }
        }
        Ok(())
    }
}

/// `fix ID group print N "text" [file f | append f] [screen yes/no] [title t]`.
pub struct Print {
    /// Id.
    pub id: String,
    /// Every N steps.
    pub every: i64,
    /// Text with `$` references, substituted when printed.
    pub text: crate::script::Word,
    /// Output file.
    pub file: Option<std::fs::File>,
    /// Print to screen.
    pub screen: bool,
}

impl Fix for Print {
    fn save_state(&self) -> crate::engine::fix::FixState {
        // a file it writes would be opened anew (and cut) by the resumed run
        if self.file.is_some() {
            crate::engine::fix::FixState::Unsupported
        } else {
            crate::engine::fix::FixState::Stateless
        }
    }
    crate::no_step_hooks!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "print"
    }
    fn setup_output(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        if sim.dialect == crate::engine::Dialect::Lammps {
            self.end_of_step(sim, vars)?;
        }
        Ok(())
    }
    fn end_of_step_due(&self, step: i64) -> bool {
        self.every > 0 && step % self.every == 0
    }
    fn end_of_step(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        use std::io::Write;
        if !self.end_of_step_due(sim.step) {
            return Ok(());
        }
        let line = vars.substitute_word(&self.text, sim)?;
        if self.screen {
            sim.log.line(&line);
        }
        if let Some(f) = &mut self.file {
            let _ = writeln!(f, "{line}");
            let _ = f.flush();
        }
        Ok(())
    }
}

/// Parse the simple fixes; `None` if the style is not one of them.
pub fn parse_simple(sim: &Sim, id: &str, group: u32, style: &str, a: &mut Args, cmd: &Command) -> Result<Option<Box<dyn Fix>>> {
    let id = id.to_string();
    Ok(Some(match style {
        "nve/sphere" => {
            while a.more() {
                let k = a.choice("nve/sphere keyword", &["update", "disc"])?;
                if k.text == "update" {
                    a.choice("update style", &["dipole", "dipole/dlm"])?;
                } else {
                    return Err(crate::error::Error::unsupported(k.span, "fix nve/sphere disc (2d discs)"));
                }
            }
            Box::new(NveSphere { id, group })
        }
        "gravity" => {
            let magnitude = Magnitude::parse(a, "magnitude")?;
            let kind = a.choice("gravity style", &["vector", "spherical", "chute"])?;
            let two_d = sim.domain.as_ref().is_some_and(|d| d.dimension == 2);
            // `FixGravity::set_acceleration` of LAMMPS and LIGGGHTS alike: chute
            // is spherical with phi = 0 and theta = 180 - angle, so its axis is
            // -z in 3d and -y in 2d; neither is normalised (sin and cos as
            // they round); a vector is, over x and y alone in 2d
            let spherical = |phi: f64, theta: f64| {
                let (phi, theta) = (phi.to_radians(), theta.to_radians());
                if two_d {
                    V3::new(theta.sin(), theta.cos(), 0.0)
                } else {
                    V3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
                }
            };
            let dir = match kind.text.as_str() {
                "vector" => {
                    let (x, y, z) = (a.f64("x")?, a.f64("y")?, a.f64("z")?);
                    let v = V3::new(x, y, if two_d { 0.0 } else { z });
                    let len = (v.x * v.x + v.y * v.y + v.z * v.z).sqrt();
                    if len == 0.0 {
                        return Err(a.err_prev("fix gravity: direction vector is zero"));
                    }
                    V3::new(v.x / len, v.y / len, v.z / len)
                }
                "chute" => spherical(0.0, 180.0 - a.f64("angle")?),
                _ => {
                    let phi = a.f64("phi")?;
                    spherical(phi, a.f64("theta")?)
                }
            };
            let m = if let Magnitude::Const(m) = magnitude { m } else { 0.0 };
            Box::new(Gravity { id, group, acc: dir * m, magnitude, dir })
        }
        "freeze" => Box::new(Freeze::new(id, group)),
        "nve" => Box::new(Nve { id, group }),
        "ave/time" => Box::new(parse_ave_time(&id, a, sim.dry)?),
        "addforce" | "setforce" => {
            let comp = [component(a, "fx")?, component(a, "fy")?, component(a, "fz")?];
            while a.more() {
                let k = a.choice("addforce keyword", &["every", "region", "energy"])?;
                let w = a.word("value")?;
                if k.text != "every" {
                    return Err(crate::error::Error::unsupported(w.span, format!("fix {style} {}", k.text)));
                }
            }
            Box::new(AddForce { id, group, comp, set: style == "setforce", total: V3::zeros() })
        }
        "viscous" => {
            let g = a.f64("gamma")?;
            let mut gamma = vec![g; sim.ntypes.max(1) + 1];
            while a.more() {
                a.choice("viscous keyword", &["scale"])?;
                let t = a.i64("type")? as usize;
                let r = a.f64("ratio")?;
                if t < gamma.len() {
                    gamma[t] = g * r;
                }
            }
            Box::new(Viscous { id, group, gamma })
        }
        "print" => {
            let every = a.i64("N")?;
            let text = a.word("text")?.clone();
            let mut file = None;
            let mut screen = true;
            // LAMMPS FixPrint: the file's first line is the title, by
            // default "# Fix print output for fix ID"
            let mut title = format!("# Fix print output for fix {id}");
            while a.more() {
                let k = a.choice("print keyword", &["file", "append", "screen", "title"])?;
                match k.text.as_str() {
                    "file" | "append" => {
                        let w = a.word("file name")?;
                        // `demx check` (and a checkpoint's replay) writes nothing
                        if sim.dry {
                            continue;
                        }
                        let f = if k.text == "file" {
                            std::fs::File::create(&w.text)
                        } else {
                            std::fs::OpenOptions::new().create(true).append(true).open(&w.text)
                        };
                        file = Some(f.map_err(|e| Error::io(w.span, format!("cannot open '{}'", w.text), &e))?);
                    }
                    "screen" => screen = a.yes_no("screen")?,
                    _ => title = a.str("title")?.to_string(),
                }
            }
            if let Some(f) = &mut file {
                use std::io::Write;
                let _ = writeln!(f, "{title}");
            }
            let _ = cmd;
            Box::new(Print { id, every, text, file, screen })
        }
        _ => return Ok(None),
    }))
}

/// `fix ID group ave/time Nevery Nrepeat Nfreq value ... [ave one|running]
/// [file F] [start S] [mode scalar]`: time averages of global scalars
/// (`c_ID`, `c_ID[i]`, `f_ID`, `f_ID[i]`, `v_name`), written every Nfreq steps
/// in LAMMPS' file layout and readable as `f_ID` / `f_ID[i]`.
pub struct AveTime {
    /// Id.
    pub id: String,
    nevery: i64,
    nrepeat: i64,
    nfreq: i64,
    values: Vec<String>,
    running: bool,
    start: i64,
    file: Option<std::fs::File>,
    sums: Vec<f64>,
    count: i64,
    /// Last completed averages.
    result: Vec<f64>,
    /// Running totals over all windows (`ave running`).
    total: Vec<f64>,
    windows: i64,
    header_written: bool,
}

impl AveTime {
    fn sample(&self, sim: &Sim, vars: &Variables) -> Result<Vec<f64>> {
        self.values.iter().map(|v| crate::engine::output::thermo_value(sim, vars, v)).collect()
    }
}

impl Fix for AveTime {
    crate::no_step_hooks!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "ave/time"
    }
    /// A sampling step: the window of output step s samples
    /// s - (Nrepeat-1) Nevery ... s.
    fn end_of_step_due(&self, step: i64) -> bool {
        let next_out = ((step + self.nfreq - 1) / self.nfreq) * self.nfreq;
        let first = next_out - (self.nrepeat - 1) * self.nevery;
        step >= self.start && step >= first && (step - first) % self.nevery == 0
    }
    fn end_of_step(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        use std::io::Write;
        let step = sim.step;
        if !self.end_of_step_due(step) {
            return Ok(());
        }
        let next_out = ((step + self.nfreq - 1) / self.nfreq) * self.nfreq;
        let vals = self.sample(sim, vars)?;
        if self.sums.len() != vals.len() {
            self.sums = vec![0.0; vals.len()];
        }
        for (s, v) in self.sums.iter_mut().zip(&vals) {
            *s += v;
        }
        self.count += 1;
        if step == next_out {
            let avg: Vec<f64> = self.sums.iter().map(|s| s / self.count as f64).collect();
            self.sums.iter_mut().for_each(|s| *s = 0.0);
            self.count = 0;
            if self.running {
                if self.total.len() != avg.len() {
                    self.total = vec![0.0; avg.len()];
                }
                for (t, a) in self.total.iter_mut().zip(&avg) {
                    *t += a;
                }
                self.windows += 1;
                self.result = self.total.iter().map(|t| t / self.windows as f64).collect();
            } else {
                self.result = avg;
            }
            if let Some(f) = &mut self.file {
                if !self.header_written {
                    let _ = writeln!(f, "# Time-averaged data for fix {}\n# TimeStep {}", self.id, self.values.join(" "));
                    self.header_written = true;
                }
                let line: Vec<String> = self.result.iter().map(|v| crate::io::cfmt::fmt_g(*v, 6)).collect();
                let _ = writeln!(f, "{} {}", step, line.join(" "));
                let _ = f.flush();
            }
        }
        Ok(())
    }
    fn scalar(&self, _sim: &Sim) -> Option<f64> {
        (self.values.len() == 1).then(|| self.result.first().copied().unwrap_or(0.0))
    }
    fn vector(&self, _sim: &Sim, i: usize) -> Option<f64> {
        (i >= 1 && i <= self.values.len()).then(|| self.result.get(i - 1).copied().unwrap_or(0.0))
    }
}

/// Parse `fix ave/time`.
pub fn parse_ave_time(id: &str, a: &mut Args, check: bool) -> Result<AveTime> {
    let nevery = a.i64("Nevery")?;
    let nrepeat = a.i64("Nrepeat")?;
    let nfreq = a.i64("Nfreq")?;
    if nevery <= 0 || nrepeat <= 0 || nfreq <= 0 || nfreq % nevery != 0 || (nrepeat - 1) * nevery >= nfreq + nevery {
        return Err(a.err_prev("fix ave/time: illegal Nevery/Nrepeat/Nfreq (Nfreq must be a multiple of Nevery and Nrepeat*Nevery <= Nfreq)"));
    }
    let mut values = vec![];
    let mut running = false;
    let mut start = 0;
    let mut file = None;
    while a.more() {
        let w = a.word("value or keyword")?;
        let t = w.text.as_str();
        if t.starts_with("c_") || t.starts_with("f_") || t.starts_with("v_") {
            values.push(t.to_string());
            continue;
        }
        match t {
            "ave" => {
                let m = a.choice("ave mode", &["one", "running", "window"])?;
                match m.text.as_str() {
                    "running" => running = true,
                    "window" => return Err(Error::unsupported(m.span, "fix ave/time ave window")),
                    _ => {}
                }
            }
            "file" => {
                let f = a.word("file")?;
                if !check {
                    file = Some(std::fs::File::create(&f.text).map_err(|e| Error::io(f.span, format!("cannot open '{}'", f.text), &e))?);
                }
            }
            "start" => start = a.i64("start")?,
            "mode" => {
                let m = a.choice("mode", &["scalar", "vector"])?;
                if m.text == "vector" {
                    return Err(Error::unsupported(m.span, "fix ave/time mode vector"));
                }
            }
            "off" | "overwrite" | "title1" | "title2" | "title3" | "format" => {
                if t != "overwrite" {
                    a.word("value")?;
                }
            }
            _ => {
                return Err(Error::deck(w.span, format!("fix ave/time: unknown value or keyword '{t}'"))
                    .with_hint("values are c_ID, c_ID[i], f_ID, f_ID[i] or v_name"))
            }
        }
    }
    if values.is_empty() {
        return Err(Error::deck(a.end_span(), "fix ave/time: no values"));
    }
    Ok(AveTime {
        id: id.to_string(),
        nevery,
        nrepeat,
        nfreq,
        values,
        running,
        start,
        file,
        sums: vec![],
        count: 0,
        result: vec![],
        total: vec![],
        windows: 0,
        header_written: false,
    })
}

/// `fix ID group check/timestep/gran N fraction_rayleigh fraction_hertz`
/// (LIGGGHTS): every N steps the time step as a fraction of the Rayleigh time
/// of the smallest particle and of the Hertz time at the largest particle
/// speed; `f_ID[1]`, `f_ID[2]` are those fractions; a warning is printed above
/// the given fractions, as LIGGGHTS does.
pub struct CheckTimestep {
    id: String,
    every: i64,
    limit: (f64, f64),
    /// (Young's modulus, Poisson ratio) per atom type, 0-based.
    materials: Vec<(f64, f64)>,
    fractions: (f64, f64),
}

impl CheckTimestep {
    /// A check fix.
    pub fn new(id: &str, every: i64, fr: f64, fh: f64, materials: Vec<(f64, f64)>) -> CheckTimestep {
        CheckTimestep { id: id.to_string(), every, limit: (fr, fh), materials, fractions: (0.0, 0.0) }
    }
    fn compute(&mut self, sim: &Sim) {
        let p = &sim.particles;
        let vmax = p.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let (mut fr, mut fh) = (0.0f64, 0.0f64);
        for i in 0..p.len() {
            let Some(&(y, nu)) = self.materials.get(p.kind[i] as usize - 1) else { continue };
            if y <= 0.0 {
                continue;
            }
            let (r, rho) = (p.radius[i], p.density[i]);
            let g = y / (2.0 * (1.0 + nu));
            // Rayleigh time pi R sqrt(rho/G) / (0.1631 nu + 0.8766)
            let tr = std::f64::consts::PI * r * (rho / g).sqrt() / (0.1631 * nu + 0.8766);
            fr = fr.max(sim.dt / tr);
            if vmax > 0.0 {
                // Hertz time 2.87 (m*^2 / (R* E*^2 v))^(1/5), two equal spheres
                let m_eff = 0.5 * p.mass[i];
                let e_eff = y / (2.0 * (1.0 - nu * nu));
                let th = 2.87 * (m_eff * m_eff / (0.5 * r * e_eff * e_eff * vmax)).powf(0.2);
                fh = fh.max(sim.dt / th);
            }
        }
        self.fractions = (fr, fh);
    }
}

impl Fix for CheckTimestep {
    crate::stateless_fix!();
    crate::no_step_hooks!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "check/timestep/gran"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        self.compute(sim);
        Ok(())
    }
    fn end_of_step_due(&self, step: i64) -> bool {
        self.every > 0 && step % self.every == 0
    }
    fn end_of_step(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        if self.end_of_step_due(sim.step) {
            self.compute(sim);
            if self.fractions.0 > self.limit.0 {
                sim.log.line(&format!("WARNING: time-step is {:.6} % of rayleigh time", 100.0 * self.fractions.0));
            }
            if self.fractions.1 > self.limit.1 {
                sim.log.line(&format!("WARNING: time-step is {:.6} % of hertz time", 100.0 * self.fractions.1));
            }
        }
        Ok(())
    }
    fn vector(&self, _sim: &Sim, i: usize) -> Option<f64> {
        match i {
            1 => Some(self.fractions.0),
            2 => Some(self.fractions.1),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Freeze's stage on chunks taken last first, as the fused tail may
    /// take them, removes the sum of one serial pass, bit for bit, and
    /// leaves the frozen spheres flagged and without force or torque.
    #[test]
    fn freeze_stage_sums_in_particle_order_whatever_the_chunks_order() {
        let n = 1000;
        let fr = Freeze::new("fr".into(), 2);
        // every third particle in the group, forces of unequal magnitudes
        let force = |i: usize| V3::new((i as f64 * 0.37).sin() * 1e3, (i as f64).sqrt(), 1.0 / (1.0 + i as f64));
        let mut p = crate::engine::particles::Particles::default();
        for i in 0..n {
            let mask = if i % 3 == 0 { 3 } else { 1 };
            p.push(crate::engine::particles::NewParticle {
                tag: i as i64 + 1,
                kind: 1,
                mask,
                x: V3::zeros(),
                v: V3::zeros(),
                omega: V3::zeros(),
                radius: 1.0,
                density: 1.0,
            });
            (p.f[i], p.torque[i]) = (force(i), V3::new(1.0, 2.0, 3.0));
        }
        let stage = Hold { group: 2, removed: fr.removed.clone() };
        for c in Chunk::split(&mut p, 128).iter_mut().rev() {
            stage.apply(c);
        }
        let serial = (0..n).filter(|i| i % 3 == 0).fold(V3::zeros(), |s, i| s + force(i));
        let bits = |v: V3| [v.x, v.y, v.z].map(f64::to_bits);
        assert_eq!(bits(fr.removed_sum()), bits(serial));
        for i in 0..n {
            let held = i % 3 == 0;
            assert_eq!(p.frozen[i], held, "particle {i}");
            assert_eq!(p.f[i] == V3::zeros() && p.torque[i] == V3::zeros(), held, "particle {i}");
        }
    }
}
