//! `demx repose DUMP [--frame N] [--json] [--plot FILE.png]`: the angle of repose of a heap the
//! way Elekes & Parteli (2021, PNAS, Fig. 1) measure it. For each side
//! projection (x-z and y-z) the heap's upper boundary is found by
//! rasterising the spheres (each column of the raster takes the highest
//! sphere surface above it); the heap base is the contiguous stretch of
//! non-empty columns around the crest; theta is the base angle of the
//! isosceles triangle with the same area over that base,
//! theta = atan(4 A / B^2). The result is the mean and SD of the two
//! projections, with the Bond number Bo = 12 gamma / (d^2 g rho) (paper,
//! after Eq. 3) and the regime: irregular heaps (regime I) above Bo ~ 1e4.

use crate::error::{Error, Result};
use crate::io::dump::{DumpReader, Frame};
use std::process::ExitCode;

/// Angle of repose of one heap.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Repose {
    /// Base angle in the x-z projection, degrees.
    pub theta_xz: f64,
    /// Base angle in the y-z projection, degrees.
    pub theta_yz: f64,
    /// Mean of the two, degrees.
    pub theta: f64,
    /// Sample standard deviation of the two, degrees.
    pub sd: f64,
    /// Heap height over the plate (highest sphere surface), m.
    pub height: f64,
    /// Particles used.
    pub particles: usize,
    /// Mean particle diameter, m.
    pub diameter: f64,
}

/// Bond number of the paper, Bo = 12 gamma / (d^2 g rho).
pub fn bond_number(gamma: f64, d: f64, g: f64, rho: f64) -> f64 {
    12.0 * gamma / (d * d * g * rho)
}

/// The paper's heap regime for a Bond number.
pub fn regime(bo: f64) -> &'static str {
    if bo > 1e4 {
        "irregular heap (regime I, Bo > ~1e4): Eq. 1 does not apply"
    } else {
        "regular heap (regime II)"
    }
}

/// Rasterised upper boundary of a heap in one side projection and the
/// isosceles triangle fitted to it.
#[derive(Clone, Debug)]
pub struct Profile {
    /// Horizontal coordinate of the left edge of column 0, m.
    pub lo: f64,
    /// Column width, m.
    pub pixel: f64,
    /// Height of the highest sphere surface over each column (0: empty), m.
    pub top: Vec<f64>,
    /// First and last column of the heap base (contiguous non-empty columns
    /// around the crest).
    pub base_cols: (usize, usize),
    /// Base length B, m.
    pub base: f64,
    /// Area A under the boundary over the base, m^2.
    pub area: f64,
    /// Base angle theta = atan(4 A / B^2), degrees.
    pub theta: f64,
}

impl Profile {
    /// Centre of column `i`, m.
    pub fn column_centre(&self, i: usize) -> f64 {
        self.lo + (i as f64 + 0.5) * self.pixel
    }
    /// The fitted isosceles triangle: left base corner, apex, right base
    /// corner (height 2 A / B over the base midpoint).
    pub fn triangle(&self) -> [(f64, f64); 3] {
        let x0 = self.lo + self.base_cols.0 as f64 * self.pixel;
        let x1 = self.lo + (self.base_cols.1 + 1) as f64 * self.pixel;
        [(x0, 0.0), (0.5 * (x0 + x1), 2.0 * self.area / self.base), (x1, 0.0)]
    }
}

/// Upper boundary and fitted triangle of spheres (horizontal centre `h`,
/// height `z` above the plate, radius `r`) in one side projection,
/// rasterised with `pixel` wide columns. None without particles.
pub fn projection_profile(h: &[f64], z: &[f64], r: &[f64], pixel: f64) -> Option<Profile> {
    if h.is_empty() || !(pixel > 0.0) {
        return None;
    }
    let lo = h.iter().zip(r).map(|(a, b)| a - b).fold(f64::INFINITY, f64::min);
    let hi = h.iter().zip(r).map(|(a, b)| a + b).fold(f64::NEG_INFINITY, f64::max);
    let n = ((hi - lo) / pixel).ceil() as usize + 1;
    if !(n < 50_000_000) {
        return None;
    }
    let mut top = vec![0.0_f64; n];
    for k in 0..h.len() {
        let (c, zc, rad) = (h[k], z[k], r[k]);
        let i0 = ((c - rad - lo) / pixel).floor().max(0.0) as usize;
        let i1 = (((c + rad - lo) / pixel).ceil() as usize).min(n - 1);
        for (i, t) in top.iter_mut().enumerate().take(i1 + 1).skip(i0) {
            let x = lo + (i as f64 + 0.5) * pixel - c;
            if x.abs() < rad {
                let s = zc + (rad * rad - x * x).sqrt();
                if s > *t {
                    *t = s;
                }
            }
        }
    }
    let crest = top.iter().enumerate().fold(0, |b, (i, &v)| if v > top[b] { i } else { b });
    let mut a = crest;
    while a > 0 && top[a - 1] > 0.0 {
        a -= 1;
    }
    let mut b = crest;
    while b + 1 < n && top[b + 1] > 0.0 {
        b += 1;
    }
    let base = (b - a + 1) as f64 * pixel;
    let area: f64 = top[a..=b].iter().sum::<f64>() * pixel;
    let theta = (4.0 * area / (base * base)).atan().to_degrees();
    Some(Profile { lo, pixel, top, base_cols: (a, b), base, area, theta })
}

