//! Lexing of deck text: logical lines, comments, `$` substitution and words.
//!
//! Follows the LAMMPS parsing rules (LAMMPS 29 Sep 2021, `Input::file`,
//! `Input::parse`, `Input::substitute`, `Input::nextword`):
//! - a physical line whose last non-blank character is `&` is joined with the
//!   next line: the `&` and the blanks after it are dropped, nothing is
//!   inserted (so `x&` + `y` gives `xy`, also inside quotes);
//! - while a logical line holds an odd number of `"""`, the next line is
//!   appended after a newline;
//! - `#` outside single, double or triple quotes starts a comment; the quote
//!   state toggles on every quote character, also in the middle of a word;
//! - `$x`, `${name}` and `$(expr)` / `$(expr:%fmt)` are replaced outside
//!   quotes, in one left-to-right pass: substituted text is not scanned again,
//!   so `${a${i}}` names the variable `a${i` (an error, as in LAMMPS);
//! - words are split at blanks; a word starting with `"`, `'` or `"""` runs to
//!   the matching quote, which must be followed by a blank or the end.
//!
//! Text is carried as [`Text`]: a string with the source [`Span`] of each
//! byte, so every word keeps the place the person wrote it, and substituted
//! text carries the span of its `$` reference.

use super::source::{FileId, Span};
use crate::error::{Error, Result};

/// A string with the source span of every byte.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Text {
    /// The characters.
    pub s: String,
    /// `spans[i]` is where byte `i` of `s` came from.
    pub spans: Vec<Span>,
}

impl Text {
    /// Text of a source range: byte `i` maps to `file`, `offset + i`.
    pub fn from_source(file: FileId, offset: usize, s: &str) -> Text {
        let spans = (0..s.len()).map(|i| Span::new(file, offset + i, offset + i + 1)).collect();
        Text { s: s.to_string(), spans }
    }
    /// Text whose every byte carries one span (substituted values).
    pub fn uniform(s: &str, span: Span) -> Text {
        Text { s: s.to_string(), spans: vec![span; s.len()] }
    }
    /// Append a string with one span for all its bytes.
    pub fn push_str(&mut self, s: &str, span: Span) {
        self.s.push_str(s);
        self.spans.extend(std::iter::repeat_n(span, s.len()));
    }
    /// Append another text.
    pub fn push_text(&mut self, t: &Text) {
        self.s.push_str(&t.s);
        self.spans.extend_from_slice(&t.spans[..t.s.len().min(t.spans.len())]);
    }
    /// Append the byte range `a..b` of another text.
    pub fn push_range(&mut self, t: &Text, a: usize, b: usize) {
        self.s.push_str(&t.s[a..b]);
        self.spans.extend_from_slice(&t.spans[a..b]);
    }
    /// The sub-text `a..b` (byte offsets on char boundaries).
    pub fn slice(&self, a: usize, b: usize) -> Text {
        Text { s: self.s[a..b].to_string(), spans: self.spans[a..b].to_vec() }
    }
    /// Span covering bytes `a..b` (or the nearest byte if empty).
    pub fn span_of(&self, a: usize, b: usize) -> Span {
        if self.spans.is_empty() {
            return Span::DUMMY;
        }
        let a = a.min(self.spans.len() - 1);
        let b = b.max(a + 1).min(self.spans.len());
        let mut sp = self.spans[a];
        for s in &self.spans[a..b] {
            sp = sp.to(*s);
        }
        sp
    }
    /// Span of the whole text.
    pub fn span(&self) -> Span {
        self.span_of(0, self.s.len())
    }
}

/// One logical line of a file: physical lines joined by `&` or open triple
/// quotes, line ending removed.
#[derive(Clone, Debug)]
pub struct LogicalLine {
    /// The text with per-byte spans.
    pub text: Text,
    /// 1-based number of the first physical line.
    pub line: usize,
}

