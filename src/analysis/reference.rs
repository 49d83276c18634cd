//! `demx reference`: run the real LIGGGHTS (`liggghts`) or LAMMPS (`lmp`) on a
//! deck in a temporary directory, with its dumps switched to full precision,
//! and collect dumps, log, engine version, command line and wall time.
//!
//! Facts this relies on (checked with LIGGGHTS 3.8.0 and LAMMPS 29 Sep 2021):
//! - both print dump values with `%g` (6 significant digits) by default;
//! - LAMMPS takes `dump_modify ID format none` (reset) and
//!   `dump_modify ID format float %20.15g` (every float column);
//! - LIGGGHTS 3.8 only takes a whole-line `dump_modify ID format "..."` with
//!   one conversion per column (`%d` for id, type, ... and a float format for
//!   the rest); the last format given wins.

use crate::error::{Error, Result};
use crate::io::dump::is_int_column;
use crate::script::source::Span;
use clap::Parser;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

/// A reference engine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RefEngine {
    /// LIGGGHTS 3.8 (`liggghts`).
    Liggghts,
    /// LAMMPS 29 Sep 2021 (`lmp`).
    Lammps,
}

impl RefEngine {
    /// Executable name (overridable with the LIGGGHTS / LMP environment variables).
    pub fn binary(self) -> String {
        let (var, def) = match self {
            RefEngine::Liggghts => ("LIGGGHTS", "liggghts"),
            RefEngine::Lammps => ("LMP", "lmp"),
        };
        std::env::var(var).ok().filter(|s| !s.is_empty()).unwrap_or_else(|| def.to_string())
    }
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            RefEngine::Liggghts => "liggghts",
            RefEngine::Lammps => "lammps",
        }
    }
}

/// A deck made ready to run elsewhere: its (rewritten) text and the files
/// beside it that it names.
#[derive(Clone, Debug)]
pub struct PreparedDeck {
    /// File name of the deck inside the run directory.
    pub deck_name: String,
    /// Deck text with full-precision dump formats.
    pub text: String,
    /// Other files: path relative to the run directory, and source path.
    pub files: Vec<(PathBuf, PathBuf)>,
    /// Remarks (dumps whose precision could not be changed, ...).
    pub notes: Vec<String>,
}

impl PreparedDeck {
    /// Write the deck and its files into `dir`.
    pub fn install(&self, dir: &Path) -> Result<()> {
        let wr = |p: &Path, e: std::io::Error| Error::io(Span::DUMMY, format!("cannot write '{}'", p.display()), &e);
        let dp = dir.join(&self.deck_name);
        std::fs::write(&dp, &self.text).map_err(|e| wr(&dp, e))?;
        for (rel, src) in &self.files {
            let to = dir.join(rel);
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent).map_err(|e| wr(parent, e))?;
            }
            std::fs::copy(src, &to).map_err(|e| wr(&to, e))?;
        }
        Ok(())
    }
}

/// Split one logical deck line into words (quotes kept together, stops at
/// `#` outside quotes). Returns the words without their quotes.
fn words(line: &str) -> Vec<String> {
    let mut out = vec![];
    let mut cur = String::new();
    let mut have = false;
    let mut quote: Option<char> = None;
    for c in line.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => cur.push(c),
            None if c == '"' || c == '\'' => {
                quote = Some(c);
                have = true;
            }
            None if c == '#' => break,
            None if c.is_whitespace() => {
                if have {
                    out.push(std::mem::take(&mut cur));
                    have = false;
                }
            }
            None => {
                cur.push(c);
                have = true;
            }
        }
    }
    if have {
        out.push(cur);
    }
    out
}

