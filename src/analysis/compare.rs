//! `demx compare`: compare two runs (dump files, dump globs, or output
//! folders of `demx run` / `demx reference`) particle by id and frame by
//! timestep, with statistics that do not need matching trajectories; or run
//! a deck with demx and a reference engine and compare (see
//! [`super::compare_deck`]).
//!
//! Exit codes: 0 within tolerance, 1 not, 2 bad input.

use super::compare_stats::{frame_stats, ks_two_sample, speeds, FrameStats};
use crate::error::{Error, Result};
use crate::io::dump::{DumpReader, Frame};
use clap::Parser;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The columns of one frame that a comparison needs.
#[derive(Clone, Debug)]
pub struct Snap {
    /// Timestep.
    pub timestep: u64,
    /// Particle ids (row order).
    pub ids: Vec<u64>,
    /// Positions (x y z; xu yu zu; or unscaled xs ys zs).
    pub x: Vec<[f64; 3]>,
    /// Velocities, if dumped.
    pub v: Option<Vec<[f64; 3]>>,
    /// Angular velocities, if dumped.
    pub w: Option<Vec<[f64; 3]>>,
    /// Radii (from radius or diameter), if dumped.
    pub r: Option<Vec<f64>>,
    /// Masses, if dumped.
    pub m: Option<Vec<f64>>,
    /// Box lower corner.
    pub lo: [f64; 3],
    /// Box upper corner.
    pub hi: [f64; 3],
    /// Periodic dimensions whose positions are wrapped (minimum image applies).
    pub periodic: [bool; 3],
}

impl Snap {
    /// Build from a dump frame; None if it has no id or position columns.
    pub fn from_frame(f: &Frame) -> Option<Snap> {
        let idc = f.col("id")?;
        let c3 = |a: &str, b: &str, c: &str| Some([f.col(a)?, f.col(b)?, f.col(c)?]);
        let n = f.natoms;
        let v3 = |c: [usize; 3], r: usize| [f.get(r, c[0]).unwrap_or(0.0), f.get(r, c[1]).unwrap_or(0.0), f.get(r, c[2]).unwrap_or(0.0)];
        let (x, wrapped) = if let Some(c) = c3("x", "y", "z") {
            ((0..n).map(|r| v3(c, r)).collect::<Vec<_>>(), true)
        } else if let Some(c) = c3("xu", "yu", "zu") {
            ((0..n).map(|r| v3(c, r)).collect(), false)
        } else if let Some(c) = c3("xs", "ys", "zs") {
            ((0..n).map(|r| f.bounds.from_scaled(v3(c, r))).collect(), true)
        } else {
            return None;
        };
        let opt3 = |a, b, c| c3(a, b, c).map(|c| (0..n).map(|r| v3(c, r)).collect::<Vec<_>>());
        let r = match (f.column("radius"), f.column("diameter")) {
            (Some(r), _) => Some(r),
            (None, Some(d)) => Some(d.iter().map(|d| 0.5 * d).collect()),
            _ => None,
        };
        let mut periodic = [false; 3];
        for k in 0..3 {
            periodic[k] = wrapped && f.bounds.tilt.is_none() && f.bounds.boundary[k] == "pp";
        }
        Some(Snap {
            timestep: f.timestep,
            ids: (0..n).map(|r| f.get(r, idc).unwrap_or(-1.0).max(0.0) as u64).collect(),
            x,
            v: opt3("vx", "vy", "vz"),
            w: opt3("omegax", "omegay", "omegaz"),
            r,
            m: f.column("mass"),
            lo: f.bounds.lo,
            hi: f.bounds.hi,
            periodic,
        })
    }

    /// b - a with the minimum image across periodic dimensions.
    pub fn delta(&self, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        let mut d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        for k in 0..3 {
            let l = self.hi[k] - self.lo[k];
            if self.periodic[k] && l > 0.0 {
                d[k] -= l * (d[k] / l).round();
            }
        }
        d
    }
}

/// The frames of one run (one dump series).
#[derive(Clone, Debug)]
pub struct Series {
    /// Series name (file name, `*` for the timestep of multi-file dumps).
    pub name: String,
    /// Files read.
    pub files: Vec<PathBuf>,
    /// Frames sorted by timestep (the last one kept for repeated timesteps).
    pub snaps: Vec<Snap>,
    /// Remarks (truncated files, repeated timesteps, ...).
    pub notes: Vec<String>,
}

fn read_dump(path: &Path, out: &mut BTreeMap<u64, Snap>, notes: &mut Vec<String>) -> Result<()> {
    let rd = DumpReader::open(path)?;
    let mut any = false;
    for (k, fr) in rd.enumerate() {
        let fr = match fr {
            Ok(f) => f,
            Err(e) if any && e.message().contains("truncated") => {
                notes.push(e.message());
                break;
            }
            Err(e) => return Err(e),
        };
        any = true;
        let s = Snap::from_frame(&fr).ok_or_else(|| {
            Error::usage(format!("{}: frame at timestep {} has no id and x y z (or xu yu zu, xs ys zs) columns", path.display(), fr.timestep))
        })?;
        check_snap(path, k + 1, &fr, &s)?;
        if out.insert(s.timestep, s).is_some() {
            notes.push(format!("{}: timestep {} appears more than once; the last frame is used", path.display(), fr.timestep));
        }
    }
    Ok(())
}

