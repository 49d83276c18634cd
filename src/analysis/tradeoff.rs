//! `demx tradeoff DECK --vary NAME=V1,V2,... [--vary ...] --metric M`: what
//! accuracy costs in time. Runs the deck (this executable, `demx run`, one
//! subprocess per run, sequentially, each in its own folder) for every
//! setting of the grid of varied parameters and every seed, measures the wall
//! time and a metric of the result, and reports the metric (mean +- SD over
//! seeds), its error against the most accurate setting (or a given exact
//! value) and the speed-up: the cost-accuracy front.
//!
//! Parameters: `dt_fraction` (time step as a fraction of the Hertz time,
//! `demx run --dt-fraction`), `youngs_scale` (stiffnesses divided,
//! `demx run --youngs-scale`), `var:NAME` (a deck variable, `-var NAME V`).
//! Metrics: `repose` and `packing` (last dump frame, the paper's way),
//! `restitution` (two-particle decks: relative normal velocity at the last
//! dump frame over the first), `ke` and `custom:NAME` (last value of a thermo
//! column in the run's log).

use super::compare_deck::SEEDS;
use super::reference::{extract_vars, prepare_deck, tail, RefEngine};
use crate::error::{Error, Result};
use crate::io::dump::{DumpReader, Frame};
use crate::script::source::Span;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The names `--vary` accepts.
pub const VARY_NAMES: &str = "dt_fraction, youngs_scale, var:NAME";

/// A varied parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Param {
    /// `demx run --dt-fraction`.
    DtFraction,
    /// `demx run --youngs-scale`.
    YoungsScale,
    /// A deck variable (`-var NAME V`).
    Var(String),
}

impl Param {
    /// Name as written in `--vary`.
    pub fn name(&self) -> String {
        match self {
            Param::DtFraction => "dt_fraction".into(),
            Param::YoungsScale => "youngs_scale".into(),
            Param::Var(n) => format!("var:{n}"),
        }
    }
}

/// One `--vary NAME=V1,V2,...`.
#[derive(Clone, Debug, Serialize)]
pub struct Vary {
    /// The parameter.
    pub param: Param,
    /// Its values, as written.
    pub values: Vec<String>,
}

/// Parse `NAME=V1,V2,...`; errors name the valid parameters.
pub fn parse_vary(text: &str) -> Result<Vary> {
    let Some((name, vals)) = text.split_once('=') else {
        return Err(Error::usage(format!("--vary '{text}': expected NAME=V1,V2,... with NAME one of {VARY_NAMES}")));
    };
    let param = match name.trim() {
        "dt_fraction" => Param::DtFraction,
        "youngs_scale" => Param::YoungsScale,
        n => match n.strip_prefix("var:") {
            Some(v) if !v.is_empty() && v.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') => Param::Var(v.to_string()),
            _ => return Err(Error::usage(format!("--vary: unknown parameter '{n}' (valid names: {VARY_NAMES})"))),
        },
    };
    let values: Vec<String> = vals.split(',').map(|v| v.trim().to_string()).filter(|v| !v.is_empty()).collect();
    if values.is_empty() {
        return Err(Error::usage(format!("--vary {}: no values", param.name())));
    }
    if !matches!(param, Param::Var(_)) {
        for v in &values {
            match v.parse::<f64>() {
                Ok(x) if x > 0.0 && x.is_finite() => {}
                _ => return Err(Error::usage(format!("--vary {}: '{v}' is not a positive number", param.name()))),
            }
        }
    }
    Ok(Vary { param, values })
}

/// What is measured on each run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Metric {
    /// Angle of repose (degrees) of the last dump frame.
    Repose,
    /// Packing fraction of the last dump frame.
    Packing,
    /// Restitution coefficient of a two-particle collision (first and last dump frames).
    Restitution,
    /// Last thermo `ke`.
    Ke,
    /// Last value of a thermo column.
    Custom(String),
}

/// The names `--metric` accepts.
pub const METRIC_NAMES: &str = "repose, packing, restitution, ke, custom:NAME";