/// Rewrite a deck so every `dump custom` writes full precision for `engine`.
/// Returns the new text and remarks about dumps left unchanged.
pub fn full_precision(text: &str, engine: RefEngine) -> (String, Vec<String>) {
    let mut out = String::with_capacity(text.len() + 256);
    let mut notes = vec![];
    // per dump id: the LIGGGHTS line format (None: not a custom dump we can format)
    let mut dumps: std::collections::HashMap<String, (bool, Option<String>)> = Default::default();
    let mut logical = String::new();
    for phys in text.split_inclusive('\n') {
        out.push_str(phys);
        let t = phys.trim_end_matches(['\n', '\r']);
        let (body, cont) = match t.trim_end().strip_suffix('&') {
            Some(b) => (b, true),
            None => (t, false),
        };
        logical.push_str(body);
        logical.push(' ');
        if cont {
            continue;
        }
        let w = words(&logical);
        logical.clear();
        let extra = match w.first().map(String::as_str) {
            Some("dump") if w.len() >= 5 => {
                let id = w[1].clone();
                let style = w[3].as_str();
                if !matches!(style, "custom" | "custom/gz" | "custom/zstd") {
                    dumps.insert(id, (false, None));
                    continue;
                }
                let cols = &w[w.len().min(6)..];
                let fmt = if cols.is_empty() || cols.iter().any(|c| c.contains('$') || c.contains('*')) {
                    if engine == RefEngine::Liggghts {
                        notes.push(format!("dump {id}: columns not countable ({}); left at the engine's precision", cols.join(" ")));
                    }
                    None
                } else {
                    let f: Vec<&str> = cols.iter().map(|c| if is_int_column(c) { "%d" } else { "%.17g" }).collect();
                    Some(f.join(" "))
                };
                dumps.insert(id.clone(), (true, fmt));
                format_lines(&id, &dumps, engine)
            }
            Some("dump_modify") if w.len() >= 3 && w[2..].iter().any(|x| x == "format") => format_lines(&w[1], &dumps, engine),
            _ => String::new(),
        };
        if !extra.is_empty() {
            if !out.ends_with('\n') {
                out.push('\n');
            }
            out.push_str(&extra);
        }
    }
    (out, notes)
}

fn format_lines(id: &str, dumps: &std::collections::HashMap<String, (bool, Option<String>)>, engine: RefEngine) -> String {
    match (engine, dumps.get(id)) {
        (RefEngine::Lammps, Some((true, _))) => {
            format!("dump_modify {id} format none\ndump_modify {id} format float %20.15g # demx reference: full precision\n")
        }
        (RefEngine::Liggghts, Some((true, Some(f)))) => format!("dump_modify {id} format \"{f}\" # demx reference: full precision\n"),
        _ => String::new(),
    }
}

/// Read `deck`, switch its dumps to full precision and find the files it
/// names that exist beside it.
///
/// Unless `allow_shell`, a deck (or a file it names) that runs system
/// commands or Python (`shell`, `python`, `variable ... python`, `fix
/// python/...`, also inside `if ... then "..."`) is refused before any
/// engine starts: the engine would run them before demx read the deck.
pub fn prepare_deck(deck: &Path, engine: RefEngine, allow_shell: bool) -> Result<PreparedDeck> {
    let text = std::fs::read_to_string(deck).map_err(|e| Error::io(Span::DUMMY, format!("cannot read deck '{}'", deck.display()), &e))?;
    if !allow_shell {
        refuse_system_commands(deck, &text, engine)?;
    }
    let dir = deck.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let deck_name = deck.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "in.deck".into());
    let mut files: Vec<(PathBuf, PathBuf)> = vec![];
    for line in text.lines() {
        for w in words(line) {
            if w.contains("..") || w.starts_with('/') || w == deck_name || w.contains('$') {
                continue;
            }
            let src = dir.join(&w);
            if src.is_file() && !files.iter().any(|(r, _)| r == Path::new(&w)) {
                files.push((PathBuf::from(&w), src));
            }
        }
    }
    if !allow_shell {
        // an `include`d file runs as well; any text file the deck names is
        // read as a deck (a data or mesh file has no such words)
        for (_, src) in &files {
            if let Ok(t) = std::fs::read_to_string(src) {
                refuse_system_commands(src, &t, engine)?;
            }
        }
    }
    let (text, notes) = full_precision(&text, engine);
    Ok(PreparedDeck { deck_name, text, files, notes })
}

/// Whether `shell ...` (the whole command) is one of the file operations
/// the engines run themselves, without a system shell (`mkdir`, `rm`,
/// `rmdir`, `mv`), on names inside the folder where the deck runs: no
/// absolute path, no `..`, no variable.
fn engine_file_operation(command: &str) -> bool {
    let mut w = command.split_whitespace().skip(1);
    let op = w.next().unwrap_or("");
    ["mkdir", "rm", "rmdir", "mv"].contains(&op) && w.all(|a| !a.starts_with('/') && !a.contains("..") && !a.contains('$') && !a.contains('~'))
}

