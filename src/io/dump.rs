//! LAMMPS/LIGGGHTS text dumps (`dump custom`, `dump atom`): a streaming
//! reader (plain or gzip, detected by magic bytes) and a writer that follows
//! either engine's conventions byte for byte.
//!
//! Facts the writer reproduces (checked against LAMMPS 29 Sep 2021 and
//! LIGGGHTS 3.8.0 on tiny decks, see tests/data/io/):
//! - LAMMPS writes box bounds with `%-1.16e`, LIGGGHTS with `%g`.
//! - LIGGGHTS ends the `ITEM: ATOMS` column list and every atom line with a
//!   space; LAMMPS does not.
//! - Default per-atom formats in both: `%d` for integer columns (id, type,
//!   mol, proc, procp1, ix, iy, iz), `%g` for everything else.
//! - A triclinic box is written as `ITEM: BOX BOUNDS xy xz yz pp pp pp` with
//!   bounding-box extents (`xlo + min(0,xy,xz,xy+xz)` ...) and the tilt as a
//!   third number on each line.
//! - `dump atom` (LAMMPS only; LIGGGHTS 3.8 has no such style) writes
//!   `id type xs ys zs` (scaled) or `id type x y z` with `scale no`, plus
//!   `ix iy iz` with `image yes`.
//! - `dump_modify format`: a per-column format beats `format int/float`,
//!   which beats `format line`, which beats the default. LAMMPS joins the
//!   formatted words with single spaces; LIGGGHTS appends a space to each.

use crate::error::{Error, Result};
use crate::io::cfmt::{fmt_e16, fmt_g6, CArg, CFormat};
use crate::script::source::Span;
use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

/// Which engine's file conventions to follow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Engine {
    /// LAMMPS 29 Sep 2021.
    Lammps,
    /// LIGGGHTS 3.8.
    Liggghts,
}

/// Simulation box of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxBounds {
    /// Lower corner (for a triclinic box: xlo, ylo, zlo of the parallelepiped,
    /// not of the bounding box written in the file).
    pub lo: [f64; 3],
    /// Upper corner (xhi, yhi, zhi; same remark).
    pub hi: [f64; 3],
    /// Tilt factors xy, xz, yz of a triclinic box.
    pub tilt: Option<[f64; 3]>,
    /// Boundary flags per dimension as written, e.g. `["pp", "pp", "fm"]`.
    pub boundary: [String; 3],
}

impl BoxBounds {
    /// An orthogonal box with boundary flags such as `"pp pp fm"`.
    pub fn orthogonal(lo: [f64; 3], hi: [f64; 3], boundary: &str) -> BoxBounds {
        let mut b = ["pp".to_string(), "pp".to_string(), "pp".to_string()];
        for (i, w) in boundary.split_whitespace().take(3).enumerate() {
            b[i] = w.to_string();
        }
        BoxBounds { lo, hi, tilt: None, boundary: b }
    }

    /// The three `lo hi [tilt]` lines of the file: bounding-box extents for a
    /// triclinic box.
    pub fn file_bounds(&self) -> [[f64; 2]; 3] {
        let [xlo, ylo, zlo] = self.lo;
        let [xhi, yhi, zhi] = self.hi;
        match self.tilt {
            None => [[xlo, xhi], [ylo, yhi], [zlo, zhi]],
            Some([xy, xz, yz]) => {
                let xmin = 0f64.min(xy).min(xz).min(xy + xz);
                let xmax = 0f64.max(xy).max(xz).max(xy + xz);
                [[xlo + xmin, xhi + xmax], [ylo + 0f64.min(yz), yhi + 0f64.max(yz)], [zlo, zhi]]
            }
        }
    }

    /// Inverse of [`BoxBounds::file_bounds`].
    fn from_file_bounds(v: [[f64; 3]; 3], tilt: bool, boundary: [String; 3]) -> BoxBounds {
        if !tilt {
            return BoxBounds { lo: [v[0][0], v[1][0], v[2][0]], hi: [v[0][1], v[1][1], v[2][1]], tilt: None, boundary };
        }
        let (xy, xz, yz) = (v[0][2], v[1][2], v[2][2]);
        let xmin = 0f64.min(xy).min(xz).min(xy + xz);
        let xmax = 0f64.max(xy).max(xz).max(xy + xz);
        BoxBounds {
            lo: [v[0][0] - xmin, v[1][0] - 0f64.min(yz), v[2][0]],
            hi: [v[0][1] - xmax, v[1][1] - 0f64.max(yz), v[2][1]],
            tilt: Some([xy, xz, yz]),
            boundary,
        }
    }

    /// Scaled (fractional) coordinates of `x`, computed as LAMMPS does.
    pub fn to_scaled(&self, x: [f64; 3]) -> [f64; 3] {
        let prd = [self.hi[0] - self.lo[0], self.hi[1] - self.lo[1], self.hi[2] - self.lo[2]];
        let d = [x[0] - self.lo[0], x[1] - self.lo[1], x[2] - self.lo[2]];
        match self.tilt {
            None => [d[0] * (1.0 / prd[0]), d[1] * (1.0 / prd[1]), d[2] * (1.0 / prd[2])],
            Some([xy, xz, yz]) => {
                let h0 = 1.0 / prd[0];
                let h1 = 1.0 / prd[1];
                let h2 = 1.0 / prd[2];
                let h3 = -yz / (prd[1] * prd[2]);
                let h4 = (yz * xy - prd[1] * xz) / (prd[0] * prd[1] * prd[2]);
                let h5 = -xy / (prd[0] * prd[1]);
                [h0 * d[0] + h5 * d[1] + h4 * d[2], h1 * d[1] + h3 * d[2], h2 * d[2]]
            }
        }
    }

