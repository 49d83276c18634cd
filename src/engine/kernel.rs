//! The contact kernel: one generic pass over the pair list, monomorphised for
//! the scene's combination of laws, chosen once when the scene is built.
//!
//! The order of the laws is written down here and nowhere else:
//! normal -> cohesion -> tangential -> rolling. A law switched off by the
//! scene is a zero-sized type whose calls compile to nothing, so a scene
//! without cohesion or rolling pays nothing for them in this loop.
//!
//! Determinism: particles are cut into blocks of a fixed size ([`BLOCK`]
//! particles, contiguous in storage, which the spatial sort makes compact in
//! space). Phase 1 runs the blocks in parallel: each walks its pairs (those
//! whose first particle it holds) in increasing index and adds both shares of
//! a pair at once when both particles are its own, else its own share, keeping
//! the other for phase 2, in which every particle adds those kept shares in
//! increasing pair index. The order of additions is fixed by the blocks, never
//! by the threads, so results are bitwise identical on any thread count.

use super::integrate::cut;
use super::neighbor::PairList;
#[cfg(doc)]
use super::neighbor::BLOCK;
use super::particles::Particles;
use crate::physics::lanes::{BatchCoeffs, Coeffs, Real, Vec3, F8, LANES};
use crate::physics::{CohesionLaw, Contact, ContactL, ContactOut, NormalLaw, OutL, PairParams, RollingLaw, TangentialLaw, V3};
use rayon::prelude::*;

/// Per-type-pair coefficients, 1-based types, row-major (ntypes+1)^2.
#[derive(Clone, Debug, Default)]
pub struct ParamTable {
    /// Number of atom types.
    pub ntypes: usize,
    /// Coefficients, indexed `[ti * (ntypes + 1) + tj]`.
    pub params: Vec<PairParams>,
}

impl ParamTable {
    /// A table for `ntypes` types filled with defaults.
    pub fn new(ntypes: usize) -> ParamTable {
        ParamTable { ntypes, params: vec![PairParams::default(); (ntypes + 1) * (ntypes + 1)] }
    }
    /// Coefficients of types (ti, tj).
    #[inline(always)]
    pub fn get(&self, ti: u32, tj: u32) -> &PairParams {
        &self.params[ti as usize * (self.ntypes + 1) + tj as usize]
    }
    /// Mutable coefficients of (ti, tj).
    pub fn get_mut(&mut self, ti: u32, tj: u32) -> &mut PairParams {
        &mut self.params[ti as usize * (self.ntypes + 1) + tj as usize]
    }
    /// Largest extra interaction range of any pair.
    pub fn max_extra_range(&self) -> f64 {
        self.params.iter().map(|p| p.extra_range).fold(0.0, f64::max)
    }
}

/// The laws of one scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct Laws<N, T, C, R> {
    /// Normal law.
    pub normal: N,
    /// Tangential law.
    pub tangential: T,
    /// Cohesion law.
    pub cohesion: C,
    /// Rolling law.
    pub rolling: R,
}

/// A kernel for one combination of laws (object-safe; one dynamic call per
/// pass, never per contact).
pub trait ContactKernel: Send + Sync {
    /// History values per contact.
    fn history_width(&self) -> usize;
    /// Each history value's factor when a pair's particles swap roles, in
    /// storage order (normal, cohesion, tangential, rolling; see
    /// `NormalLaw::FLIP`).
    fn history_signs(&self) -> Vec<f64>;
    /// Whether pairs that do not touch interact (non-contact cohesion).
    fn noncontact(&self) -> bool;
    /// Force pass over the pair list, block by block (see [`Forces`]):
    /// sets each particle's force and torque to its pairs' sum (each block
    /// clears its particles' first, while they are in cache) and updates the
    /// pairs' history (`hist`, `live`: the list's own, taken out of it);
    /// returns the pair virial ([`Virial`]).
    ///
    /// Without `tail`, follow with [`cross_gather`]. With one (only for a
    /// list whose pairs reach forward, [`PairList::forward`]), each block
    /// gets its cross shares and then `tail` as soon as the last pass that
    /// reads or writes its particles is done; `tail` must change nothing but
    /// the block's particles (see [`Tail`]).
    #[allow(clippy::too_many_arguments)]
    fn force_pass(
        &self,
        p: &PassState<'_>,
        pairs: &PairList,
        hist: &mut [f64],
        live: &mut [u8],
        table: &ParamTable,
        dt: f64,
        force: Forces<'_>,
        tail: Option<&Tail<'_>>,
    ) -> Virial;
    /// One contact with a wall or any other partner given as a `Contact`;
    /// history is zeroed when apart. Returns the laws' output.
    fn contact(&self, c: &Contact, params: &PairParams, hist: &mut [f64]) -> ContactOut;
    /// Up to [`LANES`] contacts with walls at one time step, touching
    /// (`delta > 0`) unless the normal law acts beyond touching (JKR): contact `k` has coefficients `params[k]`, history
    /// `hist[k * w..(k + 1) * w]` (`w` the history width) and its output
    /// goes to `out[k]`. The laws run on lanes where they have a lane form,
    /// else contact by contact; each output has the bits
    /// [`ContactKernel::contact`] gives.
    fn wall_contacts(&self, cs: &[Contact], params: &[&PairParams], hist: &mut [f64], out: &mut [ContactOut]);
}

impl<N: NormalLaw, T: TangentialLaw, C: CohesionLaw, R: RollingLaw> Laws<N, T, C, R> {
    const WIDTH: usize = N::HISTORY + C::HISTORY + T::HISTORY + R::HISTORY;
    /// Whether the pair pass runs the laws on batches of [`LANES`] contacts:
    /// every law has a lane form and the normal law acts only on touching
    /// pairs (cohesion may reach beyond).
    const BATCHED: bool = N::LANES && T::LANES && C::LANES && R::LANES && N::CONTACT_ONLY && Self::WIDTH <= MAX_BATCH_HISTORY;

    /// The laws on a batch of contacts, in the fixed order: lanes that touch
    /// as [`Laws::apply`] does when `delta > 0`; with non-contact cohesion,
    /// lanes within its reach but apart as `apply` does otherwise (cohesion
    /// alone, the other laws' history cleared). Both are computed and each
    /// lane keeps its own, so an apart lane's normal law may compute NaN
    /// (the square root of a negative overlap) that no output keeps.
    #[inline(always)]
    fn apply_lanes<L: Real, P: Coeffs<L>>(&self, c: &ContactL<L>, pp: &P, hist: &mut [L]) -> OutL<L> {
        let mut out = OutL::zeros();
        let (hn, rest) = hist.split_at_mut(N::HISTORY);
        let (hc, rest) = rest.split_at_mut(C::HISTORY);
        let (ht, hr) = rest.split_at_mut(T::HISTORY);
        // cohesion alone, from the same history, for the lanes apart
        let zero = L::splat(0.0);
        let mut hc_apart = [zero; MAX_BATCH_HISTORY];
        let mut apart = OutL::zeros();
        if C::NONCONTACT {
            hc_apart[..C::HISTORY].copy_from_slice(hc);
            self.cohesion.cohesion_lanes(c, pp, &mut hc_apart[..C::HISTORY], &mut apart);
        }
        self.normal.normal_lanes(c, pp, hn, &mut out);
        self.cohesion.cohesion_lanes(c, pp, hc, &mut out);
        self.tangential.tangential_lanes(c, pp, ht, &mut out);
        self.rolling.rolling_lanes(c, pp, hr, &mut out);
        if C::NONCONTACT {
            let on = c.delta.gt(zero);
            for h in hn.iter_mut().chain(ht.iter_mut()).chain(hr.iter_mut()) {
                *h = L::select(on, *h, zero);
            }
            for (h, a) in hc.iter_mut().zip(&hc_apart) {
                *h = L::select(on, *h, *a);
            }
            out = OutL::select(on, &out, &apart);
        }
        out
    }

    /// Apply the laws in their fixed order.
    #[inline(always)]
    fn apply(&self, c: &Contact, pp: &PairParams, hist: &mut [f64]) -> ContactOut {
        let mut out = ContactOut::default();
        let (hn, rest) = hist.split_at_mut(N::HISTORY);
        let (hc, rest) = rest.split_at_mut(C::HISTORY);
        let (ht, hr) = rest.split_at_mut(T::HISTORY);
        let on = if N::CONTACT_ONLY { c.delta > 0.0 } else { self.normal.active(c, pp, hn) };
        if on {
            self.normal.normal(c, pp, hn, &mut out);
            self.cohesion.cohesion(c, pp, hc, &mut out);
            self.tangential.tangential(c, pp, ht, &mut out);
            self.rolling.rolling(c, pp, hr, &mut out);
        } else {
            hn.fill(0.0);
            ht.fill(0.0);
            hr.fill(0.0);
            if C::NONCONTACT {
                self.cohesion.cohesion(c, pp, hc, &mut out);
            } else {
                hc.fill(0.0);
            }
        }
        out
    }
}

/// What the force pass reads of the particles (whole arrays, by index).
#[derive(Clone, Copy)]
pub struct PassState<'a> {
    /// Positions.
    pub x: &'a [V3],
    /// Velocities.
    pub v: &'a [V3],
    /// Angular velocities.
    pub omega: &'a [V3],
    /// Radii.
    pub radius: &'a [f64],
    /// Masses.
    pub mass: &'a [f64],
    /// Types.
    pub kind: &'a [u32],
    /// Frozen flags.
    pub frozen: &'a [bool],
    /// Whether any particle is frozen: if not, a contact reads no flag (on a
    /// bed beyond the cache, each partner's flag was one more line from
    /// memory).
    pub any_frozen: bool,
}

