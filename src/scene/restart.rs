//! Restart files (demx's own format, JSON with exact round-trip floats) and
//! LAMMPS data files: `write_restart`, `read_restart`, `restart N file`,
//! `read_data`, `write_data`.
//!
//! A restart holds everything needed to continue bitwise as if the run had
//! not stopped: the box, every particle column including per-atom extra
//! columns (wall contact history), pair contact history keyed by ids, step,
//! time, time step, groups, and the commands that defined materials and the
//! contact model (replayed on read, as LAMMPS restores pair styles). Files are
//! written to a temporary file beside the target and renamed, so a killed run
//! never leaves a half-written restart.

use super::args::Args;
use super::Session;
use crate::engine::domain::{Domain, Side};
use crate::engine::fix::Fix;
use crate::engine::particles::{NewParticle, PerAtom};
use crate::engine::sim::Sim;
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{Command, Span, Variables, Word};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

const FORMAT: &str = "demx-restart-1";

#[derive(Serialize, Deserialize)]
struct Extra {
    name: String,
    width: usize,
    data: Vec<f64>,
    default: Vec<f64>,
    #[serde(default)]
    from_position: bool,
}

/// Everything a restart file holds.
#[derive(Serialize, Deserialize)]
pub struct RestartState {
    format: String,
    step: i64,
    time: f64,
    dt: f64,
    lost: u64,
    lo: [f64; 3],
    hi: [f64; 3],
    lo0: [f64; 3],
    hi0: [f64; 3],
    sides: String,
    dimension: u8,
    ntypes: usize,
    groups: Vec<String>,
    tag: Vec<i64>,
    kind: Vec<u32>,
    mask: Vec<u32>,
    x: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    omega: Vec<[f64; 3]>,
    radius: Vec<f64>,
    mass: Vec<f64>,
    density: Vec<f64>,
    image: Vec<[i32; 3]>,
    frozen: Vec<bool>,
    extra: Vec<Extra>,
    f: Vec<[f64; 3]>,
    torque: Vec<[f64; 3]>,
    pair_keys: Vec<(i64, i64)>,
    pair_hist: Vec<f64>,
    pair_width: usize,
    pair_a: Vec<u32>,
    pair_b: Vec<u32>,
    pair_shift: Vec<[f64; 3]>,
    adj_start: Vec<u32>,
    adj: Vec<u32>,
    x_built: Vec<[f64; 3]>,
    last_build: i64,
    builds: u64,
    /// The pair virial of the last force pass (its trace; its tensor where
    /// that pass summed it), which the resumed run's first thermo line
    /// prints, as the saved forces stand for that pass.
    #[serde(default)]
    virial: f64,
    #[serde(default)]
    virial_tensor: Option<[f64; 6]>,
    /// The pair list no longer fits the particles (built before some were
    /// inserted or deleted): the next run rebuilds it.
    #[serde(default)]
    stale: bool,
    /// Commands (as text) that defined units, materials and the contact model.
    pub replay: Vec<String>,
}

