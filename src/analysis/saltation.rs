//! `demx saltation`: aeolian transport measurements over a run's dump files
//! (Kamath, Shao & Parteli 2022 SI): the flux Q = sum m_i v_x,i / (L_x L_y)
//! per frame (SI Eq. 8), its time average after a transient, the normalised
//! flux Q-hat (Eq. 9) and the Shields number Theta (Eq. 10); the bed height
//! and the steady bed thickness delta_s beside Eq. 16; the concentration
//! profile above the bed and its decay length l_nu (Eq. 17); the lift-off and
//! impact velocities, slip velocity, hop time and hop length (Eqs. 12-15).
//! Writes CSV (or JSON) and plots.
//!
//! Usage: `demx saltation [--ustar U] [--rho-p 2650] [--rho-f 1.225] [--dm 200e-6]
//! [--g 9.81] [--from T] [--dt DT] [--group-type T] [-o out.csv] [--plot FILE.png] DUMP...`
//! Dumps need `id type vx` (or `vy` with `--dir y`) and `mass`, or `radius`
//! (mass from `--rho-p`); the time of a frame is `ITEM: TIME` or step*dt.
//! The layer statistics also need `z`, `vz` and `radius`.

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
    /// Solid fraction that marks the bed surface (as `fix aeolian/wind bed phi`).
    pub phic: f64,
    /// Height of the rigid ground (None: the top of the `rigid_type` grains,
    /// or the box bottom without them).
    pub ground: Option<f64>,
    /// Type of the immobile (frozen) bed grains, if any.
    pub rigid_type: Option<f64>,
    /// Initial mobile-layer thickness delta_0 in d_m, for Eq. 16.
    pub delta0: Option<f64>,
    /// Eq. 16's C_b.
    pub c_b: f64,
    /// Height of the near-bed layer in which lift-off and impact velocities
    /// are sampled, in d_m above the bed surface.
    pub hop_layer: f64,
    /// Lowest height above the bed of the l_nu fit, in d_m.
    pub fit_from: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            ustar: None,
            rho_p: 2650.0,
            rho_f: 1.225,
            d_m: 200e-6,
            g: 9.81,
            from: 0.0,
            dt: None,
            only_type: None,
            vcol: "vx".into(),
            phic: 0.3,
            ground: None,
            rigid_type: None,
            delta0: None,
            c_b: 0.02,
            hop_layer: 1.0,
            fit_from: 2.0,
        }
    }
}

/// Steady bed thickness of SI Eq. 16, in d_m:
/// delta_s/d_m = (delta_0/d_m - C_b u*/sqrt(g d_m)) H(...).
pub fn eq16_delta_s(delta0_dm: f64, ustar: f64, s: &Settings) -> f64 {
    (delta0_dm - s.c_b * ustar / (s.g * s.d_m).sqrt()).max(0.0)
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
    let cr = radius_column(f);
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
                let rad = cr.and_then(|(c, scale)| f.get(r, c).map(|v| v * scale)).unwrap_or(0.0);
                s.rho_p * 4.0 / 3.0 * PI * rad.powi(3)
            }
        };
        sum += m * f.get(r, cv).unwrap_or(0.0);
    }
    Ok(sum / area)
}

/// The column of the grain size and the factor that makes it a radius:
/// `radius` (1), else `diameter` (1/2).
fn radius_column(f: &Frame) -> Option<(usize, f64)> {
    f.col("radius").map(|c| (c, 1.0)).or_else(|| f.col("diameter").map(|c| (c, 0.5)))
}

/// One row of the time series: (step, time, Q).
pub type Row = (u64, f64, f64);

/// Vertical lift-off speed of SI S4: only grains that rise at least 3 d_m
/// above the bed, v_z >= sqrt(6 g d_m), count as hopping.
pub fn liftoff_speed(s: &Settings) -> f64 {
    (6.0 * s.g * s.d_m).sqrt()
}

/// Bin height of the bed-height and concentration profiles: d_m/2, the
/// default grid of `fix aeolian/wind`.
fn bin_height(s: &Settings) -> f64 {
    0.5 * s.d_m
}

