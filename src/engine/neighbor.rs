//! Binned Verlet pair list with skin, and contact history that survives
//! rebuilds (LIGGGHTS `neighbor 0.002 bin`, `fix contact_history`).
//!
//! Each pair is stored once (a half list) with the particle of the smaller
//! storage index first, so every force block's pairs reach only later blocks
//! (the step may finish a block as soon as its own pass is done; see
//! `Sim::one_step`); periodic images are an explicit shift of the second
//! particle. History is carried across rebuilds keyed by the two ids, and
//! turned (each law's `FLIP`) when storage order swapped a pair's roles.
//! Per-particle adjacency (CSR) lists each particle's pairs in increasing pair
//! index, so forces can be gathered in a fixed order on any thread count.
//!
//! Between builds the list is pruned (as GROMACS prunes its pair list
//! dynamically): of the pairs within the skin, the list proper keeps those
//! within a smaller buffer of touching at the current positions, and is
//! pruned again from the full list once a particle has moved half that
//! buffer. A settled bed's list within the skin is mostly pairs apart that
//! cannot touch for many steps; the force pass then walks about half of
//! them. Pruning changes no result: a pair left out is apart by more than
//! the buffer, so it would have added nothing, and the pairs kept are added
//! in the same order.

use super::domain::Domain;
use super::integrate::{cut, in_chunks, CHUNK};
use super::particles::Particles;
use crate::physics::V3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A multiply-rotate hasher for id pairs (the history map is rebuilt on every
/// list build; SipHash's protection against crafted keys is not needed for
/// particle ids and costs a third of the build).
#[derive(Default)]
struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// The half pair list with history.
#[derive(Clone, Debug, Default)]
pub struct PairList {
    /// First particle (smaller storage index) of each pair.
    pub a: Vec<u32>,
    /// Second particle.
    pub b: Vec<u32>,
    /// Periodic image of each pair: b is seen at `x[b] + images[image[k]]`
    /// (one byte per pair instead of a 24-byte shift; see [`PairList::shift`]).
    pub image: Vec<u8>,
    /// The distinct periodic shifts the pairs use.
    pub images: Vec<V3>,
    /// Per pair: 1 if its history may be non-zero, else 0. A pair found apart with 0 here is
    /// skipped without touching its history: most listed pairs are within
    /// the skin but apart, and stay so. A prune keeps every live pair.
    pub live: Vec<u8>,
    /// History values, `width` per pair.
    pub hist: Vec<f64>,
    /// History values per pair.
    pub width: usize,
    /// Ids of (a, b) at the last build: history is matched by these.
    pub keys: Vec<(i64, i64)>,
    /// Positions at the last build (for the skin check).
    pub x_built: Vec<V3>,
    /// Step of the last build.
    pub last_build: i64,
    /// Number of builds so far.
    pub builds: u64,
    /// Number of dangerous builds (a particle had moved more than half the
    /// skin when the list was rebuilt on schedule).
    pub dangerous: u64,
    /// Particles per block of the force pass (0: [`BLOCK`]; a power of two). Pairs are
    /// sorted by their first particle, so the pairs of one block are a range.
    pub block: usize,
    /// Pair index where each block's pairs start (blocks + 1 entries).
    pub block_start: Vec<u32>,
    /// CSR offsets into `cross` per particle (len = n + 1).
    pub cross_start: Vec<u32>,
    /// For each particle, the deferred slots of the pairs where it is `b`
    /// and `a` lies in another block, in increasing pair index: their share
    /// is added after the block pass.
    pub cross: Vec<u32>,
    /// The particle of each entry of `cross` (its `b`), so that a block's
    /// cross pass runs over its entries without a branch per particle.
    pub cross_b: Vec<u32>,
    /// Slot where each block's cross pairs start (blocks + 1 entries).
    pub block_cross: Vec<u32>,
    /// Per cross pair, in pair order: its slot, counted from its block's
    /// first ([`PairList::block_cross`]).
    pub xslot: Vec<u32>,
    /// The other blocks each block's pairs reach, in increasing order, as
    /// CSR offsets per block (blocks + 1) into `block_touch`.
    pub block_touch_start: Vec<u32>,
    /// See `block_touch_start`.
    pub block_touch: Vec<u32>,
    /// Per block, how many passes touch its particles: its own and those of
    /// the blocks whose pairs reach it.
    pub block_deps: Vec<u32>,
    /// Whether every block's pairs reach only later blocks (pairs by storage
    /// index, as every build makes them): then a block is complete once
    /// its own pass and the earlier ones that reach it are done, and the
    /// step finishes it right away (`kernel::fused_blocks`).
    pub forward: bool,
    /// The full list of the last build while the list proper holds a
    /// pruned part of it ([`PairList::prune`]); `None`: the list is full.
    pub outer: Option<Box<Outer>>,
    /// Positions at the last prune, in single precision, and beside each a
    /// bound on its distance from the position at the last build, rounded
    /// up ([`PairList::travel`] bounds the skin check by it); empty while
    /// the list is full.
    pub x_pruned: Vec<[f32; 4]>,
    /// Squared displacement since the last prune beyond which some pair
    /// left out might touch: half the buffer, less the rounding of
    /// `x_pruned`, squared.
    pub prune_lim: f64,
    /// Buffer beyond touching (and the pair's extra range) that the last
    /// prune kept.
    pub buffer: f64,
    /// Step of the last prune.
    pub pruned_at: i64,
    /// Number of prunes so far.
    pub prunes: u64,
    /// Fraction of the full list the last prune kept (0 before any).
    pub kept: f64,
    /// Builds to go before a prune is tried again, after one was judged
    /// not to pay ([`PairList::prune_pays`]).
    pub retry_in: u32,
    /// What the last check measured (see [`Travel`]).
    pub travel: Travel,
    /// The second particles and history of the list before the last build,
    /// which the next build writes its list into while it reads the current
    /// one's history (no fresh pages for them on every build).
    pub(crate) spare: (Vec<u32>, Vec<f64>),
}

/// The larger of a running maximum `m` and `d`, which a NaN `d` leaves as
/// it is (as `f64::max` does; written so, it compiles to the vector max).
#[inline(always)]
fn max(m: f64, d: f64) -> f64 {
    if d > m {
        d
    } else {
        m
    }
}

/// The full list of a build, of which a pruned list keeps a part.
#[derive(Clone, Debug, Default)]
pub struct Outer {
    a: Vec<u32>,
    b: Vec<u32>,
    image: Vec<u8>,
    keys: Vec<(i64, i64)>,
    /// Per pair: its index in the pruned list, or [`NONE`].
    inner: Vec<u32>,
    /// Scratch of a prune: each pair's fate (1: kept).
    keep: Vec<u8>,
    /// The history buffer of the list before the last prune, reused by
    /// the next one (which reads the current list's while it writes).
    spare: Vec<f64>,
}

/// Pairs of the full list per chunk of a prune ([`PairList::refilter`]):
/// fixed, so the list comes out the same on any thread count.
const PRUNE_CHUNK: usize = 16384;

/// One chunk of a prune's copy: its index, its places in the new list's
/// arrays, and its pairs' slots in the full list.
type PruneJob<'a> = (usize, &'a mut [u32], &'a mut [u32], &'a mut [u8], &'a mut [(i64, i64)], &'a mut [u8], &'a mut [f64], &'a mut [u32]);

/// No index (a pair of the full list that the pruned list left out).
const NONE: u32 = u32::MAX;

/// How far particles moved: the largest squared displacement since the
/// last build and since the last prune (a maximum, so the same on any
/// thread count; both 0 where not measured).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Travel {
    /// Since the last build.
    pub built: f64,
    /// Since the last prune.
    pub pruned: f64,
}

impl Travel {
    /// The larger of each.
    pub fn max(self, o: Travel) -> Travel {
        Travel { built: self.built.max(o.built), pruned: self.pruned.max(o.pruned) }
    }
}

/// Steps between prunes that the buffer is chosen for, from the speed of
/// the fastest particle: a prune costs about a force pass's walk over the
/// full list, and pays when it spares many walks over the pairs it drops.
const PRUNE_STEPS: f64 = 16.0;
/// Smallest buffer, as a fraction of the skin.
const PRUNE_MIN: f64 = 1.0 / 64.0;
/// A buffer this fraction of the skin or more: the list stays full.
const PRUNE_MAX: f64 = 0.5;
/// What a prune costs, in walks of an apart pair by the force pass, per
/// pair of the full list: the pick, the copy and the block index. Measured
/// on the LAMMPS chute (scripts/bench.py case c, 1000 steps): 87 prunes
/// took 0.20 s of Neigh for 113,000 pairs each (~20 ns a pair), and the
/// force pass walked an apart pair in ~5.4 ns.
const PRUNE_COST: f64 = 4.0;
/// Builds without a prune after one that did not pay, before the next try.
const PRUNE_RETRY: u32 = 4;

/// Whether prunes that keep this fraction of the full list pay.
fn pays(kept: f64) -> bool {
    (1.0 - kept) * PRUNE_STEPS > PRUNE_COST
}

super::switch::switch!(
    /// Tests switch it on to keep the list full, to check that pruning
    /// changes no bit.
    NO_PRUNE
);

/// Run `f` with pair-list pruning switched off on this thread (tests).
pub fn without_pruning<T>(f: impl FnOnce() -> T) -> T {
    NO_PRUNE.on_during(f)
}

super::switch::switch!(
    /// Tests switch it on to prune whenever the buffer allows, whether or
    /// not the prune pays ([`PairList::prune_pays`]), so that a scene
    /// small enough for a test prunes often.
    EVERY_PRUNE
);

/// Run `f` pruning the pair list whenever the buffer allows, on this
/// thread (tests).
pub fn with_every_prune<T>(f: impl FnOnce() -> T) -> T {
    EVERY_PRUNE.on_during(f)
}

/// Particles per block of the force pass. Fixed, never derived from the
/// number of threads: the order in which contributions are added to each
/// particle, and so every bit of the result, is the same on any thread count.
pub const BLOCK: usize = 2048;

/// History of the previous list, for the next build (see
/// [`PairList::carry_source`]).
enum Carry {
    None,
    /// Storage unchanged: the old pairs of particle `i` are
    /// `start[i]..start[i + 1]`, sorted by `b`.
    ByIndex {
        start: Vec<u32>,
        b: Vec<u32>,
        hist: Vec<f64>,
    },
    /// Non-zero history by id pair, the smaller id first, with whether the
    /// pair's first particle was the one of larger id.
    ById(HashMap<(i64, i64), (bool, Vec<f64>), BuildHasherDefault<IdHasher>>),
}

