//! LIGGGHTS 3.x <-> LAMMPS (29 Sep 2021) granular commands.
//!
//! Hertz: LIGGGHTS `model hertz` with materials maps to LAMMPS `pair_style
//! granular` `hertz/material E e' nu tangential mindlin kt xgt mu damping
//! tsuji` where
//! - `E = 2(1-nu^2) Y*` (LAMMPS takes E_eff = E/(2(1-nu^2)) for explicit
//!   coefficients), `kt = 8 G*` (LAMMPS mindlin force kt a xi, LIGGGHTS
//!   kt = 8 G* sqrt(R* delta));
//! - LAMMPS tsuji damping is alpha(e') sqrt(m* (4/3) Y* a), LIGGGHTS's is
//!   2 sqrt(5/6) |beta(e)| sqrt(2 Y* a m*): equal when alpha(e') =
//!   sqrt(5) |beta(e)|, so e' is solved from that (possible for e >= ~0.114);
//! - tangential damping ratio xgt = gamma_t/gamma_n = 2 sqrt(G*/Y*).
//!
//! The normal force law is then identical; what remains different is the
//! tangential model (LAMMPS caps the total tangential force including
//! damping and rescales history; LIGGGHTS caps the elastic part, no damping
//! while sliding; lever arm R vs R - delta/2).

use super::deck::{fmt, is_number, Facts};
use super::legacy;
use super::{Action, Ctx, Severity};

/// LAMMPS 2021 tsuji polynomial alpha(e).
pub fn tsuji_alpha(e: f64) -> f64 {
    let c = [1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218];
    c.iter().rev().fold(0.0, |acc, k| acc * e + k)
}

/// LIGGGHTS beta(e) = ln e / sqrt(ln^2 e + pi^2) (negative).
pub fn beta(e: f64) -> f64 {
    let l = e.ln();
    l / (l * l + std::f64::consts::PI.powi(2)).sqrt()
}

/// Restitution e whose beta has magnitude `b` (inverse of [`beta`]).
pub fn e_from_beta(b: f64) -> f64 {
    let b = b.abs().min(0.999_999);
    (-std::f64::consts::PI * b / (1.0 - b * b).sqrt()).exp()
}

