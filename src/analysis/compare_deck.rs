//! `demx compare DECK --against liggghts|lammps`: run the deck with demx (this
//! executable, `run`) and with the reference engine on the same
//! full-precision copy, then compare their dumps. With `--seeds K > 1` each
//! side runs K times (`-var SEEDVAR s_k`, prime seeds as LIGGGHTS wants) and
//! statistics are judged against the spread between seeds.

use super::compare::{compare_series, load, pair_series, report, CompareArgs, Comparison, Mode};
use super::reference::{prepare_deck, run_engine, EngineResult, EngineRun};
use crate::error::{Error, Result};
use crate::script::source::Span;
use serde::Serialize;
use std::path::Path;
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

/// Seeds handed to runs k = 0, 1, ... (primes above 10000, as LIGGGHTS insertion wants).
pub const SEEDS: [u64; 8] = [15485863, 32452843, 49979687, 67867967, 86028121, 104395301, 122949823, 141650939];

/// One demx run of a deck.
#[derive(Clone, Debug, Serialize)]
pub struct DemxResult {
    /// Command line.
    pub command: String,
    /// Wall time (s).
    pub wall_seconds: f64,
}

/// Run `demx run` (the current executable) on `deck_name` inside `dir`.
pub fn run_demx(dir: &Path, deck_name: &str, vars: &[(String, Vec<String>)]) -> Result<DemxResult> {
    let exe = std::env::current_exe().map_err(|e| Error::io(Span::DUMMY, "cannot find the demx executable", &e))?;
    let mut args: Vec<String> = vec!["run".into(), "--quiet".into(), "--log".into(), "log.demx".into(), deck_name.into()];
    for (n, v) in vars {
        args.push("-var".into());
        args.push(n.clone());
        args.extend(v.iter().cloned());
    }
    let t0 = Instant::now();
    let out = Command::new(&exe)
        .args(&args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| Error::io(Span::DUMMY, format!("cannot start '{}'", exe.display()), &e))?;
    let wall_seconds = t0.elapsed().as_secs_f64();
    let command = format!("demx {}", args.join(" "));
    if !out.status.success() {
        return Err(Error::usage(format!(
            "demx run failed on {deck_name} ({}); command: {command}\n{}",
            out.status,
            super::reference::tail(&String::from_utf8_lossy(&out.stderr), 15)
        )));
    }
    Ok(DemxResult { command, wall_seconds })
}

/// The runs of one seed.
#[derive(Clone, Debug, Serialize)]
pub struct SeedRuns {
    /// Seed value (None with one seed: the deck as it is).
    pub seed: Option<u64>,
    /// demx run.
    pub demx: DemxResult,
    /// Engine run.
    pub engine: EngineResult,
}

/// Statistic judged against the spread between seeds.
#[derive(Clone, Debug, Serialize)]
pub struct SpreadCheck {
    /// Dump series.
    pub series: String,
    /// Statistic name.
    pub what: String,
    /// Timestep.
    pub timestep: u64,
    /// Mean over demx seeds.
    pub demx_mean: f64,
    /// Mean over engine seeds.
    pub engine_mean: f64,
    /// Allowed difference: largest seed range of either side plus the fixed tolerance.
    pub allowed: f64,
    /// Within?
    pub pass: bool,
}

fn range(v: &[f64]) -> f64 {
    let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    if v.is_empty() {
        0.0
    } else {
        hi - lo
    }
}
fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        0.0
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

/// Judge statistics of K seed pairs (comparisons of the same series, one per
/// seed, A = engine, B = demx) against the spread between seeds.
pub fn spread_checks(series: &str, per_seed: &[&Comparison], args: &CompareArgs) -> Vec<SpreadCheck> {
    let mut out = vec![];
    let Some(first) = per_seed.first() else { return out };
    let dmean = mean_diameter(per_seed);
    for f0 in &first.frames {
        let t = f0.timestep;
        let rows: Vec<_> = per_seed.iter().filter_map(|c| c.frames.iter().find(|f| f.timestep == t)).collect();
        if rows.len() != per_seed.len() {
            continue;
        }
        let peak = per_seed
            .iter()
            .flat_map(|c| c.frames.iter().map(|f| f.a.ke + f.a.ke_rot))
            .fold(0.0, f64::max);
        let peak = if peak > 0.0 { peak } else { 1.0 };
        let mut stat = |what: &str, e: Vec<f64>, d: Vec<f64>, floor: f64| {
            let allowed = range(&e).max(range(&d)) + floor;
            let (me, md) = (mean(&e), mean(&d));
            out.push(SpreadCheck {
                series: series.to_string(),
                what: what.to_string(),
                timestep: t,
                demx_mean: md,
                engine_mean: me,
                allowed,
                pass: (md - me).abs() <= allowed,
            });
        };
        stat("count", rows.iter().map(|r| r.a.count as f64).collect(), rows.iter().map(|r| r.b.count as f64).collect(), 0.0);
        stat(
            "KE/peak",
            rows.iter().map(|r| (r.a.ke + r.a.ke_rot) / peak).collect(),
            rows.iter().map(|r| (r.b.ke + r.b.ke_rot) / peak).collect(),
            args.tol_ke,
        );
        stat(
            "coordination",
            rows.iter().map(|r| r.a.coordination).collect(),
            rows.iter().map(|r| r.b.coordination).collect(),
            args.tol_coord,
        );
        // centre of mass per component; the fixed tolerance is in mean diameters
        for (k, axis) in ["com x", "com y", "com z"].iter().enumerate() {
            stat(
                axis,
                rows.iter().map(|r| r.a.com[k]).collect(),
                rows.iter().map(|r| r.b.com[k]).collect(),
                args.tol_com * dmean,
            );
        }
    }
    out
}

