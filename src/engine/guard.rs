//! Stability guards: stop a run that has gone wrong, say why, and keep the
//! last good state.
//!
//! Every `every` steps (and at the start of every run) the guard checks
//! - that positions, velocities and angular velocities are finite,
//! - that no pair of particles overlaps by more than `overlap` times the
//!   smaller radius (the `maxoverlap` thermo keyword's measure), nor any
//!   particle a wall by more than `overlap` times its radius (walls that
//!   report their overlap through [`Fix::max_surface_overlap`]),
//! - that no particle travels more than `travel` times its radius in one
//!   step (|v| dt > travel R), and, if set, that no particle is faster than
//!   `speed`.
//!
//! An overlap beyond the limit stops the run only where the deck set the
//! limit (`demx_guard overlap F`). Otherwise it is a warning, once per run
//! (the same diagnosis: contacts, time step against the contact times,
//! placement or insertion), and overlaps are not checked again in that run:
//! LIGGGHTS and LAMMPS run decks that insert grains across a wall, or whose
//! time step spans a contact in two steps, and five third-party decks of the
//! corpus (COMPAT.md) do; demx with the overlap check off agreed with the
//! engine there. A time step too large for the stiffness still stops a run
//! when the collision it cannot resolve throws the grains apart (travel).
//! Non-finite values, travel and speed always stop.
//!
//! A failing check stops the run with [`Error::Runtime`] (exit code 1) and a
//! message naming the particle id, the step, the contact involved (partner
//! id or wall, overlap as a fraction of the radius) and the likely cause
//! (time step against the Hertz/Rayleigh times, an overlapping placement or
//! insertion, a non-finite value from outside the contact law). The state of
//! the last check that passed is written as a LAMMPS data file (temporary
//! file + rename) for inspection.
//!
//! The checks only read the state, in a fixed sequential order, so they never
//! change results: a run that passes is bitwise identical to one with the
//! guard off, on any thread count. Snapshot buffers are reused, so after the
//! first check nothing is allocated unless the particle count grows.
//!
//! [`Fix::max_surface_overlap`]: super::fix::Fix::max_surface_overlap

use super::integrate::in_chunks;
use super::neighbor::{PairList, ADJ_B};
use super::particles::Particles;
use super::sim::{Dialect, Sim};
use crate::error::Error;
use crate::physics::V3;
use std::io::Write;

/// Default overlap limit, fraction of the (smaller) radius. Measured: the
/// LIGGGHTS packing tutorial (particles grown by fix adapt, Y = 5 MPa) ends
/// with 33 %, its 125x faster-growing test variant (tests/it/tutorials_run.rs)
/// peaks at 60 %; resolved collisions stay far below. At 75 % a quarter of the
/// smaller sphere is inside the other: placements that close are stopped.
pub const DEFAULT_OVERLAP: f64 = 0.75;
/// Default travel limit per step, fraction of the particle's radius. With a
/// time step of at most 20 % of the collision time a contact spans at least 5
/// steps, so travelling half a radius per step already means an overlap near
/// a full radius; a deck whose particles do that is not resolving contacts.
pub const DEFAULT_TRAVEL: f64 = 0.5;
/// Default check interval (steps). A time step too large for the stiffness
/// turns the first collision into an explosion (overlap, then a speed far
/// above the travel limit) that the next check sees, at most 20 steps later;
/// a resolved collision spans at least 5-10 steps. At 20 the checks cost
/// about 1.3 % of the instructions of the settle template (2.7 % at 10).
pub const DEFAULT_EVERY: i64 = 20;
/// Default name of the last-good state file (current directory).
pub const DEFAULT_FILE: &str = "demx.lastgood.data";
/// A time step above this fraction of the Hertz or Rayleigh time is named as
/// the likely cause (the same threshold as `demx check`'s warning).
pub const TIMESTEP_SUSPECT_FRACTION: f64 = 0.2;
/// Overlaps at run setup above this fraction of the radius are remembered to
/// name an overlapping placement as the cause of a later failure.
const SETUP_OVERLAP_NOTE: f64 = 0.1;
/// At most this many such overlaps are remembered.
const SETUP_OVERLAP_CAP: usize = 10_000;

