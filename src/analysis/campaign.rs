//! `demx campaign FILE [--jobs J] [--status] [--stop]`: a declared matrix
//! of runs (deck, variables) that survives stops and moves between
//! machines with the repository.
//!
//! The campaign file (JSON) names the deck (relative to the file), the
//! variables every run takes, and the runs, each with its own variables
//! and an estimate of its cost:
//!
//! ```json
//! { "deck": "../../../templates/heap/in.heap", "dump": "dump.heap", "measure": "repose",
//!   "checkpoint_every_s": 600, "vars": { "Y": "63e9", "model": "paper" },
//!   "runs": [ { "name": "earth_d1000", "vars": { "d": "1e-3", "g": "1" }, "estimate_core_h": 1.8 } ] }
//! ```
//!
//! Each run lives in `runs/NAME/` beside the file: `ckpt/checkpoint.json.gz`
//! while it is unfinished (`demx run --checkpoint`, every
//! `checkpoint_every_s` of wall time and when stopped), then `result.json`
//! (the measurement, the particle-steps, the wall time and which binary ran
//! which stretch) and `final.dump.gz` (the last frame of its dump); the
//! checkpoint is removed then. What the run writes as it goes is kept in
//! `runs/NAME/work/`, which is not meant to be committed. Committing `runs/`
//! at a stop is all it takes to carry the campaign over: the next start, on
//! any machine, continues each unfinished run from its checkpoint, bit for
//! bit as if it had not stopped.
//!
//! Runs go one per core (`--jobs`, default 1), one thread each. `--stop`
//! (or SIGTERM to the runner) asks every running run to stop at its next
//! checkpoint; `--status` prints what is done, resumable and pending, with
//! the core-hours left by the estimates. `--only RUN` runs just that run
//! (what each task of the Slurm backend runs), holding `runs/RUN/runner.pid`
//! instead of the campaign's lock. `--slurm` hands the unfinished runs to
//! Slurm as one job array instead ([`super::slurm`]).

use super::repose::{pick_frame, repose};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// One run of the matrix.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunSpec {
    /// Folder name under `runs/`.
    pub name: String,
    /// Its own variables (over the campaign's).
    #[serde(default)]
    pub vars: BTreeMap<String, String>,
    /// Estimated cost, core-hours (for `--status`).
    #[serde(default)]
    pub estimate_core_h: f64,
    /// Its own deck, dump and measure, where they differ from the campaign's.
    #[serde(default)]
    pub deck: Option<PathBuf>,
    /// See [`RunSpec::deck`].
    #[serde(default)]
    pub dump: Option<String>,
    /// See [`RunSpec::deck`].
    #[serde(default)]
    pub measure: Option<String>,
}

/// A campaign file.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Campaign {
    /// The deck, relative to the campaign file.
    pub deck: PathBuf,
    /// The dump whose last frame is measured.
    #[serde(default = "default_dump")]
    pub dump: String,
    /// What is measured: `repose` (theta_r) or `packing` (phi) or `both`.
    #[serde(default = "default_measure")]
    pub measure: String,
    /// Wall-clock seconds between checkpoints.
    #[serde(default = "default_every")]
    pub checkpoint_every_s: f64,
    /// Variables every run takes.
    #[serde(default)]
    pub vars: BTreeMap<String, String>,
    /// The runs, in the order they are started.
    pub runs: Vec<RunSpec>,
}

fn default_dump() -> String {
    "dump.heap".into()
}
fn default_measure() -> String {
    "repose".into()
}
fn default_every() -> f64 {
    600.0
}

/// A finished run (`result.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunOutcome {
    /// The run's name.
    pub name: String,
    /// All its variables (campaign's and its own).
    pub vars: BTreeMap<String, String>,
    /// theta_r (mean of the two projections), degrees.
    pub theta_deg: Option<f64>,
    /// SD of the two projections, degrees.
    pub theta_sd_deg: Option<f64>,
    /// Packing fraction (whole cross-section between 0.3 and 0.7 z_max).
    pub phi: Option<f64>,
    /// Particles in the last frame.
    pub particles: usize,
    /// Sum over the deck's runs of steps x particles at each run's end.
    pub particle_steps: f64,
    /// Wall time over all stretches, s.
    pub wall_s: f64,
    /// Core-hours (one thread per run).
    pub core_hours: f64,
    /// Which binary ran which stretch.
    pub segments: Vec<crate::scene::checkpoint::Segment>,
    /// When it finished (seconds since the Unix epoch).
    pub finished_unix: u64,
}