fn mean_diameter(cs: &[&Comparison]) -> f64 {
    // com_dev = |dcom| / dmean, so dmean = |dcom| / com_dev where both are known
    for c in cs {
        for f in &c.frames {
            let d = [f.a.com[0] - f.b.com[0], f.a.com[1] - f.b.com[1], f.a.com[2] - f.b.com[2]];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if f.com_dev > 0.0 && n > 0.0 {
                return n / f.com_dev;
            }
        }
    }
    1.0
}

/// `demx compare DECK --against ENGINE`.
pub fn run(args: &CompareArgs) -> Result<ExitCode> {
    let Some(engine) = args.against else { return Err(Error::usage("--against needs liggghts or lammps")) };
    if args.b.is_some() {
        return Err(Error::usage("with --against give one deck, not two runs"));
    }
    let k = args.seeds.max(1);
    if k > SEEDS.len() {
        return Err(Error::usage(format!("--seeds: at most {}", SEEDS.len())));
    }
    let deck = Path::new(&args.a);
    let prep = prepare_deck(deck, engine)?;
    let tmp = tempfile::tempdir().map_err(|e| Error::io(Span::DUMMY, "cannot create a temporary directory", &e))?;
    let root = args.keep.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    let mut runs = vec![];
    let mut comparisons: Vec<Comparison> = vec![];
    let mut opts = args.options();
    if k > 1 && opts.mode == Mode::Auto {
        opts.mode = Mode::Statistics;
    }
    for s in 0..k {
        let seed = (k > 1).then(|| SEEDS[s]);
        let mut vars = args.vars.clone();
        if let Some(sd) = seed {
            vars.push((args.seed_var.clone(), vec![sd.to_string()]));
        }
        let suffix = if k > 1 { format!("-{s}") } else { String::new() };
        let ddir = root.join(format!("demx{suffix}"));
        let edir = root.join(format!("{}{suffix}", engine.name()));
        for d in [&ddir, &edir] {
            std::fs::create_dir_all(d).map_err(|e| Error::io(Span::DUMMY, format!("cannot create '{}'", d.display()), &e))?;
            prep.install(d)?;
        }
        let er = run_engine(&edir, &prep.deck_name, &EngineRun { engine, np: args.np.max(1), vars: vars.clone() })?;
        let dr = run_demx(&ddir, &prep.deck_name, &vars)?;
        let a = load(&edir.to_string_lossy())?;
        let b = load(&ddir.to_string_lossy())?;
        for (sa, sb) in pair_series(a, b)? {
            let mut c = compare_series(&sa, &sb, &opts);
            c.a = format!("{} {}", engine.name(), sa.name);
            c.b = format!("demx {}", sb.name);
            if let Some(sd) = seed {
                c.notes.push(format!("seed {sd}"));
            }
            comparisons.push(c);
        }
        runs.push(SeedRuns { seed, demx: dr, engine: er });
    }
    let mut spread = vec![];
    if k > 1 {
        let per = comparisons.len() / k;
        for j in 0..per {
            let cs: Vec<&Comparison> = (0..k).map(|s| &comparisons[s * per + j]).collect();
            spread.extend(spread_checks(&cs[0].b.clone(), &cs, args));
        }
    }
    let spread_pass = spread.iter().all(|s| s.pass);
    if !args.json {
        println!("deck: {} against {}", deck.display(), engine.name());
        for r in &runs {
            println!(
                "  {}{}: {:.2} s; demx: {:.2} s",
                r.engine.version,
                r.seed.map_or(String::new(), |s| format!(" (seed {s})")),
                r.engine.wall_seconds,
                r.demx.wall_seconds
            );
        }
        for n in &prep.notes {
            println!("note: {n}");
        }
        if let Some(kd) = &args.keep {
            println!("run folders kept in {}", kd.display());
        }
        println!();
    }
    let extra = serde_json::json!({ "deck": args.a, "runs": runs, "spread": spread, "notes": prep.notes });
    if k == 1 {
        return report(args, &comparisons, Some(extra));
    }
    // K seeds: the per-seed comparisons are information; the verdict is the spread.
    if args.json {
        let v = serde_json::json!({ "pass": spread_pass, "comparisons": comparisons, "run": extra });
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        for c in &comparisons {
            if let Some((t, id, e)) = c.divergence {
                println!("{} vs {}: trajectories diverge at timestep {t} (particle {:?}, {e:.3e} d)", c.a, c.b, id);
            }
        }
        let last = spread.iter().map(|s| s.timestep).max();
        println!("{:>14} {:>10} {:>14} {:>14} {:>12}  verdict", "statistic", "timestep", "demx mean", "engine mean", "allowed");
        for s in &spread {
            if !s.pass || Some(s.timestep) == last {
                println!(
                    "{:>14} {:>10} {:>14.6e} {:>14.6e} {:>12.3e}  {}",
                    s.what,
                    s.timestep,
                    s.demx_mean,
                    s.engine_mean,
                    s.allowed,
                    if s.pass { "ok" } else { "FAIL" }
                );
            }
        }
        println!("verdict: {}", if spread_pass { "PASS" } else { "FAIL" });
    }
    if let Some(p) = &args.csv {
        super::compare::write_csv(p, &comparisons)?;
    }
    Ok(ExitCode::from(if spread_pass { 0 } else { 1 }))
}