/// A frame that cannot be compared is an input error (exit 2) naming the
/// file, the frame and the particle: ids that are not positive integers or
/// that repeat (matching by id would pair the wrong particles, and 999 of
/// 1000 ids set to 1 read as 999 lost particles and a PASS), positions,
/// velocities or radii that are not finite, negative radii.
fn check_snap(path: &Path, frame: usize, fr: &Frame, s: &Snap) -> Result<()> {
    let at = |row: usize| format!("{}: frame {frame} (timestep {}), atom line {}", path.display(), s.timestep, row + 1);
    if let Some(c) = fr.col("id") {
        let mut first: HashMap<u64, usize> = HashMap::with_capacity(s.ids.len());
        for row in 0..fr.natoms {
            let v = fr.get(row, c).unwrap_or(f64::NAN);
            if !(v >= 1.0 && v.fract() == 0.0 && v < 9.0e15) {
                return Err(Error::usage(format!("{}: id {v} is not a positive integer", at(row))));
            }
            if let Some(r0) = first.insert(v as u64, row) {
                let n = s.ids.iter().filter(|&&i| i == v as u64).count();
                return Err(Error::usage(format!(
                    "{}: particle id {} appears {n} times in the frame (first on atom line {}); ids must be unique to match particles",
                    at(row),
                    v as u64,
                    r0 + 1
                )));
            }
        }
    }
    let bad3 = |v: &[[f64; 3]]| v.iter().position(|p| p.iter().any(|c| !c.is_finite()));
    for (what, col) in [("position", Some(&s.x)), ("velocity", s.v.as_ref()), ("angular velocity", s.w.as_ref())] {
        if let Some(row) = col.and_then(|v| bad3(v)) {
            let p = col.map_or([0.0; 3], |v| v[row]);
            return Err(Error::usage(format!("{}: particle {} has a {what} that is not finite ({} {} {})", at(row), s.ids[row], p[0], p[1], p[2])));
        }
    }
    if let Some(row) = s.r.as_ref().and_then(|r| r.iter().position(|&r| !(r >= 0.0 && r.is_finite()))) {
        let r = s.r.as_ref().map_or(0.0, |r| r[row]);
        return Err(Error::usage(format!("{}: particle {} has radius {r}; radii must be finite and >= 0", at(row), s.ids[row])));
    }
    Ok(())
}

fn glob_match(pat: &[char], s: &[char]) -> bool {
    match pat.first() {
        None => s.is_empty(),
        Some('*') => (0..=s.len()).any(|k| glob_match(&pat[1..], &s[k..])),
        Some('?') => !s.is_empty() && glob_match(&pat[1..], &s[1..]),
        Some(c) => s.first() == Some(c) && glob_match(&pat[1..], &s[1..]),
    }
}

/// Series key of a file name: its last digit run becomes `*`.
fn series_key(name: &str) -> String {
    let b: Vec<char> = name.chars().collect();
    let Some(end) = b.iter().rposition(|c| c.is_ascii_digit()) else { return name.to_string() };
    let mut start = end;
    while start > 0 && b[start - 1].is_ascii_digit() {
        start -= 1;
    }
    format!("{}*{}", b[..start].iter().collect::<String>(), b[end + 1..].iter().collect::<String>())
}

fn series_from(name: String, files: Vec<PathBuf>) -> Result<Series> {
    let mut map = BTreeMap::new();
    let mut notes = vec![];
    for f in &files {
        read_dump(f, &mut map, &mut notes)?;
    }
    if map.is_empty() {
        return Err(Error::usage(format!("{}: no complete dump frames", name)));
    }
    Ok(Series { name, files, snaps: map.into_values().collect(), notes })
}

/// Load the runs named by `spec`: a dump file, a glob of dump files (one
/// series), or a folder (each group of dumps that differ only in one digit
/// run is one series).
pub fn load(spec: &str) -> Result<Vec<Series>> {
    let p = Path::new(spec);
    if p.is_dir() {
        let rd = std::fs::read_dir(p).map_err(|e| Error::usage(format!("cannot read folder '{spec}': {e}")))?;
        let mut files: Vec<PathBuf> = rd.flatten().map(|e| e.path()).filter(|f| f.is_file() && super::reference::looks_like_dump(f)).collect();
        files.sort();
        if files.is_empty() {
            return Err(Error::usage(format!("folder '{spec}' holds no dump files")));
        }
        let name_of = |f: &PathBuf| f.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let mut keys: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
        for f in &files {
            keys.entry(series_key(&name_of(f))).or_default().push(f.clone());
        }
        let mut out = vec![];
        for (k, fs) in keys {
            if fs.len() > 1 {
                out.push(series_from(k, fs)?);
            } else {
                for f in fs {
                    out.push(series_from(name_of(&f), vec![f])?);
                }
            }
        }
        return Ok(out);
    }
    let fname = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if fname.contains(['*', '?']) && !p.exists() {
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let pat: Vec<char> = fname.chars().collect();
        let rd = std::fs::read_dir(dir).map_err(|e| Error::usage(format!("cannot read folder '{}': {e}", dir.display())))?;
        let mut files: Vec<PathBuf> = rd
            .flatten()
            .map(|e| e.path())
            .filter(|f| f.is_file() && f.file_name().is_some_and(|n| glob_match(&pat, &n.to_string_lossy().chars().collect::<Vec<_>>())))
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(Error::usage(format!("'{spec}' matches no files")));
        }
        return Ok(vec![series_from(fname, files)?]);
    }
    if !p.is_file() {
        return Err(Error::usage(format!("'{spec}' is not a dump file, glob or folder")));
    }
    Ok(vec![series_from(fname, vec![p.to_path_buf()])?])
}

