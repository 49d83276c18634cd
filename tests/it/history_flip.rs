//! Each law's `FLIP` (how its history turns when a pair's two particles swap
//! roles), checked by physics: a contact computed from i's side with history
//! h must give the same forces and torques, and the same new history, as the
//! contact computed from j's side with h turned by the kernel's
//! `history_signs()`. Every law with history is run in a combination
//! `build_kernel` builds, on pairs of spheres that stick and that slide.

use demx::engine::kernel::{pair_contact, ContactKernel, PassState};
use demx::engine::particles::{NewParticle, Particles};
use demx::physics::normal::granular::{GranularDamping, GranularNormal};
use demx::physics::tangential::granular::GranularTangential;
use demx::physics::{PairParams, V3};
use demx::scene::model::{build_kernel, CohesionSpec, CohesiveNormal, GranularTwisting, NormalSpec, PairSpec, RollingSpec, TangentialSpec};
use demx::script::Span;

const DT: f64 = 1e-6;
/// Steps from i's side before the swap (history builds up), then steps from
/// both sides after it.
const WARMUP: usize = 30;
const AFTER: usize = 5;
const REL: f64 = 1e-12;

/// A pair style and the coefficients its laws read.
struct Combo {
    name: &'static str,
    spec: PairSpec,
    params: fn(&Case) -> PairParams,
    /// History slots a law keeps but this combination never writes.
    unused: &'static [usize],
}

/// One pair of spheres: contact state and the friction coefficients that
/// decide whether it sticks or slides.
struct Case {
    name: &'static str,
    seed: u64,
    /// Scale of the tangential relative velocity (m/s) and of the spins (rad/s).
    v_t: f64,
    spin: f64,
    /// Sliding and rolling friction coefficients.
    mu: f64,
    mu_r: f64,
    /// Whether j is frozen (infinite mass for the contact).
    frozen_j: bool,
    /// Whether the tangential force must end at its Coulomb cap (true),
    /// below it (false), or either (None).
    slides: Option<bool>,
}

const CASES: &[Case] = &[
    Case { name: "stick", seed: 1, v_t: 0.002, spin: 2.0, mu: 0.9, mu_r: 0.5, frozen_j: false, slides: Some(false) },
    Case { name: "stick2", seed: 2, v_t: 0.004, spin: 5.0, mu: 0.7, mu_r: 0.3, frozen_j: false, slides: Some(false) },
    Case { name: "slide", seed: 3, v_t: 0.8, spin: 800.0, mu: 0.02, mu_r: 0.002, frozen_j: false, slides: Some(true) },
    Case { name: "slide2", seed: 4, v_t: 0.5, spin: 300.0, mu: 0.05, mu_r: 0.005, frozen_j: false, slides: Some(true) },
    Case { name: "mixed", seed: 5, v_t: 0.05, spin: 60.0, mu: 0.3, mu_r: 0.05, frozen_j: false, slides: None },
    Case { name: "frozen j stick", seed: 6, v_t: 0.002, spin: 2.0, mu: 0.9, mu_r: 0.5, frozen_j: true, slides: Some(false) },
    Case { name: "frozen j slide", seed: 7, v_t: 0.8, spin: 800.0, mu: 0.02, mu_r: 0.002, frozen_j: true, slides: Some(true) },
];

fn spec(normal: NormalSpec, tangential: TangentialSpec, cohesion: CohesionSpec, rolling: RollingSpec) -> PairSpec {
    PairSpec { normal, tangential, cohesion, rolling, ..PairSpec::new(Span::DUMMY, true) }
}

/// Coefficients of the LIGGGHTS laws (and the paper's) for 1 mm glass-like
/// spheres of a soft material: Y* = 1e7 Pa, G* = 4e6 Pa.
fn liggghts(c: &Case) -> PairParams {
    PairParams {
        y_eff: 1e7,
        g_eff: 4e6,
        restitution: 0.6,
        beta: -0.16,
        mu: c.mu,
        mu_r: c.mu_r,
        eta_r: 0.3,
        k_r_coeff: 1.7,
        cohesion: 3e4,
        char_vel: 0.5,
        kn: 2e3,
        kt: 6e2,
        gamma_n: 0.04,
        gamma_t: 0.02,
        tangential_damping: 1.0,
        ..Default::default()
    }
}

