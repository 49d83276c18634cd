//! Screen/log output, thermo lines in each engine's format, and the dump
//! interface.

use super::sim::{Dialect, Sim};
use crate::error::{Error, Result};
use crate::io::cfmt::{sprintf, CArg};
use crate::script::Variables;
use std::fs::File;
use std::io::{IsTerminal, Write};

/// Screen and log file.
pub struct Logger {
    /// Print to stdout.
    pub screen: bool,
    /// The log file, flushed after every line.
    pub file: Option<File>,
    /// Its path as opened (a checkpoint records it with the file's length).
    pub path: Option<std::path::PathBuf>,
    /// Whether a progress line is currently shown on the terminal.
    progress_shown: bool,
    /// Whether stderr is a terminal (progress lines only then).
    pub tty: bool,
    /// Everything printed, kept when `capture` is on (tests, check).
    pub captured: Option<String>,
    /// When the progress line was last drawn.
    last_progress: Option<std::time::Instant>,
}

impl Default for Logger {
    fn default() -> Self {
        Logger {
            screen: true,
            file: None,
            path: None,
            progress_shown: false,
            tty: std::io::stderr().is_terminal(),
            captured: None,
            last_progress: None,
        }
    }
}

impl Logger {
    /// Print a line (or several) to screen and log.
    pub fn line(&mut self, text: &str) {
        self.clear_progress();
        let text = text.strip_suffix('\n').unwrap_or(text);
        if self.screen {
            let mut out = std::io::stdout().lock();
            let _ = writeln!(out, "{text}");
        }
        if let Some(f) = &mut self.file {
            let _ = writeln!(f, "{text}");
            let _ = f.flush();
        }
        if let Some(c) = &mut self.captured {
            c.push_str(text);
            c.push('\n');
        }
    }
    /// Show a progress line on the terminal only (never in logs or pipes).
    pub fn progress(&mut self, text: &str) {
        if self.tty && self.screen {
            let _ = write!(std::io::stderr(), "\r\x1b[2K{text}");
            self.progress_shown = true;
        }
    }
    /// Remove the progress line.
    pub fn clear_progress(&mut self) {
        if self.progress_shown {
            let _ = write!(std::io::stderr(), "\r\x1b[2K");
            self.progress_shown = false;
        }
    }
    /// Open (or append to) a log file.
    pub fn open(&mut self, path: &str, append: bool) -> std::io::Result<()> {
        let f = if append { std::fs::OpenOptions::new().create(true).append(true).open(path)? } else { File::create(path)? };
        self.file = Some(f);
        self.path = Some(std::path::PathBuf::from(path));
        Ok(())
    }
}

/// Redraw the progress line (step, particles, elapsed, steps/s, ETA) of a
/// run of `n` steps started at `t0`, at most 4 times a second, on a terminal
/// only; cleared at the run's last step.
pub fn show_progress(sim: &mut Sim, t0: std::time::Instant, n: i64) {
    if !(sim.log.tty && sim.log.screen) {
        return;
    }
    let now = std::time::Instant::now();
    if sim.step >= sim.run_end {
        sim.log.clear_progress();
        sim.log.last_progress = None;
        return;
    }
    if sim.log.last_progress.is_some_and(|t| now.duration_since(t).as_secs_f64() < 0.25) {
        return;
    }
    sim.log.last_progress = Some(now);
    let done = sim.step - sim.run_start;
    let secs = now.duration_since(t0).as_secs_f64();
    let rate = if secs > 0.0 { done as f64 / secs } else { 0.0 };
    let eta = if rate > 0.0 { (n - done) as f64 / rate } else { f64::NAN };
    let text = progress_text(sim.step, sim.run_end, sim.particles.len(), secs, rate, eta);
    sim.log.progress(&text);
}

