//! LIGGGHTS 1.x/2.x commands rewritten in LIGGGHTS 3.x syntax.
//!
//! Sources of the rules: LIGGGHTS `doc/liggghts_2.X_tutorial.txt` and
//! `doc/liggghts_3.X_tutorial.txt` (summarised in engines.md 1.5), and the
//! 2.x and 3.x texts of the same tutorial decks (Debian ships the 3.x ones).

use super::deck::{fmt, is_number, Facts};
use super::{Action, Ctx, Severity};

/// Model axes of a legacy `gran/...` style name.
fn legacy_model(style: &str) -> Option<(&'static str, &'static str, Option<&'static str>)> {
    Some(match style {
        "gran/hertz/history" => ("hertz", "history", None),
        "gran/hooke/history" => ("hooke", "history", None),
        "gran/hooke" => ("hooke", "no_history", None),
        "gran/hertz" => ("hertz", "no_history", None),
        "gran/hooke/history/simple" => (
            "hooke/stiffness",
            "history",
            Some("2.x '/simple' styles took kn, kt, gamman, gammat; mapped to hooke/stiffness (damping x m*): check the damping convention"),
        ),
        "gran/hertz/history/simple" => (
            "hertz/stiffness",
            "history",
            Some("2.x '/simple' styles took kn, kt, gamman, gammat; mapped to hertz/stiffness: check the damping convention"),
        ),
        "gran/hooke/history/hysteresis" => ("hooke/hysteresis", "history", None),
        _ => return None,
    })
}

/// Parsed model part of a legacy pair or wall style.
struct Model {
    normal: String,
    tangential: String,
    cohesion: Option<String>,
    rolling: Option<String>,
    keywords: Vec<String>,
}

impl Model {
    fn block(&self) -> String {
        let mut s = format!("model {} tangential {}", self.normal, self.tangential);
        if let Some(c) = &self.cohesion {
            s += &format!(" cohesion {c}");
        }
        if let Some(r) = &self.rolling {
            s += &format!(" rolling_friction {r}");
        }
        s
    }
    fn keywords(&self) -> String {
        if self.keywords.is_empty() {
            String::new()
        } else {
            format!(" {}", self.keywords.join(" "))
        }
    }
}

/// Read 1.x flags `dampflag cohesionflag` at `args[0..2]` if present.
/// Returns the number of words used.
fn flags(ctx: &mut Ctx, args: &[String], m: &mut Model) -> usize {
    let ints = args.iter().take(2).take_while(|w| w.parse::<i64>().is_ok()).count();
    if ints == 0 {
        return 0;
    }
    let d = args[0].parse::<i64>().unwrap_or(1);
    match d {
        0 => m.keywords.push("tangential_damping off".into()),
        1 => {}
        3 => m.rolling = Some("cdt".into()),
        other => ctx.note(Severity::Approx, format!("dampflag {other} has no 3.x keyword; tangential damping left on")),
    }
    if ints == 2 {
        match args[1].parse::<i64>().unwrap_or(0) {
            0 => {}
            1 => m.cohesion = Some("sjkr".into()),
            other => ctx.note(Severity::Approx, format!("cohesionflag {other} has no 3.x keyword; cohesion off")),
        }
    }
    ints
}

/// Pull 2.x model keywords (`cohesion X`, `rolling_friction X`) out of `rest`,
/// leaving the other words in order.
fn model_keywords(rest: &[String], m: &mut Model) -> Vec<String> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < rest.len() {
        match rest[i].as_str() {
            "cohesion" if i + 1 < rest.len() => {
                m.cohesion = Some(rest[i + 1].clone());
                i += 2;
            }
            "rolling_friction" if i + 1 < rest.len() => {
                m.rolling = Some(rest[i + 1].clone());
                i += 2;
            }
            "tangential_damping"
            | "limitForce"
            | "computeDissipatedEnergy"
            | "computeElasticPotential"
            | "heating_normal_hertz"
            | "ktToKnUser"
            | "absolute_damping"
            | "tangential_reduce"
            | "torsionTorque"
                if i + 1 < rest.len() =>
            {
                m.keywords.push(format!("{} {}", rest[i], rest[i + 1]));
                i += 2;
            }
            _ => {
                out.push(rest[i].clone());
                i += 1;
            }
        }
    }
    out
}