#[derive(clap::Parser, Debug)]
#[command(name = "demx campaign", about = "Run a declared matrix of runs that survives stops (see the module's text)")]
struct Cli {
    /// The campaign file (JSON).
    file: PathBuf,
    /// Runs at a time (one thread each).
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Print what is done, resumable and pending, and the core-hours left.
    #[arg(long)]
    status: bool,
    /// Ask a running campaign to stop at its runs' next checkpoints.
    #[arg(long)]
    stop: bool,
    /// Start at most this many runs, then wait for them (tests).
    #[arg(long)]
    max_runs: Option<usize>,
    /// Extra arguments for every `demx run` (e.g. `--checkpoint-stop-after 2`, tests).
    #[arg(long, allow_hyphen_values = true)]
    run_arg: Vec<String>,
    /// Run only this run (repeatable), here: what each task of `--slurm` runs.
    #[arg(long)]
    only: Vec<String>,
    /// The Slurm backend.
    #[command(flatten)]
    slurm: super::slurm::SlurmOpts,
}

/// A campaign's folder, file and runs.
struct Place {
    dir: PathBuf,
    c: Campaign,
}

impl Place {
    fn load(file: &Path) -> Result<Place, String> {
        let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
        let c: Campaign = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", file.display()))?;
        let mut seen = std::collections::HashSet::new();
        for r in &c.runs {
            let ok = !r.name.is_empty() && r.name.chars().all(|ch| ch.is_ascii_alphanumeric() || "_-.".contains(ch)) && !r.name.starts_with('.');
            if !ok {
                return Err(format!("{}: run name '{}' is not a plain folder name", file.display(), r.name));
            }
            if !seen.insert(r.name.clone()) {
                return Err(format!("{}: run '{}' is declared twice", file.display(), r.name));
            }
        }
        if !(c.checkpoint_every_s.is_finite() && c.checkpoint_every_s >= 0.0) {
            return Err(format!("{}: checkpoint_every_s must be >= 0", file.display()));
        }
        let dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf();
        Ok(Place { dir, c })
    }
    fn run_dir(&self, r: &RunSpec) -> PathBuf {
        self.dir.join("runs").join(&r.name)
    }
    fn deck(&self, r: &RunSpec) -> PathBuf {
        self.dir.join(r.deck.as_ref().unwrap_or(&self.c.deck))
    }
    fn dump<'a>(&'a self, r: &'a RunSpec) -> &'a str {
        r.dump.as_deref().unwrap_or(&self.c.dump)
    }
    fn measure<'a>(&'a self, r: &'a RunSpec) -> &'a str {
        r.measure.as_deref().unwrap_or(&self.c.measure)
    }
    fn vars(&self, r: &RunSpec) -> BTreeMap<String, String> {
        let mut v = self.c.vars.clone();
        v.extend(r.vars.clone());
        v
    }
}

/// Where a run stands.
enum State {
    Done(Box<RunOutcome>),
    Resumable { step: i64, wall_s: f64 },
    Failed(String),
    Pending,
}

fn state(p: &Place, r: &RunSpec) -> State {
    let dir = p.run_dir(r);
    if let Ok(text) = std::fs::read_to_string(dir.join("result.json")) {
        if let Ok(o) = serde_json::from_str::<RunOutcome>(&text) {
            return State::Done(Box::new(o));
        }
    }
    if let Ok(text) = std::fs::read_to_string(dir.join("failed.txt")) {
        return State::Failed(text.lines().next().unwrap_or("").to_string());
    }
    let ck = dir.join("ckpt").join(crate::scene::checkpoint::FILE);
    if let Some((step, wall_s)) = checkpoint_progress(&ck) {
        return State::Resumable { step, wall_s };
    }
    State::Pending
}

/// The step and the wall time so far of a checkpoint file.
fn checkpoint_progress(path: &Path) -> Option<(i64, f64)> {
    #[derive(Deserialize)]
    struct Head {
        segments: Vec<crate::scene::checkpoint::Segment>,
    }
    let f = std::fs::File::open(path).ok()?;
    let mut text = String::new();
    flate2::read::GzDecoder::new(f).read_to_string(&mut text).ok()?;
    let h: Head = serde_json::from_str(&text).ok()?;
    let step = h.segments.last().map_or(0, |s| s.to_step);
    Some((step, h.segments.iter().map(|s| s.wall_s).sum()))
}