/// The progress line's text.
pub fn progress_text(step: i64, end: i64, particles: usize, elapsed: f64, rate: f64, eta: f64) -> String {
    let hms = |t: f64| {
        if !t.is_finite() {
            return "--:--:--".to_string();
        }
        let s = t.round() as i64;
        format!("{:02}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
    };
    format!("step {step}/{end}  {particles} particles  elapsed {}  {rate:.1} steps/s  ETA {}", hms(elapsed), hms(eta))
}

/// What to do with particles lost through fixed boundaries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum LostPolicy {
    /// Stop the run (LAMMPS default).
    Error,
    /// Warn once and delete them.
    Warn,
    /// Delete them silently.
    Ignore,
}

/// Thermo settings (`thermo`, `thermo_style`, `thermo_modify`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Thermo {
    /// Print every N steps (0: only first and last step of a run).
    pub every: i64,
    /// Keywords.
    pub keywords: Vec<String>,
    /// The style is `one` (also by default): the columns are the dialect's
    /// ([`one_style`]), settled when a run starts.
    pub one: bool,
    /// Lost-atom policy.
    pub lost: LostPolicy,
    /// Normalise extensive quantities by atom count.
    pub norm: bool,
    /// `thermo_modify norm` was given; otherwise `norm` follows the units
    /// (yes for lj, as LAMMPS's and LIGGGHTS's `Thermo::init`).
    pub norm_set: bool,
    /// Format of the whole line (`thermo_modify format line`).
    pub format_line: Option<String>,
    /// Per-column formats (`thermo_modify format N fmt`), by 1-based column.
    pub format_col: Vec<(usize, String)>,
    /// `thermo_modify format float`.
    pub format_float: Option<String>,
    /// `thermo_modify format int`.
    pub format_int: Option<String>,
    /// Which engine's layout to copy.
    pub dialect: Dialect,
}

/// The columns of `thermo_style one`, each engine's default: LAMMPS's
/// `Step Temp E_pair E_mol TotEng Press`, LIGGGHTS 3.8's `Step Atoms KinEng
/// CPU` (its thermo.cpp defines "one" as `step atoms ke cpu`; checked by
/// running a deck without thermo_style).
pub fn one_style(d: Dialect) -> Vec<String> {
    let ks: &[&str] = match d {
        Dialect::Lammps => &["step", "temp", "epair", "emol", "etotal", "press"],
        Dialect::Liggghts => &["step", "atoms", "ke", "cpu"],
    };
    ks.iter().map(|k| k.to_string()).collect()
}

impl Default for Thermo {
    fn default() -> Self {
        Thermo {
            every: 0,
            keywords: one_style(Dialect::Lammps),
            one: true,
            lost: LostPolicy::Error,
            norm: false,
            norm_set: false,
            format_line: None,
            format_col: vec![],
            format_float: None,
            format_int: None,
            dialect: Dialect::Lammps,
        }
    }
}

fn header_name(k: &str) -> String {
    match k {
        "step" => "Step".into(),
        "elapsed" => "Elapsed".into(),
        "elaplong" => "Elaplong".into(),
        "dt" => "Dt".into(),
        "time" => "Time".into(),
        "cpu" => "CPU".into(),
        "atoms" => "Atoms".into(),
        "temp" => "Temp".into(),
        "press" => "Press".into(),
        "pe" => "PotEng".into(),
        "ke" => "KinEng".into(),
        "etotal" => "TotEng".into(),
        "epair" => "E_pair".into(),
        "emol" => "E_mol".into(),
        "vol" => "Volume".into(),
        "lx" => "Lx".into(),
        "ly" => "Ly".into(),
        "lz" => "Lz".into(),
        "xlo" => "Xlo".into(),
        "xhi" => "Xhi".into(),
        "ylo" => "Ylo".into(),
        "yhi" => "Yhi".into(),
        "zlo" => "Zlo".into(),
        "zhi" => "Zhi".into(),
        "spcpu" => "S/CPU".into(),
        "cpuremain" => "CPULeft".into(),
        "density" => "Density".into(),
        "pxx" => "Pxx".into(),
        "pyy" => "Pyy".into(),
        "pzz" => "Pzz".into(),
        "pxy" => "Pxy".into(),
        "pxz" => "Pxz".into(),
        "pyz" => "Pyz".into(),
        other => other.to_string(),
    }
}