    /// Cartesian coordinates of scaled coordinates `s`.
    pub fn from_scaled(&self, s: [f64; 3]) -> [f64; 3] {
        let prd = [self.hi[0] - self.lo[0], self.hi[1] - self.lo[1], self.hi[2] - self.lo[2]];
        let [xy, xz, yz] = self.tilt.unwrap_or([0.0; 3]);
        [prd[0] * s[0] + xy * s[1] + xz * s[2] + self.lo[0], prd[1] * s[1] + yz * s[2] + self.lo[1], prd[2] * s[2] + self.lo[2]]
    }
}

/// One snapshot of a dump.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Timestep number.
    pub timestep: u64,
    /// Simulated time (`ITEM: TIME`, LAMMPS `dump_modify time yes`), if written.
    pub time: Option<f64>,
    /// Number of atoms (rows).
    pub natoms: usize,
    /// Box of this frame.
    pub bounds: BoxBounds,
    /// Column names from `ITEM: ATOMS`.
    pub columns: Vec<String>,
    /// Values, row-major: atom `i`, column `j` at `i * columns.len() + j`.
    pub values: Vec<f64>,
}

impl Frame {
    /// Index of the column called `name`.
    pub fn col(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }
    /// Value of column `col` of row `atom_row` (None if out of range).
    pub fn get(&self, atom_row: usize, col: usize) -> Option<f64> {
        let nc = self.columns.len();
        if col >= nc {
            return None;
        }
        self.values.get(atom_row * nc + col).copied()
    }
    /// All values of row `atom_row`.
    pub fn row(&self, atom_row: usize) -> Option<&[f64]> {
        let nc = self.columns.len();
        self.values.get(atom_row * nc..(atom_row + 1) * nc)
    }
    /// Row of the atom whose `id` column equals `id`.
    pub fn row_of_id(&self, id: u64) -> Option<usize> {
        let c = self.col("id")?;
        (0..self.natoms).find(|&r| self.get(r, c) == Some(id as f64))
    }
    /// All values of column `name`, in row order.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.col(name)?;
        Some((0..self.natoms).filter_map(|r| self.get(r, c)).collect())
    }
}

/// Streaming reader over the frames of one dump file; yields `Result<Frame>`.
///
/// After the first error the iterator ends. A file that ends inside a frame
/// (a killed run) yields all complete frames, then one error naming the
/// frame and its timestep; [`DumpReader::truncated`] then returns true.
pub struct DumpReader {
    input: Box<dyn BufRead>,
    path: String,
    line_no: usize,
    buf: String,
    /// A line read ahead (the `ITEM:` that ended the previous item).
    pending: Option<String>,
    frames: usize,
    done: bool,
    truncated: bool,
    parse_values: bool,
    gzip: bool,
}

enum ReadErr {
    /// Input ended inside a frame.
    Truncated(String),
    /// Anything else.
    Bad(Error),
}

impl DumpReader {
    /// Open `path` (gzip detected by its magic bytes).
    pub fn open(path: impl AsRef<Path>) -> Result<DumpReader> {
        let path = path.as_ref();
        let f = File::open(path).map_err(|e| Error::io(Span::DUMMY, format!("cannot read '{}'", path.display()), &e))?;
        let mut br = BufReader::with_capacity(1 << 16, f);
        let head = br.fill_buf().map_err(|e| Error::io(Span::DUMMY, format!("cannot read '{}'", path.display()), &e))?;
        let gzip = head.len() >= 2 && head[0] == 0x1f && head[1] == 0x8b;
        let input: Box<dyn BufRead> =
            if gzip { Box::new(BufReader::with_capacity(1 << 16, flate2::bufread::MultiGzDecoder::new(br))) } else { Box::new(br) };
        Ok(DumpReader::from_reader(input, &path.display().to_string(), gzip))
    }

    /// Read from any buffered text source; `name` is used in messages.
    pub fn from_reader(input: Box<dyn BufRead>, name: &str, gzip: bool) -> DumpReader {
        DumpReader {
            input,
            path: name.to_string(),
            line_no: 0,
            buf: String::new(),
            pending: None,
            frames: 0,
            done: false,
            truncated: false,
            parse_values: true,
            gzip,
        }
    }

    /// Whether the input ended inside a frame (known once iteration ended).
    pub fn truncated(&self) -> bool {
        self.truncated
    }

    /// Whether the file is gzip-compressed.
    pub fn is_gzip(&self) -> bool {
        self.gzip
    }

