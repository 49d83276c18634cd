//! Particle insertion: LIGGGHTS 3.8 `particletemplate/sphere`,
//! `particledistribution/discrete` (+ `/numberbased`, `/massbased`),
//! `insert/pack`, `insert/rate/region`, `insert/stream` (through a planar
//! `fix mesh/surface` face), and LAMMPS `fix pour`.
//!
//! Counts and schedules follow the engines (facts checked against the
//! LIGGGHTS-PUBLIC 3.8 sources and the installed `liggghts`/`lmp`):
//! - LIGGGHTS seeds must be primes > 10000 and all seeds of one insertion
//!   (insert fix, distribution, templates) must differ; errors otherwise.
//! - `particledistribution/discrete` is mass based (weights are mass
//!   fractions, converted to number fractions by each template's expected
//!   mass); `/numberbased` takes number fractions. Templates are inserted
//!   largest expected volume first.
//! - insert/pack: count = int((f V - V_in) / V_expect + u) for
//!   `volumefraction_region` (V from LIGGGHTS' Monte Carlo `volume_mc`, which
//!   demx replays with the same Park-Miller stream, seed + 12, `ntry_mc`
//!   points), N - N_in for `particles_in_region`,
//!   int((M - M_in) / M_expect + u) for `mass_in_region`; u is the first draws of the fix's own
//!   Park-Miller stream (seed), as in LIGGGHTS, so counts match exactly. The
//!   per-template split ("exact" mode, the default) draws from the
//!   distribution's stream. The first insertion is the step after the fix is
//!   defined (or `start`), then every `insert_every` steps.
//! - insert/rate/region: count per insertion int(rate dt every + u), capped
//!   at the total (nparticles, or int(mass / M_expect)).
//! - insert/stream: the face normal is flipped to point along `vel`;
//!   insert_every = int((extrude_length + 1e-14) / (dt |v_n|)) unless given
//!   (then extrude_length = duration dt |v_n|); per insertion int(rate dt
//!   every + u). Before each insertion on a box with shrink-wrapped sides
//!   (and before the first one anyway) LIGGGHTS estimates its share of the
//!   extruded volume with `ntry_mc` points (mesh stream + fix stream), which
//!   demx replays. A candidate is a random face point (triangle by area
//!   from the mesh stream, seed 179424799, barycentric u, v redrawn while
//!   u + v > 1) moved upstream by u extrude + r (fix stream); it must be in
//!   the box at least r from its faces. Inserted particles move with v_n
//!   (forces zeroed) until they cross the face, then get `vel` and `omega`.
//! - fix pour: nper = int(volfrac V / V_one) (V_one from the largest
//!   diameter, or the fraction-weighted mean for poly; in 3d dy < 1 is taken
//!   as 1), insertions every nfreq = int(t / dt + 0.5) steps with t the fall
//!   time through the region, first at the step after the fix; positions
//!   follow LAMMPS' own draw order (height, diameter, x, y per attempt, vx,
//!   vy, density) with the same generator after LAMMPS' 30 warm-up draws,
//!   so the first insertion reproduces LAMMPS' positions exactly.
//!
//! New particles get ids max_tag()+1.. and the group bits of the insert fix
//! (and, LIGGGHTS, of the distribution and template fixes) plus `all`.

use super::args::{bad_keyword, parse_f64, parse_i64, Args};
use super::Session;
use crate::engine::domain::Domain;
use crate::engine::fix::Fix;
use crate::engine::insert::{in_box, is_prime, random_point, region_volume_mc, OverlapGrid};
use crate::engine::mesh_surface::SharedMesh;
use crate::engine::particles::{NewParticle, Particles};
use crate::engine::rng::Park;
use crate::engine::sim::{Dialect, Sim};
use crate::error::{Error, Result};
use crate::geom::region::Shape;
use crate::geom::Region;
use crate::physics::V3;
use crate::script::{Command, Span, Variables, Word};
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

/// LIGGGHTS region seed offset (`SEED_OFFSET` in fix_insert_pack.cpp).
const SEED_OFFSET: i64 = 12;

/// Parse an insertion-related fix.
pub fn fix(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args, vars: &mut Variables) -> Result<()> {
    match style.text.as_str() {
        "particletemplate/sphere" => {
            s.set_dialect(Dialect::Liggghts);
            let t = parse_template(s, id, group, style, a)?;
            s.add_fix(Box::new(t))
        }
        "particletemplate/multisphere" | "particletemplate/superquadric" | "particletemplate/multiplespheres" => {
            Err(Error::unsupported(style.span, format!("fix {} (only spheres are supported)", style.text)))
        }
        "particledistribution/discrete" | "particledistribution/discrete/numberbased" | "particledistribution/discrete/massbased" => {
            s.set_dialect(Dialect::Liggghts);
            let d = parse_distribution(s, id, group, style, a)?;
            s.add_fix(Box::new(d))
        }
        "insert/pack" | "insert/rate/region" | "insert/stream" => {
            s.set_dialect(Dialect::Liggghts);
            let f = parse_liggghts_insert(s, cmd, id, group, style, a)?;
            s.sources.push(f.describe());
            s.add_fix(Box::new(f))
        }
        "insert/stream/predefined" => Err(Error::unsupported(style.span, format!("fix {}", style.text))),
        "pour" => {
            s.set_dialect(Dialect::Lammps);
            let p = parse_pour(s, cmd, id, group, a, vars)?;
            s.sim.log.line(&format!("Particle insertion: {} every {} steps, {} by step {}", p.nper, p.nfreq, p.ninsert, p.nfinal()));
            s.sources.push(p.describe());
            s.add_fix(Box::new(p))
        }
        "adapt" => {
            let f = parse_adapt(s, id, group, a)?;
            s.add_fix(Box::new(f))
        }
        _ => Err(Error::unsupported(style.span, format!("fix {}", style.text))),
    }
}

// ---------------------------------------------------------------- adapt

/// `fix ID group adapt N atom diameter v_name [scale yes|no] [reset no]`:
/// particle growth (LIGGGHTS/LAMMPS `fix adapt`, the atom-diameter form).
/// The variable (equal- or atom-style) gives each particle's new diameter
/// (times its current diameter with `scale yes`); the mass follows at
/// constant density. Applied at the start of every run and every N steps.
/// The engines apply it in `pre_force` of steps that are multiples of N;
/// demx applies it at the end of the step before (same radii for that
/// step's forces; the half-step velocity update before the force pass uses
/// the new mass) and at run start after the setup forces.
pub struct Adapt {
    id: String,
    group: u32,
    nevery: i64,
    var: String,
    scale: bool,
}

fn parse_adapt(s: &Session, id: &str, group: u32, a: &mut Args) -> Result<Adapt> {
    let nevery = a.i64("N")?;
    if nevery < 0 {
        return Err(a.err_prev("Illegal fix adapt command"));
    }
    let mut var = None;
    let mut scale = false;
    let mut reset = s.sim.dialect == Dialect::Lammps;
    let mut reset_span = a.end_span();
    while a.more() {
        let k = a.word("attribute")?;
        match k.text.as_str() {
            "atom" => {
                let what = a.word("atom attribute")?;
                if what.text != "diameter" {
                    return Err(Error::unsupported(what.span, format!("fix adapt atom {} (only diameter)", what.text)));
                }
                let v = a.word("v_name")?;
                let Some(name) = v.text.strip_prefix("v_") else {
                    return Err(Error::deck(v.span, "Illegal fix adapt command").with_hint("expected v_name"));
                };
                if var.is_some() {
                    return Err(Error::unsupported(v.span, "fix adapt with several attributes"));
                }
                var = Some(name.to_string());
            }
            "pair" | "kspace" | "bond" => return Err(Error::unsupported(k.span, format!("fix adapt {}", k.text))),
            "scale" => scale = a.yes_no("scale")?,
            "reset" => {
                reset = a.yes_no("reset")?;
                reset_span = k.span;
            }
            "mass" => {
                if !a.yes_no("mass")? {
                    return Err(Error::unsupported(k.span, "fix adapt mass no"));
                }
            }
            _ => return Err(bad_keyword(k, "fix adapt keyword", &["atom", "scale", "reset", "mass"])),
        }
    }
    if reset {
        return Err(Error::unsupported(reset_span, "fix adapt reset yes (restoring diameters after the run); add 'reset no'"));
    }
    let var = var.ok_or_else(|| Error::deck(a.end_span(), "fix adapt: no attribute to adapt"))?;
    Ok(Adapt { id: id.to_string(), group, nevery, var, scale })
}

impl Adapt {
    fn change(&self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        let vals = vars.eval_atom(&self.var, &*sim).map_err(|e| Error::runtime(format!("fix adapt {}: {e}", self.id)))?;
        let p = &mut sim.particles;
        if vals.len() != p.len() {
            return Err(Error::runtime(format!("fix adapt {}: variable {} gave {} values for {} particles", self.id, self.var, vals.len(), p.len())));
        }
        for i in 0..p.len() {
            if p.mask[i] & self.group == 0 {
                continue;
            }
            let mut d = vals[i];
            if self.scale {
                d *= 2.0 * p.radius[i];
            }
            if !(d.is_finite() && d > 0.0) {
                return Err(Error::runtime(format!("fix adapt {}: particle {} would get diameter {d}", self.id, p.tag[i])));
            }
            let r0 = p.radius[i];
            let density = p.mass[i] / (4.0 * PI / 3.0 * r0 * r0 * r0);
            p.radius[i] = 0.5 * d;
            p.mass[i] = 4.0 * PI / 3.0 * p.radius[i].powi(3) * density;
        }
        sim.force_rebuild = true;
        Ok(())
    }
}

impl Fix for Adapt {
    crate::no_step_hooks!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "adapt"
    }
    fn setup_output(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        if sim.dry {
            return Ok(());
        }
        self.change(sim, vars)
    }
    fn end_of_step_due(&self, step: i64) -> bool {
        self.nevery > 0 && (step + 1) % self.nevery == 0
    }
    fn end_of_step(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        if self.end_of_step_due(sim.step) && sim.step < sim.run_end {
            self.change(sim, vars)?;
        }
        Ok(())
    }
    fn summary(&self) -> String {
        format!("fix adapt {}: diameter from v_{} every {} steps{}", self.id, self.var, self.nevery, if self.scale { " (scaled)" } else { "" })
    }
}