/// Where a chunk of the build writes its pairs: its range of the list.
struct Place<'a> {
    a: &'a mut [u32],
    b: &'a mut [u32],
    image: &'a mut [u8],
    keys: &'a mut [(i64, i64)],
    hist: &'a mut [f64],
}

/// What the per-chunk build reads.
struct BuildCtx<'a, F> {
    p: &'a Particles,
    s: &'a NeighSettings,
    grid: &'a Grid,
    images: &'a [V3],
    /// Each image's rank in the order of its shift ([`cmp_v3`]; equal
    /// shifts, equal ranks): a pair's sort key with its partner.
    image_rank: [u8; 27],
    extra_range: &'a F,
    old: &'a Carry,
    width: usize,
    /// Pairs per particle at the last build (to size the chunks' buffers).
    per_particle: usize,
}

/// The pairs a chunk of particles found over the half stencil
/// ([`BuildCtx::find`]), before they are put in order.
struct Found {
    /// Per particle of the chunk, where its pairs start in `own` (one more
    /// entry than particles).
    start: Vec<u32>,
    /// Pairs whose first particle (the smaller storage index) found them:
    /// second particle and image.
    own: Vec<(u32, u8)>,
    /// Pairs found by their second particle: first particle, second
    /// particle and the image as seen from the first.
    foreign: Vec<(u32, u32, u8)>,
}

/// The image index of the opposite shift (of [`stencil_images`]).
const fn opposite(img: u8) -> u8 {
    26 - img
}

impl<F: Fn(usize, usize) -> f64> BuildCtx<'_, F> {
    /// The pairs within reach + skin of each particle of `range` over the
    /// half stencil ([`Grid::stencil`]): each pair and image is tested
    /// once, half the candidates of a full stencil. The test is written as
    /// from the pair's first particle whichever found it (the same
    /// operations, so the same list as a full stencil tested from there).
    fn find(&self, range: std::ops::Range<usize>) -> Found {
        let (p, s) = (self.p, self.s);
        let room = range.len() * (self.per_particle / 2 + 2);
        let mut out = Found { start: Vec::with_capacity(range.len() + 1), own: Vec::with_capacity(room), foreign: Vec::with_capacity(room) };
        out.start.push(0);
        let mut buf: Vec<(u32, u8)> = Vec::new();
        let mut stencil: Vec<Run> = Vec::with_capacity(14);
        let mut stencil_of: Option<[i64; 3]> = None;
        let excluding = !s.exclude_types.is_empty() || !s.exclude_groups.is_empty();
        for i in range {
            let ci = self.grid.cell_of(&p.x[i]);
            if stencil_of != Some(ci) {
                stencil.clear();
                self.grid.stencil(ci, &mut stencil);
                stencil_of = Some(ci);
            }
            let (xi, ri) = (p.x[i], p.radius[i]);
            // branch-free: every candidate is written, and the slot is kept
            // when the pair is listed (whether it is is a coin toss per
            // candidate, so a branch on it mispredicts half the time)
            let most: usize = stencil.iter().map(|r| (r.hi - r.lo) as usize).sum();
            if buf.len() < most {
                buf.resize(most, (0, 0));
            }
            let mut len = 0;
            for &Run { lo, hi, img, own } in &stencil {
                let (shift, back) = (self.images[img as usize], self.images[opposite(img) as usize]);
                for &j in &self.grid.items[lo as usize..hi as usize] {
                    let ju = j as usize;
                    // the own bin's pairs once, from the smaller storage
                    // index; the other bins' (a particle's own periodic
                    // images among them, at the positive shifts the half
                    // stencil reaches) all
                    let order = !own | (ju > i);
                    // as tested from the pair's first particle a: x[a] -
                    // (x[b] + shift from a)
                    let below = ju < i;
                    let (xa, xb, sh) = if below { (p.x[ju], xi, back) } else { (xi, p.x[ju], shift) };
                    let d = xa - (xb + sh);
                    let extra = if below { (self.extra_range)(ju, i) } else { (self.extra_range)(i, ju) };
                    let reach = ri + p.radius[ju] + s.skin + extra;
                    let within = d.norm_squared() < reach * reach;
                    buf[len] = (j, img);
                    len += (order & within) as usize;
                }
            }
            for &(j, img) in &buf[..len] {
                let ju = j as usize;
                if excluding && ju != i && s.excluded(p, i, ju) {
                    continue;
                }
                if ju >= i {
                    out.own.push((j, img));
                } else {
                    out.foreign.push((j, i as u32, opposite(img)));
                }
            }
            out.start.push(out.own.len() as u32);
        }
        out
    }

    /// The list's part for the particles of `range`, written into `out`
    /// (its range of the list, as many places as the chunk's pairs): each
    /// one's pairs (those it found itself, in `found_own`, and those later
    /// particles found, in `foreign` from `fstart`) in order of storage
    /// index and shift, with their ids and the history each carries.
    fn chunk(&self, range: std::ops::Range<usize>, found_own: &Found, fstart: &[u32], foreign: &[(u32, u8)], out: Place<'_>) {
        let w = self.width;
        // the next pair's place
        let mut at = 0;
        let mut found: Vec<(u32, u8)> = Vec::new();
        for i in range.clone() {
            let k = i - range.start;
            found.clear();
            found.extend_from_slice(&found_own.own[found_own.start[k] as usize..found_own.start[k + 1] as usize]);
            found.extend_from_slice(&foreign[fstart[i] as usize..fstart[i + 1] as usize]);
            // by storage index, then shift (periodic images of one pair):
            // one integer key, which compares as the shifts do, so the
            // sort makes the same moves as one comparing the vectors
            found.sort_unstable_by_key(|&(j, img)| pair_key(j, img, &self.image_rank));
            let len = found.len();
            out.a[at..at + len].fill(i as u32);
            let ti = self.p.tag[i];
            let places = out.b[at..at + len].iter_mut().zip(&mut out.image[at..at + len]).zip(&mut out.keys[at..at + len]);
            for (((b, image), key), &(j, img)) in places.zip(&found) {
                (*b, *image, *key) = (j, img, (ti, self.p.tag[j as usize]));
            }
            let h0 = at * w;
            out.hist[h0..h0 + len * w].fill(0.0);
            at += len;
            if let Carry::ByIndex { start, b, hist } = self.old {
                // the old pairs of i and the found ones are both sorted by
                // second particle: one merge, not a scan of the old pairs
                // per found pair (on the chute that scan was a third of
                // the list's part of the build)
                let (mut q, end) = (start[i] as usize, start[i + 1] as usize);
                debug_assert!(b[q..end].is_sorted(), "old pairs of {i} not in order");
                let (mut seen, mut from) = (None, None);
                for (k, &(j, _)) in found.iter().enumerate() {
                    if seen != Some(j) {
                        // the last old pair (i, j) with non-zero history, as
                        // the by-id map keeps it (of any image)
                        while q < end && b[q] < j {
                            q += 1;
                        }
                        from = None;
                        while q < end && b[q] == j {
                            if hist[q * w..(q + 1) * w].iter().any(|&v| v != 0.0) {
                                from = Some(q);
                            }
                            q += 1;
                        }
                        seen = Some(j);
                    }
                    if let Some(q) = from {
                        out.hist[h0 + k * w..h0 + (k + 1) * w].copy_from_slice(&hist[q * w..(q + 1) * w]);
                    }
                }
            }
        }
        debug_assert_eq!(at, out.b.len(), "a chunk's pairs not as counted");
    }
}

/// Put the pairs that chunks found by their second particle in the order
/// of their first: CSR offsets per particle (`n + 1`) and the pairs'
/// second particles and images, each particle's in the order found.
fn foreign_by_first(found: &[Found], n: usize) -> (Vec<u32>, Vec<(u32, u8)>) {
    let mut start = vec![0u32; n + 1];
    for f in found {
        for &(a, _, _) in &f.foreign {
            start[a as usize + 1] += 1;
        }
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut items = vec![(0u32, 0u8); start[n] as usize];
    for f in found {
        for &(a, b, img) in &f.foreign {
            items[fill[a as usize] as usize] = (b, img);
            fill[a as usize] += 1;
        }
    }
    (start, items)
}

/// Marker bit in `PairList::adj` for "this particle is b".
pub const ADJ_B: u32 = 1 << 31;

/// Neighbour settings (LAMMPS `neighbor`, `neigh_modify`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct NeighSettings {
    /// Skin distance.
    pub skin: f64,
    /// `delay` steps since the last build before a new one is considered.
    pub delay: i64,
    /// Consider a build every this many steps.
    pub every: i64,
    /// Build only if some particle moved more than half the skin.
    pub check: bool,
    /// `neigh_modify exclude type I J` pairs (unordered).
    pub exclude_types: Vec<(u32, u32)>,
    /// `neigh_modify exclude group g1 g2` as mask bits.
    pub exclude_groups: Vec<(u32, u32)>,
}

impl NeighSettings {
    /// The skin check's limit: half the skin, squared.
    pub fn skin_limit(&self) -> f64 {
        0.25 * self.skin * self.skin
    }
}

impl Default for NeighSettings {
    fn default() -> Self {
        // LAMMPS defaults: skin 0.3 sigma (lj) / 0.001 m (si); delay 0 every 1
        // check yes (since 2020; LIGGGHTS wants delay 0 too).
        NeighSettings { skin: 0.001, delay: 0, every: 1, check: true, exclude_types: vec![], exclude_groups: vec![] }
    }
}

impl NeighSettings {
    fn excluded(&self, p: &Particles, i: usize, j: usize) -> bool {
        let (ti, tj) = (p.kind[i], p.kind[j]);
        for &(a, b) in &self.exclude_types {
            if (a == ti && b == tj) || (a == tj && b == ti) {
                return true;
            }
        }
        for &(ga, gb) in &self.exclude_groups {
            let (mi, mj) = (p.mask[i], p.mask[j]);
            if (mi & ga != 0 && mj & gb != 0) || (mi & gb != 0 && mj & ga != 0) {
                return true;
            }
        }
        false
    }
}