/// The e' to give LAMMPS `damping tsuji` so it damps like LIGGGHTS hertz
/// with restitution `e`; None when no e' in [0,1] reaches it.
pub fn tsuji_e_for(e: f64) -> Option<f64> {
    if e >= 1.0 {
        return Some(1.0);
    }
    let target = 5f64.sqrt() * beta(e).abs();
    if target > tsuji_alpha(0.0) {
        return None;
    }
    // alpha decreases on [0, 1]: bisection
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if tsuji_alpha(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// LIGGGHTS restitution that LAMMPS tsuji with e' reproduces.
pub fn liggghts_e_for_tsuji(e_prime: f64) -> f64 {
    e_from_beta(tsuji_alpha(e_prime) / 5f64.sqrt())
}

/// Mixed material of a type pair (LIGGGHTS mixing, engines.md 1.3).
struct Pair {
    y_star: f64,
    g_star: f64,
    nu: f64,
    e: f64,
    mu: f64,
}

fn pair_material(f: &Facts, i: usize, j: usize) -> Option<Pair> {
    let y = f.per_type("youngsModulus")?;
    let nu = f.per_type("poissonsRatio")?;
    let (yi, yj, ni, nj) = (*y.get(i - 1)?, *y.get(j - 1)?, *nu.get(i - 1)?, *nu.get(j - 1)?);
    let y_star = 1.0 / ((1.0 - ni * ni) / yi + (1.0 - nj * nj) / yj);
    let g_star = 1.0 / (2.0 * (2.0 - ni) * (1.0 + ni) / yi + 2.0 * (2.0 - nj) * (1.0 + nj) / yj);
    let e = f.pair_value("coefficientRestitution", i, j)?;
    let mu = f.pair_value("coefficientFriction", i, j)?;
    Some(Pair { y_star, g_star, nu: 0.5 * (ni + nj), e, mu })
}

/// Parsed LIGGGHTS 3.x model block (fields private to the converter).
#[derive(Default, Debug, Clone)]
pub struct Model3 {
    normal: String,
    tangential: String,
    cohesion: Option<String>,
    rolling: Option<String>,
    tangential_damping: bool,
    rest: Vec<String>,
}

fn parse_model3(w: &[String]) -> Option<(Model3, Vec<String>)> {
    let mut m = Model3 { tangential_damping: true, tangential: "history".into(), ..Default::default() };
    let mut i = 0;
    let mut other = Vec::new();
    while i < w.len() {
        let k = w[i].as_str();
        let v = w.get(i + 1).cloned();
        match (k, v) {
            ("model", Some(v)) => m.normal = v,
            ("tangential", Some(v)) => m.tangential = v,
            ("cohesion", Some(v)) => m.cohesion = Some(v),
            ("rolling_friction", Some(v)) => m.rolling = Some(v),
            ("surface", Some(v)) if v == "default" => {}
            ("tangential_damping", Some(v)) => m.tangential_damping = v != "off",
            _ => {
                other.push(w[i].clone());
                i += 1;
                continue;
            }
        }
        i += 2;
    }
    if m.normal.is_empty() {
        return None;
    }
    Some((m, other))
}

/// LAMMPS granular coefficient string for type pair (i, j) under model `m`.
/// `wall`: the coefficients of a `fix wall/gran granular`, where LAMMPS
/// 2021 takes the wall's effective modulus as E/(2(1-nu)) (measured; pairs:
/// E/(2(1-nu^2)) from the mixing rule), so E is chosen to give LIGGGHTS' Y*.
fn granular_coeffs(ctx: &mut Ctx, m: &Model3, i: usize, j: usize, wall: bool) -> Option<String> {
    let f = ctx.facts;
    match m.normal.as_str() {
        "hertz" => {
            let p = pair_material(f, i, j)?;
            let e_p = match tsuji_e_for(p.e) {
                Some(x) => x,
                None => {
                    ctx.note(Severity::Approx, format!("restitution {} is below what LAMMPS tsuji can reach (~0.114): e' = 0 used", p.e));
                    0.0
                }
            };
            let e_lmp = if wall { 2.0 * (1.0 - p.nu) * p.y_star } else { 2.0 * (1.0 - p.nu * p.nu) * p.y_star };
            let xgt = if m.tangential_damping { 2.0 * (p.g_star / p.y_star).sqrt() } else { 0.0 };
            let tang = match m.tangential.as_str() {
                "history" => format!("mindlin {} {} {}", fmt(8.0 * p.g_star), fmt(xgt), fmt(p.mu)),
                "no_history" => format!("linear_nohistory {} {}", fmt(xgt), fmt(p.mu)),
                other => {
                    ctx.note(Severity::Approx, format!("tangential {other} has no LAMMPS counterpart: mindlin used"));
                    format!("mindlin {} {} {}", fmt(8.0 * p.g_star), fmt(xgt), fmt(p.mu))
                }
            };
            let roll = match rolling_sds(ctx, m, &p, i, j) {
                Some(r) => format!(" {r}"),
                None => {
                    if let Some(r) = m.rolling.as_deref().filter(|r| r.starts_with("epsd")) {
                        ctx.note(Severity::Approx, format!("rolling_friction {r}: no constant radius, density or coefficientRollingFriction for types {i} {j}, so no rolling sds equivalent: dropped"));
                    }
                    String::new()
                }
            };
            Some(format!("hertz/material {} {} {} tangential {tang} damping tsuji{roll}", fmt(e_lmp), fmt(e_p), fmt(p.nu)))
        }
        "hooke/stiffness" | "hertz/stiffness" => {
            let kn = f.pair_value("kn", i, j)?;
            let kt = f.pair_value("kt", i, j)?;
            let gn = f.pair_value("gamman", i, j)?;
            let gt = f.pair_value("gammat", i, j)?;
            let mu = f.pair_value("coefficientFriction", i, j)?;
            let normal = if m.normal == "hooke/stiffness" { "hooke" } else { "hertz" };
            let xgt = if gn != 0.0 { gt / gn } else { 0.0 };
            let tang = if m.tangential == "no_history" {
                format!("linear_nohistory {} {}", fmt(xgt), fmt(mu))
            } else {
                format!("linear_history {} {} {}", fmt(kt), fmt(xgt), fmt(mu))
            };
            Some(format!("{normal} {} {} tangential {tang} damping mass_velocity", fmt(kn), fmt(gn)))
        }
        _ => None,
    }
}

/// Radius and density of the particles of type `t`, from a particle template.
fn type_particle(f: &Facts, t: usize) -> Option<(f64, f64)> {
    let mut found = None;
    for tp in f.templates.values() {
        if f.num(&tp.atom_type).map(|v| v as usize) == Some(t) {
            let (r, rho) = (f.num(&tp.radius)?, f.num(&tp.density)?);
            if found.is_some_and(|(r0, _)| r0 != r) {
                return None; // several sizes of one type: no single radius
            }
            found = Some((r, rho));
        }
    }
    found
}

/// Rolling models LIGGGHTS EPSD-family -> LAMMPS `rolling sds k_roll 0 mu_roll`.
/// Both cap the rolling torque at mu_r R* |F_n| (LIGGGHTS rolling_model_epsd*.h;
/// LAMMPS pair_granular: torque R_eff n x F_roll with |F_roll| <= mu_roll F_n),
/// so mu_roll = mu_r is exact. The spring is not: EPSD's k_r follows the
/// contact (epsd: 2.25 k_n mu_r^2 R*^2, epsd2: k_t R*^2 with the Hertz
/// stiffnesses at the current overlap), SDS's k_roll R*^2 is constant. k_roll
/// is taken at a reference overlap: the Hertz overlap under ten particle
/// weights (a contact a few layers deep in a resting pile) when gravity is
/// known, else 0.1% of R*.
fn rolling_sds(ctx: &mut Ctx, m: &Model3, p: &Pair, i: usize, j: usize) -> Option<String> {
    let r = m.rolling.as_deref()?;
    if !matches!(r, "epsd" | "epsd2" | "epsd3") {
        return None;
    }
    let f = ctx.facts;
    let mu_r = f.pair_value("coefficientRollingFriction", i, j)?;
    let ((ri, rhoi), (rj, _)) = (type_particle(f, i)?, type_particle(f, j)?);
    let r_star = ri * rj / (ri + rj);
    let delta = match f.gravity {
        Some(g) if g > 0.0 => {
            let weight = 10.0 * rhoi * 4.0 / 3.0 * std::f64::consts::PI * ri.powi(3) * g;
            // Hertz: F = 4/3 Y* sqrt(R*) delta^(3/2)
            (3.0 * weight / (4.0 * p.y_star * r_star.sqrt())).powf(2.0 / 3.0)
        }
        _ => 1e-3 * r_star,
    };
    let a = (r_star * delta).sqrt();
    let (kn, kt) = (2.0 * p.y_star * a, 8.0 * p.g_star * a);
    let k_roll = match r {
        "epsd" => 2.25 * kn * mu_r * mu_r,
        "epsd2" => kt,
        _ => f.props.get("rollingStiffness").and_then(|pr| pr.values.first()).and_then(|v| f.num(v)).map(|c| c * kn * mu_r * mu_r)?,
    };
    ctx.note(
        Severity::Approx,
        format!(
            "rolling_friction {r} -> rolling sds: the torque cap mu_r R* |Fn| is the same; the spring is constant in LAMMPS (k_roll {} N/m, LIGGGHTS' value at overlap {:.3e} m){}",
            fmt(k_roll),
            delta,
            if r == "epsd" { "; the EPSD viscous rolling damping is dropped" } else { "" }
        ),
    );
    Some(format!("rolling sds {} 0 {}", fmt(k_roll), fmt(mu_r)))
}

fn ntypes(ctx: &Ctx) -> usize {
    ctx.facts.ntypes.unwrap_or(1).max(1)
}

/// Classic `gran/hooke/history` form when the model and values allow it.
fn classic_style(ctx: &Ctx, m: &Model3) -> Option<String> {
    let f = ctx.facts;
    let style = match (m.normal.as_str(), m.tangential.as_str()) {
        ("hooke/stiffness", "history") => "gran/hooke/history",
        ("hooke/stiffness", "no_history") => "gran/hooke",
        ("hertz/stiffness", "history") => "gran/hertz/history",
        _ => return None,
    };
    let n = ntypes(ctx);
    let names = ["kn", "kt", "gamman", "gammat", "coefficientFriction"];
    let first: Vec<f64> = names.iter().map(|k| f.pair_value(k, 1, 1)).collect::<Option<_>>()?;
    for i in 1..=n {
        for j in 1..=n {
            let v: Vec<f64> = names.iter().map(|k| f.pair_value(k, i, j)).collect::<Option<_>>()?;
            if v != first {
                return None;
            }
        }
    }
    if f.props.contains_key("gamman_abs") || m.rest.iter().any(|r| r == "absolute_damping") {
        return None;
    }
    Some(format!("{style} {} {} {} {} {} 1", fmt(first[0]), fmt(first[1]), fmt(first[2]), fmt(first[3]), fmt(first[4])))
}

fn drop_model_axes(ctx: &mut Ctx, m: &Model3) {
    if let Some(c) = &m.cohesion {
        ctx.note(Severity::Approx, format!("cohesion {c} has no LAMMPS counterpart (dmt/jkr are different laws): dropped"));
    }
    let sds = m.normal == "hertz" && matches!(m.rolling.as_deref(), Some("epsd" | "epsd2" | "epsd3"));
    if let Some(r) = m.rolling.as_ref().filter(|_| !sds) {
        ctx.note(Severity::Approx, format!("rolling_friction {r} has no LAMMPS counterpart (rolling sds is a different law): dropped"));
    }
}

/// 3.x `pair_style gran model ...` -> LAMMPS (the coefficients go to the
/// `pair_coeff` line).
pub fn pair_style_to_lammps(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if w.get(1).map(|s| s.as_str()) != Some("gran") {
        return None;
    }
    let (m, other) = match parse_model3(&w[2..]) {
        Some(x) => x,
        None => return Some(Action::Drop("pair_style gran without model".into(), Severity::Dropped)),
    };
    if !other.is_empty() {
        ctx.note(Severity::Approx, format!("model keywords '{}' dropped", other.join(" ")));
    }
    if !matches!(m.normal.as_str(), "hertz" | "hooke/stiffness" | "hertz/stiffness") {
        ctx.pair_dropped = true;
        return Some(Action::Drop(format!("model {} has no LAMMPS counterpart with the same law (LIGGGHTS hooke derives kn from characteristicVelocity and each pair's mass and radius)", m.normal), Severity::Dropped));
    }
    drop_model_axes(ctx, &m);
    let line = if let Some(s) = classic_style(ctx, &m) {
        ctx.pair_done = true;
        format!("pair_style {s}")
    } else {
        "pair_style granular".to_string()
    };
    ctx.model = Some(m);
    if ctx.model.as_ref().map(|m| m.normal == "hertz").unwrap_or(false) {
        ctx.note(Severity::Approx, "hertz: normal force identical (tsuji e' solved to match LIGGGHTS damping); tangential differs: LAMMPS caps |elastic+damping| and rescales history, LIGGGHTS caps the elastic part and does not damp while sliding; lever arm R vs R-delta/2".into());
    }
    Some(Action::Replace(vec![line]))
}

/// `pair_coeff * *` after a converted 3.x pair_style.
pub fn pair_coeff_to_lammps(ctx: &mut Ctx, _w: &[String]) -> Option<Action> {
    if ctx.pair_dropped {
        return Some(Action::Drop("belongs to the dropped pair_style".into(), Severity::Info));
    }
    let m = ctx.model.take()?;
    if ctx.pair_done {
        ctx.pair_done = false;
        return Some(Action::Replace(vec!["pair_coeff * *".into()]));
    }
    let n = ntypes(ctx);
    let mut lines = Vec::new();
    for i in 1..=n {
        for j in i..=n {
            match granular_coeffs(ctx, &m, i, j, false) {
                Some(c) => lines.push(format!("pair_coeff {i} {j} {c}")),
                None => {
                    return Some(Action::Drop(
                        format!("model {} or its material properties (constant numbers) not convertible", m.normal),
                        Severity::Dropped,
                    ))
                }
            }
        }
    }
    ctx.wall_model = Some(m);
    Some(Action::Replace(lines))
}

/// Wall coefficient string for a wall of material type `t` (particle type 1).
fn wall_coeffs(ctx: &mut Ctx, m: &Model3, t: usize) -> Option<String> {
    if ntypes(ctx) > 1 {
        ctx.note(Severity::Approx, "LAMMPS wall/gran takes one coefficient set for all particle types: type 1 against the wall type used".into());
    }
    let f = ctx.facts;
    if m.normal.ends_with("/stiffness") {
        let names = ["kn", "kt", "gamman", "gammat", "coefficientFriction"];
        let v: Vec<f64> = names.iter().map(|k| f.pair_value(k, 1, t)).collect::<Option<_>>()?;
        let style = match (m.normal.as_str(), m.tangential.as_str()) {
            ("hooke/stiffness", "no_history") => "hooke",
            ("hooke/stiffness", _) => "hooke/history",
            _ => "hertz/history",
        };
        return Some(format!("{style} {} {} {} {} {} 1", fmt(v[0]), fmt(v[1]), fmt(v[2]), fmt(v[3]), fmt(v[4])));
    }
    Some(format!("granular {}", granular_coeffs(ctx, m, 1, t, true)?))
}

/// Remember the force style of a classic LAMMPS `pair_style gran/hooke`,
/// `gran/hooke/history` or `gran/hertz/history` (any other pair style
/// forgets it), for the 2012-era walls after it ([`legacy_wall_to_lammps`]).
pub fn note_classic_style(ctx: &mut Ctx, w: &[String]) {
    ctx.legacy_wall_style =
        w.get(1).and_then(|s| s.strip_prefix("gran/")).filter(|s| matches!(*s, "hooke" | "hooke/history" | "hertz/history")).map(str::to_string);
}

/// 2012-era LAMMPS `fix ID G wall/gran Kn Kt gn gt xmu dampflag wallstyle
/// ...`, whose force style was the pair style's, -> the current form with
/// that style written after `wall/gran` (LAMMPS 29 Sep 2021 rejects the old
/// form: "Invalid fix wall/gran interaction style"). None for the other
/// forms.
pub fn legacy_wall_to_lammps(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if w.get(3).map(|s| s.as_str()) != Some("wall/gran") || !is_number(w.get(4)?) {
        return None;
    }
    let Some(style) = ctx.legacy_wall_style.clone() else {
        ctx.note(Severity::Approx, "fix wall/gran without a force style and no pair_style gran/* before it: LAMMPS 29 Sep 2021 needs the style (hooke, hooke/history or hertz/history) after wall/gran".into());
        return Some(Action::Keep);
    };
    ctx.note(Severity::Info, format!("2012-era fix wall/gran: the pair style's force style ({style}) written out"));
    let mut v: Vec<&str> = w.iter().map(String::as_str).collect();
    v.insert(4, &style);
    Some(Action::Replace(vec![v.join(" ")]))
}

/// 3.x `fix ID G wall/gran model ... primitive type T geom args` -> LAMMPS.
pub fn wall_to_lammps(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if w.get(3).map(|s| s.as_str()) != Some("wall/gran") || w.get(4).map(|s| s.as_str()) != Some("model") {
        return None;
    }
    let (id, group) = (&w[1], &w[2]);
    let pos = match w.iter().position(|x| x == "primitive") {
        Some(p) => p,
        None => return Some(Action::Drop("mesh walls: LAMMPS 2021 has no triangle-mesh granular walls".into(), Severity::Dropped)),
    };
    let (m, other) = parse_model3(&w[4..pos])?;
    let tail = &w[pos + 1..];
    // primitive type T geom args [keywords]
    if tail.len() < 4 || tail[0] != "type" {
        return Some(Action::Drop("primitive wall arguments not understood".into(), Severity::Dropped));
    }
    let t: usize = match ctx.facts.num(&tail[1]) {
        Some(v) => v as usize,
        None => return Some(Action::Drop("wall type is not a constant number".into(), Severity::Dropped)),
    };
    let geom = tail[2].as_str();
    let mut rest_words = Vec::new();
    let (m, _) = {
        let mut m = m;
        // keywords after the geometry (tangential_damping off etc.)
        let nargs = match geom {
            "xplane" | "yplane" | "zplane" => 1,
            _ => 3,
        };
        let after = tail.get(3 + nargs..).unwrap_or(&[]);
        let mut i = 0;
        while i < after.len() {
            if after[i] == "tangential_damping" {
                m.tangential_damping = after.get(i + 1).map(|s| s.as_str()) != Some("off");
                i += 2;
            } else {
                rest_words.push(after[i].clone());
                i += 1;
            }
        }
        (m, ())
    };
    if !other.is_empty() || !rest_words.is_empty() {
        ctx.note(Severity::Approx, format!("wall words '{}' dropped", other.iter().chain(&rest_words).cloned().collect::<Vec<_>>().join(" ")));
    }
    drop_model_axes(ctx, &m);
    let coeffs = match wall_coeffs(ctx, &m, t) {
        Some(c) => c,
        None if ctx.pair_dropped => return Some(Action::Drop("the pair model was dropped; its wall goes too".into(), Severity::Dropped)),
        None => return Some(Action::Drop(format!("wall model {} or its material properties not convertible", m.normal), Severity::Dropped)),
    };
    let line = match geom {
        "xplane" | "yplane" | "zplane" => {
            let v = &tail[3];
            let axis = (geom.as_bytes()[0] - b'x') as usize;
            let val = ctx.facts.num(v);
            let lower = match (val, ctx.facts.box_bounds(axis)) {
                (Some(x), Some((lo, hi))) => (x - lo).abs() <= (x - hi).abs(),
                _ => true,
            };
            if lower {
                format!("fix {id} {group} wall/gran {coeffs} {geom} {v} NULL")
            } else {
                format!("fix {id} {group} wall/gran {coeffs} {geom} NULL {v}")
            }
        }
        "zcylinder" if tail.len() >= 6 => {
            let (r, c1, c2) = (&tail[3], &tail[4], &tail[5]);
            if ctx.facts.num(c1) == Some(0.0) && ctx.facts.num(c2) == Some(0.0) {
                format!("fix {id} {group} wall/gran {coeffs} zcylinder {r}")
            } else {
                let rid = format!("demx_{id}");
                return Some(Action::Replace(vec![
                    format!("region {rid} cylinder z {c1} {c2} {r} INF INF units box"),
                    format!("fix {id} {group} wall/gran/region {coeffs} region {rid}"),
                ]));
            }
        }
        "xcylinder" | "ycylinder" if tail.len() >= 6 => {
            let rid = format!("demx_{id}");
            return Some(Action::Replace(vec![
                format!("region {rid} cylinder {} {} {} {} INF INF units box", &geom[..1], tail[4], tail[5], tail[3]),
                format!("fix {id} {group} wall/gran/region {coeffs} region {rid}"),
            ]));
        }
        _ => return Some(Action::Drop(format!("primitive wall {geom} has no LAMMPS wall/gran form"), Severity::Dropped)),
    };
    Some(Action::Replace(vec![line]))
}

/// 3.x insertion (`insert/pack`, `insert/rate/region`) -> LAMMPS `fix pour`.
pub fn insert_to_pour(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let style = w.get(3)?.as_str();
    if style != "insert/pack" && style != "insert/rate/region" {
        return None;
    }
    let (id, group) = (&w[1], &w[2]);
    let f = ctx.facts;
    let get = |k: &str| w.iter().position(|x| x == k).and_then(|i| w.get(i + 1)).cloned();
    let (Some(pdd), Some(region)) = (get("distributiontemplate"), get("region")) else {
        return Some(Action::Drop("insertion without distributiontemplate/region".into(), Severity::Dropped));
    };
    let Some(dist) = f.distributions.get(&pdd) else {
        return Some(Action::Drop(format!("distribution {pdd} not found"), Severity::Dropped));
    };
    // templates: diameters, number fractions from mass weights
    let mut sizes = Vec::new();
    let mut dens = Vec::new();
    let mut ty = None;
    for (tid, wt) in dist {
        let Some(t) = f.templates.get(tid) else {
            return Some(Action::Drop(format!("template {tid} not found"), Severity::Dropped));
        };
        let (Some(r), Some(rho), Some(wt)) = (f.num(&t.radius), f.num(&t.density), f.num(wt)) else {
            return Some(Action::Drop("template values are not constant numbers".into(), Severity::Dropped));
        };
        sizes.push((2.0 * r, wt / (r * r * r)));
        dens.push(rho);
        if ty.is_some() && ty.as_ref() != Some(&t.atom_type) {
            ctx.note(Severity::Approx, "templates of several atom types: fix pour inserts one type (the first)".into());
        }
        ty.get_or_insert(t.atom_type.clone());
    }
    let qsum: f64 = sizes.iter().map(|s| s.1).sum();
    let vp: f64 = sizes.iter().map(|(d, q)| q / qsum * std::f64::consts::PI / 6.0 * d * d * d).sum();
    let mp: f64 = sizes.iter().zip(&dens).map(|((d, q), rho)| q / qsum * rho * std::f64::consts::PI / 6.0 * d * d * d).sum();
    let diam = if sizes.len() == 1 {
        format!("diam one {}", fmt(sizes[0].0))
    } else {
        let parts: Vec<String> = sizes.iter().map(|(d, q)| format!("{} {}", fmt(*d), fmt(q / qsum))).collect();
        format!("diam poly {} {}", sizes.len(), parts.join(" "))
    };
    let (dlo, dhi) = dens.iter().fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(*x), b.max(*x)));
    if dlo != dhi {
        ctx.note(Severity::Approx, "templates of different densities: fix pour draws density uniformly in their range".into());
    }
    let vel = match w.iter().position(|x| x == "vel") {
        Some(i) if w.get(i + 1).map(|s| s.as_str()) == Some("constant") => {
            w.get(i + 2..i + 5).map(|v| format!("vel {} {} {} {} {}", v[0], v[0], v[1], v[1], v[2]))
        }
        _ => None,
    }
    .unwrap_or_default();
    let seed = get("seed").unwrap_or_else(|| "12345".into());
    let ty = ty.unwrap_or_else(|| "1".into());
    let first_insert = ctx.inserts_seen == 0;
    ctx.inserts_seen += 1;

    // What the fix inserts at each insertion: insert/pack tops the region up
    // to its target (LIGGGHTS `calc_ninsert_this`: target minus what is in
    // the region already); insert/rate/region inserts a fixed total.
    let target = if style == "insert/pack" {
        if let Some(fr) = get("volumefraction_region") {
            Some(PackCount::Fraction(fr))
        } else if let Some(n) = get("particles_in_region") {
            Some(PackCount::Particles(n))
        } else {
            get("mass_in_region").map(PackCount::Mass)
        }
    } else {
        None
    };
    let every = get("insert_every");
    let once = every.as_deref() == Some("once") || (style == "insert/pack" && every.is_none());
    let vol_now = f.region_volume(&region);
    // particles per insertion as a LAMMPS formula (region volume written from
    // the region's own words, so that regions built from variables work)
    let per_insert = |t: &PackCount| -> Option<String> {
        let vexpr = region_volume_expr(f, &region)?;
        Some(match t {
            PackCount::Fraction(fr) => format!("floor({fr}*{vexpr}/{})", fmt(vp)),
            PackCount::Particles(n) => n.clone(),
            PackCount::Mass(m) => format!("floor({m}/{})", fmt(mp)),
        })
    };
    let pair_before = ctx.all.get(..ctx.pos).unwrap_or(&[]).iter().any(|l| l.first().map(|s| s.as_str()) == Some("pair_style"));
    if let (Some(t), true, 1, true) = (&target, once, sizes.len(), pair_before) {
        if let Some(n) = per_insert(t) {
            return Some(pack_once_rsa(ctx, id, &region, &n, &ty, &seed, sizes[0].0, dlo, w));
        }
    }
    // particles per insertion as a number, when everything is a constant
    let per_insert_now = |t: &PackCount| -> Option<f64> {
        match t {
            PackCount::Fraction(fr) => f.num(fr).zip(vol_now).map(|(fr, v)| (fr * v / vp).floor()),
            PackCount::Particles(n) => f.num(n),
            PackCount::Mass(m) => f.num(m).map(|m| (m / mp).floor()),
        }
    };
    let referenced_later = ctx.all.get(ctx.pos + 1..).unwrap_or(&[]).iter().any(|l| l.iter().any(|x| x.contains(&format!("f_{id}"))));
    let constant_region = f.regions.get(&region).is_some_and(|r| r.args.iter().all(|a| !a.contains('$'))) && !id.contains('$');
    let mut lines = Vec::new();
    let (count, frac) = match (&target, once) {
        (Some(t), true) if !(first_insert && constant_region) => {
            // a top-up insertion in a loop or after other insertions: the count
            // depends on what is in the region when the fix is defined
            let Some(n) = per_insert(t) else {
                return Some(Action::Drop(format!("region {region} is not a block or cylinder: its volume is unknown"), Severity::Dropped));
            };
            let nvar = format!("demx_{id}_nins");
            lines.push(format!("variable {nvar} equal ({n})-count(all,{region})"));
            let fr = match t {
                PackCount::Fraction(fr) => fr.clone(),
                _ => "0.3".into(),
            };
            // fix pour needs at least one particle to insert; a fixed name, as
            // LAMMPS does not substitute ${..} inside $(..)
            lines.push(format!("variable demx_npour equal 1+(v_{nvar}>1)*(v_{nvar}-1)"));
            ("${demx_npour}".to_string(), fr)
        }
        (Some(t), true) => {
            let n = per_insert_now(t);
            let Some(n) = n else {
                return Some(Action::Drop("number of particles to insert not known as a constant".into(), Severity::Dropped));
            };
            (fmt(n), one_batch_fraction(t, n, vp, vol_now))
        }
        (Some(t), false)
            if sizes.len() == 1
                && pair_before
                && !referenced_later
                && every.as_deref().and_then(|e| f.num(e)).is_some_and(|e| e >= 1.0)
                && insertions_until_unfix(ctx, id, 1).is_some()
                && per_insert(t).is_some() =>
        {
            let e = every.as_deref().and_then(|e| f.num(e)).unwrap_or(1.0) as u64;
            let n = per_insert(t).unwrap_or_default();
            if let Some(a) = pack_every_rsa(ctx, id, &region, &n, &ty, &seed, sizes[0].0, dlo, w, e) {
                return Some(a);
            }
            return Some(Action::Drop("insert/pack every E: runs not constant".into(), Severity::Dropped));
        }
        (Some(t), false) => {
            // refills every E steps while the fix lives: N per insertion x the
            // insertions in the runs that follow until `unfix`
            let n = per_insert_now(t);
            let Some(n) = n else {
                return Some(Action::Drop("number of particles per insertion not known as a constant".into(), Severity::Dropped));
            };
            let e = every.as_deref().and_then(|e| f.num(e)).filter(|e| *e >= 1.0);
            let events = e.and_then(|e| insertions_until_unfix(ctx, id, e as u64));
            let frac = match vol_now {
                Some(v) if v > 0.0 => fmt(n * vp / v),
                _ => "0.25".into(),
            };
            match events {
                Some(k) => {
                    ctx.note(Severity::Approx, format!("{style} refills region {region} to {n} particles every {} steps, {k} times before it is removed: fix pour of {} particles in batches of {n}; pour's own interval is the fall time through the region", every.as_deref().unwrap_or("?"), n * k as f64));
                    (fmt(n * k as f64), frac)
                }
                None => {
                    ctx.note(Severity::Approx, format!("{style} refills the region every {} steps, but the runs it stays active for are not constant: fix pour of one batch ({n} particles)", every.as_deref().unwrap_or("?")));
                    (fmt(n), frac)
                }
            }
        }
        (None, _) => {
            let n = get("nparticles").and_then(|n| f.num(&n)).or_else(|| get("mass").and_then(|m| f.num(&m)).map(|m| (m / mp).floor()));
            let Some(n) = n else {
                return Some(Action::Drop("number of particles to insert not known as a constant".into(), Severity::Dropped));
            };
            (fmt(n), "0.25".into())
        }
    };
    // the count of inserted particles, for later `f_ID[1]` references
    let referenced = ctx.all.get(ctx.pos + 1..).unwrap_or(&[]).iter().any(|l| l.iter().any(|x| x.contains(&format!("f_{id}"))));
    if referenced && ctx.insert_counts.values().all(|v| v != &format!("demx_{id}_n")) {
        let n0 = format!("demx_{id}_n0");
        lines.push(format!("variable {n0} equal $(count(all))"));
        lines.push(format!("variable demx_{id}_n equal count(all)-v_{n0}"));
        ctx.insert_counts.insert(id.clone(), format!("demx_{id}_n"));
    }
    let (vx, vy, vz) = match w.iter().position(|x| x == "vel") {
        Some(i) if w.get(i + 1).map(|s| s.as_str()) == Some("constant") && w.len() >= i + 5 => (w[i + 2].clone(), w[i + 3].clone(), w[i + 4].clone()),
        _ => ("0".into(), "0".into(), "0".into()),
    };
    if once {
        // fix pour starts each particle with the speed of a fall from the top
        // of its region; LIGGGHTS gives the `vel` of the deck: set it after
        // the insertion step (the particles the next run's first step adds)
        lines.push("group demx_old empty".into());
        lines.push("group demx_old clear".into());
        lines.push("group demx_old union all".into());
        ctx.after_run = vec![
            "group demx_new empty".into(),
            "group demx_new clear".into(),
            "group demx_new subtract all demx_old".into(),
            format!("velocity demx_new set {vx} {vy} {vz} units box"),
        ];
        ctx.note(Severity::Approx, format!("{style} mapped to fix pour: positions differ; the new particles get the deck's velocity after the first step of the next run (pour gives them the speed of a fall from the top of region {region}); pour needs gravity and a block or z-cylinder region"));
    } else {
        ctx.note(Severity::Approx, format!("{style} mapped to fix pour: positions differ, and pour starts each particle with the speed of a fall from the top of region {region} (LIGGGHTS: the given velocity); pour needs gravity and a block or z-cylinder region"));
    }
    lines.push(
        format!("fix {id} {group} pour {count} {ty} {seed} region {region} {diam} dens {} {} vol {frac} 100 {vel}", fmt(dlo), fmt(dhi))
            .trim_end()
            .to_string(),
    );
    Some(Action::Replace(lines))
}