/// Guard settings (`demx_guard`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GuardSettings {
    /// Whether the guard runs at all (`demx_guard off`).
    pub enabled: bool,
    /// Overlap limit as a fraction of the radius (None: not checked).
    pub overlap: Option<f64>,
    /// Whether the deck set the overlap limit (`demx_guard overlap F`): an
    /// overlap beyond it then stops the run whatever the time step.
    pub overlap_set: bool,
    /// Limit on |v| dt / R (None: not checked).
    pub travel: Option<f64>,
    /// Absolute speed limit in the deck's velocity units (None: not checked).
    pub speed: Option<f64>,
    /// Check every this many steps (> 0).
    pub every: i64,
    /// File for the last good state (None: not written).
    pub file: Option<String>,
}

impl Default for GuardSettings {
    fn default() -> Self {
        GuardSettings {
            enabled: true,
            overlap: Some(DEFAULT_OVERLAP),
            overlap_set: false,
            travel: Some(DEFAULT_TRAVEL),
            speed: None,
            every: DEFAULT_EVERY,
            file: Some(DEFAULT_FILE.to_string()),
        }
    }
}

/// The time step as fractions of the contact time scales (from the scene's
/// `timestep_check`, set at the start of each run).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimestepFractions {
    /// dt / Hertz collision time (or linear-spring contact time).
    pub hertz: f64,
    /// dt / Rayleigh time.
    pub rayleigh: f64,
}

/// The state of the last passing check.
#[derive(Default, Debug)]
struct Snapshot {
    valid: bool,
    step: i64,
    lo: [f64; 3],
    hi: [f64; 3],
    tag: Vec<i64>,
    kind: Vec<u32>,
    x: Vec<V3>,
    v: Vec<V3>,
    omega: Vec<V3>,
    radius: Vec<f64>,
    mass: Vec<f64>,
    density: Vec<f64>,
    image: Vec<[i32; 3]>,
}

/// The guard: settings plus what it remembers between checks.
#[derive(Debug, Default)]
pub struct Guard {
    /// Settings.
    pub settings: GuardSettings,
    /// Time step fractions of the current run, if the scene could compute them.
    pub timestep: Option<TimestepFractions>,
    snap: Snapshot,
    /// Largest id at the last passing check: larger ids were inserted since.
    tag_mark: i64,
    /// Step of the last passing check.
    last_check: i64,
    /// (smaller id, larger id, overlap fraction) of pairs overlapping at the
    /// start of the current run, sorted.
    setup_overlaps: Vec<(i64, i64, f64)>,
    /// An overlap was warned about in the current run: overlaps are not
    /// checked again until the next run.
    overlap_warned: bool,
}

/// What a check found.
#[derive(Clone, Debug, PartialEq)]
enum Trip {
    /// Particle index, which quantity.
    NonFinite(usize, String),
    /// Pair overlap: particle indices (i, j), fraction of min radius.
    PairOverlap(usize, usize, f64),
    /// Wall overlap: particle index, fix index, fraction of radius.
    WallOverlap(usize, usize, f64),
    /// |v| dt / R above the limit: particle index, ratio.
    Travel(usize, f64),
    /// |v| above the limit: particle index, speed.
    Speed(usize, f64),
}

impl Guard {
    /// Whether a check is due at the end of `step`.
    #[inline]
    pub fn due(&self, step: i64) -> bool {
        self.settings.enabled && step % self.settings.every.max(1) == 0
    }
}

/// Check the state now; `at_setup` marks the check at the start of a run.
/// On success the state becomes the last good one; on failure the last good
/// state is written and the error describes what happened.
pub fn check(sim: &mut Sim, at_setup: bool) -> crate::error::Result<()> {
    if !sim.guard.settings.enabled || sim.dry {
        return Ok(());
    }
    if at_setup {
        note_setup_overlaps(sim);
        sim.guard.overlap_warned = false;
    }
    let mut trip = find_trip(sim, !sim.guard.overlap_warned);
    if let Some(t @ (Trip::PairOverlap(..) | Trip::WallOverlap(..))) = &trip {
        if !overlap_stops(&sim.guard) {
            warn(sim, t, at_setup);
            sim.guard.overlap_warned = true;
            trip = find_trip(sim, false);
        }
    }
    match trip {
        None => {
            take_snapshot(sim);
            Ok(())
        }
        Some(t) => Err(fail(sim, t, at_setup)),
    }
}