impl PairList {
    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.a.len()
    }
    /// The periodic shift of pair `k`: b is seen at `x[b] + shift(k)`.
    #[inline(always)]
    pub fn shift(&self, k: usize) -> V3 {
        self.images[self.image[k] as usize]
    }
    /// Set the pairs' shifts from one vector per pair (a restart).
    pub fn set_shifts(&mut self, shifts: &[V3]) {
        self.images.clear();
        self.image = shifts
            .iter()
            .map(|s| match self.images.iter().position(|t| t == s) {
                Some(k) => k as u8,
                None => {
                    self.images.push(*s);
                    (self.images.len() - 1) as u8
                }
            })
            .collect();
    }
    /// Whether there are no pairs.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// What `neigh_modify` asks of step `step` with `n` particles: a build
    /// whatever the particles did, a check of how far they moved, or
    /// nothing (the first half of LAMMPS `Neighbor::decide`; the step's head
    /// does the check, [`PairList::checked`] the rest).
    pub fn due(&self, n: usize, s: &NeighSettings, step: i64) -> Due {
        if self.x_built.len() != n {
            return Due::Build;
        }
        let since = step - self.last_build;
        if since < s.delay || (s.every > 0 && since % s.every != 0) {
            return Due::Skip;
        }
        if s.check {
            Due::Check
        } else {
            Due::Build
        }
    }

    /// [`PairList::travel`] of all particles (at `x`), as a pass of its own.
    pub fn travel_all(&self, x: &[V3], built: Option<f64>) -> Travel {
        // maxima over fixed chunks: the same on any thread count
        if x.len() >= 2 * CHUNK {
            use rayon::prelude::*;
            x.par_chunks(CHUNK).enumerate().map(|(c, x)| self.travel(x, c * CHUNK, built)).reduce(Travel::default, Travel::max)
        } else {
            self.travel(x, 0, built)
        }
    }

    /// How far the particles `lo..lo + x.len()` (at `x`) moved: since the
    /// last build when `built` gives the skin check's limit (squared half
    /// skin; LAMMPS `Neighbor::check_distance`), since the last prune while
    /// the list is pruned.
    ///
    /// While pruned, the distance from the last build is bounded by the
    /// one from the last prune plus the prune's own distance from the
    /// build: where that bound stays within `built`'s limit, it is
    /// returned, and the positions of the last build are not read (on a
    /// bed beyond the cache, 24 bytes less per particle and step from
    /// memory). A chunk whose bound passes the limit measures exactly, so
    /// the check decides as it would with exact distances.
    #[inline]
    pub fn travel(&self, x: &[V3], lo: usize, built: Option<f64>) -> Travel {
        let mut t = Travel::default();
        let exact = |x: &[V3]| x.iter().zip(&self.x_built[lo..lo + x.len()]).map(|(x, x0)| (x - x0).norm_squared()).fold(0.0, max);
        let Some(xp) = self.x_pruned.get(lo..lo + x.len()) else {
            if built.is_some() {
                t.built = exact(x);
            }
            return t;
        };
        let d2 = |x: &V3, p: &[f32; 4]| {
            let d = [x.x - p[0] as f64, x.y - p[1] as f64, x.z - p[2] as f64];
            d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
        };
        let Some(lim) = built else {
            t.pruned = x.iter().zip(xp).map(|(x, p)| d2(x, p)).fold(0.0, max);
            return t;
        };
        // |x - x_built| <= |x - x_pruned| + |x_pruned - x_built|, and over
        // the chunk at most the largest of the first plus the largest of the
        // second: one square root per chunk, not per particle (a chunk whose
        // bound passes the limit measures exactly). The relative margin
        // covers the rounding of both sides' sums. One pass carries both
        // maxima (each distance from the prune computed once).
        let (pruned, far) = x.iter().zip(xp).fold((0.0, 0.0f32), |(m, b), (x, p)| (max(m, d2(x, p)), if p[3] > b { p[3] } else { b }));
        let bound = pruned.sqrt() + far as f64;
        let bound = bound * bound * (1.0 + 1e-9);
        t.pruned = pruned;
        t.built = if bound <= lim { bound } else { exact(x) };
        t
    }

    /// Whether `t` tells that a particle moved more than half the skin
    /// since the last build.
    pub fn beyond_skin(&self, t: &Travel, s: &NeighSettings) -> bool {
        t.built > s.skin_limit()
    }

    /// Whether the list is pruned and `t` tells that a pair left out at the
    /// last prune might touch now.
    pub fn prune_due(&self, t: &Travel) -> bool {
        self.outer.is_some() && t.pruned > self.prune_lim
    }

    /// Pairs that interacted in the last force pass: in contact, or within
    /// the reach of a cohesion acting at a distance (the live flags).
    pub fn interacting(&self) -> usize {
        self.live.iter().take(self.a.len()).filter(|&&l| l & 1 != 0).count()
    }

    /// Pairs of the last build: the full list's, while pruned.
    pub fn listed(&self) -> usize {
        self.outer.as_ref().map_or(self.a.len(), |o| o.a.len())
    }

    /// Whether the list is pruned (the step's check measures
    /// [`Travel::pruned`] then, whatever `neigh_modify` asks).
    pub fn pruned(&self) -> bool {
        debug_assert_eq!(self.outer.is_some(), !self.x_pruned.is_empty());
        self.outer.is_some()
    }

    /// The answer of a [`Due::Check`] at `step` once `moved` is known over all
    /// particles: counts a dangerous build (one at the first step allowed).
    pub fn checked(&mut self, moved: bool, s: &NeighSettings, step: i64) -> bool {
        let since = step - self.last_build;
        if moved && since == s.delay.max(1) && s.delay > 0 {
            self.dangerous += 1;
        }
        moved
    }

    /// Build the list. `extra_range(i, j)` is how far beyond touching the
    /// pair interacts (0 for contact-only models). History of pairs present
    /// before is carried over by id; `signs` has one factor per history
    /// value (its width), applied where a pair's roles swapped since.
    ///
    /// Each particle collects, over the full 27-cell stencil, the neighbours
    /// of larger storage index (and its own positive periodic images), sorted by storage
    /// index and shift: so the list comes out ordered by (a, b, shift) with no
    /// global sort, and fixed chunks of particles are built in parallel and
    /// joined in order (the same list on any thread count).
    pub fn build<F>(&mut self, p: &Particles, dom: &Domain, s: &NeighSettings, step: i64, signs: &[f64], extra_range: F)
    where
        F: Fn(usize, usize) -> f64 + Sync,
    {
        let n = p.len();
        let width = signs.len();
        // a pruned list holds every pair with history: the carry reads it
        // as it reads a full one
        let listed = self.listed();
        self.outer = None;
        self.x_pruned.clear();
        let images = stencil_images(dom.lengths());
        let carry = self.carry_source(p, width);
        let mut built = None;
        if n > 0 {
            let rmax = p.radius.iter().cloned().fold(0.0, f64::max);
            // extra range is per type pair: its maximum over the present types
            let mut rep: Vec<(u32, usize)> = Vec::new();
            for (i, &t) in p.kind.iter().enumerate() {
                if !rep.iter().any(|&(u, _)| u == t) {
                    rep.push((t, i));
                }
            }
            let emax = rep.iter().flat_map(|&(_, i)| rep.iter().map(move |&(_, j)| (i, j))).map(|(i, j)| extra_range(i, j)).fold(0.0, f64::max);
            let grid = Grid::new(p, dom, 2.0 * rmax + s.skin + emax);
            let per_particle = listed / self.x_built.len().max(1);
            let image_rank = image_ranks(&images);
            let ctx = BuildCtx { p, s, grid: &grid, images: &images, image_rank, extra_range: &extra_range, old: &carry, width, per_particle };
            let found = in_chunks(n, CHUNK, |r| ctx.find(r));
            let (fstart, foreign) = foreign_by_first(&found, n);
            // each chunk's pairs, its own and those its particles are first
            // of but others found, at their places in the list
            let counts: Vec<usize> =
                found.iter().enumerate().map(|(c, f)| f.own.len() + (fstart[((c + 1) * CHUNK).min(n)] - fstart[c * CHUNK]) as usize).collect();
            let m: usize = counts.iter().sum();
            let (mut b, mut hist) = self.places(m, width);
            let (a, image, keys) = (&mut self.a, &mut self.image, &mut self.keys);
            let mut jobs = Vec::with_capacity(counts.len());
            let (mut ra, mut rb, mut ri, mut rk, mut rh) = (&mut a[..], &mut b[..], &mut image[..], &mut keys[..], &mut hist[..]);
            for (c, &k) in counts.iter().enumerate() {
                let (pa, pb, pi, pk) = (cut(&mut ra, k), cut(&mut rb, k), cut(&mut ri, k), cut(&mut rk, k));
                jobs.push((c, Place { a: pa, b: pb, image: pi, keys: pk, hist: cut(&mut rh, k * width) }));
            }
            let write = |(c, out): (usize, Place<'_>)| ctx.chunk(c * CHUNK..((c + 1) * CHUNK).min(n), &found[c], &fstart, &foreign, out);
            if jobs.len() > 1 {
                jobs.into_par_iter().for_each(write);
            } else {
                jobs.into_iter().for_each(write);
            }
            built = Some((b, hist));
        }
        // the buffers the list before wrote its pairs' partners and history
        // in: the next build's
        let (by_id, old_b, old_hist) = match carry {
            Carry::ByIndex { b, hist, .. } => (None, b, hist),
            Carry::ById(old) => (Some(old), std::mem::take(&mut self.b), std::mem::take(&mut self.hist)),
            Carry::None => (None, std::mem::take(&mut self.b), std::mem::take(&mut self.hist)),
        };
        let (b, mut hist) = built.unwrap_or_else(|| self.places(0, width));
        self.spare = (old_b, old_hist);
        // the new list's pairs (none when no particle is left)
        let m = self.a.len();
        let a = &self.a;
        if let Some(old) = &by_id {
            // storage changed since the last build: match history by id
            // pair, turned where the pair's first particle changed
            for k in 0..m {
                let (ta, tb) = (p.tag[a[k] as usize], p.tag[b[k] as usize]);
                if let Some((was, h)) = old.get(&(ta.min(tb), ta.max(tb))) {
                    let out = &mut hist[k * width..(k + 1) * width];
                    if *was == (ta > tb) {
                        out.copy_from_slice(h);
                    } else {
                        for ((o, &v), &sign) in out.iter_mut().zip(h).zip(signs) {
                            *o = v * sign;
                        }
                    }
                }
            }
        }
        self.b = b;
        self.images = images;
        self.hist = hist;
        self.width = width;
        self.x_built.clear();
        self.x_built.extend_from_slice(&p.x);
        self.index(n);
        self.last_build = step;
        self.builds += 1;
    }

    /// The list's arrays sized for `m` pairs of `width` history values, to
    /// be written by a build: `a`, `image` and `keys` in place, and the
    /// second particles and history (returned) in the spare buffers, those
    /// of the list before the last build (the last one's history is read
    /// by the carry while the build writes). Every place is written, so
    /// only growth is filled; the history keeps room for a prune's extra
    /// entry.
    fn places(&mut self, m: usize, width: usize) -> (Vec<u32>, Vec<f64>) {
        fn sized<T: Clone>(v: &mut Vec<T>, m: usize, fill: T) {
            v.truncate(m);
            v.resize(m, fill);
        }
        let (mut b, mut hist) = std::mem::take(&mut self.spare);
        sized(&mut self.a, m, 0);
        sized(&mut b, m, 0);
        sized(&mut self.image, m, 0);
        sized(&mut self.keys, m, (0, 0));
        hist.truncate(m * width);
        hist.reserve((m + 1) * width - hist.len());
        sized(&mut hist, m * width, 0.0);
        (b, hist)
    }

    /// The buffer for a prune at `step`: twice what the fastest particle
    /// covers in [`PRUNE_STEPS`] steps at the speed the last check measured
    /// (since the last prune, or the last build while the list is full).
    pub fn next_buffer(&self, s: &NeighSettings, step: i64) -> f64 {
        let (d2, since) = if self.pruned() { (self.travel.pruned, step - self.pruned_at) } else { (self.travel.built, step - self.last_build) };
        let speed = d2.sqrt() / since.max(1) as f64;
        (2.0 * speed * PRUNE_STEPS).max(PRUNE_MIN * s.skin)
    }

    /// Whether a prune at `step` is worth its cost ([`PRUNE_COST`]): the
    /// last one dropped enough pairs that the force passes of the
    /// [`PRUNE_STEPS`] steps it is chosen for walk fewer pairs by more than
    /// it costs. A flowing scene (the chute) keeps most pairs within any
    /// buffer its speeds allow, and its list then stays full, to be tried
    /// again every [`PRUNE_RETRY`] builds (at a build: `step` is the last
    /// build's), since a scene settles.
    fn prune_pays(&mut self, step: i64) -> bool {
        if self.kept == 0.0 || pays(self.kept) || EVERY_PRUNE.is_on() {
            return true;
        }
        if step != self.last_build {
            return false;
        }
        if self.retry_in == 0 {
            return true;
        }
        self.retry_in -= 1;
        false
    }

    /// Keep of the full list the pairs within `buffer` beyond reach
    /// (touching plus the pair's `extra_range`) at the current positions,
    /// and every pair with history; or the full list when the buffer is too
    /// large to pay ([`PRUNE_MAX`]). Then index the pairs.
    ///
    /// The owner must then check every step, before the forces, that no
    /// particle moved half the buffer ([`PairList::travel`],
    /// [`PairList::prune_due`]) and prune again if one did: so a pair left
    /// out stays beyond reach, where it would add nothing and keep no
    /// history.
    pub fn prune<F: Fn(usize, usize) -> f64 + Sync>(&mut self, p: &Particles, s: &NeighSettings, buffer: f64, step: i64, extra_range: &F) {
        let n = p.len();
        // the last prune's buffer, written over (no fresh pages to fault in)
        let mut x_pruned = std::mem::take(&mut self.x_pruned);
        let mut half = 0.0;
        let listed = self.listed();
        if buffer < PRUNE_MAX * s.skin && buffer > 0.0 && n > 0 && !NO_PRUNE.is_on() && self.x_built.len() == n && self.prune_pays(step) {
            // positions in single precision and their largest rounding
            // error, which the check's limit leaves room for
            // (in fixed chunks, in parallel, written in place; the largest
            // error is a maximum, the same on any thread count)
            let (x0, x) = (&self.x_built[..], &p.x[..]);
            let fill = |c: usize, out: &mut [[f32; 4]]| -> f64 {
                let lo = c * CHUNK;
                let mut eps2: f64 = 0.0;
                for ((o, x), x0) in out.iter_mut().zip(&x[lo..]).zip(&x0[lo..]) {
                    let q = [x.x as f32, x.y as f32, x.z as f32];
                    let d = [x.x - q[0] as f64, x.y - q[1] as f64, x.z - q[2] as f64];
                    eps2 = eps2.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    // the distance from the build, rounded up twice over
                    let e = [q[0] as f64 - x0.x, q[1] as f64 - x0.y, q[2] as f64 - x0.z];
                    let e = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt() * (1.0 + 1e-9);
                    let up = e as f32;
                    *o = [q[0], q[1], q[2], if (up as f64) < e { up.next_up() } else { up }];
                }
                eps2
            };
            // every entry is written below: a buffer of the right length
            // is not cleared first
            x_pruned.resize(n, [0.0; 4]);
            let eps2 = if n > CHUNK {
                x_pruned.par_chunks_mut(CHUNK).enumerate().map(|(c, out)| fill(c, out)).reduce(|| 0.0, f64::max)
            } else {
                fill(0, &mut x_pruned[..])
            };
            // a relative margin for the rounding of the distances themselves
            half = 0.5 * buffer * (1.0 - 1e-9) - eps2.sqrt();
        }
        if !(half > 0.0) {
            if self.outer.is_some() {
                self.refilter(|_, _, _| true);
            } else {
                self.live_from_history();
            }
            x_pruned.clear();
        } else {
            let images = std::mem::take(&mut self.images);
            self.refilter(|i, j, img| {
                let d = p.x[i] - (p.x[j] + images[img as usize]);
                let reach = p.radius[i] + p.radius[j] + extra_range(i, j) + buffer;
                d.norm_squared() < reach * reach
            });
            self.images = images;
            self.kept = self.a.len() as f64 / listed.max(1) as f64;
            if !pays(self.kept) {
                self.retry_in = PRUNE_RETRY;
            }
            if self.outer.is_some() {
                self.prune_lim = half * half;
                self.buffer = buffer;
                self.pruned_at = step;
                self.prunes += 1;
            } else {
                x_pruned.clear();
            }
        }
        self.x_pruned = x_pruned;
        // `refilter` set the live flags
        self.index_blocks(n);
    }

    /// Keep of the full list (`outer`, or the list itself when full) every
    /// pair with history and those `near(a, b, image)`, with their history
    /// and live flags; the list is pruned after unless `near` kept every
    /// pair.
    ///
    /// Two passes over fixed chunks of the full list, in parallel, without
    /// a branch on the pairs' fate, which is a coin toss in a bed: the
    /// first decides each pair's fate and counts the chunk's kept pairs,
    /// the second copies them to their places.
    fn refilter(&mut self, near: impl Fn(usize, usize, u8) -> bool + Sync) {
        let w = self.width;
        // the pairs the list holds now
        let inner = self.a.len();
        let mut outer = match self.outer.take() {
            Some(o) => o,
            None => {
                // a fresh build: its history tells which pairs are live
                self.live_from_history();
                let m = self.a.len();
                let o = Outer {
                    a: std::mem::take(&mut self.a),
                    b: std::mem::take(&mut self.b),
                    image: std::mem::take(&mut self.image),
                    keys: std::mem::take(&mut self.keys),
                    inner: (0..m as u32).collect(),
                    keep: vec![],
                    spare: vec![],
                };
                Box::new(o)
            }
        };
        let m = outer.a.len();
        // one more flag and history for the pairs the list left out: not
        // live, zero history
        self.live.truncate(inner);
        self.live.push(0);
        self.hist.truncate(inner * w);
        self.hist.resize((inner + 1) * w, 0.0);
        let Outer { a, b, image, keys, inner: slot, keep, spare } = &mut *outer;
        let (a, b, image, keys) = (&a[..], &b[..], &image[..], &keys[..]);
        let (live, hist) = (&self.live, &self.hist);
        // each pair's fate, and how many each chunk keeps
        keep.resize(m, 0);
        let fate = |c: usize, kc: &mut [u8]| -> usize {
            let lo = c * PRUNE_CHUNK;
            let mut n = 0;
            for (q, kq) in kc.iter_mut().enumerate() {
                let k = lo + q;
                let old = (slot[k] as usize).min(inner);
                // both sides evaluated: no branch
                let kept = (live[old] & 1 != 0) | near(a[k] as usize, b[k] as usize, image[k]);
                *kq = kept as u8;
                n += kept as usize;
            }
            n
        };
        let counts: Vec<usize> = if m > PRUNE_CHUNK {
            keep.par_chunks_mut(PRUNE_CHUNK).enumerate().map(|(c, kc)| fate(c, kc)).collect()
        } else {
            vec![fate(0, &mut keep[..])]
        };
        let len: usize = counts.iter().sum();
        // the kept pairs, chunk by chunk at their places in the new list;
        // the buffers of the list before are reused (no fresh pages)
        let mut na = std::mem::take(&mut self.a);
        let mut nb = std::mem::take(&mut self.b);
        let mut ni = std::mem::take(&mut self.image);
        let mut nk = std::mem::take(&mut self.keys);
        let mut nl = vec![0u8; len];
        let mut nh = std::mem::take(spare);
        na.resize(len, 0);
        nb.resize(len, 0);
        ni.resize(len, 0);
        nk.resize(len, (0, 0));
        // every place is written below: only growth needs filling (a
        // clear first would fill the whole history, serially)
        nh.truncate(len * w);
        nh.resize(len * w, 0.0);
        let mut jobs = Vec::with_capacity(counts.len());
        {
            let (mut ra, mut rb, mut ri, mut rk, mut rl, mut rh) = (&mut na[..], &mut nb[..], &mut ni[..], &mut nk[..], &mut nl[..], &mut nh[..]);
            let mut rs = &mut slot[..];
            for (c, &n) in counts.iter().enumerate() {
                let slots = cut(&mut rs, PRUNE_CHUNK.min(m - c * PRUNE_CHUNK));
                jobs.push((c, cut(&mut ra, n), cut(&mut rb, n), cut(&mut ri, n), cut(&mut rk, n), cut(&mut rl, n), cut(&mut rh, n * w), slots));
            }
        }
        let offsets: Vec<usize> = counts.iter().scan(0, |o, &n| Some(std::mem::replace(o, *o + n))).collect();
        let keep = &keep[..];
        let copy = |(c, ca, cb, ci, ck, cl, ch, cs): PruneJob<'_>| {
            let (lo, off) = (c * PRUNE_CHUNK, offsets[c]);
            // the kept pairs' indices and old places, branch-free: every
            // pair is written at the next place, which moves on when kept
            let mut from = vec![(0u32, 0u32); cs.len() + 1];
            let mut t = 0;
            for (q, s) in cs.iter_mut().enumerate() {
                let k = lo + q;
                let kept = keep[k] != 0;
                from[t] = (k as u32, (*s as usize).min(inner) as u32);
                *s = if kept { (off + t) as u32 } else { NONE };
                t += kept as usize;
            }
            for (t, &(k, old)) in from[..ca.len()].iter().enumerate() {
                let (k, old) = (k as usize, old as usize);
                ca[t] = a[k];
                cb[t] = b[k];
                ci[t] = image[k];
                ck[t] = keys[k];
                cl[t] = live[old];
                // value by value: a copy of a few values of unknown count
                // would be a call to memcpy per pair
                for v in 0..w {
                    ch[t * w + v] = hist[old * w + v];
                }
            }
        };
        if jobs.len() > 1 {
            jobs.into_par_iter().for_each(copy);
        } else {
            jobs.into_iter().for_each(copy);
        }
        *spare = std::mem::take(&mut self.hist);
        (self.a, self.b, self.image, self.keys, self.live, self.hist) = (na, nb, ni, nk, nl, nh);
        if len < m {
            self.outer = Some(outer);
        }
    }

    /// Each pair's live flag from its history (after a build or restart).
    fn live_from_history(&mut self) {
        let w = self.width;
        self.live.clear();
        // room for the prune's extra flag (a push beyond the capacity would
        // copy the flags to fresh pages)
        self.live.reserve(self.a.len() + 1);
        // an OR over each pair's values, not `any`: whether a listed pair has
        // history is a coin toss, and `any`'s early exit a branch on it
        // (1% of the chute's run)
        if w > 0 {
            self.live.extend(self.hist[..self.a.len() * w].chunks_exact(w).map(|h| h.iter().fold(false, |acc, &v| acc | (v != 0.0)) as u8));
        } else {
            self.live.resize(self.a.len(), 0);
        }
    }

    /// The list with every pair of the last build and its history, as if it
    /// had not been pruned (for a restart file).
    pub fn full(&self, n: usize) -> PairList {
        let mut l = self.unpruned();
        if self.outer.is_some() {
            l.index(n);
        }
        l
    }

    /// [`PairList::full`] without the derived indexes: for a list that no
    /// longer fits the particles (deleted or inserted since its build), whose
    /// ids and histories the next build carries over.
    pub fn unpruned(&self) -> PairList {
        let mut l = self.clone();
        if l.outer.is_some() {
            l.refilter(|_, _, _| true);
            l.x_pruned.clear();
        }
        l
    }

    /// Whether the list was built for the particles as they are (no
    /// particle inserted, deleted or reordered since its build).
    pub fn fits(&self, n: usize) -> bool {
        self.x_built.len() == n && self.a.iter().chain(&self.b).all(|&k| (k as usize) < n)
    }

    /// Where the next build finds the history of pairs listed now: by storage
    /// index when every pair's stored ids still match the particles at its
    /// indices (nothing was inserted, deleted or reordered since), by id pair
    /// otherwise. Only pairs with some non-zero history are carried.
    fn carry_source(&mut self, p: &Particles, width: usize) -> Carry {
        if self.width != width || width == 0 || self.a.is_empty() {
            return Carry::None;
        }
        let n = p.len();
        // a pass over every pair's ids, on the pool's threads (a bool: the
        // same on any thread count)
        let same = self.keys.len() == self.a.len()
            && self
                .a
                .par_iter()
                .zip(&self.b)
                .zip(&self.keys)
                .with_min_len(CHUNK)
                .all(|((&i, &j), &key)| (i as usize) < n && (j as usize) < n && (p.tag[i as usize], p.tag[j as usize]) == key);
        if same {
            let mut start = vec![0u32; n + 1];
            for &i in &self.a {
                start[i as usize + 1] += 1;
            }
            for i in 0..n {
                start[i + 1] += start[i];
            }
            return Carry::ByIndex { start, b: std::mem::take(&mut self.b), hist: std::mem::take(&mut self.hist) };
        }
        let mut old: HashMap<(i64, i64), (bool, Vec<f64>), BuildHasherDefault<IdHasher>> = HashMap::default();
        for (k, h) in self.hist.chunks_exact(width).enumerate() {
            if h.iter().any(|&v| v != 0.0) {
                if let Some(&(ta, tb)) = self.keys.get(k) {
                    // of two images of one pair, the later one is kept
                    old.insert((ta.min(tb), ta.max(tb)), (ta > tb, h.to_vec()));
                }
            }
        }
        Carry::ById(old)
    }

    /// Particles per force block.
    pub fn block_size(&self) -> usize {
        if self.block == 0 {
            BLOCK
        } else {
            self.block
        }
    }

    /// Derived indexes of the pairs `a`, `b` of `n` particles: the live
    /// flags, the pair range of each force block and the cross pairs of
    /// each particle. Called after every build, prune and restart.
    pub fn index(&mut self, n: usize) {
        self.live_from_history();
        self.index_blocks(n);
    }

    /// [`PairList::index`] but for the live flags, which are set.
    fn index_blocks(&mut self, n: usize) {
        let bs = self.block_size();
        let nblocks = n.div_ceil(bs).max(1);
        // a particle's block by a shift, not a division (~25 cycles each, a
        // few per pair: most of this pass's time when a prune calls it)
        assert!(bs.is_power_of_two(), "force blocks of {bs} particles: not a power of two");
        let sh = bs.trailing_zeros();
        // the pairs are sorted by a: each block's are a range
        debug_assert!(self.a.windows(2).all(|w| w[0] <= w[1]), "pairs not sorted by their first particle");
        let a = &self.a[..];
        self.block_start = (0..=nblocks).map(|q| a.partition_point(|&i| (i as usize >> sh) < q) as u32).collect();
        // each block's cross pairs (those whose b lies in another block), in
        // pair order, each with its place among them when sorted by b (then
        // pair index): the slots of the block's range go in that order, so
        // the cross pass, particle after particle, reads each block's range
        // in order instead of at random. Blocks in parallel.
        let (b, starts) = (&self.b[..], &self.block_start[..]);
        let per: Vec<Vec<u32>> = in_chunks(nblocks, 1, |r| {
            let q = r.start;
            (starts[q]..starts[q + 1]).filter(|&k| b[k as usize] as usize >> sh != q).collect()
        });
        self.block_cross = std::iter::once(0)
            .chain(per.iter().scan(0u32, |c, ks| {
                *c += ks.len() as u32;
                Some(*c)
            }))
            .collect();
        let total = *self.block_cross.last().unwrap_or(&0) as usize;
        // each particle lists the slots where it is b, in increasing pair
        // index (the order its shares are added): blocks in order, each
        // block's cross pairs in pair order. A counting sort by b: the
        // entries in that order are also each block's cross pairs sorted by
        // b, then pair index, which numbers the places (no sort per block)
        let mut ccount = std::mem::take(&mut self.cross_start);
        ccount.clear();
        ccount.resize(n + 1, 0);
        for ks in &per {
            for &k in ks {
                ccount[b[k as usize] as usize + 1] += 1;
            }
        }
        for i in 0..n {
            ccount[i + 1] += ccount[i];
        }
        // the entry at each place of the sorted order: its block and its
        // rank among the block's cross pairs in pair order
        let mut fill = ccount.clone();
        let mut at = vec![(0u32, 0u32); total];
        self.cross_b.clear();
        self.cross_b.resize(total, 0);
        for (q, ks) in per.iter().enumerate() {
            for (c, &k) in ks.iter().enumerate() {
                let i = b[k as usize];
                at[fill[i as usize] as usize] = (q as u32, c as u32);
                self.cross_b[fill[i as usize] as usize] = i;
                fill[i as usize] += 1;
            }
        }
        // in that order, each block's entries come sorted by b, then pair
        // index: their places in the block's range, counted. The force pass
        // finds the n-th cross pair of its walk at `xslot[n]`, its place.
        self.xslot.clear();
        self.xslot.resize(total, 0);
        self.cross.clear();
        self.cross.resize(total, 0);
        let mut next = vec![0u32; nblocks];
        for (pos, &(q, c)) in at.iter().enumerate() {
            let (q, base) = (q as usize, self.block_cross[q as usize]);
            self.xslot[(base + c) as usize] = next[q];
            self.cross[pos] = base + next[q];
            next[q] += 1;
        }
        self.cross_start = ccount;
        // which blocks each block's pairs reach
        self.block_touch_start.clear();
        self.block_touch_start.push(0);
        self.block_touch.clear();
        self.block_deps.clear();
        self.block_deps.resize(nblocks, 1);
        self.forward = true;
        let mut reach: Vec<u32> = Vec::new();
        for (q, ks) in per.iter().enumerate() {
            reach.clear();
            reach.extend(ks.iter().map(|&k| (b[k as usize] as usize >> sh) as u32));
            reach.sort_unstable();
            reach.dedup();
            for &r in &reach {
                self.forward &= r as usize > q;
                self.block_deps[r as usize] += 1;
            }
            self.block_touch.extend_from_slice(&reach);
            self.block_touch_start.push(self.block_touch.len() as u32);
        }
    }

    /// Each particle's pairs in increasing pair index, as CSR offsets per
    /// particle (n + 1 of them) and pair indices, the high bit ([`ADJ_B`])
    /// marking pairs where the particle is `b` (for a restart file and
    /// diagnostics; the force pass does not need it).
    pub fn adjacency(&self, n: usize) -> (Vec<u32>, Vec<u32>) {
        let m = self.a.len();
        let mut start = vec![0u32; n + 1];
        for k in 0..m {
            start[self.a[k] as usize + 1] += 1;
            start[self.b[k] as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut adj = vec![0; 2 * m];
        for k in 0..m {
            let (a, b) = (self.a[k] as usize, self.b[k] as usize);
            adj[fill[a] as usize] = k as u32;
            fill[a] += 1;
            adj[fill[b] as usize] = k as u32 | ADJ_B;
            fill[b] += 1;
        }
        (start, adj)
    }

    /// The pairs' history and live flags, taken out of the list for a force
    /// pass (the flags set for every pair if they are not sized for the
    /// list); [`PairList::put_history`] gives them back.
    pub fn take_history(&mut self) -> (Vec<f64>, Vec<u8>) {
        if self.live.len() != self.a.len() {
            self.live = vec![1; self.a.len()];
        }
        (std::mem::take(&mut self.hist), std::mem::take(&mut self.live))
    }

    /// Give back what [`PairList::take_history`] took.
    pub fn put_history(&mut self, hist: Vec<f64>, live: Vec<u8>) {
        (self.hist, self.live) = (hist, live);
    }

    /// Whether the list is indexed for `n` particles.
    pub fn indexed(&self, n: usize) -> bool {
        self.cross_start.len() == n + 1
    }

    /// Atom ids were renumbered (`delete_atoms ... compress yes`; `new_id`
    /// holds the ids that changed): carry the history keys over.
    pub fn retag(&mut self, new_id: &HashMap<i64, i64>) {
        let map = |t: i64| new_id.get(&t).copied().unwrap_or(t);
        let outer = self.outer.iter_mut().flat_map(|o| o.keys.iter_mut());
        for k in self.keys.iter_mut().chain(outer) {
            *k = (map(k.0), map(k.1));
        }
    }
    /// Forget all pairs and history (after particles were reordered or removed
    /// the list must be rebuilt before use; history is kept by id).
    pub fn invalidate(&mut self) {
        self.x_built.clear();
    }
}

/// What a step owes the pair list ([`PairList::due`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Due {
    /// Build it.
    Build,
    /// Build it if a particle moved more than half the skin.
    Check,
    /// Keep it.
    Skip,
}