/// One random sequential packing pass, as LAMMPS commands: fill `region` up
/// to `per_insert` particles (a formula; what is there already counts) with
/// `create_atoms random` in `target` and `delete_atoms overlap` of the
/// candidates that touch anything, looped (labels `label`, `label`_end)
/// until the count is reached; then the new particles get the velocity.
#[derive(Clone, Debug)]
pub struct RsaBlock {
    group: String,
    region: String,
    target: String,
    per_insert: String,
    ty: String,
    seed: String,
    diam: f64,
    dens: f64,
    vel: (String, String, String),
}

impl RsaBlock {
    fn lines(&self, label: &str) -> Vec<String> {
        let RsaBlock { group, region, target, per_insert, ty, seed, diam, dens, vel } = self;
        let end = format!("{label}_end");
        let mut v: Vec<String> = vec![
            "group demx_old empty".to_string(),
            "group demx_old clear".into(),
            "group demx_old union all".into(),
            format!("variable demx_nins equal ({per_insert})-count(all,{region})"),
            "variable demx_T equal $(count(all)+v_demx_nins)".into(),
            "variable demx_step0 equal $(step)".into(),
            "variable demx_r loop 1000".into(),
            format!("label {label}"),
            "variable demx_left equal v_demx_T-count(all)".into(),
            format!("if \"${{demx_left}} <= 0\" then \"jump SELF {end}\""),
            "group demx_pre empty".into(),
            "group demx_pre clear".into(),
            "group demx_pre union all".into(),
            format!("variable demx_seed equal {seed}+v_demx_r"),
            format!("create_atoms {ty} random ${{demx_left}} ${{demx_seed}} {target}"),
            "group demx_cand empty".into(),
            "group demx_cand clear".into(),
            "group demx_cand subtract all demx_pre".into(),
            format!("set group demx_cand diameter {}", fmt(*diam)),
            format!("set group demx_cand density {}", fmt(*dens)),
            // LAMMPS 29Sep2021 reuses delete_atoms' neighbour list within one
            // time step (observed: the second pass misses overlaps): step on
            "reset_timestep $(step+1)".into(),
            format!("delete_atoms overlap {} demx_cand all compress yes", fmt(*diam)),
            "next demx_r".into(),
            format!("jump SELF {label}"),
            format!("label {end}"),
            "variable demx_r delete".into(),
            "reset_timestep ${demx_step0}".into(),
            "group demx_new empty".into(),
            "group demx_new clear".into(),
            "group demx_new subtract all demx_old".into(),
            format!("velocity demx_new set {} {} {} units box", vel.0, vel.1, vel.2),
        ];
        // the insert fix's group, as LIGGGHTS gives it to what it inserts
        if group != "all" {
            v.push(format!("group {group} union {group} demx_new"));
        }
        v
    }
}