fn v3(v: &V3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

impl RestartState {
    /// Snapshot of a simulation (with `replay` commands from the session).
    pub fn of(sim: &Sim, replay: Vec<String>) -> Result<RestartState> {
        let d = sim.domain.as_ref().ok_or_else(|| Error::runtime("write_restart before the box exists"))?;
        let p = &sim.particles;
        // the list as if it had not been pruned: the resumed run need not
        // know the prune
        // a list built before particles were inserted or deleted (between
        // runs) is kept as it is, for the next build to carry its histories
        // over by ids, as the uninterrupted run's next build does
        let stale = sim.force_rebuild || !sim.pairs.fits(p.len());
        let pairs = if stale { sim.pairs.unpruned() } else { sim.pairs.full(p.len()) };
        let (adj_start, adj) = if stale { (vec![0; p.len() + 1], vec![]) } else { pairs.adjacency(p.len()) };
        let sides: String = d.sides.iter().flat_map(|s| [s[0].letter(), s[1].letter()]).collect();
        Ok(RestartState {
            format: FORMAT.into(),
            step: sim.step,
            time: sim.time,
            dt: sim.dt,
            lost: sim.lost,
            lo: d.lo,
            hi: d.hi,
            lo0: d.lo0,
            hi0: d.hi0,
            sides,
            dimension: d.dimension,
            ntypes: sim.ntypes,
            groups: sim.groups.clone(),
            tag: p.tag.clone(),
            kind: p.kind.clone(),
            mask: p.mask.clone(),
            x: p.x.iter().map(v3).collect(),
            v: p.v.iter().map(v3).collect(),
            omega: p.omega.iter().map(v3).collect(),
            radius: p.radius.clone(),
            mass: p.mass.clone(),
            density: p.density.clone(),
            image: p.image.clone(),
            frozen: p.frozen.clone(),
            extra: p
                .extra
                .iter()
                .map(|e| Extra {
                    name: e.name.clone(),
                    width: e.width,
                    data: e.data.clone(),
                    default: e.default.clone(),
                    from_position: e.from_position,
                })
                .collect(),
            f: p.f.iter().map(v3).collect(),
            torque: p.torque.iter().map(v3).collect(),
            pair_keys: pairs.keys.clone(),
            pair_hist: pairs.hist.clone(),
            pair_width: pairs.width,
            pair_a: pairs.a.clone(),
            pair_b: pairs.b.clone(),
            pair_shift: (0..pairs.len()).map(|k| v3(&pairs.shift(k))).collect(),
            adj_start,
            adj,
            x_built: pairs.x_built.iter().map(v3).collect(),
            last_build: pairs.last_build,
            builds: pairs.builds,
            virial: sim.pair_virial.trace,
            virial_tensor: sim.virial_tensor(),
            stale,
            replay,
        })
    }

    /// The step it was taken at.
    pub fn step(&self) -> i64 {
        self.step
    }

    /// Write atomically (temporary file + rename).
    ///
    /// Written to `.NAME.tmp` beside it and renamed: a run killed while
    /// writing leaves the previous file whole, and its partial temporary
    /// file is the one the next write of that name replaces (a random
    /// temporary name was left behind for good).
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let name = path.file_name().ok_or_else(|| std::io::Error::other("a restart file needs a file name"))?;
        let tmp = path.with_file_name(format!(".{}.tmp", name.to_string_lossy()));
        let f = std::fs::File::create(&tmp)?;
        {
            let mut w = std::io::BufWriter::new(&f);
            serde_json::to_writer(&mut w, self).map_err(std::io::Error::other)?;
            w.flush()?;
        }
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    }

    /// Read a restart file.
    pub fn read(path: &Path) -> std::result::Result<RestartState, String> {
        let f = std::fs::File::open(path).map_err(|e| e.to_string())?;
        let st: RestartState = serde_json::from_reader(std::io::BufReader::new(f)).map_err(|e| {
            format!(
                "not a demx restart file ({e}); demx reads only restart files written by demx (binary LAMMPS/LIGGGHTS restarts are engine-specific)"
            )
        })?;
        if st.format != FORMAT {
            return Err(format!("restart format '{}' (expected {FORMAT})", st.format));
        }
        Ok(st)
    }

    /// What a run needs of the values, as the deck commands that made them
    /// would have checked (a crafted or damaged file hung the run on mass 0
    /// or an inverted box and panicked on a short per-atom column, a
    /// per-atom width 0 or a type above ntypes): the first value that is
    /// not, named with its particle.
    fn check_values(&self) -> std::result::Result<(), String> {
        if !(1..=i32::MAX as usize).contains(&self.ntypes) {
            return Err(format!("restart file: {} atom types (1 to {} possible)", self.ntypes, i32::MAX));
        }
        let bytes = 2.0 * ((self.ntypes + 1) as f64).powi(2) * std::mem::size_of::<crate::physics::PairParams>() as f64;
        if !crate::limits::fits(bytes) {
            return Err(format!("restart file: {} atom types need {}; {}", self.ntypes, crate::limits::human(bytes), crate::limits::machine()));
        }
        if !matches!(self.dimension, 2 | 3) {
            return Err(format!("restart file: dimension {} (2 or 3)", self.dimension));
        }
        for d in 0..3 {
            let (lo, hi) = (self.lo[d], self.hi[d]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) || !(self.lo0[d].is_finite() && self.hi0[d].is_finite()) {
                return Err(format!("restart file: box {lo} to {hi} along axis {d} (finite, lo < hi)"));
            }
        }
        if !(self.dt.is_finite() && self.dt > 0.0) || !self.time.is_finite() || self.step < 0 {
            return Err(format!("restart file: step {}, time {}, time step {} (step >= 0, dt > 0, finite)", self.step, self.time, self.dt));
        }
        if self.groups.len() > 32 {
            return Err(format!("restart file: {} groups (at most 32)", self.groups.len()));
        }
        for i in 0..self.tag.len() {
            let finite = |v: &[f64; 3]| v.iter().all(|c| c.is_finite());
            let bad = if self.kind[i] < 1 || self.kind[i] as usize > self.ntypes {
                Some(format!("type {} (1 to {})", self.kind[i], self.ntypes))
            } else if !(self.mass[i] > 0.0 && self.mass[i].is_finite()) {
                Some(format!("mass {} (> 0)", self.mass[i]))
            } else if !(self.radius[i] > 0.0 && self.radius[i].is_finite()) {
                Some(format!("radius {} (> 0)", self.radius[i]))
            } else if !(self.density[i] > 0.0 && self.density[i].is_finite()) {
                Some(format!("density {} (> 0)", self.density[i]))
            } else if !(finite(&self.x[i]) && finite(&self.v[i]) && finite(&self.omega[i])) {
                Some("a position, velocity or angular velocity that is not finite".to_string())
            } else {
                None
            };
            if let Some(b) = bad {
                return Err(format!("restart file: particle {} has {b}", self.tag[i]));
            }
        }
        for e in &self.extra {
            if e.width == 0 || e.data.len() != e.width * self.tag.len() || e.default.len() != e.width {
                return Err(format!(
                    "restart file: per-atom property '{}' has width {} and {} values for {} particles (width >= 1, width x particles values, width defaults)",
                    e.name,
                    e.width,
                    e.data.len(),
                    self.tag.len()
                ));
            }
        }
        if self.pair_width > 64 {
            return Err(format!("restart file: {} history values per pair (at most 64)", self.pair_width));
        }
        Ok(())
    }

    /// Put the state into a simulation (replacing particles and box).
    pub fn apply(self, sim: &mut Sim) -> std::result::Result<(), String> {
        let n = self.tag.len();
        let ok = [
            self.kind.len(),
            self.mask.len(),
            self.x.len(),
            self.v.len(),
            self.omega.len(),
            self.radius.len(),
            self.mass.len(),
            self.density.len(),
            self.image.len(),
            self.frozen.len(),
        ]
        .iter()
        .all(|&l| l == n);
        if !ok || self.sides.len() != 6 {
            return Err("restart file is inconsistent (column lengths differ)".into());
        }
        self.check_values()?;
        let mut sides = [[Side::Periodic; 2]; 3];
        let cs: Vec<char> = self.sides.chars().collect();
        for d in 0..3 {
            for k in 0..2 {
                sides[d][k] = Side::from_char(cs[2 * d + k]).ok_or("bad boundary in restart")?;
            }
        }
        let mut dom = Domain::new(self.lo, self.hi, sides, self.dimension);
        dom.lo0 = self.lo0;
        dom.hi0 = self.hi0;
        sim.domain = Some(dom);
        sim.ntypes = self.ntypes;
        sim.groups = self.groups;
        sim.step = self.step;
        sim.time = self.time;
        sim.dt = self.dt;
        sim.lost = self.lost;
        let p = &mut sim.particles;
        *p = Default::default();
        for i in 0..n {
            let x = self.x[i];
            p.push(NewParticle {
                tag: self.tag[i],
                kind: self.kind[i],
                mask: self.mask[i],
                x: V3::new(x[0], x[1], x[2]),
                v: V3::new(self.v[i][0], self.v[i][1], self.v[i][2]),
                omega: V3::new(self.omega[i][0], self.omega[i][1], self.omega[i][2]),
                radius: self.radius[i],
                density: self.density[i],
            });
            p.mass[i] = self.mass[i];
            p.image[i] = self.image[i];
            p.frozen[i] = self.frozen[i];
        }
        p.extra = self
            .extra
            .into_iter()
            .map(|e| PerAtom { name: e.name, width: e.width, data: e.data, default: e.default, from_position: e.from_position })
            .collect();
        let m = self.pair_keys.len();
        let consistent = self.pair_a.len() == m
            && self.pair_b.len() == m
            && self.pair_shift.len() == m
            && self.pair_hist.len() == m * self.pair_width
            && self.adj_start.len() == n + 1
            && (self.stale || self.x_built.len() == n)
            && self.f.len() == n
            && self.torque.len() == n
            && (self.stale || self.pair_a.iter().chain(&self.pair_b).all(|&k| (k as usize) < n.max(1)));
        if !consistent {
            return Err("restart file is inconsistent (pair list)".into());
        }
        for i in 0..n {
            p.f[i] = V3::new(self.f[i][0], self.f[i][1], self.f[i][2]);
            p.torque[i] = V3::new(self.torque[i][0], self.torque[i][1], self.torque[i][2]);
        }
        let a3 = |v: &[f64; 3]| V3::new(v[0], v[1], v[2]);
        sim.pairs = crate::engine::neighbor::PairList {
            a: self.pair_a,
            b: self.pair_b,
            hist: self.pair_hist,
            width: self.pair_width,
            keys: self.pair_keys,
            x_built: self.x_built.iter().map(a3).collect(),
            last_build: self.last_build,
            builds: self.builds,
            dangerous: 0,
            ..Default::default()
        };
        sim.pairs.set_shifts(&self.pair_shift.iter().map(a3).collect::<Vec<_>>());
        if !self.stale {
            sim.pairs.index(n);
        }
        sim.pair_virial = crate::engine::kernel::Virial { trace: self.virial, tensor: self.virial_tensor.unwrap_or_default() };
        sim.tensor_at = self.virial_tensor.map(|_| self.step);
        // continue exactly: the next run reuses the saved list and forces
        // (a stale list is rebuilt first, as the uninterrupted run does)
        sim.force_rebuild = self.stale;
        sim.resume = !self.stale;
        Ok(())
    }
}