/// Storage order that sorts particles by the Morton (Z-order) code of their
/// bin of size `bin`, ties by current index: neighbours in space become
/// neighbours in memory, and a contiguous block of particles is a compact
/// region (few pairs cross blocks).
pub fn spatial_order(p: &Particles, bin: f64) -> Vec<usize> {
    let n = p.len();
    if n == 0 || !(bin > 0.0) {
        return (0..n).collect();
    }
    let mut lo = [f64::INFINITY; 3];
    for x in &p.x {
        for d in 0..3 {
            lo[d] = lo[d].min(x[d]);
        }
    }
    let spread = |v: u64| -> u64 {
        // 21 bits -> every third bit
        let mut v = v & 0x1f_ffff;
        v = (v | v << 32) & 0x1f00000000ffff;
        v = (v | v << 16) & 0x1f0000ff0000ff;
        v = (v | v << 8) & 0x100f00f00f00f00f;
        v = (v | v << 4) & 0x10c30c30c30c30c3;
        (v | v << 2) & 0x1249249249249249
    };
    let mut keys: Vec<(u64, usize)> = (0..n)
        .map(|i| {
            let c = |d: usize| -> u64 {
                let k = ((p.x[i][d] - lo[d]) / bin).floor();
                if k.is_finite() {
                    k.clamp(0.0, 2097151.0) as u64
                } else {
                    0
                }
            };
            (spread(c(0)) | spread(c(1)) << 1 | spread(c(2)) << 2, i)
        })
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(|(_, i)| i).collect()
}

