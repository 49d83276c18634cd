//! `fix wall/gran` with primitive shapes, in both dialects. The wall runs the
//! same laws as particle pairs (its own kernel, chosen once), with the wall as
//! a partner of infinite mass and radius; per-particle contact history lives
//! in a per-atom column so it follows particles through reordering.

use super::args::Args;
use super::model::{self, NormalSpec, PairSpec, TangentialSpec};
use super::Session;
use crate::engine::fix::{Chunk, Fix, Hook, Local, Stage};
use crate::engine::integrate::CHUNK;
use crate::engine::kernel::{ContactKernel, ParamTable};
use crate::engine::sim::{Dialect, Sim};
use crate::error::{Error, Result};
use crate::geom::{PrimitiveWall, WallMotion};
use crate::physics::lanes::LANES;
use crate::physics::normal::granular::{GranularDamping, GranularNormal};
use crate::physics::normal::jkr::jkr_pulloff_overlap;
use crate::physics::{Contact, ContactOut, PairParams, V3};
use crate::script::{Command, Variables, Word};
use rayon::prelude::*;
use std::sync::Arc;

/// What the wall's contact with one particle needs of the wall: shared by
/// the fix and the stage it hands to the step's fused tail.
#[derive(Clone)]
struct WallLaws {
    group: u32,
    wall: PrimitiveWall,
    kernel: Arc<dyn ContactKernel>,
    table: Arc<ParamTable>,
    /// Wall type (LIGGGHTS `primitive type T`); LAMMPS walls use row 1.
    wall_type: u32,
    width: usize,
    /// LAMMPS `zcylinder` radius: R* includes the wall's curvature.
    cyl_radius: Option<f64>,
    /// JKR normal law: contacts last beyond touching.
    jkr: bool,
}

/// Where the wall is at this step and how far history advances.
#[derive(Clone, Copy)]
struct WallFrame {
    shift: f64,
    vwall: V3,
    dt: f64,
}

/// One particle as the wall's contact reads it.
struct Sphere {
    x: V3,
    v: V3,
    omega: V3,
    radius: f64,
    mass: f64,
    kind: u32,
    mask: u32,
}

/// What the wall finds for one particle.
enum Meet<'t> {
    /// No contact (history cleared); whether within reach + margin.
    Apart(bool),
    /// A contact for the laws, with its coefficients.
    Touch(Contact, &'t PairParams),
}

/// Contacts of one chunk waiting to run as one batch: chunk positions,
/// contacts and coefficients, `n` of them.
struct Batch<'t> {
    q: [usize; LANES],
    c: [Contact; LANES],
    pp: [&'t PairParams; LANES],
    n: usize,
}