/// Base angle (degrees) of the isosceles triangle with the area of the
/// upper boundary of spheres (horizontal centre `h`, height `z` above the
/// plate, radius `r`) in one side projection, rasterised with `pixel`
/// wide columns. None without particles.
pub fn projection_angle(h: &[f64], z: &[f64], r: &[f64], pixel: f64) -> Option<f64> {
    projection_profile(h, z, r, pixel).map(|p| p.theta)
}

fn column(f: &Frame, names: &[&str]) -> Option<Vec<f64>> {
    names.iter().find_map(|n| f.column(n))
}

/// Radii of a frame (`radius`, or `diameter`/2); error when neither is dumped.
pub(crate) fn radii(f: &Frame) -> Result<Vec<f64>> {
    if let Some(r) = f.column("radius") {
        return Ok(r);
    }
    if let Some(d) = f.column("diameter") {
        return Ok(d.into_iter().map(|v| 0.5 * v).collect());
    }
    Err(Error::usage("the dump needs a radius or diameter column"))
}

/// Positions (x, y, z) of a frame, unscaled.
pub(crate) fn positions(f: &Frame) -> Result<[Vec<f64>; 3]> {
    let get = |a: &str, s: &str| -> Result<Vec<f64>> {
        if let Some(v) = column(f, &[a, &format!("{a}u")]) {
            return Ok(v);
        }
        let v = f.column(s).ok_or_else(|| Error::usage(format!("the dump needs {a} (or {s}) columns")))?;
        let k = ["x", "y", "z"].iter().position(|c| *c == a).unwrap_or(0);
        let (lo, hi) = (f.bounds.lo[k], f.bounds.hi[k]);
        Ok(v.into_iter().map(|u| lo + u * (hi - lo)).collect())
    };
    Ok([get("x", "xs")?, get("y", "ys")?, get("z", "zs")?])
}

/// Angle of repose of the heap in `f`; the plate is the lowest sphere bottom.
pub fn repose(f: &Frame) -> Result<Repose> {
    repose_profiles(f).map(|(r, _, _)| r)
}

/// [`repose`] with the x-z and y-z profiles it was computed from.
pub fn repose_profiles(f: &Frame) -> Result<(Repose, Profile, Profile)> {
    let [x, y, z] = positions(f)?;
    let r = radii(f)?;
    if r.is_empty() {
        return Err(Error::usage("the frame has no particles"));
    }
    let plate = z.iter().zip(&r).map(|(a, b)| a - b).fold(f64::INFINITY, f64::min);
    let zh: Vec<f64> = z.iter().map(|v| v - plate).collect();
    let rmin = r.iter().cloned().fold(f64::INFINITY, f64::min);
    let pixel = rmin / 5.0;
    let pxz = projection_profile(&x, &zh, &r, pixel).ok_or_else(|| Error::usage("cannot rasterise the x-z projection"))?;
    let pyz = projection_profile(&y, &zh, &r, pixel).ok_or_else(|| Error::usage("cannot rasterise the y-z projection"))?;
    let (txz, tyz) = (pxz.theta, pyz.theta);
    let theta = 0.5 * (txz + tyz);
    let sd = (txz - tyz).abs() / std::f64::consts::SQRT_2;
    let height = zh.iter().zip(&r).map(|(a, b)| a + b).fold(0.0, f64::max);
    let diameter = 2.0 * r.iter().sum::<f64>() / r.len() as f64;
    let rep = Repose { theta_xz: txz, theta_yz: tyz, theta, sd, height, particles: r.len(), diameter };
    Ok((rep, pxz, pyz))
}

/// `demx repose` warns when the two projections differ by more than this
/// (degrees). Regular heaps measured in VALIDATION.md's heap-size section
/// differ by 0-1.4 deg (16.97/15.57, 24.42/24.42, 25.32/26.19, 25.19/26.01)
/// and 3-seed means of one setting scatter by SD 1.1-1.6 deg (tradeoff
/// section): twice the largest such difference means an irregular heap.
pub const PROJECTION_SPREAD_WARN: f64 = 3.0;

