//! Two-body collisions driven by the contact laws with a small
//! velocity-Verlet integrator written here (no engine code): contact
//! duration against Hertz and damped-oscillator closed forms, restitution
//! against the requested coefficient, energy and momentum of elastic
//! impacts, and the Coulomb limit of a sphere sliding on a wall.

use demx::physics::mixing::*;
use demx::physics::normal::gran::LammpsGranHooke;
use demx::physics::normal::hertz::LiggghtsHertz;
use demx::physics::normal::hooke::LiggghtsHooke;
use demx::physics::tangential::gran::LammpsGranHistory;
use demx::physics::tangential::history::LiggghtsHistory;
use demx::physics::*;
use demx::script::source::{SourceMap, Span};
use std::f64::consts::PI;

const RHO: f64 = 2500.0;

#[derive(Clone, Copy, Debug)]
struct Body {
    x: V3,
    v: V3,
    w: V3,
    r: f64,
    m: f64,
    inertia: f64,
}

impl Body {
    fn sphere(r: f64, x: V3, v: V3) -> Body {
        let m = RHO * 4.0 / 3.0 * PI * r * r * r;
        Body { x, v, w: V3::zeros(), r, m, inertia: 0.4 * m * r * r }
    }
}

fn span() -> Span {
    let map = SourceMap::new();
    let id = map.add("in.test", "pair_style gran".to_string());
    Span::new(id, 0, 4)
}

fn liggghts(y: f64, nu: f64, e: f64, mu: f64, char_vel: f64) -> PairParams {
    let mut m = LiggghtsMaterials::default();
    m.n_types = 1;
    m.youngs = Some(vec![y]);
    m.poisson = Some(vec![nu]);
    m.restitution = Some(vec![e]);
    m.friction = Some(vec![mu]);
    m.char_vel = Some(char_vel);
    liggghts_pair_params(&m, &LiggghtsSettings::default(), span()).unwrap()[0]
}

/// The wall is the plane z = 0 with normal +z.
struct Sim<'a, N: NormalLaw, T: TangentialLaw> {
    n: &'a N,
    t: &'a T,
    p: PairParams,
    b: Vec<Body>,
    wall: bool,
    hist: Vec<f64>,
    dt: f64,
    gravity: f64,
    f: Vec<V3>,
    tq: Vec<V3>,
    delta: f64,
    fn_last: f64,
    ft_last: V3,
}

impl<'a, N: NormalLaw, T: TangentialLaw> Sim<'a, N, T> {
    fn new(n: &'a N, t: &'a T, p: PairParams, b: Vec<Body>, wall: bool, dt: f64, gravity: f64) -> Self {
        let k = b.len();
        let mut s = Sim {
            n,
            t,
            p,
            b,
            wall,
            hist: vec![0.0; N::HISTORY + T::HISTORY],
            dt,
            gravity,
            f: vec![V3::zeros(); k],
            tq: vec![V3::zeros(); k],
            delta: 0.0,
            fn_last: 0.0,
            ft_last: V3::zeros(),
        };
        s.forces();
        s
    }

    fn contact(&self) -> Contact {
        let bi = &self.b[0];
        if self.wall {
            let n = V3::new(0.0, 0.0, 1.0);
            let delta = bi.r - bi.x.z;
            Contact {
                n,
                r: bi.x.z,
                delta,
                ri: bi.r,
                rj: f64::INFINITY,
                r_eff: r_eff(bi.r, f64::INFINITY),
                mi: bi.m,
                mj: f64::INFINITY,
                m_eff: m_eff(bi.m, f64::INFINITY),
                vr: bi.v,
                vn: bi.v.dot(&n),
                wi: bi.w,
                wj: V3::zeros(),
                dt: self.dt,
            }
        } else {
            let bj = &self.b[1];
            let d = bi.x - bj.x;
            let r = d.norm();
            let n = d / r;
            let vr = bi.v - bj.v;
            Contact {
                n,
                r,
                delta: bi.r + bj.r - r,
                ri: bi.r,
                rj: bj.r,
                r_eff: r_eff(bi.r, bj.r),
                mi: bi.m,
                mj: bj.m,
                m_eff: m_eff(bi.m, bj.m),
                vr,
                vn: vr.dot(&n),
                wi: bi.w,
                wj: bj.w,
                dt: self.dt,
            }
        }
    }

