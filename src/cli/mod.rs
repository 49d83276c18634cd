//! The command line: `demx run`, `demx check`, `demx dump info`, and the
//! later subcommands. Parses arguments, runs, and maps the result to an exit
//! code in one place.

use crate::error::{Error, Result};
use crate::scene::{summary::Summary, Session};
use crate::script::{Interpreter, SourceMap};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// demx: DEM engine and validator for LIGGGHTS/LAMMPS granular decks.
#[derive(Parser, Debug)]
#[command(name = "demx", version, about)]
pub struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

/// Variables and deck shared by run and check.
#[derive(Args, Debug, Clone)]
pub struct DeckArgs {
    /// The deck (input script).
    pub deck: PathBuf,
    /// `-var NAME VALUE ...` (also `-v`), as LAMMPS takes them; may repeat.
    #[arg(long = "var", short = 'v', num_args = 2.., value_names = ["NAME", "VALUE"], allow_hyphen_values = true)]
    pub var: Vec<String>,
    /// Ensemble member of a chaotic scene: before the first run, move every
    /// particle by AMP of its radius in a direction drawn from SEED and its id
    /// (`SEED:AMP`, e.g. `1:1e-6`).
    #[arg(long, value_name = "SEED:AMP", value_parser = parse_perturb)]
    pub perturb: Option<(u64, f64)>,
    /// Grouped `-var` values (filled from the raw arguments).
    #[arg(skip)]
    pub var_groups: Vec<Vec<String>>,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Run a deck natively.
    Run {
        #[command(flatten)]
        deck: DeckArgs,
        /// Worker threads (results are bitwise identical for any count).
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Log file (`none` for no log), as LAMMPS `-log`.
        #[arg(long = "log", default_value = "log.demx")]
        log: String,
        /// No thermo output on the screen.
        #[arg(long)]
        quiet: bool,
        /// Run at most this many steps per `run` command (smoke tests).
        #[arg(long)]
        max_steps: Option<i64>,
        /// Time step as this fraction of the Hertz collision time (as `demx
        /// check` reports it), replacing the deck's `timestep` (applied at the
        /// `timestep` command, or at the first run if the particles are not
        /// known yet). Run lengths stay the deck's step counts.
        #[arg(long, value_name = "F")]
        dt_fraction: Option<f64>,
        /// Divide every stiffness (Young's and shear moduli, kn, kt; pairs and
        /// walls) by S: softer particles allow longer time steps.
        #[arg(long, value_name = "S")]
        youngs_scale: Option<f64>,
        /// Keep a checkpoint of the whole run in DIR (before a `run` line of
        /// the deck, every --checkpoint-every seconds, and when SIGTERM or a
        /// file DIR/STOP asks the run to stop, which then exits with code
        /// 75). The same command continues from DIR's checkpoint, bit for
        /// bit as if the run had not stopped; a finished run removes it.
        #[arg(long, value_name = "DIR")]
        checkpoint: Option<std::path::PathBuf>,
        /// Seconds of wall time between checkpoints.
        #[arg(long, value_name = "S", default_value_t = 600.0)]
        checkpoint_every: f64,
        /// Stop after this many checkpoints (tests).
        #[arg(long, hide = true)]
        checkpoint_stop_after: Option<u32>,
    },
    /// Read and validate a deck without running it; print a summary.
    Check {
        #[command(flatten)]
        deck: DeckArgs,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        /// Check only the script language (variables, loops, includes,
        /// conditionals): every other command is accepted unexecuted and
        /// thermo values read as 0.
        #[arg(long)]
        script_only: bool,
    },
    /// Dump file tools.
    Dump {
        #[command(subcommand)]
        what: DumpCmd,
    },
    /// Compare runs: dumps, output folders, or a deck against an engine.
    #[command(disable_help_flag = true)]
    Compare(Passthrough),
    /// Run the real LIGGGHTS/LAMMPS on a deck and collect full-precision results.
    #[command(disable_help_flag = true)]
    Reference(Passthrough),
    /// Convert legacy decks and translate between LIGGGHTS and LAMMPS.
    #[command(disable_help_flag = true)]
    Convert(Passthrough),
    /// Angle of repose of a heap, the paper's way.
    #[command(disable_help_flag = true)]
    Repose(Passthrough),
    /// Packing fraction of a settled column, the paper's way.
    #[command(disable_help_flag = true)]
    Packing(Passthrough),
    /// Aeolian transport measurements over a run's outputs.
    #[command(disable_help_flag = true)]
    Saltation(Passthrough),
    /// What accuracy costs in time: run a deck over settings.
    #[command(disable_help_flag = true)]
    Tradeoff(Passthrough),
    /// Angle of repose over particle size and gravity: runs and the paper's fits.
    #[command(disable_help_flag = true)]
    Sweep(Passthrough),
    /// A declared matrix of runs that survives stops and moves with the repository.
    #[command(disable_help_flag = true)]
    Campaign(Passthrough),
}