/// The thermo keywords of the pressure tensor, in LAMMPS's order of its
/// components.
pub const TENSOR_KEYWORDS: [&str; 6] = ["pxx", "pyy", "pzz", "pxy", "pxz", "pyz"];

/// Component `k` (xx, yy, zz, xy, xz, yz) of the pressure tensor, as
/// LAMMPS's `compute pressure` (thermo_press, with thermo_temp's kinetic
/// tensor) gives it in `compute_vector`: (sum m v_a v_b + W_ab) / V, with W
/// the pair virial tensor of the last force pass; in 2d V is the area and the
/// components with z are 0. `None` when the last force pass did not sum the
/// tensor ([`Sim::virial_tensor`]).
fn pressure_component(sim: &Sim, k: usize) -> Option<f64> {
    let w = sim.virial_tensor()?;
    let Some(d) = sim.domain.as_ref() else { return Some(0.0) };
    let v = d.volume();
    if v == 0.0 || (d.dimension == 2 && k != 0 && k != 1 && k != 3) {
        return Some(0.0);
    }
    // thermo_temp's vector: the kinetic tensor, summed atom by atom
    let (a, b) = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)][k];
    let p = &sim.particles;
    let ke: f64 = (0..p.len()).map(|i| p.mass[i] * p.v[i][a] * p.v[i][b]).sum();
    Some((ke + w[k]) / v)
}

fn is_int_keyword(k: &str) -> bool {
    matches!(k, "step" | "elapsed" | "elaplong" | "atoms" | "nbuild" | "ndanger")
}

impl Thermo {
    /// Whether a column is a component of the pressure tensor, which the
    /// force passes of the steps that print it sum ([`Sim::virial_tensor`]).
    pub fn reads_tensor(&self) -> bool {
        self.keywords.iter().any(|k| TENSOR_KEYWORDS.contains(&k.as_str()))
    }

    /// The header line.
    pub fn header(&self, _sim: &Sim) -> String {
        let mut s = String::new();
        for k in &self.keywords {
            let name = match self.dialect {
                // LIGGGHTS 3.8 prints c_ID / f_ID / v_ID headers without the
                // prefix and cut to 8 characters (`f_heattransfer` ->
                // `heattran`, `c_centreofmass[3]` -> `centreof`; seen in
                // its output)
                Dialect::Liggghts => {
                    let h = header_name(k);
                    match h.strip_prefix("c_").or_else(|| h.strip_prefix("f_")).or_else(|| h.strip_prefix("v_")) {
                        Some(id) => id.chars().take(8).collect(),
                        None => h,
                    }
                }
                Dialect::Lammps => header_name(k),
            };
            match self.dialect {
                Dialect::Lammps => {
                    s.push_str(&name);
                    s.push(' ');
                }
                Dialect::Liggghts => {
                    let w = if is_int_keyword(k) { 8 } else { 14 };
                    s.push_str(&format!("{name:>w$} "));
                }
            }
        }
        s
    }

    /// One thermo line at the current step.
    pub fn line(&self, sim: &Sim, vars: &Variables) -> Result<String> {
        let mut vals: Vec<(bool, f64)> = Vec::with_capacity(self.keywords.len());
        for k in &self.keywords {
            let v = thermo_value(sim, vars, k)?;
            vals.push((is_int_keyword(k), v));
        }
        if let Some(fl) = &self.format_line {
            let args: Vec<CArg> = vals.iter().map(|&(int, v)| if int { CArg::Int(v as i64) } else { CArg::Float(v) }).collect();
            return sprintf(fl, &args).map_err(|e| Error::runtime(format!("thermo_modify format line: {e}")));
        }
        let mut s = String::new();
        for (col, &(int, v)) in vals.iter().enumerate() {
            let custom = self.format_col.iter().find(|(c, _)| *c == col + 1).map(|(_, f)| f.clone());
            let fmt = custom.or_else(|| if int { self.format_int.clone() } else { self.format_float.clone() });
            let text = match fmt {
                Some(f) => sprintf(&f, &[if int { CArg::Int(v as i64) } else { CArg::Float(v) }]).unwrap_or_else(|_| v.to_string()),
                None => match (self.dialect, int) {
                    (Dialect::Lammps, true) => format!("{:>8}", v as i64),
                    (Dialect::Lammps, false) => format!("{:>12}", crate::io::cfmt::fmt_g(v, 8)),
                    (Dialect::Liggghts, true) => format!("{:>8}", v as i64),
                    (Dialect::Liggghts, false) => format!("{:>14}", crate::io::cfmt::fmt_g(v, 8)),
                },
            };
            s.push_str(&text);
            s.push(' ');
        }
        Ok(s)
    }
}

