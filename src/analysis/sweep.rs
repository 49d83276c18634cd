//! `demx sweep DECK --d D1,D2,... --g G1,G2,... [--seeds K] [--jobs J]
//! [-var NAME VALUE ...] [--out DIR] [--csv FILE] [--plot FILE.png]
//! [--markdown FILE]`: the angle-of-repose study of Elekes & Parteli (2021,
//! PNAS). Runs the heap deck (`demx run` subprocesses, one directory each
//! under `--out`, `--threads 1`, J at a time) for every diameter d, g level
//! and seed, measures theta_r on the last frame of the heap dump
//! ([`super::repose::repose`]) and the wall time, and fits the paper's
//! expressions:
//!
//! - Eq. 1, theta_r = atan(mu (1 + D/d)), per g level (mu and D free with
//!   three or more sizes, otherwise D with mu fixed to the Eq. 3 value);
//! - Eq. 2/3, D = D_E / sqrt(g~): theta_r = atan(mu (1 + D_E/(d sqrt(g~))))
//!   over all runs; also D = D_0 / g~^alpha from the per-level D;
//! - Eq. 4, theta_r = atan(mu (1 + beta sqrt(Bo))), Bo = 12 gamma/(d^2 g rho).
//!
//! All three have the form theta = atan(mu (1 + c x)); [`fit_atan`] fits it by
//! Levenberg-Marquardt on the angles (radians), unweighted, with standard
//! errors from s^2 (J^T J)^-1. A run whose `result.json` exists in its
//! directory is reused, so an interrupted sweep resumes.
//!
//! `--slurm` runs the matrix on a cluster instead: it writes it as a
//! campaign (`OUT/campaign.json`, runs in `OUT/runs/NAME/`, checkpointed and
//! resumable) and submits it as one Slurm job array
//! ([`super::slurm`]); `--collect` then measures what the tasks left and
//! fits, running nothing. A local sweep reuses a run the cluster finished.

use super::repose::{pick_frame, repose};
use crate::plot::{Chart, Series, SeriesKind};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Earth's gravity (m/s^2), the paper's g_Earth.
pub const G_EARTH: f64 = 9.81;
/// The paper's mu_eff,inf (Eq. 1 fit to Fig. 2).
pub const PAPER_MU: f64 = 0.447;
/// The paper's D_E (m).
pub const PAPER_DE: f64 = 87e-6;
/// The paper's Eq. 4 fit: mu_eff,inf and beta.
pub const PAPER_EQ4: (f64, f64) = (0.458, 0.014);
/// The paper's D = D_0 / g~^alpha fit: D_0 (m) and alpha.
pub const PAPER_POWER: (f64, f64) = (76e-6, 0.454);

/// Command-line options (the `-var` groups are taken out before clap).
#[derive(clap::Parser, Debug)]
pub struct SweepCli {
    /// The heap deck (it must take -var d, -var g, -var seed and write the dump).
    pub deck: PathBuf,
    /// Particle diameters, m (comma separated).
    #[arg(long = "d", value_delimiter = ',', required = true, num_args = 1..)]
    pub d: Vec<f64>,
    /// g levels g~ = g / 9.81 (comma separated).
    #[arg(long = "g", value_delimiter = ',', required = true, num_args = 1..)]
    pub g: Vec<f64>,
    /// Realisations per (d, g): seeds are the primes from 15485863 on.
    #[arg(long, default_value_t = 1)]
    pub seeds: usize,
    /// Runs at a time (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Directory of the runs (one subdirectory per run).
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
    /// CSV table of the runs (default: OUT/sweep.csv).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// PNG chart of theta_r(d) with the fits and the paper's curve.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Markdown section with the table and the fits beside the paper's values.
    #[arg(long)]
    pub markdown: Option<PathBuf>,
    /// Dump file the deck writes (last frame = the relaxed heap).
    #[arg(long, default_value = "dump.heap")]
    pub dump: String,
    /// Surface energy gamma (J/m^2) for the Bond number (Eq. 4).
    #[arg(long, default_value_t = 0.05)]
    pub gamma: f64,
    /// Particle density (kg/m^3) for the Bond number (Eq. 4).
    #[arg(long, default_value_t = 2500.0)]
    pub rho: f64,
    /// Measure and fit the runs a `--slurm` submission finished; run nothing (unfinished runs are reported).
    #[arg(long)]
    pub collect: bool,
    /// The Slurm backend.
    #[command(flatten)]
    pub slurm: super::slurm::SlurmOpts,
    /// Extra `-var` groups for every run (filled from the raw arguments).
    #[arg(skip)]
    pub vars: Vec<Vec<String>>,
}