/// `k.rem_euclid(n)` (`n > 0`) without the division where `k` is within
/// the box or one box out, as nearly every particle's bin is: the grid
/// bins each particle twice a build, and the remainder's division was most
/// of that.
#[inline]
fn wrap_bin(k: i64, n: i64) -> i64 {
    if (0..n).contains(&k) {
        k
    } else if (-n..0).contains(&k) {
        k + n
    } else if (n..2 * n).contains(&k) {
        k - n
    } else {
        k.rem_euclid(n)
    }
}

/// The 27 shifts a cell stencil reaches in a box of side lengths `lens`,
/// indexed by the cell offset (x fastest, -1, 0, 1 on each axis).
fn stencil_images(lens: V3) -> Vec<V3> {
    (0..27).map(|c: i64| V3::new((c % 3 - 1) as f64 * lens[0], ((c / 3) % 3 - 1) as f64 * lens[1], (c / 9 - 1) as f64 * lens[2])).collect()
}

/// A found pair's sort key: by partner, then by shift ([`image_ranks`]).
#[inline]
fn pair_key(j: u32, img: u8, rank: &[u8; 27]) -> u64 {
    (j as u64) << 8 | rank[img as usize] as u64
}

/// Each image's rank in the order [`cmp_v3`] gives their shifts (the
/// number of shifts below it; equal shifts, equal ranks), so that
/// `(partner, rank)` compares as `(partner, shift)` does.
fn image_ranks(images: &[V3]) -> [u8; 27] {
    std::array::from_fn(|k| images.get(k).map_or(0, |v| images.iter().filter(|m| cmp_v3(m, v).is_lt()).count() as u8))
}