impl WallLaws {
    /// The wall's contact with particle `s`: clears `hist` when apart.
    #[inline(always)]
    fn meet(&self, fr: &WallFrame, s: &Sphere, hist: &mut [f64], margin: Option<f64>) -> Meet<'_> {
        if s.mask & self.group == 0 {
            return Meet::Apart(false);
        }
        let ri = s.radius;
        let pp = self.table.get(s.kind, self.wall_type);
        // a JKR contact lives on to the pull-off overlap (< 0): look that
        // far; LAMMPS's zcylinder finds no contact once the sphere is
        // off the wall (its `delr > radius` test)
        let reach = if self.jkr && self.cyl_radius.is_none() { -jkr_pulloff_overlap(ri, pp.y_eff, pp.cohesion) } else { 0.0 };
        let near = margin.is_some_and(|m| self.wall.contact(s.x, ri + reach + m, fr.shift).is_some());
        let Some((delta, n, _pt)) = self.wall.contact(s.x, ri + reach, fr.shift) else {
            clear(hist);
            return Meet::Apart(near);
        };
        let delta = delta - reach;
        if delta <= 0.0 && !self.jkr {
            clear(hist);
            return Meet::Apart(near);
        }
        // LAMMPS zcylinder: the wall's curvature enters R* through
        // rwall = -2 R_c (met from inside) or +2 R_c (outside)
        let r_eff = match self.cyl_radius {
            Some(rc) => {
                let rho = (s.x.x * s.x.x + s.x.y * s.x.y).sqrt();
                let rwall = if rho < rc { -2.0 * rc } else { 2.0 * rc };
                ri * rwall / (ri + rwall)
            }
            None => ri,
        };
        let mi = s.mass;
        let vr = s.v - fr.vwall;
        Meet::Touch(Contact::with_wall(n, ri - delta, delta, ri, r_eff, mi, vr, s.omega, fr.dt), pp)
    }

    /// The wall's contacts with the particles at chunk positions `qs`
    /// (increasing; `sphere(q)` reads one), adding to the chunk's forces
    /// `f`, torques `t` and history rows `h`. Contacts are gathered into
    /// batches of [`LANES`] for the kernel ([`ContactKernel::wall_contacts`]);
    /// each particle meets the wall once, so its sums are those of one
    /// contact at a time. With `margin`, `near(q)` hears of every particle
    /// within reach + margin of the wall.
    #[allow(clippy::too_many_arguments)]
    fn touch_chunk(
        &self,
        fr: &WallFrame,
        qs: impl Iterator<Item = usize>,
        sphere: impl Fn(usize) -> Sphere,
        f: &mut [V3],
        t: &mut [V3],
        h: &mut [f64],
        margin: Option<f64>,
        mut near: impl FnMut(usize),
    ) {
        let wc = self.width.max(1);
        let mut scratch = vec![0.0; LANES * self.width];
        let z = Contact {
            n: V3::zeros(),
            r: 0.0,
            delta: 0.0,
            ri: 0.0,
            rj: 0.0,
            r_eff: 0.0,
            mi: 0.0,
            mj: 0.0,
            m_eff: 0.0,
            vr: V3::zeros(),
            vn: 0.0,
            wi: V3::zeros(),
            wj: V3::zeros(),
            dt: 0.0,
        };
        let p0 = self.table.get(1, self.wall_type);
        let mut b = Batch { q: [0; LANES], c: [z; LANES], pp: [p0; LANES], n: 0 };
        for q in qs {
            match self.meet(fr, &sphere(q), &mut h[q * wc..(q + 1) * wc], margin) {
                Meet::Apart(true) => near(q),
                Meet::Apart(false) => {}
                Meet::Touch(c, pp) => {
                    near(q);
                    (b.q[b.n], b.c[b.n], b.pp[b.n]) = (q, c, pp);
                    b.n += 1;
                    if b.n == LANES {
                        self.run(&mut b, &mut scratch, f, t, h);
                    }
                }
            }
        }
        if b.n > 0 {
            self.run(&mut b, &mut scratch, f, t, h);
        }
    }

    /// Run batch `b` and empty it.
    fn run(&self, b: &mut Batch<'_>, scratch: &mut [f64], f: &mut [V3], t: &mut [V3], h: &mut [f64]) {
        let (w, wc, n) = (self.width, self.width.max(1), b.n);
        for k in 0..n {
            scratch[k * w..(k + 1) * w].copy_from_slice(&h[b.q[k] * wc..b.q[k] * wc + w]);
        }
        let mut out = [ContactOut::default(); LANES];
        self.kernel.wall_contacts(&b.c[..n], &b.pp[..n], &mut scratch[..n * w], &mut out[..n]);
        for k in 0..n {
            let q = b.q[k];
            h[q * wc..q * wc + w].copy_from_slice(&scratch[k * w..(k + 1) * w]);
            f[q] += out[k].force_i(&b.c[k]);
            t[q] += out[k].torque_i;
        }
        b.n = 0;
    }
}

/// The wall's post_force in the step's fused tail: its candidates that fall
/// in each chunk (see `WallGran::post_force`).
struct WallStage {
    laws: WallLaws,
    frame: WallFrame,
    candidates: Arc<Vec<u32>>,
    /// The history column.
    col: usize,
}

impl Stage for WallStage {
    fn apply(&self, c: &mut Chunk<'_>) {
        let Chunk { lo, x, v, omega, radius, mass, kind, mask, f, torque, extra, .. } = c;
        let (lo, hi) = (*lo as u32, (*lo + f.len()) as u32);
        let cands = &self.candidates[self.candidates.partition_point(|&i| i < lo)..];
        let qs = cands.iter().take_while(|&&i| i < hi).map(|&i| (i - lo) as usize);
        let sphere = |q: usize| {
            let i = lo as usize + q;
            Sphere { x: x[q], v: v[q], omega: omega[q], radius: radius[i], mass: mass[i], kind: kind[i], mask: mask[i] }
        };
        self.laws.touch_chunk(&self.frame, qs, sphere, f, torque, &mut *extra[self.col], None, |_| {});
    }
}

