//! Checkpoints of a whole run (`demx run DECK --checkpoint DIR`): a run
//! stopped at any time, on any machine, continues from its last checkpoint
//! bit for bit as if it had never stopped.
//!
//! A checkpoint is taken before one of the deck's own `run` lines (not one
//! inside `if` or `run every`), once `--checkpoint-every` seconds have
//! passed since the last one, or once a stop was asked for (SIGTERM, or a
//! file `DIR/STOP`); after a stop's checkpoint the run ends with exit code
//! [`STOPPED`]. There the state is complete, no command is half done, and
//! the checkpoint holds:
//!
//! - the interpreter: variables and the position in each open file
//!   ([`crate::script::interp::SavedInterpreter`]);
//! - the journal: every command the deck gave the scene so far, in order,
//!   as executed (variables already substituted);
//! - the simulation as a restart file holds it (particles with their wall
//!   histories, the pair list with its histories, step, time, box);
//! - each fix's changing state ([`crate::engine::fix::Fix::save_state`]:
//!   insertion generators and counters, ...) and each dump file's length.
//!
//! Resuming builds the scene again by replaying the journal with the runs
//! recorded but not integrated (as `demx check` does: nothing is written),
//! puts the simulation and the fixes' states back, cuts each dump file back
//! to its length, and runs the deck on from the saved line. A fix or dump
//! whose state a checkpoint cannot keep yet stops checkpoints while it
//! exists (said once in the log), never a resume that would differ.
//!
//! The file is `DIR/checkpoint.json.gz`, written to a temporary file and
//! renamed; a finished run removes it.

use super::restart::RestartState;
use super::Session;
use crate::engine::fix::FixState;
use crate::engine::output::DumpFile;
use crate::error::{Error, Result};
use crate::script::interp::SavedInterpreter;
use crate::script::{Command, Span, Variables, Word};
use serde::{Deserialize, Serialize};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

const FORMAT: &str = "demx-checkpoint-1";

/// Exit code of a run that stopped at a checkpoint when asked to (the
/// BSD sysexits EX_TEMPFAIL: run the same command again to continue).
pub const STOPPED: u8 = 75;

/// The checkpoint's file name inside its directory.
pub const FILE: &str = "checkpoint.json.gz";

/// SIGTERM was received.
static TERM: AtomicBool = AtomicBool::new(false);

extern "C" fn on_term(_sig: libc::c_int) {
    TERM.store(true, Ordering::SeqCst);
}

/// Catch SIGTERM from now on: it asks for a stop at the next checkpoint
/// instead of ending the process.
pub fn catch_term() {
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        libc::signal(libc::SIGTERM, on_term as *const () as libc::sighandler_t);
    }
}

/// Whether SIGTERM was received since [`catch_term`].
pub fn term_received() -> bool {
    TERM.load(Ordering::SeqCst)
}

/// One stretch of a run between two starts of the process.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Segment {
    /// The demx binary that ran it (version and build).
    pub demx: String,
    /// First and last step of the stretch.
    pub from_step: i64,
    /// Step at its end (the checkpoint's step, or the run's last).
    pub to_step: i64,
    /// Wall-clock seconds it took.
    pub wall_s: f64,
    /// Threads it ran on.
    pub threads: usize,
    /// Particle-steps it integrated ([`crate::engine::sim::Sim::particle_steps`];
    /// none in checkpoints from before this field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub particle_steps: Option<f64>,
}

/// A checkpoint file.
#[derive(Serialize, Deserialize)]
struct Saved {
    format: String,
    interp: SavedInterpreter,
    journal: Vec<Vec<(String, bool)>>,
    sim: RestartState,
    fixes: Vec<(String, String, serde_json::Value)>,
    dumps: Vec<SavedDump>,
    segments: Vec<Segment>,
    /// The log file (absolute path) and its length at the checkpoint: a
    /// resumed run cuts it back there, as it does the dumps, so that lines the
    /// stopped stretch wrote after the checkpoint (a run's "Loop time" line
    /// among them) are not there twice. Checkpoints from before this field
    /// have none and leave the log as it is.
    #[serde(default)]
    log: Option<(PathBuf, u64)>,
}

