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

use super::neighbor::PairList;
#[cfg(doc)]
use super::neighbor::BLOCK;
use super::particles::Particles;
use crate::physics::{CohesionLaw, Contact, ContactOut, NormalLaw, PairParams, RollingLaw, TangentialLaw, V3};
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
    /// Whether pairs that do not touch interact (non-contact cohesion).
    fn noncontact(&self) -> bool;
    /// Force pass over the pair list, block by block (see [`Forces`]):
    /// adds the pairs' forces and torques and updates their history; returns
    /// the pair virial, the sum of r_ij . F_ij. Follow with [`cross_gather`].
    fn force_pass(&self, p: &Particles, pairs: &mut PairList, table: &ParamTable, dt: f64, force: Forces<'_>) -> f64;
    /// One contact with a wall or any other partner given as a `Contact`;
    /// history is zeroed when apart. Returns the laws' output.
    fn contact(&self, c: &Contact, params: &PairParams, hist: &mut [f64]) -> ContactOut;
}

impl<N: NormalLaw, T: TangentialLaw, C: CohesionLaw, R: RollingLaw> Laws<N, T, C, R> {
    const WIDTH: usize = N::HISTORY + C::HISTORY + T::HISTORY + R::HISTORY;

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

/// Build the contact of pair (i, j) where j is seen at `xj`.
#[inline(always)]
pub fn pair_contact(p: &Particles, i: usize, j: usize, xj: V3, dt: f64) -> Option<(Contact, f64)> {
    let d = p.x[i] - xj;
    let r2 = d.norm_squared();
    let (ri, rj) = (p.radius[i], p.radius[j]);
    let radsum = ri + rj;
    let r = r2.sqrt();
    if r == 0.0 {
        return None;
    }
    // unit normal by one reciprocal (as LAMMPS and LIGGGHTS: rinv = 1/r)
    let rinv = 1.0 / r;
    let n = d * rinv;
    let delta = radsum - r;
    let mi = if p.frozen[i] { f64::INFINITY } else { p.mass[i] };
    let mj = if p.frozen[j] { f64::INFINITY } else { p.mass[j] };
    let m_eff = effective_mass(mi, mj);
    let vr = p.v[i] - p.v[j];
    let c = Contact {
        n,
        r,
        delta,
        ri,
        rj,
        r_eff: ri * rj / radsum,
        mi,
        mj,
        m_eff,
        vr,
        vn: vr.dot(&n),
        wi: p.omega[i],
        wj: p.omega[j],
        dt,
    };
    Some((c, r2))
}

/// m* = mi mj / (mi + mj), with an infinite mass on either side giving the other.
#[inline(always)]
pub fn effective_mass(mi: f64, mj: f64) -> f64 {
    if mi.is_infinite() {
        mj
    } else if mj.is_infinite() {
        mi
    } else {
        mi * mj / (mi + mj)
    }
}

impl<N: NormalLaw + Send, T: TangentialLaw + Send, C: CohesionLaw + Send, R: RollingLaw + Send> ContactKernel for Laws<N, T, C, R> {
    fn history_width(&self) -> usize {
        Self::WIDTH
    }
    fn noncontact(&self) -> bool {
        C::NONCONTACT
    }
    fn contact(&self, c: &Contact, params: &PairParams, hist: &mut [f64]) -> ContactOut {
        self.apply(c, params, hist)
    }
    fn force_pass(&self, p: &Particles, pairs: &mut PairList, table: &ParamTable, dt: f64, force: Forces<'_>) -> f64 {
        let m = pairs.len();
        let w = Self::WIDTH;
        let bs = pairs.block_size();
        let n = p.len();
        let defer = force.defer;
        // slots are written before they are read (cross pairs only), so the
        // buffer is not cleared
        if defer.len() != m {
            defer.resize(m, [V3::zeros(); 2]);
        }
        let PairList { a, b, shift, hist, block_start, .. } = pairs;
        let (a, b, shift, block_start) = (&a[..], &b[..], &shift[..], &block_start[..]);
        // split the pairs' history and deferred slots at the block ranges
        let nblocks = block_start.len().saturating_sub(1);
        let mut jobs = Vec::with_capacity(nblocks);
        let (mut hrest, mut drest) = (&mut hist[..], &mut defer[..]);
        let (mut frest, mut trest) = (&mut force.f[..n], &mut force.torque[..n]);
        for q in 0..nblocks {
            let (ps, pe) = (block_start[q] as usize, block_start[q + 1] as usize);
            let (h, hr) = std::mem::take(&mut hrest).split_at_mut((pe - ps) * w);
            let (d, dr) = std::mem::take(&mut drest).split_at_mut(pe - ps);
            let len = bs.min(n - (q * bs).min(n));
            let (f, fr) = std::mem::take(&mut frest).split_at_mut(len);
            let (tq, tr) = std::mem::take(&mut trest).split_at_mut(len);
            (hrest, drest, frest, trest) = (hr, dr, fr, tr);
            jobs.push((q, h, d, f, tq));
        }
        let beyond = C::NONCONTACT || !N::CONTACT_ONLY;
        // one block: its pairs in increasing index; both shares of a pair
        // inside the block are added at once, the share of a particle of
        // another block is kept for the cross pass
        let block = |(q, h, d, f, tq): (usize, &mut [f64], &mut [[V3; 2]], &mut [V3], &mut [V3])| -> f64 {
            let lo = q * bs;
            let ps = block_start[q] as usize;
            let mut virial = 0.0;
            for k in ps..block_start[q + 1] as usize {
                let i = a[k] as usize;
                let j = b[k] as usize;
                let own_j = j >= lo && j - lo < f.len();
                if !own_j {
                    d[k - ps] = [V3::zeros(); 2];
                }
                let hk = &mut h[(k - ps) * w..(k - ps + 1) * w];
                let xj = p.x[j] + shift[k];
                let pp = table.get(p.kind[i], p.kind[j]);
                // most listed pairs are within the skin but apart: decide on
                // r^2 before building the contact (a normal law acting beyond
                // touching, JKR, decides itself in `apply`)
                let reach = p.radius[i] + p.radius[j] + if beyond { pp.extra_range } else { 0.0 };
                if N::CONTACT_ONLY && (p.x[i] - xj).norm_squared() >= reach * reach {
                    hk.fill(0.0);
                    continue;
                }
                let Some((c, _)) = pair_contact(p, i, j, xj, dt) else { continue };
                if N::CONTACT_ONLY && (c.delta <= -pp.extra_range || (c.delta <= 0.0 && !C::NONCONTACT)) {
                    hk.fill(0.0);
                    continue;
                }
                let o = self.apply(&c, pp, hk);
                let fi = o.force_i(&c);
                virial += (p.x[i] - xj).dot(&fi);
                f[i - lo] += fi;
                tq[i - lo] += o.torque_i;
                if own_j {
                    f[j - lo] -= fi;
                    tq[j - lo] += o.torque_j;
                } else {
                    d[k - ps] = [fi, o.torque_j];
                }
            }
            virial
        };
        let virials: Vec<f64> = if nblocks > 1 { jobs.into_par_iter().map(block).collect() } else { jobs.into_iter().map(block).collect() };
        virials.iter().sum()
    }
}

/// Where a force pass adds its forces: `f` and `torque` per particle (which
/// the caller has cleared or filled with what comes first), and the
/// deferred shares of cross-block pairs.
pub struct Forces<'a> {
    /// Force per particle.
    pub f: &'a mut [V3],
    /// Torque per particle.
    pub torque: &'a mut [V3],
    /// Per pair: force on `a` and torque on `b`, for pairs whose `b` lies in
    /// another block (other slots are unused).
    pub defer: &'a mut Vec<[V3; 2]>,
}

