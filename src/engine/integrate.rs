//! Velocity-Verlet for spheres (`fix nve/sphere`), in the same order of
//! operations as LAMMPS `FixNVESphere`, so demx and the engines stay in step.

use super::fix::{Chunk, Stage};
use super::particles::Particles;
use crate::physics::V3;
use rayon::prelude::*;

/// LAMMPS `INERTIA` for solid spheres.
pub const INERTIA: f64 = 0.4;

/// Particles per parallel chunk. Each particle's update reads and writes only
/// its own entries, so the result is the same bits on any thread count; below
/// two chunks the loop runs inline (rayon's fork costs more than it saves).
pub const CHUNK: usize = 4096;

/// The first `k` entries of `rest`, which keeps the others: cut in turn,
/// a slice gives its consecutive parts to jobs that each write their own.
pub fn cut<'a, T>(rest: &mut &'a mut [T], k: usize) -> &'a mut [T] {
    let (head, tail) = std::mem::take(rest).split_at_mut(k);
    *rest = tail;
    head
}

/// `job` over `0..n` in fixed chunks of `chunk`, in parallel when there are
/// several; the results in chunk order. The chunks never depend on the
/// thread count, so neither does anything combined from them in order.
pub fn in_chunks<T: Send>(n: usize, chunk: usize, job: impl Fn(std::ops::Range<usize>) -> T + Sync) -> Vec<T> {
    let chunks = n.div_ceil(chunk);
    let range = |c: usize| c * chunk..((c + 1) * chunk).min(n);
    if chunks > 1 {
        (0..chunks).into_par_iter().map(|c| job(range(c))).collect()
    } else {
        vec![job(0..n)]
    }
}

/// What one half-step changes of particle `i`: position, velocity, angular
/// velocity, given its force, torque, mass and radius.
struct Half<'a> {
    f: &'a [V3],
    torque: &'a [V3],
    mass: &'a [f64],
    radius: &'a [f64],
    mask: &'a [u32],
}

/// Whether every particle of `mask` is in `group` (one bit): their AND
/// holds it. Without `all`'s early exit it runs on vectors. A stage that
/// tests each particle's bit in its loop keeps the loop scalar (and, with
/// AVX-512, may turn its stores into masked scatters); where this holds it
/// can leave the test out.
#[inline]
pub fn all_in_group(mask: &[u32], group: u32) -> bool {
    mask.iter().fold(u32::MAX, |a, &b| a & b) & group != 0
}

