//! Heat conduction between grains in contact: LIGGGHTS 3.8's `fix heat/gran`
//! and `fix heat/gran/conduction` (one model under two names).
//!
//! Each grain has one uniform temperature T (the per-atom property `Temp`).
//! A pair in contact exchanges the heat flux (LIGGGHTS doc
//! fix_heat_gran_conduction, after Chaudhuri et al., Chem. Eng. Sci. 61,
//! 6348 (2006))
//!
//!   Q_ij = h_c (T_j - T_i),  h_c = 4 k_i k_j / (k_i + k_j) sqrt(A),
//!
//! with k the conductivities of the two types and A the contact area: by
//! default the area of the circle where the two spheres' surfaces meet,
//!
//!   A = -pi/4 (r - R_i - R_j)(r + R_i - R_j)(r - R_i + R_j)(r + R_i + R_j) / r^2,
//!
//! or a constant, or pi R_max^2 (`projection`; the engine takes the larger
//! radius, where its doc says the smaller). A type of conductivity below
//! 1e-8 conducts nothing. Each step the fluxes are summed after the forces,
//! from the pair list at the step's positions, and the temperature of each
//! grain of the fix group advances by explicit Euler (the engine's fix
//! transportequation/scalar):
//!
//!   T += (Q + S) dt / (m c),
//!
//! c the type's thermal capacity (no update where |c| <= 1e-8) and S the
//! grain's heat source (`set ... property/atom heatSource`). A pair counts
//! when at least one of its grains is in the group; a grain outside it
//! gains flux but keeps its temperature (so heat flows into or out of the
//! group through it: the thermal energy is not conserved then). The half of each pair's flux
//! times the centre-to-centre vector goes to each grain as
//! `directionalHeatFlux` (both grains get the same sign, as in the engine).
//!
//! The engine's fix has no setup hook: the flux is not summed at the start
//! of a run, so a dump at a run's first step shows the flux of the step
//! before it (zero at the first run).
//!
//! A scene without this fix runs none of it: the conduction is a pass of its
//! own over the pair list, not a term in the contact laws.

use super::fix::Fix;
use super::sim::Sim;
use crate::error::Result;
use crate::script::Variables;

/// Below this a conductivity conducts nothing and a capacity stops the
/// update (LIGGGHTS fix_heat_gran.h `SMALL`).
const SMALL: f64 = 1e-8;

/// The per-atom columns the fix keeps, named as LIGGGHTS names its
/// property/atom fixes (so `f_Temp[0]` and `set ... property/atom Temp`
/// find them).
pub const TEMP: &str = "Temp";
/// Heat flux into each grain this step (W).
pub const FLUX: &str = "heatFlux";
/// Heat source of each grain (W), set by the deck.
pub const SOURCE: &str = "heatSource";
/// Half the flux times the centre vector, summed (3 columns).
pub const DIRECTIONAL: &str = "directionalHeatFlux";

/// How a contact's area is taken (`contact_area`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactArea {
    /// The circle where the two spheres' surfaces meet.
    Overlap,
    /// A given area.
    Constant(f64),
    /// pi times the larger radius squared.
    Projection,
}

/// `fix ID group heat/gran initial_temperature T0 [contact_area ...]`.
pub struct HeatGran {
    /// Fix id (`f_ID` is the thermal energy Σ c m T of all grains).
    pub id: String,
    /// Style as written (`heat/gran` or `heat/gran/conduction`).
    pub style: String,
    /// Group bit.
    pub group: u32,
    /// Contact area rule.
    pub area: ContactArea,
    /// Thermal conductivity per type (index type - 1).
    pub conductivity: Vec<f64>,
    /// Thermal capacity per type (index type - 1).
    pub capacity: Vec<f64>,
    /// Temperature of grains created from now on.
    pub t0: f64,
}

impl HeatGran {
    /// The per-atom columns `[Temp, heatFlux, heatSource,
    /// directionalHeatFlux]`, added where missing (kept when they exist, as
    /// after a restart) with their values for grains created from now on.
    pub fn columns(&self, sim: &mut Sim) -> [usize; 4] {
        let p = &mut sim.particles;
        [p.add_extra(TEMP, vec![self.t0]), p.add_extra(FLUX, vec![0.0]), p.add_extra(SOURCE, vec![0.0]), p.add_extra(DIRECTIONAL, vec![0.0; 3])]
    }