fn cmp_v3(a: &V3, b: &V3) -> std::cmp::Ordering {
    for d in 0..3 {
        match a[d].partial_cmp(&b[d]) {
            Some(std::cmp::Ordering::Equal) | None => continue,
            Some(o) => return o,
        }
    }
    std::cmp::Ordering::Equal
}

/// Uniform bins over the box (particles outside non-periodic sides go to the
/// edge bins).
struct Grid {
    lo: [f64; 3],
    size: [f64; 3],
    dims: [i64; 3],
    periodic: [bool; 3],
    start: Vec<u32>,
    items: Vec<u32>,
    /// Per axis and bin coordinate: the coordinate and image shift of the
    /// bins at offsets -1, 0, 1 (coordinate -1: none, a non-periodic edge).
    axis: [Vec<[(i64, i64); 3]>; 3],
}

impl Grid {
    fn new(p: &Particles, dom: &Domain, cut: f64) -> Grid {
        let mut lo = [0.0; 3];
        let mut size = [0.0; 3];
        let mut dims = [1i64; 3];
        let mut periodic = [false; 3];
        for d in 0..3 {
            periodic[d] = dom.periodic(d);
            let (mut a, mut b) = (dom.lo[d], dom.hi[d]);
            if !periodic[d] {
                for x in &p.x {
                    a = a.min(x[d]);
                    b = b.max(x[d]);
                }
            }
            let len = (b - a).max(cut);
            let nb = ((len / cut).floor() as i64).clamp(1, 1 << 10);
            lo[d] = a;
            dims[d] = nb;
            size[d] = len / nb as f64;
        }
        // cap the total number of bins to a few per particle
        let mut total = dims[0] * dims[1] * dims[2];
        let cap = (8 * p.len() as i64).max(64);
        while total > cap {
            for d in 0..3 {
                if dims[d] > 1 && !(periodic[d] && dims[d] <= 3) {
                    let len = size[d] * dims[d] as f64;
                    dims[d] = (dims[d] / 2).max(1);
                    size[d] = len / dims[d] as f64;
                }
            }
            let nt = dims[0] * dims[1] * dims[2];
            if nt == total {
                break;
            }
            total = nt;
        }
        let axis = std::array::from_fn(|d| {
            (0..dims[d])
                .map(|k| {
                    std::array::from_fn(|o| {
                        let q = k + o as i64 - 1;
                        if periodic[d] {
                            let w = q.rem_euclid(dims[d]);
                            (w, (q - w) / dims[d])
                        } else if q < 0 || q >= dims[d] {
                            (-1, 0)
                        } else {
                            (q, 0)
                        }
                    })
                })
                .collect()
        });
        let mut g = Grid { lo, size, dims, periodic, start: vec![], items: vec![], axis };
        let ncell = (dims[0] * dims[1] * dims[2]) as usize;
        let cells: Vec<usize> = p.x.iter().map(|x| g.index(g.cell_of(x))).collect();
        let mut count = vec![0u32; ncell + 1];
        for &c in &cells {
            count[c + 1] += 1;
        }
        for c in 0..ncell {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; p.len()];
        for (i, &c) in cells.iter().enumerate() {
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        g.start = count;
        g.items = items;
        g
    }
    fn cell_of(&self, x: &V3) -> [i64; 3] {
        let mut c = [0i64; 3];
        for d in 0..3 {
            let mut k = ((x[d] - self.lo[d]) / self.size[d]).floor() as i64;
            if self.periodic[d] {
                k = wrap_bin(k, self.dims[d]);
            } else {
                k = k.clamp(0, self.dims[d] - 1);
            }
            c[d] = k;
        }
        c
    }
    fn index(&self, c: [i64; 3]) -> usize {
        ((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]) as usize
    }
    /// The half stencil of bin `c`: the bin itself and the 13 of the
    /// 26 around it at offsets (dz, dy, dx) lexicographically positive
    /// (fewer at non-periodic edges). Each pair of particles and image is
    /// then met once: from one particle at offset o, or from the other at
    /// -o, or (o = 0, the own bin) from both. Each bin's members, the
    /// image index of their shift and whether the bin is `c` itself. Bins
    /// whose members follow each other in `items` with the same shift (those
    /// along x, away from a periodic seam) make one run: a bin holds one or
    /// two particles, and a loop per bin cost more than its tests.
    fn stencil(&self, c: [i64; 3], out: &mut Vec<Run>) {
        let (ax, ay, az) = (&self.axis[0][c[0] as usize], &self.axis[1][c[1] as usize], &self.axis[2][c[2] as usize]);
        for (oz, &(nz, sz)) in az.iter().enumerate() {
            for (oy, &(ny, sy)) in ay.iter().enumerate() {
                for (ox, &(nx, sx)) in ax.iter().enumerate() {
                    let (own, forward) = ((oz, oy, ox) == (1, 1, 1), (oz, oy, ox) > (1, 1, 1));
                    if nx < 0 || ny < 0 || nz < 0 || !(own || forward) {
                        continue;
                    }
                    let img = ((sx + 1) + 3 * (sy + 1) + 9 * (sz + 1)) as u8;
                    let cell = self.index([nx, ny, nz]);
                    let (lo, hi) = (self.start[cell], self.start[cell + 1]);
                    match out.last_mut() {
                        Some(r) if r.hi == lo && r.img == img && !r.own && !own => r.hi = hi,
                        _ => out.push(Run { lo, hi, img, own }),
                    }
                }
            }
        }
    }
}

/// Stencil bins whose members follow each other in [`Grid::items`]
/// (`lo..hi`), all seen at the image `img`; `own`: the particle's own bin.
#[derive(Clone, Copy)]
struct Run {
    lo: u32,
    hi: u32,
    img: u8,
    own: bool,
}

#[cfg(test)]
mod tests {
    use super::super::domain::Side;
    use super::super::particles::NewParticle;
    use super::*;