/// Apply `step(i, x, v, omega)` to every particle of `group`, in chunks of
/// CHUNK particles, in parallel when there are several.
fn each_in_group<F>(p: &mut Particles, group: u32, step: F)
where
    F: Fn(&Half<'_>, usize, &mut V3, &mut V3, &mut V3) + Sync,
{
    let Particles { x, v, omega, f, torque, mass, radius, mask, .. } = p;
    let h = Half { f, torque, mass, radius, mask };
    let chunk = |(c, ((xc, vc), wc)): (usize, ((&mut [V3], &mut [V3]), &mut [V3]))| {
        let lo = c * CHUNK;
        for q in 0..xc.len() {
            let i = lo + q;
            if h.mask[i] & group != 0 {
                step(&h, i, &mut xc[q], &mut vc[q], &mut wc[q]);
            }
        }
    };
    if x.len() >= 2 * CHUNK {
        x.par_chunks_mut(CHUNK).zip(v.par_chunks_mut(CHUNK)).zip(omega.par_chunks_mut(CHUNK)).enumerate().for_each(chunk);
    } else {
        x.chunks_mut(CHUNK).zip(v.chunks_mut(CHUNK)).zip(omega.chunks_mut(CHUNK)).enumerate().for_each(chunk);
    }
}

/// First half: v += dt/2 f/m; x += dt v; omega += dt/2 torque/I.
/// `group` is the fix's group bit; `dtf = 0.5 dt` (ftm2v = 1 in si/lj/cgs).
pub fn initial_integrate(p: &mut Particles, group: u32, dt: f64) {
    let s = InitialHalf { group, dt, rotate: true };
    each_in_group(p, group, |h, i, x, v, w| s.one(h.f[i], h.torque[i], h.mass[i], h.radius[i], x, v, w));
}

/// The first half of `fix nve/sphere` (`rotate`) or `fix nve`, particle by
/// particle: the form the step's fused head runs (a [`Stage`]).
pub struct InitialHalf {
    /// The fix's group bit.
    pub group: u32,
    /// Time step.
    pub dt: f64,
    /// Whether angular velocity is integrated (nve/sphere) or left (nve).
    pub rotate: bool,
}

impl InitialHalf {
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn one(&self, f: V3, torque: V3, m: f64, r: f64, x: &mut V3, v: &mut V3, w: &mut V3) {
        let dt = self.dt;
        let dtf = 0.5 * dt;
        let dtfm = dtf / m;
        *v += f * dtfm;
        *x += *v * dt;
        if self.rotate {
            let dtirotate = dtf / INERTIA / (r * r * m);
            *w += torque * dtirotate;
        }
    }
}

impl Stage for InitialHalf {
    fn apply(&self, c: &mut Chunk<'_>) {
        for q in 0..c.v.len() {
            let i = c.lo + q;
            if c.mask[i] & self.group != 0 {
                self.one(c.f[q], c.torque[q], c.mass[i], c.radius[i], &mut c.x[q], &mut c.v[q], &mut c.omega[q]);
            }
        }
    }

    fn initial_half(&self) -> Option<&InitialHalf> {
        Some(self)
    }
}

/// Second half: v += dt/2 f/m; omega += dt/2 torque/I.
pub fn final_integrate(p: &mut Particles, group: u32, dt: f64) {
    let s = FinalHalf { group, dt, rotate: true };
    each_in_group(p, group, |h, i, _x, v, w| s.one(h.f[i], h.torque[i], h.mass[i], h.radius[i], v, w));
}

/// The second half of `fix nve/sphere` (`rotate`) or `fix nve`, particle by
/// particle: the form the step's fused tail runs (a [`Stage`]).
pub struct FinalHalf {
    /// The fix's group bit.
    pub group: u32,
    /// Time step.
    pub dt: f64,
    /// Whether angular velocity is integrated (nve/sphere) or left (nve).
    pub rotate: bool,
}

impl FinalHalf {
    #[inline(always)]
    fn one(&self, f: V3, torque: V3, m: f64, r: f64, v: &mut V3, w: &mut V3) {
        let dtf = 0.5 * self.dt;
        let dtfm = dtf / m;
        *v += f * dtfm;
        if self.rotate {
            let dtirotate = dtf / INERTIA / (r * r * m);
            *w += torque * dtirotate;
        }
    }
}

impl Stage for FinalHalf {
    fn apply(&self, c: &mut Chunk<'_>) {
        for q in 0..c.v.len() {
            let i = c.lo + q;
            if c.mask[i] & self.group != 0 {
                self.one(c.f[q], c.torque[q], c.mass[i], c.radius[i], &mut c.v[q], &mut c.omega[q]);
            }
        }
    }

    /// A step's second half followed by the next step's first, of the same
    /// fix (group, step, rotation): one pass.
    fn then(&self, next: &dyn Stage) -> Option<Box<dyn Stage>> {
        let n = next.initial_half()?;
        let same = n.group == self.group && n.dt.to_bits() == self.dt.to_bits() && n.rotate == self.rotate;
        same.then(|| Box::new(Halves { group: self.group, dt: self.dt, rotate: self.rotate }) as Box<dyn Stage>)
    }
}

/// [`FinalHalf`] and then [`InitialHalf`] of one fix, particle by
/// particle: v += dt/2 f/m; omega += dt/2 torque/I; then v += dt/2 f/m;
/// x += dt v; omega += dt/2 torque/I (LAMMPS `FixNVESphere`). The same
/// operations as the two stages one after the other, so the same bits;
/// each particle's dt/2m and dt/2I are divided out once, not twice, and its
/// state is read once. Written out rather than as the two halves' `one`
/// calls: those kept both divisions (bed (a), `scripts/ab.py`, 7 runs:
/// Modify 0.139 s written out, 0.159 s as calls).
struct Halves {
    group: u32,
    dt: f64,
    rotate: bool,
}

impl Stage for Halves {
    fn apply(&self, c: &mut Chunk<'_>) {
        let dt = self.dt;
        let dtf = 0.5 * dt;
        let n = c.v.len();
        let r = c.lo..c.lo + n;
        let (mask, mass, radius) = (&c.mask[r.clone()], &c.mass[r.clone()], &c.radius[r]);
        let rotate = self.rotate;
        #[inline(always)]
        #[allow(clippy::too_many_arguments)]
        fn one(dt: f64, dtf: f64, rotate: bool, m: f64, r: f64, f: V3, t: V3, x: &mut V3, v: &mut V3, w: &mut V3) {
            let dtfm = dtf / m;
            *v += f * dtfm;
            *v += f * dtfm;
            *x += *v * dt;
            if rotate {
                let dtirotate = dtf / INERTIA / (r * r * m);
                *w += t * dtirotate;
                *w += t * dtirotate;
            }
        }
        let each = c.x.iter_mut().zip(c.v.iter_mut()).zip(c.omega.iter_mut()).zip(c.f.iter().zip(c.torque.iter())).zip(mass.iter().zip(radius));
        // the whole chunk in the group: no test per particle, so the loop
        // runs on vectors (its divisions among them)
        if all_in_group(mask, self.group) {
            for ((((x, v), w), (f, t)), (&m, &r)) in each {
                one(dt, dtf, rotate, m, r, *f, *t, x, v, w);
            }
        } else {
            for (((((x, v), w), (f, t)), (&m, &r)), &bits) in each.zip(mask) {
                if bits & self.group != 0 {
                    one(dt, dtf, rotate, m, r, *f, *t, x, v, w);
                }
            }
        }
    }
}

/// `fix nve` first half: translation only (LAMMPS `FixNVE`); angular
/// velocity is left alone, so particles integrated this way do not rotate.
pub fn initial_integrate_nve(p: &mut Particles, group: u32, dt: f64) {
    let s = InitialHalf { group, dt, rotate: false };
    each_in_group(p, group, |h, i, x, v, w| s.one(h.f[i], h.torque[i], h.mass[i], h.radius[i], x, v, w));
}

/// `fix nve` second half.
pub fn final_integrate_nve(p: &mut Particles, group: u32, dt: f64) {
    let s = FinalHalf { group, dt, rotate: false };
    each_in_group(p, group, |h, i, _x, v, w| s.one(h.f[i], h.torque[i], h.mass[i], h.radius[i], v, w));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::particles::NewParticle;

    #[test]
    fn free_fall_is_exact_for_constant_force() {
        // velocity Verlet integrates constant acceleration exactly:
        // z(t) = z0 + v0 t - g t^2 / 2
        let mut p = Particles::default();
        p.push(NewParticle {
            tag: 1,
            kind: 1,
            mask: 1,
            x: V3::new(0.0, 0.0, 10.0),
            v: V3::new(0.0, 0.0, 2.0),
            omega: V3::zeros(),
            radius: 0.01,
            density: 2500.0,
        });
        let g = 9.81;
        let dt = 1e-3;
        let n = 1000;
        for _ in 0..n {
            p.f[0] = V3::new(0.0, 0.0, -g * p.mass[0]);
            initial_integrate(&mut p, 1, dt);
            p.f[0] = V3::new(0.0, 0.0, -g * p.mass[0]);
            final_integrate(&mut p, 1, dt);
        }
        let t = n as f64 * dt;
        let z = 10.0 + 2.0 * t - 0.5 * g * t * t;
        assert!((p.x[0].z - z).abs() < 1e-9 * z.abs(), "{} vs {}", p.x[0].z, z);
        assert!((p.v[0].z - (2.0 - g * t)).abs() < 1e-9);
    }

    /// `n` particles with spread-out state, forces and torques, and the
    /// group bits `mask(k)`.
    fn spread(n: usize, mask: impl Fn(usize) -> u32) -> Particles {
        let mut p = Particles::default();
        for k in 0..n {
            let s = (k as f64 * 0.618).fract();
            p.push(NewParticle {
                tag: k as i64 + 1,
                kind: 1,
                mask: mask(k),
                x: V3::new(s, 1.0 - s, 2.0 * s),
                v: V3::new(0.1 * s, -0.2, 0.3 * s),
                omega: V3::new(1.0, s, -s),
                radius: 1e-3 * (1.0 + s),
                density: 2500.0 + 100.0 * s,
            });
            p.f[k] = V3::new(s - 0.5, 0.25 * s, -1.0 / 3.0);
            p.torque[k] = V3::new(1e-6 * s, -1e-6 / 3.0, 2e-6 * s);
        }
        p
    }

    /// The fused tail's one pass of a step's second half and the next
    /// step's first gives the bits of the two stages in turn, with and
    /// without rotation, and leaves particles outside the group alone; two
    /// halves of different fixes (group, step, rotation) stay apart.
    #[test]
    fn merged_halves_are_the_two_stages_bit_for_bit() {
        // every seventh particle outside the group, or the whole chunk in it
        // (some in other groups too), which the merged pass runs without a
        // test per particle
        for mixed in [true, false] {
            merged_halves_bit_for_bit(
                || {
                    spread(101, |k| {
                        if mixed && k % 7 == 0 {
                            1
                        } else if k % 3 == 0 {
                            3
                        } else {
                            2
                        }
                    })
                },
                mixed,
            );
        }
    }

    fn merged_halves_bit_for_bit(make: impl Fn() -> Particles, mixed: bool) {
        let run = |p: &mut Particles, stages: &[&dyn Stage]| {
            let (radius, mass, kind, mask) = (p.radius.clone(), p.mass.clone(), p.kind.clone(), p.mask.clone());
            let mut c = Chunk {
                lo: 0,
                x: &mut p.x,
                radius: &radius,
                mass: &mass,
                kind: &kind,
                mask: &mask,
                v: &mut p.v,
                omega: &mut p.omega,
                f: &mut p.f,
                torque: &mut p.torque,
                frozen: &mut p.frozen,
                extra: vec![],
            };
            for s in stages {
                s.apply(&mut c);
            }
        };
        let bits = |p: &Particles| p.x.iter().chain(&p.v).chain(&p.omega).flat_map(|v| [v.x, v.y, v.z]).map(f64::to_bits).collect::<Vec<_>>();
        let dt = 1e-5 / 3.0;
        for rotate in [true, false] {
            let (fin, ini) = (FinalHalf { group: 2, dt, rotate }, InitialHalf { group: 2, dt, rotate });
            let both = fin.then(&ini).expect("halves of one fix merge");
            let (mut a, mut b) = (make(), make());
            run(&mut a, &[&fin, &ini]);
            run(&mut b, &[&*both]);
            assert_eq!(bits(&a), bits(&b), "rotate {rotate}");
            let c = make();
            assert_ne!(bits(&a), bits(&c), "the stages moved the particles");
            assert_eq!(bits(&a)[0..3] == bits(&c)[0..3], mixed, "particle 0 is outside the group when mixed");
        }
        let fin = FinalHalf { group: 2, dt, rotate: true };
        for other in [
            InitialHalf { group: 1, dt, rotate: true },
            InitialHalf { group: 2, dt: 2.0 * dt, rotate: true },
            InitialHalf { group: 2, dt, rotate: false },
        ] {
            assert!(fin.then(&other).is_none());
        }
        assert!(InitialHalf { group: 2, dt, rotate: true }.then(&fin).is_none(), "only second half, then first");
    }

    /// Several chunks (the parallel path): every particle gets the update of
    /// the formula, bit for bit, on one thread and on three, and particles
    /// outside the group are left alone.
    #[test]
    fn chunked_update_is_the_formula_on_any_thread_count() {
        let n = 3 * CHUNK + 17;
        let make = || spread(n, |k| if k % 5 == 0 { 2 } else { 1 });
        let dt = 1e-5;
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut p = make();
            pool.install(|| {
                initial_integrate(&mut p, 1, dt);
                final_integrate(&mut p, 1, dt);
            });
            p
        };
        let (a, b, p0) = (run(1), run(3), make());
        for i in 0..n {
            assert_eq!(a.x[i], b.x[i]);
            assert_eq!(a.v[i], b.v[i]);
            assert_eq!(a.omega[i], b.omega[i]);
            if p0.mask[i] & 1 == 0 {
                assert_eq!(a.x[i], p0.x[i], "outside the group: unchanged");
                assert_eq!(a.v[i], p0.v[i]);
                continue;
            }
            let dtfm = 0.5 * dt / p0.mass[i];
            let v = p0.v[i] + p0.f[i] * dtfm;
            assert_eq!(a.x[i], p0.x[i] + v * dt);
            assert_eq!(a.v[i], v + p0.f[i] * dtfm);
        }
    }
}