impl Metric {
    /// Parse a `--metric` value.
    pub fn parse(s: &str) -> Result<Metric> {
        Ok(match s {
            "repose" => Metric::Repose,
            "packing" => Metric::Packing,
            "restitution" => Metric::Restitution,
            "ke" => Metric::Ke,
            _ => match s.strip_prefix("custom:") {
                Some(n) if !n.is_empty() => Metric::Custom(n.to_string()),
                _ => return Err(Error::usage(format!("--metric: unknown metric '{s}' (valid: {METRIC_NAMES})"))),
            },
        })
    }
    /// Short name with units.
    pub fn label(&self) -> String {
        match self {
            Metric::Repose => "theta_r (deg)".into(),
            Metric::Packing => "packing fraction".into(),
            Metric::Restitution => "restitution".into(),
            Metric::Ke => "ke".into(),
            Metric::Custom(n) => n.clone(),
        }
    }
}

/// Arguments of `demx tradeoff`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "demx tradeoff",
    about = "What accuracy costs in time: run a deck over a grid of settings (and seeds) and report metric, error and wall time"
)]
pub struct TradeoffArgs {
    /// The deck.
    pub deck: PathBuf,
    /// NAME=V1,V2,... with NAME one of dt_fraction, youngs_scale, var:NAME;
    /// several --vary make a grid.
    #[arg(long, required = true, value_name = "NAME=V1,V2,...")]
    pub vary: Vec<String>,
    /// repose | packing | restitution | ke | custom:THERMO_COLUMN.
    #[arg(long, default_value = "repose")]
    pub metric: String,
    /// Seeds per setting (`-var SEEDVAR p`, primes > 10000); 1: the deck's own seed.
    #[arg(long, default_value_t = 1)]
    pub seeds: usize,
    /// The deck variable that takes the seed.
    #[arg(long, default_value = "seed")]
    pub seed_var: String,
    /// Reference: a setting label (`dt_fraction=0.02`, several joined by
    /// spaces) or an exact metric value; default the most accurate setting
    /// (smallest dt_fraction and youngs_scale, last var value).
    #[arg(long, allow_hyphen_values = true)]
    pub reference: Option<String>,
    /// Dump file the metric reads (name in the run folder, `*` allowed);
    /// default the only dump the run writes.
    #[arg(long)]
    pub dump: Option<String>,
    /// Threads of each run.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the table as CSV.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write the cost-accuracy front (error vs wall time) as PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Keep the run folders under this folder.
    #[arg(long)]
    pub keep: Option<PathBuf>,
    /// `-var NAME VALUE ...` groups for every run (taken out before parsing).
    #[arg(skip)]
    pub vars: Vec<(String, Vec<String>)>,
}

/// One run of one setting.
#[derive(Clone, Debug, Serialize)]
pub struct RunResult {
    /// Seed (None with one seed).
    pub seed: Option<u64>,
    /// Metric value (None: run or measurement failed).
    pub value: Option<f64>,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Time step the run used with --dt-fraction (from its log).
    pub timestep: Option<f64>,
    /// Failure message.
    pub error: Option<String>,
}

/// One setting of the grid, over its seeds.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Label (`dt_fraction=0.05 var:Y=1e8`).
    pub label: String,
    /// (parameter, value) pairs.
    pub setting: Vec<(String, String)>,
    /// Mean of the metric over successful seeds (NaN if none).
    pub mean: f64,
    /// Sample SD over seeds (0 with one).
    pub sd: f64,
    /// Successful runs.
    pub n: usize,
    /// |mean - reference| (NaN if unknown).
    pub error: f64,
    /// error / |reference| (NaN if unknown).
    pub rel_error: f64,
    /// Mean wall time per run (s).
    pub wall_seconds: f64,
    /// Reference wall time / this wall time (NaN if unknown).
    pub speedup: f64,
    /// Time step used (first run, with --dt-fraction).
    pub timestep: Option<f64>,
    /// Whether this is the reference setting.
    pub reference: bool,
    /// The runs.
    pub runs: Vec<RunResult>,
}

