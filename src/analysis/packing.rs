//! `demx packing DUMP [--frame N] [--json]`: packing fraction of a settled
//! column as in Elekes & Parteli (2021, Materials and Methods):
//! phi = (sphere volume with centres between H_I = 0.3 z_max and
//! H_U = 0.7 z_max) / (L_x L_y (H_U - H_I)), z_max the highest centre above
//! the box bottom; the SD comes from the four sub-columns obtained by halving
//! L_x and L_y. Also the Bond number (see [`super::repose::bond_number`]).

use super::repose::{bond_number, pick_frame, positions, radii, regime};
use crate::error::{Error, Result};
use crate::io::dump::Frame;
use std::process::ExitCode;

/// Packing fraction of one column.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Packing {
    /// phi of the whole cross-section.
    pub phi: f64,
    /// Mean phi of the four sub-columns.
    pub phi_mean: f64,
    /// Sample SD of the four sub-columns.
    pub sd: f64,
    /// The four sub-column values.
    pub sub: [f64; 4],
    /// Highest centre above the box bottom, m.
    pub z_max: f64,
    /// Particles counted (centres in the band).
    pub counted: usize,
    /// Mean particle diameter, m.
    pub diameter: f64,
}

/// Packing fraction of a frame (box bounds give L_x, L_y and the bottom).
pub fn packing(f: &Frame) -> Result<Packing> {
    let [x, y, z] = positions(f)?;
    let r = radii(f)?;
    if r.is_empty() {
        return Err(Error::usage("the frame has no particles"));
    }
    let (lo, hi) = (f.bounds.lo, f.bounds.hi);
    let (lx, ly) = (hi[0] - lo[0], hi[1] - lo[1]);
    let z_max = z.iter().map(|v| v - lo[2]).fold(f64::NEG_INFINITY, f64::max);
    let (h_i, h_u) = (0.3 * z_max, 0.7 * z_max);
    let (mut vol, mut sub, mut counted) = (0.0, [0.0; 4], 0);
    for k in 0..r.len() {
        let zk = z[k] - lo[2];
        if zk >= h_i && zk <= h_u {
            let v = 4.0 / 3.0 * std::f64::consts::PI * r[k].powi(3);
            vol += v;
            counted += 1;
            let ix = usize::from(x[k] - lo[0] >= 0.5 * lx);
            let iy = usize::from(y[k] - lo[1] >= 0.5 * ly);
            sub[2 * iy + ix] += v;
        }
    }
    let band = h_u - h_i;
    if !(band > 0.0 && lx > 0.0 && ly > 0.0) {
        return Err(Error::usage("degenerate column (z_max <= 0 or empty box)"));
    }
    let phi = vol / (lx * ly * band);
    let sub = sub.map(|v| v / (0.25 * lx * ly * band));
    let mean = sub.iter().sum::<f64>() / 4.0;
    let sd = (sub.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
    let diameter = 2.0 * r.iter().sum::<f64>() / r.len() as f64;
    Ok(Packing { phi, phi_mean: mean, sd, sub, z_max, counted, diameter })
}

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    let c = match super::repose::HeapCli::parse("demx packing", "Packing fraction of a settled column (Elekes & Parteli 2021)", args) {
        Ok(c) => c,
        Err(code) => return code,
    };
    match pick_frame(&c.dump, c.frame).and_then(|f| packing(&f)) {
        Ok(p) => {
            let bo = bond_number(c.gamma, p.diameter, c.g, c.rho);
            if c.json {
                println!("{}", serde_json::json!({"packing": p, "bond_number": bo, "regime": regime(bo)}));
            } else {
                println!("phi = {:.4} (sub-columns {:.4} +- {:.4})", p.phi, p.phi_mean, p.sd);
                println!("{} particles between 0.3 and 0.7 z_max (z_max = {:.4e} m), d = {:.4e} m", p.counted, p.z_max, p.diameter);
                println!("Bond number Bo = 12 gamma/(d^2 g rho) = {bo:.4e}: {}", regime(bo));
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
