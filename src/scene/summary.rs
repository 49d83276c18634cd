//! The scene summary `demx check` prints (and `--json`).

use super::Session;
use serde::Serialize;

/// What a person checks at a glance.
#[derive(Serialize, Debug)]
pub struct Summary {
    /// Dialect.
    pub dialect: String,
    /// Units.
    pub units: String,
    /// Box lo/hi and boundaries.
    pub domain: Option<serde_json::Value>,
    /// Atom types.
    pub ntypes: usize,
    /// Particles at the end of the deck (check mode: created, not inserted).
    pub particles: usize,
    /// Particle sources.
    pub sources: Vec<String>,
    /// Contact model and the effects the scene calls for.
    pub contact: String,
    /// Walls.
    pub walls: Vec<String>,
    /// Fixes.
    pub fixes: Vec<String>,
    /// Runs: steps each.
    pub runs: Vec<i64>,
    /// Total steps.
    pub total_steps: i64,
    /// Time step.
    pub timestep: f64,
    /// Outputs.
    pub outputs: Vec<String>,
    /// Notes on accepted no-op commands.
    pub notes: Vec<String>,
    /// The time step against the Rayleigh and Hertz times.
    pub timestep_check: Option<TimestepCheck>,
    /// Warnings (time step too large, ...).
    pub warnings: Vec<String>,
}

/// Time step criteria as LIGGGHTS `fix check/timestep/gran` computes them,
/// for the stiffest/smallest particle of the scene.
#[derive(Serialize, Debug, Clone)]
pub struct TimestepCheck {
    /// Rayleigh time pi R sqrt(rho/G) / (0.1631 nu + 0.8766).
    pub rayleigh_time: f64,
    /// Hertz collision time 2.87 (m*^2 / (R* E*^2 v))^(1/5) of two equal
    /// spheres at speed `v` (linear spring: pi sqrt(m*/kn)).
    pub hertz_time: f64,
    /// Impact speed used for the Hertz time.
    pub impact_speed: f64,
    /// dt / rayleigh_time.
    pub fraction_rayleigh: f64,
    /// dt / hertz_time.
    pub fraction_hertz: f64,
    /// Radius (m) and density of the particle that sets the criteria.
    pub particle: (f64, f64),
}

/// demx warns when the time step is above this fraction of the Rayleigh or
/// the Hertz time (LIGGGHTS tutorials use 0.1-0.2; above 0.2 restitution and
/// overlaps degrade quickly).
pub const TIMESTEP_WARN_FRACTION: f64 = 0.2;

/// demx warns when the time step is above this fraction of the Hertz time:
/// the heap template's angle of repose was measured
/// unchanged up to it and shifted above it (VALIDATION.md, "Heap: angle of
/// repose vs stiffness and time step": 0.1 within 0.5 deg of 0.05, 0.2 1.4
/// deg low, 0.3 stopped 2 of 3 runs; 3 seeds each, N = 2000, model stock).
pub const THETA_TIMESTEP_FRACTION: f64 = 0.1;

/// What the heap tradeoff measured above [`THETA_TIMESTEP_FRACTION`].
pub const THETA_TIMESTEP_EFFECT: &str = "on the heap template, dt = 0.2 of the Hertz time gave an angle of repose 1.4 deg \
     lower than 0.05 (15.86 against 17.27 deg, 3 seeds each) and 0.3 stopped 2 of 3 runs, while 0.1 stayed within 0.5 deg \
     (VALIDATION.md, 'Heap: angle of repose vs stiffness and time step')";

/// The lowest Young's modulus (Pa) at which demx's cohesive heaps were
/// measured to agree with the paper: its own 63 GPa. Every softer value
/// measured moved the angle of repose by tens of degrees, so there is no
/// safe softened range to allow (VALIDATION.md, "Cohesive heap: softened
/// stiffness and the surface energy" and "contact-force or net-force caps").
pub const COHESIVE_SAFE_YOUNGS: f64 = 6.3e10;

/// What softening a cohesive contact was measured to do.
pub const COHESIVE_SOFT_EFFECT: &str = "softening a cohesive contact below 63 GPa changed the heap's angle of repose by \
     tens of degrees: 400 um glass with van der Waals stood at 73.1, 74.0 and 52.6 deg at Y = 1e7, 1e8 and 1e9 Pa against \
     24.6 deg at 63 GPa (paper Eq. 1: 28.6 deg), 200 um at 43-86 deg against 22-23 deg (VALIDATION.md, 'Cohesive heap: \
     softened stiffness and the surface energy' and 'contact-force or net-force caps'): the energy that holds a contact \
     grows as Y^(-2/3). Run cohesive decks at the material's own modulus";