/// As [`liggghts`] with `limitForce on` and absolute damping constants.
fn liggghts_limited(c: &Case) -> PairParams {
    PairParams { limit_damping: 1.0, ..liggghts(c) }
}

/// The paper's model: Müller-Pöschel beta > 0, van der Waals reaching 5 um.
fn paper(c: &Case) -> PairParams {
    PairParams { beta: 0.3, hamaker: 1e-19, d_min: 4e-10, d_max: 5e-6, extra_range: 5e-6, ..liggghts(c) }
}

/// LAMMPS gran/*: Kn (N/m, or Pa for hertz), Kt, gamma_n, gamma_t (1/s).
fn gran_hooke(c: &Case) -> PairParams {
    PairParams { kn: 2e3, kt: 6e2, gamma_n: 5e3, gamma_t: 2e3, mu: c.mu, ..Default::default() }
}

fn gran_hertz(c: &Case) -> PairParams {
    PairParams { kn: 2e7, kt: 6e6, ..gran_hooke(c) }
}

/// LAMMPS granular: kn = 4/3 E_eff (hertz, jkr, dmt), kt for the mindlin
/// models 8 G_eff (times a in the law), x_gamma_t, rolling and twisting sds.
fn granular(c: &Case) -> PairParams {
    PairParams {
        y_eff: 1e7,
        kn: 4.0 / 3.0 * 1e7,
        kt: 3.2e7,
        gamma_n: 0.4,
        gamma_t: 0.5,
        mu: c.mu,
        mu_r: c.mu_r,
        cohesion: 0.05,
        k_roll: 1e3,
        gamma_roll: 0.02,
        k_twist: 1e-4,
        gamma_twist: 1e-8,
        mu_twist: c.mu_r * 1e-3,
        ..Default::default()
    }
}

/// As [`granular`] for `hooke` and `linear_history`: kn, kt in N/m, damping
/// `mass_velocity` (1/s).
fn granular_linear(c: &Case) -> PairParams {
    PairParams { kn: 2e3, kt: 6e2, gamma_n: 5e3, ..granular(c) }
}

/// As [`granular`] for `velocity` damping (N s/m), and a lower surface
/// energy (DMT's pull-off force takes from the friction cap).
fn granular_velocity(c: &Case) -> PairParams {
    PairParams { gamma_n: 0.05, cohesion: 0.02, ..granular(c) }
}

/// As [`granular`] for `tsuji` damping (alpha(e)).
fn granular_tsuji(c: &Case) -> PairParams {
    PairParams { gamma_n: 0.8, ..granular(c) }
}

/// As [`granular`] for `viscoelastic` damping (1/(m s)).
fn granular_visco(c: &Case) -> PairParams {
    PairParams { gamma_n: 2e8, ..granular(c) }
}