/// `path:line:col: error:` for the first command in `text` that would run a
/// system command or Python in the engine: a line whose command (or a quoted
/// command of `if`/`run every`) is `shell` or starts with `python`, or that
/// names a `python` style (`variable v python f`, `pair_style python`).
fn refuse_system_commands(path: &Path, text: &str, engine: RefEngine) -> Result<()> {
    let mut logical = String::new();
    let mut first_line = 0;
    for (k, raw) in text.lines().enumerate() {
        if logical.is_empty() {
            first_line = k + 1;
        }
        let l = raw.trim_end();
        if let Some(head) = l.strip_suffix('&') {
            logical.push_str(head);
            logical.push(' ');
            continue;
        }
        logical.push_str(l);
        let line = std::mem::take(&mut logical);
        let ws = words(&line);
        let runs = |w: &str| {
            let cmd = w.split_whitespace().next().unwrap_or("");
            (cmd == "shell" && !engine_file_operation(w)) || cmd.starts_with("python")
        };
        let whole = ws.join(" ");
        let hit = ws.first().is_some_and(|w| if w == "shell" { runs(&whole) } else { runs(w) })
            || ws.iter().skip(1).any(|w| w == "python" || w.starts_with("python/") || (w.contains(' ') && runs(w)));
        if hit {
            let what =
                ws.iter().find(|w| w.split_whitespace().next().is_some_and(|c| c == "shell" || c.starts_with("python"))).cloned().unwrap_or_default();
            let col = line.find(what.split_whitespace().next().unwrap_or("")).map_or(1, |c| c + 1);
            let kind = if what.starts_with("shell") { "a system command (shell)" } else { "Python code" };
            return Err(Error::usage(format!(
                "{}:{first_line}:{col}: `{}` runs {kind} in {}; demx read the deck first and starts no engine on it \
                 (pass --allow-shell to run it anyway, if you trust the deck)",
                path.display(),
                crate::error::printable(&crate::error::clip(line.trim(), 200)),
                engine.binary(),
            )));
        }
    }
    Ok(())
}

/// How to run an engine.
#[derive(Clone, Debug)]
pub struct EngineRun {
    /// Which engine.
    pub engine: RefEngine,
    /// MPI ranks (mpirun when > 1).
    pub np: usize,
    /// `-var NAME VALUE...` groups.
    pub vars: Vec<(String, Vec<String>)>,
}

/// What one engine run produced (files stay in the run directory).
#[derive(Clone, Debug, Serialize)]
pub struct EngineResult {
    /// Engine.
    pub engine: RefEngine,
    /// First line of the log naming the version.
    pub version: String,
    /// The command line as run (in the run directory).
    pub command: String,
    /// Wall time of the engine process (s).
    pub wall_seconds: f64,
    /// Log file name in the run directory.
    pub log: String,
    /// Dump files written by the run (names relative to the run directory).
    pub dumps: Vec<String>,
    /// Other new files.
    pub other: Vec<String>,
}

fn is_openmpi() -> bool {
    Command::new("mpirun").arg("--version").output().map(|o| String::from_utf8_lossy(&o.stdout).contains("Open MPI")).unwrap_or(false)
}

/// Last `n` lines of a text.
pub fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// Whether the file at `p` starts like a text dump (plain or gzip).
pub fn looks_like_dump(p: &Path) -> bool {
    use std::io::Read;
    let Ok(mut f) = std::fs::File::open(p) else { return false };
    let mut head = [0u8; 2];
    if f.read_exact(&mut head).is_err() {
        return false;
    }
    let Ok(f) = std::fs::File::open(p) else { return false };
    let mut buf = vec![0u8; 14];
    let ok = if head == [0x1f, 0x8b] {
        flate2::read::MultiGzDecoder::new(f).read_exact(&mut buf).is_ok()
    } else {
        std::io::BufReader::new(f).read_exact(&mut buf).is_ok()
    };
    ok && buf == b"ITEM: TIMESTEP"
}

fn list_files(dir: &Path, base: &Path, out: &mut Vec<PathBuf>) {
    if let Ok(rd) = std::fs::read_dir(dir) {
        let mut ents: Vec<_> = rd.flatten().map(|e| e.path()).collect();
        ents.sort();
        for p in ents {
            if p.is_dir() {
                list_files(&p, base, out);
            } else if let Ok(r) = p.strip_prefix(base) {
                out.push(r.to_path_buf());
            }
        }
    }
}