/// Pair series of two inputs: by name, or the only one of each.
pub fn pair_series(a: Vec<Series>, b: Vec<Series>) -> Result<Vec<(Series, Series)>> {
    if a.len() == 1 && b.len() == 1 {
        let mut a = a;
        let mut b = b;
        return Ok(vec![(a.remove(0), b.remove(0))]);
    }
    let mut out = vec![];
    let mut b = b;
    for sa in a {
        if let Some(k) = b.iter().position(|sb| sb.name == sa.name) {
            let sb = b.remove(k);
            out.push((sa, sb));
        }
    }
    if out.is_empty() {
        return Err(Error::usage("the two inputs have no dump series with the same name to compare"));
    }
    Ok(out)
}

/// How the verdict is reached.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Trajectory mode when at most 10 particles, statistics otherwise.
    Auto,
    /// Every matched frame within the trajectory tolerances.
    Trajectory,
    /// Trajectories reported, verdict from statistics (chaotic scenes).
    Statistics,
}

/// Tolerances and settings of a comparison.
#[derive(Clone, Debug, Serialize)]
pub struct CompareOptions {
    /// Position deviation, in particle diameters.
    pub tol_pos: f64,
    /// Velocity deviation relative to the largest speed of the frame in A.
    pub tol_vel: f64,
    /// Angular velocity deviation relative to the largest of the frame in A.
    pub tol_omega: f64,
    /// Kinetic energy deviation relative to the peak KE of A (statistics).
    pub tol_ke: f64,
    /// Centre-of-mass deviation in mean diameters (statistics).
    pub tol_com: f64,
    /// Mean coordination number deviation (statistics).
    pub tol_coord: f64,
    /// Density used for masses when a dump has no mass column (1 if None).
    pub density: Option<f64>,
    /// Diameter to use when a dump has no radius column.
    pub diameter: Option<f64>,
    /// Verdict mode.
    pub mode: Mode,
    /// Statistics mode: fail if trajectories diverge before this step.
    pub min_divergence: Option<u64>,
}

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            tol_pos: 1e-6,
            tol_vel: 1e-6,
            tol_omega: 1e-6,
            tol_ke: 0.03,
            tol_com: 0.05,
            tol_coord: 0.5,
            density: None,
            diameter: None,
            mode: Mode::Auto,
            min_divergence: None,
        }
    }
}

/// Comparison of one frame (timestep present in both runs).
#[derive(Clone, Debug, Default, Serialize)]
pub struct FrameRow {
    /// Timestep.
    pub timestep: u64,
    /// Particles in A, in B, in both.
    pub n_a: usize,
    /// Particles in B.
    pub n_b: usize,
    /// Particles matched by id.
    pub matched: usize,
    /// RMS position deviation (diameters).
    pub pos_rms: f64,
    /// Largest position deviation (diameters).
    pub pos_max: f64,
    /// Id of the particle with the largest position deviation.
    pub pos_max_id: Option<u64>,
    /// RMS velocity deviation (m/s).
    pub vel_rms: f64,
    /// Largest velocity deviation (m/s).
    pub vel_max: f64,
    /// Largest velocity deviation / largest speed of A in the frame.
    pub vel_rel: f64,
    /// Id with the largest velocity deviation.
    pub vel_max_id: Option<u64>,
    /// Largest angular velocity deviation (rad/s).
    pub omega_max: f64,
    /// Largest angular velocity deviation / largest |omega| of A.
    pub omega_rel: f64,
    /// Id with the largest angular velocity deviation.
    pub omega_max_id: Option<u64>,
    /// Statistics of A.
    pub a: FrameStats,
    /// Statistics of B.
    pub b: FrameStats,
    /// |com_a - com_b| in mean diameters.
    pub com_dev: f64,
    /// Speed distributions: KS statistic D and p-value.
    pub ks_d: Option<f64>,
    /// KS p-value.
    pub ks_p: Option<f64>,
    /// Whether this frame exceeds a trajectory tolerance.
    pub exceeds: bool,
}

/// Result of comparing two series.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// Series name and files of A.
    pub a: String,
    /// Series of B.
    pub b: String,
    /// Mode used for the verdict.
    pub mode: Mode,
    /// Tolerances.
    pub options: CompareOptions,
    /// Per common frame.
    pub frames: Vec<FrameRow>,
    /// Timesteps only in A.
    pub frames_only_a: Vec<u64>,
    /// Timesteps only in B.
    pub frames_only_b: Vec<u64>,
    /// Particles only in A (id, first timestep where B lacks it).
    pub only_a: Vec<(u64, u64)>,
    /// Particles only in B.
    pub only_b: Vec<(u64, u64)>,
    /// Ids present in A's first frame and gone from its last.
    pub lost_a: usize,
    /// Same for B.
    pub lost_b: usize,
    /// First frame exceeding the trajectory tolerance: timestep, particle,
    /// deviation (diameters).
    pub divergence: Option<(u64, Option<u64>, f64)>,
    /// Largest position deviation over all frames (diameters) and its frame and particle.
    pub worst: (f64, u64, Option<u64>),
    /// Largest KE deviation relative to A's peak KE.
    pub ke_dev: f64,
    /// Largest centre-of-mass deviation (mean diameters).
    pub com_dev: f64,
    /// Largest coordination number deviation.
    pub coord_dev: f64,
    /// Smallest speed KS p-value over frames.
    pub ks_p_min: Option<f64>,
    /// Why the comparison failed (empty: passed).
    pub failures: Vec<String>,
    /// Remarks.
    pub notes: Vec<String>,
    /// Passed?
    pub pass: bool,
}