/// Entry point.
pub fn cli(args: Vec<String>) -> ExitCode {
    use clap::Parser;
    let cli = match Cli::try_parse_from(std::iter::once("demx campaign".to_string()).chain(args)) {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let p = match Place::load(&cli.file) {
        Ok(p) => p,
        Err(m) => {
            eprintln!("error: {m}");
            return ExitCode::from(2);
        }
    };
    if let Some(bad) = cli.only.iter().find(|n| !p.c.runs.iter().any(|r| &r.name == *n)) {
        eprintln!("error: --only {bad}: the campaign {} declares no such run", cli.file.display());
        return ExitCode::from(2);
    }
    if cli.slurm.slurm {
        return submit_slurm(&p, &cli);
    }
    if cli.stop {
        return match std::fs::write(p.dir.join("STOP"), "") {
            Ok(()) => {
                println!("asked the campaign in {} to stop at its runs' next checkpoints", p.dir.display());
                match super::slurm::jobs(&p.dir).and_then(|j| if j.is_empty() { Ok(0) } else { super::slurm::stop(&p.dir) }) {
                    Ok(0) => {}
                    Ok(n) => println!("and Slurm to stop its {n} live tasks (running ones checkpoint and stop, pending ones are cancelled)"),
                    Err(e) => eprintln!("warning: Slurm: {e}"),
                }
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: cannot write {}: {e}", p.dir.join("STOP").display());
                ExitCode::from(1)
            }
        };
    }
    if cli.status {
        print_status(&p, &[]);
        return ExitCode::SUCCESS;
    }
    run(&p, &cli)
}

/// The runs Slurm holds for this campaign (empty without submissions).
fn queued(p: &Place) -> Result<BTreeMap<String, String>, String> {
    let jobs = super::slurm::jobs(&p.dir)?;
    if jobs.is_empty() {
        return Ok(BTreeMap::new());
    }
    super::slurm::alive(&jobs)
}

/// The campaign's table: a line per run (only the runs of `only`, where
/// given: a Slurm task's output names its own run, not the whole campaign)
/// and the totals.
fn print_status(p: &Place, only: &[String]) {
    let (mut done, mut partial, mut pending, mut failed) = (0, 0, 0, 0);
    let mut left = 0.0;
    let slurm = queued(p).unwrap_or_else(|e| {
        eprintln!("warning: Slurm: {e}");
        BTreeMap::new()
    });
    for r in &p.c.runs {
        let shown = only.is_empty() || only.contains(&r.name);
        // a line of the table, for the runs shown
        let line = |text: String| {
            if shown {
                println!("{:<28} {text}", r.name);
            }
        };
        if let Some(task) = slurm.get(&r.name) {
            line(format!("slurm task {task}"));
        }
        match state(p, r) {
            State::Done(o) => {
                done += 1;
                let th = o.theta_deg.map_or(String::new(), |t| format!("theta_r {t:.2} ± {:.2}°  ", o.theta_sd_deg.unwrap_or(f64::NAN)));
                let phi = o.phi.map_or(String::new(), |f| format!("phi {f:.4}  "));
                line(format!("done       {th}{phi}{:.2} core-h", o.core_hours));
            }
            State::Resumable { step, wall_s } => {
                partial += 1;
                left += (r.estimate_core_h - wall_s / 3600.0).max(0.0);
                line(format!("resumable  at step {step}, {:.2} core-h spent of ~{:.1}", wall_s / 3600.0, r.estimate_core_h));
            }
            State::Failed(m) => {
                failed += 1;
                line(format!("FAILED     {m}"));
            }
            State::Pending => {
                pending += 1;
                left += r.estimate_core_h;
                line(format!("pending    ~{:.1} core-h", r.estimate_core_h));
            }
        }
    }
    println!("{done} done, {partial} resumable, {pending} pending, {failed} failed; about {left:.1} core-hours left");
}

/// SIGTERM or the campaign's STOP file.
fn stop_asked(p: &Place) -> bool {
    crate::scene::checkpoint::term_received() || p.dir.join("STOP").exists()
}

/// The campaign's lock: the pid of the runner that holds it.
const LOCK: &str = "runner.pid";

/// This machine's name, for the locks (a pid means nothing on another node).
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname").map(|h| h.trim().to_string()).unwrap_or_default()
}