/// Young's modulus and Poisson ratio of type `t` as the contact model sees
/// them (after `demx run --youngs-scale`); None where the model has none.
fn youngs_of_type(s: &Session, t: u32) -> Option<(f64, f64)> {
    use crate::scene::model::NormalSpec;
    let spec = s.pair.as_ref()?;
    let per_type = |name: &str, t: u32| s.props.get(name).and_then(|(_, v)| v.get(t as usize - 1).copied());
    let (y, nu) = match spec.normal {
        NormalSpec::LigHertz | NormalSpec::LigHooke { .. } | NormalSpec::PaperViscoelastic => {
            (per_type("youngsModulus", t)?, per_type("poissonsRatio", t)?)
        }
        NormalSpec::Granular(..) | NormalSpec::GranularCohesive(..) => {
            let pp = spec.granular.iter().find(|(i, j, _)| *i == t && *j == t).map(|x| x.2)?;
            if pp.poisson > 0.0 {
                // y_eff = E / (2 (1 - nu^2)) for identical materials
                (pp.y_eff * 2.0 * (1.0 - pp.poisson * pp.poisson), pp.poisson)
            } else {
                return None;
            }
        }
        _ => return None,
    };
    Some((y / s.overrides.stiffness_divisor(), nu))
}

/// The cohesion law a scene runs, when some pair of types has a non-zero
/// surface energy or cohesion energy density: its name and the softest
/// Young's modulus (Pa) among the cohesive types.
fn cohesive_youngs(s: &Session) -> Option<(String, f64)> {
    use crate::scene::model::{CohesionSpec, CohesiveNormal, NormalSpec};
    let spec = s.pair.as_ref()?;
    let name = match (spec.normal, &spec.cohesion) {
        (NormalSpec::GranularCohesive(CohesiveNormal::Jkr, _), _) => "jkr",
        (NormalSpec::GranularCohesive(CohesiveNormal::Dmt, _), _) => "dmt",
        (_, CohesionSpec::Vdw { .. }) => "van der Waals (cohesion vdw)",
        (_, CohesionSpec::Sjkr { .. }) => "sjkr",
        (_, CohesionSpec::Sjkr2 { .. }) => "sjkr2",
        _ => return None,
    };
    let table = &s.sim.model.as_ref()?.table;
    let mut y_min: Option<f64> = None;
    for i in 1..=table.ntypes as u32 {
        for j in 1..=table.ntypes as u32 {
            if table.get(i, j).cohesion > 0.0 {
                for t in [i, j] {
                    if let Some((y, _)) = youngs_of_type(s, t) {
                        y_min = Some(y_min.map_or(y, |m: f64| m.min(y)));
                    }
                }
            }
        }
    }
    y_min.map(|y| (name.to_string(), y))
}

/// Warnings where the physics is known to break, with the measured size of
/// the effect and where it was measured: a cohesive model with a softened
/// Young's modulus, a time step above the fraction that shifted the heap's
/// angle of repose. `demx check` lists them; `demx run` prints them before
/// the first run, on screen and in the log.
pub fn physics_warnings(s: &Session) -> Vec<String> {
    let mut w = vec![];
    if let Some((name, y)) = cohesive_youngs(s) {
        if y < COHESIVE_SAFE_YOUNGS * (1.0 - 1e-9) {
            w.push(format!(
                "cohesion {name} runs with a Young's modulus of {y:e} Pa, below {COHESIVE_SAFE_YOUNGS:e} Pa, the softest \
                 modulus at which demx's cohesive heaps were measured to agree with the paper: {COHESIVE_SOFT_EFFECT}"
            ));
        }
    }
    if let Some(t) = timestep_check(s) {
        // measured as a fraction of the Hertz time (the deck's dtfrac)
        if t.fraction_hertz > THETA_TIMESTEP_FRACTION {
            w.push(format!(
                "time step {:e} s is {:.0}% of the Hertz time ({:.0}% of the Rayleigh time), above the {:.0}% up to which \
                 a heap's angle of repose was measured unchanged: {THETA_TIMESTEP_EFFECT}",
                s.sim.dt,
                100.0 * t.fraction_hertz,
                100.0 * t.fraction_rayleigh,
                100.0 * THETA_TIMESTEP_FRACTION
            ));
        }
    }
    w
}