/// The layer statistics of one frame.
#[derive(Clone, Debug, Default)]
pub struct Layer {
    /// Bed surface: the highest height where the solid fraction of all
    /// grains (mobile and rigid) exceeds `phic`, floored at the ground.
    pub zb: f64,
    /// Rigid ground height.
    pub ground: f64,
    /// Solid fraction of the mobile grains in bins of d_m/2 above `zb`.
    pub nu: Vec<f64>,
    /// Mobile grain centres per bin above `zb`.
    pub count: Vec<u64>,
    /// Ascending grains in the near-bed layer with v_z >= sqrt(6 g d_m):
    /// sums of |v_z|, |v_z| v_x, |v_z| v_z (crossing-weighted, see [`Hops`]).
    pub up: [f64; 3],
    /// Descending grains there with v_z <= -sqrt(6 g d_m): the same sums.
    pub down: [f64; 3],
    /// Grains counted in `up` and `down`.
    pub n_up: u64,
    /// See `n_up`.
    pub n_down: u64,
}

/// Bed height, concentration profile and near-bed velocities of one frame.
/// None when the frame lacks `z`, `vz` or the radius.
pub fn frame_layer(f: &Frame, s: &Settings) -> Option<Layer> {
    let (cz, cvz, cvx) = (f.col("z")?, f.col("vz")?, f.col(&s.vcol)?);
    let (cr, half) = radius_column(f)?;
    let ct = f.col("type");
    let of_type = |r: usize, t: Option<f64>| match (t, ct) {
        (Some(t), Some(c)) => f.get(r, c) == Some(t),
        _ => false,
    };
    let rigid = |r: usize| of_type(r, s.rigid_type);
    let mobile = |r: usize| match s.only_type {
        Some(_) => of_type(r, s.only_type),
        None => !rigid(r),
    };
    let sphere = |r: usize| (f.get(r, cz).unwrap_or(0.0), half * f.get(r, cr).unwrap_or(0.0));
    let b = f.bounds.file_bounds();
    let area = (b[0][1] - b[0][0]) * (b[1][1] - b[1][0]);
    let rows = 0..f.natoms;
    let ground = s.ground.unwrap_or_else(|| {
        let top = rows.clone().filter(|&r| rigid(r)).map(sphere).map(|(z, rad)| z + rad).fold(f64::NEG_INFINITY, f64::max);
        if top.is_finite() {
            top
        } else {
            b[2][0]
        }
    });
    let dz = bin_height(s);
    let top = rows.clone().map(sphere).map(|(z, rad)| z + rad).fold(ground, f64::max);
    // one empty bin above the highest grain, so that the bed surface is
    // interpolated towards it (bed_from_phi) rather than set to the grid top
    let nb = ((top - b[2][0]) / dz).ceil() as usize + 1;
    let edges: Vec<f64> = (0..=nb).map(|k| b[2][0] + k as f64 * dz).collect();
    let phi = crate::engine::wind::solid_fraction_of(rows.clone().map(sphere), &edges, area);
    let zb = crate::engine::wind::bed_from_phi(&edges, &phi, s.phic, ground);
    let np = (((b[2][1] - b[2][0]) / dz).ceil() as usize).max(1);
    let rel: Vec<f64> = (0..=np).map(|k| zb + k as f64 * dz).collect();
    let nu = crate::engine::wind::solid_fraction_of(rows.clone().filter(|&r| mobile(r)).map(sphere), &rel, area);
    let mut l = Layer { zb, ground, nu, count: vec![0; np], ..Layer::default() };
    let vth = liftoff_speed(s);
    for r in rows.filter(|&r| mobile(r)) {
        let zp = sphere(r).0 - zb;
        if zp > 0.0 {
            let k = (zp / dz) as usize;
            if k < np {
                l.count[k] += 1;
            }
        }
        if zp > 0.0 && zp <= s.hop_layer * s.d_m {
            let (vx, vz) = (f.get(r, cvx).unwrap_or(0.0), f.get(r, cvz).unwrap_or(0.0));
            let (sums, n) = if vz >= vth {
                (&mut l.up, &mut l.n_up)
            } else if vz <= -vth {
                (&mut l.down, &mut l.n_down)
            } else {
                continue;
            };
            sums[0] += vz.abs();
            sums[1] += vz.abs() * vx;
            sums[2] += vz.abs() * vz;
            *n += 1;
        }
    }
    Some(l)
}