/// A repeated insertion (insert/pack every E steps) turned into packing
/// passes between split runs.
#[derive(Clone, Debug)]
pub struct InsertSchedule {
    /// The insert fix ID (its `unfix` ends the schedule).
    pub id: String,
    /// Steps between insertions.
    pub every: u64,
    /// Absolute step of the next insertion.
    pub next: u64,
    block: RsaBlock,
    label: String,
    passes: usize,
}

impl InsertSchedule {
    /// The packing pass that inserts at step `self.next`.
    pub fn pass(&mut self) -> Vec<String> {
        self.passes += 1;
        self.next += self.every;
        self.block.lines(&format!("{}_{}", self.label, self.passes))
    }
}

/// The packing block of an insert fix, and the lines that define the region
/// its centres go in (shrunk by the radius for `all_in yes`, box units).
fn rsa_setup(
    ctx: &Ctx,
    k: usize,
    region: &str,
    per_insert: &str,
    ty: &str,
    seed: &str,
    diam: f64,
    dens: f64,
    w: &[String],
) -> (Vec<String>, RsaBlock) {
    let f = ctx.facts;
    let get = |key: &str| w.iter().position(|x| x == key).and_then(|i| w.get(i + 1)).cloned();
    let vel = match w.iter().position(|x| x == "vel") {
        Some(i) if w.get(i + 1).map(|s| s.as_str()) == Some("constant") && w.len() >= i + 5 => (w[i + 2].clone(), w[i + 3].clone(), w[i + 4].clone()),
        _ => ("0".into(), "0".into(), "0".into()),
    };
    let r = diam / 2.0;
    let mut lines = Vec::new();
    let mut target = region.to_string();
    if get("all_in").as_deref() == Some("yes") {
        if let Some(rd) = f.regions.get(region).filter(|rd| rd.args.windows(2).any(|p| p[0] == "units" && p[1] == "box")) {
            let sh = fmt(r);
            let b: Option<Vec<String>> = match rd.style.as_str() {
                "block" if rd.args.len() >= 6 => {
                    Some((0..6).map(|i| format!("({}){}{sh}", rd.args[i], if i % 2 == 0 { "+" } else { "-" })).collect())
                }
                "cylinder" if rd.args.len() >= 6 => Some(vec![
                    rd.args[0].clone(),
                    format!("({})", rd.args[1]),
                    format!("({})", rd.args[2]),
                    format!("({})-{sh}", rd.args[3]),
                    format!("({})+{sh}", rd.args[4]),
                    format!("({})-{sh}", rd.args[5]),
                ]),
                _ => None,
            };
            if let Some(b) = b.filter(|b| b.iter().all(|x| !x.contains("INF") && !x.contains("EDGE"))) {
                let first = usize::from(rd.style == "cylinder");
                let mut words = Vec::new();
                for (i, x) in b.iter().enumerate() {
                    if i < first {
                        words.push(x.clone());
                    } else {
                        lines.push(format!("variable demx_b{i} equal {x}"));
                        words.push(format!("${{demx_b{i}}}"));
                    }
                }
                // named after the region, so that a region re-made in a loop (`col${k}`) gets a fresh one
                target = format!("demx_in{k}_{region}");
                lines.push(format!("region {target} {} {} units box", rd.style, words.join(" ")));
            }
        }
    }
    let group = w.get(2).cloned().unwrap_or_else(|| "all".into());
    let block = RsaBlock { group, region: region.into(), target, per_insert: per_insert.into(), ty: ty.into(), seed: seed.into(), diam, dens, vel };
    (lines, block)
}