/// A dump at a checkpoint: its id, its file and length when the resumed run
/// appends to it, and the step of its last frame.
#[derive(Serialize, Deserialize)]
struct SavedDump {
    id: String,
    file: Option<(PathBuf, u64)>,
    last_step: Option<i64>,
}

/// What a checkpoint resumes: read by [`Checkpoints::load`], used by
/// [`resume`].
pub struct Resume {
    saved: Saved,
}

impl Resume {
    /// The interpreter's state to continue from.
    pub fn interp(&self) -> &SavedInterpreter {
        &self.saved.interp
    }
    /// The step of the checkpoint.
    pub fn step(&self) -> i64 {
        self.saved.sim.step()
    }
}

/// `demx run --checkpoint DIR --checkpoint-every S`.
pub struct Checkpoints {
    /// The directory.
    pub dir: PathBuf,
    /// Wall time between checkpoints.
    pub every: Duration,
    /// When the last checkpoint was written (or the run started).
    last: Instant,
    /// When this process started its stretch, and at which step.
    started: (Instant, i64),
    /// The stretches of earlier processes.
    pub segments: Vec<Segment>,
    /// Stop after this many checkpoints (tests: a stop at a known place).
    pub stop_after: Option<u32>,
    written: u32,
    /// A fix or dump prevented a checkpoint: said once.
    told: bool,
    /// The run stopped at a checkpoint (asked to).
    pub stopped: bool,
    /// Commands executed when the last checkpoint was written or read: the
    /// next one needs progress since (a resumed run does not stop again at
    /// the line it resumed from).
    journal_at: usize,
}

impl Checkpoints {
    /// Checkpoints into `dir` every `every`; catches SIGTERM from now on.
    pub fn new(dir: PathBuf, every: Duration) -> Checkpoints {
        catch_term();
        let now = Instant::now();
        Checkpoints {
            dir,
            every,
            last: now,
            started: (now, 0),
            segments: vec![],
            stop_after: None,
            written: 0,
            told: false,
            stopped: false,
            journal_at: 0,
        }
    }

    /// The checkpoint file.
    pub fn file(&self) -> PathBuf {
        self.dir.join(FILE)
    }

    /// The run finished: remove the checkpoint, keep the stretches in
    /// `DIR/segments.json` (which binary ran which steps, how long).
    pub fn finish(&self, step: i64, threads: usize, particle_steps: f64) -> std::io::Result<()> {
        std::fs::create_dir_all(&self.dir)?;
        let text = serde_json::to_string_pretty(&self.all_segments(step, threads, particle_steps)).map_err(std::io::Error::other)?;
        std::fs::write(self.dir.join("segments.json"), text + "\n")?;
        match std::fs::remove_file(self.file()) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        }
    }

    /// Read the directory's checkpoint, if there is one.
    pub fn load(&mut self) -> Result<Option<Resume>> {
        let path = self.file();
        if !path.exists() {
            return Ok(None);
        }
        let bad = |m: String| Error::io(Span::DUMMY, format!("cannot read checkpoint '{}'", path.display()), &std::io::Error::other(m));
        let f = std::fs::File::open(&path).map_err(|e| bad(e.to_string()))?;
        let mut text = String::new();
        flate2::read::GzDecoder::new(f).read_to_string(&mut text).map_err(|e| bad(e.to_string()))?;
        let saved: Saved = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if saved.format != FORMAT {
            return Err(bad(format!("format '{}' (expected {FORMAT})", saved.format)));
        }
        self.segments = saved.segments.clone();
        self.started = (Instant::now(), saved.sim.step());
        Ok(Some(Resume { saved }))
    }

    /// Whether a stop was asked for from outside: SIGTERM, or the file `DIR/STOP`.
    fn stop_requested(&self) -> bool {
        TERM.load(Ordering::SeqCst) || self.dir.join("STOP").exists()
    }

    /// [`Checkpoints::stop_requested`], or the tests' stop after K checkpoints.
    fn stop_asked(&self) -> bool {
        self.stop_requested() || self.stop_after.is_some_and(|k| self.written + 1 >= k)
    }

    /// Whether the next `run` line should be preceded by a checkpoint, after
    /// `journal` commands.
    pub fn due(&self, journal: usize) -> bool {
        journal > self.journal_at && (self.stop_asked() || self.last.elapsed() >= self.every || self.stop_after.is_some())
    }

    /// The stretches so far, this process's included (up to `step`).
    pub fn all_segments(&self, step: i64, threads: usize, particle_steps: f64) -> Vec<Segment> {
        let mut v = self.segments.clone();
        v.push(Segment {
            demx: build_id(),
            from_step: self.started.1,
            to_step: step,
            wall_s: self.started.0.elapsed().as_secs_f64(),
            threads,
            particle_steps: Some(particle_steps),
        });
        v
    }
}