    /// Next line without its line end; None at end of input. A gzip stream
    /// cut short (killed run) counts as end of input.
    fn line(&mut self) -> std::result::Result<Option<String>, ReadErr> {
        if let Some(p) = self.pending.take() {
            return Ok(Some(p));
        }
        self.buf.clear();
        let n = match self.input.read_line(&mut self.buf) {
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => 0,
            Err(e) if e.kind() == std::io::ErrorKind::InvalidData && !self.gzip => {
                return Err(ReadErr::Bad(Error::usage(format!("{}:{}: not a text dump (invalid UTF-8)", self.path, self.line_no + 1))))
            }
            Err(e) => return Err(ReadErr::Bad(Error::usage(format!("{}:{}: read error: {e}", self.path, self.line_no + 1)))),
        };
        if n == 0 {
            return Ok(None);
        }
        self.line_no += 1;
        let complete = self.buf.ends_with('\n');
        let t = self.buf.trim_end_matches(['\n', '\r']);
        let mut s = t.to_string();
        if !complete {
            // A last line without newline: mark it so callers can tell a cut line.
            s.push('\u{0}');
        }
        Ok(Some(s))
    }

    fn bad(&self, msg: impl std::fmt::Display) -> ReadErr {
        ReadErr::Bad(Error::usage(format!("{}:{}: {msg}", self.path, self.line_no)))
    }

    fn cut(&self, ts: Option<u64>, what: &str) -> ReadErr {
        let frame = self.frames + 1;
        let ts = ts.map_or(String::new(), |t| format!(" (timestep {t})"));
        ReadErr::Truncated(format!(
            "{}:{}: frame {frame}{ts} is truncated: {what}; the {} complete frame(s) before it are usable",
            self.path, self.line_no, self.frames
        ))
    }

    /// Line that must exist inside a frame.
    fn need(&mut self, ts: Option<u64>, what: &str) -> std::result::Result<String, ReadErr> {
        match self.line()? {
            Some(l) if l.ends_with('\u{0}') => {
                // Unterminated last line: the frame cannot be complete, except
                // for a frame of zero atoms ending in its ATOMS line.
                let l = l.trim_end_matches('\u{0}').to_string();
                if l.starts_with("ITEM: ATOMS") {
                    Ok(l)
                } else {
                    Err(self.cut(ts, "the file ends in the middle of a line"))
                }
            }
            Some(l) => Ok(l),
            None => Err(self.cut(ts, &format!("file ends before {what}"))),
        }
    }

    fn read_frame(&mut self) -> std::result::Result<Option<Frame>, ReadErr> {
        // Skip blank lines between frames.
        let first = loop {
            match self.line()? {
                None => return Ok(None),
                Some(l) if l.trim_matches(|c: char| c.is_whitespace() || c == '\u{0}').is_empty() => continue,
                Some(l) => break l.trim_end_matches('\u{0}').to_string(),
            }
        };
        if first.trim() != "ITEM: TIMESTEP" {
            return Err(self.bad(format!("expected 'ITEM: TIMESTEP', found '{}'", short(&first))));
        }
        let tl = self.need(None, "the timestep value")?;
        let timestep: u64 = match tl.trim().parse::<u64>() {
            Ok(t) => t,
            Err(_) => match tl.trim().parse::<f64>() {
                Ok(v) if v >= 0.0 && v.fract() == 0.0 && v < 1.8e19 => v as u64,
                _ => return Err(self.bad(format!("bad timestep '{}'", short(&tl)))),
            },
        };
        let ts = Some(timestep);
        let mut time = None;
        let mut natoms: Option<usize> = None;
        let mut bounds: Option<BoxBounds> = None;
        loop {
            let item = self.need(ts, "'ITEM: ATOMS'")?;
            let item_t = item.trim();
            let Some(rest) = item_t.strip_prefix("ITEM:") else {
                return Err(self.bad(format!("expected an 'ITEM:' line, found '{}'", short(&item))));
            };
            let rest = rest.trim();
            if rest == "TIME" {
                let l = self.need(ts, "the time value")?;
                time = Some(l.trim().parse::<f64>().map_err(|_| self.bad(format!("bad time '{}'", short(&l))))?);
            } else if rest == "UNITS" {
                self.need(ts, "the units value")?;
            } else if rest == "NUMBER OF ATOMS" {
                let l = self.need(ts, "the number of atoms")?;
                natoms = Some(l.trim().parse::<usize>().map_err(|_| self.bad(format!("bad number of atoms '{}'", short(&l))))?);
            } else if let Some(flags) = rest.strip_prefix("BOX BOUNDS") {
                let words: Vec<&str> = flags.split_whitespace().collect();
                let tilt = words.len() >= 3 && words[..3] == ["xy", "xz", "yz"];
                let bflags = if tilt { &words[3..] } else { &words[..] };
                let mut boundary = ["pp".to_string(), "pp".to_string(), "pp".to_string()];
                if !bflags.is_empty() {
                    if bflags.len() != 3 {
                        return Err(self.bad(format!("expected 3 boundary flags after 'BOX BOUNDS', found '{}'", flags.trim())));
                    }
                    for (i, w) in bflags.iter().enumerate() {
                        boundary[i] = w.to_string();
                    }
                }
                let mut v = [[0.0; 3]; 3];
                let want = if tilt { 3 } else { 2 };
                for row in v.iter_mut() {
                    let l = self.need(ts, "the end of the box bounds")?;
                    let nums: Vec<&str> = l.split_whitespace().collect();
                    if nums.len() != want {
                        return Err(self.bad(format!("expected {want} numbers in box bounds, found '{}'", short(&l))));
                    }
                    for (k, n) in nums.iter().enumerate() {
                        row[k] = n.parse::<f64>().map_err(|_| self.bad(format!("bad number '{}' in box bounds", short(n))))?;
                    }
                }
                bounds = Some(BoxBounds::from_file_bounds(v, tilt, boundary));
            } else if let Some(cols) = rest.strip_prefix("ATOMS") {
                let columns: Vec<String> = cols.split_whitespace().map(str::to_string).collect();
                let Some(n) = natoms else {
                    return Err(self.bad("'ITEM: ATOMS' before 'ITEM: NUMBER OF ATOMS'"));
                };
                let Some(bounds) = bounds.take() else {
                    return Err(self.bad("'ITEM: ATOMS' before 'ITEM: BOX BOUNDS'"));
                };
                if columns.is_empty() && n > 0 {
                    return Err(self.bad("'ITEM: ATOMS' names no columns"));
                }
                let nc = columns.len();
                // The header's count and columns are claims: a 4 kB file
                // claiming 16.7M atoms x 2,015 columns aborted on this
                // capacity. Reserve at most 1M values; the rows actually read
                // grow the rest.
                let mut values = Vec::with_capacity(if self.parse_values { n.saturating_mul(nc).min(1 << 20) } else { 0 });
                for row in 0..n {
                    let raw = match self.line()? {
                        Some(l) => l,
                        None => return Err(self.cut(ts, &format!("{row} of {n} atom lines present"))),
                    };
                    if raw.ends_with('\u{0}') {
                        // Last line of the file lacks its newline: a cut write
                        // unless it is the very last atom line and complete.
                        let l = raw.trim_end_matches('\u{0}');
                        let cnt = l.split_ascii_whitespace().count();
                        if row + 1 < n || cnt != nc {
                            return Err(self.cut(ts, &format!("{row} of {n} atom lines present, the next one is cut")));
                        }
                        if self.parse_values {
                            self.parse_row(l, &mut values)?;
                        }
                        continue;
                    }
                    if raw.starts_with("ITEM:") {
                        // Next frame started early: this frame lost lines.
                        return Err(self.bad(format!("expected {n} atom lines, found {row} before '{}'", short(&raw))));
                    }
                    if self.parse_values {
                        let before = values.len();
                        self.parse_row(&raw, &mut values)?;
                        if values.len() - before != nc {
                            return Err(self.bad(format!("expected {nc} values, found {}", values.len() - before)));
                        }
                    } else {
                        let cnt = raw.split_ascii_whitespace().count();
                        if cnt != nc {
                            return Err(self.bad(format!("expected {nc} values, found {cnt}")));
                        }
                    }
                }
                self.frames += 1;
                return Ok(Some(Frame { timestep, time, natoms: n, bounds, columns, values }));
            } else {
                // Unknown item (e.g. a newer engine's): skip until the next ITEM.
                loop {
                    match self.line()? {
                        None => return Err(self.cut(ts, "file ends before 'ITEM: ATOMS'")),
                        Some(l) if l.starts_with("ITEM:") => {
                            self.pending = Some(l);
                            self.line_no -= 1;
                            break;
                        }
                        Some(_) => {}
                    }
                }
            }
        }
    }