/// A side of the plate counts as covered when a sphere centred within
/// [`EDGE_BAND`] diameters of it reaches this many diameters above the plate
/// (two layers: a lone grain on the plate reaches one). Measured on the heap
/// template (1 mm, stock model, 2026-12-07): the free cone of N = 2000 has
/// only lone grains there (1.0 d on all four edges, θr 15.4 deg); the heaps
/// of N = 5000 that cover the plate reach 1.80-1.86 d (demx 24.7 deg,
/// LIGGGHTS 25.1 deg).
pub const EDGE_COVER_HEIGHT: f64 = 1.5;

/// Width of the band along each plate edge, in mean diameters.
pub const EDGE_BAND: f64 = 2.0;

/// Warnings on a heap measured by [`repose`]: a heap that does not cover the
/// plate (a free cone, lower than the protocol's heap), projections that
/// disagree beyond their usual spread. The plate is the frame's box in x and
/// y (templates/heap/in.heap: the wall spans the box, and grains that roll
/// off leave it).
pub fn heap_warnings(f: &Frame, rep: &Repose) -> Result<Vec<String>> {
    let mut w = vec![];
    let [x, y, z] = positions(f)?;
    let r = radii(f)?;
    let d = rep.diameter;
    let plate = z.iter().zip(&r).map(|(a, b)| a - b).fold(f64::INFINITY, f64::min);
    // highest sphere top near each of the four edges, in diameters
    let mut tops = [0.0_f64; 4];
    for k in 0..r.len() {
        let top = (z[k] + r[k] - plate) / d;
        let dist = [x[k] - f.bounds.lo[0], f.bounds.hi[0] - x[k], y[k] - f.bounds.lo[1], f.bounds.hi[1] - y[k]];
        for (e, t) in dist.iter().zip(tops.iter_mut()) {
            if *e < EDGE_BAND * d && top > *t {
                *t = top;
            }
        }
    }
    let names = ["x lo", "x hi", "y lo", "y hi"];
    let bare: Vec<String> = names.iter().zip(&tops).filter(|(_, &t)| t < EDGE_COVER_HEIGHT).map(|(n, t)| format!("{n} edge: {t:.1} d")).collect();
    if !bare.is_empty() {
        w.push(format!(
            "the heap does not cover the plate (the box's x-y extent, {:.1} x {:.1} d): within {EDGE_BAND} d of an edge no \
             grain stands {EDGE_COVER_HEIGHT} d above the plate ({}). This is a free cone, lower than the protocol's heap: \
             without cohesion the 1 mm cone of 2,000 grains measured 16.3 deg against 24.4-25.8 deg for heaps of 5,000-25,000 \
             that cover the plate (VALIDATION.md, 'Heap size'); pour more grains",
            (f.bounds.hi[0] - f.bounds.lo[0]) / d,
            (f.bounds.hi[1] - f.bounds.lo[1]) / d,
            bare.join(", ")
        ));
    }
    let spread = (rep.theta_xz - rep.theta_yz).abs();
    if spread > PROJECTION_SPREAD_WARN {
        w.push(format!(
            "the two projections differ by {spread:.1} deg (x-z {:.2}, y-z {:.2}), more than {PROJECTION_SPREAD_WARN} deg: \
             regular heaps differ by 0-1.4 deg (VALIDATION.md, 'Heap size'), so this heap is irregular or not yet \
             relaxed and its mean is not an angle of repose to trust",
            rep.theta_xz, rep.theta_yz
        ));
    }
    Ok(w)
}

/// The `--plot` charts: each side projection with its rasterised upper
/// boundary and fitted triangle, equal scales.
pub fn charts(xz: &Profile, yz: &Profile) -> Vec<crate::plot::Chart> {
    use crate::plot::{Chart, Series, SeriesKind};
    [("x", xz), ("y", yz)]
        .into_iter()
        .map(|(axis, p)| {
            let boundary = (0..p.top.len()).map(|i| (p.column_centre(i), p.top[i])).collect();
            Chart {
                title: format!("{axis}-z projection: theta = {:.2} deg", p.theta),
                x_label: format!("{axis} (m)"),
                y_label: "height over the plate (m)".into(),
                equal_aspect: true,
                series: vec![
                    Series { label: "upper boundary".into(), points: boundary, kind: SeriesKind::Line },
                    Series { label: format!("triangle, same area (B = {:.3e} m)", p.base), points: p.triangle().to_vec(), kind: SeriesKind::Polygon },
                ],
                ..Chart::default()
            }
        })
        .collect()
}

