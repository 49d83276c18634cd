//! `demx saltation`: aeolian transport measurements over a run's dump files
//! (Kamath, Shao & Parteli 2022 SI): the flux Q = sum m_i v_x,i / (L_x L_y)
//! per frame (SI Eq. 8), its time average after a transient, the normalised
//! flux Q-hat (Eq. 9) and the Shields number Theta (Eq. 10). Writes CSV.
//!
//! Usage: `demx saltation [--ustar U] [--rho-p 2650] [--rho-f 1.225] [--dm 200e-6]
//! [--g 9.81] [--from T] [--dt DT] [--group-type T] [-o out.csv] [--plot FILE.png] DUMP...`
//! Dumps need `id type vx` (or `vy` with `--dir y`) and `mass`, or `radius`
//! (mass from `--rho-p`); the time of a frame is `ITEM: TIME` or step*dt.

use crate::error::{Error, Result};
use crate::io::dump::{DumpReader, Frame};
use std::f64::consts::PI;
use std::process::ExitCode;

/// Settings of the analysis.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Shear velocity (for Theta), if known.
    pub ustar: Option<f64>,
    /// Grain density.
    pub rho_p: f64,
    /// Fluid density.
    pub rho_f: f64,
    /// Mean grain diameter.
    pub d_m: f64,
    /// Gravity.
    pub g: f64,
    /// Average only frames at or after this time.
    pub from: f64,
    /// Time step (time = step * dt when a frame has no TIME).
    pub dt: Option<f64>,
    /// Only grains of this type (None: all).
    pub only_type: Option<f64>,
    /// Downwind column (`vx` or `vy`).
    pub vcol: String,
}

impl Default for Settings {
    fn default() -> Self {
        Settings { ustar: None, rho_p: 2650.0, rho_f: 1.225, d_m: 200e-6, g: 9.81, from: 0.0, dt: None, only_type: None, vcol: "vx".into() }
    }
}

/// Q-hat = Q / (rho_p sqrt((s - 1) g d_m^3)), s = rho_p/rho_f (SI Eq. 9).
pub fn q_hat(q: f64, s: &Settings) -> f64 {
    let sr = s.rho_p / s.rho_f;
    q / (s.rho_p * ((sr - 1.0) * s.g * s.d_m.powi(3)).sqrt())
}

/// Theta = rho_f u*^2 / ((rho_p - rho_f) g d_m) (SI Eq. 10).
pub fn shields(ustar: f64, s: &Settings) -> f64 {
    s.rho_f * ustar * ustar / ((s.rho_p - s.rho_f) * s.g * s.d_m)
}

/// Flux of one frame (SI Eq. 8), kg/(m s).
pub fn frame_flux(f: &Frame, s: &Settings) -> Result<f64> {
    let cv = f.col(&s.vcol).ok_or_else(|| Error::usage(format!("dump frame at step {} has no column {}", f.timestep, s.vcol)))?;
    let cm = f.col("mass");
    let cr = f.col("radius").or_else(|| f.col("diameter"));
    let half = f.col("radius").is_none();
    if cm.is_none() && cr.is_none() {
        return Err(Error::usage(format!("dump frame at step {} has neither mass nor radius", f.timestep)));
    }
    let ct = f.col("type");
    let b = f.bounds.file_bounds();
    let area = (b[0][1] - b[0][0]) * (b[1][1] - b[1][0]);
    if !(area > 0.0) {
        return Err(Error::usage(format!("dump frame at step {} has a zero horizontal area", f.timestep)));
    }
    let mut sum = 0.0;
    for r in 0..f.natoms {
        if let (Some(t), Some(ct)) = (s.only_type, ct) {
            if f.get(r, ct) != Some(t) {
                continue;
            }
        }
        let m = match cm {
            Some(c) => f.get(r, c).unwrap_or(0.0),
            None => {
                let mut rad = cr.and_then(|c| f.get(r, c)).unwrap_or(0.0);
                if half {
                    rad *= 0.5;
                }
                s.rho_p * 4.0 / 3.0 * PI * rad.powi(3)
            }
        };
        sum += m * f.get(r, cv).unwrap_or(0.0);
    }
    Ok(sum / area)
}

/// One row of the time series: (step, time, Q).
pub type Row = (u64, f64, f64);

/// Flux time series over dump files.
pub fn flux_series(paths: &[String], s: &Settings) -> Result<Vec<Row>> {
    let mut out = vec![];
    for p in paths {
        for f in DumpReader::open(p)? {
            let f = f?;
            let t = f.time.or(s.dt.map(|dt| f.timestep as f64 * dt)).unwrap_or(f.timestep as f64);
            out.push((f.timestep, t, frame_flux(&f, s)?));
        }
    }
    Ok(out)
}

/// Command-line options besides the [`Settings`].
struct Outputs {
    csv: Option<String>,
    plot: Option<std::path::PathBuf>,
}