/// The whole trade-off study.
#[derive(Clone, Debug, Serialize)]
pub struct Tradeoff {
    /// Deck.
    pub deck: String,
    /// Metric.
    pub metric: Metric,
    /// Reference value of the metric.
    pub reference_value: f64,
    /// What the reference is.
    pub reference: String,
    /// Rows in grid order.
    pub rows: Vec<Row>,
    /// Remarks.
    pub notes: Vec<String>,
}

/// Every combination of the varied values, first `--vary` slowest.
pub fn grid(vary: &[Vary]) -> Vec<Vec<(Param, String)>> {
    let mut out: Vec<Vec<(Param, String)>> = vec![vec![]];
    for v in vary {
        let mut next = vec![];
        for base in &out {
            for val in &v.values {
                let mut s = base.clone();
                s.push((v.param.clone(), val.clone()));
                next.push(s);
            }
        }
        out = next;
    }
    out
}

/// Label of a setting.
pub fn label(setting: &[(Param, String)]) -> String {
    setting.iter().map(|(p, v)| format!("{}={v}", p.name())).collect::<Vec<_>>().join(" ")
}

/// The most accurate setting of the grid: smallest dt_fraction, smallest
/// youngs_scale, last value of each variable.
pub fn most_accurate(vary: &[Vary]) -> Vec<(Param, String)> {
    vary.iter()
        .map(|v| {
            let val = match v.param {
                Param::Var(_) => v.values.last().cloned().unwrap_or_default(),
                _ => v
                    .values
                    .iter()
                    .min_by(|a, b| a.parse::<f64>().unwrap_or(f64::INFINITY).total_cmp(&b.parse::<f64>().unwrap_or(f64::INFINITY)))
                    .cloned()
                    .unwrap_or_default(),
            };
            (v.param.clone(), val)
        })
        .collect()
}