/// At most 80 characters of `text`, for a message.
fn cut(text: &str) -> String {
    match text.char_indices().nth(80) {
        Some((k, _)) => format!("{}...", &text[..k]),
        None => text.to_string(),
    }
}

/// `restart N file [file2]`: periodic restart files.
pub struct RestartWriter {
    every: i64,
    files: Vec<String>,
    toggle: usize,
    replay: Vec<String>,
}

impl Fix for RestartWriter {
    fn save_state(&self) -> crate::engine::fix::FixState {
        crate::engine::fix::FixState::Saved(serde_json::json!(self.toggle))
    }
    fn load_state(&mut self, state: &serde_json::Value) -> std::result::Result<(), String> {
        self.toggle = state.as_u64().ok_or("restart toggle")? as usize;
        Ok(())
    }
    crate::no_step_hooks!();
    fn id(&self) -> &str {
        "__restart"
    }
    fn style(&self) -> &str {
        "restart"
    }
    fn end_of_step_due(&self, step: i64) -> bool {
        self.every > 0 && step % self.every == 0
    }
    fn end_of_step(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        if !self.end_of_step_due(sim.step) || sim.dry {
            return Ok(());
        }
        let name = if self.files.len() == 2 {
            let f = self.files[self.toggle].clone();
            self.toggle = 1 - self.toggle;
            f
        } else {
            self.files[0].replace('*', &sim.step.to_string())
        };
        let st = RestartState::of(sim, self.replay.clone())?;
        st.write(Path::new(&name)).map_err(|e| Error::runtime(format!("cannot write restart file '{name}': {e}")))
    }
    fn summary(&self) -> String {
        format!("restart every {} steps -> {}", self.every, self.files.join(" "))
    }
}