/// Value of one thermo column: keyword, c_ID[i], f_ID[i], v_name.
pub fn thermo_value(sim: &Sim, vars: &Variables, k: &str) -> Result<f64> {
    use crate::script::EvalContext;
    let err = |e: String| Error::runtime(format!("thermo keyword {k}: {e}"));
    if let Some(rest) = k.strip_prefix("c_") {
        let (id, i) = split_bracket(rest);
        return sim.compute(id, i, None).map_err(err);
    }
    if let Some(rest) = k.strip_prefix("f_") {
        let (id, i) = split_bracket(rest);
        return sim.fix(id, i, None).map_err(err);
    }
    if let Some(rest) = k.strip_prefix("v_") {
        return vars.eval_equal(rest, sim).map_err(err);
    }
    if TENSOR_KEYWORDS.contains(&k) && sim.virial_tensor().is_none() {
        return Err(Error::runtime(format!(
            "thermo keyword {k}: the pressure tensor was not summed at step {} (demx sums it where thermo prints it, and at every step where a variable reads it)",
            sim.step
        )));
    }
    thermo_keyword(sim, k).ok_or_else(|| Error::runtime(format!("unknown thermo keyword {k}")))
}

fn split_bracket(s: &str) -> (&str, Option<usize>) {
    match s.find('[') {
        Some(b) => (&s[..b], s[b + 1..].trim_end_matches(']').parse().ok()),
        None => (s, None),
    }
}

/// Built-in thermo keywords.
pub fn thermo_keyword(sim: &Sim, k: &str) -> Option<f64> {
    let n = sim.particles.len() as f64;
    let norm = |v: f64| if sim.thermo.norm && n > 0.0 { v / n } else { v };
    let d = sim.domain.as_ref();
    Some(match k {
        "step" => sim.step as f64,
        "elapsed" => (sim.step - sim.run_start) as f64,
        "elaplong" => (sim.step - sim.run_start) as f64,
        "dt" => sim.dt,
        "time" => sim.time,
        "cpu" => sim.clock.elapsed().as_secs_f64(),
        "atoms" => n,
        "temp" => sim.temperature(),
        "ke" if sim.dialect == super::sim::Dialect::Liggghts => {
            // LIGGGHTS: the plain sum of 1/2 m v^2 (also for a single atom)
            norm(sim.kinetic_energy(u32::MAX))
        }
        "ke" => {
            // LAMMPS `thermo.cpp` compute_ke: T * dof/2 * kB with the dof of
            // the run's setup, so 0 (or -0, dof < 0) in a run that started
            // with fewer than two atoms
            norm(sim.temperature() * 0.5 * sim.temp_dof() * sim.boltz)
        }
        "pe" | "epair" | "emol" | "evdwl" | "ecoul" | "ebond" | "elong" => 0.0,
        // pe + ke as LAMMPS adds them (pe is 0 for granular pairs), which
        // also turns ke's -0 into 0
        "etotal" => 0.0 + norm(sim.temperature() * 0.5 * sim.temp_dof() * sim.boltz),
        "press" => {
            let v = d.map_or(0.0, |d| d.volume());
            if v == 0.0 {
                0.0
            } else {
                let dim = d.map_or(3.0, |d| d.dimension as f64);
                (sim.temp_dof().max(0.0) * sim.boltz * sim.temperature() + sim.virial()) / (dim * v)
            }
        }
        "pxx" | "pyy" | "pzz" | "pxy" | "pxz" | "pyz" => pressure_component(sim, TENSOR_KEYWORDS.iter().position(|t| *t == k)?)?,
        "vol" => d.map_or(0.0, |d| d.volume()),
        "lx" => d.map_or(0.0, |d| d.len(0)),
        "ly" => d.map_or(0.0, |d| d.len(1)),
        "lz" => d.map_or(0.0, |d| d.len(2)),
        "xlo" => d.map_or(0.0, |d| d.lo[0]),
        "xhi" => d.map_or(0.0, |d| d.hi[0]),
        "ylo" => d.map_or(0.0, |d| d.lo[1]),
        "yhi" => d.map_or(0.0, |d| d.hi[1]),
        "zlo" => d.map_or(0.0, |d| d.lo[2]),
        "zhi" => d.map_or(0.0, |d| d.hi[2]),
        "density" => {
            let v = d.map_or(0.0, |d| d.volume());
            if v > 0.0 {
                sim.particles.mass.iter().sum::<f64>() / v
            } else {
                0.0
            }
        }
        "nbuild" => sim.pairs.builds as f64,
        "ndanger" => sim.pairs.dangerous as f64,
        "spcpu" => sim.last_rate,
        "cpuremain" => 0.0,
        "maxoverlap" => max_overlap(sim),
        _ => return None,
    })
}

