//! `demx compare DECK --against liggghts|lammps`: run the deck with demx (this
//! executable, `run`) and with the reference engine on the same
//! full-precision copy, then compare their dumps. With `--seeds K > 1` each
//! side runs K times (`-var SEEDVAR s_k`, prime seeds as LIGGGHTS wants) and
//! statistics are judged against the spread between seeds.

use super::compare::{compare_series, load, pair_series, report, CompareArgs, Comparison, Mode, Series};
use super::compare_stats::{heap_stats, HeapStats};
use super::reference::{prepare_deck, run_engine, EngineResult, EngineRun};
use crate::error::{Error, Result};
use crate::script::source::Span;
use serde::Serialize;
use std::path::Path;
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

/// Seeds handed to runs k = 0, 1, ... (primes above 10000, as LIGGGHTS insertion wants:
/// the 1, 3, 4, ... 9 millionth primes). 32452843 and 15485867 are left out: LIGGGHTS
/// examples use them for particle templates and distributions, and LIGGGHTS 3.8
/// aborts when an insertion fix reuses another fix's seed.
pub const SEEDS: [u64; 8] = [15485863, 49979687, 67867967, 86028121, 104395301, 122949823, 141650939, 160481183];

/// One demx run of a deck.
#[derive(Clone, Debug, Serialize)]
pub struct DemxResult {
    /// Command line.
    pub command: String,
    /// Wall time (s).
    pub wall_seconds: f64,
}

/// Run the current executable with `args` (then `-var NAME VALUES...` for
/// each of `vars`) in `dir`: its output and the wall time in seconds.
pub fn spawn_demx(dir: &Path, args: &mut Vec<String>, vars: &[(String, Vec<String>)]) -> Result<(std::process::Output, f64)> {
    let exe = std::env::current_exe().map_err(|e| Error::io(Span::DUMMY, "cannot find the demx executable", &e))?;
    for (n, v) in vars {
        args.push("-var".into());
        args.push(n.clone());
        args.extend(v.iter().cloned());
    }
    let t0 = Instant::now();
    let out = Command::new(&exe)
        .args(args.iter())
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| Error::io(Span::DUMMY, format!("cannot start '{}'", exe.display()), &e))?;
    Ok((out, t0.elapsed().as_secs_f64()))
}