// ---------------------------------------------------------------- LIGGGHTS

/// LIGGGHTS `fix error` prefix: `Fix STYLE (id ID): `.
fn lig(style: &str, id: &str, msg: &str) -> String {
    format!("Fix {style} (id {id}): {msg}")
}

/// A LIGGGHTS seed: integer, <= INT_MAX, prime and > 10000.
fn liggghts_seed(w: &Word) -> Result<i64> {
    let v = parse_i64(w)?;
    if v > i32::MAX as i64 {
        return Err(Error::deck(w.span, format!("Seed {v} is larger than INT_MAX ({})", i32::MAX)));
    }
    if v < 10000 || !is_prime(v) {
        return Err(Error::deck_hint(
            w.span,
            format!("Random number generation: It is required that the random seed value is > 10000 and a prime number (the seed used was {v})"),
            "possible valid seeds: 15485863, 15485867, 32452843, 32452867, 49979687, 49979693, 67867967, 67867979, 86028121, 86028157",
        ));
    }
    Ok(v)
}

/// `fix ID group particletemplate/sphere seed atom_type T density constant
/// RHO radius constant R`.
#[derive(Clone, Debug)]
pub struct Template {
    /// Fix id.
    pub id: String,
    /// Group bit of the template fix (added to inserted particles).
    pub group: u32,
    /// Seed.
    pub seed: i64,
    /// Atom type.
    pub kind: u32,
    /// Radius (m).
    pub radius: f64,
    /// Density (kg/m^3).
    pub density: f64,
}

impl Template {
    /// Expected volume of one particle.
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius.powi(3)
    }
    /// Expected mass of one particle.
    pub fn mass(&self) -> f64 {
        self.volume() * self.density
    }
}

impl Fix for Template {
    crate::stateless_fix!();
    crate::no_step_hooks!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "particletemplate/sphere"
    }
    fn summary(&self) -> String {
        format!("particletemplate/sphere {}: type {}, radius {}, density {}", self.id, self.kind, self.radius, self.density)
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

fn parse_template(s: &Session, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<Template> {
    let st = style.text.as_str();
    if s.dimension != 3 {
        return Err(Error::deck(style.span, lig(st, id, "this fix is for 3D simulations only")));
    }
    let seed = liggghts_seed(a.word("seed")?)?;
    let mut t = Template { id: id.to_string(), group, seed, kind: 1, radius: 0.0, density: 0.0 };
    let (mut have_r, mut have_d) = (false, false);
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "atom_type" => {
                let w = a.word("atom type")?;
                let v = parse_i64(w)?;
                if v < 1 {
                    return Err(Error::deck(w.span, lig(st, id, "invalid atom type (must be >=1)")));
                }
                if s.sim.ntypes > 0 && v as usize > s.sim.ntypes {
                    return Err(Error::deck(w.span, format!("atom type {v} exceeds the number of atom types ({})", s.sim.ntypes)));
                }
                t.kind = v as u32;
            }
            "radius" | "density" => {
                let what = k.text.clone();
                let styw = a.word("random style")?;
                if styw.text != "constant" {
                    return Err(Error::deck(styw.span, lig(st, id, &format!("invalid {what} random style")))
                        .with_hint(format!("LIGGGHTS 3.8 accepts only '{what} constant VALUE'")));
                }
                let vw = a.word("value")?;
                let v = parse_f64(vw)?;
                if v <= 0.0 {
                    let m = if what == "radius" {
                        "Illegal fix particletemplate/sphere command, radius must be >= 0".to_string()
                    } else {
                        lig(st, id, "density must be >= 0")
                    };
                    return Err(Error::deck(vw.span, m));
                }
                if what == "radius" {
                    t.radius = v;
                    have_r = true;
                } else {
                    t.density = v;
                    have_d = true;
                }
            }
            "volume_limit" => {
                let v = a.f64("volume_limit")?;
                if v <= 0.0 {
                    return Err(a.err_prev(lig(st, id, "volume_limit > 0 required")));
                }
            }
            "relative" => {
                a.yes_no("relative")?;
            }
            "additional_group" => {
                let g = a.word("group")?;
                t.group |= s.group(g)?;
            }
            "region" | "region_variable" => {
                return Err(Error::unsupported(k.span, format!("particletemplate/sphere {}", k.text)));
            }
            _ => return Err(Error::deck(k.span, lig(st, id, "unrecognized keyword"))),
        }
    }
    if !have_d {
        return Err(Error::deck(a.end_span(), lig(st, id, "have to define 'density'")));
    }
    if !have_r {
        return Err(Error::deck(a.end_span(), lig(st, id, "have to define 'radius'")));
    }
    Ok(t)
}

/// `fix ID group particledistribution/discrete seed N t1 w1 t2 w2 ...`.
#[derive(Clone, Debug)]
pub struct Distribution {
    /// Fix id.
    pub id: String,
    /// Style as written.
    pub style: String,
    /// Group bit (added to inserted particles).
    pub group: u32,
    /// Seed.
    pub seed: i64,
    /// Templates in deck order.
    pub templates: Vec<Template>,
    /// Number fractions (normalised).
    pub weights: Vec<f64>,
    /// Weights as written, normalised (mass or number fractions).
    pub given: Vec<f64>,
    /// Whether `given` are mass fractions.
    pub mass_based: bool,
    /// Template indices, largest expected volume first (insertion order).
    pub order: Vec<usize>,
    /// The distribution's random stream, shared by every insert fix using it.
    pub rng: Arc<Mutex<Park>>,
}

impl Distribution {
    /// Expected particle volume.
    pub fn vol_expect(&self) -> f64 {
        self.templates.iter().zip(&self.weights).map(|(t, w)| t.volume() * w).sum()
    }
    /// Expected particle mass.
    pub fn mass_expect(&self) -> f64 {
        self.templates.iter().zip(&self.weights).map(|(t, w)| t.mass() * w).sum()
    }
    /// Largest radius.
    pub fn max_radius(&self) -> f64 {
        self.templates.iter().map(|t| t.radius).fold(0.0, f64::max)
    }
    /// Split `n` particles over the templates (LIGGGHTS `randomize_list`):
    /// exact mode truncates and hands the remaining ones out by remainder
    /// weight; otherwise each template gets int(n w + u). Returns template
    /// indices in insertion order.
    pub fn split(&self, n: usize, exact: bool) -> Vec<usize> {
        let nt = self.templates.len();
        let mut rng = match self.rng.lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        let mut count = vec![0usize; nt];
        if !exact {
            for i in 0..nt {
                count[i] = (n as f64 * self.weights[i] + rng.uniform()) as usize;
            }
        } else {
            let mut rem = vec![0.0; nt];
            let mut sum = 0usize;
            for i in 0..nt {
                let x = n as f64 * self.weights[i];
                count[i] = x as usize;
                sum += count[i];
                rem[i] = x - count[i] as f64;
            }
            let gap = n.saturating_sub(sum);
            for _ in 0..gap {
                let r = rng.uniform() * gap as f64;
                let mut j = 0;
                let mut rsum = rem[0];
                while rsum < r && j < nt - 1 {
                    j += 1;
                    rsum += rem[j];
                }
                count[j] += 1;
            }
        }
        let mut out = Vec::new();
        for &k in &self.order {
            out.extend(std::iter::repeat_n(k, count[k]));
        }
        out
    }
}

impl Fix for Distribution {
    fn save_state(&self) -> crate::engine::fix::FixState {
        // the generator the insertions draw templates from (shared with
        // every insertion fix that uses this distribution)
        match self.rng.lock() {
            Ok(g) => serde_json::to_value(&*g).map_or(crate::engine::fix::FixState::Unsupported, crate::engine::fix::FixState::Saved),
            Err(_) => crate::engine::fix::FixState::Unsupported,
        }
    }
    fn load_state(&mut self, state: &serde_json::Value) -> std::result::Result<(), String> {
        let park: crate::engine::rng::Park = serde_json::from_value(state.clone()).map_err(|e| e.to_string())?;
        *self.rng.lock().map_err(|_| "distribution generator poisoned".to_string())? = park;
        Ok(())
    }
    crate::no_step_hooks!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        &self.style
    }
    fn summary(&self) -> String {
        let parts: Vec<String> = self.templates.iter().zip(&self.weights).map(|(t, w)| format!("{} {:.4}%", t.id, 100.0 * w)).collect();
        format!("{} {}: number fractions {}", self.style, self.id, parts.join(", "))
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

fn parse_distribution(s: &Session, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<Distribution> {
    let st = style.text.as_str();
    let mass_based = !st.contains("numberbased");
    let seed = liggghts_seed(a.word("seed")?)?;
    let nw = a.word("number of templates")?;
    let n = parse_i64(nw)?;
    if n < 1 {
        return Err(Error::deck(nw.span, lig(st, id, "illegal number of templates")));
    }
    if a.rest().len() != 2 * n as usize {
        return Err(Error::deck(nw.span, lig(st, id, "# of templates does not match # of arguments")).with_hint(format!(
            "expected {} template/weight pairs, found {} words",
            n,
            a.rest().len()
        )));
    }
    let mut templates = Vec::new();
    let mut given = Vec::new();
    for _ in 0..n {
        let tw = a.word("template id")?;
        let f = s.sim.fixes.iter().find(|f| f.id() == tw.text);
        let t = match f {
            None => return Err(Error::deck(tw.span, lig(st, id, "invalid ID for fix particletemplate provided"))),
            Some(f) => match f.as_any().and_then(|x| x.downcast_ref::<Template>()) {
                Some(t) => t.clone(),
                None => return Err(Error::deck(tw.span, lig(st, id, "fix is not of type particletemplate"))),
            },
        };
        if templates.iter().any(|x: &Template| x.id == t.id) {
            return Err(Error::deck(tw.span, lig(st, id, "cannot use the same template twice")));
        }
        let ww = a.word("weight")?;
        let w = parse_f64(ww)?;
        if w < 0.0 {
            return Err(Error::deck(ww.span, lig(st, id, "invalid weight")));
        }
        templates.push(t);
        given.push(w);
    }
    let sum: f64 = given.iter().sum();
    if sum <= 0.0 {
        return Err(Error::deck(nw.span, lig(st, id, "sum of distribution weights is zero")));
    }
    for g in given.iter_mut() {
        *g /= sum;
    }
    let mut weights = given.clone();
    if mass_based {
        for (w, t) in weights.iter_mut().zip(&templates) {
            *w /= t.mass();
        }
        let s2: f64 = weights.iter().sum();
        for w in weights.iter_mut() {
            *w /= s2;
        }
    }
    let mut order: Vec<usize> = (0..templates.len()).collect();
    order.sort_by(|&x, &y| templates[y].volume().partial_cmp(&templates[x].volume()).unwrap_or(std::cmp::Ordering::Equal));
    Ok(Distribution {
        id: id.to_string(),
        style: st.to_string(),
        group,
        seed,
        templates,
        weights,
        given,
        mass_based,
        order,
        rng: Arc::new(Mutex::new(Park::new(seed))),
    })
}

/// How inserted velocities are drawn (LIGGGHTS `vel constant|uniform|gaussian`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VelStyle {
    /// Fixed.
    Constant,
    /// mean + fluct * 2 (u - 0.5).
    Uniform,
    /// mean + fluct * gaussian.
    Gaussian,
}

/// What insert/pack fills the region up to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PackTarget {
    /// `volumefraction_region f`.
    VolumeFraction(f64),
    /// `particles_in_region N`.
    Particles(i64),
    /// `mass_in_region M`.
    Mass(f64),
}