/// `pair_style gran/...` (1.x/2.x) -> `pair_style gran model ...`.
pub fn pair_style(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let (n, t, warn) = legacy_model(w.get(1)?)?;
    // LAMMPS gran/* takes >= 5 numbers: not legacy LIGGGHTS
    if w.len() >= 7 && w[2..7].iter().all(|x| is_number(x) || x == "NULL") {
        return None;
    }
    if let Some(msg) = warn {
        ctx.note(Severity::Approx, msg.to_string());
    }
    let mut m = Model { normal: n.into(), tangential: t.into(), cohesion: None, rolling: None, keywords: Vec::new() };
    let used = flags(ctx, &w[2..], &mut m);
    let rest = model_keywords(&w[2 + used..], &mut m);
    if !rest.is_empty() {
        ctx.note(Severity::Approx, format!("pair_style words '{}' kept as written", rest.join(" ")));
        m.keywords.extend(rest);
    }
    Some(Action::Replace(vec![format!("pair_style gran {}{}", m.block(), m.keywords())]))
}

/// `fix ID G wall/gran/STYLE ...` (1.x positional or 2.x primitive/mesh forms).
pub fn wall(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let style = w.get(3)?.strip_prefix("wall/gran/")?;
    let (n, t, warn) = legacy_model(&format!("gran/{style}"))?;
    if w.len() >= 9 && w[4..9].iter().all(|x| is_number(x) || x == "NULL") {
        return None; // LAMMPS-style numbers
    }
    if let Some(msg) = warn {
        ctx.note(Severity::Approx, msg.to_string());
    }
    let (id, group) = (&w[1], &w[2]);
    let mut m = Model { normal: n.into(), tangential: t.into(), cohesion: None, rolling: None, keywords: Vec::new() };
    let used = flags(ctx, &w[4..], &mut m);
    let rest = model_keywords(&w[4 + used..], &mut m);
    let head = format!("fix {id} {group} wall/gran {}", m.block());
    let geom = rest.first().map(|s| s.as_str()).unwrap_or("");
    match geom {
        "xplane" | "yplane" | "zplane" if rest.len() >= 4 && rest[3].parse::<i64>().is_ok() || rest.len() == 4 => {
            let (lo, hi, ty) = (&rest[1], &rest[2], &rest[3]);
            let extra: String = rest[4..].iter().map(|s| format!(" {s}")).collect();
            let planes: Vec<&String> = [lo, hi].into_iter().filter(|v| v.as_str() != "NULL").collect();
            if planes.is_empty() {
                return Some(Action::Drop("both planes NULL: no wall".into(), Severity::Info));
            }
            let ids: Vec<String> = if planes.len() == 1 { vec![id.clone()] } else { vec![format!("{id}1"), format!("{id}2")] };
            if ids.len() > 1 {
                ctx.split_ids.insert(id.clone(), ids.clone());
                ctx.note(Severity::Info, format!("wall {id} split into {} (one plane per fix in 3.x)", ids.join(", ")));
            }
            let lines = planes
                .iter()
                .zip(&ids)
                .map(|(p, i)| format!("fix {i} {group} wall/gran {} primitive type {ty} {geom} {p}{extra}{}", m.block(), m.keywords()))
                .collect();
            Some(Action::Replace(lines))
        }
        "zcylinder" | "xcylinder" | "ycylinder" if rest.len() >= 3 && rest[2].parse::<i64>().is_ok() => {
            let extra: String = rest[3..].iter().map(|s| format!(" {s}")).collect();
            Some(Action::Replace(vec![format!("{head} primitive type {} {geom} {} 0. 0.{extra}{}", rest[2], rest[1], m.keywords())]))
        }
        "mesh/gran" if rest.len() >= 2 => {
            let k = rest[1].parse::<usize>().unwrap_or(0);
            let ids = rest.get(2..2 + k).unwrap_or(&[]);
            let extra: String = rest.get(2 + k..).unwrap_or(&[]).iter().map(|s| format!(" {s}")).collect();
            Some(Action::Replace(vec![format!("{head} mesh n_meshes {k} meshes {}{extra}{}", ids.join(" "), m.keywords())]))
        }
        "primitive" | "mesh" => Some(Action::Replace(vec![format!("{head} {}{}", rest.join(" "), m.keywords())])),
        _ => {
            ctx.note(Severity::Approx, format!("wall geometry '{}' not recognised; words kept as written", rest.join(" ")));
            Some(Action::Replace(vec![format!("{head} {}{}", rest.join(" "), m.keywords())]))
        }
    }
}