/// The cross pass: every particle adds the shares of its cross-block pairs
/// (where it is `b`) in increasing pair index, after its block pass.
pub fn cross_gather(pairs: &PairList, defer: &[[V3; 2]], f: &mut [V3], torque: &mut [V3]) {
    if pairs.cross.is_empty() {
        return;
    }
    let bs = pairs.block_size();
    f.par_chunks_mut(bs).zip(torque.par_chunks_mut(bs)).enumerate().for_each(|(ci, (fc, tc))| {
        for q in 0..fc.len() {
            let i = ci * bs + q;
            let (s, e) = (pairs.cross_start[i] as usize, pairs.cross_start[i + 1] as usize);
            for &k in &pairs.cross[s..e] {
                let o = &defer[k as usize];
                fc[q] -= o[0];
                tc[q] += o[1];
            }
        }
    });
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

    #[test]
    fn forces_are_equal_and_opposite_and_thread_count_independent() {
        let dom = Domain::new([0.0; 3], [3.0; 3], [[Side::Periodic; 2]; 3], 3);
        let mut p = Particles::default();
        let mut s = 7u64;
        for t in 1..=400 {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = |k: u32| ((s >> (k * 20)) & 0xfffff) as f64 / 1048576.0;
            p.push(NewParticle { tag: t, kind: 1, mask: 1, x: V3::new(3.0 * u(0), 3.0 * u(1), 3.0 * u(2)), v: V3::zeros(), omega: V3::zeros(), radius: 0.12, density: 1.0 });
        }
        let mut table = ParamTable::new(1);
        table.get_mut(1, 1).kn = 100.0;
        let laws = Laws { normal: Spring, tangential: Frictionless, cohesion: NoCohesion, rolling: NoRolling };
        // blocks of 64 particles: 7 blocks, many pairs across blocks
        let run = |threads: usize, block: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut pl = PairList { block, ..Default::default() };
                pl.build(&p, &dom, &NeighSettings { skin: 0.05, ..Default::default() }, 0, laws.history_width(), |_, _| 0.0);
                let mut defer = vec![];
                let mut f = vec![V3::zeros(); p.len()];
                let mut t = vec![V3::zeros(); p.len()];
                let w = laws.force_pass(&p, &mut pl, &table, 1e-3, Forces { f: &mut f, torque: &mut t, defer: &mut defer });
                cross_gather(&pl, &defer, &mut f, &mut t);
                assert!(block >= p.len() || !pl.cross.is_empty());
                (f, pl.hist.clone(), w)
            })
        };
        let (f1, h1, w1) = run(1, 64);
        let (f2, h2, w2) = run(2, 64);
        assert_eq!(f1, f2);
        assert_eq!(h1, h2);
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
}
