//! Parsing `fix ID group aeolian/wind ustar z0 rho_f nu_f [keywords]` (a demx
//! extension, namespaced so it cannot pass for a LAMMPS/LIGGGHTS fix) into an
//! [`crate::engine::wind::WindFix`]. Keywords and defaults: physics note
//! /work/shared/physics/aeolian.md section 4 and the README.

use super::args::{parse_f64, Args};
use super::Session;
use crate::engine::wind::{BedRule, DragLaw, GridSpec, Ustar, WindConfig, WindFix};
use crate::error::{Error, Result};
use crate::script::{Command, Variables, Word};

const KEYWORDS: &[&str] = &["kappa", "dir", "drag", "grid", "bed", "every", "relax", "feedback", "beddrag", "file", "fileevery"];

fn positive(a: &mut Args, what: &str) -> Result<f64> {
    let v = a.f64(what)?;
    if !(v > 0.0) || !v.is_finite() {
        return Err(a.err_prev(format!("fix aeolian/wind: {what} must be positive, not {v}")));
    }
    Ok(v)
}

/// Parse the fix and add it to the session.
pub fn fix(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args, vars: &mut Variables) -> Result<()> {
    let _ = (style, vars);
    s.need_box(cmd)?;
    if s.sim.domain.as_ref().is_some_and(|d| d.dimension != 3) {
        return Err(Error::deck(style.span, "fix aeolian/wind needs a 3d box (z is vertical)"));
    }
    let w = a.word("ustar")?;
    let ustar = match w.text.strip_prefix("v_") {
        Some(name) if !name.is_empty() => Ustar::Var(name.to_string()),
        _ => {
            let v = parse_f64(w)?;
            if !(v >= 0.0) || !v.is_finite() {
                return Err(Error::deck(w.span, format!("fix aeolian/wind: ustar must be >= 0, not {v}")));
            }
            Ustar::Const(v)
        }
    };
    let z0 = positive(a, "z0")?;
    let rho_f = positive(a, "rho_f")?;
    let nu_f = positive(a, "nu_f")?;
    let mut cfg = WindConfig {
        id: id.to_string(),
        group,
        ustar,
        z0,
        rho_f,
        nu_f,
        kappa: 0.4,
        dir: 0,
        drag: DragLaw::Cheng,
        grid: GridSpec::Uniform { dz: None, ztop: None },
        bed: BedRule::Phi { phic: 0.3, floor: None },
        every: 1,
        relax: 1.0,
        feedback: true,
        beddrag: true,
        file_every: 0,
    };
    let mut file_name: Option<&Word> = None;
    let mut file_every: Option<i64> = None;
    while a.more() {
        let k = a.choice("aeolian/wind keyword", KEYWORDS)?;
        match k.text.as_str() {
            "kappa" => cfg.kappa = positive(a, "kappa")?,
            "dir" => cfg.dir = if a.choice("dir", &["x", "y"])?.text == "x" { 0 } else { 1 },
            "drag" => {
                let d = a.choice("drag law", &["cheng", "duran", "const"])?;
                cfg.drag = match d.text.as_str() {
                    "cheng" => DragLaw::Cheng,
                    "duran" => DragLaw::Duran { c_inf: positive(a, "Cinf")?, r_c: positive(a, "Rc")? },
                    _ => DragLaw::Const(positive(a, "Cd")?),
                };
            }
            "grid" => {
                let g = a.choice("grid style", &["uniform", "stretch"])?;
                cfg.grid = if g.text == "uniform" {
                    GridSpec::Uniform { dz: Some(positive(a, "dz")?), ztop: Some(a.f64("ztop")?) }
                } else {
                    let dz0 = positive(a, "dz0")?;
                    let zfine = a.f64("zfine")?;
                    let ratio = a.f64("ratio")?;
                    if !(ratio >= 1.0) || !ratio.is_finite() {
                        return Err(a.err_prev(format!("fix aeolian/wind: grid ratio must be >= 1, not {ratio}")));
                    }
                    GridSpec::Stretch { dz0, zfine, ratio, ztop: a.f64("ztop")? }
                };
                let (lo, _) = box_z(s);
                let top = match cfg.grid {
                    GridSpec::Uniform { ztop, .. } => ztop.unwrap_or(f64::INFINITY),
                    GridSpec::Stretch { ztop, .. } => ztop,
                };
                if !(top > lo) || !top.is_finite() {
                    return Err(a.err_prev(format!("fix aeolian/wind: ztop {top} must be above the box bottom {lo}")));
                }
            }
            "bed" => {
                let b = a.choice("bed rule", &["fixed", "phi"])?;
                cfg.bed = if b.text == "fixed" {
                    BedRule::Fixed(a.f64("zb")?)
                } else {
                    let phic = positive(a, "phic")?;
                    let mut floor = None;
                    if a.peek().is_some_and(|w| w.text == "floor") {
                        a.word("floor")?;
                        floor = Some(a.f64("floor height")?);
                    }
                    BedRule::Phi { phic, floor }
                };
            }
            "every" => {
                cfg.every = a.i64("N")?;
                if cfg.every < 1 {
                    return Err(a.err_prev("fix aeolian/wind: every must be >= 1"));
                }
            }
            "relax" => {
                let r = a.f64("alpha")?;
                if !(r > 0.0 && r <= 1.0) {
                    return Err(a.err_prev(format!("fix aeolian/wind: relax must be in (0, 1], not {r}")));
                }
                cfg.relax = r;
            }
            "feedback" => cfg.feedback = a.yes_no("feedback")?,
            "beddrag" => cfg.beddrag = a.yes_no("beddrag")?,
            "file" => file_name = Some(a.word("file name")?),
            _ => {
                let n = a.i64("fileevery")?;
                if n < 1 {
                    return Err(a.err_prev("fix aeolian/wind: fileevery must be >= 1"));
                }
                file_every = Some(n);
            }
        }
    }
    cfg.file_every = file_every.unwrap_or(cfg.every);
    let file = match file_name {
        Some(w) if !s.check && !s.sim.dry => {
            Some(std::fs::File::create(&w.text).map_err(|e| Error::io(w.span, format!("cannot open '{}'", w.text), &e))?)
        }
        _ => None,
    };
    if let Some(f) = &file {
        use std::io::Write;
        let mut f = f;
        let _ = writeln!(f, "# fix {} aeolian/wind per-bin profile\n# z_centre u tau_g phi count", id);
    }
    s.add_fix(Box::new(WindFix::new(cfg, file)))
}

fn box_z(s: &Session) -> (f64, f64) {
    s.sim.domain.as_ref().map_or((0.0, 0.0), |d| (d.lo[2], d.hi[2]))
}