/// Whether another live runner on this machine holds the lock file `path`
/// (`HOST PID`; an old lock holds only a pid). A lock written on another
/// machine is not taken for held: under Slurm the queue, not the lock,
/// keeps a run from starting twice, and a lost node leaves such locks.
fn held_by_other(path: &Path) -> Option<i32> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut w = text.split_whitespace().rev();
    let pid: i32 = w.next()?.parse().ok()?;
    if w.next().is_some_and(|h| h != host()) {
        return None;
    }
    // SAFETY: signal 0 only asks whether the process exists
    let alive = pid > 0 && pid != std::process::id() as i32 && unsafe { libc::kill(pid, 0) } == 0;
    alive.then_some(pid)
}

fn run(p: &Place, cli: &Cli) -> ExitCode {
    if let Some(pid) = held_by_other(&p.dir.join(LOCK)) {
        eprintln!("error: the campaign in {} is already running (runner pid {pid}); `--stop` stops it", p.dir.display());
        return ExitCode::from(2);
    }
    // the whole campaign, or (--only) just its named runs
    let locks: Vec<PathBuf> = if cli.only.is_empty() {
        vec![p.dir.join(LOCK)]
    } else {
        p.c.runs.iter().filter(|r| cli.only.contains(&r.name)).map(|r| p.run_dir(r).join(LOCK)).collect()
    };
    for l in &locks {
        if let Some(pid) = held_by_other(l) {
            eprintln!("error: {} is held by runner pid {pid}", l.display());
            return ExitCode::from(2);
        }
    }
    let me = format!("{} {}\n", host(), std::process::id());
    for l in &locks {
        if let Err(e) = l.parent().map_or(Ok(()), std::fs::create_dir_all).and_then(|_| std::fs::write(l, &me)) {
            eprintln!("error: cannot write {}: {e}", l.display());
            return ExitCode::from(1);
        }
    }
    let code = run_locked(p, cli);
    for l in &locks {
        let _ = std::fs::remove_file(l);
    }
    code
}

/// `--slurm`: the unfinished runs Slurm does not already hold, as one job array.
fn submit_slurm(p: &Place, cli: &Cli) -> ExitCode {
    let live = match queued(p) {
        Ok(q) => q,
        Err(e) if cli.slurm.dry_run => {
            eprintln!("warning: Slurm: {e}");
            BTreeMap::new()
        }
        Err(e) => {
            eprintln!("error: Slurm: {e}");
            return ExitCode::from(1);
        }
    };
    let mut tasks = vec![];
    for r in &p.c.runs {
        if live.contains_key(&r.name) || (!cli.only.is_empty() && !cli.only.contains(&r.name)) {
            continue;
        }
        let remaining_h = match state(p, r) {
            State::Pending => r.estimate_core_h,
            State::Resumable { wall_s, .. } => (r.estimate_core_h - wall_s / 3600.0).max(0.0),
            State::Done(_) | State::Failed(_) => continue,
        };
        tasks.push(super::slurm::Task { name: r.name.clone(), remaining_h });
    }
    if tasks.is_empty() {
        println!("nothing to submit: {} runs queued or running in Slurm, the others done or failed (`--status`)", live.len());
        return ExitCode::SUCCESS;
    }
    // a stop asked earlier is over once the runs are handed out again
    let _ = std::fs::remove_file(p.dir.join("STOP"));
    match super::slurm::submit(&cli.slurm, &cli.file, &tasks) {
        Ok((path, None)) => {
            print!("{}", std::fs::read_to_string(&path).unwrap_or_default());
            println!("# job script written to {} ({} tasks); not submitted (--dry-run)", path.display(), tasks.len());
            ExitCode::SUCCESS
        }
        Ok((path, Some(id))) => {
            println!(
                "submitted Slurm job {id}: {} tasks ({}), script {}; `demx campaign {} --status` follows them",
                tasks.len(),
                tasks.iter().map(|t| t.name.as_str()).collect::<Vec<_>>().join(", "),
                path.display(),
                cli.file.display()
            );
            ExitCode::SUCCESS
        }
        Err((code, e)) => {
            eprintln!("error: {e}");
            ExitCode::from(code)
        }
    }
}