/// Split a file's text into logical lines.
pub fn logical_lines(file: FileId, src: &str) -> Vec<LogicalLine> {
    // physical lines: (offset, text without "\n" / "\r\n")
    let mut phys: Vec<(usize, &str)> = Vec::new();
    let mut start = 0;
    for (i, b) in src.bytes().enumerate() {
        if b == b'\n' {
            phys.push((start, src[start..i].strip_suffix('\r').unwrap_or(&src[start..i])));
            start = i + 1;
        }
    }
    if start < src.len() {
        phys.push((start, src[start..].strip_suffix('\r').unwrap_or(&src[start..])));
    }
    let mut out = Vec::new();
    let mut k = 0;
    while k < phys.len() {
        let first = k;
        let mut text = Text::default();
        loop {
            let (off, s) = phys[k];
            text.push_text(&Text::from_source(file, off, s));
            k += 1;
            if k >= phys.len() {
                break;
            }
            let trimmed = text.s.trim_end_matches([' ', '\t', '\x0b', '\x0c', '\r']);
            if trimmed.ends_with('&') {
                let cut = trimmed.len() - 1;
                text.s.truncate(cut);
                text.spans.truncate(cut);
                continue;
            }
            if text.s.matches("\"\"\"").count() % 2 == 1 {
                let nl = Span::new(file, off + s.len(), off + s.len() + 1);
                text.push_str("\n", nl);
                continue;
            }
            break;
        }
        // a trailing '&' on the last line of the file is dropped too
        let trimmed_len = text.s.trim_end_matches([' ', '\t', '\x0b', '\x0c', '\r']).len();
        if text.s[..trimmed_len].ends_with('&') {
            text.s.truncate(trimmed_len - 1);
            text.spans.truncate(trimmed_len - 1);
        }
        out.push(LogicalLine { text, line: first + 1 });
    }
    out
}

/// Quote state while scanning a line character by character.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Quote {
    None,
    Single,
    Double,
    Triple,
}

/// Advance the quote state at byte `i` of `s`; returns how many bytes the
/// quote token consumed (1, 3) or 0 if `s[i]` is not a quote that changes state.
fn quote_step(s: &[u8], i: usize, q: &mut Quote) -> usize {
    let triple = s[i..].starts_with(b"\"\"\"");
    match *q {
        Quote::None => {
            if triple {
                *q = Quote::Triple;
                3
            } else if s[i] == b'"' {
                *q = Quote::Double;
                1
            } else if s[i] == b'\'' {
                *q = Quote::Single;
                1
            } else {
                0
            }
        }
        Quote::Triple => {
            if triple {
                *q = Quote::None;
                3
            } else {
                0
            }
        }
        Quote::Double => {
            if s[i] == b'"' {
                *q = Quote::None;
                1
            } else {
                0
            }
        }
        Quote::Single => {
            if s[i] == b'\'' {
                *q = Quote::None;
                1
            } else {
                0
            }
        }
    }
}

/// Remove a `#` comment that is not inside quotes.
pub fn strip_comment(t: &Text) -> Text {
    let b = t.s.as_bytes();
    let mut q = Quote::None;
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'#' && q == Quote::None {
            return t.slice(0, i);
        }
        let n = quote_step(b, i, &mut q);
        i += n.max(1);
    }
    t.clone()
}

/// What a `$` reference asks for.
#[derive(Clone, Debug, PartialEq)]
pub enum Reference {
    /// `$x` or `${name}`: a variable's value.
    Var(String),
    /// `$(expr)` or `$(expr:%fmt)`: an immediate expression and its format.
    Immediate(String, Option<String>),
}

/// Replace `$` references outside quotes. `resolve` gets each reference and
/// the span of the reference text; its result is inserted unscanned.
pub fn substitute(t: &Text, resolve: &mut dyn FnMut(&Reference, Span) -> Result<String>) -> Result<(Text, bool)> {
    let b = t.s.as_bytes();
    if !b.contains(&b'$') {
        return Ok((t.clone(), false));
    }
    let mut out = Text::default();
    let mut q = Quote::None;
    let mut i = 0;
    let mut changed = false;
    while i < b.len() {
        if b[i] == b'$' && q == Quote::None {
            let (reference, end) = if b.get(i + 1) == Some(&b'{') {
                match t.s[i + 2..].find('}') {
                    Some(k) => (Reference::Var(t.s[i + 2..i + 2 + k].to_string()), i + 3 + k),
                    None => {
                        return Err(Error::deck(t.span_of(i, b.len()), "invalid variable name: missing '}'"));
                    }
                }
            } else if b.get(i + 1) == Some(&b'(') {
                let mut depth = 0usize;
                let mut j = i + 2;
                let mut found = None;
                while j < b.len() {
                    match b[j] {
                        b'(' => depth += 1,
                        b')' if depth == 0 => {
                            found = Some(j);
                            break;
                        }
                        b')' => depth -= 1,
                        _ => {}
                    }
                    j += 1;
                }
                let Some(j) = found else {
                    return Err(Error::deck(t.span_of(i, b.len()), "invalid immediate variable: missing ')'"));
                };
                let inner = &t.s[i + 2..j];
                let r = match inner.rfind(':') {
                    Some(c) if inner[c + 1..].starts_with('%') => Reference::Immediate(inner[..c].to_string(), Some(inner[c + 1..].to_string())),
                    _ => Reference::Immediate(inner.to_string(), None),
                };
                (r, j + 1)
            } else {
                match t.s[i + 1..].chars().next() {
                    Some(c) => (Reference::Var(c.to_string()), i + 1 + c.len_utf8()),
                    None => return Err(Error::deck(t.span_of(i, i + 1), "invalid variable name: '$' at end of line")),
                }
            };
            let span = t.span_of(i, end);
            let value = resolve(&reference, span)?;
            out.push_str(&value, span);
            changed = true;
            i = end;
            continue;
        }
        let n = quote_step(b, i, &mut q).max(1);
        // copy whole characters
        let mut e = i + n;
        while e < b.len() && !t.s.is_char_boundary(e) {
            e += 1;
        }
        out.push_range(t, i, e);
        i = e;
    }
    Ok((out, changed))
}