    fn part(tag: i64, x: V3, r: f64) -> NewParticle {
        NewParticle { tag, kind: 1, mask: 1, x, v: V3::zeros(), omega: V3::zeros(), radius: r, density: 1.0 }
    }

    /// Whether a shift is lexicographically positive, by z, then y, then x
    /// ((0, 0, 0) is not): the images of a particle with itself that the
    /// list keeps (the half stencil's offsets, which for a particle and
    /// itself are its shifts).
    fn positive(sh: [i64; 3]) -> bool {
        for d in (0..3).rev() {
            if sh[d] != 0 {
                return sh[d] > 0;
            }
        }
        false
    }

    /// The bin wrap agrees with the remainder everywhere, in the box, one
    /// box out and far out (it fails if a branch is off by one).
    #[test]
    fn wrap_bin_is_the_remainder() {
        for n in [1i64, 2, 3, 7, 64] {
            for k in -5 * n - 3..5 * n + 3 {
                assert_eq!(wrap_bin(k, n), k.rem_euclid(n), "k {k} n {n}");
            }
        }
        assert_eq!(wrap_bin(i64::MIN + 1, 5), (i64::MIN + 1).rem_euclid(5));
    }

    /// Sorting by (partner, image rank) moves exactly as sorting by
    /// (partner, shift) with the vectors compared: the same order for every
    /// list, duplicate shifts (a zero box length) among the images.
    #[test]
    fn image_rank_orders_as_the_shifts() {
        let images = stencil_images(V3::new(2.0, 3.0, 0.0));
        let rank = image_ranks(&images);
        for u in 0..27 {
            for v in 0..27 {
                assert_eq!(rank[u].cmp(&rank[v]), cmp_v3(&images[u], &images[v]), "images {u} {v}");
            }
        }
        let mut u = lcg(12345);
        let mut next = |m: u64| (u() * m as f64) as u64;
        for _ in 0..200 {
            let list: Vec<(u32, u8)> = (0..next(9)).map(|_| (next(4) as u32, next(27) as u8)).collect();
            let mut by_vectors = list.clone();
            by_vectors.sort_unstable_by(|u, v| u.0.cmp(&v.0).then_with(|| cmp_v3(&images[u.1 as usize], &images[v.1 as usize])));
            let mut by_key = list;
            by_key.sort_unstable_by_key(|&(j, img)| pair_key(j, img, &rank));
            assert_eq!(by_key, by_vectors);
        }
    }

    /// Brute-force all (i, j, image) pairs within reach.
    fn brute(p: &Particles, dom: &Domain, skin: f64) -> Vec<(i64, i64, [i64; 3])> {
        let mut out = vec![];
        let l = dom.lengths();
        for i in 0..p.len() {
            for j in i..p.len() {
                for sx in -1..=1i64 {
                    for sy in -1..=1i64 {
                        for sz in -1..=1i64 {
                            let sh = [sx, sy, sz];
                            if (0..3).any(|d| sh[d] != 0 && !dom.periodic(d)) {
                                continue;
                            }
                            if i == j && !positive(sh) {
                                continue;
                            }
                            let s = V3::new(sx as f64 * l[0], sy as f64 * l[1], sz as f64 * l[2]);
                            let d = p.x[i] - (p.x[j] + s);
                            if d.norm() < p.radius[i] + p.radius[j] + skin {
                                // the smaller storage index first
                                out.push((p.tag[i], p.tag[j], sh));
                            }
                        }
                    }
                }
            }
        }
        out.sort();
        out
    }

    #[test]
    fn binned_list_equals_brute_force_with_periodic_images() {
        // y spans 3, 2 and 1 bins: the stencil's runs meet the periodic
        // seam; the sparse boxes have empty bins between runs
        for (ly, n) in [(2.5, 300), (1.5, 300), (1.0, 300), (1.5, 40), (1.0, 25)] {
            binned_list_equals_brute_force_in(ly, n);
        }
    }

    fn binned_list_equals_brute_force_in(ly: f64, n: i64) {
        let sides = [[Side::Periodic; 2], [Side::Periodic; 2], [Side::Fixed; 2]];
        let dom = Domain::new([0.0; 3], [4.0, ly, 6.0], sides, 3);
        let mut p = Particles::default();
        let mut seed = 12345u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for t in 0..n {
            let x = V3::new(4.0 * rnd(), ly * rnd(), 6.0 * rnd());
            p.push(part(1000 - t, x, 0.2 + 0.1 * rnd()));
        }
        let s = NeighSettings { skin: 0.1, ..Default::default() };
        let mut pl = PairList::default();
        pl.build(&p, &dom, &s, 0, &[1.0; 2], |_, _| 0.0);
        let l = dom.lengths();
        let mut got: Vec<(i64, i64, [i64; 3])> = (0..pl.len())
            .map(|k| {
                let sh = pl.shift(k);
                let c = [(sh[0] / l[0]).round() as i64, (sh[1] / l[1]).round() as i64, (sh[2] / l[2]).round() as i64];
                (p.tag[pl.a[k] as usize], p.tag[pl.b[k] as usize], c)
            })
            .collect();
        got.sort();
        assert_eq!(got, brute(&p, &dom, 0.1));
        assert!(!got.is_empty());
        // every pair appears twice in the adjacency, in increasing pair order
        let (adj_start, adj) = pl.adjacency(p.len());
        assert_eq!(adj.len(), 2 * pl.len());
        for i in 0..p.len() {
            let s = &adj[adj_start[i] as usize..adj_start[i + 1] as usize];
            assert!(s.windows(2).all(|w| (w[0] & !ADJ_B) < (w[1] & !ADJ_B)));
        }
    }