/// Mean hop of SI S4 from the near-bed samples of many frames.
///
/// A grain seen in a layer of height h moving at v_z stays there h/|v_z|, so
/// averaging over the grains in the layer weights each crossing by 1/|v_z|;
/// weighting each sample by |v_z| turns it back into the average over
/// crossings, i.e. over lift-offs and impacts (the SI averages per hop).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Hops {
    /// Mean horizontal lift-off velocity u_0up.
    pub u0_up: f64,
    /// Mean horizontal impact velocity u_0down.
    pub u0_down: f64,
    /// Mean vertical lift-off velocity v_0up.
    pub v0_up: f64,
    /// Slip velocity u_0 = (u_0down + u_0up)/2 (Eq. 12).
    pub u0: f64,
    /// Hop time 2 v_0up/g (Eq. 13).
    pub t_hop: f64,
    /// Hop length (u_0down + u_0up) v_0up/g = u_0 t_hop: Eq. 14's constant
    /// horizontal acceleration integrated over t_hop.
    pub l_hop: f64,
    /// Eq. 15 as printed, (u_0down - u_0up) v_0up/g (the physics note: a sign slip).
    pub l_hop_eq15_printed: f64,
    /// Ascending and descending samples.
    pub samples_up: u64,
    /// See `samples_up`.
    pub samples_down: u64,
}

/// Hop statistics from summed layer samples.
pub fn hops(up: [f64; 3], down: [f64; 3], n_up: u64, n_down: u64, g: f64) -> Hops {
    let u0_up = up[1] / up[0];
    let v0_up = up[2] / up[0];
    let u0_down = down[1] / down[0];
    Hops {
        u0_up,
        u0_down,
        v0_up,
        u0: 0.5 * (u0_down + u0_up),
        t_hop: 2.0 * v0_up / g,
        l_hop: (u0_down + u0_up) * v0_up / g,
        l_hop_eq15_printed: (u0_down - u0_up) * v0_up / g,
        samples_up: n_up,
        samples_down: n_down,
    }
}

/// Exponential fit of SI Eq. 17, nu(z) = nu_0 exp(-z/l_nu), to a
/// time-averaged concentration profile: least squares on ln nu, each bin
/// weighted by its number of samples (the variance of ln n is about 1/n),
/// over bins centred at least `from` above the bed with 5 samples or more.
/// Returns (nu_0, l_nu, bins used, highest bin centre used); None with fewer
/// than 3 bins or no decay.
pub fn fit_decay(z: &[f64], nu: &[f64], samples: &[u64], from: f64) -> Option<(f64, f64, usize, f64)> {
    let (mut sw, mut sx, mut sy, mut sxx, mut sxy, mut n, mut top) = (0.0, 0.0, 0.0, 0.0, 0.0, 0, f64::NAN);
    for k in 0..z.len() {
        if z[k] < from || samples[k] < 5 || !(nu[k] > 0.0) {
            continue;
        }
        let (w, x, y) = (samples[k] as f64, z[k], nu[k].ln());
        sw += w;
        sx += w * x;
        sy += w * y;
        sxx += w * x * x;
        sxy += w * x * y;
        n += 1;
        top = x;
    }
    let det = sw * sxx - sx * sx;
    if n < 3 || !(det > 0.0) {
        return None;
    }
    let slope = (sw * sxy - sx * sy) / det;
    let icpt = (sy - slope * sx) / sw;
    (slope < 0.0).then(|| (icpt.exp(), -1.0 / slope, n, top))
}

