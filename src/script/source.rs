//! Source files of a deck and spans into them.
//!
//! Every token demx reads keeps a [`Span`] into the original text, also after
//! `${var}` substitution (the span then covers the reference the person wrote),
//! so diagnostics can point at what the person wrote.

use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};

/// Index of a file in the [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct FileId(pub u32);

/// A byte range in one source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Span {
    /// File the range belongs to.
    pub file: FileId,
    /// First byte.
    pub start: u32,
    /// One past the last byte.
    pub end: u32,
}

impl Span {
    /// A span from `start` to `end` in `file`.
    pub fn new(file: FileId, start: usize, end: usize) -> Span {
        Span { file, start: start as u32, end: end.max(start) as u32 }
    }
    /// The smallest span covering both (same file assumed; else `self`).
    pub fn to(self, other: Span) -> Span {
        if self.file != other.file {
            return self;
        }
        Span { file: self.file, start: self.start.min(other.start), end: self.end.max(other.end) }
    }
    /// Span of no particular place (command-line arguments, generated text).
    pub const DUMMY: Span = Span { file: FileId(u32::MAX), start: 0, end: 0 };
    /// Whether this span points into a real file.
    pub fn is_real(&self) -> bool {
        self.file.0 != u32::MAX
    }
}

/// One loaded source file.
#[derive(Debug)]
pub struct SourceFile {
    /// Path as the deck or the command line named it.
    pub path: PathBuf,
    /// Text, decoded as UTF-8 where valid, else byte-per-char Latin-1.
    pub text: String,
    /// Byte offsets of line starts.
    line_starts: Vec<usize>,
}

impl SourceFile {
    fn new(path: PathBuf, text: String) -> SourceFile {
        let mut line_starts = vec![0];
        for (i, b) in text.bytes().enumerate() {
            if b == b'\n' {
                line_starts.push(i + 1);
            }
        }
        SourceFile { path, text, line_starts }
    }
    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.line_starts[line];
        let col = self.text[start..offset].chars().count() + 1;
        (line + 1, col)
    }
    /// Text of 1-based line `line` without its line ending.
    pub fn line_text(&self, line: usize) -> &str {
        let start = self.line_starts[line - 1];
        let end = self.line_starts.get(line).copied().unwrap_or(self.text.len());
        self.text[start..end].trim_end_matches(['\n', '\r'])
    }
}

/// Decode bytes as UTF-8, falling back to Latin-1 for invalid files, so that
/// decks with stray non-UTF-8 bytes in comments still read.
pub fn decode(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}

/// All files read while interpreting a deck. Cheap to clone (shared).
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: Arc<RwLock<Vec<Arc<SourceFile>>>>,
}

impl SourceMap {
    /// An empty map.
    pub fn new() -> SourceMap {
        SourceMap::default()
    }
    /// Add text under a path; returns its id.
    pub fn add(&self, path: impl Into<PathBuf>, text: String) -> FileId {
        let mut files = self.files.write().expect("source map lock");
        files.push(Arc::new(SourceFile::new(path.into(), text)));
        FileId(files.len() as u32 - 1)
    }
    /// Read a file from disk and add it.
    pub fn load(&self, path: &Path) -> std::io::Result<FileId> {
        let bytes = std::fs::read(path)?;
        Ok(self.add(path.to_path_buf(), decode(&bytes)))
    }
    /// The file behind an id.
    pub fn get(&self, id: FileId) -> Option<Arc<SourceFile>> {
        self.files.read().expect("source map lock").get(id.0 as usize).cloned()
    }
    /// `file:line:col` of a span, or `None` for a dummy span.
    pub fn location(&self, span: Span) -> Option<(PathBuf, usize, usize)> {
        let f = self.get(span.file)?;
        let (l, c) = f.line_col(span.start as usize);
        Some((f.path.clone(), l, c))
    }
}