    /// Uniform numbers in [0, 1) from `seed`.
    fn lcg(mut s: u64) -> impl FnMut() -> f64 {
        move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// 800 spheres of radius 0.1-0.15 at random in a periodic box of side 4.
    fn gas(u: &mut impl FnMut() -> f64) -> (Domain, Particles) {
        gas_of(u, 800)
    }

    /// `n` spheres of radius 0.1-0.15 at random in a periodic cube, as
    /// dense as [`gas`].
    fn gas_of(u: &mut impl FnMut() -> f64, n: i64) -> (Domain, Particles) {
        let side = 4.0 * (n as f64 / 800.0).cbrt();
        let dom = Domain::new([0.0; 3], [side; 3], [[Side::Periodic; 2]; 3], 3);
        let mut p = Particles::default();
        for t in 1..=n {
            p.push(part(t, V3::new(side * u(), side * u(), side * u()), 0.1 + 0.05 * u()));
        }
        (dom, p)
    }

    #[test]
    fn skin_check_bounded_by_the_prune_decides_as_the_exact_one() {
        let mut u = lcg(9);
        let (dom, mut p) = gas(&mut u);
        let settings = NeighSettings { skin: 0.2, ..Default::default() };
        let lim = settings.skin_limit();
        let mut pl = PairList::default();
        pl.build(&p, &dom, &settings, 0, &[1.0], |_, _| 0.0);
        let x0 = p.x.clone();
        let mut trials = [0; 2];
        for round in 0..200 {
            // moved since the build, then pruned, then moved again: each
            // leg up to most of the half skin, so both sides of the limit
            let mut leg = |scale: f64, x: &mut Vec<V3>| {
                for x in x.iter_mut() {
                    *x += V3::new(u() - 0.5, u() - 0.5, u() - 0.5) * scale;
                }
            };
            p.x = x0.clone();
            leg(0.1, &mut p.x);
            pl.kept = 0.0;
            pl.prune(&p, &settings, 0.01, round, &|_, _| 0.0);
            assert!(pl.pruned());
            leg(0.15 * (round % 4) as f64, &mut p.x);
            let exact = p.x.iter().zip(&x0).map(|(x, x0)| (x - x0).norm_squared()).fold(0.0, f64::max);
            let t = pl.travel_all(&p.x, Some(lim));
            assert_eq!(t.built > lim, exact > lim, "round {round}: {} against {exact}", t.built);
            assert!(t.built >= exact);
            assert_eq!(t, pl.travel(&p.x, 0, Some(lim)));
            trials[(exact > lim) as usize] += 1;
        }
        // both outcomes were tried
        assert!(trials[0] > 20 && trials[1] > 20, "{trials:?}");
    }

    #[test]
    fn prunes_that_keep_most_pairs_stop_until_a_retry() {
        let mut u = lcg(5);
        let (dom, p) = gas(&mut u);
        let settings = NeighSettings { skin: 0.2, ..Default::default() };
        let mut pl = PairList::default();
        // history on 5 pairs of 6: a prune keeps those, too many to pay
        let flow = |pl: &mut PairList| {
            for k in 0..pl.len() {
                pl.hist[k] = if k % 6 == 0 { 0.0 } else { 1.0 };
            }
            pl.index(p.len());
        };
        pl.build(&p, &dom, &settings, 0, &[1.0], |_, _| 0.0);
        flow(&mut pl);
        pl.prune(&p, &settings, 0.02, 0, &|_, _| 0.0);
        assert!(pl.pruned() && pl.prunes == 1);
        assert!(!pays(pl.kept) && pl.kept < 1.0, "kept {}", pl.kept);
        // the next prune between builds is not worth it: the list is full
        let m = pl.listed();
        pl.prune(&p, &settings, 0.02, 5, &|_, _| 0.0);
        assert!(!pl.pruned() && pl.prunes == 1 && pl.len() == m);
        // nor at the next PRUNE_RETRY builds; the one after tries again
        for b in 1..=PRUNE_RETRY as i64 + 1 {
            pl.build(&p, &dom, &settings, 10 * b, &[1.0], |_, _| 0.0);
            if b == PRUNE_RETRY as i64 + 1 {
                // the scene settled: most pairs lost their history
                pl.hist.fill(0.0);
                pl.index(p.len());
            }
            pl.prune(&p, &settings, 0.02, 10 * b, &|_, _| 0.0);
            assert_eq!(pl.pruned(), b == PRUNE_RETRY as i64 + 1, "build {b}");
        }
        assert!(pl.prunes == 2 && pays(pl.kept), "kept {}", pl.kept);
        // and prunes between builds pay again
        pl.prune(&p, &settings, 0.02, 55, &|_, _| 0.0);
        assert!(pl.pruned() && pl.prunes == 3);
    }

    #[test]
    fn prune_keeps_pairs_near_and_with_history_and_gives_them_back() {
        prune_keeps_in(800, false);
        // a list of several chunks of the prune's parallel passes
        prune_keeps_in(20_000, true);
    }

    fn prune_keeps_in(n: i64, chunks: bool) {
        let mut u = lcg(3);
        let (dom, mut p) = gas_of(&mut u, n);
        let settings = NeighSettings { skin: 0.2, ..Default::default() };
        let mut pl = PairList::default();
        pl.build(&p, &dom, &settings, 0, &[1.0; 2], |_, _| 0.0);
        assert_eq!(pl.len() > 2 * PRUNE_CHUNK, chunks, "{} pairs", pl.len());
        // history on every 7th pair, touching or not
        for k in (0..pl.len()).step_by(7) {
            pl.hist[2 * k + 1] = k as f64 + 1.0;
        }
        pl.index(p.len());
        let full = pl.clone();
        let near = |k: usize, x: &[V3], buffer: f64| {
            let (a, b) = (full.a[k] as usize, full.b[k] as usize);
            (x[a] - (x[b] + full.shift(k))).norm() < p.radius[a] + p.radius[b] + buffer
        };
        // the pairs kept, as indices into the full list
        let kept = |pl: &PairList| -> Vec<usize> { (0..full.len()).filter(|&k| pl.outer.as_ref().unwrap().inner[k] != NONE).collect() };
        pl.prune(&p, &settings, 0.02, 0, &|_, _| 0.0);
        let want: Vec<usize> = (0..full.len()).filter(|&k| k % 7 == 0 || near(k, &p.x, 0.02)).collect();
        assert_eq!(kept(&pl), want);
        assert!(pl.len() < full.len() / 2, "{} of {} pairs kept", pl.len(), full.len());
        for (q, &k) in want.iter().enumerate() {
            assert_eq!((pl.a[q], pl.b[q], pl.image[q], pl.keys[q]), (full.a[k], full.b[k], full.image[k], full.keys[k]));
            assert_eq!(&pl.hist[2 * q..2 * q + 2], &full.hist[2 * k..2 * k + 2]);
        }
        assert_eq!(pl.prunes, 1);
        assert!(pl.pruned() && pl.indexed(p.len()));
        // each particle's single-precision position, and a bound on its
        // distance from the build (none moved yet: the rounding's)
        assert_eq!(pl.x_pruned.len(), p.len());
        for (q, x) in pl.x_pruned.iter().zip(&p.x) {
            assert_eq!([q[0], q[1], q[2]], [x.x as f32, x.y as f32, x.z as f32]);
            let e = V3::new(q[0] as f64, q[1] as f64, q[2] as f64) - x;
            assert!(q[3] as f64 >= e.norm() && q[3] < 1e-6, "{q:?}");
        }
        // the force pass changes history: a pair touching now gets some, and
        // every 7th loses its own (as pairs that came apart do)
        for q in 0..pl.len() {
            pl.hist[2 * q] = if pl.hist[2 * q + 1] != 0.0 { 0.0 } else { 1.0 + q as f64 };
            pl.hist[2 * q + 1] = 0.0;
        }
        pl.index(p.len());
        let after: Vec<f64> = pl.hist.clone();
        let was = kept(&pl);
        // particles move; a prune with a wider buffer keeps pairs with history
        for x in p.x.iter_mut() {
            *x += V3::new(0.01, -0.005, 0.003);
        }
        pl.prune(&p, &settings, 0.05, 5, &|_, _| 0.0);
        let live = |k: usize| was.iter().position(|&j| j == k).is_some_and(|q| after[2 * q] != 0.0);
        let want: Vec<usize> = (0..full.len()).filter(|&k| live(k) || near(k, &p.x, 0.05)).collect();
        assert_eq!(kept(&pl), want);
        // and the full list comes back with each pair's latest history
        let back = pl.full(p.len());
        assert!(back.outer.is_none() && !back.pruned());
        assert_eq!((&back.a, &back.b, &back.image, &back.keys), (&full.a, &full.b, &full.image, &full.keys));
        for k in 0..full.len() {
            let h = was.iter().position(|&j| j == k).map_or([0.0, 0.0], |q| [after[2 * q], after[2 * q + 1]]);
            assert_eq!(&back.hist[2 * k..2 * k + 2], &h, "pair {k}");
        }
        // a buffer of half the skin or more keeps the full list
        pl.prune(&p, &settings, 0.1, 6, &|_, _| 0.0);
        assert!(pl.outer.is_none() && !pl.pruned());
        assert_eq!(pl.hist, back.hist);
    }

    #[test]
    fn history_follows_ids_across_rebuild_and_reorder() {
        let sides = [[Side::Fixed; 2]; 3];
        let dom = Domain::new([0.0; 3], [10.0; 3], sides, 3);
        let mut p = Particles::default();
        p.push(part(7, V3::new(1.0, 1.0, 1.0), 0.5));
        p.push(part(3, V3::new(1.9, 1.0, 1.0), 0.5));
        p.push(part(5, V3::new(5.0, 5.0, 5.0), 0.5));
        let s = NeighSettings::default();
        let signs = [-1.0, 1.0, -1.0];
        let mut pl = PairList::default();
        pl.build(&p, &dom, &s, 0, &signs, |_, _| 0.0);
        assert_eq!(pl.len(), 1);
        assert_eq!(p.tag[pl.a[0] as usize], 7); // smaller storage index first
        pl.hist.copy_from_slice(&[1.0, 2.0, 3.0]);
        // storage unchanged: carried by index, as it was
        pl.build(&p, &dom, &s, 5, &signs, |_, _| 0.0);
        assert_eq!(pl.hist, vec![1.0, 2.0, 3.0]);
        // reversed storage: the pair's roles swap and its history turns
        p.permute(&[2, 1, 0]);
        pl.build(&p, &dom, &s, 10, &signs, |_, _| 0.0);
        assert_eq!(pl.len(), 1);
        assert_eq!(p.tag[pl.a[0] as usize], 3);
        assert_eq!(pl.hist, vec![-1.0, 2.0, -3.0]);
        // reordered without a swap (the far particle moves): kept by id as is
        p.permute(&[1, 2, 0]);
        pl.build(&p, &dom, &s, 20, &signs, |_, _| 0.0);
        assert_eq!(p.tag[pl.a[0] as usize], 3);
        assert_eq!(pl.hist, vec![-1.0, 2.0, -3.0]);
        // and back: turned back to what it was
        p.permute(&[1, 0, 2]);
        pl.build(&p, &dom, &s, 30, &signs, |_, _| 0.0);
        assert_eq!(p.tag[pl.a[0] as usize], 7);
        assert_eq!(pl.hist, vec![1.0, 2.0, 3.0]);
    }

    /// A pair's history as a function of its ids, for the test below.
    fn marked(ta: i64, tb: i64) -> [f64; 2] {
        [ta as f64, (tb * 7 % 11) as f64 + 1.0]
    }

    #[test]
    fn chunks_write_their_pairs_in_place_and_carry_history_by_index_and_by_id() {
        // several build chunks, each writing its range of the list
        let n = 3 * CHUNK as i64 + 500;
        let (dom, mut p) = gas_of(&mut lcg(21), n);
        let s = NeighSettings { skin: 0.1, ..Default::default() };
        let mut pl = PairList::default();
        let ids =
            |pl: &PairList, p: &Particles| -> Vec<(i64, i64)> { (0..pl.len()).map(|k| (p.tag[pl.a[k] as usize], p.tag[pl.b[k] as usize])).collect() };
        let check = |pl: &PairList, p: &Particles, with_history: bool| {
            assert!(pl.len() > n as usize, "more pairs than particles: {}", pl.len());
            // pairs by first particle, each after its chunk's predecessors
            assert!(pl.a.windows(2).all(|w| w[0] <= w[1]));
            assert!((0..pl.len()).all(|k| pl.a[k] < pl.b[k] || (pl.a[k] == pl.b[k] && pl.image[k] != 13)));
            assert_eq!(pl.keys, ids(pl, p), "keys are the pairs' ids");
            for (k, &(ta, tb)) in pl.keys.iter().enumerate() {
                let want = if with_history { marked(ta, tb) } else { [0.0; 2] };
                assert_eq!(pl.hist[2 * k..2 * k + 2], want, "pair {k} ({ta}, {tb})");
            }
        };
        pl.build(&p, &dom, &s, 0, &[1.0; 2], |_, _| 0.0);
        check(&pl, &p, false);
        let first = pl.keys.clone();
        for (k, &(ta, tb)) in first.iter().enumerate() {
            pl.hist[2 * k..2 * k + 2].copy_from_slice(&marked(ta, tb));
        }
        // storage unchanged: by index, into the spare buffers
        pl.build(&p, &dom, &s, 5, &[1.0; 2], |_, _| 0.0);
        assert_eq!(pl.keys, first);
        check(&pl, &p, true);
        // and again, into the first build's buffers
        pl.build(&p, &dom, &s, 10, &[1.0; 2], |_, _| 0.0);
        check(&pl, &p, true);
        // every particle gone (a run that lost them all): an empty list
        let mut none = p.clone();
        none.remove_where(&vec![true; none.len()]);
        let mut emptied = pl.clone();
        emptied.build(&none, &dom, &s, 15, &[1.0; 2], |_, _| 0.0);
        assert_eq!((emptied.len(), emptied.keys.len(), emptied.hist.len()), (0, 0, 0));
        // storage reversed: by id; every pair's roles swap, and the signs
        // (1, 1) keep the values
        let rev: Vec<usize> = (0..p.len()).rev().collect();
        p.permute(&rev);
        pl.build(&p, &dom, &s, 20, &[1.0; 2], |_, _| 0.0);
        assert_eq!(pl.len(), first.len());
        for (k, &(ta, tb)) in pl.keys.iter().enumerate() {
            assert_eq!(pl.hist[2 * k..2 * k + 2], marked(tb, ta), "pair {k} ({ta}, {tb}) after the reversal");
        }
    }
}