/// Arguments handed unparsed to a subcommand's own parser.
#[derive(Args, Debug)]
pub struct Passthrough {
    /// Arguments of the subcommand (see `demx SUBCOMMAND --help`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
    args: Vec<String>,
}

#[derive(Subcommand, Debug)]
enum DumpCmd {
    /// List frames, atoms and columns of a dump file.
    Info {
        /// The dump file (plain or gzip).
        file: PathBuf,
    },
}

fn parse_perturb(s: &str) -> std::result::Result<(u64, f64), String> {
    let (a, b) = s.split_once(':').ok_or("expected SEED:AMP, e.g. 1:1e-6")?;
    let seed = a.parse::<u64>().map_err(|e| format!("seed '{a}': {e}"))?;
    let amp = b.parse::<f64>().map_err(|e| format!("amplitude '{b}': {e}"))?;
    if !amp.is_finite() || amp < 0.0 {
        return Err(format!("amplitude '{b}' must be a finite number >= 0"));
    }
    Ok((seed, amp))
}

fn cli_vars(d: &DeckArgs) -> Vec<(String, Vec<String>)> {
    d.var_groups.iter().filter(|v| !v.is_empty()).map(|v| (v[0].clone(), v[1..].to_vec())).collect()
}

/// Pull every `-var NAME V1 V2 ...` / `-v ...` group out of the raw
/// arguments (values run until the next word starting with '-' that is not a
/// number), as LAMMPS parses them.
fn extract_vars(args: Vec<String>) -> (Vec<String>, Vec<Vec<String>>) {
    let mut rest = vec![];
    let mut groups = vec![];
    let mut k = 0;
    while k < args.len() {
        if k > 0 && matches!(args[k].as_str(), "-var" | "-v" | "--var") {
            let mut g = vec![];
            k += 1;
            while k < args.len() && (g.is_empty() || !args[k].starts_with('-') || args[k].parse::<f64>().is_ok()) {
                g.push(args[k].clone());
                k += 1;
            }
            groups.push(g);
        } else {
            rest.push(args[k].clone());
            k += 1;
        }
    }
    (rest, groups)
}

/// Translate LAMMPS-style single-dash options (`-var`, `-v`, `-log`, `-in`)
/// into clap's double-dash form, so `demx run in.x -var d 1e-3` works.
fn normalise_args(args: Vec<String>) -> Vec<String> {
    args.into_iter()
        .map(|a| match a.as_str() {
            "-var" => "--var".to_string(),
            "-log" => "--log".to_string(),
            "-in" => "--in".to_string(),
            _ => a,
        })
        .collect()
}

/// Run a deck in a session; returns the session (for summaries) or the error
/// with the source map to render it.
pub fn run_deck(
    deck: &DeckArgs,
    check: bool,
    threads: usize,
    log: Option<&str>,
    quiet: bool,
    max_steps: Option<i64>,
    overrides: crate::scene::overrides::Overrides,
    checkpoints: Option<crate::scene::checkpoint::Checkpoints>,
) -> (Session, SourceMap, Result<()>) {
    let sources = SourceMap::new();
    let mut session = Session::new(check);
    session.overrides = overrides;
    session.threads = threads;
    session.max_steps = max_steps;
    session.perturb = deck.perturb;
    // the deck's text, read once here for what is decided before it runs
    // (its dialect, whether it is a legacy deck); the run reads it again
    let text = std::fs::read_to_string(&deck.deck).ok();
    session.dialect_hint = text.as_deref().and_then(crate::scene::sniff_dialect);
    if check || quiet {
        session.sim.log.screen = false;
    }
    session.checkpoints = checkpoints;
    let resume = match session.checkpoints.as_mut().map(|c| c.load()).transpose() {
        Ok(r) => r.flatten(),
        Err(e) => return (session, sources, Err(e)),
    };
    if let Some(l) = log.filter(|l| *l != "none") {
        // a resumed run goes on writing the log it had
        if let Err(e) = session.sim.log.open(l, resume.is_some()) {
            return (session, sources, Err(Error::io(crate::script::Span::DUMMY, format!("cannot open log file '{l}'"), &e)));
        }
    }
    let mut interp = Interpreter::new(sources.clone(), cli_vars(deck));
    if check {
        interp.set_command_limit(2_000_000);
        // a check writes nothing, anywhere
        interp.set_file_writes(false);
    }
    if let Some(text) = text.filter(|t| crate::convert::is_legacy_liggghts(t)) {
        match legacy_in_memory(&sources, &deck.deck, &text) {
            Ok(converted) => {
                session.sim.log.line(&format!(
                    "note: {}: LIGGGHTS 1.x/2.x syntax; running it as `demx convert --to liggghts` rewrites it \
                     (error locations refer to that text)",
                    deck.deck.display()
                ));
                session.dialect_hint = crate::scene::sniff_dialect(&converted);
                interp.preload(&deck.deck, converted);
            }
            Err(e) => return (session, sources, Err(e)),
        }
    }
    let r = match resume {
        Some(resume) => match crate::scene::checkpoint::resume(&mut session, resume) {
            Ok(saved) => interp.resume(&saved, &deck.deck, &mut session),
            Err(e) => Err(e),
        },
        None => interp.run_file(&deck.deck, &mut session),
    };
    (session, sources, r)
}