/// Execute write_restart, read_restart, restart, read_data, write_data.
pub fn execute(s: &mut Session, cmd: &Command, vars: &mut Variables) -> Result<()> {
    let mut a = Args::new(cmd);
    match cmd.name() {
        "write_restart" => {
            s.need_box(cmd)?;
            let w = a.word("file")?;
            // `demx check` and a checkpoint's replay write nothing
            if s.check || s.sim.dry {
                return Ok(());
            }
            let name = w.text.replace('*', &s.sim.step.to_string());
            let st = RestartState::of(&s.sim, s.replay.clone())?;
            st.write(Path::new(&name)).map_err(|e| Error::io(w.span, format!("cannot write restart file '{name}'"), &e))
        }
        "restart" => {
            let n = a.i64("N")?;
            let mut files = vec![];
            while a.more() {
                let w = a.word("file")?;
                if ["fileper", "nfile"].contains(&w.text.as_str()) {
                    a.word("value")?;
                    continue;
                }
                files.push(w.text.clone());
            }
            s.sim.fixes.retain(|f| f.id() != "__restart");
            if n == 0 {
                return Ok(());
            }
            if files.is_empty() || files.len() > 2 {
                return Err(Error::deck(a.end_span(), "restart: give one file name (with * for the step) or two names to toggle between"));
            }
            let replay = s.replay.clone();
            s.sim.fixes.push(Box::new(RestartWriter { every: n, files, toggle: 0, replay }));
            Ok(())
        }
        "read_restart" => {
            let w = a.word("file")?;
            if s.sim.domain.is_some() {
                return Err(Error::deck(cmd.words[0].span, "read_restart: the box already exists"));
            }
            let name = w.text.replace('*', "");
            let path = Path::new(&name);
            if !path.exists() {
                return Err(Error::io(w.span, format!("cannot open restart file '{}'", w.text), &std::io::Error::from(std::io::ErrorKind::NotFound)));
            }
            let st = RestartState::read(path).map_err(|e| Error::deck(w.span, e))?;
            let replay = st.replay.clone();
            st.apply(&mut s.sim).map_err(|e| Error::deck(w.span, e))?;
            for text in replay {
                let words: Vec<Word> = text.split_whitespace().map(|t| Word::new(t, Span::DUMMY)).collect();
                let c = Command { words, span: Span::DUMMY };
                // only what a restart carries (units, styles, the contact
                // model, materials): a crafted file's `fix print ... file`
                // would otherwise run
                if !super::replayed(&c) {
                    return Err(Error::deck(w.span, format!("restart file replays '{}', which a restart file does not carry", cut(&text))));
                }
                s.execute_replay(&c, vars)?;
            }
            Ok(())
        }
        "read_data" => read_data(s, cmd, &mut a),
        "write_data" => {
            s.need_box(cmd)?;
            let w = a.word("file")?;
            // `demx check` and a checkpoint's replay write nothing
            if s.check || s.sim.dry {
                return Ok(());
            }
            let d = s.sim.domain.as_ref().ok_or_else(|| Error::runtime("no box"))?;
            let p = &s.sim.particles;
            let atoms = (0..p.len())
                .map(|i| crate::io::data::DataAtom {
                    id: p.tag[i] as u64,
                    kind: p.kind[i],
                    diameter: 2.0 * p.radius[i],
                    density: p.density[i],
                    x: v3(&p.x[i]),
                    image: p.image[i],
                    v: v3(&p.v[i]),
                    omega: v3(&p.omega[i]),
                })
                .collect();
            let df = crate::io::data::DataFile {
                title: "LAMMPS data file via write_data, written by demx".into(),
                atom_types: s.sim.ntypes as u32,
                lo: d.lo,
                hi: d.hi,
                tilt: None,
                masses: vec![],
                atoms,
                has_velocities: true,
            };
            let engine =
                if s.sim.dialect == crate::engine::Dialect::Liggghts { crate::io::dump::Engine::Liggghts } else { crate::io::dump::Engine::Lammps };
            crate::io::data::write_data(&w.text, &df, engine, s.sim.step.max(0) as u64)
        }
        _ => unreachable!("restart::execute dispatched a command it does not handle"),
    }
}