/// One run's measurement (also its `result.json`).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct RunResult {
    /// Diameter, m.
    pub d: f64,
    /// g level g~.
    pub g: f64,
    /// Insertion seed.
    pub seed: i64,
    /// theta_r, degrees (mean of the two projections).
    pub theta: f64,
    /// SD of the two projections, degrees.
    pub sd: f64,
    /// Particles in the heap.
    pub n: usize,
    /// Young's modulus as passed (`-var Y`), or empty for the deck's default.
    pub y: String,
    /// Wall time of the run, s.
    pub wall: f64,
}

/// Result of fitting theta = atan(mu (1 + c x)).
#[derive(Clone, Debug, serde::Serialize, PartialEq)]
pub struct AtanFit {
    /// mu_eff,inf.
    pub mu: f64,
    /// Standard error of mu (0 when mu was fixed).
    pub mu_se: f64,
    /// The scale c (D, D_E or beta).
    pub c: f64,
    /// Standard error of c.
    pub c_se: f64,
    /// Coefficient of determination on the angles.
    pub r2: f64,
    /// Points used.
    pub n: usize,
}

/// theta (radians) of the model atan(mu (1 + c x)).
pub fn atan_model(mu: f64, c: f64, x: f64) -> f64 {
    (mu * (1.0 + c * x)).atan()
}