    fn forces(&mut self) {
        for k in 0..self.b.len() {
            self.f[k] = V3::new(0.0, 0.0, -self.gravity * self.b[k].m);
            self.tq[k] = V3::zeros();
        }
        let c = self.contact();
        self.delta = c.delta;
        if c.delta > 0.0 {
            let mut out = ContactOut::default();
            let (hn, ht) = self.hist.split_at_mut(N::HISTORY);
            self.n.normal(&c, &self.p, hn, &mut out);
            self.t.tangential(&c, &self.p, ht, &mut out);
            let fi = out.force_i(&c);
            self.f[0] += fi;
            self.tq[0] += out.torque_i;
            if !self.wall {
                self.f[1] -= fi;
                self.tq[1] += out.torque_j;
            }
            self.fn_last = out.fn_for_friction;
            self.ft_last = out.ft;
        } else {
            self.hist.iter_mut().for_each(|h| *h = 0.0);
            self.fn_last = 0.0;
            self.ft_last = V3::zeros();
        }
    }

    /// One velocity-Verlet step (as LAMMPS/LIGGGHTS nve/sphere).
    fn step(&mut self) {
        let dt = self.dt;
        for k in 0..self.b.len() {
            let b = &mut self.b[k];
            b.v += self.f[k] * (0.5 * dt / b.m);
            b.w += self.tq[k] * (0.5 * dt / b.inertia);
            b.x += b.v * dt;
        }
        self.forces();
        for k in 0..self.b.len() {
            let b = &mut self.b[k];
            b.v += self.f[k] * (0.5 * dt / b.m);
            b.w += self.tq[k] * (0.5 * dt / b.inertia);
        }
    }
}

/// Head-on impact starting at first touch; returns (contact duration,
/// relative normal speed after / before, the final Sim bodies).
fn impact<N: NormalLaw, T: TangentialLaw>(n: &N, t: &T, p: PairParams, b: Vec<Body>, wall: bool, dt: f64) -> (f64, f64, Vec<Body>) {
    let mut s = Sim::new(n, t, p, b, wall, dt, 0.0);
    let vrel = |s: &Sim<N, T>| if s.wall { s.b[0].v.z } else { s.b[0].v.z - s.b[1].v.z };
    let v0 = vrel(&s);
    let mut time = 0.0;
    let mut steps = 0usize;
    loop {
        let before = s.delta;
        s.step();
        time += dt;
        steps += 1;
        assert!(steps < 1_000_000, "collision did not end");
        if steps > 2 && s.delta <= 0.0 && before > 0.0 {
            // linear interpolation of the exit crossing
            let tc = time - dt + dt * before / (before - s.delta);
            return (tc, (vrel(&s) / v0).abs(), s.b);
        }
    }
}

/// Two equal glass-like spheres (R = 1 mm) meeting head-on at relative speed v.
fn two_spheres(v: f64) -> Vec<Body> {
    let r = 1e-3;
    vec![Body::sphere(r, V3::new(0.0, 0.0, r), V3::new(0.0, 0.0, -0.5 * v)), Body::sphere(r, V3::new(0.0, 0.0, -r), V3::new(0.0, 0.0, 0.5 * v))]
}

fn hertz_tc(m: f64, r: f64, e_star: f64, v: f64) -> f64 {
    // t_c = 2.94 (15 m* / (16 E* sqrt(R*)))^(2/5) v^(-1/5) = 2.868 (m*^2/(R* E*^2 v))^(1/5)
    2.943_8 * (15.0 * m / (16.0 * e_star * r.sqrt())).powf(0.4) * v.powf(-0.2)
}