/// `insert/pack ... insert_every once` of one sphere size -> one packing
/// pass (LAMMPS 29Sep2021 `create_atoms` has no overlap check, and fix pour
/// cannot fill a region densely: it stacks its particles toward the top).
/// The particles exist at once (LIGGGHTS: on the next step).
fn pack_once_rsa(ctx: &mut Ctx, id: &str, region: &str, per_insert: &str, ty: &str, seed: &str, diam: f64, dens: f64, w: &[String]) -> Action {
    let k = ctx.inserts_seen;
    let (mut lines, block) = rsa_setup(ctx, k, region, per_insert, ty, seed, diam, dens, w);
    lines.insert(0, format!("# demx: {id} = insert/pack once -> random sequential packing (create_atoms random + delete_atoms overlap)"));
    lines.extend(block.lines(&format!("demx_rsa{k}")));
    let referenced = ctx.all.get(ctx.pos + 1..).unwrap_or(&[]).iter().any(|l| l.iter().any(|x| x.contains(&format!("f_{id}"))));
    if referenced {
        lines.push(format!("variable demx_{id}_n equal $(count(demx_new))"));
        ctx.insert_counts.insert(id.to_string(), format!("demx_{id}_n"));
    }
    ctx.dropped_fixes.insert(id.to_string());
    ctx.note(
        Severity::Approx,
        "insert/pack once -> create_atoms random + delete_atoms overlap until the count is reached: positions differ, particles exist at once (LIGGGHTS: on the next step), ids are compressed after each pass (delete_atoms), the loop uses `jump SELF` (run the deck with -in FILE)".into(),
    );
    Action::Replace(lines)
}