/// `fix ID G mesh/gran FILE TYPE scale ox oy oz rx ry rz` and 2.x `fix ID G mesh file ...`.
pub fn mesh(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let (id, group) = (w.get(1)?, w.get(2)?);
    match w.get(3)?.as_str() {
        "mesh" => Some(Action::Replace(vec![format!("fix {id} {group} mesh/surface {}", w[4..].join(" "))])),
        "mesh/gran" => {
            let file = w.get(4)?;
            let ty = w.get(5)?;
            let nums: Vec<Option<f64>> = w.iter().skip(6).take(7).map(|x| ctx.facts.num(x)).collect();
            if nums.len() < 7 || nums.iter().any(|x| x.is_none()) {
                return Some(Action::Replace(vec![format!("fix {id} {group} mesh/surface file {file} type {ty}")])).inspect(|_| {
                    ctx.note(Severity::Approx, "mesh/gran transform values not all constant numbers; scale/offset/rotation dropped".into())
                });
            }
            let v: Vec<f64> = nums.into_iter().flatten().collect();
            let mut s = format!("fix {id} {group} mesh/surface file {file} type {ty}");
            if v[0] != 1.0 {
                s += &format!(" scale {}", w[6]);
            }
            if v[1..4].iter().any(|x| *x != 0.0) {
                // 1.x offsets are in mesh-file units (the bucket example only fits the box that way)
                s += &format!(" move {} {} {}", fmt(v[1] * v[0]), fmt(v[2] * v[0]), fmt(v[3] * v[0]));
            }
            let axes = ["1. 0. 0.", "0. 1. 0.", "0. 0. 1."];
            let mut rotated = false;
            for k in 0..3 {
                if v[4 + k] != 0.0 {
                    s += &format!(" rotate axis {} angle {}", axes[k], w[10 + k]);
                    rotated = true;
                }
            }
            if rotated {
                ctx.note(Severity::Approx, "mesh/gran rotation: 1.x applied offset and x/y/z rotations in an order not verified against 3.x (scale, move, rotate as written)".into());
            }
            if w.len() > 13 {
                s += &format!(" {}", w[13..].join(" "));
            }
            Some(Action::Replace(vec![s]))
        }
        _ => None,
    }
}

/// `fix ID G move/mesh/gran STYLE args MESH TYPE` -> `fix ID G move/mesh mesh MESH STYLE ...`.
pub fn move_mesh(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let (id, group) = (w.get(1)?, w.get(2)?);
    let style = w.get(4)?.as_str();
    let a = &w[5..];
    let out = match style {
        "linear" if a.len() >= 4 => format!("fix {id} {group} move/mesh mesh {} linear {} {} {}", a[3], a[0], a[1], a[2]),
        "rotate" if a.len() >= 8 => format!(
            "fix {id} {group} move/mesh mesh {} rotate origin {} {} {} axis {} {} {} period {}",
            a[7], a[0], a[1], a[2], a[3], a[4], a[5], a[6]
        ),
        "wiggle" if a.len() >= 5 => format!("fix {id} {group} move/mesh mesh {} wiggle amplitude {} {} {} period {}", a[4], a[0], a[1], a[2], a[3]),
        _ => {
            ctx.note(Severity::Approx, format!("move/mesh/gran style '{style}' not recognised; only renamed"));
            format!("fix {id} {group} move/mesh {}", w[4..].join(" "))
        }
    };
    Some(Action::Replace(vec![out]))
}

/// `fix ID G heat/gran T0` -> `initial_temperature T0`.
pub fn heat(_ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let first = w.get(4)?;
    if !is_number(first) && !first.starts_with('$') {
        return None;
    }
    let rest: String = w[5..].iter().map(|s| format!(" {s}")).collect();
    Some(Action::Replace(vec![format!("fix {} {} heat/gran initial_temperature {first}{rest}", w[1], w[2])]))
}

/// Dump style aliases.
pub fn dump(_ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let new = match w.get(3)?.as_str() {
        "stl" => "mesh/stl",
        "mesh/gran/VTK" => "mesh/vtk",
        _ => return None,
    };
    let mut v = w.to_vec();
    v[3] = new.into();
    Some(Action::Replace(vec![v.join(" ")]))
}