impl<'a> PassState<'a> {
    /// The pass's view of `p`.
    pub fn of(p: &'a Particles) -> PassState<'a> {
        PassState {
            x: &p.x,
            v: &p.v,
            omega: &p.omega,
            radius: &p.radius,
            mass: &p.mass,
            kind: &p.kind,
            frozen: &p.frozen,
            any_frozen: any(&p.frozen),
        }
    }
}

/// Whether any flag is set: a fold without an early exit, which the
/// compiler turns into vector ORs.
pub fn any(flags: &[bool]) -> bool {
    flags.iter().fold(false, |a, &b| a | b)
}

/// What the step does with a block once its forces are complete: called
/// with the block's index and its particles' forces and torques. It may
/// change the block's particles alone, and reads no other particle's
/// position, velocity or angular velocity.
pub type Tail<'a> = dyn Fn(usize, &mut [V3], &mut [V3]) + Sync + 'a;

/// The state of the two particles of a pair that its contact is built from.
#[derive(Clone, Copy)]
pub struct PairState<L> {
    /// Position of i.
    pub xi: Vec3<L>,
    /// Position at which j is seen (periodic image).
    pub xj: Vec3<L>,
    /// Velocities.
    pub vi: Vec3<L>,
    /// Velocity of j.
    pub vj: Vec3<L>,
    /// Angular velocities.
    pub wi: Vec3<L>,
    /// Angular velocity of j.
    pub wj: Vec3<L>,
    /// Radii.
    pub ri: L,
    /// Radius of j.
    pub rj: L,
    /// Masses (infinite for frozen particles).
    pub mi: L,
    /// Mass of j.
    pub mj: L,
}

/// The contact of a pair, on lanes: the one formula the scalar and the
/// batched pass share. `r` must not be zero.
#[inline(always)]
pub fn contact_lanes<L: Real>(s: &PairState<L>, dt: f64) -> ContactL<L> {
    let d = s.xi - s.xj;
    let r = d.norm_squared().sqrt();
    let radsum = s.ri + s.rj;
    // unit normal by one reciprocal (as LAMMPS and LIGGGHTS: rinv = 1/r)
    let rinv = L::splat(1.0) / r;
    let n = d * rinv;
    let vr = s.vi - s.vj;
    ContactL {
        n,
        r,
        delta: radsum - r,
        ri: s.ri,
        rj: s.rj,
        r_eff: s.ri * s.rj / radsum,
        mi: s.mi,
        mj: s.mj,
        m_eff: effective_mass(s.mi, s.mj),
        vr,
        vn: vr.dot(&n),
        wi: s.wi,
        wj: s.wj,
        dt,
        wall: false,
    }
}

/// The masses of pair (i, j) as its contact sees them: a frozen particle's
/// infinite, so that the effective mass is the other's alone; of two
/// frozen ones, j's alone, so that the effective mass is i's (LAMMPS
/// `pair gran/*`: meff = mj if i is frozen, then meff = mi if j is; both
/// infinite would damp with an infinite mass, inf * 0 = NaN at rest).
#[inline(always)]
fn contact_masses(p: &PassState<'_>, i: usize, j: usize) -> (f64, f64) {
    let (mut mi, mut mj) = (p.mass[i], p.mass[j]);
    if p.any_frozen {
        (mi, mj) = frozen_masses(p.frozen[i], p.frozen[j], mi, mj);
    }
    (mi, mj)
}

/// [`contact_masses`] given the two frozen flags.
#[inline(always)]
fn frozen_masses(fi: bool, fj: bool, mi: f64, mj: f64) -> (f64, f64) {
    (if fi && !fj { f64::INFINITY } else { mi }, if fj { f64::INFINITY } else { mj })
}

/// The state of pair (i, j) of one contact, j seen at `xj`.
#[inline(always)]
fn pair_state(p: &PassState<'_>, i: usize, j: usize, xj: V3) -> PairState<f64> {
    let (mi, mj) = contact_masses(p, i, j);
    PairState {
        xi: p.x[i].into(),
        xj: xj.into(),
        vi: p.v[i].into(),
        vj: p.v[j].into(),
        wi: p.omega[i].into(),
        wj: p.omega[j].into(),
        ri: p.radius[i],
        rj: p.radius[j],
        mi,
        mj,
    }
}

/// Build the contact of pair (i, j) where j is seen at `xj`.
#[inline(always)]
pub fn pair_contact(p: &PassState<'_>, i: usize, j: usize, xj: V3, dt: f64) -> Option<(Contact, f64)> {
    let r2 = (p.x[i] - xj).norm_squared();
    if r2 == 0.0 {
        return None;
    }
    Some((contact_lanes(&pair_state(p, i, j, xj), dt).into(), r2))
}

/// m* = mi mj / (mi + mj), with an infinite mass on either side giving the other.
#[inline(always)]
pub fn effective_mass<L: Real>(mi: L, mj: L) -> L {
    L::select(mi.is_inf(), mj, L::select(mj.is_inf(), mi, mi * mj / (mi + mj)))
}

impl<N: NormalLaw + Send, T: TangentialLaw + Send, C: CohesionLaw + Send, R: RollingLaw + Send> ContactKernel for Laws<N, T, C, R> {
    fn history_width(&self) -> usize {
        Self::WIDTH
    }
    fn history_signs(&self) -> Vec<f64> {
        // each law's FLIP has one factor per history value (checked when
        // the crate compiles, physics::check_flip)
        let signs = [N::FLIP, C::FLIP, T::FLIP, R::FLIP].concat();
        debug_assert_eq!(signs.len(), Self::WIDTH, "a law's FLIP does not match its HISTORY");
        signs
    }
    fn noncontact(&self) -> bool {
        C::NONCONTACT
    }
    fn contact(&self, c: &Contact, params: &PairParams, hist: &mut [f64]) -> ContactOut {
        self.apply(c, params, hist)
    }
    fn wall_contacts(&self, cs: &[Contact], params: &[&PairParams], hist: &mut [f64], out: &mut [ContactOut]) {
        let (w, count) = (Self::WIDTH, cs.len());
        debug_assert!(count <= LANES && params.len() == count && hist.len() == count * w && out.len() == count);
        debug_assert!(cs.iter().all(|c| c.is_wall() && (c.delta > 0.0 || !Self::BATCHED) && c.dt == cs[0].dt));
        if !Self::BATCHED || count < 2 || self.scalar_only() {
            for (k, c) in cs.iter().enumerate() {
                out[k] = self.apply(c, params[k], &mut hist[k * w..(k + 1) * w]);
            }
            return;
        }
        // every lane touches: `apply_lanes` gives each the bits of `apply`
        // (lanes past `count` repeat the last contact and are dropped)
        let c = ContactL::<F8>::gather(cs);
        let mut coeffs = BatchCoeffs { p: [params[0]; LANES], uniform: true };
        let mut lanes = [F8::splat(0.0); MAX_BATCH_HISTORY];
        for l in 0..LANES {
            let k = l.min(count - 1);
            coeffs.p[l] = params[k];
            coeffs.uniform &= std::ptr::eq(params[k], params[0]);
            for (m, v) in hist[k * w..(k + 1) * w].iter().enumerate() {
                lanes[m].0[l] = *v;
            }
        }
        let o = self.apply_lanes(&c, &coeffs, &mut lanes[..w]);
        for k in 0..count {
            for (m, v) in hist[k * w..(k + 1) * w].iter_mut().enumerate() {
                *v = lanes[m].0[k];
            }
            out[k] = o.lane(k);
        }
    }
    fn force_pass(
        &self,
        p: &PassState<'_>,
        pairs: &PairList,
        hist: &mut [f64],
        live: &mut [u8],
        table: &ParamTable,
        dt: f64,
        force: Forces<'_>,
        tail: Option<&Tail<'_>>,
    ) -> Virial {
        let m = pairs.len();
        let w = Self::WIDTH;
        let bs = pairs.block_size();
        let n = p.x.len();
        let (defer, tensor) = (force.defer, force.tensor);
        // one slot per cross pair; each block clears its slots first
        let ncross = pairs.block_cross.last().copied().unwrap_or(0) as usize;
        if defer.len() != ncross {
            defer.resize(ncross, [V3::zeros(); 2]);
        }
        assert!(live.len() == m && hist.len() == m * w, "pair flags or history not sized for the list");
        let PairList { a, b, image, images, block_start, block_cross, xslot, .. } = pairs;
        let (a, b, image, images, block_start, block_cross, xslot) =
            (&a[..], &b[..], &image[..], &images[..], &block_start[..], &block_cross[..], &xslot[..]);
        // split the pairs' history and deferred slots at the block ranges
        let nblocks = block_start.len().saturating_sub(1);
        let mut jobs = Vec::with_capacity(nblocks);
        // the deferred slots as the cross pass of a fused tail reads them
        let slots = Shared(defer.as_mut_ptr());
        let (mut hrest, mut drest, mut lrest) = (hist, &mut defer[..], live);
        let (mut frest, mut trest) = (&mut force.f[..n], &mut force.torque[..n]);
        for q in 0..nblocks {
            let (ps, pe) = (block_start[q] as usize, block_start[q + 1] as usize);
            let len = bs.min(n - (q * bs).min(n));
            let (h, d) = (cut(&mut hrest, (pe - ps) * w), cut(&mut drest, (block_cross[q + 1] - block_cross[q]) as usize));
            jobs.push((q, h, d, cut(&mut lrest, pe - ps), cut(&mut frest, len), cut(&mut trest, len)));
        }
        // particles beyond the blocks (none while the list is indexed for n)
        frest.fill(V3::zeros());
        trest.fill(V3::zeros());
        let beyond = C::NONCONTACT || !N::CONTACT_ONLY;
        // one block: its pairs in increasing index; both shares of a pair
        // inside the block are added at once, the share of a particle of
        // another block is kept for the cross pass
        let block = |(q, h, d, lv, f, tq): &mut Job<'_>| -> Virial {
            let (q, h, d, lv, f, tq) = (*q, &mut **h, &mut **d, &mut **lv, &mut **f, &mut **tq);
            let lo = q * bs;
            let ps = block_start[q] as usize;
            // the block's n-th cross pair in pair order has slot xs[n]
            let xs = &xslot[block_cross[q] as usize..];
            let mut slot = 0;
            d.fill([V3::zeros(); 2]);
            f.fill(V3::zeros());
            tq.fill(V3::zeros());
            let mut virial = Virial::default();
            for k in ps..block_start[q + 1] as usize {
                let i = a[k] as usize;
                let j = b[k] as usize;
                let own_j = j.wrapping_sub(lo) < f.len();
                let js = slot;
                slot += !own_j as usize;
                lv[k - ps] = 1;
                let hk = &mut h[(k - ps) * w..(k - ps + 1) * w];
                let xj = p.x[j] + images[image[k] as usize];
                let pp = table.get(p.kind[i], p.kind[j]);
                // most listed pairs are within the skin but apart: decide on
                // r^2 before building the contact (a normal law acting beyond
                // touching, JKR, decides itself in `apply`)
                let reach = p.radius[i] + p.radius[j] + if beyond { pp.extra_range } else { 0.0 };
                if N::CONTACT_ONLY && (p.x[i] - xj).norm_squared() >= reach * reach {
                    hk.fill(0.0);
                    lv[k - ps] = 0;
                    continue;
                }
                let Some((c, _)) = pair_contact(p, i, j, xj, dt) else {
                    continue;
                };
                if N::CONTACT_ONLY && (c.delta <= -pp.extra_range || (c.delta <= 0.0 && !C::NONCONTACT)) {
                    hk.fill(0.0);
                    lv[k - ps] = 0;
                    continue;
                }
                let o = self.apply(&c, pp, hk);
                let fi = o.force_i(&c);
                // the lane form of the dot product, as the batched pass
                virial.trace += Vec3::from(p.x[i] - xj).dot(&Vec3::from(fi));
                if tensor {
                    add_tensor(&mut virial.tensor, p.x[i] - xj, fi);
                }
                f[i - lo] += fi;
                tq[i - lo] += o.torque_i;
                if own_j {
                    f[j - lo] -= fi;
                    tq[j - lo] += o.torque_j;
                } else {
                    d[xs[js] as usize] = [fi, o.torque_j];
                }
            }
            virial
        };
        // read here: the blocks may run on other threads
        let dense_only = DENSE_ONLY.is_on();
        let batched = |(q, h, d, lv, f, tq): &mut Job<'_>| -> Virial {
            let (q, h, d, lv, f, tq) = (*q, &mut **h, &mut **d, &mut **lv, &mut **f, &mut **tq);
            let (ps, pe) = (block_start[q] as usize, block_start[q + 1] as usize);
            d.fill([V3::zeros(); 2]);
            f.fill(V3::zeros());
            tq.fill(V3::zeros());
            let xs = &xslot[block_cross[q] as usize..];
            let blk = Block { p, a, b, image, images, xs, table, dt, lo: q * bs, ps, pe, dense: dense_only, tensor };
            // the batches index without bounds checks what this bounds
            assert!(blk.bounded(f, tq, h, lv, w), "pair list not built for these particles");
            self.block_batched(&blk, h, d, lv, f, tq)
        };
        let lanes = Self::BATCHED && !self.scalar_only();
        let pass = |job: &mut Job<'_>| if lanes { batched(job) } else { block(job) };
        let virials: Vec<Virial> = match tail {
            Some(tail) => {
                fused_blocks(pairs, jobs, &pass, &|s: usize, f: &mut [V3], tq: &mut [V3]| {
                    // SAFETY: the slots block `s` reads were written by
                    // passes that are over (its dependency count reached
                    // zero after their last write); no pass writes them
                    // until this call returns
                    let defer = unsafe { std::slice::from_raw_parts(slots.ptr(), ncross) };
                    cross_gather_chunk(pairs, defer, s * bs, f, tq);
                    tail(s, f, tq);
                })
            }
            None if nblocks > 1 => jobs.par_iter_mut().map(pass).collect(),
            None => jobs.iter_mut().map(pass).collect(),
        };
        virials.iter().fold(Virial::default(), Virial::plus)
    }
}