/// insert/pack or insert/rate/region specifics.
#[derive(Clone, Debug)]
pub enum InsertMode {
    /// insert/pack.
    Pack(PackTarget),
    /// insert/rate/region: total (None = INF) and rate.
    Rate {
        /// Total number (None: unlimited).
        ninsert: Option<i64>,
        /// Particles per time.
        nflowrate: f64,
        /// Particles per insertion (set at setup from dt).
        ninsert_per: f64,
    },
}

/// LIGGGHTS `fix insert/pack` and `fix insert/rate/region`.
pub struct LiggghtsInsert {
    /// Fix id.
    pub id: String,
    /// Style.
    pub style: String,
    /// Group bit.
    pub group: u32,
    /// Seed.
    pub seed: i64,
    rng: Park,
    gauss_save: Option<f64>,
    region_rng: Park,
    /// The insertion region.
    pub region: Region,
    /// The particle distribution.
    pub dist: Distribution,
    /// Maximum attempts per particle.
    pub maxattempt: i64,
    /// Steps between insertions (0 = once).
    pub insert_every: i64,
    /// Next insertion step.
    pub next: Option<i64>,
    /// Overlap check.
    pub overlap: bool,
    /// Particles entirely inside the region.
    pub all_in: bool,
    /// Exact per-template split (`random_distribute exact`).
    pub exact: bool,
    /// Velocity style, mean and fluctuation.
    pub vel: (VelStyle, V3, V3),
    /// Angular velocity.
    pub omega: V3,
    /// Mode and target.
    pub mode: InsertMode,
    /// Monte Carlo tries for the region volume.
    pub ntry_mc: usize,
    /// Region volume (Monte Carlo, at the first setup).
    pub region_volume: Option<f64>,
    /// Particles inserted so far.
    pub ninserted: i64,
    /// Mass inserted so far.
    pub mass_inserted: f64,
    /// insert/stream: the insertion face and the particles not yet released.
    pub stream: Option<Box<StreamFace>>,
    span: Span,
}

/// What a checkpoint keeps of a LIGGGHTS insertion fix.
#[derive(serde::Serialize, serde::Deserialize)]
struct InsertState {
    rng: Park,
    gauss_save: Option<f64>,
    region_rng: Park,
    next: Option<i64>,
    ninserted: i64,
    mass_inserted: f64,
    region_volume: Option<f64>,
}

/// Where an insert/stream particle started and when it is released.
#[derive(Clone, Copy, Debug)]
pub struct Release {
    /// Position at insertion.
    pub x0: V3,
    /// Insertion step.
    pub i_step: i64,
    /// Release step (the particle reaches the face).
    pub r_step: i64,
}

/// The insertion face of `fix insert/stream` and its release bookkeeping.
#[derive(Clone, Debug)]
pub struct StreamFace {
    /// Id of the `fix mesh/surface` giving the face.
    pub mesh_id: String,
    /// Triangles of the face (world frame, file order).
    pub tris: Vec<crate::geom::mesh::Triangle>,
    /// Accumulated triangle areas.
    pub area_acc: Vec<f64>,
    /// Unit face normal, pointing along the insertion velocity.
    pub normal: V3,
    /// Insertion velocity projected on the normal (particles move with it until released).
    pub v_normal: V3,
    /// First node of the first triangle.
    pub p_ref: V3,
    /// Extrusion length of the face (upstream).
    pub extrude: f64,
    /// The mesh's own random stream (LIGGGHTS seeds every mesh with 179424799).
    pub mesh_rng: Park,
    /// The insertion fraction has been estimated once.
    pub fraction_done: bool,
    /// Fraction of the extruded volume inside the box.
    pub fraction: f64,
    /// Particles moving with v_normal, by tag.
    pub release: std::collections::HashMap<i64, Release>,
}

/// LIGGGHTS `FIX_INSERT_STREAM_TINY`.
const STREAM_TINY: f64 = 1e-14;

impl StreamFace {
    /// A random point on the face (LIGGGHTS `generateRandomOwnedGhost`).
    fn face_point(&mut self) -> V3 {
        let total = self.area_acc.last().copied().unwrap_or(0.0);
        let r = self.mesh_rng.uniform() * total;
        let k = self.area_acc.partition_point(|a| *a < r).min(self.tris.len().saturating_sub(1));
        let (mut u, mut v);
        loop {
            u = self.mesh_rng.uniform();
            v = self.mesh_rng.uniform();
            if u + v <= 1.0 {
                break;
            }
        }
        let t = &self.tris[k].v;
        (1.0 - u - v) * t[0] + v * t[1] + u * t[2]
    }
}

/// Whether `x` is in the box and at least `r` from its faces (LIGGGHTS
/// `is_in_subdomain` and `dist_subbox_borders`, one process).
fn in_box_away(d: &Domain, x: &V3, r: f64) -> bool {
    in_box(d, x) && (0..3).all(|k| (d.lo[k] - x[k]).abs() >= r && (d.hi[k] - x[k]).abs() >= r)
}