/// Parsed `fix pour` (LIGGGHTS 1.x, LAMMPS old and new forms).
#[derive(Clone, Debug, Default)]
pub struct Pour {
    /// Total particles.
    pub n: String,
    /// Atom type.
    pub ty: String,
    /// Seed.
    pub seed: String,
    /// Volume fraction and tries.
    pub vol: Option<(String, String)>,
    /// Diameters: (d, probability) list; a range is (lo, hi) with `range`.
    pub diam_range: Option<(String, String)>,
    /// Poly diameters with number fractions.
    pub poly: Vec<(String, String)>,
    /// Density range.
    pub dens: Option<(String, String)>,
    /// Velocities vxlo vxhi vylo vyhi vz.
    pub vel: Vec<String>,
    /// Region ID.
    pub region: String,
    /// Words not understood.
    pub other: Vec<String>,
}

/// Parse `fix ID G pour N type seed keyword...`.
pub fn parse_pour(w: &[String]) -> Option<Pour> {
    let mut p = Pour { n: w.get(4)?.clone(), ty: w.get(5)?.clone(), seed: w.get(6)?.clone(), ..Default::default() };
    let mut i = 7;
    let skip_uniform = |i: &mut usize| {
        if w.get(*i).map(|s| s.as_str()) == Some("uniform") {
            *i += 1;
        }
    };
    while i < w.len() {
        let k = w[i].as_str();
        i += 1;
        match k {
            "vol" => {
                p.vol = Some((w.get(i)?.clone(), w.get(i + 1)?.clone()));
                i += 2;
            }
            "diam" => {
                skip_uniform(&mut i);
                match w.get(i)?.as_str() {
                    "one" => {
                        p.diam_range = Some((w.get(i + 1)?.clone(), w.get(i + 1)?.clone()));
                        i += 2;
                    }
                    "range" => {
                        p.diam_range = Some((w.get(i + 1)?.clone(), w.get(i + 2)?.clone()));
                        i += 3;
                    }
                    "poly" => {
                        let n: usize = w.get(i + 1)?.parse().ok()?;
                        for k in 0..n {
                            p.poly.push((w.get(i + 2 + 2 * k)?.clone(), w.get(i + 3 + 2 * k)?.clone()));
                        }
                        i += 2 + 2 * n;
                    }
                    _ => {
                        p.diam_range = Some((w.get(i)?.clone(), w.get(i + 1)?.clone()));
                        i += 2;
                    }
                }
            }
            "dens" => {
                skip_uniform(&mut i);
                p.dens = Some((w.get(i)?.clone(), w.get(i + 1)?.clone()));
                i += 2;
            }
            "vel" => {
                skip_uniform(&mut i);
                // 3d: vxlo vxhi vylo vyhi vz
                p.vel = w.get(i..i + 5)?.to_vec();
                i += 5;
            }
            "region" => {
                p.region = w.get(i)?.clone();
                i += 1;
            }
            _ => p.other.push(k.to_string()),
        }
    }
    if p.region.is_empty() {
        return None;
    }
    Some(p)
}

/// Number of timesteps a pour batch takes to fall through its region
/// (LAMMPS fix pour's insertion interval, from v0 and g), if known.
pub fn fall_steps(facts: &Facts, region: &str, vz: f64) -> Option<u64> {
    let h = facts.region_height(region)?;
    let g = facts.gravity?;
    let dt = facts.dt?;
    let v0 = vz.abs();
    // h = v0 t + g t^2 / 2
    let t = if g > 0.0 { (-v0 + (v0 * v0 + 2.0 * g * h).sqrt()) / g } else { h / v0.max(1e-12) };
    Some(((t / dt).ceil() as u64).max(1))
}