/// A granular wall of primitive shape.
pub struct WallGran {
    id: String,
    laws: WallLaws,
    motion: WallMotion,
    hist_name: String,
    summary: String,
    /// Time the wall motion started.
    t0: f64,
    /// Particles within reach + skin of the wall at pair-list build
    /// `candidates_at`, in increasing index (see `post_force`).
    candidates: Arc<Vec<u32>>,
    candidates_at: Option<u64>,
}

/// Zero a history that is not already zero (bit for bit), so that the many
/// particles away from the wall only read theirs.
#[inline(always)]
fn clear(hist: &mut [f64]) {
    if hist.iter().any(|h| h.to_bits() != 0) {
        hist.fill(0.0);
    }
}

impl WallGran {
    /// The wall at this step; consumes the setup flag.
    fn frame(&mut self, sim: &Sim) -> WallFrame {
        let t = sim.time - self.t0;
        let shift = self.motion.shift(self.laws.wall.axis(), t);
        let vwall = self.motion.velocity(t);
        let dt = if sim.setup_pass { 0.0 } else { sim.dt };
        WallFrame { shift, vwall, dt }
    }

    /// Between pair-list builds no particle moves more than half the skin
    /// when every step checks for a build (delay 0, every 1, check yes):
    /// then a static wall needs only the particles within reach + skin of it
    /// at the last build, and the others have no contact and zero history.
    /// Otherwise (moving wall, delayed checks) every particle is tried every
    /// step. Whether the list is bounded so, and whether the candidates are
    /// those of the current build.
    fn bounded(&self, sim: &Sim) -> (bool, bool) {
        let ns = &sim.neigh;
        let built = sim.pairs.x_built.len() == sim.particles.len();
        let bounded = built && matches!(self.motion, WallMotion::None) && ns.check && ns.delay == 0 && ns.every <= 1;
        (bounded, bounded && self.candidates_at == Some(sim.pairs.builds))
    }
}

