//! The interpreter: drives a deck through a [`super::Host`].
//!
//! Reads files as logical lines, strips comments, substitutes `$`
//! references, splits words and runs the script-level commands itself
//! (`variable`, `next`, `label`, `jump`, `include`, `if`, `print`, `log`,
//! `echo`, `quit`, `run ... every`). Every other command goes to
//! [`Host::execute`] fully substituted.
//!
//! Control flow follows LAMMPS (29 Sep 2021): `jump FILE LABEL` rewinds
//! (`SELF`) or replaces the current file and skips lines, without
//! substituting them, until `label LABEL`; an exhausted `next` makes the
//! following `jump` do nothing; `include` reads a file (path relative to the
//! working directory) before continuing; `print` and `if` substitute their
//! quoted arguments when they run.

use super::lexer::{self, LogicalLine, RawWord, Reference, Text};
use super::{Command, EvalContext, FileId, Host, SourceMap, Span, Variables, Word};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where `echo` sends the commands it echoes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Echo {
    /// No echo (the default of `lmp -echo none`).
    #[default]
    None,
    /// Echo to the screen.
    Screen,
    /// Echo to the log file.
    Log,
    /// Both.
    Both,
}

/// One open input file.
#[derive(Clone, Debug)]
struct Frame {
    file: FileId,
    lines: Arc<Vec<LogicalLine>>,
    pos: usize,
}

/// Where a deck stands between two commands, as a checkpoint keeps it
/// ([`Interpreter::save_before_current`], [`Interpreter::resume`]): the
/// variables, and each open file (the deck first, then nested includes) with
/// the index of the logical line to run next.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SavedInterpreter {
    /// The variable store.
    pub vars: super::vars::SavedVariables,
    /// Open files, outermost first: path, next logical line, and the FNV-1a
    /// hash of the file's text (a changed file cannot be resumed).
    pub frames: Vec<(PathBuf, usize, u64)>,
    /// A `next` ran out of values and the next `jump` is to be skipped.
    pub jump_skip: bool,
    /// Lines and commands processed so far (for the command limit).
    pub count: u64,
}

/// FNV-1a (64 bits) of a text: the same on every machine and build.
fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// Most input files open at once (nested `include`).
const MAX_NESTING: usize = 64;

/// Runs deck files command by command.
pub struct Interpreter {
    /// The variable store.
    pub vars: Variables,
    /// All files read.
    pub sources: SourceMap,
    /// The `echo` setting.
    pub echo: Echo,
    files: HashMap<PathBuf, FileId>,
    lines: HashMap<FileId, Arc<Vec<LogicalLine>>>,
    stack: Vec<Frame>,
    label: Option<(String, Span)>,
    jump_skip: bool,
    quit: bool,
    limit: Option<u64>,
    count: u64,
    file_access: bool,
    /// Whether `print ... file/append` writes (off for `demx check`).
    write_files: bool,
    /// Commands run from inside another (`if`, `run every`): a checkpoint is
    /// taken only at a deck's own `run` lines.
    nested: u32,
}

impl Interpreter {
    /// A new interpreter with `-var` variables from the command line.
    pub fn new(sources: SourceMap, cli_vars: Vec<(String, Vec<String>)>) -> Interpreter {
        let mut vars = Variables::default();
        for (name, values) in cli_vars {
            vars.define_index(&name, values);
        }
        Interpreter {
            vars,
            sources,
            echo: Echo::None,
            files: HashMap::new(),
            lines: HashMap::new(),
            stack: Vec::new(),
            label: None,
            jump_skip: false,
            quit: false,
            limit: None,
            count: 0,
            file_access: true,
            write_files: true,
            nested: 0,
        }
    }

    /// Stop with an error after `n` more executed (or skipped) lines and
    /// commands, so decks that loop forever end.
    pub fn set_command_limit(&mut self, n: u64) {
        self.limit = Some(self.count.saturating_add(n));
    }

