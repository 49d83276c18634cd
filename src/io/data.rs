//! LAMMPS data files for `atom_style sphere` (LIGGGHTS `granular`): a reader
//! and a writer that reproduces `write_data`.
//!
//! Facts (LAMMPS 29 Sep 2021 and LIGGGHTS 3.8.0 `write_data`, see
//! tests/data/io/lmp_data.sphere and lig_data.sphere):
//! - LAMMPS prints every number in the shortest form that reads back exactly
//!   ({fmt} `{}`), heads the atoms with `Atoms # sphere`, and writes the title
//!   `LAMMPS data file via write_data, version 29 Sep 2021, timestep = N`.
//! - LIGGGHTS prints floats with `%-1.16e` and writes a bare `Atoms` header.
//! - Atom lines: `id type diameter density x y z ix iy iz`; velocity lines:
//!   `id vx vy vz wx wy wz`. Atoms are written in storage order (not sorted).

use crate::error::{Error, Result};
use crate::io::cfmt::{fmt_e16, fmt_shortest};
use crate::io::dump::Engine;
use crate::script::source::Span;
use std::path::Path;

/// One atom of a sphere data file.
#[derive(Clone, Debug, PartialEq)]
pub struct DataAtom {
    /// Atom ID.
    pub id: u64,
    /// Atom type (1-based).
    pub kind: u32,
    /// Diameter (length units).
    pub diameter: f64,
    /// Density (mass/length^3); LAMMPS: mass itself when diameter is 0.
    pub density: f64,
    /// Position.
    pub x: [f64; 3],
    /// Image flags (0 when the file has none).
    pub image: [i32; 3],
    /// Velocity (0 when there is no Velocities section).
    pub v: [f64; 3],
    /// Angular velocity.
    pub omega: [f64; 3],
}

/// Contents of a sphere data file.
#[derive(Clone, Debug, PartialEq)]
pub struct DataFile {
    /// First line.
    pub title: String,
    /// `N atom types`.
    pub atom_types: u32,
    /// xlo ylo zlo.
    pub lo: [f64; 3],
    /// xhi yhi zhi.
    pub hi: [f64; 3],
    /// xy xz yz of a triclinic box.
    pub tilt: Option<[f64; 3]>,
    /// Per-type masses from a `Masses` section (type, mass), if present.
    pub masses: Vec<(u32, f64)>,
    /// Atoms in file order.
    pub atoms: Vec<DataAtom>,
    /// Whether the file had a Velocities section.
    pub has_velocities: bool,
}

fn strip_comment(l: &str) -> &str {
    l.split('#').next().unwrap_or("").trim()
}