fn n3(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn frame_row(a: &Snap, b: &Snap, o: &CompareOptions, density: f64, only_a: &mut Vec<(u64, u64)>, only_b: &mut Vec<(u64, u64)>) -> FrameRow {
    let mut row = FrameRow { timestep: a.timestep, n_a: a.ids.len(), n_b: b.ids.len(), ..Default::default() };
    let bmap: HashMap<u64, usize> = b.ids.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let amap: HashSet<u64> = a.ids.iter().copied().collect();
    for &id in &a.ids {
        if !bmap.contains_key(&id) && !only_a.iter().any(|x| x.0 == id) {
            only_a.push((id, a.timestep));
        }
    }
    for &id in &b.ids {
        if !amap.contains(&id) && !only_b.iter().any(|x| x.0 == id) {
            only_b.push((id, b.timestep));
        }
    }
    let vmax = a.v.as_ref().map_or(0.0, |v| v.iter().map(|x| n3(*x)).fold(0.0, f64::max));
    let wmax = a.w.as_ref().map_or(0.0, |v| v.iter().map(|x| n3(*x)).fold(0.0, f64::max));
    let (mut s2, mut v2) = (0.0, 0.0);
    for (i, &id) in a.ids.iter().enumerate() {
        let Some(&j) = bmap.get(&id) else { continue };
        row.matched += 1;
        let d = a.r.as_ref().map(|r| 2.0 * r[i]).or(b.r.as_ref().map(|r| 2.0 * r[j])).or(o.diameter).unwrap_or(1.0);
        let d = if d > 0.0 { d } else { 1.0 };
        let e = n3(a.delta(a.x[i], b.x[j])) / d;
        s2 += e * e;
        if e > row.pos_max || row.pos_max_id.is_none() {
            row.pos_max = e;
            row.pos_max_id = Some(id);
        }
        if let (Some(va), Some(vb)) = (&a.v, &b.v) {
            let e = n3(sub(va[i], vb[j]));
            v2 += e * e;
            if e > row.vel_max || row.vel_max_id.is_none() {
                row.vel_max = e;
                row.vel_max_id = Some(id);
            }
        }
        if let (Some(wa), Some(wb)) = (&a.w, &b.w) {
            let e = n3(sub(wa[i], wb[j]));
            if e > row.omega_max || row.omega_max_id.is_none() {
                row.omega_max = e;
                row.omega_max_id = Some(id);
            }
        }
    }
    if row.matched > 0 {
        row.pos_rms = (s2 / row.matched as f64).sqrt();
        row.vel_rms = (v2 / row.matched as f64).sqrt();
    }
    row.vel_rel = if vmax > 0.0 { row.vel_max / vmax } else { row.vel_max };
    row.omega_rel = if wmax > 0.0 { row.omega_max / wmax } else { row.omega_max };
    row.a = frame_stats(a, density);
    row.b = frame_stats(b, density);
    let dmean = a.r.as_ref().filter(|r| !r.is_empty()).map(|r| 2.0 * r.iter().sum::<f64>() / r.len() as f64).or(o.diameter).unwrap_or(1.0);
    row.com_dev = n3(a.delta(row.a.com, row.b.com)) / if dmean > 0.0 { dmean } else { 1.0 };
    if let Some((d, p)) = ks_two_sample(&speeds(a), &speeds(b)) {
        row.ks_d = Some(d);
        row.ks_p = Some(p);
    }
    row.exceeds = row.pos_max > o.tol_pos || row.vel_rel > o.tol_vel || row.omega_rel > o.tol_omega;
    row
}

/// Compare two series frame by frame.
pub fn compare_series(a: &Series, b: &Series, o: &CompareOptions) -> Comparison {
    let density = o.density.unwrap_or(1.0);
    let bmap: HashMap<u64, &Snap> = b.snaps.iter().map(|s| (s.timestep, s)).collect();
    let amap: HashSet<u64> = a.snaps.iter().map(|s| s.timestep).collect();
    let mut only_a = vec![];
    let mut only_b = vec![];
    let mut frames = vec![];
    let mut frames_only_a = vec![];
    for sa in &a.snaps {
        match bmap.get(&sa.timestep) {
            Some(sb) => frames.push(frame_row(sa, sb, o, density, &mut only_a, &mut only_b)),
            None => frames_only_a.push(sa.timestep),
        }
    }
    let frames_only_b: Vec<u64> = b.snaps.iter().map(|s| s.timestep).filter(|t| !amap.contains(t)).collect();
    let lost = |s: &Series| -> usize {
        match (s.snaps.first(), s.snaps.last()) {
            (Some(f), Some(l)) => {
                let last: HashSet<u64> = l.ids.iter().copied().collect();
                f.ids.iter().filter(|id| !last.contains(id)).count()
            }
            _ => 0,
        }
    };
    let nmax = a.snaps.iter().chain(&b.snaps).map(|s| s.ids.len()).max().unwrap_or(0);
    let mode = match o.mode {
        Mode::Auto if nmax <= 10 => Mode::Trajectory,
        Mode::Auto => Mode::Statistics,
        m => m,
    };
    let divergence = frames.iter().find(|f| f.exceeds).map(|f| (f.timestep, f.pos_max_id, f.pos_max));
    let mut worst = (0.0, 0, None);
    for f in &frames {
        if f.pos_max > worst.0 || worst.2.is_none() {
            worst = (f.pos_max, f.timestep, f.pos_max_id);
        }
    }
    let peak = frames.iter().map(|f| f.a.ke + f.a.ke_rot).fold(0.0, f64::max);
    let ke_dev =
        frames.iter().map(|f| ((f.a.ke + f.a.ke_rot) - (f.b.ke + f.b.ke_rot)).abs() / if peak > 0.0 { peak } else { 1.0 }).fold(0.0, f64::max);
    let com_dev = frames.iter().map(|f| f.com_dev).fold(0.0, f64::max);
    let coord_dev = frames.iter().map(|f| (f.a.coordination - f.b.coordination).abs()).fold(0.0, f64::max);
    let ks_p_min = frames.iter().filter_map(|f| f.ks_p).reduce(f64::min);
    let mut failures = vec![];
    if frames.is_empty() {
        failures.push("no timestep is in both runs".to_string());
    }
    if !frames_only_a.is_empty() || !frames_only_b.is_empty() {
        failures.push(format!("frames missing: {} only in A, {} only in B", frames_only_a.len(), frames_only_b.len()));
    }
    let counts_differ = frames.iter().find(|f| f.a.count != f.b.count);
    match mode {
        Mode::Trajectory | Mode::Auto => {
            if !only_a.is_empty() || !only_b.is_empty() {
                failures.push(format!("particle sets differ: {} only in A, {} only in B", only_a.len(), only_b.len()));
            }
            if let Some((t, id, e)) = divergence {
                let f = frames.iter().find(|f| f.timestep == t);
                let extra = f.map_or(String::new(), |f| format!(" (velocity {:.3e}, omega {:.3e} relative)", f.vel_rel, f.omega_rel));
                failures.push(format!(
                    "trajectories differ from timestep {t}: particle {} is off by {e:.3e} diameters{extra}",
                    id.map_or("?".to_string(), |i| i.to_string())
                ));
            }
        }
        Mode::Statistics => {
            if let Some(f) = counts_differ {
                failures.push(format!("particle count differs at timestep {}: {} vs {}", f.timestep, f.a.count, f.b.count));
            } else if !only_a.is_empty() || !only_b.is_empty() {
                // same counts, other ids: particles vanished from one run and
                // others appeared, which no deck explains
                failures.push(format!("particle ids differ: {} only in A, {} only in B", only_a.len(), only_b.len()));
            }
            if ke_dev > o.tol_ke {
                failures.push(format!("kinetic energy differs by {ke_dev:.3e} of the peak (tolerance {})", o.tol_ke));
            }
            if com_dev > o.tol_com {
                failures.push(format!("centre of mass differs by {com_dev:.3e} diameters (tolerance {})", o.tol_com));
            }
            if coord_dev > o.tol_coord {
                failures.push(format!("coordination number differs by {coord_dev:.3} (tolerance {})", o.tol_coord));
            }
            if let (Some(min), Some((t, _, _))) = (o.min_divergence, divergence) {
                if t < min {
                    failures.push(format!("trajectories diverge at timestep {t}, before {min}"));
                }
            }
        }
    }
    let mut notes: Vec<String> = a.notes.iter().chain(&b.notes).cloned().collect();
    let no_mass = a.snaps.first().is_some_and(|s| s.m.is_none()) && o.density.is_none();
    if no_mass {
        notes.push("no mass column and no --density: kinetic energies are per unit density (kg/m^3)".into());
    }
    if a.snaps.first().is_some_and(|s| s.r.is_none()) && b.snaps.first().is_some_and(|s| s.r.is_none()) {
        notes.push(format!(
            "no radius column: deviations in units of {}",
            o.diameter.map_or("length (use --diameter)".to_string(), |d| format!("d = {d}"))
        ));
    }
    let name = |s: &Series| if s.files.len() == 1 { s.files[0].display().to_string() } else { format!("{} ({} files)", s.name, s.files.len()) };
    Comparison {
        a: name(a),
        b: name(b),
        mode,
        options: o.clone(),
        pass: failures.is_empty(),
        frames,
        frames_only_a,
        frames_only_b,
        lost_a: lost(a),
        lost_b: lost(b),
        only_a,
        only_b,
        divergence,
        worst,
        ke_dev,
        com_dev,
        coord_dev,
        ks_p_min,
        failures,
        notes,
    }
}

fn ids_text(v: &[(u64, u64)]) -> String {
    let mut s: Vec<String> = v.iter().take(10).map(|(id, t)| format!("{id} (from step {t})")).collect();
    if v.len() > 10 {
        s.push(format!("... {} more", v.len() - 10));
    }
    s.join(", ")
}

fn opt_id(id: Option<u64>) -> String {
    id.map_or("-".into(), |i| i.to_string())
}

/// Human-readable report.
pub fn render(c: &Comparison) -> String {
    let mut o = String::new();
    o.push_str(&format!("A: {}\nB: {}\n", c.a, c.b));
    o.push_str(&format!(
        "frames: {} in both, {} only in A, {} only in B; mode: {:?}\n",
        c.frames.len(),
        c.frames_only_a.len(),
        c.frames_only_b.len(),
        c.mode
    ));
    if !c.frames_only_a.is_empty() {
        o.push_str(&format!("  timesteps only in A: {:?}\n", &c.frames_only_a[..c.frames_only_a.len().min(10)]));
    }
    if !c.frames_only_b.is_empty() {
        o.push_str(&format!("  timesteps only in B: {:?}\n", &c.frames_only_b[..c.frames_only_b.len().min(10)]));
    }
    if !c.only_a.is_empty() {
        o.push_str(&format!("particles only in A: {}\n", ids_text(&c.only_a)));
    }
    if !c.only_b.is_empty() {
        o.push_str(&format!("particles only in B: {}\n", ids_text(&c.only_b)));
    }
    if c.lost_a + c.lost_b > 0 {
        o.push_str(&format!("particles lost during the run: {} in A, {} in B\n", c.lost_a, c.lost_b));
    }
    o.push_str(&format!(
        "{:>10} {:>6} {:>6} {:>10} {:>10} {:>7} {:>10} {:>10} {:>11} {:>11} {:>6} {:>6} {:>8}\n",
        "timestep", "n_A", "n_B", "pos_rms/d", "pos_max/d", "id", "vel_rel", "omega_rel", "KE_A", "KE_B", "Z_A", "Z_B", "KS_p"
    ));
    let n = c.frames.len();
    let step = (n / 40).max(1);
    for (k, f) in c.frames.iter().enumerate() {
        let special = c.divergence.is_some_and(|d| d.0 == f.timestep) || f.timestep == c.worst.1;
        if k % step != 0 && k + 1 != n && !special {
            continue;
        }
        o.push_str(&format!(
            "{:>10} {:>6} {:>6} {:>10.3e} {:>10.3e} {:>7} {:>10.3e} {:>10.3e} {:>11.4e} {:>11.4e} {:>6.2} {:>6.2} {:>8}{}\n",
            f.timestep,
            f.n_a,
            f.n_b,
            f.pos_rms,
            f.pos_max,
            opt_id(f.pos_max_id),
            f.vel_rel,
            f.omega_rel,
            f.a.ke + f.a.ke_rot,
            f.b.ke + f.b.ke_rot,
            f.a.coordination,
            f.b.coordination,
            f.ks_p.map_or("-".into(), |p| format!("{p:.3}")),
            if f.exceeds { " *" } else { "" }
        ));
    }
    if step > 1 {
        o.push_str(&format!("({} of {} frames shown; --csv or --json for all)\n", n.div_ceil(step), n));
    }
    match c.divergence {
        Some((t, id, e)) => {
            let f = c.frames.iter().find(|f| f.timestep == t);
            o.push_str(&format!(
                "divergence: first frame beyond tolerance at timestep {t} (particle {}, {e:.3e} diameters{})\n",
                opt_id(id),
                f.map_or(String::new(), |f| format!(
                    "; velocity {:.3e} (particle {}), omega {:.3e} (particle {}) relative",
                    f.vel_rel,
                    opt_id(f.vel_max_id),
                    f.omega_rel,
                    opt_id(f.omega_max_id)
                ))
            ))
        }
        None => o.push_str("divergence: none (every common frame within the trajectory tolerances)\n"),
    }
    o.push_str(&format!(
        "worst position deviation {:.3e} diameters (particle {}, timestep {}); KE deviation {:.3e} of peak; centre of mass {:.3e} d; coordination {:.3}; speed KS min p {}\n",
        c.worst.0,
        opt_id(c.worst.2),
        c.worst.1,
        c.ke_dev,
        c.com_dev,
        c.coord_dev,
        c.ks_p_min.map_or("-".into(), |p| format!("{p:.3}"))
    ));
    o.push_str(&format!(
        "tolerances: position {} d, velocity {} rel, omega {} rel{}\n",
        c.options.tol_pos,
        c.options.tol_vel,
        c.options.tol_omega,
        if c.mode == Mode::Statistics {
            format!("; KE {} of peak, centre of mass {} d, coordination {}", c.options.tol_ke, c.options.tol_com, c.options.tol_coord)
        } else {
            String::new()
        }
    ));
    for n in &c.notes {
        o.push_str(&format!("note: {n}\n"));
    }
    if c.pass {
        o.push_str("verdict: PASS\n");
    } else {
        for f in &c.failures {
            o.push_str(&format!("FAIL: {f}\n"));
        }
        o.push_str("verdict: FAIL\n");
    }
    o
}

/// Write every frame row of the comparisons as CSV.
pub fn write_csv(path: &Path, cs: &[Comparison]) -> Result<()> {
    let err = |e: csv::Error| Error::usage(format!("cannot write '{}': {e}", path.display()));
    let mut w = csv::Writer::from_path(path).map_err(err)?;
    w.write_record([
        "series",
        "timestep",
        "n_a",
        "n_b",
        "matched",
        "pos_rms_d",
        "pos_max_d",
        "pos_max_id",
        "vel_rms",
        "vel_max",
        "vel_rel",
        "omega_max",
        "omega_rel",
        "ke_a",
        "ke_b",
        "ke_rot_a",
        "ke_rot_b",
        "com_a_x",
        "com_a_y",
        "com_a_z",
        "com_b_x",
        "com_b_y",
        "com_b_z",
        "com_dev_d",
        "coord_a",
        "coord_b",
        "ks_d",
        "ks_p",
        "exceeds",
    ])
    .map_err(err)?;
    for c in cs {
        for f in &c.frames {
            let o = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
            let rec: Vec<String> = vec![
                c.b.clone(),
                f.timestep.to_string(),
                f.n_a.to_string(),
                f.n_b.to_string(),
                f.matched.to_string(),
                f.pos_rms.to_string(),
                f.pos_max.to_string(),
                f.pos_max_id.map_or(String::new(), |i| i.to_string()),
                f.vel_rms.to_string(),
                f.vel_max.to_string(),
                f.vel_rel.to_string(),
                f.omega_max.to_string(),
                f.omega_rel.to_string(),
                f.a.ke.to_string(),
                f.b.ke.to_string(),
                f.a.ke_rot.to_string(),
                f.b.ke_rot.to_string(),
                f.a.com[0].to_string(),
                f.a.com[1].to_string(),
                f.a.com[2].to_string(),
                f.b.com[0].to_string(),
                f.b.com[1].to_string(),
                f.b.com[2].to_string(),
                f.com_dev.to_string(),
                f.a.coordination.to_string(),
                f.b.coordination.to_string(),
                o(f.ks_d),
                o(f.ks_p),
                f.exceeds.to_string(),
            ];
            w.write_record(&rec).map_err(err)?;
        }
    }
    w.flush().map_err(|e| Error::usage(format!("cannot write '{}': {e}", path.display())))
}

/// Options of `demx compare`.
#[derive(Parser, Debug)]
#[command(name = "demx compare", about = "Compare two runs (dump files, globs, output folders), or a deck run by demx and by a reference engine")]
pub struct CompareArgs {
    /// Run A (dump, glob, folder) or a deck with --against.
    pub a: String,
    /// Run B (not with --against).
    pub b: Option<String>,
    /// Run the deck with demx and this engine, then compare.
    #[arg(long, value_enum)]
    pub against: Option<super::reference::RefEngine>,
    /// With --against: run decks with `shell` or `python` commands (the
    /// engine runs them).
    #[arg(long)]
    pub allow_shell: bool,
    /// Seeds per engine for chaotic decks (passed as -var SEEDVAR k).
    #[arg(long, default_value_t = 1)]
    pub seeds: usize,
    /// Deck variable that takes the seed.
    #[arg(long, default_value = "seed")]
    pub seed_var: String,
    /// MPI ranks for the reference engine.
    #[arg(long, default_value_t = 1)]
    pub np: usize,
    /// Keep the run folders of --against in this directory.
    #[arg(long)]
    pub keep: Option<PathBuf>,
    /// Trajectory tolerance: position in diameters, and velocity/omega relative
    /// to the frame's largest value (unless set separately).
    #[arg(long, default_value_t = 1e-6)]
    pub tol: f64,
    /// Velocity tolerance (relative).
    #[arg(long)]
    pub tol_vel: Option<f64>,
    /// Angular velocity tolerance (relative).
    #[arg(long)]
    pub tol_omega: Option<f64>,
    /// Statistics: KE tolerance relative to the peak KE.
    #[arg(long, default_value_t = 0.03)]
    pub tol_ke: f64,
    /// Statistics: centre-of-mass tolerance in diameters.
    #[arg(long, default_value_t = 0.05)]
    pub tol_com: f64,
    /// Statistics: coordination number tolerance.
    #[arg(long, default_value_t = 0.5)]
    pub tol_coord: f64,
    /// Verdict mode.
    #[arg(long, value_enum, default_value_t = Mode::Auto)]
    pub mode: Mode,
    /// Statistics mode: fail when trajectories diverge before this timestep.
    #[arg(long)]
    pub min_divergence: Option<u64>,
    /// Particle density for KE when the dumps have no mass column.
    #[arg(long)]
    pub density: Option<f64>,
    /// Particle diameter when the dumps have no radius column.
    #[arg(long)]
    pub diameter: Option<f64>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write every frame's numbers to this CSV file.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// With --against: the scene is a heap; judge its final angle of repose
    /// and core packing fraction (`demx repose`) across seeds too.
    #[arg(long)]
    pub heap: bool,
    /// Allowed θr difference beyond the seeds' spread (degrees).
    #[arg(long, default_value_t = 0.5)]
    pub tol_theta: f64,
    /// Allowed core packing-fraction difference beyond the seeds' spread.
    #[arg(long, default_value_t = 0.01)]
    pub tol_phi: f64,
    /// With --against and one seed: when the trajectories diverge (chaos),
    /// run this many extra demx ensemble members, each started with every
    /// particle moved by --perturb of its radius, and judge the statistics
    /// against the ensemble's spread (0: fixed tolerances only).
    #[arg(long, default_value_t = 2)]
    pub ensemble: usize,
    /// Perturbation of the ensemble members, in particle radii.
    #[arg(long, default_value_t = 1e-6)]
    pub perturb: f64,
    /// Two-run mode: draw position deviation and kinetic energies vs
    /// timestep into this PNG file.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Variables for --against runs (filled from `-var NAME VALUE...`).
    #[arg(skip)]
    pub vars: Vec<(String, Vec<String>)>,
}

impl CompareArgs {
    /// The comparison options these arguments set.
    pub fn options(&self) -> CompareOptions {
        CompareOptions {
            tol_pos: self.tol,
            tol_vel: self.tol_vel.unwrap_or(self.tol),
            tol_omega: self.tol_omega.unwrap_or(self.tol),
            tol_ke: self.tol_ke,
            tol_com: self.tol_com,
            tol_coord: self.tol_coord,
            density: self.density,
            diameter: self.diameter,
            mode: self.mode,
            min_divergence: self.min_divergence,
        }
    }
}

/// Compare two inputs (dump, glob or folder each).
pub fn compare_inputs(a: &str, b: &str, o: &CompareOptions) -> Result<Vec<Comparison>> {
    let pairs = pair_series(load(a)?, load(b)?)?;
    Ok(pairs.iter().map(|(sa, sb)| compare_series(sa, sb, o)).collect())
}

/// Print comparisons as asked and return the exit code.
pub fn report(args: &CompareArgs, cs: &[Comparison], extra: Option<serde_json::Value>) -> Result<ExitCode> {
    if let Some(p) = &args.csv {
        write_csv(p, cs)?;
    }
    let pass = cs.iter().all(|c| c.pass);
    if args.json {
        let mut v = serde_json::json!({ "pass": pass, "comparisons": cs });
        if let Some(e) = extra {
            v["run"] = e;
        }
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        for (k, c) in cs.iter().enumerate() {
            if k > 0 {
                println!();
            }
            print!("{}", render(c));
        }
    }
    Ok(ExitCode::from(if pass { 0 } else { 1 }))
}

/// The `--plot` charts: RMS and largest position deviation (diameters, log
/// scale) with the position tolerance, and the kinetic energy of each run,
/// against the timestep.
pub fn charts(cs: &[Comparison]) -> Vec<crate::plot::Chart> {
    use crate::plot::{Chart, Series, SeriesKind};
    let mut dev = Chart {
        title: "position deviation B - A".into(),
        x_label: "timestep".into(),
        y_label: "deviation / particle diameter".into(),
        log_y: true,
        ..Chart::default()
    };
    let ke_unit = if cs.iter().any(|c| c.notes.iter().any(|n| n.contains("per unit density"))) { "J/(kg/m^3)" } else { "J" };
    let mut ke =
        Chart { title: "kinetic energy".into(), x_label: "timestep".into(), y_label: format!("translational KE ({ke_unit})"), ..Chart::default() };
    let many = cs.len() > 1;
    let tag = |what: &str, c: &Comparison, run: &str| {
        if many {
            format!("{what} {}", if run == "B" { &c.b } else { &c.a })
        } else {
            what.to_string()
        }
    };
    for c in cs {
        let ts = |f: &FrameRow| f.timestep as f64;
        let line = |label: String, points: Vec<(f64, f64)>| Series { label, points, kind: SeriesKind::Line };
        dev.series.push(line(tag("RMS", c, "A"), c.frames.iter().map(|f| (ts(f), f.pos_rms)).collect()));
        dev.series.push(line(tag("max", c, "A"), c.frames.iter().map(|f| (ts(f), f.pos_max)).collect()));
        ke.series.push(line(tag("A", c, "A"), c.frames.iter().map(|f| (ts(f), f.a.ke)).collect()));
        ke.series.push(line(tag("B", c, "B"), c.frames.iter().map(|f| (ts(f), f.b.ke)).collect()));
    }
    let (t0, t1) =
        cs.iter().flat_map(|c| c.frames.iter().map(|f| f.timestep as f64)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(t), b.max(t)));
    if let (Some(c), true) = (cs.first(), t0 <= t1) {
        let tol = c.options.tol_pos;
        dev.series.push(Series { label: format!("tolerance {tol:e}"), points: vec![(t0, tol), (t1, tol)], kind: SeriesKind::Line });
    }
    vec![dev, ke]
}