#[test]
fn hertz_contact_duration_matches_closed_form() {
    let (y, nu) = (7e10, 0.25);
    let p = liggghts(y, nu, 1.0, 0.0, 1.0);
    let e_star = y / (2.0 * (1.0 - nu * nu));
    for v in [0.1, 1.0, 5.0] {
        let b = two_spheres(v);
        let m = b[0].m / 2.0;
        let tc = hertz_tc(m, 0.5e-3, e_star, v);
        let (t, e, _) = impact(&LiggghtsHertz, &LiggghtsHistory, p, b, false, tc / 200.0);
        assert!(((t - tc) / tc).abs() < 0.01, "v={v}: t={t} tc={tc}");
        assert!((e - 1.0).abs() < 1e-6, "v={v}: e={e}");
        // sphere on a wall: R* = R, m* = m, E* mixed with the same material
        let b = vec![Body::sphere(1e-3, V3::new(0.0, 0.0, 1e-3), V3::new(0.0, 0.0, -v))];
        let tc = hertz_tc(b[0].m, 1e-3, e_star, v);
        let (t, _, _) = impact(&LiggghtsHertz, &LiggghtsHistory, p, b, true, tc / 200.0);
        assert!(((t - tc) / tc).abs() < 0.01, "wall v={v}: t={t} tc={tc}");
    }
}

#[test]
fn liggghts_restitution_is_the_requested_coefficient() {
    let (y, nu) = (7e10, 0.25);
    for e_req in [0.3, 0.5, 0.9] {
        let p = liggghts(y, nu, e_req, 0.0, 1.0);
        let e_star = y / (2.0 * (1.0 - nu * nu));
        for v in [0.1, 1.0, 5.0] {
            let b = two_spheres(v);
            let tc = hertz_tc(b[0].m / 2.0, 0.5e-3, e_star, v);
            let (_, e, _) = impact(&LiggghtsHertz, &LiggghtsHistory, p, b, false, tc / 200.0);
            assert!(((e - e_req) / e_req).abs() < 0.005, "hertz e={e_req} v={v}: {e}");
            // hooke: kn from characteristicVelocity; e independent of v
            let b = two_spheres(v);
            let ms = b[0].m / 2.0;
            let kn = demx::physics::normal::hooke::liggghts_hooke_kn(p.y_eff, 0.5e-3, ms, 1.0);
            let (t, e, _) = impact(&LiggghtsHooke::default(), &LiggghtsHistory, p, b, false, PI * (ms / kn).sqrt() / 200.0);
            assert!(((e - e_req) / e_req).abs() < 0.005, "hooke e={e_req} v={v}: {e}");
            // damped oscillator: t_c = pi / sqrt(kn/m* - (gamma_n/(2 m*))^2), gamma_n from ln e
            let le = e_req.ln();
            let gamma = (4.0 * ms * kn * le * le / (le * le + PI * PI)).sqrt();
            let tc = PI / (kn / ms - (gamma / (2.0 * ms)).powi(2)).sqrt();
            assert!(((t - tc) / tc).abs() < 0.01, "hooke tc e={e_req} v={v}: {t} vs {tc}");
        }
    }
}

#[test]
fn lammps_hooke_restitution_formula() {
    // pair_style gran/hooke/history kn kt gamma_n gamma_t ...: F = kn delta - m* gamma_n vn,
    // e = exp(-pi gamma_n / sqrt(4 kn/m* - gamma_n^2))
    let b = two_spheres(1.0);
    let ms = b[0].m / 2.0;
    let kn = 2e5 * b[0].m * 9.81 / 2e-3; // Silbert: kn = 2e5 m g / d
    let gamma_n = 50.0 * (9.81f64 / 2e-3).sqrt();
    let p = lammps_gran_params(kn, None, gamma_n, None, 0.5, true, false);
    let omega = (kn / ms - (gamma_n / 2.0).powi(2)).sqrt();
    let tc = PI / omega;
    let (t, e, _) = impact(&LammpsGranHooke, &LammpsGranHistory, p, b, false, tc / 200.0);
    let e_expected = (-PI * gamma_n / (4.0 * kn / ms - gamma_n * gamma_n).sqrt()).exp();
    assert!(((e - e_expected) / e_expected).abs() < 0.005, "{e} vs {e_expected}");
    assert!(((t - tc) / tc).abs() < 0.01, "{t} vs {tc}");
}