/// Run the engine on `deck_name` inside `dir` (already installed there).
/// Errors (exit 2): engine not installed, engine failed (with its log tail).
pub fn run_engine(dir: &Path, deck_name: &str, run: &EngineRun) -> Result<EngineResult> {
    let mut before = vec![];
    list_files(dir, dir, &mut before);
    let bin = run.engine.binary();
    let log = format!("log.{}", run.engine.name());
    let mut argv: Vec<String> = vec![];
    if run.np > 1 {
        argv.push("mpirun".into());
        if is_openmpi() {
            argv.extend(["--allow-run-as-root".into(), "--oversubscribe".into()]);
        }
        argv.extend(["-np".into(), run.np.to_string()]);
    }
    argv.extend([bin.clone(), "-in".into(), deck_name.to_string(), "-log".into(), log.clone(), "-echo".into(), "log".into()]);
    for (name, vals) in &run.vars {
        argv.push("-var".into());
        argv.push(name.clone());
        argv.extend(vals.iter().cloned());
    }
    let command = argv.iter().map(|a| if a.contains(' ') { format!("'{a}'") } else { a.clone() }).collect::<Vec<_>>().join(" ");
    let screen = dir.join("screen.txt");
    let out_file = std::fs::File::create(&screen).map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", screen.display()), &e))?;
    let err_file = out_file.try_clone().map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", screen.display()), &e))?;
    let t0 = Instant::now();
    let status = Command::new(&argv[0]).args(&argv[1..]).current_dir(dir).stdin(Stdio::null()).stdout(out_file).stderr(err_file).status();
    let wall_seconds = t0.elapsed().as_secs_f64();
    let status = match status {
        Ok(s) => s,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Error::usage(format!(
                "'{}' is not installed (not found on PATH); {} is needed to run the {} reference",
                argv[0],
                argv[0],
                run.engine.name()
            )))
        }
        Err(e) => return Err(Error::usage(format!("cannot start '{}': {e}", argv[0]))),
    };
    let log_text = std::fs::read_to_string(dir.join(&log)).unwrap_or_default();
    let screen_text = std::fs::read_to_string(&screen).unwrap_or_default();
    let error_line = log_text.lines().chain(screen_text.lines()).any(|l| l.starts_with("ERROR"));
    if !status.success() || error_line {
        let t = if log_text.trim().is_empty() { &screen_text } else { &log_text };
        return Err(Error::usage(format!(
            "{} failed on {deck_name} ({status}); command: {command}\nlast lines of its log:\n{}",
            run.engine.name(),
            tail(t, 15)
        )));
    }
    let version = log_text.lines().next().unwrap_or("").trim().to_string();
    let mut after = vec![];
    list_files(dir, dir, &mut after);
    let mut dumps = vec![];
    let mut other = vec![];
    for f in after {
        if before.contains(&f) || f == Path::new(&log) || f == Path::new("screen.txt") {
            continue;
        }
        let s = f.to_string_lossy().into_owned();
        if looks_like_dump(&dir.join(&f)) {
            dumps.push(s);
        } else {
            other.push(s);
        }
    }
    Ok(EngineResult { engine: run.engine, version, command, wall_seconds, log, dumps, other })
}

/// Options of `demx reference`.
#[derive(Parser, Debug)]
#[command(name = "demx reference", about = "Run the real LIGGGHTS/LAMMPS on a deck and collect full-precision results")]
pub struct ReferenceArgs {
    /// The deck.
    pub deck: PathBuf,
    /// Engine to run.
    #[arg(long, value_enum)]
    pub engine: RefEngine,
    /// MPI ranks (mpirun -np N when N > 1).
    #[arg(long, default_value_t = 1)]
    pub np: usize,
    /// Output directory.
    #[arg(long, default_value = "reference-out")]
    pub out: PathBuf,
    /// Run decks with `shell` or `python` commands (the engine runs them).
    #[arg(long)]
    pub allow_shell: bool,
    /// Variables (filled from `-var NAME VALUE...`).
    #[arg(skip)]
    pub vars: Vec<(String, Vec<String>)>,
}

/// Pull `-var NAME V1 V2 ...` / `-v` / `--var` groups out of `args`.
pub fn extract_vars(args: Vec<String>) -> Result<(Vec<String>, Vec<(String, Vec<String>)>)> {
    let mut rest = vec![];
    let mut groups = vec![];
    let mut k = 0;
    while k < args.len() {
        if matches!(args[k].as_str(), "-var" | "-v" | "--var") {
            k += 1;
            let mut g: Vec<String> = vec![];
            while k < args.len() && (g.is_empty() || !args[k].starts_with('-') || args[k].parse::<f64>().is_ok()) {
                g.push(args[k].clone());
                k += 1;
            }
            if g.len() < 2 {
                return Err(Error::usage("-var needs a name and at least one value"));
            }
            groups.push((g[0].clone(), g[1..].to_vec()));
        } else {
            rest.push(args[k].clone());
            k += 1;
        }
    }
    Ok((rest, groups))
}