/// `insert/pack ... insert_every E` of one sphere size, in a deck whose runs
/// are constants: a packing pass now (LIGGGHTS inserts on the next step),
/// and one at every E-th step after, by splitting the runs that follow until
/// `unfix` (see `split_run`).
fn pack_every_rsa(
    ctx: &mut Ctx,
    id: &str,
    region: &str,
    per_insert: &str,
    ty: &str,
    seed: &str,
    diam: f64,
    dens: f64,
    w: &[String],
    every: u64,
) -> Option<Action> {
    let now = steps_before(ctx, ctx.pos)?;
    let k = ctx.inserts_seen;
    let (mut lines, block) = rsa_setup(ctx, k, region, per_insert, ty, seed, diam, dens, w);
    lines.insert(0, format!("# demx: {id} = insert/pack every {every} steps -> a random sequential packing pass now and before every {every}th step of the runs below"));
    let mut sched = InsertSchedule { id: id.to_string(), every, next: now + 1, block, label: format!("demx_rsa{k}"), passes: 0 };
    lines.extend(sched.pass());
    ctx.insert_schedules.push(sched);
    ctx.dropped_fixes.insert(id.to_string());
    ctx.note(
        Severity::Approx,
        format!("insert/pack every {every} steps -> create_atoms random + delete_atoms overlap passes, the runs split at the insertion steps: positions differ, each pass happens after the step before LIGGGHTS' insertion step, thermo prints at the splits"),
    );
    Some(Action::Replace(lines))
}

/// The absolute step at logical line `pos` (the sum of the constant runs
/// before it); None if a run is not constant or the deck loops before it.
pub fn steps_before(ctx: &Ctx, pos: usize) -> Option<u64> {
    let f = ctx.facts;
    let mut step = 0u64;
    for w in ctx.all.get(..pos)? {
        match w.first().map(|s| s.as_str()) {
            Some("run") => step = run_end(f, w, step)?,
            Some("jump" | "label" | "next" | "include") => return None,
            _ => {}
        }
    }
    Some(step)
}

/// The step a `run N [upto]` ends at, from `step`; None unless N is a constant
/// and the run has no other keywords.
fn run_end(f: &Facts, w: &[String], step: u64) -> Option<u64> {
    let n = f.num(w.get(1)?)?;
    if n < 0.0 || w.iter().skip(2).any(|x| x != "upto") {
        return None;
    }
    Some(if w.iter().any(|x| x == "upto") { (n as u64).max(step) } else { step + n as u64 })
}