/// This binary: the package version and the build's git commit where the
/// build knew it.
pub fn build_id() -> String {
    format!("demx {} ({})", env!("CARGO_PKG_VERSION"), option_env!("DEMX_GIT").unwrap_or("unknown commit"))
}

/// The checkpoint before a `run` line (the interpreter's `saved`). Returns
/// whether the run is to stop there.
pub fn write(s: &mut Session, saved: &SavedInterpreter) -> Result<bool> {
    let Some(cp) = s.checkpoints.as_ref() else {
        return Ok(false);
    };
    let stop = cp.stop_asked();
    // every fix and dump must be able to go on from what is saved
    let mut fixes = vec![];
    let mut blocker = None;
    for f in &s.sim.fixes {
        match f.save_state() {
            FixState::Stateless => fixes.push((f.id().to_string(), f.style().to_string(), serde_json::Value::Null)),
            FixState::Saved(v) => fixes.push((f.id().to_string(), f.style().to_string(), v)),
            FixState::Unsupported => {
                blocker = Some(format!("fix {} ({})", f.id(), f.style()));
                break;
            }
        }
    }
    let mut dumps = vec![];
    for d in &s.sim.dumps {
        match d.checkpoint_file() {
            DumpFile::Fresh => dumps.push(SavedDump { id: d.id().to_string(), file: None, last_step: d.last_step() }),
            DumpFile::Appended(p) => {
                let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
                dumps.push(SavedDump { id: d.id().to_string(), file: Some((p, len)), last_step: d.last_step() });
            }
            DumpFile::Unsupported => blocker = blocker.or(Some(format!("dump {}", d.id()))),
        }
    }
    if let Some(what) = blocker {
        let cp = s.checkpoints.as_mut().expect("checked above");
        cp.last = Instant::now();
        if cp.stop_requested() {
            // asked to stop: stop, leaving the last checkpoint (if any) to continue from
            cp.stopped = true;
            s.sim.log.line(&format!(
                "demx: stopping at step {} without a new checkpoint ({what} keeps state a checkpoint cannot carry yet); the last checkpoint stays",
                s.sim.step
            ));
            return Ok(true);
        }
        if !cp.told {
            cp.told = true;
            s.sim.log.line(&format!(
                "demx: no checkpoint at step {}: {what} keeps state a checkpoint cannot carry yet; trying again at later runs",
                s.sim.step
            ));
        }
        return Ok(false);
    }
    let threads = s.threads;
    let log = log_at_checkpoint(s);
    let cp = s.checkpoints.as_mut().expect("checked above");
    let segments = cp.all_segments(s.sim.step, threads, s.sim.particle_steps);
    let saved = Saved {
        format: FORMAT.into(),
        interp: saved.clone(),
        journal: s.journal.clone(),
        sim: RestartState::of(&s.sim, s.replay.clone())?,
        fixes,
        dumps,
        segments,
        log,
    };
    std::fs::create_dir_all(&cp.dir).map_err(|e| Error::io(Span::DUMMY, format!("cannot create '{}'", cp.dir.display()), &e))?;
    let path = cp.file();
    write_gz(&path, &saved).map_err(|e| Error::io(Span::DUMMY, format!("cannot write checkpoint '{}'", path.display()), &e))?;
    cp.written += 1;
    cp.last = Instant::now();
    cp.journal_at = s.journal.len();
    cp.stopped = stop;
    s.sim.log.line(&format!("demx: checkpoint at step {} written to {}", s.sim.step, path.display()));
    Ok(stop)
}

/// The log file and its length now, where there is one.
fn log_at_checkpoint(s: &Session) -> Option<(PathBuf, u64)> {
    let len = s.sim.log.file.as_ref()?.metadata().ok()?.len();
    Some((s.sim.log.path.as_ref()?.canonicalize().ok()?, len))
}