/// One word of a line with per-byte spans.
#[derive(Clone, Debug, PartialEq)]
pub struct RawWord {
    /// The word's text (quotes removed).
    pub text: Text,
    /// Whether it was quoted.
    pub quoted: bool,
}

impl RawWord {
    /// The public form of the word.
    pub fn to_word(&self) -> super::Word {
        super::Word { text: self.text.s.clone(), span: self.text.span(), quoted: self.quoted }
    }
}

fn is_blank(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\n' | b'\x0b' | b'\x0c' | b'\r')
}

/// Split a (substituted) line into words, removing quotes.
pub fn split_words(t: &Text) -> Result<Vec<RawWord>> {
    let b = t.s.as_bytes();
    let mut words = Vec::new();
    let mut i = 0;
    loop {
        while i < b.len() && is_blank(b[i]) {
            i += 1;
        }
        if i >= b.len() {
            break;
        }
        let (qlen, close): (usize, &[u8]) = if b[i..].starts_with(b"\"\"\"") {
            (3, b"\"\"\"")
        } else if b[i] == b'"' {
            (1, b"\"")
        } else if b[i] == b'\'' {
            (1, b"'")
        } else {
            (0, b"")
        };
        if qlen > 0 {
            let body = i + qlen;
            let rel = t.s.as_bytes()[body..].windows(close.len()).position(|w| w == close);
            let Some(rel) = rel else {
                return Err(Error::deck(t.span_of(i, i + qlen), "unbalanced quotes in input line"));
            };
            let end = body + rel;
            let after = end + qlen;
            if after < b.len() && !is_blank(b[after]) {
                return Err(Error::deck(t.span_of(end, after + 1), "input line quote not followed by white-space"));
            }
            let mut text = t.slice(body, end);
            if text.s.is_empty() {
                // an empty word keeps the span of its quotes
                text.spans = vec![t.span_of(i, after)];
            }
            words.push(RawWord { text, quoted: true });
            i = after;
        } else {
            let start = i;
            while i < b.len() && !is_blank(b[i]) {
                i += 1;
            }
            words.push(RawWord { text: t.slice(start, i), quoted: false });
        }
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ll(s: &str) -> Vec<String> {
        logical_lines(FileId(0), s).into_iter().map(|l| l.text.s).collect()
    }

    #[test]
    fn ampersand_joins_without_space() {
        assert_eq!(ll("print \"x&\ny\"\nz\n"), vec!["print \"xy\"", "z"]);
        assert_eq!(ll("a b &  \r\nc\r\n"), vec!["a b c"]);
    }

    #[test]
    fn triple_quotes_span_lines() {
        assert_eq!(ll("print \"\"\"a\nb\"\"\"\nc"), vec!["print \"\"\"a\nb\"\"\"", "c"]);
    }

    #[test]
    fn comments_respect_quotes() {
        let t = Text::from_source(FileId(0), 0, "print 'a # b' # c");
        assert_eq!(strip_comment(&t).s, "print 'a # b' ");
        let t = Text::from_source(FileId(0), 0, "x it's # no comment");
        assert_eq!(strip_comment(&t).s, "x it's # no comment");
    }

    #[test]
    fn words_and_spans() {
        let t = Text::from_source(FileId(0), 10, "a  \"b c\" '' d");
        let w = split_words(&t).unwrap();
        let texts: Vec<&str> = w.iter().map(|w| w.text.s.as_str()).collect();
        assert_eq!(texts, vec!["a", "b c", "", "d"]);
        assert_eq!(w[1].to_word().span, Span::new(FileId(0), 14, 17));
        assert_eq!(w[2].to_word().span, Span::new(FileId(0), 19, 21));
        assert!(split_words(&Text::from_source(FileId(0), 0, "a \"b")).is_err());
        assert!(split_words(&Text::from_source(FileId(0), 0, "a \"b\"c")).is_err());
    }
}