#[test]
fn elastic_impact_conserves_energy_and_momentum() {
    let p = liggghts(7e10, 0.25, 1.0, 0.0, 1.0);
    let (r1, r2) = (1e-3, 1.5e-3);
    let v = 2.0;
    let b =
        vec![Body::sphere(r1, V3::new(0.0, 0.0, r1), V3::new(0.0, 0.0, -v)), Body::sphere(r2, V3::new(0.0, 0.0, -r2), V3::new(0.0, 0.0, 0.3 * v))];
    let ke = |b: &[Body]| b.iter().map(|x| 0.5 * x.m * x.v.norm_squared()).sum::<f64>();
    let mom = |b: &[Body]| b.iter().map(|x| x.v * x.m).sum::<V3>();
    let (ke0, p0) = (ke(&b), mom(&b));
    let ms = m_eff(b[0].m, b[1].m);
    let tc = hertz_tc(ms, r_eff(r1, r2), 7e10 / (2.0 * (1.0 - 0.0625)), 1.3 * v);
    let (_, _, b1) = impact(&LiggghtsHertz, &LiggghtsHistory, p, b, false, tc / 200.0);
    assert!(((ke(&b1) - ke0) / ke0).abs() < 1e-6, "energy {} vs {}", ke(&b1), ke0);
    assert!((mom(&b1) - p0).norm() / p0.norm() < 1e-12);
}

/// A sphere launched without spin along a wall under gravity: it slides with
/// deceleration mu g until it rolls at v0 / (1 + I / (m l^2)), l the lever arm
/// (5/7 v0 for l = R; the tight tolerance tells R from R - delta/2).
fn sliding<T: TangentialLaw>(t: &T, lever_is_reduced: bool) {
    let (mu, g, v0) = (0.3, 9.81, 1.0);
    let p = liggghts(1e7, 0.3, 0.5, mu, 1.0);
    let r = 1e-3;
    let mut b = Body::sphere(r, V3::zeros(), V3::new(v0, 0.0, 0.0));
    // static overlap under gravity: 4/3 E* sqrt(R) delta^1.5 = m g
    let e_star = p.y_eff;
    let delta0 = (b.m * g / (4.0 / 3.0 * e_star * r.sqrt())).powf(2.0 / 3.0);
    b.x.z = r - delta0;
    let dt = 1e-5;
    let mut s = Sim::new(&LiggghtsHertz, t, p, vec![b], true, dt, g);
    let t_slide = 2.0 / 7.0 * v0 / (mu * g);
    let n1 = (0.2 * t_slide / dt) as usize;
    let n2 = (0.8 * t_slide / dt) as usize;
    for _ in 0..n1 {
        s.step();
    }
    let v1 = s.b[0].v.x;
    for _ in n1..n2 {
        s.step();
        // while sliding the friction force is at the Coulomb limit
        assert!((s.ft_last.norm() - mu * s.fn_last.abs()).abs() <= 0.02 * mu * s.fn_last.abs());
    }
    let v2 = s.b[0].v.x;
    let decel = (v1 - v2) / ((n2 - n1) as f64 * dt);
    assert!(((decel - mu * g) / (mu * g)).abs() < 0.01, "deceleration {decel}");
    for _ in n2..(3 * n2) {
        s.step();
    }
    let l = if lever_is_reduced { r - 0.5 * delta0 } else { r };
    let v_roll = v0 / (1.0 + s.b[0].inertia / (s.b[0].m * l * l));
    assert!(((s.b[0].v.x - v_roll) / v_roll).abs() < 2e-5, "rolling {} vs {v_roll}", s.b[0].v.x);
    // rolling without slip at the contact point
    assert!((s.b[0].v.x - s.b[0].w.y * l).abs() < 0.01 * v_roll);
}