/// A LIGGGHTS 1.x/2.x deck as LIGGGHTS 3.x text, when `demx convert`
/// rewrites every line exactly (new prime seeds, split fixes and moved
/// values are exact); the caller notes on the screen and log that the run uses it. With an
/// approximated or dropped line the run stops at that line (exit 3).
fn legacy_in_memory(sources: &SourceMap, path: &std::path::Path, text: &str) -> Result<String> {
    use crate::convert::{convert, Severity, Target};
    let c = convert(text, Target::Liggghts);
    if let Some(n) = c.notes.iter().find(|n| n.severity > Severity::Info) {
        // the span of the line's text, after its indentation
        let start: usize = text.split_inclusive('\n').take(n.line.saturating_sub(1)).map(str::len).sum();
        let line = text[start..].lines().next().unwrap_or("");
        let indent = line.len() - line.trim_start().len();
        let id = sources.add(path.to_path_buf(), text.to_string());
        let span = crate::script::Span::new(id, start + indent, start + line.trim_end().len().max(indent + 1));
        let msg = format!("running this LIGGGHTS 1.x/2.x line (its conversion to 3.x would be approximate: {})", n.message);
        return Err(Error::unsupported(span, msg)
            .with_hint(format!("`demx convert {} --to liggghts` writes the 3.x deck with its notes, to edit and run", path.display())));
    }
    Ok(c.text)
}

fn report(err: &Error, sources: &SourceMap) -> ExitCode {
    eprint!("{}", err.render(sources));
    ExitCode::from(err.exit_code())
}

