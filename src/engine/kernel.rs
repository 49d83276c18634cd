//! The contact kernel: one generic pass over the pair list, monomorphised for
//! the scene's combination of laws, chosen once when the scene is built.
//!
//! The order of the laws is written down here and nowhere else:
//! normal -> cohesion -> tangential -> rolling. A law switched off by the
//! scene is a zero-sized type whose calls compile to nothing, so a scene
//! without cohesion or rolling pays nothing for them in this loop.
//!
//! Determinism: phase 1 computes every pair independently (in parallel), each
//! writing only its own output slot and history; phase 2 lets every particle
//! gather its pairs in increasing pair index. The sum order therefore never
//! depends on the number of threads, and results are bitwise identical for
//! any thread count.

use super::neighbor::{PairList, ADJ_B};
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

/// Output of one pair: force on a, torque on a, torque on b.
pub type PairOut = [V3; 3];

/// A kernel for one combination of laws (object-safe; one dynamic call per
/// pass, never per contact).
pub trait ContactKernel: Send + Sync {
    /// History values per contact.
    fn history_width(&self) -> usize;
    /// Whether pairs that do not touch interact (non-contact cohesion).
    fn noncontact(&self) -> bool;
    /// Pair pass: fills `out` (one slot per pair) and updates history.
    fn pair_pass(&self, p: &Particles, pairs: &mut PairList, table: &ParamTable, dt: f64, out: &mut Vec<PairOut>);
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
    let n = d / r;
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
    fn pair_pass(&self, p: &Particles, pairs: &mut PairList, table: &ParamTable, dt: f64, out: &mut Vec<PairOut>) {
        let m = pairs.len();
        out.clear();
        out.resize(m, [V3::zeros(); 3]);
        let w = Self::WIDTH;
        let a = &pairs.a;
        let b = &pairs.b;
        let shift = &pairs.shift;
        let one = |k: usize, slot: &mut PairOut, hist: &mut [f64]| {
            let i = a[k] as usize;
            let j = b[k] as usize;
            let xj = p.x[j] + shift[k];
            let pp = table.get(p.kind[i], p.kind[j]);
            // most listed pairs are within the skin but apart: decide on r^2
            // before building the contact
            // (a normal law acting beyond touching, JKR, decides itself in
            // `apply`: its range depends on the radii, not only the types)
            let beyond = C::NONCONTACT || !N::CONTACT_ONLY;
            let reach = p.radius[i] + p.radius[j] + if beyond { pp.extra_range } else { 0.0 };
            if N::CONTACT_ONLY && (p.x[i] - xj).norm_squared() >= reach * reach {
                hist.fill(0.0);
                return;
            }
            let Some((c, _)) = pair_contact(p, i, j, xj, dt) else { return };
            if N::CONTACT_ONLY && (c.delta <= -pp.extra_range || (c.delta <= 0.0 && !C::NONCONTACT)) {
                hist.fill(0.0);
                return;
            }
            let o = self.apply(&c, pp, hist);
            *slot = [o.force_i(&c), o.torque_i, o.torque_j];
        };
        const CHUNK: usize = 1024;
        if w == 0 {
            out.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, chunk)| {
                for (q, slot) in chunk.iter_mut().enumerate() {
                    one(ci * CHUNK + q, slot, &mut []);
                }
            });
        } else {
            out.par_chunks_mut(CHUNK).zip(pairs.hist.par_chunks_mut(CHUNK * w)).enumerate().for_each(|(ci, (chunk, hchunk))| {
                for (q, slot) in chunk.iter_mut().enumerate() {
                    one(ci * CHUNK + q, slot, &mut hchunk[q * w..(q + 1) * w]);
                }
            });
        }
    }
}

/// Phase 2: every particle sums its pairs' outputs in increasing pair index
/// into `f` and `torque` (which the caller has cleared).
pub fn gather(pairs: &PairList, out: &[PairOut], f: &mut [V3], torque: &mut [V3]) {
    const CHUNK: usize = 512;
    f.par_chunks_mut(CHUNK).zip(torque.par_chunks_mut(CHUNK)).enumerate().for_each(|(ci, (fc, tc))| {
        for q in 0..fc.len() {
            let i = ci * CHUNK + q;
            let (s, e) = (pairs.adj_start[i] as usize, pairs.adj_start[i + 1] as usize);
            let mut fi = fc[q];
            let mut ti = tc[q];
            for &code in &pairs.adj[s..e] {
                let k = (code & !ADJ_B) as usize;
                let o = &out[k];
                if code & ADJ_B == 0 {
                    fi += o[0];
                    ti += o[1];
                } else {
                    fi -= o[0];
                    ti += o[2];
                }
            }
            fc[q] = fi;
            tc[q] = ti;
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
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut pl = PairList::default();
                pl.build(&p, &dom, &NeighSettings { skin: 0.05, ..Default::default() }, 0, laws.history_width(), |_, _| 0.0);
                let mut out = vec![];
                laws.pair_pass(&p, &mut pl, &table, 1e-3, &mut out);
                let mut f = vec![V3::zeros(); p.len()];
                let mut t = vec![V3::zeros(); p.len()];
                gather(&pl, &out, &mut f, &mut t);
                (f, pl.hist.clone())
            })
        };
        let (f1, h1) = run(1);
        let (f2, h2) = run(2);
        assert_eq!(f1, f2);
        assert_eq!(h1, h2);
        let total: V3 = f1.iter().sum();
        assert!(total.norm() < 1e-9, "momentum not conserved: {total}");
        assert!(f1.iter().any(|f| f.norm() > 0.0));
        // history counted only for touching pairs
        assert!(h1.iter().all(|&v| v == 0.0 || v == 1.0));
    }
}