/// Parse data-file text; `name` is used in messages (`name:line: ...`).
pub fn parse_data(text: &str, name: &str) -> Result<DataFile> {
    let err = |line: usize, m: String| Error::usage(format!("{name}:{line}: {m}"));
    let lines: Vec<&str> = text.lines().collect();
    let mut df = DataFile {
        title: lines.first().map_or(String::new(), |l| l.trim_end().to_string()),
        atom_types: 0,
        lo: [-0.5; 3],
        hi: [0.5; 3],
        tilt: None,
        masses: Vec::new(),
        atoms: Vec::new(),
        has_velocities: false,
    };
    let mut natoms: Option<usize> = None;
    let mut i = 1;
    // Header.
    while i < lines.len() {
        let l = strip_comment(lines[i]);
        if l.is_empty() {
            i += 1;
            continue;
        }
        let w: Vec<&str> = l.split_whitespace().collect();
        let num = |s: &str| s.parse::<f64>().map_err(|_| err(i + 1, format!("'{s}' is not a number")));
        let count = |s: &str| s.parse::<usize>().map_err(|_| err(i + 1, format!("'{s}' is not a count")));
        match w.as_slice() {
            [n, "atoms"] => natoms = Some(count(n)?),
            [n, "atom", "types"] => df.atom_types = u32::try_from(count(n)?).map_err(|_| err(i + 1, "too many atom types".into()))?,
            [a, b, "xlo", "xhi"] => (df.lo[0], df.hi[0]) = (num(a)?, num(b)?),
            [a, b, "ylo", "yhi"] => (df.lo[1], df.hi[1]) = (num(a)?, num(b)?),
            [a, b, "zlo", "zhi"] => (df.lo[2], df.hi[2]) = (num(a)?, num(b)?),
            [a, b, c, "xy", "xz", "yz"] => df.tilt = Some([num(a)?, num(b)?, num(c)?]),
            [n, "bonds" | "angles" | "dihedrals" | "impropers"] | [n, _, "types"] => {
                if count(n)? != 0 {
                    return Err(err(i + 1, format!("'{l}': atom_style sphere has no bonded interactions")));
                }
            }
            [n, "extra", ..] => {
                count(n)?;
            }
            _ if w[0].chars().next().is_some_and(|c| c.is_ascii_alphabetic()) => break,
            _ => return Err(err(i + 1, format!("unknown header line '{l}'"))),
        }
        i += 1;
    }
    let natoms = natoms.ok_or_else(|| err(i.min(lines.len()), "the header has no 'N atoms' line".into()))?;
    let mut vel_seen = false;
    let mut index: std::collections::HashMap<u64, usize> = std::collections::HashMap::new();
    // Sections.
    while i < lines.len() {
        let raw = lines[i];
        let head = raw.trim();
        if head.is_empty() {
            i += 1;
            continue;
        }
        let (title, hint) = match head.split_once('#') {
            Some((t, h)) => (t.trim(), h.trim()),
            None => (head, ""),
        };
        let sec_line = i + 1;
        let rows = match title {
            "Atoms" => {
                if !hint.is_empty() && hint != "sphere" && hint != "granular" {
                    return Err(err(sec_line, format!("Atoms section is for atom_style '{hint}', expected sphere")));
                }
                natoms
            }
            "Velocities" => natoms,
            "Masses" => df.atom_types as usize,
            "Pair Coeffs" | "PairIJ Coeffs" => {
                return Err(err(sec_line, format!("section '{title}' is not supported; give pair coefficients in the deck")))
            }
            _ => return Err(err(sec_line, format!("unknown or unsupported section '{title}'"))),
        };
        i += 1;
        let mut got = 0;
        while got < rows {
            let Some(l) = lines.get(i) else {
                return Err(err(i, format!("section '{title}' ends after {got} of {rows} lines")));
            };
            let l = strip_comment(l);
            i += 1;
            if l.is_empty() {
                continue;
            }
            let w: Vec<&str> = l.split_whitespace().collect();
            let f = |k: usize| -> Result<f64> { w[k].parse::<f64>().map_err(|_| err(i, format!("'{}' is not a number", w[k]))) };
            let int = |k: usize| -> Result<i64> { w[k].parse::<i64>().map_err(|_| err(i, format!("'{}' is not an integer", w[k]))) };
            match title {
                "Atoms" => {
                    if w.len() != 7 && w.len() != 10 {
                        return Err(err(
                            i,
                            format!("an atom_style sphere line has 7 or 10 values (id type diameter density x y z [ix iy iz]), found {}", w.len()),
                        ));
                    }
                    let id = u64::try_from(int(0)?).map_err(|_| err(i, format!("bad atom id '{}'", w[0])))?;
                    let kind = u32::try_from(int(1)?).map_err(|_| err(i, format!("bad atom type '{}'", w[1])))?;
                    if kind == 0 || kind > df.atom_types {
                        return Err(err(i, format!("atom type {kind} is outside 1..{}", df.atom_types)));
                    }
                    let mut image = [0; 3];
                    if w.len() == 10 {
                        for k in 0..3 {
                            image[k] = i32::try_from(int(7 + k)?).map_err(|_| err(i, "image flag out of range".into()))?;
                        }
                    }
                    df.atoms.push(DataAtom {
                        id,
                        kind,
                        diameter: f(2)?,
                        density: f(3)?,
                        x: [f(4)?, f(5)?, f(6)?],
                        image,
                        v: [0.0; 3],
                        omega: [0.0; 3],
                    });
                }
                "Velocities" => {
                    if w.len() != 7 {
                        return Err(err(i, format!("a sphere velocity line has 7 values (id vx vy vz wx wy wz), found {}", w.len())));
                    }
                    let id = int(0)?;
                    if index.len() != df.atoms.len() {
                        index = df.atoms.iter().enumerate().map(|(k, a)| (a.id, k)).collect();
                    }
                    let k = u64::try_from(id)
                        .ok()
                        .and_then(|id| index.get(&id).copied())
                        .ok_or_else(|| err(i, format!("velocity for unknown atom id {id}")))?;
                    let a = &mut df.atoms[k];
                    a.v = [f(1)?, f(2)?, f(3)?];
                    a.omega = [f(4)?, f(5)?, f(6)?];
                    vel_seen = true;
                }
                _ => {
                    if w.len() < 2 {
                        return Err(err(i, "a Masses line needs 'type mass'".into()));
                    }
                    let t = u32::try_from(int(0)?).map_err(|_| err(i, format!("bad atom type '{}'", w[0])))?;
                    df.masses.push((t, f(1)?));
                }
            }
            got += 1;
        }
    }
    if df.atoms.len() != natoms {
        return Err(err(lines.len(), format!("header says {natoms} atoms but there is no Atoms section")));
    }
    df.has_velocities = vel_seen;
    Ok(df)
}