fn run_locked(p: &Place, cli: &Cli) -> ExitCode {
    crate::scene::checkpoint::catch_term();
    // a task of --only leaves the campaign's stop request to the others
    let whole = cli.only.is_empty();
    if whole {
        let _ = std::fs::remove_file(p.dir.join("STOP"));
    }
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: cannot find the demx executable: {e}");
            return ExitCode::from(1);
        }
    };
    for r in &p.c.runs {
        if let Err(e) = p.deck(r).canonicalize() {
            eprintln!("error: deck {} of run {}: {e}", p.deck(r).display(), r.name);
            return ExitCode::from(2);
        }
    }
    let mut queue: Vec<&RunSpec> =
        p.c.runs
            .iter()
            .filter(|r| whole || cli.only.contains(&r.name))
            .filter(|r| matches!(state(p, r), State::Resumable { .. } | State::Pending))
            // a run another (--only) runner holds here
            .filter(|r| held_by_other(&p.run_dir(r).join(LOCK)).is_none())
            .collect();
    // unfinished runs first: their checkpoints are what a stop carries over
    queue.sort_by_key(|r| !matches!(state(p, r), State::Resumable { .. }));
    queue.truncate(cli.max_runs.unwrap_or(usize::MAX));
    let mut running: Vec<(&RunSpec, std::process::Child, Instant)> = vec![];
    let mut failures = 0;
    let mut stopping = false;
    loop {
        if !stopping && stop_asked(p) {
            stopping = true;
            for (r, _, _) in &running {
                // the folder exists only from the run's first checkpoint on
                let ckpt = p.run_dir(r).join("ckpt");
                if let Err(e) = std::fs::create_dir_all(&ckpt).and_then(|_| std::fs::write(ckpt.join("STOP"), "")) {
                    eprintln!("campaign: {}: cannot ask it to stop: {e}", r.name);
                }
            }
            println!("campaign: stopping; each run stops at its next checkpoint");
        }
        while !stopping && running.len() < cli.jobs.max(1) && !queue.is_empty() {
            let r = queue.remove(0);
            match start(p, r, &exe, &cli.run_arg) {
                Ok(child) => {
                    println!("campaign: {} started", r.name);
                    running.push((r, child, Instant::now()));
                }
                Err(m) => {
                    eprintln!("campaign: {}: {m}", r.name);
                    failures += 1;
                }
            }
        }
        if running.is_empty() {
            break;
        }
        std::thread::sleep(Duration::from_millis(200));
        let mut k = 0;
        while k < running.len() {
            let exited = running[k].1.try_wait();
            match exited {
                Ok(None) => k += 1,
                Ok(Some(status)) => {
                    let (r, _, t0) = running.remove(k);
                    let dir = p.run_dir(r);
                    let _ = std::fs::remove_file(dir.join("ckpt").join("STOP"));
                    match status.code() {
                        Some(0) => match finish(p, r) {
                            Ok(o) => println!(
                                "campaign: {} done in {:.0} s: {}",
                                r.name,
                                t0.elapsed().as_secs_f64(),
                                o.theta_deg.map_or(String::new(), |t| format!("theta_r {t:.2}°"))
                            ),
                            Err(m) => {
                                failures += 1;
                                let _ = std::fs::write(dir.join("failed.txt"), &m);
                                eprintln!("campaign: {}: {m}", r.name);
                            }
                        },
                        Some(c) if c == crate::scene::checkpoint::STOPPED as i32 => println!("campaign: {} stopped at a checkpoint", r.name),
                        _ => {
                            failures += 1;
                            let m = format!("demx run exited with {status} (see {})", dir.join("work").join("log.demx").display());
                            let _ = std::fs::write(dir.join("failed.txt"), &m);
                            eprintln!("campaign: {}: {m}", r.name);
                        }
                    }
                }
                Err(e) => {
                    eprintln!("campaign: {}: {e}", running[k].0.name);
                    k += 1;
                }
            }
        }
    }
    if whole {
        let _ = std::fs::remove_file(p.dir.join("STOP"));
    }
    print_status(p, &cli.only);
    if failures > 0 {
        ExitCode::from(1)
    } else if stopping {
        ExitCode::from(crate::scene::checkpoint::STOPPED)
    } else {
        ExitCode::SUCCESS
    }
}