    fn parse_row(&self, l: &str, values: &mut Vec<f64>) -> std::result::Result<(), ReadErr> {
        for w in l.split_ascii_whitespace() {
            match w.parse::<f64>() {
                Ok(v) => values.push(v),
                Err(_) => return Err(self.bad(format!("'{}' is not a number", short(w)))),
            }
        }
        Ok(())
    }
}

fn short(s: &str) -> String {
    let s = s.trim_end_matches('\u{0}');
    if s.chars().count() > 60 {
        format!("{}...", s.chars().take(60).collect::<String>())
    } else {
        s.to_string()
    }
}

impl Iterator for DumpReader {
    type Item = Result<Frame>;
    fn next(&mut self) -> Option<Result<Frame>> {
        if self.done {
            return None;
        }
        match self.read_frame() {
            Ok(Some(f)) => Some(Ok(f)),
            Ok(None) => {
                self.done = true;
                None
            }
            Err(ReadErr::Truncated(m)) => {
                self.done = true;
                self.truncated = true;
                Some(Err(Error::usage(m)))
            }
            Err(ReadErr::Bad(e)) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }
}

/// Read every complete frame of `path` into memory (small files and tests).
/// A truncated last frame is an error; use [`DumpReader`] to keep going.
pub fn read_all(path: impl AsRef<Path>) -> Result<Vec<Frame>> {
    DumpReader::open(path)?.collect()
}

/// Summary of a dump file, for `demx dump info FILE`.
#[derive(Clone, Debug, PartialEq)]
pub struct DumpInfo {
    /// File as given.
    pub path: String,
    /// gzip-compressed?
    pub gzip: bool,
    /// Timestep of each complete frame.
    pub timesteps: Vec<u64>,
    /// Atom count of each complete frame.
    pub atoms: Vec<usize>,
    /// Columns of the first frame.
    pub columns: Vec<String>,
    /// Whether later frames have other columns.
    pub columns_change: bool,
    /// Box of the first frame.
    pub first_box: Option<BoxBounds>,
    /// The truncation message if the file ends inside a frame.
    pub truncated: Option<String>,
}

impl DumpInfo {
    /// Number of complete frames.
    pub fn frames(&self) -> usize {
        self.timesteps.len()
    }