/// Entry point.
pub fn main() -> ExitCode {
    let raw: Vec<String> = std::env::args().collect();
    // only run and check take -var themselves; the other subcommands parse
    // their own (compare, reference and tradeoff pass them on to runs)
    let own_vars = matches!(raw.get(1).map(String::as_str), Some("run" | "check"));
    let (args, groups) = if own_vars { extract_vars(raw) } else { (raw, vec![]) };
    let args = normalise_args(args);
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match cli.cmd {
        Cmd::Run { mut deck, threads, log, quiet, max_steps, dt_fraction, youngs_scale, checkpoint, checkpoint_every, checkpoint_stop_after } => {
            deck.var_groups = groups.clone();
            let overrides = match crate::scene::overrides::Overrides::new(dt_fraction, youngs_scale) {
                Ok(o) => o,
                Err(e) => return report(&e, &SourceMap::new()),
            };
            // the whole run executes on a pool thread: parallel passes then
            // run inline (one thread) or fork from a worker, without waking
            // the pool from outside every step
            let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build() {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("error: cannot start {threads} threads: {e}");
                    return ExitCode::from(1);
                }
            };
            let checkpoints = match checkpoint {
                Some(dir) if checkpoint_every.is_finite() && checkpoint_every >= 0.0 => {
                    let mut c = crate::scene::checkpoint::Checkpoints::new(dir, std::time::Duration::from_secs_f64(checkpoint_every));
                    c.stop_after = checkpoint_stop_after;
                    Some(c)
                }
                Some(_) => {
                    eprintln!("error: --checkpoint-every must be a number of seconds >= 0");
                    return ExitCode::from(2);
                }
                None => None,
            };
            let (s, sources, r) = pool.install(|| run_deck(&deck, false, threads, Some(&log), quiet, max_steps, overrides, checkpoints));
            match r {
                Ok(()) if s.checkpoints.as_ref().is_some_and(|c| c.stopped) => {
                    eprintln!("demx: stopped at a checkpoint; run the same command again to continue");
                    ExitCode::from(crate::scene::checkpoint::STOPPED)
                }
                Ok(()) => {
                    // finished: the checkpoint has nothing left to resume
                    if let Some(c) = &s.checkpoints {
                        if let Err(e) = c.finish(s.sim.step, threads, s.sim.particle_steps) {
                            eprintln!("error: checkpoint folder {}: {e}", c.dir.display());
                            return ExitCode::from(1);
                        }
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => report(&e, &sources),
            }
        }
        Cmd::Check { mut deck, json, script_only: true } => {
            deck.var_groups = groups.clone();
            let sources = SourceMap::new();
            let mut host = ScriptOnly::default();
            let mut interp = Interpreter::new(sources.clone(), cli_vars(&deck));
            interp.set_command_limit(50_000_000);
            match interp.run_file(&deck.deck, &mut host) {
                Ok(()) => {
                    if json {
                        println!("{{\"commands\": {}}}", host.commands);
                    } else {
                        println!("script language: ok ({} commands)", host.commands);
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => report(&e, &sources),
            }
        }
        Cmd::Check { mut deck, json, .. } => {
            deck.var_groups = groups.clone();
            let (s, sources, r) = run_deck(&deck, true, 1, None, true, None, Default::default(), None);
            match r {
                Ok(()) => {
                    let sum = Summary::of(&s);
                    if json {
                        println!("{}", serde_json::to_string_pretty(&sum).unwrap_or_default());
                    } else {
                        print!("{}", sum.render());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => report(&e, &sources),
            }
        }
        Cmd::Dump { what: DumpCmd::Info { file } } => match crate::io::dump::info(&file) {
            Ok(i) => {
                print!("{}", i.render());
                ExitCode::SUCCESS
            }
            // a dump that cannot be read is bad input (exit 2), as for
            // compare, repose and packing; an Io error without a deck span
            // would say 1
            Err(e @ crate::Error::Io { .. }) => report(&crate::Error::usage(e.message()), &SourceMap::new()),
            Err(e) => report(&e, &SourceMap::new()),
        },
        Cmd::Compare(p) => crate::analysis::compare::cli(p.args),
        Cmd::Reference(p) => crate::analysis::reference::cli(p.args),
        Cmd::Convert(p) => crate::convert::cli(p.args),
        Cmd::Repose(p) => crate::analysis::repose::cli(p.args),
        Cmd::Packing(p) => crate::analysis::packing::cli(p.args),
        Cmd::Saltation(p) => crate::analysis::saltation::cli(p.args),
        Cmd::Tradeoff(p) => crate::analysis::tradeoff::cli(p.args),
        Cmd::Sweep(p) => crate::analysis::sweep::cli(p.args),
        Cmd::Campaign(p) => crate::analysis::campaign::cli(p.args),
    }
}

/// Host for `demx check --script-only`: accepts every command unexecuted.
#[derive(Default)]
struct ScriptOnly {
    commands: u64,
}

impl crate::script::EvalContext for ScriptOnly {
    fn thermo(&self, _name: &str) -> Option<f64> {
        Some(0.0)
    }
    fn compute(&self, _id: &str, _i: Option<usize>, _j: Option<usize>) -> std::result::Result<f64, String> {
        Ok(0.0)
    }
    fn fix(&self, _id: &str, _i: Option<usize>, _j: Option<usize>) -> std::result::Result<f64, String> {
        Ok(0.0)
    }
    fn atom_value(&self, _k: &str, _id: i64) -> std::result::Result<f64, String> {
        Ok(0.0)
    }
    fn group_function(&self, _name: &str, _args: &[&str]) -> std::result::Result<f64, String> {
        Ok(0.0)
    }
}

impl crate::script::Host for ScriptOnly {
    fn execute(&mut self, _cmd: &crate::script::Command, _vars: &mut crate::script::Variables) -> Result<()> {
        self.commands += 1;
        Ok(())
    }
    fn output(&mut self, _text: &str) {}
    fn set_log(&mut self, _path: Option<&str>, _append: bool, _span: crate::script::Span) -> Result<()> {
        Ok(())
    }
}
