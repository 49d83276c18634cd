//! Measurements on runs: comparison with the reference engines, angle of
//! repose, packing fraction, aeolian transport, cost-accuracy trade-offs,
//! size-gravity sweeps of the angle of repose.
pub mod campaign;
pub mod compare;
pub mod compare_deck;
pub mod compare_stats;
pub mod packing;
pub mod reference;
pub mod repose;
pub mod saltation;
pub mod slurm;
pub mod sweep;
pub mod tradeoff;

use crate::error::{Error, Result};
use crate::io::dump::Frame;

/// A heap frame that would give a wrong number (`demx repose` printed
/// 31.18 +- 44.09 deg on NaN positions and 0 deg on infinite ones, `demx
/// packing` phi = -0.36 with negative radii) is an input error (exit 2)
/// naming the file, the frame (0-based, as `--frame` counts) and the
/// particle. Frames without the columns pass: the measurement says which it
/// needs.
pub(crate) fn check_heap_frame(path: &str, frame: usize, f: &Frame) -> Result<()> {
    let (Ok([x, y, z]), Ok(r)) = (repose::positions(f), repose::radii(f)) else {
        return Ok(());
    };
    let id = |k: usize| f.col("id").and_then(|c| f.get(k, c)).map_or(String::new(), |v| format!("particle {v} "));
    let at = |k: usize| format!("{path}: frame {frame} (timestep {}), atom line {}: {}", f.timestep, k + 1, id(k));
    for k in 0..r.len() {
        if ![x[k], y[k], z[k]].iter().all(|v| v.is_finite()) {
            return Err(Error::usage(format!("{}has position ({} {} {}), which is not finite", at(k), x[k], y[k], z[k])));
        }
        if !(r[k] > 0.0 && r[k].is_finite()) {
            return Err(Error::usage(format!("{}has radius {}; radii must be finite and > 0", at(k), r[k])));
        }
    }
    Ok(())
}