/// One block's share of the pass: its index, its pairs' history, deferred
/// slots and live flags, and its particles' forces and torques.
type Job<'a> = (usize, &'a mut [f64], &'a mut [[V3; 2]], &'a mut [u8], &'a mut [V3], &'a mut [V3]);

/// A pointer the blocks of a fused pass share across threads: the deferred
/// slots here, the particles' state in `Sim::fused_pass`.
#[derive(Clone, Copy)]
pub(crate) struct Shared<T>(pub(crate) *mut T);
// SAFETY: what is read or written through it is ordered by the dependency
// counts of `fused_blocks`: a block's entries are written by one finish at
// a time, after every pass that reads them, and read by a finish only after
// every pass that wrote them
unsafe impl<T> Sync for Shared<T> {}
unsafe impl<T> Send for Shared<T> {}

impl<T> Shared<T> {
    pub(crate) fn ptr(self) -> *mut T {
        self.0
    }
}

/// Run each block's pass, and each block's `finish` as soon as every pass
/// that touches its particles is done (its own and those of the earlier
/// blocks whose pairs reach it: [`PairList::block_deps`]); returns the
/// passes' virials in block order.
///
/// Passes are taken in block order by whichever thread is free; the thread
/// whose pass brings a block's count to zero finishes that block. Each pass
/// and each finish reads and writes the same things in any schedule, and
/// what each adds is added in the same order, so the bits do not depend on
/// the threads. On one thread this is pass, finish, pass, finish...: a
/// block's particles are finished while the pass has left them in cache.
fn fused_blocks<'a>(pairs: &PairList, jobs: Vec<Job<'a>>, pass: &(dyn Fn(&mut Job<'a>) -> Virial + Sync), finish: &Tail<'_>) -> Vec<Virial> {
    use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
    use std::sync::{Mutex, PoisonError};
    let nb = jobs.len();
    let count: Vec<AtomicU32> = pairs.block_deps.iter().map(|&c| AtomicU32::new(c)).collect();
    assert_eq!(count.len(), nb, "block dependencies not indexed for this list");
    let virial: Vec<Mutex<Virial>> = (0..nb).map(|_| Mutex::new(Virial::default())).collect();
    let jobs: Vec<Mutex<Option<Job<'a>>>> = jobs.into_iter().map(|j| Mutex::new(Some(j))).collect();
    let next = AtomicUsize::new(0);
    // tests take the passes last block first: any order is valid
    let reversed = REVERSED_PASSES.is_on();
    let take = |q: usize| jobs[q].lock().unwrap_or_else(PoisonError::into_inner).take();
    // blocks claimed whose pass or finishes are still running
    let busy = AtomicUsize::new(0);
    let work = || loop {
        // counted busy before the claim: a thread whose claim comes up
        // empty sees every block claimed before it as busy until done
        // (the guard counts it done however the block ends, a panic too,
        // so that no thread waits for it for ever)
        let held = Busy::hold(&busy);
        let q = next.fetch_add(1, Ordering::AcqRel);
        if q >= nb {
            drop(held);
            // Wait for the other threads' last blocks here, awake, rather
            // than in rayon's join, which puts a thread that waits long
            // enough to sleep on a futex: on bed (a) at 2 threads the
            // step's owner slept ~15% of the loop, and each wake-up is a
            // VM exit on the critical path. A block's work is at most
            // ~100 µs; after a short spin the core is yielded to the OS.
            let mut spins = 0u32;
            while busy.load(Ordering::Acquire) > 0 {
                spins = spins.saturating_add(1);
                if spins < 1024 {
                    std::hint::spin_loop();
                } else {
                    std::thread::yield_now();
                }
            }
            break;
        }
        let q = if reversed { nb - 1 - q } else { q };
        let Some(mut job) = take(q) else { unreachable!("block {q} passed twice") };
        *virial[q].lock().unwrap_or_else(PoisonError::into_inner) = pass(&mut job);
        *jobs[q].lock().unwrap_or_else(PoisonError::into_inner) = Some(job);
        let touched = &pairs.block_touch[pairs.block_touch_start[q] as usize..pairs.block_touch_start[q + 1] as usize];
        for s in std::iter::once(q).chain(touched.iter().map(|&s| s as usize)) {
            // the last pass to touch block s releases it (AcqRel: every
            // earlier pass's writes are seen by the finish)
            if count[s].fetch_sub(1, Ordering::AcqRel) == 1 {
                let Some((_, _, _, _, f, tq)) = take(s) else { unreachable!("block {s} finished twice") };
                finish(s, f, tq);
            }
        }
        drop(held);
    };
    if nb > 1 && rayon::current_num_threads() > 1 {
        (0..rayon::current_num_threads()).into_par_iter().for_each(|_| work());
    } else {
        work();
    }
    virial.into_iter().map(|v| v.into_inner().unwrap_or_else(PoisonError::into_inner)).collect()
}

/// One block claimed and not yet done (see `fused_blocks`): counted in
/// `busy` while the guard lives.
struct Busy<'a>(&'a std::sync::atomic::AtomicUsize);

impl<'a> Busy<'a> {
    fn hold(busy: &'a std::sync::atomic::AtomicUsize) -> Busy<'a> {
        busy.fetch_add(1, std::sync::atomic::Ordering::AcqRel);
        Busy(busy)
    }
}

impl Drop for Busy<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, std::sync::atomic::Ordering::AcqRel);
    }
}

/// History values per contact the batched pass holds in lanes; wider
/// combinations take the per-contact pass.
const MAX_BATCH_HISTORY: usize = 16;

/// How many listed pairs ahead the batched walk and the cross pass
/// prefetch: a listed pair takes a few ns, a load from DRAM ~100 ns.
const PREFETCH_AHEAD: usize = 16;

/// Ask the cache for `s[k]`: a hint, with no effect on results, that never
/// faults (a `k` past the end is harmless).
#[inline(always)]
fn prefetch<T>(s: &[T], k: usize) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch neither reads into the program nor faults, whatever
    // the address; the pointer is only computed (wrapping), never dereferenced
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(s.as_ptr().wrapping_add(k) as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (s, k);
}

/// Ask the cache for `s[k]`'s last byte: the second line of an element
/// that straddles two (a quarter of the 24-byte vectors), else a hint for
/// a line already asked for.
#[inline(always)]
fn prefetch_end<T>(s: &[T], k: usize) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: as in `prefetch`
    unsafe {
        let end = (s.as_ptr().wrapping_add(k + 1) as *const i8).wrapping_sub(1);
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(end);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (s, k);
}

/// Ask the cache for the partner of the block's pair `q + PREFETCH_AHEAD`
/// and that pair's history (`w` values a pair). Partners lie later in
/// storage, those across a block boundary often far later (the spatial
/// order keeps most neighbours close in memory, not all), and on beds
/// beyond the cache each first touch of one waits on DRAM. `BOTH`: the
/// partner's vectors whole, both lines of those that straddle two; where
/// every pair is a contact (dense blocks) the batch reads them all, and on
/// a bed of 480,000 spheres its loads waited on the second lines. The walk
/// reads only the position of most pairs, and the chute ran slower with it.
#[inline(always)]
fn prefetch_ahead<const BOTH: bool>(k: &Block<'_>, h: &[f64], q: usize, w: usize) {
    let ahead = k.b[(k.ps + q + PREFETCH_AHEAD).min(k.pe.saturating_sub(1))] as usize;
    let p = k.p;
    prefetch(p.x, ahead);
    prefetch(p.v, ahead);
    prefetch(p.omega, ahead);
    if BOTH {
        prefetch_end(p.x, ahead);
        prefetch_end(p.v, ahead);
        prefetch_end(p.omega, ahead);
    }
    prefetch(p.radius, ahead);
    prefetch(p.mass, ahead);
    prefetch(h, (q + PREFETCH_AHEAD) * w);
}