fn parse_liggghts_insert(s: &Session, _cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<LiggghtsInsert> {
    let st = style.text.clone();
    let pack = st == "insert/pack";
    let is_stream = st == "insert/stream";
    let mut face: Option<(SharedMesh, Span)> = None;
    let mut extrude_length = 0.0;
    let mut duration = 0i64;
    s.need_box(a.cmd)?;
    if s.dimension != 3 {
        return Err(Error::deck(style.span, lig(&st, id, "Can use fix insert for 3d simulations only")));
    }
    let kw = a.word("keyword 'seed'")?;
    if kw.text != "seed" {
        return Err(Error::deck(kw.span, lig(&st, id, "expecting keyword 'seed'")));
    }
    let seedw = a.word("seed")?;
    let seed = liggghts_seed(seedw)?;
    let mut dist: Option<Distribution> = None;
    let mut maxattempt = 50;
    let mut ninsert: Option<f64> = None;
    let mut inf = false;
    let mut massinsert: Option<f64> = None;
    let (mut nflowrate, mut massflowrate) = (0.0, 0.0);
    let mut insert_every: Option<i64> = None;
    let mut start: Option<i64> = None;
    let (mut overlap, mut all_in, mut exact) = (true, false, true);
    let mut vel = (VelStyle::Constant, V3::zeros(), V3::zeros());
    let mut omega = V3::zeros();
    let mut region: Option<Region> = None;
    let mut targets: Vec<(PackTarget, Span)> = Vec::new();
    let mut ntry_mc = 100000usize;
    // LIGGGHTS reads the common insertion keywords first, then the
    // region/target keywords; a common keyword after those is an error.
    let mut phase2 = false;
    const BASE: &[&str] = &[
        "distributiontemplate",
        "maxattempt",
        "nparticles",
        "mass",
        "massrate",
        "particlerate",
        "insert_every",
        "insert_every_time",
        "every",
        "start",
        "overlapcheck",
        "all_in",
        "random_distribute",
        "verbose",
        "vel",
        "omega",
        "orientation",
        "set_property",
        "compress_tags",
    ];
    const PACK: &[&str] =
        &["region", "volumefraction_region", "particles_in_region", "mass_in_region", "ntry_mc", "warn_region", "check_dist_from_subdomain_border"];
    const STREAM: &[&str] = &["insertion_face", "extrude_length", "duration", "parallel", "ntry_mc"];
    while a.more() {
        let k = a.word("keyword")?;
        let kt = k.text.as_str();
        if BASE.contains(&kt) && phase2 {
            let m = if pack { "unknown keyword" } else { "unknown keyword or wrong keyword order" };
            return Err(Error::deck(k.span, lig(&st, id, m))
                .with_hint(format!("LIGGGHTS reads '{kt}' only before the region keywords ({})", PACK.join(", "))));
        }
        if PACK.contains(&kt) || (is_stream && STREAM.contains(&kt)) {
            phase2 = true;
        }
        if is_stream && PACK.contains(&kt) && !STREAM.contains(&kt) {
            return Err(Error::deck(k.span, lig(&st, id, "unknown keyword")).with_hint(format!("insert/stream keywords: {}", STREAM.join(", "))));
        }
        match kt {
            "insertion_face" if is_stream => {
                let w = a.word("mesh id")?;
                let f = s.sim.fixes.iter().find(|f| f.id() == w.text);
                match f {
                    None => return Err(Error::deck(w.span, lig(&st, id, "Could not find fix mesh/gran id you provided"))),
                    Some(f) if !f.style().starts_with("mesh") => {
                        return Err(Error::deck(w.span, lig(&st, id, "The fix belonging to the id you provided is not of type mesh")))
                    }
                    _ => {}
                }
                let m = super::mesh::find_mesh(s, &w.text)
                    .ok_or_else(|| Error::deck(w.span, lig(&st, id, "The fix belonging to the id you provided is not of type mesh")))?;
                face = Some((m, w.span));
            }
            "extrude_length" if is_stream => {
                extrude_length = a.f64("extrude_length")?;
                if extrude_length < 0.0 {
                    return Err(a.err_prev(lig(&st, id, "invalid extrude_length")));
                }
            }
            "duration" if is_stream => {
                duration = a.i64("duration")?;
                if duration < 1 {
                    return Err(a.err_prev(lig(&st, id, "'duration' can not be < 1")));
                }
            }
            "parallel" if is_stream => {
                a.yes_no("parallel")?;
            }
            "distributiontemplate" => {
                let w = a.word("distribution id")?;
                let d = s.sim.fixes.iter().find(|f| f.id() == w.text).and_then(|f| f.as_any().and_then(|x| x.downcast_ref::<Distribution>()));
                match d {
                    Some(d) => dist = Some(d.clone()),
                    None => {
                        return Err(Error::deck(
                            w.span,
                            lig(&st, id, "Fix insert requires you to define a valid ID for a fix of type particledistribution/discrete"),
                        ))
                    }
                }
            }
            "maxattempt" => maxattempt = a.i64("maxattempt")?,
            "nparticles" | "mass" => {
                let w = a.word("value")?;
                if w.text == "INF" {
                    inf = true;
                } else if kt == "nparticles" {
                    ninsert = Some(parse_f64(w)?.trunc());
                } else {
                    massinsert = Some(parse_f64(w)?);
                }
            }
            "massrate" => massflowrate = a.f64("massrate")?,
            "particlerate" => nflowrate = a.f64("particlerate")?,
            "insert_every" | "every" | "insert_every_time" => {
                let w = a.word("insert_every")?;
                let v = if w.text == "once" {
                    0
                } else if kt == "insert_every_time" {
                    (parse_f64(w)? / s.sim.dt) as i64
                } else {
                    parse_i64(w)?
                };
                if v < 0 {
                    return Err(Error::deck(w.span, lig(&st, id, "insert_every must be >= 0")));
                }
                insert_every = Some(v);
            }
            "start" => {
                let w = a.word("start step")?;
                let v = parse_i64(w)?;
                if v < s.sim.step + 1 {
                    return Err(Error::deck(w.span, lig(&st, id, "'start' step can not be before current step")));
                }
                start = Some(v);
            }
            "overlapcheck" => overlap = a.yes_no("overlapcheck")?,
            "all_in" => all_in = a.yes_no("all_in")?,
            "random_distribute" => {
                let w = a.choice("random_distribute", &["uncorrelated", "exact"])?;
                exact = w.text == "exact";
            }
            "verbose" | "warn_region" | "check_dist_from_subdomain_border" => {
                a.yes_no(kt)?;
            }
            "compress_tags" => {
                if a.yes_no("compress_tags")? {
                    return Err(Error::unsupported(k.span, "insert compress_tags yes"));
                }
            }
            "set_property" => return Err(Error::unsupported(k.span, format!("fix {st} set_property"))),
            "vel" => {
                let w = a.choice("vel style", &["constant", "uniform", "gaussian"])?;
                let m = V3::new(a.f64("vx")?, a.f64("vy")?, a.f64("vz")?);
                vel = match w.text.as_str() {
                    "constant" => (VelStyle::Constant, m, V3::zeros()),
                    sty => {
                        let f = V3::new(a.f64("dvx")?, a.f64("dvy")?, a.f64("dvz")?);
                        (if sty == "uniform" { VelStyle::Uniform } else { VelStyle::Gaussian }, m, f)
                    }
                };
            }
            "omega" => {
                a.choice("omega style", &["constant"])?;
                omega = V3::new(a.f64("omegax")?, a.f64("omegay")?, a.f64("omegaz")?);
            }
            "orientation" => {
                // spheres: orientation does not matter
                let w = a.choice("orientation", &["random", "template", "constant"])?;
                if w.text == "constant" {
                    for _ in 0..4 {
                        a.f64("quaternion component")?;
                    }
                }
            }
            "region" => {
                let w = a.word("region id")?;
                let r = super::setup::region(s, w)?;
                if r.is_dynamic() {
                    return Err(Error::deck(w.span, lig(&st, id, "dynamic regions are not allowed")));
                }
                if r.bbox().is_none() {
                    return Err(Error::deck(w.span, "Unable to calculate region volume. Region needs to have existing bounding box"));
                }
                region = Some(r.clone());
            }
            "volumefraction_region" => {
                let v = a.f64("volume fraction")?;
                if !(0.0..=1.0).contains(&v) {
                    return Err(a.err_prev(lig(&st, id, "Invalid volumefraction")));
                }
                if v > 0.0 {
                    targets.push((PackTarget::VolumeFraction(v), k.span));
                }
            }
            "particles_in_region" => {
                let v = a.i64("particles")?;
                if v <= 0 {
                    return Err(a.err_prev(lig(&st, id, "'ntotal_region' > 0 required")));
                }
                targets.push((PackTarget::Particles(v), k.span));
            }
            "mass_in_region" => {
                let v = a.f64("mass")?;
                if v <= 0.0 {
                    return Err(a.err_prev(lig(&st, id, "'masstotal_region' > 0 required")));
                }
                targets.push((PackTarget::Mass(v), k.span));
            }
            "ntry_mc" => {
                let v = a.i64("ntry_mc")?;
                if v < 1000 {
                    return Err(a.err_prev(lig(&st, id, "ntry_mc must be > 1000")));
                }
                ntry_mc = v as usize;
            }
            _ => {
                let mut all: Vec<&str> = BASE.to_vec();
                all.extend_from_slice(if is_stream { STREAM } else { PACK });
                return Err(bad_keyword(k, &format!("{st} keyword"), &all));
            }
        }
    }
    let dist = dist.ok_or_else(|| Error::deck(style.span, lig(&st, id, "have to define a 'distributiontemplate'")))?;
    // seeds must all differ
    let mut seeds = vec![seed, dist.seed];
    seeds.extend(dist.templates.iter().map(|t| t.seed));
    let mut sorted = seeds.clone();
    sorted.sort();
    sorted.dedup();
    if sorted.len() != seeds.len() {
        return Err(Error::deck(
            seedw.span,
            format!("Fix {st}, ID {id}: Random number generation: It is required that all the random seeds of this fix insert/*, the random seed of particle distribution fix (id {}) and all random seeds of its fix particletemplate/* commands are different", dist.id),
        ));
    }
    if let Some(t) = dist.templates.iter().find(|t| t.kind as usize > s.sim.ntypes.max(1)) {
        return Err(Error::deck(style.span, format!("template {} inserts atom type {}, but the box has {} atom types", t.id, t.kind, s.sim.ntypes)));
    }
    if ninsert.is_some() && massinsert.is_some() {
        return Err(Error::deck(style.span, lig(&st, id, "must not define both 'nparticles' and 'mass'")));
    }
    if nflowrate > 0.0 && massflowrate > 0.0 {
        return Err(Error::deck(style.span, lig(&st, id, "must not define both 'particlerate' and 'massrate'")));
    }
    let mut stream = None;
    if is_stream {
        let (f, sp, ie) = stream_face(s, &st, id, face, vel.1, extrude_length, duration, insert_every, &dist, style.span)?;
        insert_every = Some(ie);
        region = Some(Region {
            id: f.mesh_id.clone(),
            shape: Shape::Block { lo: sp.0, hi: sp.1 },
            interior: true,
            open: [false; 6],
            motion: None,
            disp: V3::zeros(),
            angle: 0.0,
            box_bounds: None,
        });
        stream = Some(Box::new(f));
    }
    let insert_every = insert_every.ok_or_else(|| Error::deck(style.span, lig(&st, id, "must define 'insert_every'")))?;
    if insert_every == 0 && (nflowrate > 0.0 || massflowrate > 0.0) {
        return Err(Error::deck(style.span, lig(&st, id, "must not define 'particlerate' or 'massrate' for 'insert_every' = 0")));
    }
    let region = region.ok_or_else(|| Error::deck(style.span, lig(&st, id, "must define an insertion region")))?;
    let mode = if pack {
        if ninsert.is_some() || massinsert.is_some() {
            return Err(Error::deck(style.span, lig(&st, id, "specifying 'nparticles' or 'mass' not allowed")));
        }
        if nflowrate > 0.0 || massflowrate > 0.0 {
            return Err(Error::deck(style.span, lig(&st, id, "specifying 'nflowrate' or 'massflowrate' not allowed")));
        }
        if targets.len() != 1 {
            let sp = targets.get(1).map(|t| t.1).unwrap_or(style.span);
            return Err(Error::deck(
                sp,
                lig(&st, id, "must define exactly one keyword out of 'volumefraction_region', 'particles_in_region', and 'mass_in_region'"),
            ));
        }
        InsertMode::Pack(targets[0].0)
    } else {
        if let Some((_, sp)) = targets.first() {
            return Err(Error::deck(*sp, lig(&st, id, "unknown keyword or wrong keyword order")));
        }
        if insert_every == 0 {
            return Err(Error::deck(style.span, lig(&st, id, "'insert_every' = once not allowed")));
        }
        let total = if inf {
            None
        } else if let Some(n) = ninsert.filter(|n| *n > 0.0) {
            Some(n as i64)
        } else if let Some(m) = massinsert.filter(|m| *m > 0.0) {
            Some((m / dist.mass_expect()) as i64)
        } else {
            return Err(Error::deck(style.span, lig(&st, id, "must define either 'nparticles' or 'mass'")));
        };
        let rate = if nflowrate > 0.0 {
            nflowrate
        } else if massflowrate > 0.0 {
            massflowrate / dist.mass_expect()
        } else {
            return Err(Error::deck(style.span, lig(&st, id, "must define either 'massrate' or 'particlerate'")));
        };
        InsertMode::Rate { ninsert: total, nflowrate: rate, ninsert_per: 0.0 }
    };
    Ok(LiggghtsInsert {
        id: id.to_string(),
        style: st,
        group,
        seed,
        rng: Park::new(seed),
        gauss_save: None,
        region_rng: Park::new(seed + SEED_OFFSET),
        region,
        dist,
        maxattempt,
        insert_every,
        next: Some(start.unwrap_or(s.sim.step + 1)),
        overlap,
        all_in,
        exact,
        vel,
        omega,
        mode,
        ntry_mc,
        region_volume: None,
        ninserted: 0,
        mass_inserted: 0.0,
        stream,
        span: style.span,
    })
}

/// Check the insertion face of insert/stream and derive its geometry
/// (LIGGGHTS `calc_insertion_properties`): the face, the extruded volume's
/// bounding box and insert_every.
#[allow(clippy::too_many_arguments)]
fn stream_face(
    s: &Session,
    st: &str,
    id: &str,
    face: Option<(SharedMesh, Span)>,
    v_insert: V3,
    extrude_length: f64,
    duration: i64,
    insert_every: Option<i64>,
    dist: &Distribution,
    span: Span,
) -> Result<(StreamFace, (V3, V3), i64)> {
    let (mesh, mspan) = face.ok_or_else(|| Error::deck(span, lig(st, id, "must define an insertion face")))?;
    let m = mesh.read().map_err(|_| Error::runtime("mesh state poisoned by an earlier failure"))?;
    if m.tris.is_empty() {
        return Err(Error::deck(mspan, lig(st, id, "the insertion face has no triangles")));
    }
    if !m.is_planar() {
        return Err(Error::deck(mspan, lig(st, id, "command requires a planar face for insertion")));
    }
    if m.motion.is_some() {
        return Err(Error::deck(mspan, lig(st, id, "cannot translate, rotate, scale mesh which is used for particle insertion")));
    }
    let tris = m.tris.clone();
    let mut normal = tris[0].n;
    if v_insert.dot(&normal) < 0.0 {
        normal = -normal;
    }
    let v_normal = normal * v_insert.dot(&normal);
    if v_normal.norm() < 1e-3 {
        return Err(Error::deck(span, lig(st, id, "insertion velocity projected on face normal is < 1e-3")));
    }
    if v_insert.norm() < 1e-5 {
        return Err(Error::deck(span, lig(st, id, "insertion velocity too low")));
    }
    if insert_every.is_none() && extrude_length == 0.0 {
        return Err(Error::deck(span, lig(st, id, "must define either 'insert_every' or 'extrude_length'")));
    }
    if insert_every.is_some() && extrude_length > 0.0 {
        return Err(Error::deck(span, lig(st, id, "must not provide both 'insert_every' and 'extrude_length'")));
    }
    if extrude_length > 0.0 && duration > 0 {
        return Err(Error::deck(span, lig(st, id, "must not provide both 'extrude_length' and 'duration'")));
    }
    let dt = s.sim.dt;
    let rmax = dist.max_radius();
    let (every, extrude) = match insert_every {
        None => {
            if extrude_length < 3.0 * rmax {
                return Err(Error::deck(span, lig(st, id, "'extrude_length' is too small"))
                    .with_hint(format!("it must be at least 3 x the largest radius ({})", 3.0 * rmax)));
            }
            let e = ((extrude_length + STREAM_TINY) / (dt * v_normal.norm())) as i64;
            if e == 0 {
                return Err(Error::deck(span, lig(st, id, "insertion velocity too high or extrude_length too low")));
            }
            (e, extrude_length)
        }
        Some(e) => {
            if e < 1 {
                return Err(Error::deck(span, lig(st, id, "'insert_every' must be > 0")));
            }
            let d = if duration == 0 { e } else { duration };
            if d > e {
                return Err(Error::deck(span, lig(st, id, "'duration' > 'insert_every' not allowed")));
            }
            let x = d as f64 * dt * v_normal.norm();
            if x < 3.0 * rmax {
                return Err(Error::deck(span, lig(st, id, "'insert_every' or 'vel' is too small, or radius of inserted particles too large")));
            }
            (e, x)
        }
    };
    let mut area_acc = Vec::with_capacity(tris.len());
    let mut acc = 0.0;
    let (mut lo, mut hi) = (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY));
    for t in &tris {
        acc += t.area();
        area_acc.push(acc);
        for v in &t.v {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
    }
    let ext = -extrude * normal;
    let (lo2, hi2) = (lo.inf(&(lo + ext)), hi.sup(&(hi + ext)));
    let f = StreamFace {
        mesh_id: m.id.clone(),
        p_ref: tris[0].v[0],
        tris,
        area_acc,
        normal,
        v_normal,
        extrude,
        mesh_rng: Park::new(179424799),
        fraction_done: false,
        fraction: 1.0,
        release: Default::default(),
    };
    Ok((f, (lo2, hi2), every))
}

/// C `%e`.
fn fmt_e(x: f64) -> String {
    crate::io::cfmt::sprintf("%e", &[crate::io::cfmt::CArg::Float(x)]).unwrap_or_else(|_| format!("{x:e}"))
}

/// Park-Miller gaussian (polar method with a saved second value, LAMMPS `RanPark::gaussian`).
fn gaussian(rng: &mut Park, save: &mut Option<f64>) -> f64 {
    if let Some(v) = save.take() {
        return v;
    }
    loop {
        let v1 = 2.0 * rng.uniform() - 1.0;
        let v2 = 2.0 * rng.uniform() - 1.0;
        let rsq = v1 * v1 + v2 * v2;
        if rsq < 1.0 && rsq != 0.0 {
            let fac = (-2.0 * rsq.ln() / rsq).sqrt();
            *save = Some(v1 * fac);
            return v2 * fac;
        }
    }
}

impl LiggghtsInsert {
    /// One line for the `demx check` summary.
    pub fn describe(&self) -> String {
        let what = match &self.mode {
            InsertMode::Pack(PackTarget::VolumeFraction(f)) => {
                let v = self.region.volume().unwrap_or(0.0);
                format!("volume fraction {f} of region {} (about {:.1} particles)", self.region.id, f * v / self.dist.vol_expect())
            }
            InsertMode::Pack(PackTarget::Particles(n)) => format!("{n} particles in region {}", self.region.id),
            InsertMode::Pack(PackTarget::Mass(m)) => format!("mass {m} in region {}", self.region.id),
            InsertMode::Rate { ninsert, nflowrate, .. } => format!(
                "{} particles at {nflowrate} per time unit into region {}",
                ninsert.map_or("unlimited".to_string(), |n| n.to_string()),
                self.region.id
            ),
        };
        let every = if self.insert_every == 0 { "once".to_string() } else { format!("every {} steps", self.insert_every) };
        let tpl: Vec<String> = self
            .dist
            .templates
            .iter()
            .zip(&self.dist.weights)
            .map(|(t, w)| format!("{} (type {}, r {}, rho {}, {:.1}% by number)", t.id, t.kind, t.radius, t.density, 100.0 * w))
            .collect();
        let when = match self.next {
            Some(n) => format!("from step {n} {every}"),
            None => format!("{every}, no insertion left"),
        };
        format!("fix {} {}: {what}, {when}; {}", self.style, self.id, tpl.join(", "))
    }

    fn volume(&mut self, domain: &Domain) -> Result<f64> {
        if let Some(v) = self.region_volume {
            return Ok(v);
        }
        let mut r = Park::new(self.seed + SEED_OFFSET);
        let v = region_volume_mc(&self.region, domain, &mut r, self.ntry_mc).unwrap_or(0.0);
        self.region_rng = r;
        if v <= 0.0 {
            return Err(Error::deck(
                self.span,
                format!("fix {} {}: Unable to calculate region volume (region {} is empty or outside the box)", self.style, self.id, self.region.id),
            ));
        }
        self.region_volume = Some(v);
        Ok(v)
    }

    fn draw_velocity(&mut self) -> V3 {
        let (sty, m, f) = self.vel;
        match sty {
            VelStyle::Constant => m,
            VelStyle::Uniform => {
                let mut v = m;
                for k in 0..3 {
                    v[k] += f[k] * 2.0 * (self.rng.uniform() - 0.5);
                }
                v
            }
            VelStyle::Gaussian => {
                let mut v = m;
                for k in 0..3 {
                    v[k] += f[k] * gaussian(&mut self.rng, &mut self.gauss_save);
                }
                v
            }
        }
    }

    /// One insert/stream insertion (LIGGGHTS `FixInsert::pre_exchange` with
    /// the stream's `x_v_omega` and `finalize_insertion`).
    fn stream_insert(&mut self, sim: &mut Sim, domain: &Domain) -> Result<()> {
        let Some(mut f) = self.stream.take() else { return Ok(()) };
        let r = self.stream_insert_with(sim, domain, &mut f);
        self.stream = Some(f);
        r
    }

    fn stream_insert_with(&mut self, sim: &mut Sim, domain: &Domain, f: &mut StreamFace) -> Result<()> {
        let (mut n, _) = self.count(sim)?;
        let mut exact = self.exact;
        if let InsertMode::Rate { ninsert: Some(t), .. } = self.mode {
            if self.ninserted + n >= t {
                n = (t - self.ninserted).max(0);
                exact = true;
            }
        }
        // insertion fraction: first time, and every time on a shrink-wrapped box
        let shrink = domain.sides.iter().any(|s| s.contains(&crate::engine::domain::Side::Shrink));
        if !f.fraction_done || shrink {
            f.fraction_done = true;
            let mut nin = 0usize;
            for _ in 0..self.ntry_mc {
                let mut x = f.face_point();
                x -= f.normal * (self.rng.uniform() * f.extrude);
                if in_box(domain, &x) {
                    nin += 1;
                }
            }
            f.fraction = nin as f64 / self.ntry_mc.max(1) as f64;
        }
        if !exact {
            n = (f.fraction * n as f64 + self.rng.uniform()) as i64;
        } else if f.fraction < 0.02 {
            return Err(Error::runtime(format!("fix {} {}: the extruded insertion face lies outside the box", self.style, self.id)));
        }
        let list = self.dist.split(n.max(0) as usize, exact);
        let want = list.len();
        if want == 0 {
            sim.log.line("WARNING: Particle insertion: Inserting no particle - check particle insertion settings");
            let more = match self.mode {
                InsertMode::Rate { ninsert: Some(t), .. } => self.ninserted < t,
                _ => true,
            };
            self.schedule_next(more);
            return Ok(());
        }
        let maxtry = want as i64 * self.maxattempt;
        let rmax_new = self.dist.max_radius();
        let p = &sim.particles;
        let rmax_old = p.radius.iter().copied().fold(0.0, f64::max);
        let mut grid = OverlapGrid::new(rmax_new + rmax_old.max(rmax_new), Some(domain));
        if self.overlap {
            for i in 0..p.len() {
                grid.add(p.x[i], p.radius[i]);
            }
        }
        let extrude = f.extrude;
        let gen = |f: &mut StreamFace, rng: &mut Park, rad: f64, ol: bool| {
            let x = f.face_point();
            let r = if ol { rng.uniform() * extrude + rad } else { rng.uniform() * (extrude - 2.0 * rad) + rad };
            x - f.normal * r
        };
        let mut placed: Vec<(usize, V3)> = Vec::new();
        let mut ntry = 0i64;
        if !self.overlap {
            for _ in 0..want {
                let k = list[placed.len()];
                let rad = self.dist.templates[k].radius;
                let mut x;
                loop {
                    x = gen(f, &mut self.rng, rad, false);
                    ntry += 1;
                    if !(ntry < maxtry && !in_box_away(domain, &x, rad)) {
                        break;
                    }
                }
                if ntry < maxtry {
                    placed.push((k, x));
                }
            }
        } else {
            while ntry < maxtry && placed.len() < want {
                let k = list[placed.len()];
                let rad = self.dist.templates[k].radius;
                let mut ok = false;
                while !ok && ntry < maxtry {
                    let mut x;
                    loop {
                        x = gen(f, &mut self.rng, rad, true);
                        ntry += 1;
                        if !(ntry < maxtry && !in_box_away(domain, &x, rad)) {
                            break;
                        }
                    }
                    if ntry < maxtry && !grid.overlaps(x, rad) {
                        grid.add(x, rad);
                        placed.push((k, x));
                        ok = true;
                    }
                }
            }
        }
        let mut tag = sim.particles.max_tag();
        let mut mass_now = 0.0;
        let speed = f.v_normal.norm();
        for &(k, x) in &placed {
            let t = &self.dist.templates[k];
            tag += 1;
            sim.particles.push(NewParticle {
                tag,
                kind: t.kind,
                mask: 1 | self.group | self.dist.group | t.group,
                x,
                v: f.v_normal,
                omega: V3::zeros(),
                radius: t.radius,
                density: t.density,
            });
            mass_now += t.mass();
            let dist_normal = (f.p_ref - x).dot(&f.normal);
            let n_steps = ((dist_normal + STREAM_TINY) / (speed * sim.dt)) as i64;
            f.release.insert(tag, Release { x0: x, i_step: sim.step, r_step: sim.step + n_steps });
        }
        sim.force_rebuild = true;
        self.ninserted += placed.len() as i64;
        self.mass_inserted += mass_now;
        sim.log.line(&format!(
            "INFO: Particle insertion {}: inserted {} particle templates (mass {}) at step {}\n - a total of {} particle templates (mass {}) inserted so far.",
            self.id,
            placed.len(),
            fmt_e(mass_now),
            sim.step,
            self.ninserted,
            fmt_e(self.mass_inserted)
        ));
        if placed.len() < want {
            sim.log.line("WARNING: Particle insertion: Less insertions than requested");
        }
        let more = match self.mode {
            InsertMode::Rate { ninsert: Some(t), .. } => self.ninserted < t,
            _ => true,
        };
        self.schedule_next(more);
        Ok(())
    }

    /// After an insertion event at `self.next`: the following event, or none
    /// when `insert_every once` (LIGGGHTS inserts once, and later runs keep
    /// the fix without inserting again) or when the target count is reached.
    fn schedule_next(&mut self, more: bool) {
        self.next = if self.insert_every > 0 && more { self.next.map(|s| s + self.insert_every) } else { None };
    }

    /// Number to insert now and the insertion ratio (pack) (LIGGGHTS `calc_ninsert_this`).
    fn count(&mut self, sim: &Sim) -> Result<(i64, f64)> {
        let p = &sim.particles;
        match self.mode.clone() {
            InsertMode::Pack(target) => {
                let (mut np, mut vol, mut mass) = (0i64, 0.0, 0.0);
                for i in 0..p.len() {
                    if self.region.contains(p.x[i]) {
                        np += 1;
                        vol += 4.0 * PI / 3.0 * p.radius[i].powi(3);
                        mass += p.mass[i];
                    }
                }
                let rv = self.region_volume.unwrap_or(0.0);
                let (n, ratio) = match target {
                    PackTarget::VolumeFraction(f) => (((f * rv - vol) / self.dist.vol_expect() + self.rng.uniform()).trunc() as i64, vol / (f * rv)),
                    PackTarget::Particles(n) => (n - np, np as f64 / n as f64),
                    PackTarget::Mass(m) => (((m - mass) / self.dist.mass_expect() + self.rng.uniform()).trunc() as i64, mass / m),
                };
                Ok((n.max(0), ratio.clamp(0.0, 1.0)))
            }
            InsertMode::Rate { ninsert, ninsert_per, .. } => {
                let mut n = (ninsert_per + self.rng.uniform()) as i64;
                if let Some(t) = ninsert {
                    if self.ninserted + n > t {
                        n = t - self.ninserted;
                    }
                }
                Ok((n.max(0), 0.0))
            }
        }
    }
}

impl Fix for LiggghtsInsert {
    fn save_state(&self) -> crate::engine::fix::FixState {
        // insert/stream keeps its particles in flight: not yet
        if self.stream.is_some() {
            return crate::engine::fix::FixState::Unsupported;
        }
        let st = InsertState {
            rng: self.rng.clone(),
            gauss_save: self.gauss_save,
            region_rng: self.region_rng.clone(),
            next: self.next,
            ninserted: self.ninserted,
            mass_inserted: self.mass_inserted,
            region_volume: self.region_volume,
        };
        serde_json::to_value(st).map_or(crate::engine::fix::FixState::Unsupported, crate::engine::fix::FixState::Saved)
    }
    fn load_state(&mut self, state: &serde_json::Value) -> std::result::Result<(), String> {
        let st: InsertState = serde_json::from_value(state.clone()).map_err(|e| e.to_string())?;
        self.rng = st.rng;
        self.gauss_save = st.gauss_save;
        self.region_rng = st.region_rng;
        self.next = st.next;
        self.ninserted = st.ninserted;
        self.mass_inserted = st.mass_inserted;
        self.region_volume = st.region_volume;
        Ok(())
    }
    crate::no_step_hooks!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        &self.style
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        if let Some(n) = self.next {
            if n < sim.step && sim.dry {
                // check mode skips the steps of a run without inserting: catch
                // the schedule up as the skipped insertions would have
                self.next = if self.insert_every > 0 {
                    let late = sim.step - n;
                    Some(n + (late + self.insert_every - 1) / self.insert_every * self.insert_every)
                } else {
                    None
                };
            } else if n < sim.step {
                return Err(Error::runtime(format!("Fix {} (id {}): 'start' step can not be before current step", self.style, self.id)));
            }
        }
        if let Some(d) = sim.domain.clone() {
            if self.stream.is_none() {
                self.volume(&d)?;
            }
        }
        if let InsertMode::Rate { nflowrate, ninsert_per, .. } = &mut self.mode {
            *ninsert_per = *nflowrate * self.insert_every as f64 * sim.dt;
        }
        Ok(())
    }
    fn next_reneighbor(&self) -> Option<i64> {
        self.next
    }
    fn pre_exchange(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        if sim.dry || self.next != Some(sim.step) {
            return Ok(());
        }
        let Some(domain) = sim.domain.clone() else { return Ok(()) };
        if self.stream.is_some() {
            return self.stream_insert(sim, &domain);
        }
        self.volume(&domain)?;
        // region outside the box with a fixed boundary
        if let Some((lo, hi)) = self.region.bbox() {
            let out = (0..3).any(|d| lo[d] < domain.lo[d] || hi[d] > domain.hi[d]);
            let fixed = domain.sides.iter().any(|s| s.contains(&crate::engine::domain::Side::Fixed));
            if out && fixed {
                return Err(Error::runtime(format!(
                    "Fix {} (id {}): Insertion region extends outside simulation box and a fixed boundary is used. Please use non-fixed boundaries in this case only",
                    self.style, self.id
                )));
            }
        }
        let (mut n, ratio) = self.count(sim)?;
        let mut exact = self.exact;
        let limit = if let InsertMode::Rate { ninsert: Some(t), .. } = self.mode { Some(t) } else { None };
        if let Some(t) = limit {
            if self.ninserted + n >= t {
                n = (t - self.ninserted).max(0);
                exact = true;
            }
        }
        let list = self.dist.split(n as usize, exact);
        let want = list.len();
        let mut placed = 0usize;
        let mut mass_now = 0.0;
        if want > 0 {
            let maxtry = match self.mode {
                InsertMode::Pack(_) if ratio < 1.0 => ((want as f64 * self.maxattempt as f64) / (1.0 - ratio)) as i64,
                _ => want as i64 * self.maxattempt,
            };
            let rmax_new = self.dist.max_radius();
            let p = &sim.particles;
            let rmax_old = p.radius.iter().copied().fold(0.0, f64::max);
            let mut grid = OverlapGrid::new(rmax_new + rmax_old.max(rmax_new), Some(&domain));
            if self.overlap {
                for i in 0..p.len() {
                    grid.add(p.x[i], p.radius[i]);
                }
            }
            let mut tag = sim.particles.max_tag();
            let mut ntry = 0i64;
            'outer: for &k in &list {
                let t = self.dist.templates[k].clone();
                let shrink = if self.all_in { t.radius } else { 0.0 };
                loop {
                    if ntry >= maxtry {
                        break 'outer;
                    }
                    ntry += 1;
                    let Some(x) = random_point(&self.region, &domain, &mut self.region_rng, shrink, 100_000) else {
                        return Err(Error::runtime(format!(
                            "fix {} {}: could not find a random point in region {} (all_in yes with particles larger than the region?)",
                            self.style, self.id, self.region.id
                        )));
                    };
                    let v = self.draw_velocity();
                    if self.overlap && grid.overlaps(x, t.radius) {
                        continue;
                    }
                    if self.overlap {
                        grid.add(x, t.radius);
                    }
                    tag += 1;
                    sim.particles.push(NewParticle {
                        tag,
                        kind: t.kind,
                        mask: 1 | self.group | self.dist.group | t.group,
                        x,
                        v,
                        omega: self.omega,
                        radius: t.radius,
                        density: t.density,
                    });
                    mass_now += t.mass();
                    placed += 1;
                    break;
                }
            }
            sim.force_rebuild = true;
        }
        self.ninserted += placed as i64;
        self.mass_inserted += mass_now;
        if want > 0 {
            sim.log.line(&format!(
                "INFO: Particle insertion {}: inserted {} particle templates (mass {}) at step {}\n - a total of {} particle templates (mass {}) inserted so far.",
                self.id,
                placed,
                fmt_e(mass_now),
                sim.step,
                self.ninserted,
                fmt_e(self.mass_inserted)
            ));
            if placed < want {
                sim.log.line(&format!("WARNING: Particle insertion: Less insertions than requested ({placed} of {want})"));
            }
        } else if let InsertMode::Rate { .. } = self.mode {
            sim.log.line("WARNING: Particle insertion: Inserting no particle - check particle insertion settings");
        }
        let more = match self.mode {
            InsertMode::Rate { ninsert: Some(t), .. } => self.ninserted < t,
            _ => true,
        };
        self.schedule_next(more);
        Ok(())
    }
    /// Particles of an insert/stream still on their way into the box.
    fn end_of_step_due(&self, _step: i64) -> bool {
        self.stream.as_ref().is_some_and(|f| !f.release.is_empty())
    }
    fn end_of_step(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        let Some(mut f) = self.stream.take() else { return Ok(()) };
        if !f.release.is_empty() {
            let step = sim.step;
            let dt = sim.dt;
            for i in 0..sim.particles.len() {
                if sim.particles.mask[i] & self.group == 0 {
                    continue;
                }
                let tag = sim.particles.tag[i];
                let Some(r) = f.release.get(&tag).copied() else { continue };
                if step > r.r_step {
                    f.release.remove(&tag);
                    continue;
                }
                let p = &mut sim.particles;
                p.x[i] = r.x0 + f.v_normal * ((step - r.i_step) as f64 * dt);
                p.f[i] = V3::zeros();
                p.torque[i] = V3::zeros();
                if step == r.r_step {
                    f.release.remove(&tag);
                    let v = self.draw_velocity();
                    let p = &mut sim.particles;
                    p.v[i] = v;
                    p.omega[i] = self.omega;
                } else {
                    p.v[i] = f.v_normal;
                    p.omega[i] = V3::zeros();
                }
            }
        }
        self.stream = Some(f);
        Ok(())
    }
    fn vector(&self, _sim: &Sim, i: usize) -> Option<f64> {
        match i {
            1 => Some(self.ninserted as f64),
            2 => Some(self.mass_inserted),
            _ => None,
        }
    }
    fn summary(&self) -> String {
        self.describe()
    }
}