    /// Thermal energy of all grains, Σ c m T (the engine's scalar sums every
    /// grain, in the group or not).
    pub fn energy(&self, sim: &Sim) -> f64 {
        let p = &sim.particles;
        let Some(tc) = p.extra_index(TEMP) else { return 0.0 };
        let t = &p.extra[tc].data;
        (0..p.len()).map(|i| self.capacity[p.kind[i] as usize - 1] * p.mass[i] * t[i]).sum()
    }
}

impl Fix for HeatGran {
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        &self.style
    }
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn summary(&self) -> String {
        format!("fix {} {}: heat conduction between grains in contact ({:?} contact area)", self.id, self.style, self.area)
    }

    /// The engine's init: the fix sums over a granular pair style's list.
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        if sim.model.is_none() {
            return Err(crate::error::Error::runtime(format!("fix {} {} needs a granular pair style", self.id, self.style)));
        }
        Ok(())
    }

    /// The step's fluxes start from zero (sources stay): every grain's,
    /// in the group or not, as Debian's LIGGGHTS 3.8 runs it (a grain
    /// outside the group shows one step's flux, not a running sum;
    /// tests/it/heat_gran.rs).
    fn initial_integrate(&mut self, sim: &mut Sim) {
        let [_, fc, _, dc] = self.columns(sim);
        let p = &mut sim.particles;
        p.extra[fc].data.fill(0.0);
        p.extra[dc].data.fill(0.0);
    }

    /// Sum each contact's flux into both grains.
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        // no setup hook in the engine: nothing at a run's first force pass
        if sim.step == sim.run_start {
            return Ok(());
        }
        let [tc, fc, _, dc] = self.columns(sim);
        let mut flux = std::mem::take(&mut sim.particles.extra[fc].data);
        let mut dir = std::mem::take(&mut sim.particles.extra[dc].data);
        let (p, pairs) = (&sim.particles, &sim.pairs);
        let temp = &p.extra[tc].data;
        for k in 0..pairs.len() {
            let (i, j) = (pairs.a[k] as usize, pairs.b[k] as usize);
            if p.mask[i] & self.group == 0 && p.mask[j] & self.group == 0 {
                continue;
            }
            let d = p.x[i] - (p.x[j] + pairs.shift(k));
            let (ri, rj) = (p.radius[i], p.radius[j]);
            let rsq = d.norm_squared();
            if rsq >= (ri + rj) * (ri + rj) {
                continue;
            }
            let area = match self.area {
                ContactArea::Overlap => {
                    let r = rsq.sqrt();
                    -std::f64::consts::PI / 4.0 * ((r - ri - rj) * (r + ri - rj) * (r - ri + rj) * (r + ri + rj)) / (r * r)
                }
                ContactArea::Constant(a) => a,
                ContactArea::Projection => std::f64::consts::PI * ri.max(rj) * ri.max(rj),
            };
            let (ki, kj) = (self.conductivity[p.kind[i] as usize - 1], self.conductivity[p.kind[j] as usize - 1]);
            let hc = if ki < SMALL || kj < SMALL { 0.0 } else { 4.0 * ki * kj / (ki + kj) * area.sqrt() };
            let q = (temp[j] - temp[i]) * hc;
            flux[i] += q;
            flux[j] -= q;
            for (c, dc) in [d.x, d.y, d.z].into_iter().enumerate() {
                dir[3 * i + c] += 0.5 * (q * dc);
                dir[3 * j + c] += 0.5 * (q * dc);
            }
        }
        sim.particles.extra[fc].data = flux;
        sim.particles.extra[dc].data = dir;
        Ok(())
    }

    /// Explicit Euler on each grain's temperature.
    fn final_integrate(&mut self, sim: &mut Sim) {
        let [tc, fc, sc, _] = self.columns(sim);
        let dt = sim.dt;
        let p = &mut sim.particles;
        let mut temp = std::mem::take(&mut p.extra[tc].data);
        let (flux, source) = (&p.extra[fc].data, &p.extra[sc].data);
        for i in 0..p.len() {
            let c = self.capacity[p.kind[i] as usize - 1];
            if p.mask[i] & self.group != 0 && c.abs() > SMALL {
                temp[i] += (flux[i] + source[i]) * dt / (p.mass[i] * c);
            }
        }
        p.extra[tc].data = temp;
    }

    fn scalar(&self, sim: &Sim) -> Option<f64> {
        Some(self.energy(sim))
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