    /// Set the `echo` setting (as `-echo` on the command line).
    pub fn set_echo(&mut self, echo: Echo) {
        self.echo = echo;
    }

    /// Whether the deck may touch files: `print ... file/append` writes,
    /// `include` and `jump FILE` reads (off for fuzzing: prints skip the
    /// file, reads fail with an error).
    pub fn set_file_access(&mut self, allow: bool) {
        self.file_access = allow;
    }

    /// Whether `print ... file/append` writes its file (`demx check` writes
    /// nothing; reads stay allowed).
    pub fn set_file_writes(&mut self, allow: bool) {
        self.write_files = allow;
    }

    /// Number of lines and commands processed so far.
    pub fn commands_processed(&self) -> u64 {
        self.count
    }

    /// Whether `quit` was executed.
    pub fn has_quit(&self) -> bool {
        self.quit
    }

    /// Run a deck file to its end (or `quit`).
    pub fn run_file(&mut self, path: &Path, host: &mut dyn Host) -> Result<()> {
        let id = self.load(path, Span::DUMMY)?;
        self.run_id(id, host)
    }

    /// Use `text` as the contents of the file at `path` when it is run, included or
    /// jumped to (a deck converted in memory).
    pub fn preload(&mut self, path: &Path, text: String) {
        let id = self.sources.add(path.to_path_buf(), text);
        self.files.insert(path.to_path_buf(), id);
    }

    /// Run deck text under a name (the name is what `jump SELF` and error
    /// messages use; `jump NAME` reads the file of that name from disk).
    pub fn run_text(&mut self, name: &str, text: &str, host: &mut dyn Host) -> Result<()> {
        let id = self.sources.add(name, text.to_string());
        self.run_id(id, host)
    }

    fn run_id(&mut self, id: FileId, host: &mut dyn Host) -> Result<()> {
        self.quit = false;
        self.label = None;
        self.jump_skip = false;
        let base = self.stack.len();
        let lines = self.lines_of(id);
        self.stack.push(Frame { file: id, lines, pos: 0 });
        let r = self.drive(base, host);
        self.stack.truncate(base);
        r
    }