/// Read a sphere data file.
pub fn read_data(path: impl AsRef<Path>) -> Result<DataFile> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(Span::DUMMY, format!("cannot read '{}'", path.display()), &e))?;
    parse_data(&String::from_utf8_lossy(&bytes), &path.display().to_string())
}

/// The text `write_data` of `engine` produces for `df` at `timestep` (the
/// title line is regenerated; `df.title` is not used).
pub fn format_data(df: &DataFile, engine: Engine, timestep: u64) -> String {
    let num: fn(f64) -> String = match engine {
        Engine::Lammps => fmt_shortest,
        Engine::Liggghts => fmt_e16,
    };
    let mut o = String::new();
    match engine {
        Engine::Lammps => o.push_str(&format!("LAMMPS data file via write_data, version 29 Sep 2021, timestep = {timestep}\n")),
        Engine::Liggghts => {
            o.push_str(&format!("LAMMPS data file via write_data, version Version LIGGGHTS-PUBLIC 3.8.0 (written by demx), timestep = {timestep}\n"))
        }
    }
    o.push_str(&format!("\n{} atoms\n{} atom types\n\n", df.atoms.len(), df.atom_types));
    for (k, n) in ["x", "y", "z"].iter().enumerate() {
        o.push_str(&format!("{} {} {n}lo {n}hi\n", num(df.lo[k]), num(df.hi[k])));
    }
    if let Some([a, b, c]) = df.tilt {
        o.push_str(&format!("{} {} {} xy xz yz\n", num(a), num(b), num(c)));
    }
    o.push_str(match engine {
        Engine::Lammps => "\nAtoms # sphere\n\n",
        Engine::Liggghts => "\nAtoms\n\n",
    });
    for a in &df.atoms {
        o.push_str(&format!(
            "{} {} {} {} {} {} {} {} {} {}\n",
            a.id,
            a.kind,
            num(a.diameter),
            num(a.density),
            num(a.x[0]),
            num(a.x[1]),
            num(a.x[2]),
            a.image[0],
            a.image[1],
            a.image[2]
        ));
    }
    o.push_str("\nVelocities\n\n");
    for a in &df.atoms {
        o.push_str(&format!(
            "{} {} {} {} {} {} {}\n",
            a.id,
            num(a.v[0]),
            num(a.v[1]),
            num(a.v[2]),
            num(a.omega[0]),
            num(a.omega[1]),
            num(a.omega[2])
        ));
    }
    o
}

/// Write `df` as `engine`'s `write_data` would.
pub fn write_data(path: impl AsRef<Path>, df: &DataFile, engine: Engine, timestep: u64) -> Result<()> {
    let path = path.as_ref();
    std::fs::write(path, format_data(df, engine, timestep)).map_err(|e| Error::io(Span::DUMMY, format!("cannot write '{}'", path.display()), &e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_lines_are_located_errors() {
        let t = "title\n1 atoms\n1 atom types\n0 1 xlo xhi\n\nAtoms # sphere\n\n1 1 0.1 2500 0.5 0.5\n";
        let e = parse_data(t, "d").unwrap_err().message();
        assert!(e.starts_with("d:8: an atom_style sphere line has 7 or 10 values"), "{e}");
        let t = "title\n1 atoms\n1 atom types\n\nAtoms # atomic\n\n1 1 0 0 0\n";
        assert!(parse_data(t, "d").unwrap_err().message().contains("atom_style 'atomic'"));
        let t = "title\n2 atoms\n1 atom types\n\nAtoms\n\n1 1 0.1 1 0 0 0\n";
        assert!(parse_data(t, "d").unwrap_err().message().contains("ends after 1 of 2"));
        for cut in 0..t.len() {
            let _ = parse_data(&t[..cut], "d");
        }
    }
}