/// `fix pour` / `pour/legacy` -> particletemplate + particledistribution + insert/rate/region.
pub fn pour_to_insert(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let p = match parse_pour(w) {
        Some(p) => p,
        None => return Some(Action::Drop("fix pour arguments not understood".into(), Severity::Dropped)),
    };
    let (id, group) = (&w[1], &w[2]);
    let f = ctx.facts;
    let mut sizes: Vec<(f64, f64)> = Vec::new(); // (diameter, number fraction)
    if let Some((lo, hi)) = &p.diam_range {
        let (lo, hi) = match (f.num(lo), f.num(hi)) {
            (Some(a), Some(b)) => (a, b),
            _ => return Some(Action::Drop("pour diameters are not constant numbers".into(), Severity::Dropped)),
        };
        if lo == hi {
            sizes.push((lo, 1.0));
        } else {
            let nb = 5;
            for k in 0..nb {
                sizes.push((lo + (k as f64 + 0.5) / nb as f64 * (hi - lo), 1.0 / nb as f64));
            }
            ctx.note(
                Severity::Approx,
                format!("uniform diameters {lo}..{hi} discretised into {nb} equal-number sizes (LIGGGHTS 3.x templates take one radius each)"),
            );
        }
    } else {
        for (d, q) in &p.poly {
            match (f.num(d), f.num(q)) {
                (Some(d), Some(q)) => sizes.push((d, q)),
                _ => return Some(Action::Drop("pour poly values are not constant numbers".into(), Severity::Dropped)),
            }
        }
    }
    if sizes.is_empty() {
        sizes.push((1.0, 1.0));
        ctx.note(Severity::Approx, "pour without diam: LAMMPS default diameter 1.0".into());
    }
    let dens = match &p.dens {
        Some((lo, hi)) => match (f.num(lo), f.num(hi)) {
            (Some(a), Some(b)) => {
                if a != b {
                    ctx.note(Severity::Approx, format!("uniform density {a}..{b} replaced by its mean"));
                }
                0.5 * (a + b)
            }
            _ => return Some(Action::Drop("pour densities are not constant numbers".into(), Severity::Dropped)),
        },
        None => 1.0,
    };
    let mut lines = Vec::new();
    // mass-based weights (LIGGGHTS particledistribution/discrete weighs by mass)
    let masses: Vec<f64> = sizes.iter().map(|(d, q)| q * d * d * d).collect();
    let msum: f64 = masses.iter().sum();
    let mut tmpl = Vec::new();
    for (k, (d, _)) in sizes.iter().enumerate() {
        let tid = if sizes.len() == 1 { format!("{id}_pts") } else { format!("{id}_pts{}", k + 1) };
        let seed = ctx.new_seed();
        lines.push(format!(
            "fix {tid} {group} particletemplate/sphere {seed} atom_type {} density constant {} radius constant {}",
            p.ty,
            fmt(dens),
            fmt(d / 2.0)
        ));
        tmpl.push(format!("{tid} {}", fmt(masses[k] / msum)));
    }
    let seed = ctx.new_seed();
    lines.push(format!("fix {id}_pdd {group} particledistribution/discrete {seed} {} {}", sizes.len(), tmpl.join(" ")));
    // batch size and interval as LAMMPS fix pour computes them
    let vel: Vec<f64> = p.vel.iter().map(|x| f.num(x).unwrap_or(0.0)).collect();
    let (vx, vy, vz) = if vel.len() == 5 { (0.5 * (vel[0] + vel[1]), 0.5 * (vel[2] + vel[3]), vel[4]) } else { (0.0, 0.0, 0.0) };
    if vel.len() == 5 && (vel[0] != vel[1] || vel[2] != vel[3]) {
        ctx.note(Severity::Approx, "random lateral velocity range replaced by its mean".into());
    }
    let frac = p.vol.as_ref().and_then(|(v, _)| f.num(v)).unwrap_or(0.25);
    let n_total = f.num(&p.n);
    let vp: f64 = sizes.iter().map(|(d, q)| q * std::f64::consts::PI / 6.0 * d * d * d).sum::<f64>();
    let batch = f.region_volume(&p.region).map(|v| (frac * v / vp).floor().max(1.0));
    let steps = fall_steps(f, &p.region, vz);
    let (every, rate) = match (batch, steps, f.dt) {
        (Some(b), Some(k), Some(dt)) => {
            let b = n_total.map(|n| b.min(n)).unwrap_or(b);
            (k, b / (k as f64 * dt))
        }
        _ => {
            ctx.note(
                Severity::Approx,
                "pour batch size or interval unknown (region, gravity or timestep not constant): insert_every 1000 with 1 particle per step".into(),
            );
            (1000, 1.0 / f.dt.unwrap_or(1.0))
        }
    };
    ctx.note(Severity::Approx, format!("fix pour emulated by insert/rate/region: a batch every {every} steps (the fall time through region {}) at volume fraction {frac}; positions and timing differ", p.region));
    lines.push(format!(
        "fix {id} {group} insert/rate/region seed {} distributiontemplate {id}_pdd nparticles {} particlerate {} insert_every {every} overlapcheck yes vel constant {} {} {} region {}",
        ctx.new_seed(),
        p.n,
        fmt(rate),
        fmt(vx),
        fmt(vy),
        fmt(vz),
        p.region
    ));
    if !p.other.is_empty() {
        ctx.note(Severity::Approx, format!("pour words '{}' dropped", p.other.join(" ")));
    }
    Some(Action::Replace(lines))
}