/// Largest relative overlap delta / min(ri, rj) over current pairs (demx's
/// `maxoverlap` thermo keyword).
pub fn max_overlap(sim: &Sim) -> f64 {
    let p = &sim.particles;
    let mut m: f64 = 0.0;
    for k in 0..sim.pairs.len() {
        let (a, b) = (sim.pairs.a[k] as usize, sim.pairs.b[k] as usize);
        if a >= p.len() || b >= p.len() {
            continue;
        }
        let r = (p.x[a] - p.x[b] - sim.pairs.shift(k)).norm();
        let delta = p.radius[a] + p.radius[b] - r;
        m = m.max(delta / p.radius[a].min(p.radius[b]));
    }
    m
}

/// A dump (`dump ID group style N file ...`).
pub trait Dump: Send {
    /// Whether a frame is due at `step` (`first`: the start of a run).
    fn due(&self, step: i64, first: bool) -> bool;
    /// Write one frame (flushed).
    fn write(&mut self, sim: &Sim) -> Result<()>;
    /// The dump id.
    fn id(&self) -> &str;
    /// `dump_modify` options.
    fn modify(&mut self, _args: &[crate::script::Word]) -> Result<()> {
        Ok(())
    }
    /// One line for `demx check`.
    fn summary(&self) -> String;
    /// How this dump's file goes on across a checkpoint (`demx run
    /// --checkpoint`). The default says it cannot.
    fn checkpoint_file(&self) -> DumpFile {
        DumpFile::Unsupported
    }
    /// The step of the last frame written (a frame is written once per step).
    fn last_step(&self) -> Option<i64> {
        None
    }
    /// Resuming from a checkpoint: the step of the last frame written then,
    /// and whether the file goes on (cut back to its length at the
    /// checkpoint and appended to) instead of starting anew.
    fn resume_at(&mut self, _last_step: Option<i64>, _append: bool) {}
}

/// A dump's file at a checkpoint ([`Dump::checkpoint_file`]).
pub enum DumpFile {
    /// Not opened yet, or one file per frame: the resumed run writes as
    /// the uninterrupted one would.
    Fresh,
    /// One file, open: cut back to its length at the checkpoint, then appended to.
    Appended(std::path::PathBuf),
    /// A checkpoint cannot carry it on yet.
    Unsupported,
}

/// Placeholder while a dump writes.
pub struct NoDump;
impl Dump for NoDump {
    fn due(&self, _: i64, _: bool) -> bool {
        false
    }
    fn write(&mut self, _: &Sim) -> Result<()> {
        Ok(())
    }
    fn id(&self) -> &str {
        ""
    }
    fn summary(&self) -> String {
        String::new()
    }
}
