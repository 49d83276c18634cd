//! The one error type of the library and how it is shown to a person.
//!
//! Exit codes (same for every subcommand): 0 the deck is understood / the run
//! finished; 1 a run failed at run time (stability guard, I/O while writing,
//! a comparison outside tolerance); 2 the deck or the input is wrong;
//! 3 the deck is valid but uses something demx does not support yet.

use crate::script::source::{SourceMap, Span};
use std::fmt;

/// What went wrong, with where.
#[derive(Debug, Clone)]
pub enum Error {
    /// The deck is wrong: `file:line:col: error: msg`.
    Deck {
        /// Offending text.
        span: Span,
        /// What is wrong.
        msg: String,
        /// A hint (valid keywords, did-you-mean), if any.
        hint: Option<String>,
    },
    /// Valid for LIGGGHTS/LAMMPS, not supported by demx yet.
    Unsupported {
        /// Offending text.
        span: Span,
        /// What is not supported, e.g. "fix mesh/surface/stress".
        what: String,
        /// Why or what to do instead.
        hint: Option<String>,
    },
    /// A file could not be read or written.
    Io {
        /// Where the path was named (dummy for command-line paths).
        span: Span,
        /// Path and operation.
        what: String,
        /// The OS error text.
        err: String,
    },
    /// A run stopped at run time (stability guard, lost particles with
    /// `thermo_modify lost error`, ...).
    Runtime {
        /// The full message.
        msg: String,
    },
    /// Bad command-line use or bad non-deck input (dump files, ...).
    Usage {
        /// The full message.
        msg: String,
    },
}

/// Result with the library's error.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// A deck error at `span`.
    pub fn deck(span: Span, msg: impl Into<String>) -> Error {
        Error::Deck { span, msg: msg.into(), hint: None }
    }
    /// A deck error with a hint.
    pub fn deck_hint(span: Span, msg: impl Into<String>, hint: impl Into<String>) -> Error {
        Error::Deck { span, msg: msg.into(), hint: Some(hint.into()) }
    }
    /// An unsupported feature at `span`.
    pub fn unsupported(span: Span, what: impl Into<String>) -> Error {
        Error::Unsupported { span, what: what.into(), hint: None }
    }
    /// An I/O error on `what` (e.g. "cannot read 'mesh.stl'").
    pub fn io(span: Span, what: impl Into<String>, err: &std::io::Error) -> Error {
        Error::Io { span, what: what.into(), err: err.to_string() }
    }
    /// A run-time failure.
    pub fn runtime(msg: impl Into<String>) -> Error {
        Error::Runtime { msg: msg.into() }
    }
    /// Bad usage or bad input file.
    pub fn usage(msg: impl Into<String>) -> Error {
        Error::Usage { msg: msg.into() }
    }
    /// Attach a hint (no-op for kinds without one).
    pub fn with_hint(mut self, h: impl Into<String>) -> Error {
        match &mut self {
            Error::Deck { hint, .. } | Error::Unsupported { hint, .. } => *hint = Some(h.into()),
            _ => {}
        }
        self
    }
    /// The span the error points at, if any.
    pub fn span(&self) -> Option<Span> {
        match self {
            Error::Deck { span, .. } | Error::Unsupported { span, .. } | Error::Io { span, .. } => Some(*span).filter(|s| s.is_real()),
            _ => None,
        }
    }
    /// Process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Deck { .. } | Error::Usage { .. } => 2,
            Error::Io { span, .. } => {
                if span.is_real() {
                    2
                } else {
                    1
                }
            }
            Error::Unsupported { .. } => 3,
            Error::Runtime { .. } => 1,
        }
    }
    /// Short one-line message without location.
    pub fn message(&self) -> String {
        let m = match self {
            Error::Deck { msg, .. } => msg.clone(),
            Error::Unsupported { what, .. } => format!("{what} is not supported yet"),
            Error::Io { what, err, .. } => format!("{what}: {err}"),
            Error::Runtime { msg } | Error::Usage { msg } => msg.clone(),
        };
        tidy(&m)
    }
    /// Render as `file:line:col: error: msg`, the source line and a caret,
    /// LAMMPS `point_to_error` style.
    pub fn render(&self, map: &SourceMap) -> String {
        let (label, hint) = match self {
            Error::Deck { hint, .. } => ("error", hint.as_deref()),
            Error::Unsupported { hint, .. } => ("unsupported", hint.as_deref()),
            Error::Io { .. } | Error::Usage { .. } => ("error", None),
            Error::Runtime { .. } => ("error", None),
        };
        let mut out = String::new();
        let span = self.span();
        let located = span.and_then(|s| map.get(s.file).map(|f| (s, f)));
        match located {
            Some((s, f)) => {
                let (line, col) = f.line_col(s.start as usize);
                out.push_str(&format!("{}:{}:{}: {}: {}\n", f.path.display(), line, col, label, self.message()));
                let text = f.line_text(line);
                let lno = line.to_string();
                let (eline, ecol) = f.line_col((s.end as usize).max(s.start as usize + 1) - 1);
                let width = if eline == line { (ecol + 1).saturating_sub(col).max(1) } else { 1 };
                // a window of at most 240 characters around the caret, control
                // characters shown as '?' so that the caret stays aligned
                let skip = (col - 1).saturating_sub(40);
                let shown: String = text.chars().skip(skip).take(240).map(|c| if c.is_control() { '?' } else { c }).collect();
                let more = if text.chars().count() > skip + 240 { " ..." } else { "" };
                let lead = if skip > 0 { "... " } else { "" };
                out.push_str(&format!("{} | {lead}{shown}{more}\n", lno));
                let pad = col - 1 - skip + lead.len();
                let width = width.min(240usize.saturating_sub(col - 1 - skip)).max(1);
                out.push_str(&format!("{} | {}{}\n", " ".repeat(lno.len()), " ".repeat(pad), "^".repeat(width)));
            }
            None => out.push_str(&format!("{}: {}\n", label, self.message())),
        }
        if let Some(h) = hint {
            out.push_str(&format!("hint: {}\n", tidy(h)));
        }
        out
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message())
    }
}