/// Mean and sample SD.
fn mean_sd(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = if v.len() > 1 { (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt() } else { 0.0 };
    (m, sd)
}

// ------------------------------------------------------------------ metrics

/// Values of a thermo column in a log (LAMMPS/LIGGGHTS layout: a header line
/// of names followed by rows of numbers). `name` is a thermo keyword (`ke`)
/// or a header (`KinEng`), case-insensitive; LIGGGHTS headers drop the
/// `c_`/`f_`/`v_` prefix, so both forms match.
pub fn thermo_column(log: &str, name: &str) -> Vec<f64> {
    let alias = match name {
        "ke" => "KinEng",
        "pe" => "PotEng",
        "etotal" => "TotEng",
        "step" => "Step",
        "atoms" => "Atoms",
        "time" => "Time",
        "dt" => "Dt",
        "temp" => "Temp",
        "press" => "Press",
        "vol" => "Volume",
        "cpu" => "CPU",
        other => other,
    };
    let bare = |s: &str| -> String {
        let l = s.to_ascii_lowercase();
        for p in ["c_", "f_", "v_"] {
            if let Some(r) = l.strip_prefix(p) {
                return r.to_string();
            }
        }
        l
    };
    let want = [name.to_ascii_lowercase(), alias.to_ascii_lowercase(), bare(name)];
    let mut out = vec![];
    let mut header: Option<Vec<String>> = None;
    let mut pending: Option<Vec<String>> = None;
    for line in log.lines() {
        let toks: Vec<&str> = line.split_whitespace().collect();
        if toks.is_empty() {
            continue;
        }
        let nums: Vec<Option<f64>> = toks.iter().map(|t| t.parse::<f64>().ok()).collect();
        if nums.iter().all(Option::is_some) {
            if let Some(p) = pending.take() {
                if p.len() == toks.len() {
                    header = Some(p);
                }
            }
            if let Some(h) = &header {
                if h.len() == toks.len() {
                    if let Some(k) = h.iter().position(|c| want.contains(&c.to_ascii_lowercase()) || want.contains(&bare(c))) {
                        if let Some(v) = nums[k] {
                            out.push(v);
                        }
                    }
                }
            }
        } else if nums.iter().all(Option::is_none) {
            pending = Some(toks.iter().map(|s| s.to_string()).collect());
        } else {
            pending = None;
        }
    }
    out
}

/// Restitution of a two-particle collision: minus the relative normal
/// velocity at `last` over that at `first` (normal along the line of
/// centres of each frame).
pub fn restitution(first: &Frame, last: &Frame) -> Result<f64> {
    let vn = |f: &Frame| -> Result<f64> {
        if f.natoms != 2 {
            return Err(Error::usage(format!(
                "restitution needs a two-particle deck; the dump frame at step {} has {} particles",
                f.timestep, f.natoms
            )));
        }
        let [x, y, z] = super::repose::positions(f)?;
        let get = |n: &str| f.column(n).ok_or_else(|| Error::usage(format!("restitution needs vx vy vz in the dump (missing {n})")));
        let (vx, vy, vz) = (get("vx")?, get("vy")?, get("vz")?);
        // order by id so both frames use the same normal direction
        let (a, b) = match f.column("id") {
            Some(id) if id[0] > id[1] => (1, 0),
            _ => (0, 1),
        };
        let d = [x[b] - x[a], y[b] - y[a], z[b] - z[a]];
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if !(r > 0.0) {
            return Err(Error::usage("restitution: the two particles coincide"));
        }
        Ok(((vx[b] - vx[a]) * d[0] + (vy[b] - vy[a]) * d[1] + (vz[b] - vz[a]) * d[2]) / r)
    };
    let before = vn(first)?;
    let after = vn(last)?;
    if !(before < 0.0) {
        return Err(Error::usage(format!("restitution: the particles do not approach at the first dump frame (relative normal velocity {before})")));
    }
    Ok(-after / before)
}

/// Simple `*` glob on file names.
fn glob(pat: &str, name: &str) -> bool {
    let parts: Vec<&str> = pat.split('*').collect();
    if parts.len() == 1 {
        return pat == name;
    }
    let mut rest = name;
    for (k, p) in parts.iter().enumerate() {
        if k == 0 {
            match rest.strip_prefix(p) {
                Some(r) => rest = r,
                None => return false,
            }
        } else if k == parts.len() - 1 {
            return rest.ends_with(p);
        } else {
            match rest.find(p) {
                Some(i) => rest = &rest[i + p.len()..],
                None => return false,
            }
        }
    }
    true
}

/// First and last frames (by timestep) of the dump a run wrote in `dir`.
fn dump_frames(dir: &Path, installed: &[PathBuf], pattern: Option<&str>) -> Result<(Frame, Frame)> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::io(Span::DUMMY, format!("cannot read '{}'", dir.display()), &e))?;
    let mut files: Vec<PathBuf> = rd
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file() && !installed.iter().any(|i| dir.join(i) == *p) && super::reference::looks_like_dump(p))
        .collect();
    files.sort();
    let name = |p: &PathBuf| p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if let Some(pat) = pattern {
        files.retain(|f| glob(pat, &name(f)));
        if files.is_empty() {
            return Err(Error::usage(format!("the run wrote no dump matching '{pat}'")));
        }
    } else {
        // several files are one series only when they differ in digits
        let key = |p: &PathBuf| name(p).chars().map(|c| if c.is_ascii_digit() { '#' } else { c }).collect::<String>();
        let mut keys: Vec<String> = files.iter().map(key).collect();
        keys.dedup();
        if keys.is_empty() {
            return Err(Error::usage("the run wrote no dump file (the metric needs one)"));
        }
        if keys.len() > 1 {
            let names: Vec<String> = files.iter().map(name).collect();
            return Err(Error::usage(format!("the run wrote several dumps ({}): choose one with --dump", names.join(", "))));
        }
    }
    let mut first: Option<Frame> = None;
    let mut last: Option<Frame> = None;
    for f in &files {
        for fr in DumpReader::open(f)? {
            let fr = fr?;
            if first.as_ref().is_none_or(|a| fr.timestep < a.timestep) {
                first = Some(fr.clone());
            }
            if last.as_ref().is_none_or(|a| fr.timestep >= a.timestep) {
                last = Some(fr);
            }
        }
    }
    match (first, last) {
        (Some(a), Some(b)) => Ok((a, b)),
        _ => Err(Error::usage("the dump holds no frames")),
    }
}