/// Whether an overlap beyond the limit stops the run: where the deck set
/// the limit (see the module's text).
fn overlap_stops(g: &Guard) -> bool {
    g.settings.overlap_set
}

/// Log an overlap that does not stop the run (once per run); on stderr too
/// when the screen is off, as demx's other physics warnings.
fn warn(sim: &mut Sim, trip: &Trip, at_setup: bool) {
    let text = describe(sim, trip, at_setup);
    let lim = sim.guard.settings.overlap.unwrap_or(DEFAULT_OVERLAP);
    let line = format!(
        "WARNING (demx): {text}\n  LIGGGHTS and LAMMPS run on with such an overlap, and so does demx; \
         overlaps are not checked again in this run (`demx_guard overlap {lim}` stops a run at an overlap beyond {})",
        pct(lim)
    );
    if !sim.log.screen {
        eprintln!("{line}");
    }
    sim.log.line(&line);
}

/// Called by `rebuild` when particles are about to be dropped as lost
/// (outside a fixed boundary or non-finite): if the guard finds a violation
/// it is the better explanation, returned as the error to stop with.
pub fn on_lost(sim: &mut Sim) -> Option<Error> {
    if !sim.guard.settings.enabled || sim.dry {
        return None;
    }
    // particle checks only: the pair list may not match the particles here
    find_trip(sim, false).map(|t| fail(sim, t, false))
}

/// Whether the pair list indexes the current particles (no insertion or
/// removal since it was built).
fn pairs_valid(sim: &Sim) -> bool {
    let n = sim.particles.len();
    !sim.force_rebuild && sim.pairs.x_built.len() == n && sim.pairs.indexed(n)
}

/// Remember the pairs that overlap noticeably at the start of a run.
fn note_setup_overlaps(sim: &mut Sim) {
    let mut found = std::mem::take(&mut sim.guard.setup_overlaps);
    found.clear();
    if !pairs_valid(sim) {
        sim.guard.setup_overlaps = found;
        return;
    }
    let p = &sim.particles;
    for k in 0..sim.pairs.len() {
        let (a, b) = (sim.pairs.a[k] as usize, sim.pairs.b[k] as usize);
        if a >= p.len() || b >= p.len() || found.len() >= SETUP_OVERLAP_CAP {
            continue;
        }
        let f = pair_overlap(p, &sim.pairs, k);
        if f > SETUP_OVERLAP_NOTE {
            let (ta, tb) = (p.tag[a].min(p.tag[b]), p.tag[a].max(p.tag[b]));
            found.push((ta, tb, f));
        }
    }
    found.sort_by_key(|x| (x.0, x.1));
    sim.guard.setup_overlaps = found;
}

/// Overlap of pair k at the current positions as a fraction of the smaller
/// radius (the `maxoverlap` measure; negative when apart).
#[inline]
fn pair_overlap(p: &Particles, pairs: &PairList, k: usize) -> f64 {
    let (a, b) = (pairs.a[k] as usize, pairs.b[k] as usize);
    let r = (p.x[a] - p.x[b] - pairs.shift(k)).norm();
    (p.radius[a] + p.radius[b] - r) / p.radius[a].min(p.radius[b])
}