#[test]
fn sliding_sphere_reaches_coulomb_limit_and_rolls_liggghts() {
    sliding(&LiggghtsHistory, true);
}

#[test]
fn sliding_sphere_reaches_coulomb_limit_and_rolls_lammps() {
    sliding(&LammpsGranHistory, false);
}

/// The run `liggghts` 3.8 makes (model hertz, tangential history, wall/gran
/// zplane, Y = 1e7, nu = 0.3, e = 0.5, mu = 0.3, R = 1 mm, rho = 2500,
/// gravity 981 m/s^2, start at the static overlap with vx = 1, dt = 1e-6,
/// 8000 steps) ends rolling at vx = 0.711714016194768: the lever arm
/// R - delta/2 (delta = 12.5 um), not 5/7.
#[test]
fn sliding_matches_liggghts_run() {
    let (g, r) = (981.0, 1e-3);
    let p = liggghts(1e7, 0.3, 0.5, 0.3, 1.0);
    let mut b = Body::sphere(r, V3::zeros(), V3::new(1.0, 0.0, 0.0));
    let delta0 = (b.m * g / (4.0 / 3.0 * p.y_eff * r.sqrt())).powf(2.0 / 3.0);
    b.x.z = r - delta0;
    let mut s = Sim::new(&LiggghtsHertz, &LiggghtsHistory, p, vec![b], true, 1e-6, g);
    for _ in 0..8000 {
        s.step();
    }
    assert!((s.b[0].v.x - 0.711714016194768).abs() < 1e-7, "{}", s.b[0].v.x);
}

/// LAMMPS `pair_style granular` restitution measured with `lmp` (29 Sep 2021,
/// docs in shared/physics/engines.md): hertz/material E = 5e6, nu = 0.45,
/// d = 2 mm, `damping tsuji` with e = 0.3/0.5/0.9 gives e_eff =
/// 0.440/0.616/0.928 (the alpha(e) fit under-damps).
#[test]
fn lammps_tsuji_restitution_matches_lmp() {
    use demx::physics::normal::granular::{GranularDamping, GranularNormal, LammpsGranular};
    use demx::physics::tangential::granular::LammpsLinearNoHistory;
    let law = LammpsGranular { model: GranularNormal::HertzMaterial, damping: GranularDamping::Tsuji };
    for (e_in, e_lmp) in [(0.3, 0.440), (0.5, 0.616), (0.9, 0.928)] {
        let gc = GranularCoeff {
            normal: GranularNormal::HertzMaterial,
            damping: GranularDamping::Tsuji,
            kn_or_e: 5e6,
            damp: e_in,
            poisson: 0.45,
            tangential: GranularTangentialChoice::NoHistory,
            kt: Some(0.0),
            x_gamma_t: 0.0,
            mu: 0.0,
            rolling: None,
            twisting: None,
            limit_damping: false,
        };
        let p = lammps_granular_params(&gc, false, span()).unwrap();
        for v in [0.2, 2.0] {
            let b = two_spheres(v);
            let tc = hertz_tc(b[0].m / 2.0, 0.5e-3, p.y_eff, v);
            let (_, e, _) = impact(&law, &LammpsLinearNoHistory, p, b, false, tc / 400.0);
            assert!((e - e_lmp).abs() < 0.0015, "e_in={e_in} v={v}: {e} vs lmp {e_lmp}");
        }
    }
}

use crate::common;

type Frames = std::collections::BTreeMap<i64, std::collections::BTreeMap<i64, Vec<f64>>>;