// ---------------------------------------------------------------- LAMMPS pour

/// Diameter distribution of fix pour (radii stored).
#[derive(Clone, Debug)]
pub enum PourDiam {
    /// `diam one D`.
    One(f64),
    /// `diam range Dlo Dhi`.
    Range(f64, f64),
    /// `diam poly N D1 P1 ...`: (radius, fraction).
    Poly(Vec<(f64, f64)>),
}

/// Insertion region of fix pour.
#[derive(Clone, Copy, Debug)]
pub enum PourRegion {
    /// Block: x and y bounds (3d; in 2d only x is used).
    Block {
        /// x range.
        x: (f64, f64),
        /// y range.
        y: (f64, f64),
    },
    /// z-axis cylinder: centre and radius.
    Cylinder {
        /// Centre x.
        xc: f64,
        /// Centre y.
        yc: f64,
        /// Radius.
        rc: f64,
    },
}

/// LAMMPS `fix ID group pour N type seed keyword values`.
pub struct Pour {
    /// Fix id.
    pub id: String,
    /// Group bit.
    pub group: u32,
    /// Total to insert.
    pub ninsert: i64,
    /// Atom type.
    pub kind: u32,
    rng: Park,
    /// Region footprint.
    pub region: PourRegion,
    /// Vertical range (z in 3d, y in 2d).
    pub vlo: f64,
    /// Top of the vertical range.
    pub vhi: f64,
    /// 2 or 3.
    pub dim: u8,
    /// Diameters.
    pub diam: PourDiam,
    /// Density range.
    pub dens: (f64, f64),
    /// Volume fraction.
    pub volfrac: f64,
    /// Attempts per particle.
    pub maxattempt: i64,
    /// Region rise rate.
    pub rate: f64,
    /// vxlo, vxhi, vylo, vyhi, vy, vz.
    pub vel: [f64; 6],
    /// `id next`.
    pub idnext: bool,
    maxtag: i64,
    /// Gravity (negative, along -z or -y).
    pub grav: f64,
    /// dt at creation.
    pub dt: f64,
    /// Steps between insertions.
    pub nfreq: i64,
    /// Particles per insertion.
    pub nper: i64,
    /// First insertion step.
    pub nfirst: i64,
    /// Next insertion step.
    pub next: Option<i64>,
    /// Inserted so far.
    pub ninserted: i64,
}