fn parse(args: &[String]) -> Result<(Settings, Vec<String>, Outputs)> {
    let mut s = Settings::default();
    let mut files = vec![];
    let mut out = Outputs { csv: None, plot: None };
    let mut i = 0;
    let num = |i: usize| -> Result<f64> {
        let v = args.get(i).ok_or_else(|| Error::usage(format!("{} needs a value", args[i - 1])))?;
        v.parse::<f64>().map_err(|_| Error::usage(format!("{}: '{v}' is not a number", args[i - 1])))
    };
    while i < args.len() {
        match args[i].as_str() {
            "--ustar" => s.ustar = Some(num(i + 1)?),
            "--rho-p" => s.rho_p = num(i + 1)?,
            "--rho-f" => s.rho_f = num(i + 1)?,
            "--dm" => s.d_m = num(i + 1)?,
            "--g" => s.g = num(i + 1)?,
            "--from" => s.from = num(i + 1)?,
            "--dt" => s.dt = Some(num(i + 1)?),
            "--group-type" => s.only_type = Some(num(i + 1)?),
            "--dir" => {
                s.vcol = match args.get(i + 1).map(|a| a.as_str()) {
                    Some("x") => "vx".into(),
                    Some("y") => "vy".into(),
                    _ => return Err(Error::usage("--dir needs x or y")),
                }
            }
            "-o" | "--output" => out.csv = Some(args.get(i + 1).ok_or_else(|| Error::usage("-o needs a file"))?.clone()),
            "--plot" => out.plot = Some(args.get(i + 1).ok_or_else(|| Error::usage("--plot needs a file"))?.into()),
            "-h" | "--help" => return Err(Error::usage(HELP)),
            a if a.starts_with('-') => return Err(Error::usage(format!("unknown option {a}\n{HELP}"))),
            _ => {
                files.push(args[i].clone());
                i += 1;
                continue;
            }
        }
        i += 2;
    }
    if files.is_empty() {
        return Err(Error::usage(format!("no dump files given\n{HELP}")));
    }
    Ok((s, files, out))
}

const HELP: &str = "usage: demx saltation [--ustar U] [--rho-p 2650] [--rho-f 1.225] [--dm 200e-6] [--g 9.81] [--from T] [--dt DT] [--group-type T] [--dir x|y] [-o out.csv] [--plot FILE.png] DUMP...";

/// Run the analysis and write the CSV (time series, then a summary row).
pub fn run(args: &[String]) -> Result<String> {
    let (s, files, out) = parse(args)?;
    if let Some(p) = &out.plot {
        crate::plot::check_path(p)?;
    }
    let rows = flux_series(&files, &s)?;
    let mut csv = String::from("step,time,Q\n");
    for (st, t, q) in &rows {
        csv += &format!("{st},{t:.9e},{q:.9e}\n");
    }
    let avg: Vec<f64> = rows.iter().filter(|r| r.1 >= s.from).map(|r| r.2).collect();
    let mean = if avg.is_empty() { f64::NAN } else { avg.iter().sum::<f64>() / avg.len() as f64 };
    let theta = s.ustar.map(|u| shields(u, &s));
    csv += &format!(
        "# summary: ustar,frames,Q_mean,Q_hat,Theta\n# {},{},{:.9e},{:.9e},{}\n",
        s.ustar.map_or("".into(), |u| u.to_string()),
        avg.len(),
        mean,
        q_hat(mean, &s),
        theta.map_or("".into(), |t| format!("{t:.9e}"))
    );
    if let Some(o) = out.csv {
        std::fs::write(&o, &csv).map_err(|e| Error::usage(format!("cannot write {o}: {e}")))?;
    }
    if let Some(p) = &out.plot {
        crate::plot::write_png(p, &[chart(&rows, &s)])?;
    }
    Ok(csv)
}

/// The `--plot` chart: Q of every frame against time, the running mean of Q
/// from `--from` on, and the time-averaged Q over the averaging window.
pub fn chart(rows: &[Row], s: &Settings) -> crate::plot::Chart {
    use crate::plot::{Chart, Series, SeriesKind};
    let q: Vec<(f64, f64)> = rows.iter().map(|r| (r.1, r.2)).collect();
    let mut running = vec![];
    let (mut sum, mut n) = (0.0, 0.0);
    for r in rows.iter().filter(|r| r.1 >= s.from) {
        sum += r.2;
        n += 1.0;
        running.push((r.1, sum / n));
    }
    let mut series = vec![Series { label: "Q per frame".into(), points: q, kind: SeriesKind::Line }];
    if let (Some(first), Some(last)) = (running.first().copied(), running.last().copied()) {
        series.push(Series { label: format!("running mean from t = {:.4}", s.from), points: running, kind: SeriesKind::Line });
        series.push(Series {
            label: format!("mean Q = {:.4e} (Q-hat {:.4})", last.1, q_hat(last.1, s)),
            points: vec![(first.0, last.1), (last.0, last.1)],
            kind: SeriesKind::Line,
        });
    }
    Chart {
        title: format!("saltation flux ({} downwind)", s.vcol.trim_start_matches('v')),
        x_label: "time (s)".into(),
        y_label: "Q (kg/(m s))".into(),
        series,
        ..Chart::default()
    }
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    match run(&args) {
        Ok(csv) => {
            print!("{csv}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}", e.message());
            ExitCode::from(e.exit_code())
        }
    }
}