/// The particle sizes and densities the scene holds or will insert, by type.
fn particle_kinds(s: &Session) -> Vec<(u32, f64, f64)> {
    let mut out = vec![];
    let p = &s.sim.particles;
    for i in 0..p.len() {
        if !out.iter().any(|&(t, r, _)| t == p.kind[i] && r <= p.radius[i]) {
            out.retain(|&(t, _, _)| t != p.kind[i]);
            out.push((p.kind[i], p.radius[i], p.density[i]));
        }
    }
    for f in &s.sim.fixes {
        if let Some(t) = f.as_any().and_then(|a| a.downcast_ref::<crate::scene::insert::Template>()) {
            out.push((t.kind, t.radius, t.density));
        }
    }
    out
}

/// Compute the time step criteria of a scene, if it has a contact model and
/// particles (present or to be inserted).
pub fn timestep_check(s: &Session) -> Option<TimestepCheck> {
    use crate::scene::model::NormalSpec;
    let spec = s.pair.as_ref()?;
    let kinds = particle_kinds(s);
    if kinds.is_empty() {
        return None;
    }
    let dt = s.sim.dt;
    // impact speed: the fastest particle, or free fall over the box height
    let vmax = s.sim.particles.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let g = s
        .sim
        .fixes
        .iter()
        .filter_map(|f| f.as_any().and_then(|a| a.downcast_ref::<crate::scene::fixes::Gravity>()))
        .map(|g| g.acc.norm())
        .fold(0.0, f64::max);
    let h = s.sim.domain.as_ref().map_or(0.0, |d| d.len(2));
    let v = vmax.max((2.0 * g * h).sqrt()).max(1e-3);
    let mut best: Option<TimestepCheck> = None;
    for (t, r, rho) in kinds {
        let (y, nu) = match spec.normal {
            NormalSpec::LigHertz | NormalSpec::LigHooke { .. } | NormalSpec::PaperViscoelastic => youngs_of_type(s, t)?,
            NormalSpec::Granular(..) | NormalSpec::GranularCohesive(..) => youngs_of_type(s, t).unwrap_or((0.0, 0.0)),
            NormalSpec::GranHertz => {
                // Kn = 4/3 E* with E* = Y / (2 (1 - nu^2)); take nu = 0.3
                let kn = spec.gran.map(|g| g[0])?;
                // demx run --youngs-scale divides every stiffness
                (0.75 * kn * 2.0 * (1.0 - 0.09) / s.overrides.stiffness_divisor(), 0.3)
            }
            _ => (0.0, 0.0),
        };
        let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * rho;
        let m_eff = 0.5 * m;
        let (tr, th) = if y > 0.0 {
            let gmod = y / (2.0 * (1.0 + nu));
            let tr = std::f64::consts::PI * r * (rho / gmod).sqrt() / (0.1631 * nu + 0.8766);
            let e_eff = y / (2.0 * (1.0 - nu * nu));
            let r_eff = 0.5 * r;
            let th = 2.87 * (m_eff * m_eff / (r_eff * e_eff * e_eff * v)).powf(0.2);
            (tr, th)
        } else {
            // linear spring: contact time pi sqrt(m*/kn) (undamped)
            let kn = match spec.normal {
                NormalSpec::GranHooke => spec.gran.map(|g| g[0]).unwrap_or(0.0),
                _ => s.props.get("kn").and_then(|(_, v)| v.get(1).copied()).unwrap_or(0.0),
            };
            let kn = kn / s.overrides.stiffness_divisor();
            if kn <= 0.0 {
                continue;
            }
            let tc = std::f64::consts::PI * (m_eff / kn).sqrt();
            (tc, tc)
        };
        let c = TimestepCheck {
            rayleigh_time: tr,
            hertz_time: th,
            impact_speed: v,
            fraction_rayleigh: dt / tr,
            fraction_hertz: dt / th,
            particle: (r, rho),
        };
        if best.as_ref().is_none_or(|b| c.fraction_rayleigh.max(c.fraction_hertz) > b.fraction_rayleigh.max(b.fraction_hertz)) {
            best = Some(c);
        }
    }
    best
}