/// A grazing collision of two spheres falling onto a floor (the first
/// spinning about z), with the
/// contact model `model` (pair and wall) and the extra `props`, run by
/// LIGGGHTS and by demx: their dumps (id x y z v omega), which must agree
/// to rounding.
fn grazing_pair(model: &str, props: &str) -> (Frames, Frames) {
    let deck = format!(
        "atom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\n\
region reg block -0.01 0.01 -0.01 0.01 0 0.01 units box\ncreate_box 1 reg\nneighbor 0.0005 bin\nneigh_modify delay 0\n\
fix m1 all property/global youngsModulus peratomtype 5.e6\nfix m2 all property/global poissonsRatio peratomtype 0.45\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
{props}pair_style gran {model}\npair_coeff * *\ntimestep 1e-6\n\
fix floor all wall/gran {model} primitive type 1 zplane 0.0\n\
create_atoms 1 single -0.002 0.0 0.0012 units box\ncreate_atoms 1 single 0.002 0.0006 0.0011 units box\n\
set group all diameter 0.002 density 2500\ngroup a id 1\ngroup b id 2\n\
velocity a set 1.0 0.0 -0.3 units box\nvelocity b set -1.0 0.0 -0.2 units box\nset group a omegaz 50.0\n\
fix 1 all nve/sphere\nfix g all gravity 9.81 vector 0.0 0.0 -1.0\n\
dump d all custom 500 dump.c id x y z vx vy vz omegax omegay omegaz\n\
dump_modify d sort id format \"%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\nrun 4000\n"
    );
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &deck)]);
    let (theirs, ours) = (common::dump_frames(&b.theirs.path().join("dump.c")), common::dump_frames(&b.ours.path().join("dump.c")));
    assert_eq!(theirs.keys().collect::<Vec<_>>(), ours.keys().collect::<Vec<_>>());
    // the spheres met (their x velocities turned)
    let last = ours.values().last().unwrap();
    assert!(last[&1][3] < 0.0 && last[&2][3] > 0.0, "{model}: no collision: {last:?}");
    for (step, rows) in &theirs {
        for (id, t) in rows {
            let o = &ours[step][id];
            for k in 0..9 {
                let scale = if k < 3 { 0.01 } else { 1.0 };
                assert!((t[k] - o[k]).abs() <= 1e-10 * scale, "{model}: step {step} atom {id} column {k}: liggghts {} demx {}", t[k], o[k]);
            }
        }
    }
    (theirs, ours)
}

/// LIGGGHTS `tangential off`: a grazing collision of two spheres (and of
/// each with a floor) pushes only along the normals, so no sphere's spin
/// changes, and the run is the one LIGGGHTS 3.8 makes, to rounding (with
/// the spin that `set ... omegaz` gives one of them).
#[test]
fn tangential_off_pushes_along_the_normal_only_as_liggghts() {
    // no coefficientFriction: LIGGGHTS reads none for tangential off
    let (_, ours) = grazing_pair("model hertz tangential off", "");
    let (first, last) = (&ours[&0], ours.values().last().unwrap());
    for (step, rows) in &ours {
        for (id, o) in rows {
            // no torque at any contact: sphere 1 keeps the spin `set omegaz`
            // gave it, sphere 2 never spins
            let spin = if *id == 1 { [0.0, 0.0, 50.0] } else { [0.0; 3] };
            assert_eq!(o[6..9], spin, "step {step} atom {id}");
        }
    }
    // the frictionless floor pushes along z only and the pair's pushes are
    // equal and opposite: the y momentum stays (the spheres are alike)
    let py = |rows: &std::collections::BTreeMap<i64, Vec<f64>>| rows[&1][4] + rows[&2][4];
    assert!((py(first) - py(last)).abs() < 1e-12, "y momentum changed: {} -> {}", py(first), py(last));
}