/// Least-squares fit of theta (radians) = atan(mu (1 + c x)) to the points
/// (x, theta): Levenberg-Marquardt from the linear fit of tan(theta) on x;
/// `mu_fixed` fits c alone. None with too few points or a degenerate fit.
pub fn fit_atan(x: &[f64], theta: &[f64], mu_fixed: Option<f64>) -> Option<AtanFit> {
    let n = x.len();
    let np = if mu_fixed.is_some() { 1 } else { 2 };
    if n != theta.len() || n < np || x.iter().chain(theta).any(|v| !v.is_finite()) {
        return None;
    }
    // start: tan(theta) = a + b x, mu = a, c = b / a
    let t: Vec<f64> = theta.iter().map(|v| v.tan()).collect();
    let (mut mu, mut c) = match mu_fixed {
        Some(m) => {
            let num: f64 = x.iter().zip(&t).map(|(xi, ti)| xi * (ti - m)).sum();
            let den: f64 = x.iter().map(|xi| m * xi * xi).sum();
            (m, if den != 0.0 { num / den } else { 0.0 })
        }
        None => {
            let mx = x.iter().sum::<f64>() / n as f64;
            let mt = t.iter().sum::<f64>() / n as f64;
            let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
            let sxt: f64 = x.iter().zip(&t).map(|(a, b)| (a - mx) * (b - mt)).sum();
            let b = if sxx > 0.0 { sxt / sxx } else { 0.0 };
            let a = mt - b * mx;
            if a.abs() < 1e-300 {
                return None;
            }
            (a, b / a)
        }
    };
    let ssr = |mu: f64, c: f64| -> f64 { x.iter().zip(theta).map(|(xi, ti)| (ti - atan_model(mu, c, *xi)).powi(2)).sum() };
    // Jacobian rows of the model: d/dmu, d/dc
    let jac = |mu: f64, c: f64, xi: f64| -> [f64; 2] {
        let u = mu * (1.0 + c * xi);
        let k = 1.0 / (1.0 + u * u);
        [k * (1.0 + c * xi), k * mu * xi]
    };
    let mut lambda = 1e-3;
    let mut s = ssr(mu, c);
    for _ in 0..200 {
        let (mut a, mut g) = ([[0.0; 2]; 2], [0.0; 2]);
        for (xi, ti) in x.iter().zip(theta) {
            let j = jac(mu, c, *xi);
            let r = ti - atan_model(mu, c, *xi);
            for p in 0..2 {
                g[p] += j[p] * r;
                for q in 0..2 {
                    a[p][q] += j[p] * j[q];
                }
            }
        }
        if mu_fixed.is_some() {
            a[0] = [1.0, 0.0];
            a[1][0] = 0.0;
            g[0] = 0.0;
        }
        let mut improved = false;
        for _ in 0..30 {
            let m = [[a[0][0] * (1.0 + lambda), a[0][1]], [a[1][0], a[1][1] * (1.0 + lambda)]];
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            if det == 0.0 || !det.is_finite() {
                lambda *= 10.0;
                continue;
            }
            let dmu = (g[0] * m[1][1] - g[1] * m[0][1]) / det;
            let dc = (m[0][0] * g[1] - m[1][0] * g[0]) / det;
            let (mu2, c2) = (mu + dmu, c + dc);
            let s2 = ssr(mu2, c2);
            if s2.is_finite() && s2 <= s {
                let small = (dmu.abs() <= 1e-14 * mu.abs().max(1e-300)) && (dc.abs() <= 1e-14 * c.abs().max(1e-300));
                mu = mu2;
                c = c2;
                let done = small || s - s2 <= 1e-15 * s.max(1e-300);
                s = s2;
                lambda = (lambda * 0.1).max(1e-12);
                improved = !done;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    if !(mu.is_finite() && c.is_finite()) {
        return None;
    }
    // standard errors: s^2 (J^T J)^-1, s^2 = SSR / (n - p)
    let mut a = [[0.0; 2]; 2];
    for xi in x {
        let j = jac(mu, c, *xi);
        for p in 0..2 {
            for q in 0..2 {
                a[p][q] += j[p] * j[q];
            }
        }
    }
    let dof = n as f64 - np as f64;
    let s2 = if dof > 0.0 { s / dof } else { f64::NAN };
    let (mu_se, c_se) = if mu_fixed.is_some() {
        (0.0, if a[1][1] > 0.0 { (s2 / a[1][1]).sqrt() } else { f64::NAN })
    } else {
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        if det > 0.0 {
            ((s2 * a[1][1] / det).sqrt(), (s2 * a[0][0] / det).sqrt())
        } else {
            (f64::NAN, f64::NAN)
        }
    };
    let mean = theta.iter().sum::<f64>() / n as f64;
    let sst: f64 = theta.iter().map(|v| (v - mean).powi(2)).sum();
    let r2 = if sst > 0.0 { 1.0 - s / sst } else { f64::NAN };
    Some(AtanFit { mu, mu_se, c, c_se, r2, n })
}

/// Power law D = D_0 / g~^alpha by linear regression of ln D on ln g~:
/// (D_0, its SE, alpha, its SE). None with fewer than two g levels.
pub fn fit_power(g: &[f64], d: &[f64]) -> Option<(f64, f64, f64, f64)> {
    let pts: Vec<(f64, f64)> = g.iter().zip(d).filter(|(a, b)| **a > 0.0 && **b > 0.0).map(|(a, b)| (a.ln(), b.ln())).collect();
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let b = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let a = my - b * mx;
    let (sa, sb) = if pts.len() > 2 {
        let s2 = pts.iter().map(|p| (p.1 - a - b * p.0).powi(2)).sum::<f64>() / (n - 2.0);
        ((s2 * (1.0 / n + mx * mx / sxx)).sqrt(), (s2 / sxx).sqrt())
    } else {
        (f64::NAN, f64::NAN)
    };
    Some((a.exp(), a.exp() * sa, -b, sb))
}

/// All fits of a sweep.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Fits {
    /// Eq. 1 per g level: (g~, fit), c = D in m.
    pub eq1: Vec<(f64, AtanFit)>,
    /// Eq. 3 over all runs: c = D_E in m.
    pub eq3: Option<AtanFit>,
    /// D = D_0 / g~^alpha from the Eq. 1 D values: (D_0, SE, alpha, SE).
    pub power: Option<(f64, f64, f64, f64)>,
    /// Eq. 4 over all runs: c = beta.
    pub eq4: Option<AtanFit>,
}

/// Bond number of a run (gamma in J/m^2, rho in kg/m^3; g~ in units of 9.81).
pub fn bond(d: f64, g: f64, gamma: f64, rho: f64) -> f64 {
    super::repose::bond_number(gamma, d, g * G_EARTH, rho)
}

/// Fit Eqs. 1-4 to the runs.
pub fn fit_all(runs: &[RunResult], gamma: f64, rho: f64) -> Fits {
    let rad = |r: &RunResult| r.theta.to_radians();
    let x3: Vec<f64> = runs.iter().map(|r| 1.0 / (r.d * r.g.sqrt())).collect();
    let th: Vec<f64> = runs.iter().map(rad).collect();
    let eq3 = fit_atan(&x3, &th, None);
    let x4: Vec<f64> = runs.iter().map(|r| bond(r.d, r.g, gamma, rho).sqrt()).collect();
    let eq4 = fit_atan(&x4, &th, None);
    let mut levels: Vec<f64> = runs.iter().map(|r| r.g).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let mut eq1 = vec![];
    for &g in &levels {
        let sel: Vec<&RunResult> = runs.iter().filter(|r| r.g == g).collect();
        let x: Vec<f64> = sel.iter().map(|r| 1.0 / r.d).collect();
        let t: Vec<f64> = sel.iter().map(|r| rad(r)).collect();
        let mut sizes: Vec<f64> = sel.iter().map(|r| r.d).collect();
        sizes.sort_by(f64::total_cmp);
        sizes.dedup();
        let fit = if sizes.len() >= 3 { fit_atan(&x, &t, None) } else { eq3.as_ref().and_then(|f| fit_atan(&x, &t, Some(f.mu))) };
        if let Some(f) = fit {
            eq1.push((g, f));
        }
    }
    let power = fit_power(&eq1.iter().map(|e| e.0).collect::<Vec<_>>(), &eq1.iter().map(|e| e.1.c).collect::<Vec<_>>());
    Fits { eq1, eq3, power, eq4 }
}

/// The `k`-th seed of a sweep: `demx compare`'s seeds (primes > 10000, as
/// LIGGGHTS wants, none equal to a seed the heap deck's templates use:
/// LIGGGHTS and demx refuse an insertion seed equal to those), then the
/// primes after the last of them.
pub fn seed(k: usize) -> i64 {
    let fixed = &super::compare_deck::SEEDS;
    if let Some(s) = fixed.get(k) {
        return *s as i64;
    }
    let mut p = fixed[fixed.len() - 1] as i64 + 1;
    let mut found = fixed.len();
    loop {
        if crate::engine::insert::is_prime(p) {
            if found == k {
                return p;
            }
            found += 1;
        }
        p += 1;
    }
}

/// Directory name of one run.
pub fn run_dir(d: f64, g: f64, seed: i64) -> String {
    format!("d{d:e}_g{g}_s{seed}")
}

fn usage(msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(2)
}

/// Parse and validate the arguments; `Err` is the exit code (help 0, bad use 2).
pub fn parse(args: Vec<String>) -> Result<SweepCli, ExitCode> {
    use clap::{CommandFactory, FromArgMatches};
    // the same -var grouping as compare/reference/tradeoff
    let (rest, vars) = match super::reference::extract_vars(args) {
        Ok((rest, groups)) => (rest, groups.into_iter().map(|(n, v)| std::iter::once(n).chain(v).collect::<Vec<String>>()).collect::<Vec<_>>()),
        Err(e) => return Err(usage(e.message())),
    };
    let cmd = SweepCli::command().name("demx sweep").about("Angle of repose over particle size and gravity (Elekes & Parteli 2021, Eqs. 1-4)");
    let mut c = match cmd.try_get_matches_from(std::iter::once("demx sweep".to_string()).chain(rest)).and_then(|m| SweepCli::from_arg_matches(&m)) {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return Err(ExitCode::from(if e.use_stderr() { 2 } else { 0 }));
        }
    };
    for v in &vars {
        match v.first().map(String::as_str) {
            None => return Err(usage("-var needs a name and a value")),
            Some("d" | "g" | "seed") => return Err(usage(format!("-var {} is set by the sweep (use --d, --g, --seeds)", v[0]))),
            Some(_) if v.len() < 2 => return Err(usage(format!("-var {} needs a value", v[0]))),
            Some(_) => {}
        }
    }
    c.vars = vars;
    if let Some(bad) = c.d.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(usage(format!("--d: diameters must be positive, got {bad}")));
    }
    if let Some(bad) = c.g.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(usage(format!("--g: g levels must be positive, got {bad}")));
    }
    if c.seeds == 0 {
        return Err(usage("--seeds must be at least 1"));
    }
    if c.jobs == Some(0) {
        return Err(usage("--jobs must be at least 1"));
    }
    if !c.deck.is_file() {
        return Err(usage(format!("cannot read the deck '{}'", c.deck.display())));
    }
    Ok(c)
}