/// Set pair `q`'s live flag from the pass's test and clear its history
/// if it came apart. Few pairs come apart in a step, so the branch is
/// foreseen (unlike whether a pair touches); a pass over the block's flags
/// after the walk to find them cost the chute 3% of its run.
///
/// # Safety
/// `q < lv.len()` and `(q + 1) * w <= h.len()` ([`Block::bounded`]).
#[inline(always)]
unsafe fn came_apart(h: &mut [f64], lv: &mut [u8], q: usize, w: usize, apart: bool) {
    // one branch on both (as integers: on bools the compiler tests `apart`
    // first, the coin toss)
    // SAFETY: the caller's
    let flag = unsafe { at_mut(lv, q) };
    let was = *flag;
    *flag = (!apart) as u8;
    if was > *flag {
        for m in 0..w {
            // SAFETY: the caller's
            unsafe { *at_mut(h, q * w + m) = 0.0 };
        }
    }
}

/// `s[k]`, its bounds check left out: for the batched pass's indices,
/// which [`Block::bounded`] checked for the whole block before its pass.
///
/// # Safety
/// `k < s.len()`.
#[inline(always)]
unsafe fn at<T: Copy>(s: &[T], k: usize) -> T {
    debug_assert!(k < s.len());
    // SAFETY: the caller's
    unsafe { *s.get_unchecked(k) }
}

/// `&s[k]`, as [`at`].
///
/// # Safety
/// `k < s.len()`.
#[inline(always)]
unsafe fn at_ref<T>(s: &[T], k: usize) -> &T {
    debug_assert!(k < s.len());
    // SAFETY: the caller's
    unsafe { s.get_unchecked(k) }
}

/// `&mut s[k]`, as [`at`].
///
/// # Safety
/// `k < s.len()`.
#[inline(always)]
unsafe fn at_mut<T>(s: &mut [T], k: usize) -> &mut T {
    debug_assert!(k < s.len());
    // SAFETY: the caller's
    unsafe { s.get_unchecked_mut(k) }
}

/// `SPREAD[b]` has byte `l` set to bit `l` of `b`: eight lanes' flags, as
/// eight live flags.
const SPREAD: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut b = 0;
    while b < 256 {
        let mut l = 0;
        while l < 8 {
            t[b] |= ((b as u64 >> l) & 1) << (8 * l);
            l += 1;
        }
        b += 1;
    }
    t
};

/// [`came_apart`] for the `count` consecutive pairs from `q0` of a dense
/// batch, lane `l`'s pair apart where bit `l` of `apart` is set: a full
/// batch's eight flags are read and written as one word, and the history of
/// those that came apart (rare) cleared one by one.
///
/// # Safety
/// `q0 + count <= lv.len()`, `(q0 + count) * w <= h.len()` and
/// `count <= LANES`.
#[inline(always)]
unsafe fn batch_came_apart(h: &mut [f64], lv: &mut [u8], q0: usize, count: usize, w: usize, apart: u32) {
    debug_assert!(q0 + count <= lv.len() && (q0 + count) * w <= h.len() && count <= LANES);
    if count < LANES {
        for l in 0..count {
            // SAFETY: the caller's
            unsafe { came_apart(h, lv, q0 + l, w, apart >> l & 1 != 0) };
        }
        return;
    }
    // SAFETY: the caller's: the eight flags from q0 are the block's
    let flags = unsafe { lv.get_unchecked_mut(q0..q0 + LANES) };
    let was = u64::from_le_bytes(<[u8; 8]>::try_from(&*flags).unwrap_or_default());
    let now = SPREAD[(!apart & 0xff) as usize];
    flags.copy_from_slice(&now.to_le_bytes());
    // flags are 0 or 1: a byte of `gone` is 1 where the pair was live and
    // is now apart
    let mut gone = was & !now;
    while gone != 0 {
        let l = gone.trailing_zeros() as usize / 8;
        for m in 0..w {
            // SAFETY: the caller's
            unsafe { *at_mut(h, (q0 + l) * w + m) = 0.0 };
        }
        gone &= gone - 1;
    }
}

/// What a block of the batched pass reads.
struct Block<'a> {
    p: &'a PassState<'a>,
    a: &'a [u32],
    b: &'a [u32],
    image: &'a [u8],
    images: &'a [V3],
    /// The block's cross pairs' slots, in pair order (`PairList::xslot`).
    xs: &'a [u32],
    table: &'a ParamTable,
    dt: f64,
    /// First particle of the block.
    lo: usize,
    /// The block's pairs.
    ps: usize,
    pe: usize,
    /// Run it in batches of consecutive pairs however few touch (tests).
    dense: bool,
    /// Sum the virial tensor ([`Forces::tensor`]).
    tensor: bool,
}

impl Block<'_> {
    /// Whether every index the block's batches read without a bounds check
    /// ([`at`]) is in bounds: the particles' arrays of one length `n`, each
    /// pair's first particle among the block's (whose forces and torques `f`
    /// and `tq` hold), its second below `n`, its image in `images`, and a
    /// live flag in `lv` and `w` history values in `h` for each pair. A list
    /// built for these particles always is; a fold without an early exit,
    /// one pass over the block's indices.
    fn bounded(&self, f: &[V3], tq: &[V3], h: &[f64], lv: &[u8], w: usize) -> bool {
        let p = self.p;
        let n = p.x.len();
        let same = [p.v.len(), p.omega.len(), p.radius.len(), p.mass.len(), p.kind.len(), p.frozen.len()].iter().all(|&l| l == n);
        let (lo, nf, ni) = (self.lo, f.len(), self.images.len());
        let range = self.ps <= self.pe && self.pe <= self.a.len() && self.pe <= self.b.len() && self.pe <= self.image.len();
        let np = self.pe.saturating_sub(self.ps);
        if !(same && range && lo + nf <= n && tq.len() == nf && h.len() == np * w && lv.len() == np) {
            return false;
        }
        let a = self.a[self.ps..self.pe].iter().fold(true, |ok, &i| ok & ((i as usize).wrapping_sub(lo) < nf));
        let b = self.b[self.ps..self.pe].iter().fold(true, |ok, &j| ok & ((j as usize) < n));
        let im = self.image[self.ps..self.pe].iter().fold(true, |ok, &c| ok & ((c as usize) < ni));
        a & b & im
    }
}

super::switch::switch!(
    /// Tests switch it on to run the laws contact by contact where they
    /// would run on lanes (pairs and walls), to check that both give the
    /// same bits.
    SCALAR_ONLY
);

super::switch::switch!(
    /// Tests switch it on to run every block of the batched pass in
    /// batches of consecutive pairs (as a block whose pairs mostly touch),
    /// to check that both forms give the same bits.
    DENSE_ONLY
);

super::switch::switch!(
    /// Tests switch it on to run a fused pass's blocks last first, where a
    /// block that finished as soon as its own pass did would miss the
    /// shares of the earlier blocks' pairs.
    REVERSED_PASSES
);

/// Run `f` with the laws on lanes switched off on this thread (tests).
pub fn with_scalar_pass<T>(f: impl FnOnce() -> T) -> T {
    SCALAR_ONLY.on_during(f)
}

impl<N: NormalLaw, T: TangentialLaw, C: CohesionLaw, R: RollingLaw> Laws<N, T, C, R> {
    fn scalar_only(&self) -> bool {
        SCALAR_ONLY.is_on()
    }

    /// One block of the batched pass. The same contributions, added in the
    /// same order, as the per-contact pass: the laws run on [`LANES`]
    /// contacts at once and the lanes' forces are added in pair order, the
    /// touching pairs sorted out by a walk ([`Self::block_walk`]) or, where
    /// most touched at the last pass, by each batch of consecutive pairs
    /// ([`Self::block_dense`]). Either clears the history of the pairs that
    /// came apart as it finds them.
    #[inline(always)]
    fn block_batched(&self, k: &Block<'_>, h: &mut [f64], d: &mut [[V3; 2]], lv: &mut [u8], f: &mut [V3], tq: &mut [V3]) -> Virial {
        // most pairs touched at the last pass (a bed at rest): batches of
        // consecutive pairs, without a walk that sorts them out first
        let live = lv.iter().map(|&l| (l & 1) as usize).sum::<usize>();

        if (3 * live >= 2 * lv.len() && lv.len() >= LANES) || (k.dense && !lv.is_empty()) {
            self.block_dense(k, h, d, lv, f, tq)
        } else {
            self.block_walk(k, h, d, lv, f, tq)
        }
    }

    /// A block's pairs in batches of [`LANES`] consecutive ones, touching
    /// or not: each batch decides which of its lanes touch by the walk's
    /// test, on lanes, and adds the forces of those alone, in pair order:
    /// the same contributions in the same order as [`Self::block_walk`].
    #[inline(never)]
    fn block_dense(&self, k: &Block<'_>, h: &mut [f64], d: &mut [[V3; 2]], lv: &mut [u8], f: &mut [V3], tq: &mut [V3]) -> Virial {
        let w = Self::WIDTH;
        // a dense batch's pairs are consecutive: no queue, and their cross
        // slots are counted by the batch
        let none = [0usize; LANES];
        let mut slot = 0;
        let mut lanes = BatchLanes::new();
        // the trace a plain local, as the hot loop adds to it; the tensor
        // apart, which only the out-of-line `batch_tensor` touches
        let (mut trace, mut tensor) = (0.0, [0.0; 6]);
        let n = k.pe - k.ps;
        let mut q0 = 0;
        while q0 < n {
            let count = (n - q0).min(LANES);
            for l in 0..count {
                prefetch_ahead::<true>(k, h, q0 + l, w);
            }
            let dense = Dense { first: k.ps + q0, slot: &mut slot };
            self.run_batch::<true>(k, &mut lanes, &none, &none, dense, count, h, d, lv, f, tq, &mut trace, &mut tensor);
            q0 += count;
        }
        Virial { trace, tensor }
    }