fn read_data(s: &mut Session, cmd: &Command, a: &mut Args) -> Result<()> {
    let w = a.word("file")?;
    let mut append = false;
    let mut shift = V3::zeros();
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "add" => {
                let v = a.word("add value")?;
                if v.text != "append" && v.text != "merge" {
                    return Err(Error::unsupported(v.span, format!("read_data add {}", v.text)));
                }
                append = true;
            }
            "shift" => shift = V3::new(a.f64("dx")?, a.f64("dy")?, a.f64("dz")?),
            "extra/atom/types" | "extra/bond/types" | "extra/angle/types" | "extra/bond/per/atom" | "extra/special/per/atom" => {
                a.i64("count")?;
            }
            "fix" => {
                a.word("fix id")?;
                a.word("header")?;
                a.word("section")?;
            }
            _ => return Err(Error::unsupported(k.span, format!("read_data keyword {}", k.text))),
        }
    }
    if !std::path::Path::new(&w.text).exists() {
        return Err(Error::io(w.span, format!("cannot open data file '{}'", w.text), &std::io::Error::from(std::io::ErrorKind::NotFound)));
    }
    let df = crate::io::data::read_data(&w.text).map_err(|e| Error::deck(w.span, e.message()))?;
    if s.sim.domain.is_none() {
        if append {
            return Err(Error::deck(cmd.words[0].span, "read_data add needs an existing box"));
        }
        if df.tilt.is_some() {
            return Err(Error::unsupported(w.span, "triclinic boxes"));
        }
        let sides = s.pending_sides.unwrap_or([[Side::Periodic; 2]; 3]);
        s.sim.domain = Some(Domain::new(df.lo, df.hi, sides, s.dimension));
        s.sim.ntypes = df.atom_types as usize;
    } else if !append {
        return Err(Error::deck(cmd.words[0].span, "read_data: the box already exists").with_hint("use `read_data FILE add append`"));
    }
    let offset = if append { s.sim.particles.max_tag() } else { 0 };
    for at in &df.atoms {
        s.sim.particles.push(NewParticle {
            tag: at.id as i64 + offset,
            kind: at.kind,
            mask: 1,
            x: V3::new(at.x[0], at.x[1], at.x[2]) + shift,
            v: V3::new(at.v[0], at.v[1], at.v[2]),
            omega: V3::new(at.omega[0], at.omega[1], at.omega[2]),
            radius: 0.5 * at.diameter,
            density: at.density,
        });
        let k = s.sim.particles.len() - 1;
        s.sim.particles.image[k] = at.image;
    }
    s.sources.push(format!("read_data {}: {} particles", w.text, df.atoms.len()));
    s.sim.force_rebuild = true;
    s.sim.log.line(&format!("  {} atoms", df.atoms.len()));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::rng::Park;

    /// Positions read back from a restart file are the written ones to the
    /// last bit, over values of every magnitude a deck produces.
    #[test]
    fn restart_round_trips_every_float_exactly() {
        let mut sim = Sim::default();
        sim.domain = Some(Domain::new([0.0; 3], [1.0; 3], [[Side::Periodic; 2]; 3], 3));
        // what create_box and timestep give a run (a restart checks them)
        sim.ntypes = 1;
        sim.dt = 1e-6;
        let mut rng = Park::new(4711);
        let n = 2000;
        for k in 0..n {
            // mantissas of all kinds, scales from 1e-9 to 1e3
            let s = 10f64.powi((k % 13) as i32 - 9);
            let x = V3::new(rng.uniform() * s, rng.uniform() * s, (rng.uniform() - 0.5) * s);
            sim.particles.push(NewParticle { tag: k as i64 + 1, kind: 1, mask: 1, x, v: x * 3.7, omega: x * -1.3, radius: 1e-3, density: 2500.0 });
        }
        sim.pairs.index(n);
        sim.pairs.x_built = sim.particles.x.clone();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("restart.1");
        RestartState::of(&sim, vec![]).unwrap().write(&path).unwrap();
        let mut back = Sim::default();
        RestartState::read(&path).unwrap().apply(&mut back).unwrap();
        let bits = |p: &crate::engine::particles::Particles| -> Vec<u64> {
            p.x.iter().chain(&p.v).chain(&p.omega).flat_map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]).collect()
        };
        let (a, b) = (bits(&sim.particles), bits(&back.particles));
        let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "{differ} of {} values changed in the round trip", a.len());
    }
}