impl Fix for WallGran {
    // the candidates are a cache of the last build: rebuilt, they give the same bits
    crate::stateless_fix!();
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "wall/gran"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        sim.particles.add_extra(&self.hist_name, vec![0.0; self.laws.width.max(1)]);
        Ok(())
    }
    fn local(&mut self, hook: Hook, sim: &Sim, _vars: &Variables) -> Result<Local> {
        if hook != Hook::PostForce {
            return Ok(Local::Nothing);
        }
        let (Some(col), (_, true)) = (sim.particles.extra_index(&self.hist_name), self.bounded(sim)) else {
            return Ok(Local::Whole);
        };
        let frame = self.frame(sim);
        Ok(Local::Stage(Box::new(WallStage { laws: self.laws.clone(), frame, candidates: self.candidates.clone(), col })))
    }
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        let col = sim.particles.add_extra(&self.hist_name, vec![0.0; self.laws.width.max(1)]);
        let fr = self.frame(sim);
        let (bounded, reuse) = self.bounded(sim);
        let build = sim.pairs.builds;
        let margin = bounded.then_some(sim.neigh.skin);
        let laws = &self.laws;
        let w = laws.width.max(1);
        let crate::engine::particles::Particles { x, v, omega, f, torque, radius, mass, kind, mask, extra, .. } = &mut sim.particles;
        let (x, v, omega, radius, mass, kind, mask) = (&*x, &*v, &*omega, &*radius, &*mass, &*kind, &*mask);
        let data = &mut extra[col].data;
        let sphere = |i: usize| Sphere { x: x[i], v: v[i], omega: omega[i], radius: radius[i], mass: mass[i], kind: kind[i], mask: mask[i] };
        if reuse {
            // the candidates in fixed chunks, each with the slices of the
            // particles from its first candidate to the next chunk's
            let cands = &self.candidates;
            let n = f.len();
            let cuts: Vec<usize> = (0..cands.len().div_ceil(CHUNK)).map(|c| cands[c * CHUNK] as usize).chain([n]).collect();
            let mut jobs = Vec::with_capacity(cuts.len());
            let (mut fr_, mut tr, mut hr) = (&mut f[cuts[0]..], &mut torque[cuts[0]..], &mut data[cuts[0] * w..]);
            for (c, win) in cuts.windows(2).enumerate() {
                let len = win[1] - win[0];
                let (fc, fnext) = std::mem::take(&mut fr_).split_at_mut(len);
                let (tc, tnext) = std::mem::take(&mut tr).split_at_mut(len);
                let (hc, hnext) = std::mem::take(&mut hr).split_at_mut(len * w);
                (fr_, tr, hr) = (fnext, tnext, hnext);
                jobs.push((&cands[c * CHUNK..((c + 1) * CHUNK).min(cands.len())], win[0], fc, tc, hc));
            }
            let run = |(cs, lo, fc, tc, hc): (&[u32], usize, &mut [V3], &mut [V3], &mut [f64])| {
                laws.touch_chunk(&fr, cs.iter().map(|&i| i as usize - lo), |q| sphere(lo + q), fc, tc, hc, None, |_| {});
            };
            if jobs.len() > 1 {
                jobs.into_par_iter().for_each(run);
            } else {
                jobs.into_iter().for_each(run);
            }
            return Ok(());
        }
        // every particle, in fixed chunks, in parallel from two chunks up:
        // each particle touches only its own force, torque and history, so
        // the bits do not depend on the thread count
        let body = |(c, ((fc, tc), hc)): (usize, ((&mut [V3], &mut [V3]), &mut [f64]))| -> Vec<u32> {
            let mut near = vec![];
            let lo = c * CHUNK;
            laws.touch_chunk(&fr, 0..fc.len(), |q| sphere(lo + q), fc, tc, hc, margin, |q| near.push((lo + q) as u32));
            near
        };
        let near: Vec<Vec<u32>> = if f.len() >= 2 * CHUNK {
            f.par_chunks_mut(CHUNK).zip(torque.par_chunks_mut(CHUNK)).zip(data.par_chunks_mut(CHUNK * w)).enumerate().map(body).collect()
        } else {
            f.chunks_mut(CHUNK).zip(torque.chunks_mut(CHUNK)).zip(data.chunks_mut(CHUNK * w)).enumerate().map(body).collect()
        };
        if bounded {
            self.candidates = Arc::new(near.concat());
            self.candidates_at = Some(build);
        } else {
            self.candidates_at = None;
        }
        Ok(())
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
    fn max_surface_overlap(&self, sim: &Sim) -> Option<(usize, f64)> {
        crate::engine::fix::deepest_overlap(sim, self.laws.group, |i| self.surface_overlap(sim, i))
    }
    fn surface_overlap(&self, sim: &Sim, i: usize) -> Option<f64> {
        let shift = self.motion.shift(self.laws.wall.axis(), sim.time - self.t0);
        let p = &sim.particles;
        self.laws.wall.contact(p.x[i], p.radius[i], shift).map(|c| c.0).filter(|d| *d > 0.0)
    }
}

/// The LAMMPS wall geometry (`zplane lo hi`, `zcylinder r`, wiggle/shear)
/// and the keywords after it.
fn lammps_wall_geometry(cmd: &Command, a: &mut Args) -> Result<(PrimitiveWall, WallMotion)> {
    let words = a.rest().to_vec();
    let (wall, motion, used) = PrimitiveWall::parse_lammps(cmd, &words)?;
    a.pos += used;
    while a.more() {
        let k = a.word("keyword")?;
        if k.text == "contacts" {
            continue;
        }
        return Err(Error::deck(k.span, format!("fix wall/gran: unknown keyword '{}'", k.text)));
    }
    Ok((wall, motion))
}