/// Summary written to DIR/reference.json.
#[derive(Serialize, Debug)]
pub struct ReferenceRecord {
    /// Deck as given.
    pub deck: String,
    /// The engine run.
    #[serde(flatten)]
    pub run: EngineResult,
    /// MPI ranks.
    pub np: usize,
    /// Remarks about the deck rewrite.
    pub notes: Vec<String>,
}

/// Run `demx reference`; returns the record (also written to `out`).
pub fn reference(a: &ReferenceArgs) -> Result<ReferenceRecord> {
    let prep = prepare_deck(&a.deck, a.engine, a.allow_shell)?;
    let tmp = tempfile::tempdir().map_err(|e| Error::io(Span::DUMMY, "cannot create a temporary directory", &e))?;
    prep.install(tmp.path())?;
    let run = run_engine(tmp.path(), &prep.deck_name, &EngineRun { engine: a.engine, np: a.np.max(1), vars: a.vars.clone() })?;
    let wr = |p: &Path, e: std::io::Error| Error::io(Span::DUMMY, format!("cannot write '{}'", p.display()), &e);
    std::fs::create_dir_all(&a.out).map_err(|e| wr(&a.out, e))?;
    let mut copy = vec![prep.deck_name.clone(), run.log.clone(), "screen.txt".to_string()];
    copy.extend(run.dumps.iter().cloned());
    copy.extend(run.other.iter().cloned());
    for f in &copy {
        let to = a.out.join(f);
        if let Some(p) = to.parent() {
            std::fs::create_dir_all(p).map_err(|e| wr(p, e))?;
        }
        std::fs::copy(tmp.path().join(f), &to).map_err(|e| wr(&to, e))?;
    }
    let rec = ReferenceRecord { deck: a.deck.display().to_string(), run, np: a.np.max(1), notes: prep.notes };
    let put = |name: &str, text: String| {
        let p = a.out.join(name);
        std::fs::write(&p, text).map_err(|e| wr(&p, e))
    };
    put("version.txt", format!("{}\n", rec.run.version))?;
    put("command.txt", format!("cd <tmpdir> && {}\n", rec.run.command))?;
    put("wall_time.txt", format!("{:.3}\n", rec.run.wall_seconds))?;
    put("reference.json", serde_json::to_string_pretty(&rec).unwrap_or_default() + "\n")?;
    Ok(rec)
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    let (rest, vars) = match extract_vars(args) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut argv = vec!["demx reference".to_string()];
    argv.extend(rest);
    let mut a = match ReferenceArgs::try_parse_from(argv) {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    a.vars = vars;
    match reference(&a) {
        Ok(rec) => {
            println!("{} ({}) ran {} in {:.2} s", rec.run.engine.name(), rec.run.version, a.deck.display(), rec.run.wall_seconds);
            println!("command: {}", rec.run.command);
            println!("dumps: {}", if rec.run.dumps.is_empty() { "(none)".to_string() } else { rec.run.dumps.join(", ") });
            for n in &rec.notes {
                println!("note: {n}");
            }
            println!("results in {}", a.out.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}", e.message());
            ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lammps_dumps_get_float_format_after_dump_and_user_format() {
        let d = "dump d all custom 5 dump.x id type x y z & \n   vx\ndump_modify d format line \"%d %d %g %g %g %g\"\nrun 1\n";
        let (t, notes) = full_precision(d, RefEngine::Lammps);
        assert!(notes.is_empty());
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[2], "dump_modify d format none");
        assert!(lines[3].starts_with("dump_modify d format float %20.15g"));
        assert!(lines[4].starts_with("dump_modify d format line"));
        assert_eq!(lines[5], "dump_modify d format none");
        assert!(lines[6].starts_with("dump_modify d format float %20.15g"));
        assert_eq!(lines[7], "run 1");
    }

    #[test]
    fn liggghts_line_format_counts_int_and_float_columns() {
        let d = "dump d all custom 5 dump.x id type x radius # c\ndump m all mesh/stl 5 m*.stl\n";
        let (t, _) = full_precision(d, RefEngine::Liggghts);
        assert!(t.contains("\ndump_modify d format \"%d %d %.17g %.17g\""), "{t}");
        assert!(!t.contains("dump_modify m"));
    }
}