/// The campaign file a `--slurm` sweep writes in its folder.
pub const CAMPAIGN: &str = "campaign.json";

/// The sweep's matrix (g, d, seed), in its fixed order.
fn matrix(c: &SweepCli) -> Vec<(f64, f64, i64)> {
    let mut todo = vec![];
    for &g in &c.g {
        for &d in &c.d {
            for k in 0..c.seeds {
                todo.push((d, g, seed(k)));
            }
        }
    }
    todo
}

/// The matrix as a campaign: one run per (d, g, seed), named as the local
/// sweep's folders, the `-var` groups as the campaign's variables.
fn campaign(c: &SweepCli, deck: &Path) -> Result<super::campaign::Campaign, String> {
    let mut vars = std::collections::BTreeMap::new();
    for v in &c.vars {
        if v.len() != 2 {
            return Err(format!("-var {} has {} values; a campaign's variables take one", v[0], v.len() - 1));
        }
        vars.insert(v[0].clone(), v[1].clone());
    }
    let runs = matrix(c)
        .into_iter()
        .map(|(d, g, s)| super::campaign::RunSpec {
            name: run_dir(d, g, s),
            vars: [("d", format!("{d:e}")), ("g", g.to_string()), ("seed", s.to_string())].into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
            estimate_core_h: 0.0,
            deck: None,
            dump: None,
            measure: None,
        })
        .collect();
    Ok(super::campaign::Campaign { deck: deck.to_path_buf(), dump: c.dump.clone(), measure: "repose".into(), checkpoint_every_s: 600.0, vars, runs })
}