impl std::error::Error for Error {}

/// `s` with its control characters but newline and tab written as escapes (`\x1b`), so
/// that a token in a message cannot move the cursor or recolour the
/// terminal.
pub fn printable(s: &str) -> String {
    let bad = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !s.chars().any(bad) {
        return s.to_string();
    }
    s.chars().map(|c| if bad(c) { format!("\\x{:02x}", c as u32) } else { c.to_string() }).collect()
}

/// `s` cut to `max` characters (its head and tail, with the number left out)
/// for messages: a 10 MB token made a 20 MB message.
pub fn clip(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let half = max / 2;
    let head: String = s.chars().take(half).collect();
    let tail: String = s.chars().skip(n - half).collect();
    format!("{head}...[{} characters]...{tail}", n - 2 * half)
}

/// A message made safe to print: control characters escaped, every quoted
/// ('...') token longer than 200 characters clipped, and the whole kept
/// under 20,000 characters.
fn tidy(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len().min(4096));
    let mut rest = msg;
    while let Some(a) = rest.find('\'') {
        out.push_str(&rest[..=a]);
        rest = &rest[a + 1..];
        match rest.find('\'') {
            Some(b) => {
                out.push_str(&clip(&rest[..b], 200));
                out.push('\'');
                rest = &rest[b + 1..];
            }
            None => break,
        }
    }
    out.push_str(rest);
    printable(&clip(&out, 20_000))
}

/// Closest candidate to `word` by edit distance, for "did you mean" hints.
pub fn did_you_mean<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let mut best: Option<(usize, &str)> = None;
    let limit = (word.len().max(3) / 3).max(2);
    for c in candidates {
        // the distance is at least the difference in length: skip the
        // quadratic comparison (a 10 MB token took 20 s over every command)
        if word.len().abs_diff(c.len()) > limit {
            continue;
        }
        let d = edit_distance(word, c);
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_caret_under_word() {
        let map = SourceMap::new();
        let id = map.add("in.pour", "units si\npair_style gran model hertz cohesion sjrk\n".to_string());
        let start = "units si\npair_style gran model hertz cohesion ".len();
        let e = Error::deck_hint(Span::new(id, start, start + 4), "unknown cohesion model 'sjrk'", "did you mean 'sjkr'?");
        let r = e.render(&map);
        assert!(r.starts_with("in.pour:2:38: error: unknown cohesion model 'sjrk'\n"), "{r}");
        assert!(r.contains("\n  |                                      ^^^^\n"), "{r}");
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn suggests_close_keyword() {
        assert_eq!(did_you_mean("sjrk", ["sjkr", "sjkr2", "off"]), Some("sjkr"));
        assert_eq!(did_you_mean("zzzzzz", ["sjkr", "off"]), None);
    }
}