/// Parse `fix ID group wall/gran ...` in either dialect.
pub fn wall_gran(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    let first = a.word("wall model")?;
    let rest_after = |a: &Args| a.rest().to_vec();
    let (spec, table, wall_type, wall, motion) = if first.text == "model" {
        s.set_dialect(Dialect::Liggghts);
        a.pos -= 1;
        let mut spec = PairSpec::new(cmd.span, true);
        // the model block ends at `primitive` or `mesh`
        let words = rest_after(a);
        let end = words
            .iter()
            .position(|w| w.text == "primitive" || w.text == "mesh")
            .ok_or_else(|| Error::deck(a.end_span(), "fix wall/gran: missing `primitive type T <shape>` or `mesh n_meshes N meshes ...`"))?;
        let model_cmd = Command { words: std::iter::once(cmd.words[0].clone()).chain(words[..end].iter().cloned()).collect(), span: cmd.span };
        let mut ma = Args::new(&model_cmd);
        model::parse_liggghts_model(&mut ma, &mut spec)?;
        a.pos += end;
        let kind = a.word("primitive or mesh")?;
        if kind.text == "mesh" {
            return Err(Error::unsupported(kind.span, "fix wall/gran ... mesh (triangle-mesh walls)"));
        }
        a.choice("keyword", &["type"])?;
        let wt = a.i64("wall type")?;
        if wt < 1 || wt as usize > s.sim.ntypes {
            return Err(a.err_prev(format!("wall type {wt} out of range 1..{}", s.sim.ntypes)));
        }
        let words = a.rest().to_vec();
        let (wall, used) = PrimitiveWall::parse_liggghts(cmd, &words)?;
        a.pos += used;
        while a.more() {
            let k = a.word("keyword")?;
            match k.text.as_str() {
                // LIGGGHTS 3.8 takes model keywords after the geometry too
                _ if model::model_keyword(k, a, &mut spec)? => {}
                "shear" | "store_force" | "store_force_contact" | "temperature" | "track_energy" | "contact_area" => {
                    return Err(Error::unsupported(k.span, format!("fix wall/gran keyword {}", k.text)))
                }
                _ => return Err(Error::deck(k.span, format!("fix wall/gran: unknown keyword '{}'", k.text))),
            }
        }
        let table = model::fill_table(s, &spec, cmd.span)?;
        spec.has_coeff = true;
        (spec, table, wt as u32, wall, WallMotion::None)
    } else {
        s.set_dialect(Dialect::Lammps);
        let mut spec = PairSpec::new(cmd.span, true);
        // 2012-era LAMMPS: `fix wall/gran Kn Kt gn gt xmu dampflag wallstyle ...`
        // takes its force style from the pair style.
        let legacy = super::args::parse_f64(first).is_ok();
        let style_name: String = if legacy {
            a.pos -= 1;
            match s.pair.as_ref().map(|p| p.normal) {
                Some(NormalSpec::GranHertz) => "hertz/history".into(),
                Some(NormalSpec::GranHooke) if s.pair.as_ref().map(|p| p.tangential) == Some(TangentialSpec::GranNoHistory) => "hooke".into(),
                Some(NormalSpec::GranHooke) => "hooke/history".into(),
                _ => {
                    return Err(Error::deck(first.span, "fix wall/gran without a force style needs a gran/* pair style defined first")
                        .with_hint("write the style explicitly, e.g. `fix ID all wall/gran hooke/history Kn Kt gn gt xmu dampflag zplane lo hi`"))
                }
            }
        } else {
            first.text.clone()
        };
        match style_name.as_str() {
            "hooke" | "hooke/history" | "hertz/history" => {
                let kn = a.f64("Kn")?;
                let ktw = a.word("Kt")?;
                let gn = a.f64("gamma_n")?;
                let gtw = a.word("gamma_t")?;
                let xmu = a.f64("xmu")?;
                let damp = a.i64("dampflag")?;
                let kt = if ktw.text == "NULL" { 2.0 / 7.0 * kn } else { super::args::parse_f64(ktw)? };
                let gt = if gtw.text == "NULL" { 0.5 * gn } else { super::args::parse_f64(gtw)? };
                if a.peek().map(|w| w.text == "limit_damping").unwrap_or(false) {
                    a.pos += 1;
                    spec.limit_damping = true;
                }
                spec.gran = Some([kn, kt, gn, if damp == 0 { 0.0 } else { gt }, xmu]);
                spec.tangential_damping = damp == 1;
                spec.normal = if style_name == "hertz/history" { NormalSpec::GranHertz } else { NormalSpec::GranHooke };
                spec.tangential = if style_name == "hooke" { TangentialSpec::GranNoHistory } else { TangentialSpec::GranHistory };
            }
            "granular" => {
                let (gspec, table) = granular_coeffs(s, cmd, a, first)?;
                let (wall, motion) = lammps_wall_geometry(cmd, a)?;
                if matches!(gspec.normal, NormalSpec::GranularCohesive(model::CohesiveNormal::Jkr, _)) {
                    s.notes.push((
                        first.span,
                        "fix wall/gran granular jkr: LAMMPS 29 Sep 2021 turns a sphere leaving a JKR wall into NaN; demx ends the contact at the JKR pull-off overlap, as for pairs".into(),
                    ));
                }
                return add_wall(s, id, group, gspec, table, 1, wall, motion);
            }
            _ => {
                return Err(super::args::bad_keyword(first, "wall/gran style", &["model", "hooke", "hooke/history", "hertz/history", "granular"])
                    .with_hint("LIGGGHTS 2.x `wall/gran/hertz/history` forms are converted by `demx convert`"))
            }
        }
        let (wall, motion) = lammps_wall_geometry(cmd, a)?;
        spec.has_coeff = true;
        let table = model::fill_table(s, &spec, cmd.span)?;
        (spec, table, 1, wall, motion)
    };
    let _ = style;
    add_wall(s, id, group, spec, table, wall_type, wall, motion)
}