    /// A block's pairs walked one by one: those apart are sorted out, the
    /// touching ones queued and run in batches.
    #[inline(never)]
    fn block_walk(&self, k: &Block<'_>, h: &mut [f64], d: &mut [[V3; 2]], lv: &mut [u8], f: &mut [V3], tq: &mut [V3]) -> Virial {
        let p = k.p;
        let w = Self::WIDTH;
        let mut queue = [0usize; LANES];
        // each queued pair's count among the block's cross pairs (used when
        // b is outside the block): its deferred slot is `k.xs` of it
        let mut slots = [0usize; LANES];
        let mut slot = 0;
        let (lo, len) = (k.lo, f.len());
        let mut queued = 0;
        // the batches' lanes, cleared once per block: each batch writes
        // every lane it reads
        let mut lanes = BatchLanes::new();
        let (mut trace, mut tensor) = (0.0, [0.0; 6]);
        // non-contact cohesion reaches beyond touching, by the pair's
        // `extra_range` (as in the per-contact pass)
        let one_type = k.table.ntypes == 1;
        let extra0 = if C::NONCONTACT { k.table.get(1, 1).extra_range } else { 0.0 };
        let pairs = k.a[k.ps..k.pe].iter().zip(&k.b[k.ps..k.pe]).zip(&k.image[k.ps..k.pe]);
        for (q, ((&i, &j), &img)) in pairs.enumerate() {
            prefetch_ahead::<false>(k, h, q, w);
            let (i, j) = (i as usize, j as usize);
            // SAFETY (each `at` and `at_mut` below): the block's pairs, whose
            // particles and images `Block::bounded` bounded; `queued` is
            // below LANES (a full queue is run and emptied)
            let (xi, xj, ri, rj) = unsafe { (at(p.x, i), at(p.x, j) + at(k.images, img as usize), at(p.radius, i), at(p.radius, j)) };
            let reach = if C::NONCONTACT {
                let extra = if one_type { extra0 } else { k.table.get(p.kind[i], p.kind[j]).extra_range };
                ri + rj + extra
            } else {
                ri + rj
            };
            let r2 = (xi - xj).norm_squared();
            // no branch on touching, which is a coin toss for pairs in the
            // skin: every pair is written to the queue, touching ones stay
            let apart = r2 >= reach * reach;
            let touch = !apart & (r2 != 0.0);
            debug_assert!(queued < LANES);
            unsafe {
                *at_mut(&mut queue, queued) = k.ps + q;
                *at_mut(&mut slots, queued) = slot;
            }
            slot += (j.wrapping_sub(lo) >= len) as usize;
            queued += touch as usize;
            // SAFETY: q < pe - ps, the block's pairs ([`Block::bounded`])
            unsafe { came_apart(h, lv, q, w, apart) };
            if queued == LANES {
                self.run_batch::<false>(
                    k,
                    &mut lanes,
                    &queue,
                    &slots,
                    Dense { first: 0, slot: &mut 0 },
                    LANES,
                    h,
                    d,
                    lv,
                    f,
                    tq,
                    &mut trace,
                    &mut tensor,
                );
                queued = 0;
            }
        }
        if queued > 0 {
            self.run_batch::<false>(
                k,
                &mut lanes,
                &queue,
                &slots,
                Dense { first: 0, slot: &mut 0 },
                queued,
                h,
                d,
                lv,
                f,
                tq,
                &mut trace,
                &mut tensor,
            );
        }
        Virial { trace, tensor }
    }

    /// Gather `count` queued pairs into lanes (the rest repeat the last one
    /// and are dropped), run the laws, write history back and add forces in
    /// queue order, and the lanes' virial to `trace` (and, where the block
    /// asks, [`Block::tensor`], to `tensor`), in queue order.
    /// `DENSE`: the pairs, the `count` from `dense.first`, were not sorted
    /// out by the walk; the batch sets their live flags, keeps the touching
    /// lanes alone, and counts their cross slots on from `dense.slot`
    /// (`queue` and `slots` unread).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn run_batch<const DENSE: bool>(
        &self,
        k: &Block<'_>,
        lanes: &mut BatchLanes,
        queue: &[usize; LANES],
        slots: &[usize; LANES],
        dense: Dense<'_>,
        count: usize,
        h: &mut [f64],
        d: &mut [[V3; 2]],
        lv: &mut [u8],
        f: &mut [V3],
        tq: &mut [V3],
        trace: &mut f64,
        tensor: &mut [f64; 6],
    ) {
        let p = k.p;
        let w = Self::WIDTH;
        let BatchLanes { s, hist } = lanes;
        let one_type = k.table.ntypes == 1;
        debug_assert!((1..=LANES).contains(&count));
        let last = count.clamp(1, LANES) - 1;
        let Dense { first, slot } = dense;
        // lane l's pair (lanes past `count` repeat the last)
        let pair = |l: usize| if DENSE { first + l.min(last) } else { queue[l.min(last)] };
        // with one type, types are not read (as in the walk): each batch's
        // first partner's type was a line from memory on a large bed
        let p0 = if one_type { k.table.get(1, 1) } else { k.table.get(p.kind[k.a[pair(0)] as usize], p.kind[k.b[pair(0)] as usize]) };
        let mut coeffs = BatchCoeffs { p: [p0; LANES], uniform: true };
        // the lanes whose pair's second particle is in a later block (dense)
        let mut cross = 0u32;
        // each lane's particles, image and first history value, for the rows
        // below
        let mut ia = [0usize; LANES];
        let mut ja = [0usize; LANES];
        let mut ima = [0usize; LANES];
        let mut ha = [0usize; LANES];
        // SAFETY (each `at` below): a queued pair lies among the block's
        // pairs, whose particles, images and history `Block::bounded`
        // bounded before the pass
        for l in 0..LANES {
            let pk = pair(l);
            let (i, j, img) = unsafe { (at(k.a, pk) as usize, at(k.b, pk) as usize, at(k.image, pk) as usize) };
            (ia[l], ja[l], ima[l]) = (i, j, img);
            cross |= ((j.wrapping_sub(k.lo) >= f.len()) as u32) << l;
            unsafe {
                s.ri.0[l] = at(p.radius, i);
                s.rj.0[l] = at(p.radius, j);
            }
            // masses as contacts see them (`contact_masses`): frozen ones below
            unsafe {
                s.mi.0[l] = at(p.mass, i);
                s.mj.0[l] = at(p.mass, j);
            }
            if !one_type {
                let pp = unsafe { k.table.get(at(p.kind, i), at(p.kind, j)) };
                coeffs.uniform &= std::ptr::eq(pp, p0);
                coeffs.p[l] = pp;
            }
            let h0 = (pk - k.ps) * w;
            for (m, v) in hist[..w].iter_mut().enumerate().skip(w / 3 * 3) {
                v.0[l] = unsafe { at(h, h0 + m) };
            }
            ha[l] = h0;
        }
        // the history in threes as rows (as the vectors below), the rest
        // lane by lane above
        for c in 0..w / 3 {
            let three = |h0: usize| {
                debug_assert!(h0 + 3 * c + 3 <= h.len());
                // SAFETY: each pair's `w` values lie in `h` ([`Block::bounded`]),
                // and `3 * c + 3 <= w`
                unsafe { &*(h.as_ptr().add(h0 + 3 * c) as *const [f64; 3]) }
            };
            let v = Vec3::rows_of(ha.map(three));
            (hist[3 * c], hist[3 * c + 1], hist[3 * c + 2]) = (v.x, v.y, v.z);
        }
        // SAFETY (each `at_ref`): as the loop's
        unsafe {
            s.xi = Vec3::rows(ia.map(|i| at_ref(p.x, i)));
            s.xj = Vec3::rows_plus(ja.map(|j| at_ref(p.x, j)), ima.map(|m| at_ref(k.images, m)));
            s.vi = Vec3::rows(ia.map(|i| at_ref(p.v, i)));
            s.vj = Vec3::rows(ja.map(|j| at_ref(p.v, j)));
            s.wi = Vec3::rows(ia.map(|i| at_ref(p.omega, i)));
            s.wj = Vec3::rows(ja.map(|j| at_ref(p.omega, j)));
        }
        if p.any_frozen {
            for l in 0..LANES {
                let pk = pair(l);
                // SAFETY: as the gather's
                let (i, j) = unsafe { (at(k.a, pk) as usize, at(k.b, pk) as usize) };
                (s.mi.0[l], s.mj.0[l]) = frozen_masses(p.frozen[i], p.frozen[j], s.mi.0[l], s.mj.0[l]);
            }
        }
        // the lanes whose forces are added, as bits: every queued one, or in
        // a dense batch those that touch (decided as the walk decides it, by
        // the same operations: r^2 summed x + y + z, the reach ri + rj plus
        // the extra range)
        let mut touch = u32::MAX;
        if DENSE {
            let r2 = (s.xi - s.xj).norm_squared();
            let mut reach = s.ri + s.rj;
            if C::NONCONTACT {
                reach += F8(std::array::from_fn(|l| coeffs.p[l].extra_range));
            }
            let rr = reach * reach;
            let apart = r2.ge(rr).bits() & ((1u32 << last) << 1).wrapping_sub(1);
            touch = !apart & r2.ne(F8::splat(0.0)).bits();
            // SAFETY: a dense batch's pairs are consecutive from `first`,
            // the block's ([`Block::bounded`])
            unsafe { batch_came_apart(h, lv, first - k.ps, last + 1, w, apart) };
        }
        let c = contact_lanes(s, k.dt);
        let o = self.apply_lanes(&c, &coeffs, &mut hist[..w]);
        let fi = o.force_i(&c);
        let vir = (s.xi - s.xj).dot(&fi);
        // what the lanes below read, lane by lane, taken out of the contact
        // and the laws' output, which then need not be kept in memory (a
        // lane read at a varying index pins the whole struct there: each
        // batch copied both)
        let (overlap, ti, tj) = (c.delta, o.torque_i, o.torque_j);
        for l in 0..count.min(LANES) {
            if DENSE && touch >> l & 1 == 0 {
                continue;
            }
            let pk = pair(l);
            let q = pk - k.ps;
            // SAFETY (each `at` and `at_mut` below): as the gather's; `i` is
            // the block's, `j` is where the branch says
            let (i, j) = unsafe { (at(k.a, pk) as usize, at(k.b, pk) as usize) };
            let delta = overlap.0[l];
            let beyond = if C::NONCONTACT { delta <= -coeffs.p[l].extra_range } else { delta <= 0.0 };
            if beyond {
                // within reach by r^2 but not by the overlap (rounding): apart,
                // as the per-contact pass decides
                h[q * w..(q + 1) * w].fill(0.0);
                lv[q] = 0;
                continue;
            }
            for (m, v) in hist[..w].iter().enumerate() {
                unsafe { *at_mut(h, q * w + m) = v.0[l] };
            }
            let fl = fi.lane(l);
            *trace += vir.0[l];
            unsafe {
                *at_mut(f, i - k.lo) += fl;
                *at_mut(tq, i - k.lo) += ti.lane(l);
            }
            if j.wrapping_sub(k.lo) < f.len() {
                unsafe {
                    *at_mut(f, j - k.lo) -= fl;
                    *at_mut(tq, j - k.lo) += tj.lane(l);
                }
            } else {
                let sl = if DENSE { *slot + (cross & ((1u32 << l) - 1)).count_ones() as usize } else { slots[l] };
                d[k.xs[sl] as usize] = [fl, tj.lane(l)];
            }
        }
        if DENSE {
            *slot += (cross & ((1u32 << last) << 1).wrapping_sub(1)).count_ones() as usize;
        }
        // only on the steps that ask, out of line: on the others the loop
        // above is all there is (a mask of kept lanes built in it cost bed
        // (a) ~7% of its pair time)
        if k.tensor {
            let extra: [f64; LANES] = std::array::from_fn(|l| if C::NONCONTACT { coeffs.p[l].extra_range } else { 0.0 });
            batch_tensor(tensor, &(s.xi - s.xj), &fi, &overlap, &extra, if DENSE { touch } else { u32::MAX }, count.min(LANES));
        }
    }
}