impl Summary {
    /// Collect from a session after the deck ran in check mode.
    pub fn of(s: &Session) -> Summary {
        let domain =
            s.sim.domain.as_ref().map(|d| serde_json::json!({"lo": d.lo, "hi": d.hi, "boundary": d.boundary_strings(), "dimension": d.dimension}));
        let contact = match &s.pair {
            Some(p) => p.summary() + "; wind: none",
            None => "none (no pair_style)".to_string(),
        };
        let mut outputs = vec![format!("thermo every {} ({})", s.sim.thermo.every, s.sim.thermo.keywords.join(" "))];
        outputs.extend(s.sim.dumps.iter().map(|d| d.summary()));
        Summary {
            dialect: format!("{:?}", s.sim.dialect).to_lowercase(),
            units: format!("{:?}", s.units).to_lowercase(),
            domain,
            ntypes: s.sim.ntypes,
            particles: s.sim.particles.len(),
            sources: s.sources.clone(),
            contact,
            walls: s.walls.clone(),
            fixes: s.sim.fixes.iter().map(|f| f.summary()).collect(),
            runs: s.schedule.iter().map(|r| r.steps).collect(),
            total_steps: s.schedule.iter().map(|r| r.steps).sum(),
            timestep: s.sim.dt,
            outputs,
            notes: s.notes.iter().map(|(_, n)| n.clone()).collect(),
            timestep_check: timestep_check(s),
            warnings: vec![],
        }
        .with_warnings(physics_warnings(s))
    }

    fn with_warnings(mut self, physics: Vec<String>) -> Summary {
        if let Some(t) = &self.timestep_check {
            if t.fraction_rayleigh > TIMESTEP_WARN_FRACTION || t.fraction_hertz > TIMESTEP_WARN_FRACTION {
                self.warnings.push(format!(
                    "time step {} is {:.0}% of the Rayleigh time and {:.0}% of the Hertz time (warning above {:.0}%): contacts may be resolved badly",
                    self.timestep,
                    100.0 * t.fraction_rayleigh,
                    100.0 * t.fraction_hertz,
                    100.0 * TIMESTEP_WARN_FRACTION
                ));
            }
        }
        self.warnings.extend(physics);
        if self.contact.contains("viscoelastic") || self.contact.contains("vdw") || self.contact.contains("paper") {
            self.notes.push("this deck uses demx-only contact models (the paper's): it runs in demx only".into());
        }
        self
    }
    /// Human-readable text.
    pub fn render(&self) -> String {
        let mut o = String::new();
        o.push_str(&format!("dialect: {}   units: {}\n", self.dialect, self.units));
        if let Some(d) = &self.domain {
            o.push_str(&format!("box: {} to {}, boundary {}\n", d["lo"], d["hi"], d["boundary"]));
        } else {
            o.push_str("box: none\n");
        }
        o.push_str(&format!("atom types: {}   particles: {}\n", self.ntypes, self.particles));
        for src in &self.sources {
            o.push_str(&format!("source: {src}\n"));
        }
        o.push_str(&format!("contact: {}\n", self.contact));
        for w in &self.walls {
            o.push_str(&format!("wall: {w}\n"));
        }
        for f in &self.fixes {
            o.push_str(&format!("fix: {f}\n"));
        }
        o.push_str(&format!("timestep: {}   runs: {:?} ({} steps)\n", self.timestep, self.runs, self.total_steps));
        if let Some(t) = &self.timestep_check {
            o.push_str(&format!(
                "timestep check: {:.1}% of Rayleigh time {:.3e} s, {:.1}% of Hertz time {:.3e} s (impact speed {:.3} m/s; radius {:.3e}, density {})\n",
                100.0 * t.fraction_rayleigh,
                t.rayleigh_time,
                100.0 * t.fraction_hertz,
                t.hertz_time,
                t.impact_speed,
                t.particle.0,
                t.particle.1
            ));
        }
        for w in &self.warnings {
            o.push_str(&format!("warning: {w}\n"));
        }
        for out in &self.outputs {
            o.push_str(&format!("output: {out}\n"));
        }
        for n in &self.notes {
            o.push_str(&format!("note: {n}\n"));
        }
        o
    }
}