fn run(args: &CompareArgs) -> Result<ExitCode> {
    if args.against.is_some() {
        if args.plot.is_some() {
            return Err(Error::usage("--plot works in two-run mode (demx compare A B), not with --against"));
        }
        return super::compare_deck::run(args);
    }
    let Some(b) = &args.b else {
        return Err(Error::usage("demx compare needs two runs A B, or a deck with --against liggghts|lammps"));
    };
    if let Some(p) = &args.plot {
        crate::plot::check_path(p)?;
    }
    let cs = compare_inputs(&args.a, b, &args.options())?;
    if let Some(p) = &args.plot {
        crate::plot::write_png(p, &charts(&cs))?;
    }
    if !args.heap {
        return report(args, &cs, None);
    }
    // heaps: the final frames' angle of repose and core packing, judged
    // against the fixed tolerances (one run each: no spread to use)
    let last = |spec: &str| -> Result<Option<super::compare_stats::HeapStats>> {
        Ok(load(spec)?.first().and_then(|s| s.snaps.last()).and_then(super::compare_stats::heap_stats))
    };
    let (ha, hb) = (last(&args.a)?, last(b)?);
    let heap_ok = match (ha, hb) {
        (Some(x), Some(y)) => (x.theta - y.theta).abs() <= args.tol_theta && (x.phi - y.phi).abs() <= args.tol_phi,
        _ => false,
    };
    let code = report(args, &cs, Some(serde_json::json!({ "heap": [ha, hb], "heap_pass": heap_ok })))?;
    if !args.json {
        let f = |h: &Option<super::compare_stats::HeapStats>| {
            h.map_or("no heap".to_string(), |h| format!("theta_r {:.2} +- {:.2} deg, phi {:.3}, {} particles", h.theta, h.theta_sd, h.phi, h.count))
        };
        println!("heap A: {}\nheap B: {}", f(&ha), f(&hb));
        println!("heap verdict (theta_r within {} deg, phi within {}): {}", args.tol_theta, args.tol_phi, if heap_ok { "PASS" } else { "FAIL" });
    }
    Ok(if heap_ok { code } else { ExitCode::from(1) })
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    let (rest, vars) = match super::reference::extract_vars(args) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut argv = vec!["demx compare".to_string()];
    argv.extend(rest);
    let mut a = match CompareArgs::try_parse_from(argv) {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    a.vars = vars;
    match run(&a) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {}", e.message());
            ExitCode::from(2)
        }
    }
}