    /// The state before the command now running, a top-level `run` line
    /// ([`Host::checkpoint_due`]): resuming runs that line again.
    fn save_before_current(&self) -> SavedInterpreter {
        let frames = self
            .stack
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let (path, hash) = self.sources.get(f.file).map(|s| (s.path.clone(), fnv1a(&s.text))).unwrap_or_default();
                // the innermost file's line was already taken
                let pos = if k + 1 == self.stack.len() { f.pos.saturating_sub(1) } else { f.pos };
                (path, pos, hash)
            })
            .collect();
        SavedInterpreter { vars: self.vars.save(), frames, jump_skip: self.jump_skip, count: self.count.saturating_sub(1) }
    }

    /// Continue a deck from a checkpoint's state: `deck` stands for the
    /// outermost file (the deck may have moved since), the other files are
    /// read from their saved paths.
    pub fn resume(&mut self, saved: &SavedInterpreter, deck: &Path, host: &mut dyn Host) -> Result<()> {
        self.vars = super::Variables::restore(&saved.vars).map_err(|m| Error::runtime(format!("checkpoint: {m}")))?;
        self.quit = false;
        self.label = None;
        self.jump_skip = saved.jump_skip;
        self.count = saved.count;
        self.stack.clear();
        for (k, (path, pos, hash)) in saved.frames.iter().enumerate() {
            let file = if k == 0 { deck } else { path };
            let id = self.load(file, Span::DUMMY)?;
            let lines = self.lines_of(id);
            let now = self.sources.get(id).map(|s| fnv1a(&s.text)).unwrap_or_default();
            if now != *hash || *pos > lines.len() {
                return Err(Error::runtime(format!(
                    "checkpoint: {} has changed since the checkpoint was written; it resumes only the file it was taken in",
                    file.display()
                )));
            }
            self.stack.push(Frame { file: id, lines, pos: *pos });
        }
        let r = self.drive(0, host);
        self.stack.clear();
        r
    }

    fn lines_of(&mut self, id: FileId) -> Arc<Vec<LogicalLine>> {
        if let Some(l) = self.lines.get(&id) {
            return l.clone();
        }
        let text = self.sources.get(id).map(|f| f.text.clone()).unwrap_or_default();
        let l = Arc::new(lexer::logical_lines(id, &text));
        self.lines.insert(id, l.clone());
        l
    }

    fn load(&mut self, path: &Path, span: Span) -> Result<FileId> {
        if let Some(&id) = self.files.get(path) {
            return Ok(id);
        }
        if !self.file_access && span.is_real() {
            return Err(Error::deck(span, format!("cannot open input script '{}': file access is disabled", path.display())));
        }
        let id = self.sources.load(path).map_err(|e| Error::io(span, format!("cannot open input script '{}'", path.display()), &e))?;
        self.files.insert(path.to_path_buf(), id);
        Ok(id)
    }

    fn drive(&mut self, base: usize, host: &mut dyn Host) -> Result<()> {
        while self.stack.len() > base && !self.quit {
            let top = self.stack.len() - 1;
            let frame = &mut self.stack[top];
            let Some(line) = frame.lines.get(frame.pos).cloned() else {
                if let Some((label, span)) = self.label.take() {
                    return Err(Error::deck(span, format!("label '{label}' was not found in the input script")));
                }
                self.stack.pop();
                continue;
            };
            frame.pos += 1;
            self.process(&line.text, host)?;
        }
        Ok(())
    }

    fn tick(&mut self, span: Span) -> Result<()> {
        self.count += 1;
        if let Some(l) = self.limit {
            if self.count > l {
                return Err(Error::deck(span, format!("command limit reached ({l} commands)")));
            }
        }
        Ok(())
    }

    /// One line or one command string (from `if` or `run every`): strip the
    /// comment, substitute, split, execute.
    fn process(&mut self, raw: &Text, host: &mut dyn Host) -> Result<()> {
        self.tick(raw.span())?;
        let text = lexer::strip_comment(raw);
        if let Some((label, _)) = &self.label {
            let words = lexer::split_words(&text)?;
            if words.len() >= 2 && words[0].text.s == "label" && &words[1].text.s == label {
                self.label = None;
            }
            return Ok(());
        }
        if self.echo != Echo::None && !raw.s.trim().is_empty() {
            host.output(&raw.s);
        }
        let (subst, changed) = {
            let ctx: &dyn EvalContext = &*host;
            let vars = &self.vars;
            lexer::substitute(&text, &mut |r, sp| resolve(vars, r, sp, ctx))?
        };
        if changed && self.echo != Echo::None {
            host.output(&subst.s);
        }
        let words = lexer::split_words(&subst)?;
        if words.is_empty() {
            return Ok(());
        }
        self.execute(words, text.span(), host)
    }

    fn execute(&mut self, words: Vec<RawWord>, span: Span, host: &mut dyn Host) -> Result<()> {
        let cmd = Command { words: words.iter().map(|w| w.to_word()).collect(), span };
        let args = &cmd.words[1..];
        let name_span = cmd.words[0].span;
        match cmd.name() {
            "variable" => self.vars.define(&cmd),
            "next" => {
                if args.is_empty() {
                    return Err(Error::deck(name_span, "illegal next command: name at least one variable"));
                }
                if self.vars.next(args)? {
                    self.jump_skip = true;
                }
                Ok(())
            }
            "label" => {
                if args.len() != 1 {
                    return Err(Error::deck(name_span, "illegal label command: expected 'label ID'"));
                }
                Ok(())
            }
            "jump" => self.jump(&cmd),
            "include" => {
                if args.len() != 1 {
                    return Err(Error::deck(name_span, "illegal include command: expected 'include FILE'"));
                }
                if self.stack.len() >= MAX_NESTING {
                    return Err(Error::deck(args[0].span, "too many nested input files"));
                }
                let id = self.load(Path::new(&args[0].text), args[0].span)?;
                let lines = self.lines_of(id);
                self.stack.push(Frame { file: id, lines, pos: 0 });
                Ok(())
            }
            "if" => self.ifthenelse(&words, name_span, host),
            "print" => self.print(&words, name_span, host),
            "log" => match args {
                [f] if f.text == "none" => host.set_log(None, false, f.span),
                [f] => host.set_log(Some(&f.text), false, f.span),
                [f, a] if a.text == "append" => host.set_log(Some(&f.text), true, f.span),
                _ => Err(Error::deck(args.get(1).map_or(name_span, |w| w.span), "illegal log command: expected 'log FILE [append]' or 'log none'")),
            },
            "echo" => {
                self.echo = match args {
                    [w] => match w.text.as_str() {
                        "none" => Echo::None,
                        "screen" => Echo::Screen,
                        "log" => Echo::Log,
                        "both" => Echo::Both,
                        _ => {
                            return Err(Error::deck(
                                w.span,
                                format!("illegal echo command: unknown setting '{}' (expected none, screen, log, both)", w.text),
                            ))
                        }
                    },
                    _ => return Err(Error::deck(name_span, "illegal echo command: expected one of none, screen, log, both")),
                };
                Ok(())
            }
            "quit" => {
                if args.len() > 1 || args.first().is_some_and(|w| w.text.parse::<i64>().is_err()) {
                    return Err(Error::deck(args.first().map_or(name_span, |w| w.span), "illegal quit command: expected 'quit [status]'"));
                }
                self.quit = true;
                Ok(())
            }
            "run" if args.iter().any(|w| w.text == "every") => {
                self.nested += 1;
                let r = self.run_every(&cmd, &words, host);
                self.nested -= 1;
                r
            }
            "run" if self.nested == 0 && host.checkpoint_due() => {
                // a deck's own `run` line: the state before it is complete
                // (no command half done), so a checkpoint taken here resumes
                // by running this line again
                let saved = self.save_before_current();
                if host.checkpoint(&saved)? {
                    self.quit = true;
                    return Ok(());
                }
                host.execute(&cmd, &mut self.vars)
            }
            _ => host.execute(&cmd, &mut self.vars),
        }
    }

    fn jump(&mut self, cmd: &Command) -> Result<()> {
        let args = cmd.args();
        if args.is_empty() || args.len() > 2 {
            return Err(Error::deck(cmd.words[0].span, "illegal jump command: expected 'jump FILE [LABEL]'"));
        }
        if self.jump_skip {
            self.jump_skip = false;
            return Ok(());
        }
        let Some(top) = self.stack.len().checked_sub(1) else {
            return Err(Error::deck(cmd.words[0].span, "jump outside an input file"));
        };
        if args[0].text == "SELF" {
            self.stack[top].pos = 0;
        } else {
            let id = self.load(Path::new(&args[0].text), args[0].span)?;
            let lines = self.lines_of(id);
            self.stack[top] = Frame { file: id, lines, pos: 0 };
        }
        if let Some(l) = args.get(1) {
            self.label = Some((l.text.clone(), l.span));
        }
        Ok(())
    }

    fn substitute_word(&self, w: &RawWord, host: &dyn Host) -> Result<Text> {
        let ctx: &dyn EvalContext = host;
        let vars = &self.vars;
        Ok(lexer::substitute(&w.text, &mut |r, sp| resolve(vars, r, sp, ctx))?.0)
    }

    fn ifthenelse(&mut self, words: &[RawWord], name_span: Span, host: &mut dyn Host) -> Result<()> {
        let args = &words[1..];
        let illegal = |sp: Span, what: &str| Error::deck(sp, format!("illegal if command: {what}"));
        if args.len() < 3 {
            return Err(illegal(name_span, "expected 'if BOOLEAN then COMMAND ...'"));
        }
        if args[1].text.s != "then" {
            return Err(illegal(args[1].text.span(), "expected 'then'"));
        }
        let cond = |me: &Self, w: &RawWord, host: &dyn Host| -> Result<bool> {
            let t = me.substitute_word(w, host)?;
            let v = super::expr::eval_boolean(&t.s).map_err(|m| Error::deck(w.text.span(), m))?;
            Ok(v != 0.0)
        };
        let block_end = |from: usize| {
            let mut k = from;
            while k < args.len() && args[k].text.s != "elif" && args[k].text.s != "else" {
                k += 1;
            }
            k
        };
        let mut test = cond(self, &args[0], &*host)?;
        let mut first = 2;
        let mut end = block_end(first);
        loop {
            if test {
                if end <= first {
                    return Err(illegal(args.get(first.saturating_sub(1)).map_or(name_span, |w| w.text.span()), "no commands to execute"));
                }
                let cmds: Vec<Text> = args[first..end].iter().map(|w| w.text.clone()).collect();
                for (k, c) in cmds.iter().enumerate() {
                    if c.s.trim().is_empty() {
                        return Err(illegal(args[first + k].text.span(), "empty command"));
                    }
                    self.nested += 1;
                    let r = self.process(c, host);
                    self.nested -= 1;
                    r?;
                    if self.quit {
                        break;
                    }
                }
                return Ok(());
            }
            if end >= args.len() {
                return Ok(());
            }
            if end + 2 > args.len() {
                return Err(illegal(args[end].text.span(), "expected commands after elif/else"));
            }
            if args[end].text.s == "elif" {
                test = cond(self, &args[end + 1], &*host)?;
                first = end + 2;
            } else {
                test = true;
                first = end + 1;
            }
            end = block_end(first);
        }
    }

    fn print(&mut self, words: &[RawWord], name_span: Span, host: &mut dyn Host) -> Result<()> {
        let args = &words[1..];
        let Some(msg) = args.first() else {
            return Err(Error::deck(name_span, "illegal print command: nothing to print"));
        };
        let text = self.substitute_word(msg, &*host)?;
        let mut screen = true;
        let mut file: Option<(&RawWord, bool)> = None;
        let mut k = 1;
        while k < args.len() {
            let kw = &args[k];
            let val = args.get(k + 1).ok_or_else(|| Error::deck(kw.text.span(), format!("illegal print command: '{}' needs a value", kw.text.s)))?;
            match kw.text.s.as_str() {
                "file" | "append" => file = Some((val, kw.text.s == "append")),
                "screen" | "universe" => {
                    let yes = match val.text.s.as_str() {
                        "yes" => true,
                        "no" => false,
                        _ => return Err(Error::deck(val.text.span(), format!("illegal print command: expected yes or no, got '{}'", val.text.s))),
                    };
                    if kw.text.s == "screen" {
                        screen = yes;
                    }
                }
                other => {
                    return Err(Error::deck(
                        kw.text.span(),
                        format!("illegal print command: unknown keyword '{other}' (expected file, append, screen, universe)"),
                    ))
                }
            }
            k += 2;
        }
        if let Some((f, append)) = file {
            if self.file_access && self.write_files {
                use std::io::Write;
                let mut opts = std::fs::OpenOptions::new();
                if append {
                    opts.append(true).create(true);
                } else {
                    opts.write(true).create(true).truncate(true);
                }
                let mut fh = opts.open(&f.text.s).map_err(|e| Error::io(f.text.span(), format!("cannot open print file '{}'", f.text.s), &e))?;
                writeln!(fh, "{}", text.s).map_err(|e| Error::io(f.text.span(), format!("cannot write print file '{}'", f.text.s), &e))?;
            }
        }
        if screen {
            host.output(&text.s);
        }
        Ok(())
    }

    fn run_every(&mut self, cmd: &Command, words: &[RawWord], host: &mut dyn Host) -> Result<()> {
        let args = cmd.args();
        let name_span = cmd.words[0].span;
        let int = |w: Option<&Word>, sp: Span| -> Result<i64> {
            let w = w.ok_or_else(|| Error::deck(sp, "illegal run command: missing value"))?;
            w.text.parse::<i64>().map_err(|_| Error::deck(w.span, format!("illegal run command: expected an integer, got '{}'", w.text)))
        };
        let n = int(args.first(), name_span)?;
        let (mut upto, mut start, mut stop, mut pre, mut post) = (false, None, None, false, false);
        let mut every = 0i64;
        let mut commands: Vec<Text> = Vec::new();
        let mut k = 1;
        while k < args.len() {
            let kw = &args[k];
            match kw.text.as_str() {
                "upto" => {
                    upto = true;
                    k += 1;
                }
                "start" | "stop" => {
                    let v = int(args.get(k + 1), kw.span)?;
                    if kw.text == "start" {
                        start = Some(v);
                    } else {
                        stop = Some(v);
                    }
                    k += 2;
                }
                "pre" | "post" => {
                    let v = args.get(k + 1).map(|w| w.text.as_str());
                    let yes = match v {
                        Some("yes") => true,
                        Some("no") => false,
                        _ => return Err(Error::deck(args.get(k + 1).map_or(kw.span, |w| w.span), "illegal run command: expected yes or no")),
                    };
                    if kw.text == "pre" {
                        pre = yes;
                    } else {
                        post = yes;
                    }
                    k += 2;
                }
                "every" => {
                    every = int(args.get(k + 1), kw.span)?;
                    if every <= 0 {
                        return Err(Error::deck(args[k + 1].span, "illegal run command: every must be > 0"));
                    }
                    let rest = &words[k + 3..];
                    if !(rest.len() == 1 && rest[0].text.s == "NULL") {
                        commands = rest.iter().map(|w| w.text.clone()).collect();
                    }
                    break;
                }
                other => return Err(Error::deck(kw.span, format!("illegal run command: unknown keyword '{other}'"))),
            }
        }
        let step_now = host.thermo("step").unwrap_or(0.0) as i64;
        let nsteps = if upto { n - step_now } else { n };
        if nsteps < 0 {
            return Err(Error::deck(args[0].span, "invalid run command N value (negative number of steps)"));
        }
        let mut nleft = nsteps;
        let mut iter = 0;
        while nleft > 0 || iter == 0 {
            let chunk = nleft.min(every);
            let last = nleft <= chunk;
            let w = |s: String, sp: Span| Word::new(s, sp);
            let mut ws = vec![w("run".into(), name_span), w(chunk.to_string(), args[0].span)];
            if let Some(s) = start {
                ws.push(w("start".into(), name_span));
                ws.push(w(s.to_string(), name_span));
            }
            if let Some(s) = stop {
                ws.push(w("stop".into(), name_span));
                ws.push(w(s.to_string(), name_span));
            }
            ws.push(w("pre".into(), name_span));
            ws.push(w(if pre || iter == 0 { "yes" } else { "no" }.into(), name_span));
            ws.push(w("post".into(), name_span));
            ws.push(w(if post || last { "yes" } else { "no" }.into(), name_span));
            let run = Command { words: ws, span: cmd.span };
            self.tick(cmd.span)?;
            host.execute(&run, &mut self.vars)?;
            for c in &commands {
                self.process(c, host)?;
                if self.quit {
                    return Ok(());
                }
            }
            nleft -= chunk;
            iter += 1;
        }
        Ok(())
    }
}

/// The text a `$` reference stands for.
fn resolve(vars: &Variables, r: &Reference, span: Span, ctx: &dyn EvalContext) -> Result<String> {
    super::vars::resolve_reference(vars, r, span, ctx)
}