/// Run `demx run` (the current executable) on `deck_name` inside `dir`.
pub fn run_demx(dir: &Path, deck_name: &str, vars: &[(String, Vec<String>)], extra: &[String]) -> Result<DemxResult> {
    let mut args: Vec<String> = vec!["run".into(), "--quiet".into(), "--log".into(), "log.demx".into(), deck_name.into()];
    args.extend(extra.iter().cloned());
    let (out, wall_seconds) = spawn_demx(dir, &mut args, vars)?;
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
        let peak = per_seed.iter().flat_map(|c| c.frames.iter().map(|f| f.a.ke + f.a.ke_rot)).fold(0.0, f64::max);
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
        stat("coordination", rows.iter().map(|r| r.a.coordination).collect(), rows.iter().map(|r| r.b.coordination).collect(), args.tol_coord);
        // centre of mass per component; the fixed tolerance is in mean diameters
        for (k, axis) in ["com x", "com y", "com z"].iter().enumerate() {
            stat(axis, rows.iter().map(|r| r.a.com[k]).collect(), rows.iter().map(|r| r.b.com[k]).collect(), args.tol_com * dmean);
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

/// Heap statistics of the last frame of each side, per seed.
#[derive(Clone, Debug, Serialize)]
pub struct HeapRow {
    /// Seed (None: the deck's own).
    pub seed: Option<u64>,
    /// Engine heap.
    pub engine: Option<HeapStats>,
    /// demx heap.
    pub demx: Option<HeapStats>,
}

fn last_heap(series: &[Series]) -> Option<HeapStats> {
    series.first().and_then(|s| s.snaps.last()).and_then(heap_stats)
}

/// Judge heap statistics (count, θr, core ϕ) of K seeds against their spread.
pub fn heap_checks(rows: &[HeapRow], args: &CompareArgs) -> Vec<SpreadCheck> {
    let pairs: Vec<(HeapStats, HeapStats)> = rows.iter().filter_map(|r| Some((r.engine?, r.demx?))).collect();
    let mut out = vec![];
    if pairs.len() != rows.len() || pairs.is_empty() {
        out.push(SpreadCheck {
            series: "heap".into(),
            what: "heap found".into(),
            timestep: 0,
            demx_mean: rows.iter().filter(|r| r.demx.is_some()).count() as f64,
            engine_mean: rows.iter().filter(|r| r.engine.is_some()).count() as f64,
            allowed: 0.0,
            pass: false,
        });
        return out;
    }
    let mut stat = |what: &str, f: &dyn Fn(&HeapStats) -> f64, floor: f64| {
        let e: Vec<f64> = pairs.iter().map(|p| f(&p.0)).collect();
        let d: Vec<f64> = pairs.iter().map(|p| f(&p.1)).collect();
        let allowed = range(&e).max(range(&d)) + floor;
        let (me, md) = (mean(&e), mean(&d));
        out.push(SpreadCheck {
            series: "heap".into(),
            what: what.into(),
            timestep: 0,
            demx_mean: md,
            engine_mean: me,
            allowed,
            pass: (md - me).abs() <= allowed,
        });
    };
    stat("heap count", &|h| h.count as f64, 0.0);
    stat("theta_r (deg)", &|h| h.theta, args.tol_theta);
    stat("core phi", &|h| h.phi, args.tol_phi);
    out
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
    let prep = prepare_deck(deck, engine, args.allow_shell)?;
    let tmp = tempfile::tempdir().map_err(|e| Error::io(Span::DUMMY, "cannot create a temporary directory", &e))?;
    let root = args.keep.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    let mut runs = vec![];
    let mut comparisons: Vec<Comparison> = vec![];
    let mut heaps = vec![];
    let mut opts = args.options();
    if k > 1 && opts.mode == Mode::Auto {
        opts.mode = Mode::Statistics;
    }
    let mkdir = |d: &Path| -> Result<()> {
        std::fs::create_dir_all(d).map_err(|e| Error::io(Span::DUMMY, format!("cannot create '{}'", d.display()), &e))?;
        prep.install(d)
    };
    for s in 0..k {
        let seed = (k > 1).then(|| SEEDS[s]);
        let mut vars = args.vars.clone();
        if let Some(sd) = seed {
            vars.push((args.seed_var.clone(), vec![sd.to_string()]));
        }
        let suffix = if k > 1 { format!("-{s}") } else { String::new() };
        let ddir = root.join(format!("demx{suffix}"));
        let edir = root.join(format!("{}{suffix}", engine.name()));
        mkdir(&ddir)?;
        mkdir(&edir)?;
        let er = run_engine(&edir, &prep.deck_name, &EngineRun { engine, np: args.np.max(1), vars: vars.clone() })?;
        let dr = run_demx(&ddir, &prep.deck_name, &vars, &[])?;
        let a = load(&edir.to_string_lossy())?;
        let b = load(&ddir.to_string_lossy())?;
        if args.heap {
            heaps.push(HeapRow { seed, engine: last_heap(&a), demx: last_heap(&b) });
        }
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
    let mut ensemble_runs = vec![];
    if k > 1 {
        let per = comparisons.len() / k;
        for j in 0..per {
            let cs: Vec<&Comparison> = (0..k).map(|s| &comparisons[s * per + j]).collect();
            spread.extend(spread_checks(&cs[0].b.clone(), &cs, args));
        }
    } else if args.ensemble > 0 && comparisons.iter().any(|c| c.mode == Mode::Statistics && c.divergence.is_some()) {
        // one seed but chaos took over: the spread of a demx ensemble (the
        // same deck, particles moved by a tiny amount at the start) says how
        // far apart two equally valid runs end up
        let edir = root.join(engine.name());
        let mut members: Vec<Vec<Comparison>> = vec![];
        for m in 1..=args.ensemble {
            let ddir = root.join(format!("demx-ensemble-{m}"));
            mkdir(&ddir)?;
            let extra = vec!["--perturb".to_string(), format!("{m}:{}", args.perturb)];
            ensemble_runs.push(run_demx(&ddir, &prep.deck_name, &args.vars, &extra)?);
            let a = load(&edir.to_string_lossy())?;
            let b = load(&ddir.to_string_lossy())?;
            members.push(pair_series(a, b)?.iter().map(|(sa, sb)| compare_series(sa, sb, &opts)).collect());
        }
        for (j, base) in comparisons.iter().enumerate() {
            let mut cs: Vec<&Comparison> = vec![base];
            cs.extend(members.iter().filter_map(|m| m.get(j)));
            spread.extend(spread_checks(&base.b.clone(), &cs, args));
        }
        // the fixed statistics tolerances give way to the spread; what the
        // base comparison still judges is structure (frames, counts, early divergence)
        let mut loose = opts.clone();
        (loose.tol_ke, loose.tol_com, loose.tol_coord) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let a = load(&edir.to_string_lossy())?;
        let b = load(&root.join("demx").to_string_lossy())?;
        let names: Vec<(String, String)> = comparisons.iter().map(|c| (c.a.clone(), c.b.clone())).collect();
        comparisons = pair_series(a, b)?.iter().map(|(sa, sb)| compare_series(sa, sb, &loose)).collect();
        for (c, (na, nb)) in comparisons.iter_mut().zip(names) {
            (c.a, c.b) = (na, nb);
            c.notes.push(format!("statistics judged against a {}-member demx ensemble (perturbation {} radii)", args.ensemble + 1, args.perturb));
        }
    }
    spread.extend(heap_checks(&heaps, args).into_iter().filter(|_| args.heap));
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
        for (m, r) in ensemble_runs.iter().enumerate() {
            println!("  demx ensemble member {}: {:.2} s", m + 1, r.wall_seconds);
        }
        for h in &heaps {
            let f = |x: &Option<HeapStats>| {
                x.map_or("no heap".to_string(), |h| {
                    format!("theta_r {:.2} +- {:.2} deg, phi {:.3}, {} particles", h.theta, h.theta_sd, h.phi, h.count)
                })
            };
            println!("  heap{}: {}: {}; demx: {}", h.seed.map_or(String::new(), |s| format!(" (seed {s})")), engine.name(), f(&h.engine), f(&h.demx));
        }
        for n in &prep.notes {
            println!("note: {n}");
        }
        if let Some(kd) = &args.keep {
            println!("run folders kept in {}", kd.display());
        }
        println!();
    }
    let extra = serde_json::json!({ "deck": args.a, "runs": runs, "ensemble": ensemble_runs, "spread": spread, "heap": heaps, "notes": prep.notes });
    if spread.is_empty() {
        return report(args, &comparisons, Some(extra));
    }
    // the per-run comparisons are information; the spread (and, with one
    // seed, the structural checks of the base comparison) give the verdict
    let base_pass = k > 1 || comparisons.iter().all(|c| c.pass);
    let pass = spread_pass && base_pass;
    if args.json {
        let v = serde_json::json!({ "pass": pass, "comparisons": comparisons, "run": extra });
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        if k == 1 {
            for c in &comparisons {
                print!("{}", super::compare::render(c));
            }
            println!();
        }
        for c in &comparisons {
            if let Some((t, id, e)) = c.divergence {
                println!(
                    "{} vs {}: trajectories diverge at timestep {t} (particle {}, {e:.3e} d)",
                    c.a,
                    c.b,
                    id.map_or("?".to_string(), |i| i.to_string())
                );
            }
        }
        let last = spread.iter().filter(|s| s.series != "heap").map(|s| s.timestep).max();
        println!("{:>14} {:>10} {:>14} {:>14} {:>12}  verdict", "statistic", "timestep", "demx mean", "engine mean", "allowed");
        for s in &spread {
            if !s.pass || Some(s.timestep) == last || s.series == "heap" {
                println!(
                    "{:>14} {:>10} {:>14.6e} {:>14.6e} {:>12.3e}  {}",
                    s.what,
                    if s.series == "heap" { "final".to_string() } else { s.timestep.to_string() },
                    s.demx_mean,
                    s.engine_mean,
                    s.allowed,
                    if s.pass { "ok" } else { "FAIL" }
                );
            }
        }
        println!("verdict: {}", if pass { "PASS" } else { "FAIL" });
    }
    if let Some(p) = &args.csv {
        super::compare::write_csv(p, &comparisons)?;
    }
    Ok(ExitCode::from(if pass { 0 } else { 1 }))
}