/// Serialize, gzip and write atomically (temporary file beside, renamed).
fn write_gz(path: &Path, saved: &Saved) -> std::io::Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    {
        let mut gz = flate2::write::GzEncoder::new(std::io::BufWriter::new(tmp.as_file_mut()), flate2::Compression::default());
        serde_json::to_writer(&mut gz, saved).map_err(std::io::Error::other)?;
        gz.finish()?.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Build the scene again from a checkpoint (see the module's text); the
/// interpreter then continues from [`Resume::interp`].
pub fn resume(s: &mut Session, r: Resume) -> Result<SavedInterpreter> {
    let bad = |m: String| Error::runtime(format!("checkpoint does not fit this deck: {m}"));
    let step = r.step();
    let saved = r.saved;
    let mut vars = Variables::restore(&saved.interp.vars).map_err(bad)?;
    // the journal, runs recorded but not integrated, nothing written
    let dry = s.sim.dry;
    s.sim.dry = true;
    s.replaying = true;
    let screen = std::mem::replace(&mut s.sim.log.screen, false);
    let log = s.sim.log.file.take();
    let mut result = Ok(());
    for words in &saved.journal {
        let cmd = Command { words: words.iter().map(|(t, q)| Word { text: t.clone(), span: Span::DUMMY, quoted: *q }).collect(), span: Span::DUMMY };
        if let Err(e) = crate::script::Host::execute(s, &cmd, &mut vars) {
            result = Err(bad(format!("replaying '{}': {e:?}", cmd.text())));
            break;
        }
    }
    s.replaying = false;
    s.sim.dry = dry;
    s.sim.log.screen = screen;
    s.sim.log.file = log;
    result?;
    s.journal = saved.journal;
    if let Some(cp) = s.checkpoints.as_mut() {
        cp.journal_at = s.journal.len();
    }
    // the simulation
    saved.sim.apply(&mut s.sim).map_err(bad)?;
    // a run line comes next: its setup runs as in the uninterrupted run
    s.sim.resume = false;
    // the fixes
    if s.sim.fixes.len() != saved.fixes.len() {
        return Err(bad(format!("{} fixes after the replay, {} at the checkpoint", s.sim.fixes.len(), saved.fixes.len())));
    }
    for (f, (id, style, state)) in s.sim.fixes.iter_mut().zip(&saved.fixes) {
        if f.id() != id || f.style() != style {
            return Err(bad(format!("fix {} ({}) where the checkpoint has fix {id} ({style})", f.id(), f.style())));
        }
        if !state.is_null() {
            f.load_state(state).map_err(|m| bad(format!("fix {id}: {m}")))?;
        }
    }
    // the dump files, cut back to the checkpoint and appended to
    if s.sim.dumps.len() != saved.dumps.len() {
        return Err(bad(format!("{} dumps after the replay, {} at the checkpoint", s.sim.dumps.len(), saved.dumps.len())));
    }
    for (d, SavedDump { id, file, last_step: last }) in s.sim.dumps.iter_mut().zip(&saved.dumps) {
        if d.id() != id {
            return Err(bad(format!("dump {} where the checkpoint has dump {id}", d.id())));
        }
        if let Some((path, len)) = file {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(|e| Error::io(Span::DUMMY, format!("cannot reopen dump '{}', which the checkpoint continues", path.display()), &e))?;
            f.set_len(*len).map_err(|e| Error::io(Span::DUMMY, format!("cannot cut dump '{}' back", path.display()), &e))?;
        }
        d.resume_at(*last, file.is_some());
    }
    // the log, cut back where it is the file the checkpoint measured
    let mut cut = String::new();
    if let (Some((path, len)), Some(now)) = (&saved.log, log_at_checkpoint(s)) {
        if *path == now.0 && now.1 >= *len {
            if let Some(f) = &s.sim.log.file {
                f.set_len(*len).map_err(|e| Error::io(Span::DUMMY, format!("cannot cut log '{}' back", path.display()), &e))?;
                if now.1 > *len {
                    cut = format!(" (the {} bytes the stopped stretch logged after it were cut)", now.1 - len);
                }
            }
        }
    }
    s.sim.log.line(&format!("demx: resumed from the checkpoint at step {step}{cut}"));
    Ok(saved.interp)
}