/// Measure `metric` on the run in `dir`.
pub fn measure(metric: &Metric, dir: &Path, installed: &[PathBuf], dump: Option<&str>) -> Result<f64> {
    let log = || std::fs::read_to_string(dir.join("log.demx")).map_err(|e| Error::io(Span::DUMMY, "cannot read the run's log.demx", &e));
    let last_thermo = |name: &str| -> Result<f64> {
        thermo_column(&log()?, name).last().copied().ok_or_else(|| Error::usage(format!("the run's log has no thermo column '{name}'")))
    };
    match metric {
        Metric::Repose => Ok(super::repose::repose(&dump_frames(dir, installed, dump)?.1)?.theta),
        Metric::Packing => Ok(super::packing::packing(&dump_frames(dir, installed, dump)?.1)?.phi),
        Metric::Restitution => {
            let (a, b) = dump_frames(dir, installed, dump)?;
            restitution(&a, &b)
        }
        Metric::Ke => last_thermo("ke"),
        Metric::Custom(n) => last_thermo(n),
    }
}

/// The time step a run reported for --dt-fraction (from its log).
fn logged_timestep(dir: &Path) -> Option<f64> {
    let log = std::fs::read_to_string(dir.join("log.demx")).ok()?;
    let line = log.lines().find(|l| l.starts_with("demx: --dt-fraction"))?;
    let after = line.split("timestep ").nth(1)?;
    after.split_whitespace().next()?.parse().ok()
}

/// Run `demx run` in `dir`; Ok(wall seconds) or the failure text.
fn run_one(
    dir: &Path,
    deck_name: &str,
    setting: &[(Param, String)],
    vars: &[(String, Vec<String>)],
    threads: usize,
) -> Result<std::result::Result<f64, String>> {
    let mut args: Vec<String> =
        vec!["run".into(), "--quiet".into(), "--log".into(), "log.demx".into(), "--threads".into(), threads.max(1).to_string()];
    for (p, v) in setting {
        match p {
            Param::DtFraction => args.extend(["--dt-fraction".to_string(), v.clone()]),
            Param::YoungsScale => args.extend(["--youngs-scale".to_string(), v.clone()]),
            Param::Var(_) => {}
        }
    }
    args.push(deck_name.into());
    let mut all: Vec<(String, Vec<String>)> = vars.to_vec();
    for (p, v) in setting {
        if let Param::Var(n) = p {
            all.retain(|(m, _)| m != n);
            all.push((n.clone(), vec![v.clone()]));
        }
    }
    let (out, wall) = super::compare_deck::spawn_demx(dir, &mut args, &all)?;
    if !out.status.success() {
        return Ok(Err(format!("demx run failed ({}): {}", out.status, tail(&String::from_utf8_lossy(&out.stderr), 4).trim())));
    }
    Ok(Ok(wall))
}