/// A `run` while repeated insertions are scheduled: split at their steps,
/// a packing pass at each (None: nothing to split, or the run is not constant).
pub fn split_run(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if ctx.insert_schedules.is_empty() {
        return None;
    }
    let start = steps_before(ctx, ctx.pos)?;
    let end = run_end(ctx.facts, w, start)?;
    let mut out = Vec::new();
    let mut cur = start;
    // the earliest pending insertion inside (cur, end]
    while let Some(k) = (0..ctx.insert_schedules.len()).filter(|&k| ctx.insert_schedules[k].next <= end).min_by_key(|&k| ctx.insert_schedules[k].next)
    {
        let at = ctx.insert_schedules[k].next;
        // LIGGGHTS inserts at the start of step `at`: after step at - 1
        if at > cur + 1 {
            out.push(format!("run {}", at - 1 - cur));
            cur = at - 1;
        }
        out.extend(ctx.insert_schedules[k].pass());
    }
    if end > cur || out.is_empty() {
        out.push(format!("run {}", end - cur));
    }
    Some(Action::Replace(out))
}

/// What an insert/pack fix fills its region to.
enum PackCount {
    Fraction(String),
    Particles(String),
    Mass(String),
}

/// fix pour's volume fraction so that one batch holds all `n` particles.
fn one_batch_fraction(t: &PackCount, n: f64, vp: f64, vol: Option<f64>) -> String {
    match (t, vol) {
        (PackCount::Fraction(fr), _) => fr.clone(),
        (_, Some(v)) if v > 0.0 => fmt((n * vp / v * 1.001).max(0.25)),
        _ => "0.25".into(),
    }
}

/// The region's volume as a LAMMPS formula over its own words (`${x}`
/// substituted by LAMMPS when the line is read). Block or cylinder.
fn region_volume_expr(f: &Facts, id: &str) -> Option<String> {
    let r = f.regions.get(id)?;
    let a = |i: usize| -> Option<String> {
        let w = r.args.get(i)?;
        (!matches!(w.as_str(), "INF" | "-INF" | "EDGE")).then(|| format!("({w})"))
    };
    match r.style.as_str() {
        "block" => Some(format!("({}-{})*({}-{})*({}-{})", a(1)?, a(0)?, a(3)?, a(2)?, a(5)?, a(4)?)),
        "cylinder" => Some(format!("PI*{}^2*abs({}-{})", a(3)?, a(5)?, a(4)?)),
        _ => None,
    }
}

/// How many insertions a fix inserting every `every` steps makes in the runs
/// after the current line until `unfix ID` (or the end of the deck): the
/// first on the step after it is defined, then every `every` steps. None if
/// a run length is not a constant or the deck loops.
fn insertions_until_unfix(ctx: &Ctx, id: &str, every: u64) -> Option<u64> {
    let start = steps_before(ctx, ctx.pos)?;
    let mut step = start;
    for w in ctx.all.get(ctx.pos + 1..)? {
        match w.first().map(|s| s.as_str()) {
            Some("run") => step = run_end(ctx.facts, w, step)?,
            Some("unfix") if w.get(1).map(|s| s.as_str()) == Some(id) => break,
            Some("jump" | "label" | "next" | "include") => return None,
            _ => {}
        }
    }
    let steps = step - start;
    (steps >= 1).then(|| (steps - 1) / every + 1)
}

/// Material values to LIGGGHTS property/global lines from LAMMPS pair
/// coefficients of the classic styles.
pub fn classic_to_liggghts(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    let style = w.get(1)?.as_str();
    let (normal, tang) = match style {
        "gran/hooke/history" => ("hooke/stiffness", "history"),
        "gran/hooke" => ("hooke/stiffness", "no_history"),
        "gran/hertz/history" => ("hertz/stiffness", "history"),
        _ => return None,
    };
    let a = w.get(2..8)?;
    if !is_number(&a[0]) {
        return None;
    }
    let f = ctx.facts;
    let kn = f.num(&a[0])?;
    let kt = if a[1] == "NULL" { 2.0 / 7.0 * kn } else { f.num(&a[1])? };
    let gn = f.num(&a[2])?;
    let mut gt = if a[3] == "NULL" { 0.5 * gn } else { f.num(&a[3])? };
    let mu = f.num(&a[4])?;
    if f.num(&a[5]) == Some(0.0) {
        gt = 0.0;
    }
    if w.len() > 8 {
        ctx.note(Severity::Approx, format!("pair_style words '{}' dropped", w[8..].join(" ")));
    }
    ctx.note(Severity::Approx, "LIGGGHTS */stiffness: Coulomb cap on the elastic part only, no damping while sliding, lever arm R-delta/2 (LAMMPS: total force cap, lever arm R)".into());
    let n = ntypes(ctx);
    let pp = |name: &str, v: f64| format!("fix demx_{name} all property/global {name} peratomtypepair {n} {}", vec![fmt(v); n * n].join(" "));
    let mut lines = Vec::new();
    if !ctx.facts.has_newton_off {
        lines.push("newton off".to_string());
    }
    lines.push(pp("kn", kn));
    lines.push(pp("kt", kt));
    lines.push(pp("gamman", gn));
    lines.push(pp("gammat", gt));
    lines.push(pp("coefficientFriction", mu));
    lines.push(format!("pair_style gran model {normal} tangential {tang}"));
    ctx.pair_done = true;
    ctx.liggghts_walls = Some((normal.to_string(), tang.to_string()));
    Some(Action::Replace(lines))
}

/// LAMMPS `pair_style granular` -> `pair_style gran model hertz` (values come
/// from the `pair_coeff` lines, turned into property/global there).
pub fn granular_to_liggghts(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if w.get(1).map(|s| s.as_str()) != Some("granular") {
        return None;
    }
    ctx.granular = true;
    Some(Action::Drop("pair_style granular: becomes pair_style gran with the pair_coeff values below".into(), Severity::Info))
}

/// Parsed `hertz/material E e nu tangential mindlin kt xgt mu damping tsuji`.
struct HertzCoeff {
    e_mod: f64,
    e_rest: f64,
    nu: f64,
    tangential: String,
    xgt: f64,
    mu: f64,
    damping: String,
}

fn parse_hertz(f: &Facts, a: &[String]) -> Option<HertzCoeff> {
    if a.first()? != "hertz/material" {
        return None;
    }
    let mut c = HertzCoeff {
        e_mod: f.num(a.get(1)?)?,
        e_rest: f.num(a.get(2)?)?,
        nu: f.num(a.get(3)?)?,
        tangential: String::new(),
        xgt: 0.0,
        mu: 0.0,
        damping: "viscoelastic".into(),
    };
    let mut i = 4;
    while i < a.len() {
        match a[i].as_str() {
            "tangential" => {
                c.tangential = a.get(i + 1)?.clone();
                if c.tangential == "linear_nohistory" {
                    c.xgt = f.num(a.get(i + 2)?)?;
                    c.mu = f.num(a.get(i + 3)?)?;
                    i += 4;
                } else {
                    c.xgt = f.num(a.get(i + 3)?)?;
                    c.mu = f.num(a.get(i + 4)?)?;
                    i += 5;
                }
            }
            "damping" => {
                c.damping = a.get(i + 1)?.clone();
                i += 2;
            }
            _ => return None,
        }
    }
    Some(c)
}