impl Pour {
    fn radius_max(&self) -> f64 {
        match &self.diam {
            PourDiam::One(r) => *r,
            PourDiam::Range(_, h) => *h,
            PourDiam::Poly(v) => v.iter().map(|x| x.0).fold(0.0, f64::max),
        }
    }
    /// The last insertion step if every insertion succeeds (LAMMPS' message).
    pub fn nfinal(&self) -> i64 {
        self.nfirst + (self.ninsert - 1) / self.nper * self.nfreq
    }
    /// One line for the `demx check` summary.
    pub fn describe(&self) -> String {
        let d = match &self.diam {
            PourDiam::One(r) => format!("diameter {}", 2.0 * r),
            PourDiam::Range(a, b) => format!("diameter {}..{}", 2.0 * a, 2.0 * b),
            PourDiam::Poly(v) => format!("{} diameters", v.len()),
        };
        format!(
            "fix pour {}: {} particles of type {}, {} every {} steps from step {} (last at step {}), {d}, density {}..{}",
            self.id,
            self.ninsert,
            self.kind,
            self.nper,
            self.nfreq,
            self.nfirst,
            self.nfinal(),
            self.dens.0,
            self.dens.1
        )
    }
    fn radius_sample(&mut self) -> f64 {
        match &self.diam {
            PourDiam::One(r) => *r,
            PourDiam::Range(lo, hi) => lo + self.rng.uniform() * (hi - lo),
            PourDiam::Poly(v) => {
                let u = self.rng.uniform();
                let mut i = 0;
                let mut sum = 0.0;
                while sum < u && i < v.len() {
                    sum += v[i].1;
                    i += 1;
                }
                v[i.max(1) - 1].0
            }
        }
    }
    fn xyz_random(&mut self, h: f64) -> V3 {
        match self.region {
            PourRegion::Block { x, y } => {
                let px = x.0 + self.rng.uniform() * (x.1 - x.0);
                if self.dim == 2 {
                    return V3::new(px, h, 0.0);
                }
                let py = y.0 + self.rng.uniform() * (y.1 - y.0);
                V3::new(px, py, h)
            }
            PourRegion::Cylinder { xc, yc, rc } => loop {
                let r1 = self.rng.uniform() - 0.5;
                let r2 = self.rng.uniform() - 0.5;
                if r1 * r1 + r2 * r2 < 0.25 {
                    return V3::new(xc + 2.0 * r1 * rc, yc + 2.0 * r2 * rc, h);
                }
            },
        }
    }
}