/// Run the whole study; `progress` gets one line per run.
pub fn tradeoff(a: &TradeoffArgs, progress: &mut dyn FnMut(&str)) -> Result<Tradeoff> {
    let metric = Metric::parse(&a.metric)?;
    let vary: Vec<Vary> = a.vary.iter().map(|v| parse_vary(v)).collect::<Result<_>>()?;
    for (k, v) in vary.iter().enumerate() {
        if vary[..k].iter().any(|w| w.param == v.param) {
            return Err(Error::usage(format!("--vary {} given twice", v.param.name())));
        }
    }
    let k = a.seeds.max(1);
    if k > SEEDS.len() {
        return Err(Error::usage(format!("--seeds: at most {}", SEEDS.len())));
    }
    // only demx runs these variants, and demx refuses `shell` itself
    let prep = prepare_deck(&a.deck, RefEngine::Liggghts, true)?;
    let installed: Vec<PathBuf> = prep.files.iter().map(|(r, _)| r.clone()).chain(std::iter::once(PathBuf::from(&prep.deck_name))).collect();
    let tmp = tempfile::tempdir().map_err(|e| Error::io(Span::DUMMY, "cannot create a temporary directory", &e))?;
    let root = a.keep.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    let settings = grid(&vary);
    // reference: a value, a setting label, or the most accurate setting
    let mut ref_value: Option<f64> = None;
    let ref_label = match &a.reference {
        Some(r) if r.parse::<f64>().is_ok() => {
            ref_value = r.parse().ok();
            None
        }
        Some(r) => {
            let want: Vec<&str> = r.split_whitespace().collect();
            let found = settings.iter().map(|s| label(s)).find(|l| {
                let have: Vec<&str> = l.split(' ').collect();
                want.len() == have.len() && want.iter().all(|w| have.contains(w))
            });
            match found {
                Some(l) => Some(l),
                None => return Err(Error::usage(format!("--reference '{r}' is neither a number nor a setting of the grid"))),
            }
        }
        None => Some(label(&most_accurate(&vary))),
    };
    let mut rows = vec![];
    let mut notes = prep.notes.clone();
    for (i, setting) in settings.iter().enumerate() {
        let lab = label(setting);
        let mut runs = vec![];
        for s in 0..k {
            let seed = (k > 1).then(|| SEEDS[s]);
            let mut vars = a.vars.clone();
            if let Some(sd) = seed {
                vars.retain(|(n, _)| *n != a.seed_var);
                vars.push((a.seed_var.clone(), vec![sd.to_string()]));
            }
            let dir = root.join(format!("setting{i:02}-seed{s}"));
            std::fs::create_dir_all(&dir).map_err(|e| Error::io(Span::DUMMY, format!("cannot create '{}'", dir.display()), &e))?;
            prep.install(&dir)?;
            let r = match run_one(&dir, &prep.deck_name, setting, &vars, a.threads)? {
                Ok(wall) => match measure(&metric, &dir, &installed, a.dump.as_deref()) {
                    Ok(v) => RunResult { seed, value: Some(v), wall_seconds: wall, timestep: logged_timestep(&dir), error: None },
                    Err(e) => RunResult { seed, value: None, wall_seconds: wall, timestep: logged_timestep(&dir), error: Some(e.message()) },
                },
                Err(msg) => RunResult { seed, value: None, wall_seconds: f64::NAN, timestep: None, error: Some(msg) },
            };
            progress(&format!(
                "{lab}{}: {} ({:.2} s)",
                seed.map_or(String::new(), |s| format!(" seed {s}")),
                match (&r.value, &r.error) {
                    (Some(v), _) => format!("{} = {}", metric.label(), num(*v, 6)),
                    (None, Some(e)) => format!("FAILED: {e}"),
                    _ => "?".into(),
                },
                r.wall_seconds
            ));
            runs.push(r);
        }
        let vals: Vec<f64> = runs.iter().filter_map(|r| r.value).collect();
        let walls: Vec<f64> = runs.iter().map(|r| r.wall_seconds).filter(|w| w.is_finite()).collect();
        let (mean, sd) = mean_sd(&vals);
        let wall = mean_sd(&walls).0;
        rows.push(Row {
            label: lab.clone(),
            setting: setting.iter().map(|(p, v)| (p.name(), v.clone())).collect(),
            mean,
            sd,
            n: vals.len(),
            error: f64::NAN,
            rel_error: f64::NAN,
            wall_seconds: wall,
            speedup: f64::NAN,
            timestep: runs.iter().find_map(|r| r.timestep),
            reference: ref_label.as_deref() == Some(lab.as_str()),
            runs,
        });
    }
    let ref_row = rows.iter().find(|r| r.reference).cloned();
    let (reference, rv) = match (ref_value, &ref_row) {
        (Some(v), _) => (format!("exact value {v}"), v),
        (None, Some(r)) => (format!("setting {}", r.label), r.mean),
        (None, None) => ("none".to_string(), f64::NAN),
    };
    if !rv.is_finite() {
        notes.push("the reference has no metric value (its runs failed): errors are unknown".into());
    }
    let ref_wall = ref_row.as_ref().map_or(f64::NAN, |r| r.wall_seconds);
    for r in rows.iter_mut() {
        r.error = (r.mean - rv).abs();
        r.rel_error = if rv != 0.0 { r.error / rv.abs() } else { f64::NAN };
        r.speedup = ref_wall / r.wall_seconds;
    }
    if a.seeds <= 1 {
        notes.push("one run per setting: the SD is not measured (use --seeds K)".into());
    }
    Ok(Tradeoff { deck: a.deck.display().to_string(), metric, reference_value: rv, reference, rows, notes })
}

