//! Reading command arguments with spans: every error points at the word.

use crate::error::{did_you_mean, Error, Result};
use crate::script::{Command, Span, Word};

/// A cursor over a command's arguments.
pub struct Args<'a> {
    /// The command.
    pub cmd: &'a Command,
    /// Index into `cmd.args()` of the next word.
    pub pos: usize,
}

/// Parse a number as LAMMPS `numeric()` accepts it.
pub fn parse_f64(w: &Word) -> Result<f64> {
    let t = w.text.trim();
    let ok = !t.is_empty() && t.chars().all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-'));
    match t.parse::<f64>() {
        // A literal beyond f64 (1e400): LAMMPS 29 Sep 2021 and LIGGGHTS 3.8
        // take atof's infinity and run on with it (`timestep 1e400`); no
        // deck means that, so it is refused here
        Ok(v) if ok && v.is_infinite() => Err(Error::deck(w.span, format!("number '{}' is too large for a double (at most {:e})", w.text, f64::MAX))),
        Ok(v) if ok => Ok(v),
        _ => Err(Error::deck(w.span, format!("expected a number, found '{}'", w.text))),
    }
}

/// Parse an integer.
pub fn parse_i64(w: &Word) -> Result<i64> {
    w.text.trim().parse::<i64>().map_err(|_| Error::deck(w.span, format!("expected an integer, found '{}'", w.text)))
}

impl<'a> Args<'a> {
    /// A cursor at the first argument.
    pub fn new(cmd: &'a Command) -> Args<'a> {
        Args { cmd, pos: 0 }
    }
    /// Span to point at when an argument is missing: the end of the line.
    pub fn end_span(&self) -> Span {
        let s = self.cmd.words.last().map(|w| w.span).unwrap_or(self.cmd.span);
        Span { file: s.file, start: s.end, end: s.end + 1 }
    }
    /// Whether arguments remain.
    pub fn more(&self) -> bool {
        self.pos < self.cmd.args().len()
    }
    /// Remaining arguments.
    pub fn rest(&self) -> &'a [Word] {
        &self.cmd.args()[self.pos.min(self.cmd.args().len())..]
    }
    /// Peek at the next word.
    pub fn peek(&self) -> Option<&'a Word> {
        self.cmd.args().get(self.pos)
    }
    /// The next word; error naming `what` if missing.
    pub fn word(&mut self, what: &str) -> Result<&'a Word> {
        match self.cmd.args().get(self.pos) {
            Some(w) => {
                self.pos += 1;
                Ok(w)
            }
            None => Err(Error::deck(self.end_span(), format!("{}: missing {}", self.cmd.name(), what))),
        }
    }
    /// The next word's text.
    pub fn str(&mut self, what: &str) -> Result<&'a str> {
        Ok(self.word(what)?.text.as_str())
    }
    /// The next word as a number.
    pub fn f64(&mut self, what: &str) -> Result<f64> {
        let w = self.word(what)?;
        parse_f64(w).map_err(|e| {
            if w.text.trim().parse::<f64>().is_ok_and(f64::is_infinite) {
                Error::deck(w.span, format!("{}: {what}: {}", self.cmd.name(), e.message()))
            } else {
                Error::deck(w.span, format!("{}: {} must be a number, not '{}'", self.cmd.name(), what, w.text)).with_hint(e.message())
            }
        })
    }
    /// The next word as an integer.
    pub fn i64(&mut self, what: &str) -> Result<i64> {
        let w = self.word(what)?;
        parse_i64(w).map_err(|_| Error::deck(w.span, format!("{}: {} must be an integer, not '{}'", self.cmd.name(), what, w.text)))
    }
    /// The next word, which must be one of `choices`.
    pub fn choice(&mut self, what: &str, choices: &[&str]) -> Result<&'a Word> {
        let w = self.word(what)?;
        if choices.contains(&w.text.as_str()) {
            Ok(w)
        } else {
            Err(bad_keyword(w, what, choices))
        }
    }
    /// The next word as yes/no (also on/off).
    pub fn yes_no(&mut self, what: &str) -> Result<bool> {
        let w = self.word(what)?;
        match w.text.as_str() {
            "yes" | "on" => Ok(true),
            "no" | "off" => Ok(false),
            _ => Err(bad_keyword(w, what, &["yes", "no"])),
        }
    }
    /// The word last read, if any.
    pub fn prev(&self) -> Option<&'a Word> {
        self.pos.checked_sub(1).and_then(|k| self.cmd.args().get(k))
    }
    /// Error at the word just read.
    pub fn err_prev(&self, msg: impl Into<String>) -> Error {
        Error::deck(self.prev().map(|w| w.span).unwrap_or(self.cmd.span), msg)
    }
}

/// "unknown X 'w' (expected a, b, c)" with a did-you-mean hint.
pub fn bad_keyword(w: &Word, what: &str, choices: &[&str]) -> Error {
    let mut e = Error::deck(w.span, format!("unknown {} '{}' (expected {})", what, w.text, choices.join(", ")));
    if let Some(s) = did_you_mean(&w.text, choices.iter().copied()) {
        e = e.with_hint(format!("did you mean '{s}'?"));
    }
    e
}

/// An atom type or range (`2`, `1*3`, `*`, `2*`) within 1..=ntypes.
pub fn type_range(w: &Word, ntypes: u32) -> Result<(u32, u32)> {
    let t = w.text.as_str();
    let parse = |x: &str, d: u32| -> Result<u32> {
        if x.is_empty() {
            Ok(d)
        } else {
            x.parse::<u32>().map_err(|_| Error::deck(w.span, format!("bad atom type '{}'", w.text)))
        }
    };
    let (lo, hi) = match t.find('*') {
        Some(k) => (parse(&t[..k], 1)?, parse(&t[k + 1..], ntypes)?),
        None => {
            let v = parse(t, 1)?;
            (v, v)
        }
    };
    if lo < 1 || hi > ntypes || lo > hi {
        return Err(Error::deck(w.span, format!("atom type '{}' out of range 1..{}", w.text, ntypes)));
    }
    Ok((lo, hi))
}