/// Acceleration a gravity fix applies (measured on a unit-mass probe, so
/// constant and variable magnitudes both work).
fn gravity_of(f: &mut Box<dyn Fix>, vars: &Variables) -> Result<V3> {
    let mut probe = Sim::default();
    probe.particles.push(NewParticle {
        tag: 1,
        kind: 1,
        mask: u32::MAX,
        x: V3::zeros(),
        v: V3::zeros(),
        omega: V3::zeros(),
        radius: 1.0,
        density: 1.0 / Particles::sphere_mass(1.0, 1.0),
    });
    f.post_force(&mut probe, vars)?;
    Ok(probe.particles.f[0] / probe.particles.mass[0])
}

fn parse_pour(s: &mut Session, cmd: &Command, id: &str, group: u32, a: &mut Args, vars: &Variables) -> Result<Pour> {
    s.need_box(cmd)?;
    let illegal = |w: &Word| Error::deck(w.span, "Illegal fix pour command");
    let nw = a.word("number of particles")?;
    let ninsert = parse_i64(nw)?;
    let tw = a.word("atom type")?;
    let kind = parse_i64(tw)?;
    let sw = a.word("seed")?;
    let seed = parse_i64(sw)?;
    if seed <= 0 {
        return Err(illegal(sw));
    }
    let dim = s.sim.domain.as_ref().map_or(s.dimension, |d| d.dimension);
    let mut region: Option<(Region, Span)> = None;
    let mut diam = PourDiam::One(0.5);
    let mut dens = (1.0, 1.0);
    let (mut volfrac, mut maxattempt, mut rate) = (0.25, 50i64, 0.0);
    let mut vel = [0.0; 6];
    let mut idnext = false;
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "region" => {
                let w = a.word("region id")?;
                let r = super::setup::region(s, w).map_err(|_| Error::deck(w.span, "Fix pour region ID does not exist"))?;
                region = Some((r.clone(), w.span));
            }
            "diam" => {
                let st = a.choice("diam style", &["one", "range", "poly"]).map_err(|e| {
                    // 2012-era LAMMPS wrote `diam lo hi`
                    if a.prev().is_some_and(|w| super::args::parse_f64(w).is_ok()) {
                        e.with_hint(
                            "2012-era `diam lo hi` is written `diam range lo hi` in current LAMMPS; `demx convert --to lammps` rewrites old decks",
                        )
                    } else {
                        e
                    }
                })?;
                diam = match st.text.as_str() {
                    "one" => PourDiam::One(0.5 * a.f64("diameter")?),
                    "range" => PourDiam::Range(0.5 * a.f64("diameter lo")?, 0.5 * a.f64("diameter hi")?),
                    _ => {
                        let w = a.word("number of diameters")?;
                        let n = parse_i64(w)?;
                        if n <= 0 {
                            return Err(illegal(w));
                        }
                        let mut v = Vec::new();
                        for _ in 0..n {
                            let d = a.f64("diameter")?;
                            let f = a.f64("fraction")?;
                            if d <= 0.0 || f < 0.0 {
                                return Err(a.err_prev("Illegal fix pour command"));
                            }
                            v.push((0.5 * d, f));
                        }
                        let sum: f64 = v.iter().map(|x| x.1).sum();
                        if (sum - 1.0).abs() > 1e-10 {
                            return Err(Error::deck(st.span, "Fix pour polydisperse fractions do not sum to 1.0"));
                        }
                        PourDiam::Poly(v)
                    }
                };
            }
            "dens" => dens = (a.f64("density lo")?, a.f64("density hi")?),
            "vol" => {
                volfrac = a.f64("volume fraction")?;
                maxattempt = a.i64("max attempts")?;
            }
            "rate" => rate = a.f64("rate")?,
            "vel" => {
                if dim == 3 {
                    vel = [a.f64("vxlo")?, a.f64("vxhi")?, a.f64("vylo")?, a.f64("vyhi")?, 0.0, a.f64("vz")?];
                } else {
                    vel = [a.f64("vxlo")?, a.f64("vxhi")?, 0.0, 0.0, a.f64("vy")?, 0.0];
                }
            }
            "id" => idnext = a.choice("id", &["max", "next"])?.text == "next",
            "ignore" => {}
            "mol" | "molfrac" | "rigid" | "shake" => return Err(Error::unsupported(k.span, format!("fix pour {} (molecules)", k.text))),
            _ => {
                return Err(bad_keyword(
                    k,
                    "fix pour keyword",
                    &["region", "diam", "dens", "vol", "rate", "vel", "id", "ignore", "mol", "molfrac", "rigid", "shake"],
                )
                .with_hint("LAMMPS: Illegal fix pour command"))
            }
        }
    }
    if kind <= 0 || kind as usize > s.sim.ntypes {
        return Err(Error::deck(tw.span, "Invalid atom type in fix pour command"));
    }
    let Some((reg, rspan)) = region else {
        return Err(Error::deck(a.end_span(), "Must specify a region in fix pour"));
    };
    if reg.bbox().is_none() && reg.interior {
        return Err(Error::deck(rspan, "Fix pour region does not support a bounding box"));
    }
    if reg.is_dynamic() {
        return Err(Error::deck(rspan, "Fix pour region cannot be dynamic"));
    }
    let dom = s.sim.domain.as_ref().ok_or_else(|| Error::deck(cmd.span, "fix pour before the box exists"))?;
    let (blo, bhi) = (dom.lo, dom.hi);
    let outside = || Error::deck(rspan, "Insertion region extends outside simulation box");
    let (preg, vlo, vhi) = match &reg.shape {
        Shape::Block { lo, hi } => {
            if (0..3).any(|d| lo[d] < blo[d] || hi[d] > bhi[d]) {
                return Err(outside());
            }
            let (vl, vh) = if dim == 3 { (lo.z, hi.z) } else { (lo.y, hi.y) };
            (PourRegion::Block { x: (lo.x, hi.x), y: (lo.y, hi.y) }, vl, vh)
        }
        Shape::Axisym { axis, c1, c2, rlo, rhi, lo, hi, cone: false } if rlo == rhi => {
            if *axis != 2 {
                return Err(Error::deck(rspan, "Must use a z-axis cylinder region with fix pour"));
            }
            if dim == 2 {
                return Err(Error::deck(rspan, "Must use a block region with fix pour for 2d simulations"));
            }
            if c1 - rlo < blo[0] || c1 + rlo > bhi[0] || c2 - rlo < blo[1] || c2 + rlo > bhi[1] || *lo < blo[2] || *hi > bhi[2] {
                return Err(outside());
            }
            (PourRegion::Cylinder { xc: *c1, yc: *c2, rc: *rlo }, *lo, *hi)
        }
        _ => return Err(Error::deck(rspan, "Must use a block or cylinder region with fix pour")),
    };
    // gravity: exactly as LAMMPS, the first gravity fix defined so far
    let Some(gk) = s.sim.fixes.iter().position(|f| f.style() == "gravity") else {
        return Err(Error::deck(cmd.words[0].span, "No fix gravity defined for fix pour").with_hint("define fix gravity before fix pour"));
    };
    let acc = {
        let mut f = std::mem::replace(&mut s.sim.fixes[gk], Box::new(crate::engine::fix::Hole));
        let r = gravity_of(&mut f, vars);
        s.sim.fixes[gk] = f;
        r?
    };
    let mag = acc.norm();
    let dir = if mag > 0.0 { acc / mag } else { V3::zeros() };
    let want = if dim == 3 { V3::new(0.0, 0.0, -1.0) } else { V3::new(0.0, -1.0, 0.0) };
    if (dir - want).iter().any(|c| c.abs() > 0.001) {
        return Err(Error::deck(
            cmd.words[0].span,
            if dim == 3 { "Gravity must point in -z to use with fix pour in 3d" } else { "Gravity must point in -y to use with fix pour in 2d" },
        ));
    }
    let grav = -mag;
    let (vrel, delta) = if dim == 3 { (vel[5] - rate, vhi - vlo) } else { (vel[4] - rate, vhi - vlo) };
    let t = (-vrel - (vrel * vrel - 2.0 * grav * delta).sqrt()) / grav;
    let dt = s.sim.dt;
    let nfreq = (t / dt + 0.5) as i64;
    let mut p = Pour {
        id: id.to_string(),
        group,
        ninsert,
        kind: kind as u32,
        rng: {
            // LAMMPS warms the generator up with 30 draws before first use
            let mut r = Park::new(seed);
            for _ in 0..30 {
                r.uniform();
            }
            r
        },
        region: preg,
        vlo,
        vhi,
        dim,
        diam,
        dens,
        volfrac,
        maxattempt,
        rate,
        vel,
        idnext,
        maxtag: s.sim.particles.max_tag(),
        grav,
        dt,
        nfreq,
        nper: 0,
        nfirst: s.sim.step + 1,
        next: Some(s.sim.step + 1),
        ninserted: 0,
    };
    let rmax = p.radius_max();
    let (volume, volume_one) = if dim == 3 {
        let v = match p.region {
            PourRegion::Block { x, y } => (x.1 - x.0) * (y.1 - y.0).max(1.0) * (vhi - vlo),
            PourRegion::Cylinder { rc, .. } => PI * rc * rc * (vhi - vlo),
        };
        let one = match &p.diam {
            PourDiam::Poly(v) => v.iter().map(|(r, f)| 4.0 / 3.0 * PI * r * r * r * f).sum(),
            _ => 4.0 / 3.0 * PI * rmax * rmax * rmax,
        };
        (v, one)
    } else {
        let v = match p.region {
            PourRegion::Block { x, .. } => (x.1 - x.0) * (vhi - vlo),
            PourRegion::Cylinder { .. } => 0.0,
        };
        let one = match &p.diam {
            PourDiam::Poly(v) => v.iter().map(|(r, f)| PI * r * r * f).sum(),
            _ => PI * rmax * rmax,
        };
        (v, one)
    };
    p.nper = (volfrac * volume / volume_one) as i64;
    if p.nper <= 0 {
        return Err(Error::deck(cmd.words[0].span, "Fix pour insertion count per timestep is 0")
            .with_hint(format!("vol {volfrac} x region volume {volume} / particle volume {volume_one} < 1")));
    }
    if !nfreq.is_positive() {
        return Err(Error::deck(cmd.words[0].span, format!("fix pour: insertion interval {t} is shorter than the time step")));
    }
    Ok(p)
}