/// 1.x `fix ID G pour/dev (mass M | N) seed distributiontemplate PDD ... massflowrate R | particlerate R ...`.
pub fn pour_dev(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let (id, group) = (&w[1], &w[2]);
    let mut i = 4;
    let amount = if w.get(4).map(|s| s.as_str()) == Some("mass") {
        i += 2;
        format!("mass {}", w.get(5)?)
    } else {
        i += 1;
        format!("nparticles {}", w.get(4)?)
    };
    i += 1; // seed
    let mut pdd = None;
    let mut rate = None;
    let mut vel = Vec::new();
    let mut region = None;
    let mut frac = None;
    while i < w.len() {
        let k = w[i].as_str();
        i += 1;
        match k {
            "distributiontemplate" => {
                pdd = w.get(i).cloned();
                i += 1;
            }
            "vol" => {
                frac = w.get(i).cloned();
                i += 2;
            }
            "massflowrate" => {
                rate = Some(format!("massrate {}", w.get(i)?));
                i += 1;
            }
            "particleflowrate" | "particlerate" => {
                rate = Some(format!("particlerate {}", w.get(i)?));
                i += 1;
            }
            "vel" => {
                if w.get(i).map(|s| s.as_str()) == Some("uniform") {
                    i += 1;
                }
                vel = w.get(i..i + 5)?.to_vec();
                i += 5;
            }
            "region" => {
                region = w.get(i).cloned();
                i += 1;
            }
            _ => ctx.note(Severity::Approx, format!("pour/dev word '{k}' dropped")),
        }
    }
    let (pdd, region) = match (pdd, region) {
        (Some(a), Some(b)) => (a, b),
        _ => return Some(Action::Drop("pour/dev without distributiontemplate or region".into(), Severity::Dropped)),
    };
    let v: Vec<f64> = vel.iter().map(|x| ctx.facts.num(x).unwrap_or(0.0)).collect();
    let (vx, vy, vz) = if v.len() == 5 { (0.5 * (v[0] + v[1]), 0.5 * (v[2] + v[3]), v[4]) } else { (0.0, 0.0, 0.0) };
    if v.len() == 5 && (v[0] != v[1] || v[2] != v[3]) {
        ctx.note(Severity::Approx, "random lateral velocity range replaced by its mean".into());
    }
    let every = fall_steps(ctx.facts, &region, vz).unwrap_or(1000);
    let rate = rate.unwrap_or_else(|| "particlerate 1000".into());
    if let Some(fr) = frac {
        ctx.note(Severity::Info, format!("pour/dev volume fraction {fr} is implied by the rate in insert/rate/region"));
    }
    ctx.note(Severity::Approx, format!("pour/dev mapped to insert/rate/region, a batch every {every} steps (fall time through region {region})"));
    let seed = ctx.new_seed();
    Some(Action::Replace(vec![format!(
        "fix {id} {group} insert/rate/region seed {seed} distributiontemplate {pdd} {amount} {rate} insert_every {every} overlapcheck yes vel constant {} {} {} region {region}",
        fmt(vx),
        fmt(vy),
        fmt(vz)
    )]))
}

/// Seeds: LIGGGHTS 3.8 requires primes > 10000 (random.cpp, verified).
pub fn seeds(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let style = w.get(3)?.as_str();
    let pos = if style == "particletemplate/sphere" || style.starts_with("particledistribution/discrete") {
        4
    } else if style.starts_with("insert/") {
        w.iter().position(|x| x == "seed")? + 1
    } else {
        return None;
    };
    let s = w.get(pos)?;
    if let Some(v) = s.parse::<u64>().ok().filter(|v| *v > 10000 && is_prime(*v)) {
        ctx.used_seeds.insert(v);
        return None;
    }
    let new = ctx.new_seed();
    ctx.note(Severity::Info, format!("seed {s} -> {new} (LIGGGHTS 3.x requires a prime > 10000)"));
    let mut v = w.to_vec();
    v[pos] = new.to_string();
    Some(Action::Replace(vec![v.join(" ")]))
}

/// Primality by trial division (seeds only).
pub fn is_prime(n: u64) -> bool {
    if n < 2 {
        return false;
    }
    let mut d = 2;
    while d * d <= n {
        if n.is_multiple_of(d) {
            return false;
        }
        d += 1;
    }
    true
}