#[inline(always)]
fn finite3(v: &V3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// The worst violation, in order of precedence: non-finite values, overlaps
/// (pairs, then walls; only with `overlaps` and a valid pair list), travel,
/// speed.
fn find_trip(sim: &Sim, overlaps: bool) -> Option<Trip> {
    let g = &sim.guard.settings;
    let p = &sim.particles;
    let dt2 = sim.dt * sim.dt;
    let travel2 = g.travel.map(|t| t * t);
    let speed2 = g.speed.map(|s| s * s);
    let mut worst_travel: Option<(usize, f64)> = None;
    let mut worst_speed: Option<(usize, f64)> = None;
    // fast pass: any particle non-finite, too fast for its radius, or too
    // fast? (no early exits in the loop body; the detailed pass below runs
    // only when something is flagged)
    let t2dt = travel2.map_or(f64::INFINITY, |t2| t2 / dt2.max(f64::MIN_POSITIVE));
    let s2 = speed2.unwrap_or(f64::INFINITY);
    let flag = |range: std::ops::Range<usize>| {
        let mut flagged = false;
        for i in range {
            let (x, v, w, r) = (&p.x[i], &p.v[i], &p.omega[i], p.radius[i]);
            let v2 = v.norm_squared();
            let sum = x.x + x.y + x.z + v2 + w.x + w.y + w.z;
            // v2 > (travel R / dt)^2 is |v| dt > travel R
            flagged |= !sum.is_finite() | (v2 > t2dt * (r * r)) | (v2 > s2);
        }
        flagged
    };
    // a yes/no, in fixed chunks: the same answer on any thread count
    let flagged = in_chunks(p.len(), GUARD_CHUNK, flag).into_iter().any(|f| f);
    for i in 0..if flagged { p.len() } else { 0 } {
        let (x, v, w) = (&p.x[i], &p.v[i], &p.omega[i]);
        // one test for the common case; the sum of finite values overflows
        // only near f64::MAX, which the travel check flags anyway
        if !(x.x + x.y + x.z + v.x + v.y + v.z + w.x + w.y + w.z).is_finite() {
            let mut what = String::new();
            for (name, q) in [("position", x), ("velocity", v), ("angular velocity", w)] {
                if !finite3(q) {
                    what.push_str(if what.is_empty() { "" } else { " and " });
                    what.push_str(name);
                }
            }
            if what.is_empty() {
                what.push_str("state (values near the largest float)");
            }
            return Some(Trip::NonFinite(i, what));
        }
        let v2 = v.norm_squared();
        if let Some(t2) = travel2 {
            let r2 = p.radius[i] * p.radius[i];
            if r2 > 0.0 && v2 * dt2 > t2 * r2 {
                let ratio = (v2 * dt2 / r2).sqrt();
                if worst_travel.is_none_or(|(_, w)| ratio > w) {
                    worst_travel = Some((i, ratio));
                }
            }
        }
        if let Some(s2) = speed2 {
            if v2 > s2 && worst_speed.is_none_or(|(_, w)| v2 > w * w) {
                worst_speed = Some((i, v2.sqrt()));
            }
        }
    }
    let lim = if overlaps && pairs_valid(sim) { g.overlap } else { None };
    if let Some(lim) = lim {
        let n = p.len();
        let pl = &sim.pairs;
        // the deepest overlap, the first in pair order on a tie: each fixed
        // chunk keeps its first deepest, and the chunks are compared in order
        let deepest = |range: std::ops::Range<usize>| {
            let mut worst: Option<(usize, usize, f64)> = None;
            for k in range {
                let (a, b) = (pl.a[k] as usize, pl.b[k] as usize);
                if a >= n || b >= n {
                    continue;
                }
                // compare squared distances; take the root only for violations
                let (ra, rb) = (p.radius[a], p.radius[b]);
                let reach = ra + rb - lim * ra.min(rb);
                let r2 = (p.x[a] - p.x[b] - pl.shift(k)).norm_squared();
                if reach > 0.0 && r2 < reach * reach {
                    let f = pair_overlap(p, pl, k);
                    if worst.is_none_or(|(_, _, w)| f > w) {
                        worst = Some((a, b, f));
                    }
                }
            }
            worst
        };
        let mut worst: Option<(usize, usize, f64)> = None;
        for (a, b, f) in in_chunks(pl.len(), GUARD_CHUNK, deepest).into_iter().flatten() {
            if worst.is_none_or(|(_, _, w)| f > w) {
                worst = Some((a, b, f));
            }
        }
        if let Some((a, b, f)) = worst {
            return Some(Trip::PairOverlap(a, b, f));
        }
        let mut worst_wall: Option<(usize, usize, f64)> = None;
        for (k, fix) in sim.fixes.iter().enumerate() {
            if let Some((i, f)) = fix.max_surface_overlap(sim) {
                if f > lim && i < n && worst_wall.is_none_or(|(_, _, w)| f > w) {
                    worst_wall = Some((i, k, f));
                }
            }
        }
        if let Some((i, k, f)) = worst_wall {
            return Some(Trip::WallOverlap(i, k, f));
        }
    }
    if let Some((i, r)) = worst_travel {
        return Some(Trip::Travel(i, r));
    }
    worst_speed.map(|(i, s)| Trip::Speed(i, s))
}

/// Items per chunk of the guard's parallel scans.
const GUARD_CHUNK: usize = 4 * super::integrate::CHUNK;

/// Copy the state into the snapshot buffers (no allocation once they are
/// large enough). The columns are copied side by side, each in chunks, on
/// the pool's threads: a serial copy (~3.7 MB on bed (a), every 20 steps)
/// was the largest part of the step the second thread waited through.
fn take_snapshot(sim: &mut Sim) {
    fn copy<T: Copy + Default + Send + Sync>(dst: &mut Vec<T>, src: &[T]) {
        use rayon::prelude::*;
        dst.resize(src.len(), T::default());
        if src.len() > GUARD_CHUNK {
            dst.par_chunks_mut(GUARD_CHUNK).zip(src.par_chunks(GUARD_CHUNK)).for_each(|(d, s)| d.copy_from_slice(s));
        } else {
            dst.copy_from_slice(src);
        }
    }
    let p = &sim.particles;
    let s = &mut sim.guard.snap;
    let Snapshot { tag, kind, x, v, omega, radius, mass, density, image, .. } = s;
    rayon::scope(|sc| {
        sc.spawn(|_| copy(x, &p.x));
        sc.spawn(|_| copy(v, &p.v));
        sc.spawn(|_| copy(omega, &p.omega));
        sc.spawn(|_| {
            copy(tag, &p.tag);
            copy(kind, &p.kind);
            copy(radius, &p.radius);
            copy(mass, &p.mass);
            copy(density, &p.density);
            copy(image, &p.image);
        });
    });
    if let Some(d) = &sim.domain {
        s.lo = d.lo;
        s.hi = d.hi;
    }
    s.step = sim.step;
    s.valid = true;
    sim.guard.tag_mark = p.tag.iter().copied().max().unwrap_or(0);
    sim.guard.last_check = sim.step;
}

fn g4(x: f64) -> String {
    crate::io::cfmt::fmt_g(x, 4)
}

fn pct(f: f64) -> String {
    if 100.0 * f.abs() >= 10.0 || !f.is_finite() {
        format!("{:.0}%", 100.0 * f)
    } else {
        format!("{}%", crate::io::cfmt::fmt_g(100.0 * f, 2))
    }
}

/// The contacts of particle i now: (partner text, overlap as a fraction of
/// the smaller radius of the two; walls: of i's radius), largest first, at
/// most 3.
fn contacts_of(sim: &Sim, i: usize) -> Vec<(String, f64)> {
    let p = &sim.particles;
    let mut out: Vec<(String, f64)> = vec![];
    let pl = &sim.pairs;
    if pairs_valid(sim) && i < p.len() {
        let (start, adj) = pl.adjacency(p.len());
        for &e in &adj[start[i] as usize..start[i + 1] as usize] {
            let k = (e & !ADJ_B) as usize;
            if k >= pl.len() {
                continue;
            }
            let (a, b) = (pl.a[k] as usize, pl.b[k] as usize);
            if a >= p.len() || b >= p.len() {
                continue;
            }
            let j = if a == i { b } else { a };
            let r = (p.x[a] - p.x[b] - pl.shift(k)).norm();
            let delta = p.radius[a] + p.radius[b] - r;
            if delta > 0.0 || !delta.is_finite() {
                out.push((format!("particle {}", p.tag[j]), delta / p.radius[i].min(p.radius[j])));
            }
        }
    }
    for f in &sim.fixes {
        if let Some(delta) = f.surface_overlap(sim, i) {
            if delta > 0.0 {
                out.push((format!("wall (fix {} {})", f.id(), f.style()), delta / p.radius[i]));
            }
        }
    }
    out.sort_by(|x, y| y.1.partial_cmp(&x.1).unwrap_or(std::cmp::Ordering::Equal));
    out.truncate(3);
    out
}

/// What a trip is, where, the particle's contacts and the likely cause.
fn describe(sim: &Sim, trip: &Trip, at_setup: bool) -> String {
    let p = &sim.particles;
    let g = &sim.guard;
    let step = sim.step;
    let when = if at_setup { format!("at the start of the run (step {step})") } else { format!("at step {step}") };
    let i = match trip {
        Trip::NonFinite(i, _) | Trip::PairOverlap(i, _, _) | Trip::WallOverlap(i, _, _) | Trip::Travel(i, _) | Trip::Speed(i, _) => *i,
    };
    let tag = p.tag[i];
    let r = p.radius[i];
    let mut msg = String::from("stability guard: ");
    let mut partner: Option<usize> = None;
    match trip {
        Trip::NonFinite(_, what) => {
            msg.push_str(&format!("particle {tag} has a non-finite {what} {when}"));
        }
        Trip::PairOverlap(a, b, f) => {
            let (a, b) = if p.tag[*a] <= p.tag[*b] { (*a, *b) } else { (*b, *a) };
            partner = Some(if a == i { b } else { a });
            msg.push_str(&format!(
                "particles {} and {} overlap by {} of the smaller radius {when} (limit {})",
                p.tag[a],
                p.tag[b],
                pct(*f),
                pct(g.settings.overlap.unwrap_or(0.0))
            ));
        }
        Trip::WallOverlap(_, k, f) => {
            let fx = &sim.fixes[*k];
            msg.push_str(&format!(
                "particle {tag} overlaps wall (fix {} {}) by {} of its radius {when} (limit {})",
                fx.id(),
                fx.style(),
                pct(*f),
                pct(g.settings.overlap.unwrap_or(0.0))
            ));
        }
        Trip::Travel(_, ratio) => {
            msg.push_str(&format!(
                "particle {tag} moves {} of its radius per step (speed {}, timestep {}) {when} (limit {})",
                pct(*ratio),
                g4(p.v[i].norm()),
                g4(sim.dt),
                pct(g.settings.travel.unwrap_or(0.0))
            ));
        }
        Trip::Speed(_, s) => {
            msg.push_str(&format!("particle {tag} has speed {} {when} (limit {})", g4(*s), g4(g.settings.speed.unwrap_or(0.0))));
        }
    }
    // contacts of the particle
    let contacts = contacts_of(sim, i);
    if contacts.is_empty() {
        msg.push_str(&format!("\n  contact: particle {tag} touches nothing now"));
    } else {
        let list: Vec<String> = contacts.iter().map(|(who, f)| format!("{who} (overlap {})", pct(*f))).collect();
        msg.push_str(&format!("\n  contacts of particle {tag} (radius {}; overlaps as fractions of the smaller radius): {}", g4(r), list.join(", ")));
    }
    // likely causes, most specific first
    let mut causes: Vec<String> = vec![];
    let overlap_trip = matches!(trip, Trip::PairOverlap(..) | Trip::WallOverlap(..));
    let ids: Vec<i64> = std::iter::once(tag).chain(partner.map(|j| p.tag[j])).collect();
    if overlap_trip && at_setup {
        causes.push(
            "overlapping placement: the overlap existed when the run started (create_atoms, read_data, set diameter or an insertion placed the particles too close)"
                .into(),
        );
    } else {
        let setup_hit = g.setup_overlaps.iter().find(|(a, b, _)| ids.contains(a) || ids.contains(b));
        if let Some((a, b, f)) = setup_hit {
            causes.push(format!(
                "overlapping placement: particles {a} and {b} already overlapped by {} of the smaller radius when the run started",
                pct(*f)
            ));
        }
        let fresh: Vec<i64> = ids.iter().copied().filter(|&t| t > g.tag_mark).collect();
        if !fresh.is_empty() && g.snap.valid && !at_setup {
            let who: Vec<String> = fresh.iter().map(|t| t.to_string()).collect();
            causes.push(format!(
                "overlapping insertion: particle {} was inserted within the last {} steps (after step {})",
                who.join(" and "),
                step - g.last_check,
                g.last_check
            ));
        }
    }
    let ts_text =
        g.timestep.map(|t| format!("timestep {} is {} of the Hertz time and {} of the Rayleigh time", g4(sim.dt), pct(t.hertz), pct(t.rayleigh)));
    let ts_big = g.timestep.is_some_and(|t| t.hertz.max(t.rayleigh) > TIMESTEP_SUSPECT_FRACTION);
    if ts_big {
        causes.push(format!(
            "timestep too large for the stiffness: {} (keep both below {})",
            ts_text.clone().unwrap_or_default(),
            pct(TIMESTEP_SUSPECT_FRACTION)
        ));
    }
    if causes.is_empty() {
        causes.push(match trip {
            Trip::NonFinite(..) => "a non-finite value from outside the contact law (a variable evaluating to NaN or inf in fix addforce, set or velocity; a zero mass or radius)".into(),
            Trip::PairOverlap(..) | Trip::WallOverlap(..) => {
                "the particles are pressed together harder than the contact stiffness resists (a large external force, a wall moving into particles, or a too soft material)".into()
            }
            Trip::Travel(..) | Trip::Speed(..) => {
                "the particle was accelerated by a fix or a set velocity, or the limit is too tight for this deck (raise it with `demx_guard travel F` / `speed V`)".into()
            }
        });
        if let Some(t) = &ts_text {
            causes.push(format!("for reference, the {t}"));
        }
    }
    msg.push_str(&format!("\n  likely cause: {}", causes.join("; ")));
    msg
}

/// Build the error for a trip, write the last good state and flush outputs.
fn fail(sim: &mut Sim, trip: Trip, at_setup: bool) -> Error {
    let mut msg = describe(sim, &trip, at_setup);
    let g = &sim.guard;
    let step = sim.step;
    // last good state
    match g.settings.file.clone() {
        Some(file) => match write_last_good(sim, &file) {
            Ok(Some(s)) => msg.push_str(&format!("\n  last good state (step {s}) written to {file} (LAMMPS data file, read_data reads it)")),
            Ok(None) => msg.push_str(&format!(
                "\n  no state passed the checks yet: the state at the start of the run (step {step}) is written to {file} for inspection"
            )),
            Err(e) => msg.push_str(&format!("\n  could not write the last good state to {file}: {e}")),
        },
        None => msg.push_str("\n  last good state not written (`demx_guard file none`)"),
    }
    msg.push_str("\n  tune or switch off the checks with `demx_guard` (see README)");
    // outputs: dumps flush every frame and the log every line; make sure
    // screen output is out and the log records why the run stopped
    let _ = std::io::stdout().flush();
    if let Some(f) = &mut sim.log.file {
        let _ = writeln!(f, "ERROR: {msg}");
        let _ = f.flush();
    }
    Error::runtime(msg)
}

/// Write the snapshot (or, if no check passed yet, the current state) as a
/// data file through a temporary file and a rename. Returns the snapshot's
/// step, or None when the current state was written.
fn write_last_good(sim: &Sim, file: &str) -> std::io::Result<Option<i64>> {
    use crate::io::data::{format_data, DataAtom, DataFile};
    let s = &sim.guard.snap;
    let p = &sim.particles;
    let arr = |v: &V3| [v.x, v.y, v.z];
    // one atom of the data file from the columns of the snapshot or the particles
    #[allow(clippy::too_many_arguments)]
    fn atom(tag: i64, kind: u32, radius: f64, density: f64, mass: f64, x: [f64; 3], image: [i32; 3], v: [f64; 3], omega: [f64; 3]) -> DataAtom {
        DataAtom { id: tag.max(0) as u64, kind, diameter: 2.0 * radius, density: if radius > 0.0 { density } else { mass }, x, image, v, omega }
    }
    let (atoms, lo, hi, step, which): (Vec<DataAtom>, [f64; 3], [f64; 3], i64, Option<i64>) = if s.valid {
        let atoms = (0..s.tag.len())
            .map(|i| atom(s.tag[i], s.kind[i], s.radius[i], s.density[i], s.mass[i], arr(&s.x[i]), s.image[i], arr(&s.v[i]), arr(&s.omega[i])))
            .collect();
        (atoms, s.lo, s.hi, s.step, Some(s.step))
    } else {
        let atoms = (0..p.len())
            .map(|i| atom(p.tag[i], p.kind[i], p.radius[i], p.density[i], p.mass[i], arr(&p.x[i]), p.image[i], arr(&p.v[i]), arr(&p.omega[i])))
            .collect();
        let (lo, hi) = sim.domain.as_ref().map_or(([0.0; 3], [0.0; 3]), |d| (d.lo, d.hi));
        (atoms, lo, hi, sim.step, None)
    };
    let df = DataFile { title: String::new(), atom_types: sim.ntypes.max(1) as u32, lo, hi, tilt: None, masses: vec![], atoms, has_velocities: true };
    let engine = if sim.dialect == Dialect::Liggghts { crate::io::dump::Engine::Liggghts } else { crate::io::dump::Engine::Lammps };
    let text = format_data(&df, engine, step.max(0) as u64);
    let path = std::path::Path::new(file);
    let tmp = {
        let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
        name.push(format!(".tmp{}", std::process::id()));
        path.with_file_name(name)
    };
    std::fs::write(&tmp, text)?;
    if let Err(e) = std::fs::rename(&tmp, path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    Ok(which)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::domain::{Domain, Side};
    use crate::engine::particles::NewParticle;

    fn two(gap: f64) -> Sim {
        let mut sim = Sim::default();
        sim.domain = Some(Domain::new([-1.0; 3], [1.0; 3], [[Side::Fixed; 2]; 3], 3));
        sim.ntypes = 1;
        for (k, x) in [(1, -0.5 - 0.5 * gap), (2, 0.5 + 0.5 * gap)] {
            sim.particles.push(NewParticle {
                tag: k,
                kind: 1,
                mask: 1,
                x: V3::new(x, 0.0, 0.0),
                v: V3::zeros(),
                omega: V3::zeros(),
                radius: 0.5,
                density: 1.0,
            });
        }
        sim.guard.settings.file = None;
        // a pair list as a contact model would have it (rebuild without a
        // model keeps none)
        let dom = sim.domain.clone().expect("box");
        sim.pairs.build(&sim.particles, &dom, &sim.neigh, 0, &[], |_, _| 0.0);
        sim.force_rebuild = false;
        sim
    }

    #[test]
    fn overlap_limit_is_a_fraction_of_the_smaller_radius() {
        // centres 0.8 apart, radii 0.5: overlap 0.2 = 40 % of R
        let sim = two(-0.2);
        assert_eq!(find_trip(&sim, true), None);
        // 0.6 apart: overlap 0.4 = 80 % of R
        let sim = two(-0.4);
        match find_trip(&sim, true) {
            Some(Trip::PairOverlap(_, _, f)) => assert!((f - 0.8).abs() < 1e-12, "{f}"),
            t => panic!("{t:?}"),
        }
    }

    #[test]
    fn travel_and_nan() {
        let mut sim = two(0.1);
        sim.dt = 0.01;
        // 0.5 R per step at R = 0.5, dt = 0.01: v = 25
        sim.particles.v[1] = V3::new(24.9, 0.0, 0.0);
        assert_eq!(find_trip(&sim, true), None);
        sim.particles.v[1] = V3::new(25.1, 0.0, 0.0);
        assert!(matches!(find_trip(&sim, true), Some(Trip::Travel(1, _))));
        sim.particles.omega[0].y = f64::NAN;
        assert_eq!(find_trip(&sim, true), Some(Trip::NonFinite(0, "angular velocity".into())));
        sim.guard.settings.speed = Some(1.0);
        sim.particles.omega[0].y = 0.0;
        sim.guard.settings.travel = None;
        assert!(matches!(find_trip(&sim, true), Some(Trip::Speed(1, s)) if (s - 25.1).abs() < 1e-12));
    }
}