    /// Human-readable multi-line summary.
    pub fn render(&self) -> String {
        let mut o = String::new();
        o.push_str(&format!("file: {}{}\n", self.path, if self.gzip { " (gzip)" } else { "" }));
        let n = self.frames();
        o.push_str(&format!("frames: {n} complete"));
        if let (Some(a), Some(b)) = (self.timesteps.first(), self.timesteps.last()) {
            o.push_str(&format!(", timesteps {a} .. {b}"));
            if n > 2 {
                let d = self.timesteps[1].wrapping_sub(self.timesteps[0]);
                if self.timesteps.windows(2).all(|w| w[1].wrapping_sub(w[0]) == d) {
                    o.push_str(&format!(" every {d}"));
                } else {
                    o.push_str(" (irregular spacing)");
                }
            }
        }
        o.push('\n');
        if let (Some(lo), Some(hi)) = (self.atoms.iter().min(), self.atoms.iter().max()) {
            if lo == hi {
                o.push_str(&format!("atoms: {lo} per frame\n"));
            } else {
                o.push_str(&format!("atoms: {} .. {} (first frame {}, last frame {})\n", lo, hi, self.atoms[0], self.atoms[self.atoms.len() - 1]));
            }
        }
        if !self.columns.is_empty() {
            o.push_str(&format!("columns: {}{}\n", self.columns.join(" "), if self.columns_change { " (changes in later frames)" } else { "" }));
        }
        if let Some(b) = &self.first_box {
            o.push_str(&format!(
                "box: x [{}, {}] y [{}, {}] z [{}, {}] boundary {} {} {}",
                fmt_g6(b.lo[0]),
                fmt_g6(b.hi[0]),
                fmt_g6(b.lo[1]),
                fmt_g6(b.hi[1]),
                fmt_g6(b.lo[2]),
                fmt_g6(b.hi[2]),
                b.boundary[0],
                b.boundary[1],
                b.boundary[2]
            ));
            if let Some([xy, xz, yz]) = b.tilt {
                o.push_str(&format!(" tilt xy {} xz {} yz {}", fmt_g6(xy), fmt_g6(xz), fmt_g6(yz)));
            }
            o.push('\n');
        }
        match &self.truncated {
            Some(m) => o.push_str(&format!("truncated: yes: {m}\n")),
            None => o.push_str("truncated: no\n"),
        }
        o
    }
}

/// Scan `path` and summarise it. A truncated last frame is reported in the
/// result, not as an error; malformed content is an error.
pub fn info(path: impl AsRef<Path>) -> Result<DumpInfo> {
    let path = path.as_ref();
    let mut r = DumpReader::open(path)?;
    r.parse_values = false;
    let mut inf = DumpInfo {
        path: path.display().to_string(),
        gzip: r.is_gzip(),
        timesteps: Vec::new(),
        atoms: Vec::new(),
        columns: Vec::new(),
        columns_change: false,
        first_box: None,
        truncated: None,
    };
    while let Some(f) = r.next() {
        match f {
            Ok(f) => {
                if inf.timesteps.is_empty() {
                    inf.columns = f.columns.clone();
                    inf.first_box = Some(f.bounds.clone());
                } else if f.columns != inf.columns {
                    inf.columns_change = true;
                }
                inf.timesteps.push(f.timestep);
                inf.atoms.push(f.natoms);
            }
            Err(e) if r.truncated() => inf.truncated = Some(e.message()),
            Err(e) => return Err(e),
        }
    }
    Ok(inf)
}

// ---------------------------------------------------------------- writer

/// Dump style.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DumpStyle {
    /// `dump custom` with the configured columns.
    Custom,
    /// `dump atom` (LAMMPS): id type xs ys zs [ix iy iz].
    Atom,
}

/// One `dump_modify format ...` setting.
#[derive(Clone, Debug, PartialEq)]
pub enum FormatSpec {
    /// `format line "..."` (LIGGGHTS: `format "..."`): one word per column.
    Line(String),
    /// `format float F` (LAMMPS).
    Float(String),
    /// `format int F` (LAMMPS).
    Int(String),
    /// `format N F` (LAMMPS): column N, counted from 1.
    Column(usize, String),
    /// `format none`: forget earlier settings.
    None,
}

/// Row order (`dump_modify sort`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SortBy {
    /// `sort id`.
    Id,
    /// `sort N` (column N from 1) ascending, `sort -N` descending.
    Column(usize, bool),
}

/// Everything that shapes the text of a dump.
#[derive(Clone, Debug, PartialEq)]
pub struct DumpOptions {
    /// Whose conventions.
    pub engine: Engine,
    /// custom or atom.
    pub style: DumpStyle,
    /// Columns of `dump custom` (ignored for `dump atom`).
    pub columns: Vec<String>,
    /// `dump_modify format` settings in the order given.
    pub formats: Vec<FormatSpec>,
    /// `dump_modify sort`.
    pub sort: Option<SortBy>,
    /// `dump_modify scale` (dump atom; default yes).
    pub scale: bool,
    /// `dump_modify image` (dump atom; default no).
    pub image: bool,
    /// `dump_modify pad N`: zero-pad the timestep that replaces `*`.
    pub pad: usize,
    /// `dump_modify first yes`: also write on the first step of a run.
    pub first: bool,
    /// `dump_modify append yes`: append instead of truncating.
    pub append: bool,
    /// Dump interval N.
    pub every: u64,
}