fn combos() -> Vec<Combo> {
    use CohesionSpec as C;
    use GranularTangential as GT;
    use NormalSpec as N;
    use RollingSpec as R;
    use TangentialSpec as T;
    let lmp = |rolling, twisting| R::Lammps { rolling, twisting };
    vec![
        Combo {
            name: "hertz history sjkr epsd2",
            spec: spec(N::LigHertz, T::LigHistory, C::Sjkr { tangential_reduce: true }, R::Epsd2 { torsion: false }),
            params: liggghts,
            unused: &[],
        },
        Combo {
            name: "hertz/stiffness history epsd2 torsion",
            spec: spec(N::LigHertzStiffness, T::LigHistory, C::Off, R::Epsd2 { torsion: true }),
            params: liggghts_limited,
            unused: &[],
        },
        Combo {
            name: "hertz history sjkr2 epsd torsion",
            spec: spec(N::LigHertz, T::LigHistory, C::Sjkr2 { tangential_reduce: false }, R::Epsd { torsion: true }),
            params: liggghts,
            unused: &[],
        },
        Combo {
            name: "hooke history epsd",
            spec: spec(N::LigHooke { kt_to_kn: false }, T::LigHistory, C::Off, R::Epsd { torsion: false }),
            params: liggghts,
            unused: &[],
        },
        Combo {
            name: "hooke ktToKn history epsd3",
            spec: spec(N::LigHooke { kt_to_kn: true }, T::LigHistory, C::Off, R::Epsd3 { torsion: false }),
            params: liggghts,
            unused: &[],
        },
        Combo {
            name: "hooke/stiffness history sjkr epsd3 torsion",
            spec: spec(N::LigHookeStiffness { absolute: true }, T::LigHistory, C::Sjkr { tangential_reduce: false }, R::Epsd3 { torsion: true }),
            params: liggghts_limited,
            unused: &[],
        },
        Combo { name: "hertz history cdt", spec: spec(N::LigHertz, T::LigHistory, C::Off, R::Cdt), params: liggghts, unused: &[] },
        Combo {
            name: "paper: viscoelastic history/paper vdw epsd/paper",
            spec: spec(N::PaperViscoelastic, T::PaperHistory, C::Vdw { tangential_reduce: false }, R::PaperEpsd { torsion: false }),
            params: paper,
            unused: &[],
        },
        Combo {
            name: "paper: viscoelastic history/paper vdw reduce epsd/paper torsion",
            spec: spec(N::PaperViscoelastic, T::PaperHistory, C::Vdw { tangential_reduce: true }, R::PaperEpsd { torsion: true }),
            params: paper,
            unused: &[],
        },
        Combo {
            name: "viscoelastic history epsd2",
            spec: spec(N::PaperViscoelastic, T::LigHistory, C::Off, R::Epsd2 { torsion: false }),
            params: paper,
            unused: &[],
        },
        Combo { name: "gran/hooke/history", spec: spec(N::GranHooke, T::GranHistory, C::Off, R::Off), params: gran_hooke, unused: &[] },
        Combo { name: "gran/hertz/history", spec: spec(N::GranHertz, T::GranHistory, C::Off, R::Off), params: gran_hertz, unused: &[] },
        Combo {
            name: "granular hertz linear_history rolling sds twisting sds",
            spec: spec(
                N::Granular(GranularNormal::Hertz, GranularDamping::Viscoelastic),
                T::Granular(GT::LinearHistory),
                C::Off,
                lmp(true, GranularTwisting::Sds),
            ),
            params: |c| PairParams { kt: 6e2, ..granular_visco(c) },
            // the previous contact radius: rescale models only
            unused: &[3],
        },
        Combo {
            name: "granular hooke mindlin rolling sds",
            spec: spec(
                N::Granular(GranularNormal::Hooke, GranularDamping::MassVelocity),
                T::Granular(GT::Mindlin),
                C::Off,
                lmp(true, GranularTwisting::None),
            ),
            params: |c| PairParams { kt: 3.2e7, ..granular_linear(c) },
            // the previous contact radius; the sds twist angle (no twisting)
            unused: &[3, 7],
        },
        Combo {
            name: "granular hertz/material mindlin_rescale twisting marshall",
            spec: spec(
                N::Granular(GranularNormal::HertzMaterial, GranularDamping::Tsuji),
                T::Granular(GT::MindlinRescale),
                C::Off,
                lmp(false, GranularTwisting::Marshall),
            ),
            params: granular_tsuji,
            unused: &[],
        },
        Combo {
            name: "granular jkr mindlin_rescale/force rolling sds twisting marshall",
            spec: spec(
                N::GranularCohesive(CohesiveNormal::Jkr, GranularDamping::Viscoelastic),
                T::Granular(GT::MindlinRescaleForce),
                C::Off,
                lmp(true, GranularTwisting::Marshall),
            ),
            params: granular_visco,
            // LammpsSdsMarshall's slot of the sds twist angle
            unused: &[8],
        },
        Combo {
            name: "granular dmt mindlin/force twisting sds",
            spec: spec(
                N::GranularCohesive(CohesiveNormal::Dmt, GranularDamping::Velocity),
                T::Granular(GT::MindlinForce),
                C::Off,
                lmp(false, GranularTwisting::Sds),
            ),
            // twisting alone: rolling sds sees zero coefficients (as the deck
            // gives them), yet sums its displacement
            params: |c| PairParams { k_roll: 0.0, gamma_roll: 0.0, ..granular_velocity(c) },
            // the previous contact radius (not a rescale model)
            unused: &[3],
        },
    ]
}