/// Register a primitive wall fix running `spec`'s laws with `table`.
#[allow(clippy::too_many_arguments)]
fn add_wall(
    s: &mut Session,
    id: &str,
    group: u32,
    spec: PairSpec,
    table: ParamTable,
    wall_type: u32,
    wall: PrimitiveWall,
    motion: WallMotion,
) -> Result<()> {
    let kernel = model::build_kernel(&spec)?;
    let width = kernel.history_width();
    let summary = format!("wall/gran {} ({:?}): {}", id, wall, spec.summary());
    s.walls.push(summary.clone());
    let t0 = s.sim.time;
    let cyl_radius = match wall {
        PrimitiveWall::LammpsZCylinder { radius } => Some(radius),
        _ => None,
    };
    let jkr = matches!(spec.normal, NormalSpec::GranularCohesive(model::CohesiveNormal::Jkr, _));
    s.add_fix(Box::new(WallGran {
        laws: WallLaws { cyl_radius, jkr, group, wall, kernel: Arc::from(kernel), table: Arc::new(table), wall_type, width },
        id: id.to_string(),
        motion,
        hist_name: format!("wall_history:{id}"),
        summary,
        t0,
        candidates: Arc::new(vec![]),
        candidates_at: None,
    }))
}

// ------------------------------------------------------------ LAMMPS granular walls

/// Words that end the coefficient block of `fix wall/gran granular` (the
/// wall style; LAMMPS 29 Sep 2021 `FixWallGran` stops at these).
const GRANULAR_WALL_STYLES: &[&str] = &["xplane", "yplane", "zplane", "zcylinder", "region"];

/// Number of coefficients after each normal model name.
fn normal_arity(name: &str) -> Option<usize> {
    match name {
        "hooke" | "hertz" => Some(2),
        "hertz/material" => Some(3),
        "dmt" | "jkr" => Some(4),
        _ => None,
    }
}