/// `pair_coeff I J hertz/material ...` lines of `pair_style granular`:
/// the type-diagonal ones become LIGGGHTS materials (all lines are read
/// from the deck facts at the first pair_coeff).
pub fn granular_coeff_to_liggghts(ctx: &mut Ctx, w: &[String], all: &[Vec<String>]) -> Option<Action> {
    if !ctx.granular {
        return None;
    }
    if ctx.pair_done {
        return Some(Action::Drop("folded into the property/global lines above".into(), Severity::Info));
    }
    let f = ctx.facts;
    let n = ntypes(ctx);
    // collect coefficients per type pair
    let mut per: Vec<Option<HertzCoeff>> = (0..n * n).map(|_| None).collect();
    for c in all {
        let (Some(i), Some(j)) = (c.get(1), c.get(2)) else { continue };
        let range = |s: &str| -> Vec<usize> {
            if s == "*" {
                (1..=n).collect()
            } else {
                s.parse::<usize>().ok().filter(|x| *x >= 1 && *x <= n).into_iter().collect()
            }
        };
        let Some(h) = parse_hertz(f, &c[3..]) else {
            return Some(Action::Drop("pair_coeff of pair_style granular: only hertz/material converts to LIGGGHTS".into(), Severity::Dropped));
        };
        for a in range(i) {
            for b in range(j) {
                per[(a - 1) * n + (b - 1)] = parse_hertz(f, &c[3..]);
                per[(b - 1) * n + (a - 1)] = parse_hertz(f, &c[3..]);
            }
        }
        let _ = h;
    }
    let mut ym = Vec::new();
    let mut nu = Vec::new();
    let mut rest = Vec::new();
    let mut fric = Vec::new();
    let mut tdamp = None;
    let mut tang = "history";
    for i in 0..n {
        let Some(c) = per[i * n + i].as_ref() else {
            return Some(Action::Drop(format!("no pair_coeff for type {}", i + 1), Severity::Dropped));
        };
        ym.push(fmt(c.e_mod));
        nu.push(fmt(c.nu));
    }
    for c in per.iter() {
        let Some(c) = c else {
            return Some(Action::Drop("pair_coeff does not cover every type pair".into(), Severity::Dropped));
        };
        let e = match c.damping.as_str() {
            "tsuji" => liggghts_e_for_tsuji(c.e_rest),
            d => {
                ctx.note(Severity::Approx, format!("damping {d}: no LIGGGHTS counterpart, restitution {} taken as a constant coefficient", c.e_rest));
                c.e_rest
            }
        };
        rest.push(fmt(e));
        fric.push(fmt(c.mu));
        if c.tangential == "linear_nohistory" {
            tang = "no_history";
        }
        tdamp.get_or_insert(c.xgt != 0.0);
    }
    ctx.note(Severity::Approx, "hertz/material + tsuji -> LIGGGHTS hertz: restitution from alpha(e') = sqrt(5)|beta(e)| (same normal force); tangential cap, history and lever arm conventions differ".into());
    let mut lines = Vec::new();
    if !f.has_newton_off {
        lines.push("newton off".to_string());
    }
    lines.push(format!("fix demx_m1 all property/global youngsModulus peratomtype {}", ym.join(" ")));
    lines.push(format!("fix demx_m2 all property/global poissonsRatio peratomtype {}", nu.join(" ")));
    lines.push(format!("fix demx_m3 all property/global coefficientRestitution peratomtypepair {n} {}", rest.join(" ")));
    lines.push(format!("fix demx_m4 all property/global coefficientFriction peratomtypepair {n} {}", fric.join(" ")));
    let td = if tdamp == Some(false) { " tangential_damping off" } else { "" };
    lines.push(format!("pair_style gran model hertz tangential {tang}{td}"));
    lines.push("pair_coeff * *".into());
    ctx.pair_done = true;
    ctx.liggghts_walls = Some(("hertz".into(), tang.into()));
    let _ = w;
    Some(Action::Replace(lines))
}

/// LAMMPS `fix ID G wall/gran STYLE ... {x,y,z}plane lo hi | zcylinder r` -> LIGGGHTS primitive walls.
pub fn wall_to_liggghts(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if w.get(3).map(|s| s.as_str()) != Some("wall/gran") || w.get(4).map(|s| s.as_str()) == Some("model") {
        return None;
    }
    let (id, group) = (&w[1], &w[2]);
    let gpos = w.iter().position(|x| matches!(x.as_str(), "xplane" | "yplane" | "zplane" | "zcylinder"));
    let Some(gpos) = gpos else {
        return Some(Action::Drop("wall/gran geometry not understood".into(), Severity::Dropped));
    };
    let Some((normal, tang)) = ctx.liggghts_walls.clone() else {
        return Some(Action::Drop("wall/gran before a convertible pair style".into(), Severity::Dropped));
    };
    ctx.note(
        Severity::Info,
        format!("wall {id} uses the pair materials of type 1 (LIGGGHTS primitive type 1); wall values written in the LAMMPS line are not re-read"),
    );
    let block = format!("model {normal} tangential {tang}");
    let geom = w[gpos].as_str();
    let extra = w.get(gpos + if geom == "zcylinder" { 2 } else { 3 }..).unwrap_or(&[]);
    if !extra.is_empty() {
        ctx.note(Severity::Approx, format!("wall words '{}' dropped", extra.join(" ")));
    }
    if geom == "zcylinder" {
        return Some(Action::Replace(vec![format!("fix {id} {group} wall/gran {block} primitive type 1 zcylinder {} 0. 0.", w.get(gpos + 1)?)]));
    }
    let planes: Vec<&String> = w.get(gpos + 1..gpos + 3)?.iter().filter(|v| v.as_str() != "NULL").collect();
    let ids: Vec<String> = if planes.len() == 1 { vec![id.clone()] } else { vec![format!("{id}1"), format!("{id}2")] };
    if ids.len() > 1 {
        ctx.split_ids.insert(id.clone(), ids.clone());
    }
    Some(Action::Replace(planes.iter().zip(&ids).map(|(p, i)| format!("fix {i} {group} wall/gran {block} primitive type 1 {geom} {p}")).collect()))
}

/// LAMMPS `fix pour` -> LIGGGHTS templates + insert/rate/region.
pub fn pour_to_liggghts(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if !matches!(w.get(3)?.as_str(), "pour" | "pour/legacy") {
        return None;
    }
    legacy::pour_to_insert(ctx, w)
}

/// Old `fix pour` syntax (`diam [uniform] lo hi`, `dens uniform`, `vel
/// uniform`; LIGGGHTS 1.x and LAMMPS before 2013) -> LAMMPS 2021 syntax.
pub fn pour_to_lammps(ctx: &mut Ctx, w: &[String]) -> Option<Action> {
    if !matches!(w.get(3)?.as_str(), "pour" | "pour/legacy") {
        return None;
    }
    let Some(p) = legacy::parse_pour(w) else {
        return Some(Action::Drop("fix pour arguments not understood".into(), Severity::Dropped));
    };
    if ctx.facts.gravity.is_none() {
        return Some(Action::Drop("LAMMPS fix pour needs fix gravity".into(), Severity::Dropped));
    }
    let mut s = format!("fix {} {} pour {} {} {} region {}", w[1], w[2], p.n, p.ty, p.seed, p.region);
    if let Some((lo, hi)) = &p.diam_range {
        if lo == hi {
            s += &format!(" diam one {lo}");
        } else {
            s += &format!(" diam range {lo} {hi}");
        }
    } else if !p.poly.is_empty() {
        let parts: Vec<String> = p.poly.iter().map(|(d, q)| format!("{d} {q}")).collect();
        s += &format!(" diam poly {} {}", p.poly.len(), parts.join(" "));
    }
    if let Some((lo, hi)) = &p.dens {
        s += &format!(" dens {lo} {hi}");
    }
    if let Some((f, n)) = &p.vol {
        s += &format!(" vol {f} {n}");
    }
    if p.vel.len() == 5 {
        s += &format!(" vel {}", p.vel.join(" "));
    }
    if !p.other.is_empty() {
        ctx.note(Severity::Approx, format!("pour words '{}' dropped", p.other.join(" ")));
    }
    Some(Action::Replace(vec![s]))
}