/// A uniform number in [0, 1).
struct Rng(u64);
impl Rng {
    fn u(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn sym(&mut self) -> f64 {
        2.0 * self.u() - 1.0
    }
    fn vec(&mut self) -> V3 {
        V3::new(self.sym(), self.sym(), self.sym())
    }
    fn unit(&mut self) -> V3 {
        loop {
            let v = self.vec();
            if v.norm() > 0.2 && v.norm() < 1.0 {
                return v.normalize();
            }
        }
    }
}

/// Two overlapping spheres (about 1 mm) of case `c`: particle 0 and 1.
fn pair(c: &Case) -> Particles {
    let mut g = Rng(c.seed.wrapping_mul(0x9e3779b97f4a7c15) ^ 0x5bd1e995);
    for _ in 0..4 {
        g.u();
    }
    let ri = 1e-3 * (0.7 + 0.6 * g.u());
    let rj = 1e-3 * (0.7 + 0.6 * g.u());
    let r_eff = ri * rj / (ri + rj);
    let n = g.unit();
    let delta = r_eff * (0.004 + 0.01 * g.u());
    let xi = V3::new(g.sym(), g.sym(), g.sym()) * 0.01;
    let xj = xi - n * (ri + rj - delta);
    // slow approach or separation (the contact lasts the whole run), a
    // tangential velocity of about v_t
    let vn = delta * 1e3 * g.sym() * 0.3;
    let u = g.unit();
    let t = (u - n * n.dot(&u)).normalize();
    let vrel = n * vn + t * (c.v_t * (0.7 + 0.6 * g.u()));
    let vj = g.vec() * 0.01;
    let mut p = Particles::default();
    let mut add = |tag, x, v, omega, radius, density| p.push(NewParticle { tag, kind: 1, mask: 1, x, v, omega, radius, density });
    add(1, xi, vj + vrel, g.vec() * c.spin, ri, 2500.0 * (0.8 + 0.4 * g.u()));
    add(2, xj, vj, g.vec() * c.spin, rj, 2500.0 * (0.8 + 0.4 * g.u()));
    if c.frozen_j {
        p.frozen[1] = true;
        p.v[0] = vrel;
        p.v[1] = V3::zeros();
        p.omega[1] = V3::zeros();
    }
    p
}

/// Largest deviation found, relative to the size of the compared vectors,
/// and whether every comparison was bitwise equal.
struct Tally {
    worst: f64,
    bitwise: bool,
    count: usize,
    /// What differed in its last bits (case: quantity).
    inexact: std::collections::BTreeSet<String>,
}

impl Tally {
    fn new() -> Tally {
        Tally { worst: 0.0, bitwise: true, count: 0, inexact: Default::default() }
    }
    /// Compare `a` (from i's side) with `b` (from j's side, turned back).
    fn check(&mut self, what: &str, a: &[f64], b: &[f64]) {
        assert_eq!(a.len(), b.len());
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let diff: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        let scale = norm(a).max(norm(b));
        let dev = norm(&diff);
        assert!(a.iter().chain(b).all(|x| x.is_finite()), "{what}: not finite: {a:?} vs {b:?}");
        assert!(dev <= REL * scale + 1e-300, "{what}: {a:?} vs {b:?} (relative deviation {:e})", dev / scale);
        if scale > 0.0 {
            self.worst = self.worst.max(dev / scale);
        }
        if a.iter().zip(b).any(|(x, y)| x.to_bits() != y.to_bits()) {
            self.bitwise = false;
            let mut parts = what.split(" / ").skip(1);
            let case = parts.next().unwrap_or("");
            let quantity = what.rsplit(": ").next().unwrap_or("");
            self.inexact.insert(format!("{case}: {quantity}"));
        }
        self.count += 1;
    }
}

fn v(x: V3) -> [f64; 3] {
    [x.x, x.y, x.z]
}

/// Run `combo` on `case`; returns which history slots were ever non-zero
/// and whether the tangential force sat on its cap at the last step.
fn run(combo: &Combo, case: &Case, kernel: &dyn ContactKernel, tally: &mut Tally) -> (Vec<bool>, bool) {
    let pp = (combo.params)(case);
    let signs = kernel.history_signs();
    let w = kernel.history_width();
    assert_eq!(signs.len(), w, "{}: history_signs has {} factors for {w} values", combo.name, signs.len());
    let mut p = pair(case);
    let advance = |p: &mut Particles| {
        for k in 0..2 {
            let v = p.v[k];
            p.x[k] += v * DT;
        }
    };
    // history from i's side
    let mut h = vec![0.0; w];
    let mut seen = vec![false; w];
    for _ in 0..WARMUP {
        let (c, _) = pair_contact(&PassState::of(&p), 0, 1, p.x[1], DT).unwrap();
        kernel.contact(&c, &pp, &mut h);
        for (s, x) in seen.iter_mut().zip(&h) {
            *s |= *x != 0.0;
        }
        advance(&mut p);
    }
    // then i's side with h and j's side with h turned, step by step
    let mut hi = h.clone();
    let mut hj: Vec<f64> = h.iter().zip(&signs).map(|(x, s)| x * s).collect();
    let mut at_cap = false;
    for step in 0..AFTER {
        let what = |q: &str| format!("{} / {} / step {step}: {q}", combo.name, case.name);
        let (ci, _) = pair_contact(&PassState::of(&p), 0, 1, p.x[1], DT).unwrap();
        let (cj, _) = pair_contact(&PassState::of(&p), 1, 0, p.x[0], DT).unwrap();
        assert!(ci.delta > 0.0, "{}", what("apart"));
        let oi = kernel.contact(&ci, &pp, &mut hi);
        let oj = kernel.contact(&cj, &pp, &mut hj);
        tally.check(&what("force on i"), &v(oi.force_i(&ci)), &v(-oj.force_i(&cj)));
        tally.check(&what("torque on i"), &v(oi.torque_i), &v(oj.torque_j));
        tally.check(&what("torque on j"), &v(oi.torque_j), &v(oj.torque_i));
        let turned: Vec<f64> = hj.iter().zip(&signs).map(|(x, s)| x * s).collect();
        tally.check(&what("history"), &hi, &turned);
        for (s, x) in seen.iter_mut().zip(&hi) {
            *s |= *x != 0.0;
        }
        let cap = pp.mu * oi.fn_for_friction.abs();
        at_cap = (oi.ft.norm() - cap).abs() <= 1e-9 * cap;
        advance(&mut p);
    }
    (seen, at_cap)
}

#[test]
fn history_turned_by_flip_gives_the_contact_seen_from_the_other_side() {
    let mut report = vec![];
    for combo in combos() {
        let kernel = build_kernel(&combo.spec).unwrap_or_else(|e| panic!("{}: {e}", combo.name));
        let mut tally = Tally::new();
        let mut seen = vec![false; kernel.history_width()];
        for case in CASES {
            let (s, at_cap) = run(&combo, case, kernel.as_ref(), &mut tally);
            for (a, b) in seen.iter_mut().zip(s) {
                *a |= b;
            }
            if let Some(slides) = case.slides {
                assert_eq!(at_cap, slides, "{} / {}: sliding is {at_cap}, wanted {slides}", combo.name, case.name);
            }
        }
        // every history value was exercised (non-zero at some point)
        for (k, s) in seen.iter().enumerate() {
            assert_eq!(*s, !combo.unused.contains(&k), "{}: history slot {k} non-zero: {s}", combo.name);
        }
        report.push(format!(
            "{:<66} signs {:?}: {} comparisons, {}",
            combo.name,
            kernel.history_signs(),
            tally.count,
            if tally.bitwise {
                "bitwise equal".to_string()
            } else {
                format!("largest relative deviation {:.1e} ({})", tally.worst, tally.inexact.iter().cloned().collect::<Vec<_>>().join(", "))
            }
        ));
    }
    eprintln!("{}", report.join("\n"));
}