/// `rolling_friction epsd3` reads its stiffness factor from
/// `rollingStiffness` (a scalar), as LIGGGHTS 3.8 does (its documentation
/// says coeffRollingStiffness, which the engine does not read): the
/// spinning spheres' rolling torques as LIGGGHTS computes them.
#[test]
fn epsd3_reads_rolling_stiffness_as_liggghts() {
    let props = "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.3\n\
fix m6 all property/global coefficientRollingViscousDamping peratomtypepair 1 0.2\n\
fix m7 all property/global rollingStiffness scalar 2.0\n";
    let (_, ours) = grazing_pair("model hertz tangential history rolling_friction epsd3", props);
    let last = ours.values().last().unwrap();
    assert!(last.values().all(|o| o[6..9].iter().any(|&w| w.abs() > 1.0)), "the spheres do not spin: {last:?}");
}

/// A LIGGGHTS deck without `thermo_style` prints LIGGGHTS's own columns
/// (`Step Atoms KinEng CPU`), not LAMMPS's, and the same values (the CPU
/// column is each program's clock); a LAMMPS deck keeps LAMMPS's; with a
/// shrink-wrapped box both add `Volume`.
#[test]
fn default_thermo_columns_are_the_dialects() {
    let deck = "atom_style sphere\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\n\
region reg block 0 1 0 1 0 1 units box\ncreate_box 1 reg\nneighbor 0.01 bin\n\
fix m1 all property/global youngsModulus peratomtype 5.e6\nfix m2 all property/global poissonsRatio peratomtype 0.45\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\nfix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 1e-5\n\
create_atoms 1 single 0.5 0.5 0.5\ncreate_atoms 1 single 0.2 0.5 0.5\nset group all diameter 0.1 density 2500\n\
velocity all set 1 0 0\nfix 1 all nve/sphere\nfix g all gravity 9.81 vector 0 0 -1\nthermo 5\nrun 10\n";
    let header = |out: &str| out.lines().find(|l| l.trim_start().starts_with("Step")).map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "));
    // a shrink-wrapped box adds the Volume column (both engines)
    let shrunk = deck.replace("boundary f f f", "boundary m m m");
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &shrunk)]);
    assert_eq!(header(&b.theirs_out).as_deref(), Some("Step Atoms KinEng CPU Volume"));
    assert_eq!(header(&b.ours_out), header(&b.theirs_out));
    let lammps = "units si\natom_style sphere\nboundary m m m\ncomm_modify vel yes\nregion reg block 0 1 0 1 0 1 units box\ncreate_box 1 reg\n\
create_atoms 1 single 0.5 0.5 0.5\nset group all diameter 0.1 density 2500\npair_style gran/hooke 2e5 NULL 50 NULL 0.5 0\npair_coeff * *\n\
velocity all set 1 0 0\nfix 1 all nve/sphere\nthermo 5\nrun 10\n";
    let b = common::engine_and_demx("lmp", "in.deck", &[("in.deck", lammps)]);
    assert_eq!(header(&b.theirs_out).as_deref(), Some("Step Temp E_pair E_mol TotEng Press Volume"));
    assert_eq!(header(&b.ours_out), header(&b.theirs_out));
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", deck)]);
    let (theirs, ours) = (common::thermo_runs(&b.theirs_out), common::thermo_runs(&b.ours_out));
    assert_eq!(header(&b.theirs_out).as_deref(), Some("Step Atoms KinEng CPU"));
    assert_eq!(header(&b.ours_out), header(&b.theirs_out));
    assert_eq!(theirs[0].len(), 3, "{theirs:?}");
    for (t, o) in theirs[0].iter().zip(&ours[0]) {
        assert_eq!(t[..2], o[..2]);
        let (kt, ko): (f64, f64) = (t[2].parse().unwrap(), o[2].parse().unwrap());
        assert!(kt > 1.0 && (kt - ko).abs() <= 1e-7 * kt, "KinEng: liggghts {kt} demx {ko}");
    }
}