/// `p` decimals, or `p` significant digits in exponent form for values far from 1.
fn num(v: f64, p: usize) -> String {
    if !v.is_finite() {
        "-".into()
    } else if v != 0.0 && !(1e-3..1e6).contains(&v.abs()) {
        format!("{v:.p$e}")
    } else {
        format!("{v:.p$}")
    }
}

/// Text table.
pub fn render(t: &Tradeoff) -> String {
    let mut o = String::new();
    o.push_str(&format!("deck: {}   metric: {}   reference: {} = {}\n", t.deck, t.metric.label(), t.reference, num(t.reference_value, 6)));
    let w = t.rows.iter().map(|r| r.label.len()).max().unwrap_or(7).max(7);
    o.push_str(&format!(
        "{:<w$}  {:>22}  {:>11}  {:>9}  {:>11}  {:>9}  {:>8}\n",
        "setting", "metric (mean +- SD)", "|error|", "rel", "wall (s)", "speed-up", "dt (s)"
    ));
    for r in &t.rows {
        let m = if r.n > 0 { format!("{} +- {}", num(r.mean, 5), num(r.sd, 5)) } else { "FAILED".to_string() };
        o.push_str(&format!(
            "{:<w$}  {:>22}  {:>11}  {:>8}%  {:>11}  {:>9}  {:>8}{}\n",
            r.label,
            m,
            num(r.error, 6),
            num(100.0 * r.rel_error, 3),
            num(r.wall_seconds, 3),
            if r.speedup.is_finite() { format!("{:.2}x", r.speedup) } else { "-".into() },
            r.timestep.map_or("-".to_string(), |d| format!("{d:.3e}")),
            if r.reference { "  (reference)" } else { "" }
        ));
        for run in &r.runs {
            if let Some(e) = &run.error {
                o.push_str(&format!("    failed{}: {e}\n", run.seed.map_or(String::new(), |s| format!(" (seed {s})"))));
            }
        }
    }
    for n in &t.notes {
        o.push_str(&format!("note: {n}\n"));
    }
    o
}

/// CSV table (one line per setting).
pub fn write_csv(path: &Path, t: &Tradeoff) -> Result<()> {
    let mut s = String::from("setting,mean,sd,n,error,rel_error,wall_seconds,speedup,timestep,reference\n");
    for r in &t.rows {
        s.push_str(&format!(
            "\"{}\",{},{},{},{},{},{},{},{},{}\n",
            r.label,
            r.mean,
            r.sd,
            r.n,
            r.error,
            r.rel_error,
            r.wall_seconds,
            r.speedup,
            r.timestep.map_or(String::new(), |d| d.to_string()),
            r.reference
        ));
    }
    std::fs::write(path, s).map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", path.display()), &e))
}