/// Parse the coefficient block of `fix wall/gran granular` and
/// `fix wall/gran/region granular` (the cursor stands after `granular`; it
/// is left on the wall style word). The block has the syntax of a
/// `pair_coeff` line of `pair_style granular` and is read by the same parser;
/// then the values LAMMPS 29 Sep 2021 derives differently for a wall are
/// replaced (verified with lmp, a sphere pressed into a zplane):
///
/// * material models (hertz/material, dmt, jkr): the wall is the particle's
///   material, but the effective modulus is `E / (2 (1 - nu))`, not the
///   pair mixing `E / (2 (1 - nu^2))`, so `k_n = 4/3 E / (2 (1 - nu))`;
/// * `tangential mindlin* NULL ...`: `k_t = E / 4 (2 - nu) (1 + nu)`
///   (the pair value is `8 G* = 2 E / ((2 - nu)(1 + nu))`).
///
/// Every particle type meets the wall with the same coefficients.
///
/// Known differences from lmp, not reproduced: a DMT wall contact that
/// attracts (F_ne < 0) and slides is capped by lmp at mu (|F_ne| - ~2.5e-8 N)
/// (constant offset, independent of E, gamma, mass, k_t; demx caps at
/// mu |F_ne| as for pairs); a sphere leaving a JKR wall turns into NaN in lmp.
pub fn granular_coeffs(s: &mut Session, cmd: &Command, a: &mut Args, style: &Word) -> Result<(PairSpec, ParamTable)> {
    let rest = a.rest();
    let end = rest
        .iter()
        .position(|w| GRANULAR_WALL_STYLES.contains(&w.text.as_str()))
        .ok_or_else(|| Error::deck(a.end_span(), "fix wall/gran granular: missing the wall style (xplane, yplane, zplane, zcylinder or region)"))?;
    let block = &rest[..end];
    // LAMMPS takes the sub-models in any order; the pair_coeff parser wants
    // the normal model first
    let k = block.iter().position(|w| normal_arity(&w.text).is_some()).ok_or_else(|| {
        let at = block.first().map(|w| w.span).unwrap_or(style.span);
        Error::deck(at, "fix wall/gran granular: missing the normal model (hooke, hertz, hertz/material, dmt or jkr)")
    })?;
    let n = normal_arity(&block[k].text).unwrap_or(0);
    if k + n >= block.len() {
        return Err(Error::deck(block[k].span, format!("fix wall/gran granular: {} needs {n} coefficients", block[k].text)));
    }
    if let Some(c) = block.iter().find(|w| w.text == "cutoff") {
        return Err(Error::deck(c.span, "Unknown fix wall/gran keyword cutoff"));
    }
    if !block.iter().any(|w| w.text == "tangential") {
        return Err(Error::unsupported(style.span, "fix wall/gran granular without a tangential model")
            .with_hint("add e.g. `tangential linear_nohistory 0 0` (LAMMPS 29 Sep 2021 leaves the default undocumented)"));
    }
    let mut words: Vec<Word> = Vec::with_capacity(block.len() + 3);
    let synth = |t: &str| Word { text: t.to_string(), span: style.span, quoted: false };
    words.push(synth("pair_coeff"));
    words.push(synth("*"));
    words.push(synth("*"));
    words.extend(block[k..=k + n].iter().cloned());
    words.extend(block[..k].iter().cloned());
    words.extend(block[k + n + 1..].iter().cloned());
    let kt_null = block.windows(3).any(|w| w[0].text == "tangential" && w[1].text.starts_with("mindlin") && w[2].text == "NULL");
    let coeff = Command { words, span: cmd.span };
    // the pair parser records into the pair spec: give it a scratch one
    let mut scratch = PairSpec::new(cmd.span, true);
    scratch.normal = NormalSpec::Granular(GranularNormal::Hertz, GranularDamping::Viscoelastic);
    let saved = s.pair.replace(scratch);
    let parsed = model::execute(s, &coeff);
    let got = std::mem::replace(&mut s.pair, saved);
    parsed.map_err(|e| match e {
        Error::Deck { span, msg, hint } => Error::Deck { span, msg: msg.replace("pair_coeff", "fix wall/gran granular"), hint },
        other => other,
    })?;
    a.pos += end;
    let got = got.ok_or_else(|| Error::deck(style.span, "fix wall/gran granular: no coefficients"))?;
    let mut pp = got.granular.first().map(|g| g.2).ok_or_else(|| Error::deck(style.span, "fix wall/gran granular: no coefficients"))?;
    let material = matches!(got.normal, NormalSpec::Granular(GranularNormal::HertzMaterial, _) | NormalSpec::GranularCohesive(..));
    if material {
        let nu = pp.poisson;
        let e_young = pp.y_eff * 2.0 * (1.0 - nu * nu);
        pp.y_eff = e_young / (2.0 * (1.0 - nu));
        pp.kn = 4.0 / 3.0 * pp.y_eff;
        if kt_null {
            pp.kt = e_young / 4.0 * (2.0 - nu) * (1.0 + nu);
        }
    }
    let mut spec = PairSpec::new(cmd.span, true);
    spec.normal = got.normal;
    spec.tangential = got.tangential;
    spec.rolling = got.rolling;
    spec.limit_damping = pp.limit_damping != 0.0;
    let mut table = ParamTable::new(s.sim.ntypes.max(1));
    for p in table.params.iter_mut() {
        *p = pp;
    }
    // demx run --youngs-scale divides every stiffness (pairs and walls)
    super::overrides::scale_table(s, &mut table);
    Ok((spec, table))
}