/// Time-averaged results over the frames at or after `from`.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Summary {
    /// Shear velocity given.
    pub ustar: Option<f64>,
    /// Frames averaged.
    pub frames: usize,
    /// Mean flux (Eq. 8), kg/(m s).
    pub q_mean: f64,
    /// Eq. 9.
    pub q_hat: f64,
    /// Eq. 10.
    pub theta: Option<f64>,
    /// Mean bed surface height.
    pub zb: f64,
    /// Rigid ground height (last frame).
    pub ground: f64,
    /// Mobile-layer thickness at the first frame, in d_m.
    pub delta_first_dm: f64,
    /// Mean mobile-layer thickness zb - ground over the averaged frames (delta_s), in d_m.
    pub delta_s_dm: f64,
    /// Eq. 16 with the given delta_0 (`--delta0`), in d_m.
    pub delta_s_eq16_dm: Option<f64>,
    /// Eq. 16 with the measured first-frame thickness as delta_0, in d_m.
    pub delta_s_eq16_from_first_dm: Option<f64>,
    /// Fitted concentration at the bed (Eq. 17).
    pub nu0: Option<f64>,
    /// Decay length of the concentration (Eq. 17), m.
    pub l_nu: Option<f64>,
    /// The same in d_m.
    pub l_nu_dm: Option<f64>,
    /// Bins in the fit.
    pub fit_bins: usize,
    /// Height above the bed of the highest bin in the fit, in d_m.
    pub fit_top_dm: Option<f64>,
    /// Hop statistics (Eqs. 12-15).
    pub hops: Hops,
}

/// Everything `demx saltation` measures.
pub struct Analysis {
    /// Per frame: (step, time, Q, layer statistics).
    pub frames: Vec<(u64, f64, f64, Option<Layer>)>,
    /// Time-averaged profile: height above the bed (bin centre), nu, samples.
    pub profile: Vec<(f64, f64, u64)>,
    /// Time averages.
    pub summary: Summary,
}

/// Read the dumps and measure.
pub fn analyse(paths: &[String], s: &Settings) -> Result<Analysis> {
    let mut frames = vec![];
    for p in paths {
        for f in DumpReader::open(p)? {
            let f = f?;
            let t = f.time.or(s.dt.map(|dt| f.timestep as f64 * dt)).unwrap_or(f.timestep as f64);
            frames.push((f.timestep, t, frame_flux(&f, s)?, frame_layer(&f, s)));
        }
    }
    let avg: Vec<&(u64, f64, f64, Option<Layer>)> = frames.iter().filter(|r| r.1 >= s.from).collect();
    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let (mut a, mut n) = (0.0, 0.0);
        for x in v {
            a += x;
            n += 1.0;
        }
        if n > 0.0 {
            a / n
        } else {
            f64::NAN
        }
    };
    let q_mean = mean(&mut avg.iter().map(|r| r.2));
    let layers: Vec<&Layer> = avg.iter().filter_map(|r| r.3.as_ref()).collect();
    let dz = bin_height(s);
    let np = layers.iter().map(|l| l.nu.len()).max().unwrap_or(0);
    let mut profile: Vec<(f64, f64, u64)> = (0..np).map(|k| ((k as f64 + 0.5) * dz, 0.0, 0)).collect();
    let (mut up, mut down, mut n_up, mut n_down) = ([0.0; 3], [0.0; 3], 0, 0);
    for l in &layers {
        for k in 0..l.nu.len() {
            profile[k].1 += l.nu[k] / layers.len() as f64;
            profile[k].2 += l.count[k];
        }
        for j in 0..3 {
            up[j] += l.up[j];
            down[j] += l.down[j];
        }
        n_up += l.n_up;
        n_down += l.n_down;
    }
    let zs: Vec<f64> = profile.iter().map(|p| p.0).collect();
    let nus: Vec<f64> = profile.iter().map(|p| p.1).collect();
    let cnt: Vec<u64> = profile.iter().map(|p| p.2).collect();
    let fit = fit_decay(&zs, &nus, &cnt, s.fit_from * s.d_m);
    let first = frames.iter().find_map(|r| r.3.as_ref());
    let delta_first_dm = first.map_or(f64::NAN, |l| (l.zb - l.ground) / s.d_m);
    let summary = Summary {
        ustar: s.ustar,
        frames: avg.len(),
        q_mean,
        q_hat: q_hat(q_mean, s),
        theta: s.ustar.map(|u| shields(u, s)),
        zb: mean(&mut layers.iter().map(|l| l.zb)),
        ground: layers.last().map_or(f64::NAN, |l| l.ground),
        delta_first_dm,
        delta_s_dm: mean(&mut layers.iter().map(|l| (l.zb - l.ground) / s.d_m)),
        delta_s_eq16_dm: s.delta0.zip(s.ustar).map(|(d0, u)| eq16_delta_s(d0, u, s)),
        delta_s_eq16_from_first_dm: s.ustar.filter(|_| delta_first_dm.is_finite()).map(|u| eq16_delta_s(delta_first_dm, u, s)),
        nu0: fit.map(|f| f.0),
        l_nu: fit.map(|f| f.1),
        l_nu_dm: fit.map(|f| f.1 / s.d_m),
        fit_bins: fit.map_or(0, |f| f.2),
        fit_top_dm: fit.map(|f| f.3 / s.d_m),
        hops: hops(up, down, n_up, n_down, s.g),
    };
    Ok(Analysis { frames, profile, summary })
}

