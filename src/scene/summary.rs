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
}

impl Summary {
    /// Collect from a session after the deck ran in check mode.
    pub fn of(s: &Session) -> Summary {
        let domain = s.sim.domain.as_ref().map(|d| serde_json::json!({"lo": d.lo, "hi": d.hi, "boundary": d.boundary_strings(), "dimension": d.dimension}));
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
        }
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
        for out in &self.outputs {
            o.push_str(&format!("output: {out}\n"));
        }
        for n in &self.notes {
            o.push_str(&format!("note: {n}\n"));
        }
        o
    }
}