/// Pick frame `index` (negative: from the end; default the last) of a dump.
pub(crate) fn pick_frame(path: &str, index: Option<i64>) -> Result<Frame> {
    let mut frames = vec![];
    for f in DumpReader::open(path)? {
        frames.push(f?);
        if let Some(i) = index {
            if i >= 0 && frames.len() as i64 > i {
                break;
            }
        }
    }
    let n = frames.len() as i64;
    let i = match index {
        None => n - 1,
        Some(i) if i < 0 => n + i,
        Some(i) => i,
    };
    if i < 0 || i >= n {
        return Err(Error::usage(format!("{path}: no frame {} ({n} frames)", index.unwrap_or(-1))));
    }
    super::check_heap_frame(path, i as usize, &frames[i as usize])?;
    Ok(frames.swap_remove(i as usize))
}

/// Arguments shared by `demx repose` and `demx packing`.
#[derive(clap::Parser, Debug)]
pub struct HeapCli {
    /// LIGGGHTS/LAMMPS dump with x y z (or xs ys zs) and radius (or diameter).
    pub dump: String,
    /// Frame index (0-based; negative from the end; default: the last).
    #[arg(long, allow_hyphen_values = true)]
    pub frame: Option<i64>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Surface energy gamma (J/m^2) for the Bond number.
    #[arg(long, default_value_t = 0.05)]
    pub gamma: f64,
    /// Gravity (m/s^2) for the Bond number.
    #[arg(long, default_value_t = 9.81)]
    pub g: f64,
    /// Particle density (kg/m^3) for the Bond number.
    #[arg(long, default_value_t = 2500.0)]
    pub rho: f64,
}

impl HeapCli {
    /// Parse the words after `name`; `Err` carries the exit code (help: 0, bad use: 2).
    pub fn parse(name: &'static str, about: &'static str, args: Vec<String>) -> std::result::Result<HeapCli, ExitCode> {
        use clap::{CommandFactory, FromArgMatches};
        let cmd = HeapCli::command().name(name).about(about);
        match cmd.try_get_matches_from(std::iter::once(name.to_string()).chain(args)).and_then(|m| HeapCli::from_arg_matches(&m)) {
            Ok(c) => Ok(c),
            Err(e) => {
                let _ = e.print();
                Err(ExitCode::from(if e.use_stderr() { 2 } else { 0 }))
            }
        }
    }
}

/// Arguments of `demx repose`: the heap arguments and `--plot`.
#[derive(clap::Parser, Debug)]
pub struct ReposeCli {
    /// Dump, frame and Bond number settings.
    #[command(flatten)]
    pub heap: HeapCli,
    /// Draw both side projections with their upper boundary and fitted
    /// triangle into this PNG file.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<std::path::PathBuf>,
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    use clap::{CommandFactory, FromArgMatches};
    let name = "demx repose";
    let cmd = ReposeCli::command().name(name).about("Angle of repose of a heap (Elekes & Parteli 2021)");
    let parsed = cmd.try_get_matches_from(std::iter::once(name.to_string()).chain(args)).and_then(|m| ReposeCli::from_arg_matches(&m));
    let (c, plot) = match parsed {
        Ok(r) => (r.heap, r.plot),
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    if let Some(p) = &plot {
        if let Err(e) = crate::plot::check_path(p) {
            eprintln!("error: {}", e.message());
            return ExitCode::from(e.exit_code());
        }
    }
    let res = pick_frame(&c.dump, c.frame).and_then(|f| {
        let (r, xz, yz) = repose_profiles(&f)?;
        if let Some(p) = &plot {
            crate::plot::write_png(p, &charts(&xz, &yz))?;
        }
        let w = heap_warnings(&f, &r)?;
        Ok((r, w))
    });
    match res {
        Ok((r, warnings)) => {
            let bo = bond_number(c.gamma, r.diameter, c.g, c.rho);
            if c.json {
                let v = serde_json::json!({"repose": r, "bond_number": bo, "regime": regime(bo), "warnings": warnings});
                println!("{v}");
            } else {
                println!("theta_r = {:.2} +- {:.2} deg (x-z {:.2}, y-z {:.2})", r.theta, r.sd, r.theta_xz, r.theta_yz);
                println!("heap height {:.4e} m, {} particles, d = {:.4e} m", r.height, r.particles, r.diameter);
                // the dump does not know the deck's surface energy, gravity or
                // density: say which ones the Bond number assumed
                println!(
                    "Bond number Bo = 12 gamma/(d^2 g rho) = {bo:.4e} with gamma = {} J/m^2, g = {} m/s^2, rho = {} kg/m^3 \
                     (the paper's glass unless --gamma/--g/--rho): {}",
                    c.gamma,
                    c.g,
                    c.rho,
                    regime(bo)
                );
                for w in &warnings {
                    println!("warning: {w}");
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