impl DumpOptions {
    /// Defaults of `dump ID group custom N file cols...` for `engine`.
    pub fn custom(engine: Engine, every: u64, columns: &[&str]) -> DumpOptions {
        DumpOptions {
            engine,
            style: DumpStyle::Custom,
            columns: columns.iter().map(|s| s.to_string()).collect(),
            formats: Vec::new(),
            sort: None,
            scale: true,
            image: false,
            pad: 0,
            first: false,
            append: false,
            every,
        }
    }
    /// Defaults of `dump ID group atom N file`.
    pub fn atom(engine: Engine, every: u64) -> DumpOptions {
        DumpOptions { style: DumpStyle::Atom, ..DumpOptions::custom(engine, every, &[]) }
    }
    /// The column names written in `ITEM: ATOMS`.
    pub fn output_columns(&self) -> Vec<String> {
        match self.style {
            DumpStyle::Custom => self.columns.clone(),
            DumpStyle::Atom => {
                let mut c: Vec<&str> = if self.scale { vec!["id", "type", "xs", "ys", "zs"] } else { vec!["id", "type", "x", "y", "z"] };
                if self.image {
                    c.extend(["ix", "iy", "iz"]);
                }
                c.into_iter().map(str::to_string).collect()
            }
        }
    }
}

/// Whether a `dump custom` column holds integers (printed with `%d`).
pub fn is_int_column(name: &str) -> bool {
    matches!(name, "id" | "mol" | "proc" | "procp1" | "type" | "ix" | "iy" | "iz")
}

enum Sink {
    Plain(std::io::BufWriter<File>),
    Gz(flate2::write::GzEncoder<std::io::BufWriter<File>>),
}

impl Sink {
    fn write_all(&mut self, b: &[u8]) -> std::io::Result<()> {
        match self {
            Sink::Plain(w) => w.write_all(b),
            Sink::Gz(w) => w.write_all(b),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Sink::Plain(w) => w.flush(),
            Sink::Gz(w) => w.flush(),
        }
    }
    fn finish(self) -> std::io::Result<()> {
        match self {
            Sink::Plain(mut w) => w.flush(),
            Sink::Gz(w) => w.finish().and_then(|mut f| f.flush()),
        }
    }
}

/// Writes frames like LAMMPS or LIGGGHTS `dump custom` / `dump atom`.
/// Every frame is flushed, so a killed run leaves all complete frames
/// readable (gzip: a sync flush per frame). A `*` in the file name makes one
/// file per frame with the timestep (padded to `pad` digits) in its place.
pub struct DumpWriter {
    path: PathBuf,
    opts: DumpOptions,
    formats: Vec<CFormat>,
    int_col: Vec<bool>,
    sink: Option<Sink>,
    frames: usize,
    text: String,
}

impl DumpWriter {
    /// Prepare a writer; opens the file now unless the name contains `*`.
    pub fn create(path: impl AsRef<Path>, opts: DumpOptions) -> Result<DumpWriter> {
        let path = path.as_ref().to_path_buf();
        if opts.style == DumpStyle::Atom && opts.engine == Engine::Liggghts {
            return Err(Error::usage("LIGGGHTS 3.8 has no 'dump atom' style (use 'dump custom')"));
        }
        if opts.style == DumpStyle::Custom && opts.columns.is_empty() {
            return Err(Error::usage("dump custom needs at least one column"));
        }
        let cols = opts.output_columns();
        let int_col: Vec<bool> = cols.iter().map(|c| is_int_column(c)).collect();
        let formats = build_formats(&cols, &int_col, &opts.formats)?;
        let mut w = DumpWriter { path, opts, formats, int_col, sink: None, frames: 0, text: String::new() };
        if !w.multi_file() {
            let p = w.path.clone();
            w.sink = Some(open_sink(&p, w.opts.append)?);
        }
        Ok(w)
    }

    fn multi_file(&self) -> bool {
        self.path.to_string_lossy().contains('*')
    }

    /// Options in effect.
    pub fn options(&self) -> &DumpOptions {
        &self.opts
    }

    /// Number of frames written.
    pub fn frames_written(&self) -> usize {
        self.frames
    }

    /// Whether a frame is due at `step` (multiple of `every`, or the first
    /// step of a run with `first yes`).
    pub fn is_due(&self, step: u64, first_step_of_run: bool) -> bool {
        (self.opts.every > 0 && step.is_multiple_of(self.opts.every)) || (self.opts.first && first_step_of_run)
    }

    /// File name a frame at `timestep` goes to.
    pub fn file_for(&self, timestep: u64) -> PathBuf {
        let s = self.path.to_string_lossy();
        if !s.contains('*') {
            return self.path.clone();
        }
        let ts = format!("{:0width$}", timestep, width = self.opts.pad);
        PathBuf::from(s.replacen('*', &ts, 1))
    }