/// Command-line options besides the [`Settings`].
struct Outputs {
    csv: Option<String>,
    plot: Option<std::path::PathBuf>,
    profile: Option<String>,
    json: bool,
}

fn parse(args: &[String]) -> Result<(Settings, Vec<String>, Outputs)> {
    let mut s = Settings::default();
    let mut files = vec![];
    let mut out = Outputs { csv: None, plot: None, profile: None, json: false };
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
            "--rigid-type" => s.rigid_type = Some(num(i + 1)?),
            "--ground" => s.ground = Some(num(i + 1)?),
            "--phic" => s.phic = num(i + 1)?,
            "--delta0" => s.delta0 = Some(num(i + 1)?),
            "--cb" => s.c_b = num(i + 1)?,
            "--hop-layer" => s.hop_layer = num(i + 1)?,
            "--fit-from" => s.fit_from = num(i + 1)?,
            "--profile" => out.profile = Some(args.get(i + 1).ok_or_else(|| Error::usage("--profile needs a file"))?.clone()),
            "--json" => {
                out.json = true;
                i += 1;
                continue;
            }
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

const HELP: &str = "usage: demx saltation [--ustar U] [--rho-p 2650] [--rho-f 1.225] [--dm 200e-6] [--g 9.81] [--from T] [--dt DT] [--group-type T] [--rigid-type T] [--ground Z] [--phic 0.3] [--delta0 D] [--cb 0.02] [--hop-layer 1] [--fit-from 2] [--dir x|y] [-o out.csv] [--profile FILE.csv] [--json] [--plot FILE.png] DUMP...
  Q (SI Eq. 8), Q-hat (Eq. 9), Theta (Eq. 10) per frame and averaged from --from on; the bed surface (highest
  height with solid fraction > --phic, bins of d_m/2) and the mobile-layer thickness above the ground (--ground,
  or the top of the --rigid-type grains, or the box bottom) beside Eq. 16 (--delta0 in d_m, C_b --cb); the
  concentration profile above the bed and its decay length l_nu (Eq. 17, fitted from --fit-from d_m up); lift-off
  and impact velocities of grains with |v_z| >= sqrt(6 g d_m) within --hop-layer d_m of the bed, the slip velocity
  and the hop time and length (Eqs. 12-15).";

/// Run the analysis and write the CSV (time series, then a summary row), or
/// JSON with `--json`.
pub fn run(args: &[String]) -> Result<String> {
    let (s, files, out) = parse(args)?;
    if let Some(p) = &out.plot {
        crate::plot::check_path(p)?;
    }
    let a = analyse(&files, &s)?;
    let m = &a.summary;
    let num = |x: f64| if x.is_finite() { format!("{x:.9e}") } else { "nan".into() };
    let opt = |x: Option<f64>| x.map_or(String::new(), num);
    let mut csv = String::from("step,time,Q,zb,delta_dm,n_up,n_down\n");
    for (st, t, q, l) in &a.frames {
        match l {
            Some(l) => csv += &format!("{st},{t:.9e},{q:.9e},{},{},{},{}\n", num(l.zb), num((l.zb - l.ground) / s.d_m), l.n_up, l.n_down),
            None => csv += &format!("{st},{t:.9e},{q:.9e},nan,nan,0,0\n"),
        }
    }
    let h = &m.hops;
    csv += &format!(
        "# summary: ustar,frames,Q_mean,Q_hat,Theta,zb,delta_first_dm,delta_s_dm,delta_s_eq16_dm,l_nu,l_nu_dm,nu0,u0_up,u0_down,v0_up,u0,t_hop,l_hop,samples_up,samples_down\n# {},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
        s.ustar.map_or("".into(), |u| u.to_string()),
        m.frames,
        num(m.q_mean),
        num(m.q_hat),
        opt(m.theta),
        num(m.zb),
        num(m.delta_first_dm),
        num(m.delta_s_dm),
        opt(m.delta_s_eq16_dm.or(m.delta_s_eq16_from_first_dm)),
        opt(m.l_nu),
        opt(m.l_nu_dm),
        opt(m.nu0),
        num(h.u0_up),
        num(h.u0_down),
        num(h.v0_up),
        num(h.u0),
        num(h.t_hop),
        num(h.l_hop),
        h.samples_up,
        h.samples_down
    );
    if let Some(o) = &out.csv {
        crate::io::write_atomic(o, csv.as_bytes())?;
    }
    if let Some(o) = &out.profile {
        let mut t = String::from("z_above_bed,z_over_dm,nu,samples,nu_fit\n");
        for &(z, nu, n) in &a.profile {
            let fit = m.nu0.zip(m.l_nu).map_or(f64::NAN, |(n0, l)| n0 * (-z / l).exp());
            t += &format!("{z:.9e},{:.6},{},{n},{}\n", z / s.d_m, num(nu), num(fit));
        }
        crate::io::write_atomic(o, t.as_bytes())?;
    }
    if let Some(p) = &out.plot {
        let rows: Vec<Row> = a.frames.iter().map(|r| (r.0, r.1, r.2)).collect();
        let mut charts = vec![chart(&rows, &s)];
        if m.frames > 0 && a.profile.iter().any(|p| p.1 > 0.0) {
            charts.push(profile_chart(&a, &s));
        }
        crate::plot::write_png(p, &charts)?;
    }
    if out.json {
        return serde_json::to_string_pretty(&a.summary).map(|j| j + "\n").map_err(|e| Error::runtime(format!("json: {e}")));
    }
    Ok(csv)
}

/// The concentration profile (log scale) with the Eq. 17 fit.
fn profile_chart(a: &Analysis, s: &Settings) -> crate::plot::Chart {
    use crate::plot::{Chart, Series, SeriesKind};
    let pts: Vec<(f64, f64)> = a.profile.iter().filter(|p| p.1 > 0.0 && p.2 > 0).map(|p| (p.0 / s.d_m, p.1)).collect();
    let mut series = vec![Series { label: "solid fraction above the bed".into(), points: pts.clone(), kind: SeriesKind::Points }];
    if let (Some(n0), Some(l), Some(zmax)) = (a.summary.nu0, a.summary.l_nu, a.summary.fit_top_dm) {
        // over the bins the fit used
        let fit = (0..=50).map(|k| {
            let z = s.fit_from + (zmax - s.fit_from) * k as f64 / 50.0;
            (z, n0 * (-z * s.d_m / l).exp())
        });
        series.push(Series {
            label: format!("Eq. 17 fit, l_nu = {:.2} d_m ({:.0}-{:.0} d_m)", l / s.d_m, s.fit_from, zmax),
            points: fit.collect(),
            kind: SeriesKind::Line,
        });
    }
    Chart {
        title: "concentration above the bed".into(),
        x_label: "height above the bed (d_m)".into(),
        y_label: "solid fraction".into(),
        log_y: true,
        series,
        ..Chart::default()
    }
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