/// A batch's share of the virial tensor: the lanes below `count` whose forces
/// the batch added (those in `touch` whose overlap is beyond `-extra`, as the
/// batch decides), in lane order.
#[cold]
#[inline(never)]
fn batch_tensor(tensor: &mut [f64; 6], r: &Vec3<F8>, f: &Vec3<F8>, overlap: &F8, extra: &[f64; LANES], touch: u32, count: usize) {
    for l in 0..count {
        if touch >> l & 1 == 0 || overlap.0[l] <= -extra[l] {
            continue;
        }
        add_tensor(tensor, r.lane(l), f.lane(l));
    }
}

/// A dense batch's pairs: `first` and those after it, their cross slots
/// counted on from `slot` (see [`Laws::run_batch`]).
struct Dense<'a> {
    first: usize,
    slot: &'a mut usize,
}

/// The lanes of a batch of the batched pass: the pairs' state and history.
/// Kept across a block's batches, so that they are cleared once per block,
/// not per batch (a batch writes every lane of the state and of the
/// history values the laws read).
struct BatchLanes {
    s: PairState<F8>,
    hist: [F8; MAX_BATCH_HISTORY],
}

impl BatchLanes {
    #[inline(always)]
    fn new() -> BatchLanes {
        let z = Vec3::<F8>::zeros();
        let zf = F8::splat(0.0);
        BatchLanes { s: PairState { xi: z, xj: z, vi: z, vj: z, wi: z, wj: z, ri: zf, rj: zf, mi: zf, mj: zf }, hist: [zf; MAX_BATCH_HISTORY] }
    }
}

/// Where a force pass puts its forces: `f` and `torque` per particle (the
/// pass clears them to +0.0 and adds the block's shares; [`cross_gather`]
/// then adds zero shares, which leave a sum that never was -0.0 bit for
/// bit), and the deferred shares of cross-block pairs.
pub struct Forces<'a> {
    /// Force per particle.
    pub f: &'a mut [V3],
    /// Torque per particle.
    pub torque: &'a mut [V3],
    /// Per cross pair (a range per block, by `b` within it; see `PairList::xslot`): force on `a` and torque on `b`,
    /// zero when the pair is apart.
    pub defer: &'a mut Vec<[V3; 2]>,
    /// Whether to sum the virial tensor too ([`Virial::tensor`]): only on
    /// the steps whose output reads it, so the others do not pay for it.
    pub tensor: bool,
}

/// The pair virial of a force pass, summed pair by pair in the pass's fixed
/// order (blocks, then each block's pairs): the trace, sum r_ij . F_ij, on
/// every pass (it gives `press`), and the tensor, sum r_ij (x) F_ij, where
/// [`Forces::tensor`] asked for it (zeros otherwise). r_ij = x_i - x_j (at
/// the pair's image) and F_ij is the force on i; the components are in
/// LAMMPS's order xx, yy, zz, xy, xz, yz, with xy = sum r_x F_y, as
/// `Pair::virial_fdotr_compute` sums x_i f_i over owned and ghost atoms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Virial {
    /// sum r_ij . F_ij.
    pub trace: f64,
    /// sum r_ij (x) F_ij: xx, yy, zz, xy, xz, yz.
    pub tensor: [f64; 6],
}

/// One pair's r_ij (x) F_ij added to the tensor `t` ([`Virial::tensor`]).
#[inline(always)]
fn add_tensor(t: &mut [f64; 6], r: V3, f: V3) {
    t[0] += r.x * f.x;
    t[1] += r.y * f.y;
    t[2] += r.z * f.z;
    t[3] += r.x * f.y;
    t[4] += r.x * f.z;
    t[5] += r.y * f.z;
}

impl Virial {
    /// `self` then `o`, component by component.
    fn plus(mut self, o: &Virial) -> Virial {
        self.trace += o.trace;
        for (a, b) in self.tensor.iter_mut().zip(&o.tensor) {
            *a += b;
        }
        self
    }
}

/// The cross pass: every particle adds the shares of its cross-block pairs
/// (where it is `b`) in increasing pair index, after its block pass.
pub fn cross_gather(pairs: &PairList, defer: &[[V3; 2]], f: &mut [V3], torque: &mut [V3]) {
    if pairs.cross.is_empty() {
        return;
    }
    let bs = pairs.block_size();
    f.par_chunks_mut(bs).zip(torque.par_chunks_mut(bs)).enumerate().for_each(|(ci, (fc, tc))| cross_gather_chunk(pairs, defer, ci * bs, fc, tc));
}

/// [`cross_gather`] for the particles `lo..lo + f.len()` alone (`f` and
/// `torque` are theirs).
#[inline]
pub fn cross_gather_chunk(pairs: &PairList, defer: &[[V3; 2]], lo: usize, f: &mut [V3], torque: &mut [V3]) {
    // a particle's slots lie in the ranges of the few blocks it borders,
    // each read in order (`PairList::xslot`) but jumping from range to
    // range: prefetch a few ahead, as the pair walk does (measured: fewer
    // samples here with it, on beds of 1.2e5 and 1.1e6 spheres)
    let (s, e) = (pairs.cross_start[lo] as usize, pairs.cross_start[lo + f.len()] as usize);
    let last = e.saturating_sub(1);
    // the entries run particle by particle, each particle's in increasing
    // pair index: the order its shares were always added, without a branch
    // on whether a particle has any (most have none)
    for (c, (&slot, &i)) in pairs.cross[s..e].iter().zip(&pairs.cross_b[s..e]).enumerate() {
        prefetch(defer, pairs.cross[(s + c + PREFETCH_AHEAD).min(last)] as usize);
        let q = i as usize - lo;
        // apart pairs add zeros, which leave every bit as it is: the sums
        // started from +0.0, so they are never -0.0
        let o = &defer[slot as usize];
        f[q] -= o[0];
        torque[q] += o[1];
    }
}

#[cfg(test)]
mod tests {
    use super::super::domain::{Domain, Side};
    use super::super::neighbor::NeighSettings;
    use super::super::particles::NewParticle;
    use super::*;
    use crate::physics::{NoCohesion, NoRolling};

    /// A linear spring with a history counter, for testing the kernel only.
    #[derive(Clone, Copy, Default)]
    struct Spring;
    impl NormalLaw for Spring {
        const HISTORY: usize = 1;
        /// A count of the pair's passes, the same from both sides.
        const FLIP: &'static [f64] = &[1.0];
        fn normal(&self, c: &Contact, p: &PairParams, h: &mut [f64], out: &mut ContactOut) {
            h[0] += 1.0;
            out.fn_elastic = p.kn * c.delta;
        }
    }
    #[derive(Clone, Copy, Default)]
    struct Frictionless;
    impl TangentialLaw for Frictionless {
        const HISTORY: usize = 0;
        fn tangential(&self, _: &Contact, _: &PairParams, _: &mut [f64], _: &mut ContactOut) {}
    }