    /// Write one frame. `frame.columns` must contain every input column:
    /// for `dump custom` the configured columns; for `dump atom` id, type and
    /// x y z (or xs ys zs), plus ix iy iz with `image yes` (0 if absent).
    pub fn write_frame(&mut self, frame: &Frame) -> Result<()> {
        let cols = self.opts.output_columns();
        let nc_in = frame.columns.len();
        if frame.values.len() != frame.natoms * nc_in {
            return Err(Error::usage(format!(
                "dump frame at timestep {} has {} values for {} atoms x {} columns",
                frame.timestep,
                frame.values.len(),
                frame.natoms,
                nc_in
            )));
        }
        // Build the output table (row-major, output columns).
        let nc = cols.len();
        let mut table = vec![0.0; frame.natoms * nc];
        match self.opts.style {
            DumpStyle::Custom => {
                for (j, c) in cols.iter().enumerate() {
                    let src = frame
                        .col(c)
                        .ok_or_else(|| Error::usage(format!("dump column '{c}' is missing from the frame at timestep {}", frame.timestep)))?;
                    for r in 0..frame.natoms {
                        table[r * nc + j] = frame.values[r * nc_in + src];
                    }
                }
            }
            DumpStyle::Atom => {
                let need = |n: &str| {
                    frame.col(n).ok_or_else(|| Error::usage(format!("dump atom needs column '{n}' (frame at timestep {})", frame.timestep)))
                };
                let (id, ty) = (need("id")?, need("type")?);
                let xyz = match (frame.col("x"), frame.col("y"), frame.col("z")) {
                    (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                    _ => None,
                };
                let sxyz = match (frame.col("xs"), frame.col("ys"), frame.col("zs")) {
                    (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                    _ => None,
                };
                if xyz.is_none() && sxyz.is_none() {
                    return Err(Error::usage(format!("dump atom needs columns x y z (or xs ys zs) (frame at timestep {})", frame.timestep)));
                }
                let img = [frame.col("ix"), frame.col("iy"), frame.col("iz")];
                for r in 0..frame.natoms {
                    let v = |c: usize| frame.values[r * nc_in + c];
                    let (c, scaled) = match xyz {
                        Some(c) => (c, false),
                        None => (sxyz.unwrap_or([id, id, id]), true),
                    };
                    let pos = [v(c[0]), v(c[1]), v(c[2])];
                    let out = match (self.opts.scale, scaled) {
                        (true, false) => frame.bounds.to_scaled(pos),
                        (false, true) => frame.bounds.from_scaled(pos),
                        _ => pos,
                    };
                    let row = &mut table[r * nc..(r + 1) * nc];
                    row[0] = v(id);
                    row[1] = v(ty);
                    row[2..5].copy_from_slice(&out);
                    if self.opts.image {
                        for k in 0..3 {
                            row[5 + k] = img[k].map_or(0.0, v);
                        }
                    }
                }
            }
        }
        let order = self.row_order(&table, nc, frame.natoms, &cols);
        self.text.clear();
        self.header(frame, &cols);
        let lig = self.opts.engine == Engine::Liggghts;
        for &r in &order {
            let row = &table[r * nc..(r + 1) * nc];
            for (j, &x) in row.iter().enumerate() {
                let arg = if self.int_col[j] && x.fract() == 0.0 && x.abs() < 9.2e18 { CArg::Int(x as i64) } else { CArg::Float(x) };
                self.formats[j].write(&mut self.text, &[arg]).map_err(Error::usage)?;
                if lig || j + 1 < nc {
                    self.text.push(' ');
                }
            }
            self.text.push('\n');
        }
        let file = self.file_for(frame.timestep);
        let mut sink = match self.sink.take() {
            Some(s) => s,
            None => open_sink(&file, self.opts.append)?,
        };
        let res = sink.write_all(self.text.as_bytes()).and_then(|_| sink.flush());
        res.map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", file.display()), &e))?;
        if self.multi_file() {
            sink.finish().map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", file.display()), &e))?;
        } else {
            self.sink = Some(sink);
        }
        self.frames += 1;
        Ok(())
    }

    fn row_order(&self, table: &[f64], nc: usize, n: usize, cols: &[String]) -> Vec<usize> {
        let mut order: Vec<usize> = (0..n).collect();
        let key = match self.opts.sort {
            None => return order,
            Some(SortBy::Id) => cols.iter().position(|c| c == "id").map(|c| (c, false)),
            Some(SortBy::Column(k, desc)) => (k >= 1 && k <= nc).then(|| (k - 1, desc)),
        };
        if let Some((c, desc)) = key {
            order.sort_by(|&a, &b| {
                let o = table[a * nc + c].total_cmp(&table[b * nc + c]);
                if desc {
                    o.reverse()
                } else {
                    o
                }
            });
        }
        order
    }

    fn header(&mut self, frame: &Frame, cols: &[String]) {
        let t = &mut self.text;
        let lig = self.opts.engine == Engine::Liggghts;
        t.push_str(&format!("ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\n", frame.timestep, frame.natoms));
        let b = &frame.bounds;
        t.push_str("ITEM: BOX BOUNDS ");
        if b.tilt.is_some() {
            t.push_str("xy xz yz ");
        }
        t.push_str(&format!("{} {} {}\n", b.boundary[0], b.boundary[1], b.boundary[2]));
        let fb = b.file_bounds();
        let num = |x: f64| if lig { fmt_g6(x) } else { fmt_e16(x) };
        for (k, lh) in fb.iter().enumerate() {
            t.push_str(&num(lh[0]));
            t.push(' ');
            t.push_str(&num(lh[1]));
            if let Some(tilt) = b.tilt {
                t.push(' ');
                t.push_str(&num(tilt[k]));
            }
            t.push('\n');
        }
        t.push_str("ITEM: ATOMS");
        for c in cols {
            t.push(' ');
            t.push_str(c);
        }
        if lig {
            t.push(' ');
        }
        t.push('\n');
    }

    /// Finish the file (gzip trailer); also done on drop.
    pub fn close(mut self) -> Result<()> {
        if let Some(s) = self.sink.take() {
            s.finish().map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", self.path.display()), &e))?;
        }
        Ok(())
    }
}

fn open_sink(path: &Path, append: bool) -> Result<Sink> {
    let f = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .append(append)
        .truncate(!append)
        .open(path)
        .map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", path.display()), &e))?;
    let w = std::io::BufWriter::with_capacity(1 << 16, f);
    if path.to_string_lossy().ends_with(".gz") {
        Ok(Sink::Gz(flate2::write::GzEncoder::new(w, flate2::Compression::default())))
    } else {
        Ok(Sink::Plain(w))
    }
}

/// Per-column formats after applying `dump_modify format` settings with
/// LAMMPS precedence: column > int/float > line > default.
fn build_formats(cols: &[String], int_col: &[bool], specs: &[FormatSpec]) -> Result<Vec<CFormat>> {
    let mut line: Option<Vec<String>> = None;
    let mut fint: Option<String> = None;
    let mut ffloat: Option<String> = None;
    let mut per: Vec<Option<String>> = vec![None; cols.len()];
    for s in specs {
        match s {
            FormatSpec::None => {
                line = None;
                fint = None;
                ffloat = None;
                per.iter_mut().for_each(|p| *p = None);
            }
            FormatSpec::Line(l) => {
                let words: Vec<String> = l.split_whitespace().map(str::to_string).collect();
                if words.len() < cols.len() {
                    return Err(Error::usage(format!("dump_modify format line \"{l}\" has {} words for {} columns", words.len(), cols.len())));
                }
                line = Some(words);
            }
            FormatSpec::Int(f) => fint = Some(f.clone()),
            FormatSpec::Float(f) => ffloat = Some(f.clone()),
            FormatSpec::Column(n, f) => {
                if *n == 0 || *n > cols.len() {
                    return Err(Error::usage(format!("dump_modify format {n}: there are only {} columns", cols.len())));
                }
                per[n - 1] = Some(f.clone());
            }
        }
    }
    let mut out = Vec::with_capacity(cols.len());
    for j in 0..cols.len() {
        let f: String = if let Some(p) = &per[j] {
            p.clone()
        } else if int_col[j] && fint.is_some() {
            fint.clone().unwrap_or_default()
        } else if !int_col[j] && ffloat.is_some() {
            ffloat.clone().unwrap_or_default()
        } else if let Some(l) = &line {
            l[j].clone()
        } else if int_col[j] {
            "%d".to_string()
        } else {
            "%g".to_string()
        };
        let cf = CFormat::parse(&f).map_err(|e| Error::usage(format!("dump_modify format for column '{}': {e}", cols[j])))?;
        if cf.arg_kinds().len() != 1 {
            return Err(Error::usage(format!("dump_modify format '{f}' for column '{}' must have exactly one conversion", cols[j])));
        }
        out.push(cf);
    }
    Ok(out)
}

/// A reader over in-memory bytes (plain or gzip), e.g. for tests.
pub fn reader_from_bytes(bytes: Vec<u8>, name: &str) -> DumpReader {
    let gzip = bytes.len() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b;
    let input: Box<dyn BufRead> = if gzip {
        Box::new(BufReader::new(flate2::read::MultiGzDecoder::new(std::io::Cursor::new(bytes))))
    } else {
        Box::new(BufReader::new(std::io::Cursor::new(bytes)))
    };
    DumpReader::from_reader(input, name, gzip)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp fm\n0 1\n0 1\n0 1\nITEM: ATOMS id type x \n1 1 0.5 \n2 1 0.25 \nITEM: TIMESTEP\n10\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp fm\n0 1\n0 1\n0 1\nITEM: ATOMS id type x\n1 1 0.5\n2 1 0.75\n";

    #[test]
    fn reads_frames_and_trailing_spaces() {
        let fr: Vec<Frame> = reader_from_bytes(TWO.as_bytes().to_vec(), "t").collect::<Result<_>>().unwrap();
        assert_eq!(fr.len(), 2);
        assert_eq!(fr[0].columns, ["id", "type", "x"]);
        assert_eq!(fr[1].get(1, 2), Some(0.75));
        assert_eq!(fr[1].timestep, 10);
        assert_eq!(fr[0].bounds.boundary[2], "fm");
    }

    #[test]
    fn every_prefix_is_frames_or_an_error_never_a_panic() {
        let b = TWO.as_bytes();
        for cut in 0..b.len() {
            let items: Vec<Result<Frame>> = reader_from_bytes(b[..cut].to_vec(), "t").collect();
            let ok = items.iter().filter(|r| r.is_ok()).count();
            assert!(ok <= 2);
            // Either it ends cleanly at a frame boundary or the last item is an error.
            if let Some(Err(e)) = items.last() {
                assert!(e.message().starts_with("t:"), "{}", e.message());
            }
        }
        // Random byte flips never panic.
        let mut seed = 12345u64;
        for _ in 0..2000 {
            let mut v = b.to_vec();
            for _ in 0..3 {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let i = (seed >> 33) as usize % v.len();
                v[i] = (seed >> 13) as u8;
            }
            let _: Vec<Result<Frame>> = reader_from_bytes(v, "t").collect();
        }
    }
}