/// `--slurm`: write the campaign and hand it to the campaign's Slurm backend.
fn submit_slurm(c: &SweepCli, deck: &Path) -> ExitCode {
    let spec = match campaign(c, deck) {
        Ok(s) => s,
        Err(e) => return usage(e),
    };
    let file = c.out.join(CAMPAIGN);
    let text = match serde_json::to_string_pretty(&spec) {
        Ok(t) => t + "\n",
        Err(e) => return usage(e),
    };
    // a campaign written before for another matrix is not silently replaced
    if let Ok(old) = std::fs::read_to_string(&file) {
        if old != text {
            return usage(format!("{} holds another sweep's campaign; use another --out", file.display()));
        }
    }
    if !write(&file, &text) {
        return ExitCode::from(1);
    }
    let mut args: Vec<String> = vec![file.to_string_lossy().into_owned(), "--slurm".into()];
    let o = &c.slurm;
    if o.dry_run {
        args.push("--dry-run".into());
    }
    for (k, v) in [("--partition", &o.partition), ("--account", &o.account), ("--time", &o.time), ("--mem", &o.mem)] {
        if let Some(v) = v {
            args.extend([k.to_string(), v.clone()]);
        }
    }
    if let Some(f) = &o.sbatch_lines {
        args.extend(["--sbatch-lines".to_string(), f.to_string_lossy().into_owned()]);
    }
    args.extend(["--cpus-per-task".to_string(), o.cpus_per_task.to_string(), "--checkpoint-lead-s".to_string(), o.checkpoint_lead_s.to_string()]);
    super::campaign::cli(args)
}

/// A run the campaign of a `--slurm` sweep finished, measured from the last
/// frame it kept (as [`one_run`] measures its own).
fn from_campaign(c: &SweepCli, d: f64, g: f64, seed: i64) -> Option<Result<RunResult, String>> {
    let dir = c.out.join("runs").join(run_dir(d, g, seed));
    let text = std::fs::read_to_string(dir.join("result.json")).ok()?;
    let measure = || -> Result<RunResult, String> {
        let o: super::campaign::RunOutcome = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", dir.join("result.json").display()))?;
        let dump = dir.join("final.dump.gz");
        let frame = pick_frame(&dump.to_string_lossy(), None).map_err(|e| format!("{}: {e}", dump.display()))?;
        let rep = repose(&frame).map_err(|e| format!("{}: {e}", dump.display()))?;
        let y = c.vars.iter().find(|v| v[0] == "Y").map(|v| v[1..].join(" ")).unwrap_or_default();
        Ok(RunResult { d, g, seed, theta: rep.theta, sd: rep.sd, n: rep.particles, y, wall: o.wall_s })
    };
    Some(measure())
}

/// Run (or reuse) one heap run; Ok(result) or the failure message.
fn one_run(c: &SweepCli, deck: &Path, d: f64, g: f64, seed: i64) -> Result<RunResult, String> {
    let dir = c.out.join(run_dir(d, g, seed));
    let res_path = dir.join("result.json");
    if let Ok(text) = std::fs::read_to_string(&res_path) {
        if let Ok(r) = serde_json::from_str::<RunResult>(&text) {
            return Ok(r);
        }
    }
    if let Some(r) = from_campaign(c, d, g, seed) {
        return r;
    }
    if c.collect {
        return Err(format!("not finished (`demx campaign {} --status`)", c.out.join(CAMPAIGN).display()));
    }
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let exe = std::env::current_exe().map_err(|e| format!("cannot find the demx executable: {e}"))?;
    let mut cmd = std::process::Command::new(exe);
    cmd.current_dir(&dir).arg("run").arg(deck).args(["--threads", "1", "--quiet", "--log", "log.demx"]);
    cmd.args(["-var", "d", &format!("{d:e}"), "-var", "g", &g.to_string(), "-var", "seed", &seed.to_string()]);
    for v in &c.vars {
        cmd.arg("-var").args(v);
    }
    let t0 = Instant::now();
    let out = cmd.output().map_err(|e| format!("cannot start demx run: {e}"))?;
    let wall = t0.elapsed().as_secs_f64();
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let _ = std::fs::write(dir.join("stderr.txt"), err.as_bytes());
        return Err(format!("demx run failed ({}): {}", out.status, err.lines().next().unwrap_or("")));
    }
    let dump = dir.join(&c.dump);
    let frame = pick_frame(&dump.to_string_lossy(), None).map_err(|e| format!("{}: {e}", dump.display()))?;
    let rep = repose(&frame).map_err(|e| format!("{}: {e}", dump.display()))?;
    let y = c.vars.iter().find(|v| v[0] == "Y").map(|v| v[1..].join(" ")).unwrap_or_default();
    let r = RunResult { d, g, seed, theta: rep.theta, sd: rep.sd, n: rep.particles, y, wall };
    let text = serde_json::to_string_pretty(&r).map_err(|e| e.to_string())?;
    std::fs::write(&res_path, text).map_err(|e| format!("cannot write {}: {e}", res_path.display()))?;
    Ok(r)
}