    /// A force pass of `laws` over `pl` and its cross pass, into `f`, `t`;
    /// with `fused`, the cross shares come block by block through the
    /// pass's tail instead (which copies each finished block out, so `f`
    /// and `t` must be whole). Returns the virial.
    #[allow(clippy::too_many_arguments)]
    fn pass_and_gather(
        laws: &dyn ContactKernel,
        p: &Particles,
        pl: &mut PairList,
        table: &ParamTable,
        f: &mut Vec<V3>,
        t: &mut Vec<V3>,
        defer: &mut Vec<[V3; 2]>,
        fused: bool,
    ) -> f64 {
        let (mut hist, mut live) = pl.take_history();
        let n = p.len();
        let done = std::sync::Mutex::new((vec![V3::repeat(f64::NAN); n], vec![V3::repeat(f64::NAN); n], vec![0u32; n.div_ceil(pl.block_size())]));
        let bs = pl.block_size();
        let tail = |b: usize, fb: &mut [V3], tb: &mut [V3]| {
            let mut d = done.lock().unwrap();
            d.0[b * bs..b * bs + fb.len()].copy_from_slice(fb);
            d.1[b * bs..b * bs + tb.len()].copy_from_slice(tb);
            d.2[b] += 1;
        };
        let w = laws
            .force_pass(
                &PassState::of(p),
                pl,
                &mut hist,
                &mut live,
                table,
                1e-3,
                Forces { f, torque: t, defer, tensor: false },
                fused.then_some(&tail as &Tail<'_>),
            )
            .trace;
        pl.put_history(hist, live);
        if fused {
            let (df, dt, calls) = done.into_inner().unwrap();
            assert!(calls.iter().all(|&c| c == 1), "each block finished once: {calls:?}");
            (*f, *t) = (df, dt);
        } else {
            cross_gather(pl, defer, f, t);
        }
        w
    }

    /// 400 spheres at random in a periodic box of side 3, a linear spring
    /// between them.
    fn spring_gas() -> (Domain, Particles, ParamTable, Laws<Spring, Frictionless, NoCohesion, NoRolling>) {
        let dom = Domain::new([0.0; 3], [3.0; 3], [[Side::Periodic; 2]; 3], 3);
        let mut p = Particles::default();
        let mut s = 7u64;
        for t in 1..=400 {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = |k: u32| ((s >> (k * 20)) & 0xfffff) as f64 / 1048576.0;
            p.push(NewParticle {
                tag: t,
                kind: 1,
                mask: 1,
                x: V3::new(3.0 * u(0), 3.0 * u(1), 3.0 * u(2)),
                v: V3::zeros(),
                omega: V3::zeros(),
                radius: 0.12,
                density: 1.0,
            });
        }
        let mut table = ParamTable::new(1);
        table.get_mut(1, 1).kn = 100.0;
        (dom, p, table, Laws { normal: Spring, tangential: Frictionless, cohesion: NoCohesion, rolling: NoRolling })
    }

    /// A block whose finish panics on one of two threads: the panic reaches
    /// the caller, and the other thread, out of blocks and waiting awake for
    /// the busy ones, is not left waiting for it for ever.
    #[test]
    fn a_panicking_block_does_not_hang_the_fused_pass() {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let (dom, p, table, laws) = spring_gas();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
            let outcome = pool.install(|| {
                let mut pl = PairList { block: 64, ..Default::default() };
                pl.build(&p, &dom, &NeighSettings { skin: 0.05, ..Default::default() }, 0, &laws.history_signs(), |_, _| 0.0);
                let (mut hist, mut live) = pl.take_history();
                let (mut f, mut t, mut defer) = (vec![V3::zeros(); p.len()], vec![V3::zeros(); p.len()], vec![]);
                let tail = |b: usize, _: &mut [V3], _: &mut [V3]| assert_ne!(b, 3, "block 3 fails");
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    let force = Forces { f: &mut f, torque: &mut t, defer: &mut defer, tensor: false };
                    laws.force_pass(&PassState::of(&p), &pl, &mut hist, &mut live, &table, 1e-3, force, Some(&tail as &Tail<'_>))
                }))
                .is_err()
            });
            let _ = tx.send(outcome);
        });
        let panicked = rx.recv_timeout(std::time::Duration::from_secs(60)).expect("the fused pass hung after a block panicked");
        assert!(panicked, "the block's panic did not reach the caller");
    }

    /// The check behind the batches' unchecked indexing: a block of a list
    /// built for the particles is bounded; one whose particles are fewer than
    /// the list's, or whose pair, image or history is out of range, is not.
    #[test]
    fn a_block_is_bounded_only_for_the_particles_its_list_was_built_for() {
        let (dom, p, table, laws) = spring_gas();
        let mut pl = PairList { block: 64, ..Default::default() };
        pl.build(&p, &dom, &NeighSettings { skin: 0.05, ..Default::default() }, 0, &laws.history_signs(), |_, _| 0.0);
        let w = 1;
        let (ps, pe) = (pl.block_start[1] as usize, pl.block_start[2] as usize);
        assert!(pe > ps, "block 1 has pairs");
        let (f, h, lv) = (vec![V3::zeros(); 64], vec![0.0; (pe - ps) * w], vec![0u8; pe - ps]);
        let bounded = |state: &PassState<'_>, b: &[u32], image: &[u8], f: &[V3], h: &[f64]| {
            let k = Block {
                p: state,
                a: &pl.a,
                b,
                image,
                images: &pl.images,
                xs: &[],
                table: &table,
                dt: 1e-3,
                lo: 64,
                ps,
                pe,
                dense: false,
                tensor: false,
            };
            k.bounded(f, f, h, &lv, w)
        };
        let whole = PassState::of(&p);
        assert!(bounded(&whole, &pl.b, &pl.image, &f, &h));
        // the last particle, a partner of block 1, gone
        let far = pl.b[ps..pe].iter().copied().max().unwrap() as usize;
        let n = far;
        let fewer = PassState {
            x: &p.x[..n],
            v: &p.v[..n],
            omega: &p.omega[..n],
            radius: &p.radius[..n],
            mass: &p.mass[..n],
            kind: &p.kind[..n],
            frozen: &p.frozen[..n],
            any_frozen: false,
        };
        assert!(!bounded(&fewer, &pl.b, &pl.image, &f, &h));
        let mut b = pl.b.clone();
        b[pe - 1] = p.len() as u32;
        assert!(!bounded(&whole, &b, &pl.image, &f, &h));
        let mut image = pl.image.clone();
        image[ps] = pl.images.len() as u8;
        assert!(!bounded(&whole, &pl.b, &image, &f, &h));
        // one force slot fewer than the block's last first particle needs
        let top = pl.a[ps..pe].iter().copied().max().unwrap() as usize - 64;
        assert!(!bounded(&whole, &pl.b, &pl.image, &f[..top], &h));
        assert!(!bounded(&whole, &pl.b, &pl.image, &f, &h[1..]));
    }

    #[test]
    fn forces_are_equal_and_opposite_and_thread_count_independent() {
        let (dom, p, table, laws) = spring_gas();
        // blocks of 64 particles: 7 blocks, many pairs across blocks
        let run_as = |threads: usize, block: usize, fused: bool, reversed: bool| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let go = || {
                let mut pl = PairList { block, ..Default::default() };
                pl.build(&p, &dom, &NeighSettings { skin: 0.05, ..Default::default() }, 0, &laws.history_signs(), |_, _| 0.0);
                // pairs by storage index reach only later blocks
                assert!(pl.forward && pl.a.iter().zip(&pl.b).all(|(a, b)| a <= b));
                let mut defer = vec![];
                let mut f = vec![V3::zeros(); p.len()];
                let mut t = vec![V3::zeros(); p.len()];
                let w = pass_and_gather(&laws, &p, &mut pl, &table, &mut f, &mut t, &mut defer, fused);
                assert!(block >= p.len() || !pl.cross.is_empty());
                (f, pl.hist.clone(), w)
            };
            pool.install(|| if reversed { REVERSED_PASSES.on_during(go) } else { go() })
        };
        let run = |threads: usize, block: usize| run_as(threads, block, false, false);
        let (f1, h1, w1) = run(1, 64);
        let (f2, h2, w2) = run(2, 64);
        assert_eq!(f1, f2);
        assert_eq!(h1, h2);
        // each block finished right after the passes that touch it: the
        // same bits on one and two threads, and with the passes taken last
        // block first
        for threads in [1, 2] {
            let (ff, hf, wf) = run_as(threads, 64, true, false);
            assert_eq!((&ff, &hf, wf.to_bits()), (&f1, &h1, w1.to_bits()), "fused on {threads} threads");
            let (ff, hf, wf) = run_as(threads, 64, true, true);
            assert_eq!((&ff, &hf, wf.to_bits()), (&f1, &h1, w1.to_bits()), "fused, last block first, on {threads} threads");
        }
        assert_eq!(w1.to_bits(), w2.to_bits());
        // one block (no cross pairs) gives the same forces up to rounding
        let (f3, _, w3) = run(2, 4096);
        for (x, y) in f1.iter().zip(&f3) {
            assert!((x - y).norm() <= 1e-12 * (1.0 + x.norm()), "{x} vs {y}");
        }
        assert!((w1 - w3).abs() <= 1e-12 * w1.abs() && w1 != 0.0);
        let total: V3 = f1.iter().sum();
        assert!(total.norm() < 1e-9, "momentum not conserved: {total}");
        assert!(f1.iter().any(|f| f.norm() > 0.0));
        // history counted only for touching pairs
        assert!(h1.iter().all(|&v| v == 0.0 || v == 1.0));
    }

    /// A dense random packing of two sizes and two types, some particles
    /// frozen, moving and spinning, in a periodic box.
    fn random_bed(seed: u64) -> (Particles, Domain) {
        let dom = Domain::new([0.0; 3], [2.0; 3], [[Side::Periodic; 2]; 3], 3);
        let mut p = Particles::default();
        let mut s = seed;
        let mut u = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for t in 1..=600 {
            let x = V3::new(2.0 * u(), 2.0 * u(), 2.0 * u());
            let v = V3::new(u() - 0.5, u() - 0.5, u() - 0.5);
            let w = V3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 10.0;
            let radius = if u() < 0.5 { 0.1 } else { 0.08 };
            p.push(NewParticle { tag: t, kind: 1 + (u() < 0.3) as u32, mask: 1, x, v, omega: w, radius, density: 1.0 + u() });
        }
        for i in (0..p.len()).step_by(17) {
            p.frozen[i] = true;
        }
        (p, dom)
    }

    /// [`passes`] with every block in batches of consecutive pairs.
    fn dense_passes<K: ContactKernel>(laws: &K, table: &ParamTable) -> Vec<(Vec<u64>, Vec<u64>, Vec<u64>, u64)> {
        DENSE_ONLY.on_during(|| passes(laws, table, false))
    }
    /// The walked, the dense and the per-contact pass give the same bits.
    fn same_bits_every_way<K: ContactKernel>(laws: &K, table: &ParamTable) {
        let scalar = passes(laws, table, true);
        assert_eq!(passes(laws, table, false), scalar);
        assert_eq!(dense_passes(laws, table), scalar);
    }
    /// Several passes of `laws` (positions advanced by the velocities in
    /// between, so history builds up and pairs come apart); forces, torques,
    /// history and virial of each pass.
    fn passes<K: ContactKernel>(laws: &K, table: &ParamTable, scalar: bool) -> Vec<(Vec<u64>, Vec<u64>, Vec<u64>, u64)> {
        passes_on(laws, table, scalar, random_bed(11))
    }

    /// [`passes`] on the bed `(p, dom)`.
    fn passes_on<K: ContactKernel>(
        laws: &K,
        table: &ParamTable,
        scalar: bool,
        (mut p, dom): (Particles, Domain),
    ) -> Vec<(Vec<u64>, Vec<u64>, Vec<u64>, u64)> {
        let mut pl = PairList { block: 128, ..Default::default() };
        let settings = NeighSettings { skin: 0.05, ..Default::default() };
        let mut out = vec![];
        for step in 0..4 {
            pl.build(&p, &dom, &settings, step, &laws.history_signs(), |_, _| 0.0);
            let mut defer = vec![];
            let mut f = vec![V3::zeros(); p.len()];
            let mut t = vec![V3::zeros(); p.len()];
            let pass = |f: &mut Vec<V3>, t: &mut Vec<V3>, defer: &mut Vec<[V3; 2]>, pl: &mut PairList| {
                pass_and_gather(laws, &p, pl, table, f, t, defer, step % 2 == 1)
            };
            let w = if scalar { with_scalar_pass(|| pass(&mut f, &mut t, &mut defer, &mut pl)) } else { pass(&mut f, &mut t, &mut defer, &mut pl) };
            // the pairs the pass found interacting are those that overlap
            let overlap = (0..pl.a.len())
                .filter(|&k| {
                    let (i, j) = (pl.a[k] as usize, pl.b[k] as usize);
                    let r = (p.x[i] - p.x[j] - pl.images[pl.image[k] as usize]).norm();
                    p.radius[i] + p.radius[j] - r > 0.0
                })
                .count();
            assert!(overlap > 50, "{overlap} contacts: too few to test");
            if laws.noncontact() {
                // and those apart within the cohesion's reach
                assert!(pl.interacting() > overlap, "step {step}");
            } else {
                assert_eq!(pl.interacting(), overlap, "step {step}");
            }
            let bits = |v: &[V3]| v.iter().flat_map(|x| x.iter().map(|c| c.to_bits())).collect::<Vec<u64>>();
            out.push((bits(&f), bits(&t), pl.hist.iter().map(|h| h.to_bits()).collect(), w.to_bits()));
            for i in 0..p.len() {
                let v = p.v[i];
                p.x[i] += v * 0.01;
            }
        }
        out
    }

    fn two_type_table(fill: impl Fn(&mut PairParams, u32)) -> ParamTable {
        let mut table = ParamTable::new(2);
        for (a, b) in [(1, 1), (1, 2), (2, 1), (2, 2)] {
            fill(table.get_mut(a, b), a + b);
        }
        table
    }

    /// LAMMPS gran/hooke/history on [`two_type_table`]: one type pair
    /// without tangential damping and with little friction.
    fn gran_hooke(
    ) -> (Laws<crate::physics::normal::gran::LammpsGranHooke, crate::physics::tangential::gran::LammpsGranHistory, NoCohesion, NoRolling>, ParamTable)
    {
        use crate::physics::normal::gran::LammpsGranHooke;
        use crate::physics::tangential::gran::LammpsGranHistory;
        let laws = Laws { normal: LammpsGranHooke, tangential: LammpsGranHistory, cohesion: NoCohesion, rolling: NoRolling };
        let table = two_type_table(|q, s| {
            q.kn = 1e4 * s as f64;
            q.kt = 3e3 * s as f64;
            q.gamma_n = 50.0;
            q.gamma_t = if s == 3 { 0.0 } else { 25.0 };
            q.mu = if s == 3 { 0.05 } else { 0.5 };
        });
        (laws, table)
    }

    /// A frozen particle meets its contacts with an infinite mass, in both
    /// passes, and a pass reads the flags only when some particle is frozen.
    #[test]
    fn frozen_partners_weigh_as_infinite_masses() {
        // gran/hooke damps with the effective mass, which a frozen partner
        // makes the other's alone
        let (laws, table) = gran_hooke();
        let bed = random_bed(11);
        assert!(PassState::of(&bed.0).any_frozen);
        let mut heavy = bed.clone();
        for i in 0..heavy.0.len() {
            if std::mem::take(&mut heavy.0.frozen[i]) {
                heavy.0.mass[i] = f64::INFINITY;
            }
        }
        assert!(!PassState::of(&heavy.0).any_frozen);
        let mut light = bed.clone();
        light.0.frozen.iter_mut().for_each(|f| *f = false);
        for scalar in [false, true] {
            let (frozen, heavy, light) = (
                passes_on(&laws, &table, scalar, bed.clone()),
                passes_on(&laws, &table, scalar, heavy.clone()),
                passes_on(&laws, &table, scalar, light.clone()),
            );
            assert_eq!(frozen, heavy, "scalar pass: {scalar}");
            assert_ne!(frozen, light, "scalar pass: {scalar}: the frozen flags changed nothing");
        }
    }

    #[test]
    fn two_frozen_partners_damp_with_the_first_mass() {
        // LAMMPS pair gran/*: meff = mi mj / (mi + mj), then mj if i is
        // frozen, then mi if j is
        let (mi, mj) = (2.5, 0.75);
        for (fi, fj) in [(false, false), (true, false), (false, true), (true, true)] {
            let lammps = if fj {
                mi
            } else if fi {
                mj
            } else {
                mi * mj / (mi + mj)
            };
            let (a, b) = frozen_masses(fi, fj, mi, mj);
            assert_eq!(effective_mass(a, b), lammps, "i frozen {fi}, j frozen {fj}");
        }
        // a bed all frozen: every contact between two frozen particles, whose
        // forces (and virial) stay finite on every path, with the same bits
        let (laws, table) = gran_hooke();
        let mut bed = random_bed(11);
        bed.0.frozen.iter_mut().for_each(|f| *f = true);
        let runs: Vec<_> = [false, true].map(|scalar| passes_on(&laws, &table, scalar, bed.clone())).into();
        let dense = DENSE_ONLY.on_during(|| passes_on(&laws, &table, false, bed.clone()));
        for (f, t, _, w) in runs.iter().flatten() {
            let finite = f.iter().chain(t).chain([w]).all(|&b| f64::from_bits(b).is_finite());
            assert!(finite, "a force, torque or the virial of two frozen partners is not finite");
        }
        assert_eq!(runs[0], runs[1]);
        assert_eq!(dense, runs[1]);
    }

    #[test]
    fn batched_pass_gives_the_per_contact_bits() {
        use crate::physics::normal::hertz::LiggghtsHertz;
        use crate::physics::tangential::history::LiggghtsHistory;
        // LIGGGHTS hertz + history; small mu on one type pair so that some
        // contacts slide and some stick
        let laws = Laws { normal: LiggghtsHertz, tangential: LiggghtsHistory, cohesion: NoCohesion, rolling: NoRolling };
        const { assert!(Laws::<LiggghtsHertz, LiggghtsHistory, NoCohesion, NoRolling>::BATCHED) };
        let table = two_type_table(|q, s| {
            q.y_eff = 1e4 * s as f64;
            q.g_eff = 4e3 * s as f64;
            q.beta = -0.2;
            q.mu = if s == 3 { 0.05 } else { 0.5 };
            q.tangential_damping = 1.0;
            q.limit_damping = if s == 4 { 1.0 } else { 0.0 };
        });
        let (batched, scalar) = (passes(&laws, &table, false), passes(&laws, &table, true));
        assert_eq!(dense_passes(&laws, &table), scalar);
        for (st, (b, s)) in batched.iter().zip(&scalar).enumerate() {
            for (n, (x, y)) in [(&b.0, &s.0), (&b.1, &s.1), (&b.2, &s.2)].iter().enumerate() {
                if let Some(q) = x.iter().zip(y.iter()).position(|(u, v)| u != v) {
                    eprintln!("step {st} array {n} index {q}: {} vs {}", f64::from_bits(x[q]), f64::from_bits(y[q]));
                }
            }
            if b.3 != s.3 {
                eprintln!("step {st} virial {} vs {}", f64::from_bits(b.3), f64::from_bits(s.3));
            }
        }
        assert_eq!(batched, scalar);
        let contacts = scalar.last().unwrap().2.chunks(3).filter(|h| h.iter().any(|&v| v != 0)).count();
        assert!(contacts > 100, "only {contacts} contacts with history");
        // LAMMPS gran/hooke/history
        let (laws, table) = gran_hooke();
        same_bits_every_way(&laws, &table);
        // LIGGGHTS hertz + history + cohesion sjkr + rolling_friction epsd2
        use crate::physics::cohesion::sjkr::LiggghtsSjkr;
        use crate::physics::rolling::epsd2::LiggghtsEpsd2;
        let laws = Laws {
            normal: LiggghtsHertz,
            tangential: LiggghtsHistory,
            cohesion: LiggghtsSjkr { tangential_reduce: true },
            rolling: LiggghtsEpsd2 { torsion_torque: false },
        };
        let table = two_type_table(|q, s| {
            q.y_eff = 1e4 * s as f64;
            q.g_eff = 4e3 * s as f64;
            q.beta = -0.2;
            q.mu = 0.5;
            q.mu_r = if s == 3 { 0.01 } else { 0.3 };
            q.cohesion = 1e3;
            q.tangential_damping = 1.0;
        });
        let (batched, scalar) = (passes(&laws, &table, false), passes(&laws, &table, true));
        assert_eq!(batched, scalar);
        assert_eq!(dense_passes(&laws, &table), scalar);
        assert!(scalar.last().unwrap().1.iter().any(|&t| t != 0));
        // LIGGGHTS hooke (k_n from the characteristic velocity) + history
        use crate::physics::normal::hooke::LiggghtsHooke;
        let laws = Laws { normal: LiggghtsHooke { kt_to_kn: true }, tangential: LiggghtsHistory, cohesion: NoCohesion, rolling: NoRolling };
        let table = two_type_table(|q, s| {
            q.y_eff = 1e4 * s as f64;
            q.beta = -0.2;
            q.char_vel = 0.5;
            q.mu = 0.3;
            q.tangential_damping = 1.0;
        });
        same_bits_every_way(&laws, &table);
        // LIGGGHTS hooke/stiffness + history
        use crate::physics::normal::hooke_stiffness::LiggghtsHookeStiffness;
        let laws = Laws {
            normal: LiggghtsHookeStiffness { absolute_damping: false },
            tangential: LiggghtsHistory,
            cohesion: NoCohesion,
            rolling: NoRolling,
        };
        let table = two_type_table(|q, s| {
            q.kn = 1e4 * s as f64;
            q.kt = 3e3 * s as f64;
            q.gamma_n = 40.0;
            q.gamma_t = 20.0;
            q.mu = 0.3;
            q.tangential_damping = 1.0;
        });
        same_bits_every_way(&laws, &table);
        // the paper's model: viscoelastic Hertz (A_n computed at first
        // touch), Cundall-Strack on the total, EPSD rolling, and van der
        // Waals reaching across gaps up to D_max (a reach per type pair)
        use crate::physics::cohesion::vdw::Hamaker;
        use crate::physics::normal::viscoelastic::PaperViscoelastic;
        use crate::physics::rolling::paper::PaperEpsd;
        use crate::physics::tangential::paper::PaperCundallStrack;
        let laws = Laws {
            normal: PaperViscoelastic,
            tangential: PaperCundallStrack,
            cohesion: Hamaker { tangential_reduce: false },
            rolling: PaperEpsd { torsion_torque: false },
        };
        const { assert!(Laws::<PaperViscoelastic, PaperCundallStrack, Hamaker, PaperEpsd>::BATCHED) };
        let table = two_type_table(|q, s| {
            q.y_eff = 1e4 * s as f64;
            q.g_eff = 4e3 * s as f64;
            q.beta = if s == 4 { 0.0 } else { 0.3 };
            q.mu = if s == 3 { 0.05 } else { 0.5 };
            q.mu_r = 0.1;
            q.hamaker = 1e-2;
            q.d_min = 1e-2;
            q.d_max = 0.01 * s as f64;
            q.extra_range = q.d_max;
        });
        let (batched, scalar) = (passes(&laws, &table, false), passes(&laws, &table, true));
        assert_eq!(batched, scalar);
        assert_eq!(dense_passes(&laws, &table), scalar);
        // with the attraction in the caps (tangential_reduce on): same bits
        // both ways, and a different result (the caps bind in this bed)
        let reduced = Laws { cohesion: Hamaker { tangential_reduce: true }, ..laws };
        let (batched_r, scalar_r) = (passes(&reduced, &table, false), passes(&reduced, &table, true));
        assert_eq!(batched_r, scalar_r);
        assert_eq!(dense_passes(&reduced, &table), scalar_r);
        assert_ne!(batched_r, batched, "tangential_reduce changed nothing");
        // pairs within D_max but apart exist in the bed, so the lanes' apart
        // branch is exercised
        let (p, _) = random_bed(11);
        let gaps = (0..p.len())
            .flat_map(|i| (0..i).map(move |j| (i, j)))
            .filter(|&(i, j)| {
                let gap = (p.x[i] - p.x[j]).norm() - p.radius[i] - p.radius[j];
                gap > 0.0 && gap < 0.02
            })
            .count();
        assert!(gaps > 50, "only {gaps} pairs in the van der Waals gap");
    }
}