/// Start (or continue) one run.
fn start(p: &Place, r: &RunSpec, exe: &Path, extra: &[String]) -> Result<std::process::Child, String> {
    let deck = p.deck(r).canonicalize().map_err(|e| format!("deck {}: {e}", p.deck(r).display()))?;
    let dir = p.run_dir(r);
    let work = dir.join("work");
    std::fs::create_dir_all(&work).map_err(|e| format!("cannot create {}: {e}", work.display()))?;
    let ckpt = dir.join("ckpt").canonicalize().unwrap_or_else(|_| std::env::current_dir().unwrap_or_default().join(dir.join("ckpt")));
    let mut cmd = std::process::Command::new(exe);
    cmd.current_dir(&work).arg("run").arg(deck).args(["--threads", "1", "--quiet", "--log", "log.demx"]);
    cmd.arg("--checkpoint").arg(&ckpt).arg("--checkpoint-every").arg(p.c.checkpoint_every_s.to_string());
    cmd.args(extra);
    for (k, v) in p.vars(r) {
        cmd.arg("-var").arg(k).arg(v);
    }
    cmd.stdout(std::process::Stdio::null()).stderr(std::fs::File::create(work.join("stderr.txt")).map_err(|e| e.to_string())?);
    cmd.spawn().map_err(|e| format!("cannot start demx run: {e}"))
}

/// Measure a finished run, keep its result and last frame, remove its
/// checkpoint and working files.
fn finish(p: &Place, r: &RunSpec) -> Result<RunOutcome, String> {
    let dir = p.run_dir(r);
    let work = dir.join("work");
    let dump = work.join(p.dump(r));
    let frame = pick_frame(&dump.to_string_lossy(), None).map_err(|e| format!("{}: {e}", dump.display()))?;
    let (mut theta, mut sd, mut phi) = (None, None, None);
    if matches!(p.measure(r), "repose" | "both") {
        let rep = repose(&frame).map_err(|e| format!("{}: {e}", dump.display()))?;
        theta = Some(rep.theta);
        sd = Some(rep.sd);
    }
    if matches!(p.measure(r), "packing" | "both") {
        phi = Some(super::packing::packing(&frame).map_err(|e| format!("{}: {e}", dump.display()))?.phi);
    }
    let segs_path = dir.join("ckpt").join("segments.json");
    let segments: Vec<crate::scene::checkpoint::Segment> = std::fs::read_to_string(&segs_path)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .ok_or_else(|| format!("{} is missing", segs_path.display()))?;
    let wall_s: f64 = segments.iter().map(|s| s.wall_s).sum();
    // counted by each stretch where its checkpoints carry the count (the log
    // of a stretch on another machine is not here); else the log's runs
    let particle_steps = match segments.iter().map(|s| s.particle_steps).collect::<Option<Vec<f64>>>() {
        Some(each) => each.iter().sum(),
        None => particle_steps(&std::fs::read_to_string(work.join("log.demx")).unwrap_or_default()),
    };
    let o = RunOutcome {
        name: r.name.clone(),
        vars: p.vars(r),
        theta_deg: theta,
        theta_sd_deg: sd,
        phi,
        particles: frame.natoms,
        particle_steps,
        wall_s,
        core_hours: segments.iter().map(|s| s.wall_s * s.threads as f64).sum::<f64>() / 3600.0,
        segments,
        finished_unix: std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()),
    };
    // the last frame, gzipped
    let frame_text = last_frame_text(&dump).map_err(|e| format!("{}: {e}", dump.display()))?;
    let gz = std::fs::File::create(dir.join("final.dump.gz")).map_err(|e| e.to_string())?;
    let mut enc = flate2::write::GzEncoder::new(gz, flate2::Compression::best());
    std::io::Write::write_all(&mut enc, frame_text.as_bytes()).map_err(|e| e.to_string())?;
    enc.finish().map_err(|e| e.to_string())?;
    let text = serde_json::to_string_pretty(&o).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("result.json"), text + "\n").map_err(|e| e.to_string())?;
    let _ = std::fs::remove_dir_all(dir.join("ckpt"));
    let _ = std::fs::remove_dir_all(&work);
    Ok(o)
}

/// Sum of steps x atoms over the log's "Loop time ... for N steps with M
/// atoms" lines.
pub fn particle_steps(log: &str) -> f64 {
    log.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("Loop time of ")?;
            let w: Vec<&str> = rest.split_whitespace().collect();
            let k = w.iter().position(|x| *x == "steps")?;
            let n: f64 = w.get(k.checked_sub(1)?)?.parse().ok()?;
            let m: f64 = w.get(k + 2)?.parse().ok()?;
            Some(n * m)
        })
        .sum()
}

/// The text of a dump's last frame.
fn last_frame_text(path: &Path) -> std::io::Result<String> {
    let text = std::fs::read_to_string(path)?;
    let start = text.rfind("ITEM: TIMESTEP").ok_or_else(|| std::io::Error::other("no frame"))?;
    Ok(text[start..].to_string())
}