/// Run every (d, g, seed) J at a time; results in a fixed order (g, d, seed).
pub fn run_all(c: &SweepCli) -> Vec<(f64, f64, i64, Result<RunResult, String>)> {
    let deck = std::fs::canonicalize(&c.deck).unwrap_or_else(|_| c.deck.clone());
    let todo = matrix(c);
    let jobs = c.jobs.unwrap_or_else(|| std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)).min(todo.len()).max(1);
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<RunResult, String>>>> = Mutex::new(vec![None; todo.len()]);
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(&(d, g, sd)) = todo.get(i) else { break };
                let r = one_run(c, &deck, d, g, sd);
                match &r {
                    Ok(x) => eprintln!("sweep: d = {d:e} m, g = {g}, seed {sd}: theta_r = {:.2} +- {:.2} deg ({:.1} s)", x.theta, x.sd, x.wall),
                    Err(e) => eprintln!("sweep: d = {d:e} m, g = {g}, seed {sd}: {e}"),
                }
                if let Ok(mut v) = results.lock() {
                    v[i] = Some(r);
                }
            });
        }
    });
    let results = results.into_inner().unwrap_or_default();
    todo.into_iter().zip(results).map(|((d, g, s), r)| (d, g, s, r.unwrap_or_else(|| Err("not run".into())))).collect()
}

/// The CSV table of the runs.
pub fn csv_table(runs: &[RunResult]) -> String {
    let mut s = String::from("d,g,seed,theta_deg,sd_deg,n,Y,wall_s\n");
    for r in runs {
        s += &format!("{:e},{},{},{:.4},{:.4},{},{},{:.2}\n", r.d, r.g, r.seed, r.theta, r.sd, r.n, r.y, r.wall);
    }
    s
}

fn pm(v: f64, se: f64, scale: f64, digits: usize) -> String {
    if se.is_finite() {
        format!("{:.*} ± {:.*}", digits, v * scale, digits, se * scale)
    } else {
        format!("{:.*}", digits, v * scale)
    }
}

/// The fitted parameters as text lines (also the CSV of the fits).
pub fn fits_csv(f: &Fits) -> String {
    let mut s = String::from("equation,g,parameter,value,se,r2,n\n");
    for (g, e) in &f.eq1 {
        s += &format!("1,{g},mu_eff_inf,{},{},{},{}\n", e.mu, e.mu_se, e.r2, e.n);
        s += &format!("1,{g},D_m,{},{},{},{}\n", e.c, e.c_se, e.r2, e.n);
    }
    if let Some(e) = &f.eq3 {
        s += &format!("3,all,mu_eff_inf,{},{},{},{}\n", e.mu, e.mu_se, e.r2, e.n);
        s += &format!("3,all,D_E_m,{},{},{},{}\n", e.c, e.c_se, e.r2, e.n);
    }
    if let Some((d0, sd0, a, sa)) = f.power {
        s += &format!("2,all,D_0_m,{d0},{sd0},,\n2,all,alpha,{a},{sa},,\n");
    }
    if let Some(e) = &f.eq4 {
        s += &format!("4,all,mu_eff_inf,{},{},{},{}\n", e.mu, e.mu_se, e.r2, e.n);
        s += &format!("4,all,beta,{},{},{},{}\n", e.c, e.c_se, e.r2, e.n);
    }
    s
}