/// The cost-accuracy front: error vs wall time, and the metric vs wall time.
pub fn charts(t: &Tradeoff) -> Vec<crate::plot::Chart> {
    use crate::plot::{Chart, Series, SeriesKind};
    let ok: Vec<&Row> = t.rows.iter().filter(|r| r.n > 0 && r.wall_seconds > 0.0).collect();
    let front: Vec<(f64, f64)> = ok.iter().filter(|r| r.error > 0.0).map(|r| (r.wall_seconds, r.error)).collect();
    vec![
        Chart {
            title: format!("cost-accuracy front ({})", t.reference),
            x_label: "wall time per run (s)".into(),
            y_label: format!("|error| of {}", t.metric.label()),
            log_x: true,
            log_y: true,
            series: vec![Series { label: "settings".into(), points: front, kind: SeriesKind::Points }],
            ..Default::default()
        },
        Chart {
            title: "metric over seeds".into(),
            x_label: "wall time per run (s)".into(),
            y_label: t.metric.label(),
            log_x: true,
            series: vec![Series {
                label: "mean +- SD".into(),
                points: ok.iter().map(|r| (r.wall_seconds, r.mean)).collect(),
                kind: SeriesKind::ErrorBars(ok.iter().map(|r| r.sd).collect()),
            }],
            ..Default::default()
        },
    ]
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    use clap::Parser;
    let (rest, vars) = match extract_vars(args) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {}", e.message());
            return ExitCode::from(2);
        }
    };
    let mut argv = vec!["demx tradeoff".to_string()];
    argv.extend(rest);
    let mut a = match TradeoffArgs::try_parse_from(argv) {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    a.vars = vars;
    let quiet = a.json;
    let mut progress = |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    let t = match tradeoff(&a, &mut progress) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {}", e.message());
            return ExitCode::from(2);
        }
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&t).unwrap_or_default());
    } else {
        print!("{}", render(&t));
    }
    if let Some(p) = &a.csv {
        if let Err(e) = write_csv(p, &t) {
            eprintln!("error: {}", e.message());
            return ExitCode::from(1);
        }
    }
    if let Some(p) = &a.plot {
        if let Err(e) = crate::plot::write_png(p, &charts(&t)) {
            eprintln!("warning: --plot: {}", e.message());
        }
    }
    ExitCode::from(if t.reference_value.is_finite() { 0 } else { 1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vary_names_and_grid() {
        assert!(parse_vary("dt_fraction=0.1,0.2").is_ok());
        assert!(parse_vary("var:Y=1e7,1e8").is_ok());
        let e = parse_vary("dtfrac=0.1").unwrap_err().message();
        assert!(e.contains("dt_fraction") && e.contains("youngs_scale") && e.contains("var:NAME"), "{e}");
        assert!(parse_vary("youngs_scale=0,10").is_err());
        let v = vec![parse_vary("dt_fraction=0.2,0.05").unwrap(), parse_vary("var:Y=a,b,c").unwrap()];
        let g = grid(&v);
        assert_eq!(g.len(), 6);
        assert_eq!(label(&g[1]), "dt_fraction=0.2 var:Y=b");
        assert_eq!(label(&most_accurate(&v)), "dt_fraction=0.05 var:Y=c");
    }

    #[test]
    fn thermo_column_reads_last_block() {
        let log = "demx: note\nStep Atoms KinEng \n 0 2 1.5\n 50 2 1.25\nLoop time of 0.1 on 1 procs\n   Step c_x \n 50 7\n 60 8\n";
        assert_eq!(thermo_column(log, "ke"), vec![1.5, 1.25]);
        assert_eq!(thermo_column(log, "c_x"), vec![7.0, 8.0]);
        assert_eq!(thermo_column(log, "step"), vec![0.0, 50.0, 50.0, 60.0]);
    }

    #[test]
    fn glob_matches_star() {
        assert!(glob("dump.*.heap", "dump.100.heap"));
        assert!(!glob("dump.*.heap", "dump.100.x"));
        assert!(glob("dump.heap", "dump.heap"));
    }
}