impl Fix for Pour {
    crate::no_step_hooks!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "pour"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        if sim.dt != self.dt {
            return Err(Error::runtime("Cannot change timestep with fix pour"));
        }
        Ok(())
    }
    fn next_reneighbor(&self) -> Option<i64> {
        self.next
    }
    fn pre_exchange(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        if sim.dry || self.next != Some(sim.step) {
            return Ok(());
        }
        if !self.idnext {
            self.maxtag = sim.particles.max_tag();
        }
        let nnew = self.nper.min(self.ninsert - self.ninserted).max(0);
        let shift = (sim.step - self.nfirst) as f64 * sim.dt * self.rate;
        let (lo, hi) = (self.vlo + shift, self.vhi + shift);
        let rmax = self.radius_max();
        let p = &sim.particles;
        let rold = p.radius.iter().copied().fold(0.0, f64::max);
        let mut grid = OverlapGrid::new(rmax + rold.max(rmax), sim.domain.as_ref());
        for i in 0..p.len() {
            grid.add(p.x[i], p.radius[i]);
        }
        let maxiter = nnew * self.maxattempt;
        let mut attempt = 0i64;
        let mut nsuccess = 0i64;
        while nsuccess < nnew {
            let rn = self.rng.uniform();
            let h = hi - rn * rn * (hi - lo);
            let rad = self.radius_sample();
            let mut found = None;
            while attempt < maxiter {
                attempt += 1;
                let c = self.xyz_random(h);
                if !grid.overlaps(c, rad) {
                    found = Some(c);
                    break;
                }
            }
            let Some(c) = found else { break };
            nsuccess += 1;
            grid.add(c, rad);
            let [vxlo, vxhi, vylo, vyhi, vy, vz] = self.vel;
            let v = if self.dim == 3 {
                let vx = vxlo + self.rng.uniform() * (vxhi - vxlo);
                let vyy = vylo + self.rng.uniform() * (vyhi - vylo);
                V3::new(vx, vyy, -(vz * vz + 2.0 * self.grav * (c.z - hi)).sqrt())
            } else {
                let vx = vxlo + self.rng.uniform() * (vxhi - vxlo);
                V3::new(vx, -(vy * vy + 2.0 * self.grav * (c.y - hi)).sqrt(), 0.0)
            };
            let dens = self.dens.0 + self.rng.uniform() * (self.dens.1 - self.dens.0);
            // LAMMPS keeps atoms inside the box or above its top
            let keep = match &sim.domain {
                Some(d) => in_box(d, &c) || (self.dim == 3 && c.z >= d.hi[2]) || (self.dim == 2 && c.y >= d.hi[1]),
                None => true,
            };
            if keep {
                sim.particles.push(NewParticle {
                    tag: self.maxtag + 1,
                    kind: self.kind,
                    mask: 1 | self.group,
                    x: c,
                    v,
                    omega: V3::zeros(),
                    radius: rad,
                    density: dens,
                });
            }
            self.maxtag += 1;
        }
        self.ninserted += nsuccess;
        if nsuccess < nnew {
            sim.log.line("WARNING: Less insertions than requested");
        }
        if nsuccess > 0 {
            sim.force_rebuild = true;
        }
        self.next = if self.ninserted < self.ninsert { Some(sim.step + self.nfreq) } else { None };
        Ok(())
    }
    fn summary(&self) -> String {
        self.describe()
    }
}