/// The Markdown section: runs table and fits beside the paper's values.
pub fn markdown(runs: &[RunResult], failed: &[String], f: &Fits) -> String {
    let mut s = String::from("## Angle of repose sweep (Elekes & Parteli 2021)\n\n");
    s += "| d (µm) | g/g_E | seed | θr (°) | SD (°) | N | Y (Pa) | wall (s) | paper Eq. 3 (°) |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for r in runs {
        let paper = atan_model(PAPER_MU, PAPER_DE, 1.0 / (r.d * r.g.sqrt())).to_degrees();
        let y = if r.y.is_empty() { "deck" } else { r.y.as_str() };
        s += &format!("| {:.1} | {} | {} | {:.2} | {:.2} | {} | {y} | {:.1} | {paper:.2} |\n", r.d * 1e6, r.g, r.seed, r.theta, r.sd, r.n, r.wall);
    }
    for e in failed {
        s += &format!("\nFailed: {e}\n");
    }
    s += "\n| fit | parameter | this sweep | paper |\n|---|---|---:|---:|\n";
    if let Some(e) = &f.eq3 {
        s += &format!("| Eq. 3 (all g) | μ_eff,∞ | {} | {PAPER_MU} |\n", pm(e.mu, e.mu_se, 1.0, 3));
        s += &format!("| Eq. 3 (all g) | D_E (µm) | {} | {} |\n", pm(e.c, e.c_se, 1e6, 1), PAPER_DE * 1e6);
        s += &format!("| Eq. 3 (all g) | θr,∞ = atan μ (°) | {:.2} | {:.2} |\n", e.mu.atan().to_degrees(), PAPER_MU.atan().to_degrees());
        s += &format!("| Eq. 3 (all g) | R² | {:.3} | 0.99 |\n", e.r2);
    }
    for (g, e) in &f.eq1 {
        let paper_d = PAPER_DE / g.sqrt();
        s += &format!(
            "| Eq. 1 (g/g_E = {g}) | μ_eff,∞ | {}{} | {PAPER_MU} |\n",
            pm(e.mu, e.mu_se, 1.0, 3),
            if e.mu_se == 0.0 { " (fixed)" } else { "" }
        );
        s += &format!("| Eq. 1 (g/g_E = {g}) | D (µm) | {} | {:.1} (Eq. 2) |\n", pm(e.c, e.c_se, 1e6, 1), paper_d * 1e6);
    }
    if let Some((d0, sd0, a, sa)) = f.power {
        s += &format!("| D = D_0/g^α | D_0 (µm) | {} | {} |\n", pm(d0, sd0, 1e6, 1), PAPER_POWER.0 * 1e6);
        s += &format!("| D = D_0/g^α | α | {} | {} (Eq. 2: 0.5) |\n", pm(a, sa, 1.0, 3), PAPER_POWER.1);
    }
    if let Some(e) = &f.eq4 {
        s += &format!("| Eq. 4 | μ_eff,∞ | {} | {} |\n", pm(e.mu, e.mu_se, 1.0, 3), PAPER_EQ4.0);
        s += &format!("| Eq. 4 | β | {} | {} |\n", pm(e.c, e.c_se, 1.0, 4), PAPER_EQ4.1);
    }
    s += &format!(
        "\nPaper: non-cohesive θr ≈ atan({PAPER_MU}) = {:.1}°; Eq. 1 θr = atan(μ_eff,∞ (1 + D/d)), Eq. 2 D = D_E/√g̃, Eq. 3 θr = atan(μ_eff,∞ (1 + D_E/(d √g̃))), Eq. 4 θr = atan(μ_eff,∞ (1 + β √Bo)), Bo = 12γ/(d² g ρ).\n",
        PAPER_MU.atan().to_degrees()
    );
    s
}

/// The charts: theta_r(d) per g level with SD bars, the Eq. 1 fits and the paper's Eq. 3.
pub fn charts(runs: &[RunResult], f: &Fits) -> Vec<Chart> {
    let mut series = vec![];
    let dmin = runs.iter().map(|r| r.d).fold(f64::INFINITY, f64::min);
    let dmax = runs.iter().map(|r| r.d).fold(0.0, f64::max);
    let grid: Vec<f64> = (0..=60).map(|i| dmin * 0.8 * (dmax * 1.25 / (dmin * 0.8)).powf(i as f64 / 60.0)).collect();
    let mut levels: Vec<f64> = runs.iter().map(|r| r.g).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    for g in levels {
        let sel: Vec<&RunResult> = runs.iter().filter(|r| r.g == g).collect();
        series.push(Series {
            label: format!("demx g/g_E = {g}"),
            points: sel.iter().map(|r| (r.d * 1e6, r.theta)).collect(),
            kind: SeriesKind::ErrorBars(sel.iter().map(|r| r.sd).collect()),
        });
        if let Some((_, e)) = f.eq1.iter().find(|e| e.0 == g) {
            series.push(Series {
                label: format!("Eq. 1 fit, D = {:.1} µm", e.c * 1e6),
                points: grid.iter().map(|d| (d * 1e6, atan_model(e.mu, e.c, 1.0 / d).to_degrees())).collect(),
                kind: SeriesKind::Line,
            });
        }
        series.push(Series {
            label: format!("paper Eq. 3, g/g_E = {g}"),
            points: grid.iter().map(|d| (d * 1e6, atan_model(PAPER_MU, PAPER_DE, 1.0 / (d * g.sqrt())).to_degrees())).collect(),
            kind: SeriesKind::Line,
        });
    }
    vec![Chart {
        title: "Angle of repose vs particle size".into(),
        x_label: "d (µm)".into(),
        y_label: "θr (°)".into(),
        log_x: true,
        series,
        ..Chart::default()
    }]
}

fn write(path: &Path, text: &str) -> bool {
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        let _ = std::fs::create_dir_all(dir);
    }
    match std::fs::write(path, text) {
        Ok(()) => true,
        Err(e) => {
            eprintln!("error: cannot write {}: {e}", path.display());
            false
        }
    }
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    let c = match parse(args) {
        Ok(c) => c,
        Err(code) => return code,
    };
    if let Err(e) = std::fs::create_dir_all(&c.out) {
        return usage(format!("cannot create {}: {e}", c.out.display()));
    }
    if c.slurm.slurm {
        if c.collect {
            return usage("--slurm submits, --collect gathers: one at a time");
        }
        return submit_slurm(&c, &std::fs::canonicalize(&c.deck).unwrap_or_else(|_| c.deck.clone()));
    }
    let all = run_all(&c);
    let mut runs = vec![];
    let mut failed = vec![];
    for (d, g, s, r) in all {
        match r {
            Ok(r) => runs.push(r),
            Err(e) => failed.push(format!("d = {d:e} m, g = {g}, seed {s}: {e}")),
        }
    }
    let fits = fit_all(&runs, c.gamma, c.rho);
    let mut ok = failed.is_empty();
    let csv = c.csv.clone().unwrap_or_else(|| c.out.join("sweep.csv"));
    ok &= write(&csv, &csv_table(&runs));
    ok &= write(&c.out.join("fits.csv"), &fits_csv(&fits));
    print!("{}", csv_table(&runs));
    if let Some(e) = &fits.eq3 {
        println!(
            "Eq. 3: mu_eff,inf = {}, D_E = {} um (R^2 {:.3}); paper {PAPER_MU}, {} um",
            pm(e.mu, e.mu_se, 1.0, 4),
            pm(e.c, e.c_se, 1e6, 2),
            e.r2,
            PAPER_DE * 1e6
        );
    }
    for (g, e) in &fits.eq1 {
        println!("Eq. 1, g/g_E = {g}: mu_eff,inf = {}, D = {} um", pm(e.mu, e.mu_se, 1.0, 4), pm(e.c, e.c_se, 1e6, 2));
    }
    if let Some((d0, sd0, a, sa)) = fits.power {
        println!("D = D_0/g^alpha: D_0 = {} um, alpha = {}; paper 76 um, 0.454", pm(d0, sd0, 1e6, 2), pm(a, sa, 1.0, 3));
    }
    if let Some(e) = &fits.eq4 {
        println!("Eq. 4: mu_eff,inf = {}, beta = {}; paper 0.458, 0.014", pm(e.mu, e.mu_se, 1.0, 4), pm(e.c, e.c_se, 1.0, 5));
    }
    if let Some(md) = &c.markdown {
        ok &= write(md, &markdown(&runs, &failed, &fits));
    }
    if let Some(png) = &c.plot {
        if !runs.is_empty() {
            if let Err(e) = crate::plot::write_png(png, &charts(&runs, &fits)) {
                eprintln!("warning: {}", e.message());
            }
        }
    }
    for e in &failed {
        eprintln!("error: run failed: {e}");
    }
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_are_primes_that_the_heap_deck_accepts() {
        // the heap's template (15485867) and distribution (32452843) seeds
        // must never come up: LIGGGHTS aborts on an insertion seed equal to them
        let s: Vec<i64> = (0..12).map(seed).collect();
        assert_eq!(s[0], 15485863);
        for (k, x) in s.iter().enumerate() {
            assert!(crate::engine::insert::is_prime(*x) && *x > 10000, "{x}");
            assert!(*x != 15485867 && *x != 32452843, "{x}");
            assert!(!s[..k].contains(x), "repeated {x}");
        }
    }
}
