//! Stability suite (issue #9 item 3): decks written here, run through the
//! library (`Session` + `Interpreter`) in chunks so the test can look at the
//! particles between chunks. Each case checks bounded energy (the energy the
//! test computes itself from positions and velocities never exceeds what the
//! initial state can release), no NaN, no lost particle, and a physical
//! outcome from closed forms:
//!
//! - the paper's extremes (Elekes & Parteli 2021): a glass cluster at
//!   Y = 63 GPa with van der Waals sticks and cools; confined piles at
//!   g = 0.06 and 100 g_Earth hold; a layer resting under its own weight
//!   neither creeps nor gains energy;
//! - stiff two-sphere impacts with dt = 10 % and 30 % of the Hertz collision
//!   time keep the requested restitution;
//! - a nearly elastic granular gas cools by Haff's law;
//! - an overlapping lattice explodes within its initial Hertz energy;
//! - corners, edges and vertices of primitive, region and mesh walls;
//! - grazing wall impacts (60-89 degrees) in both dialects;
//! - the van der Waals force around D_min and D_max;
//! - fast particles crossing periodic boundaries.
//!
//! The default run uses short versions; `DEMX_LONG=1` runs the same cases at
//! full length.

use demx::engine::particles::Particles;
use demx::physics::V3;
use demx::scene::Session;
use demx::script::{Interpreter, SourceMap};
use std::f64::consts::PI;
use std::time::Instant;

// ------------------------------------------------------------------ harness

/// Whether the long versions were asked for.
fn long() -> bool {
    std::env::var("DEMX_LONG").is_ok_and(|v| v == "1")
}

/// `fast` steps in the default run, `full` with DEMX_LONG=1.
fn steps(fast: u64, full: u64) -> u64 {
    if long() {
        full
    } else {
        fast
    }
}

/// A deck run through the library, continued chunk by chunk.
struct Run {
    s: Session,
    it: Interpreter,
    chunks: usize,
    started: Instant,
    name: String,
}

impl Run {
    fn new(name: &str, deck: &str) -> Run {
        let mut s = Session::new(false);
        s.sim.log.screen = false;
        let mut it = Interpreter::new(SourceMap::new(), Vec::new());
        // `run 0` initialises the scene (model, tables, fixes); later chunks
        // call the engine directly (the deck-level `run` re-initialises the
        // scene every time, which costs ~0.2 s with restitutionExact)
        let deck = format!("{deck}run 0 post no\n");
        if let Err(e) = it.run_text("in.stability", &deck, &mut s) {
            panic!("{name}: deck failed: {}\n{deck}", e.render(&it.sources));
        }
        Run { s, it, chunks: 0, started: Instant::now(), name: name.to_string() }
    }

    fn cmd(&mut self, text: &str) {
        self.chunks += 1;
        let file = format!("chunk{}", self.chunks);
        if let Err(e) = self.it.run_text(&file, text, &mut self.s) {
            panic!("{}: '{}' failed at step {}: {}", self.name, text.trim(), self.s.sim.step, e.render(&self.it.sources));
        }
    }

    fn run(&mut self, n: u64) {
        if let Err(e) = self.s.sim.run(n as i64, &self.it.vars, false, false) {
            panic!("{}: run failed at step {}: {}", self.name, self.s.sim.step, e.render(&self.it.sources));
        }
    }

    fn p(&self) -> &Particles {
        &self.s.sim.particles
    }

    fn time(&self) -> f64 {
        self.s.sim.time
    }

    /// No NaN or infinity in any state column.
    fn assert_finite(&self) {
        let p = self.p();
        for i in 0..p.len() {
            for v in [p.x[i], p.v[i], p.omega[i], p.f[i], p.torque[i]] {
                assert!(
                    v.iter().all(|c| c.is_finite()),
                    "{}: atom {} not finite at step {}: x {:?} v {:?} f {:?}",
                    self.name,
                    p.tag[i],
                    self.s.sim.step,
                    p.x[i],
                    p.v[i],
                    p.f[i]
                );
            }
        }
    }

    /// Translational plus rotational kinetic energy.
    fn kinetic(&self) -> f64 {
        let p = self.p();
        (0..p.len()).map(|i| 0.5 * p.mass[i] * p.v[i].norm_squared() + 0.5 * p.inertia(i) * p.omega[i].norm_squared()).sum()
    }

    fn done(&self) {
        eprintln!("{}: {} steps in {:.2} s", self.name, self.s.sim.step, self.started.elapsed().as_secs_f64());
    }
}

/// Deterministic uniform numbers in [0, 1) (xorshift64*).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u1, u2) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

// ------------------------------------------------------------- deck pieces

/// Box, granular atom style and neighbour settings (LIGGGHTS dialect).
fn header(boundary: &str, lo: [f64; 3], hi: [f64; 3], ntypes: usize, skin: f64) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary {boundary}\nnewton off\ncommunicate single vel yes\nunits si\nhard_particles yes\n\
         region reg block {} {} {} {} {} {} units box\ncreate_box {ntypes} reg\nneighbor {skin:e} bin\nneigh_modify delay 0\n",
        lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
    )
}

/// LIGGGHTS material properties: one Young's modulus and Poisson ratio for
/// all types, restitution matrix `e` (row-major, ntypes x ntypes), one
/// friction coefficient.
fn materials(ntypes: usize, y: f64, nu: f64, e: &[f64], mu: f64) -> String {
    let rep = |v: f64, n: usize| vec![format!("{v:e}"); n].join(" ");
    let es: Vec<String> = e.iter().map(|v| v.to_string()).collect();
    format!(
        "fix m1 all property/global youngsModulus peratomtype {}\nfix m2 all property/global poissonsRatio peratomtype {}\n\
         fix m3 all property/global coefficientRestitution peratomtypepair {ntypes} {}\n\
         fix m4 all property/global coefficientFriction peratomtypepair {ntypes} {}\n",
        rep(y, ntypes),
        rep(nu, ntypes),
        es.join(" "),
        rep(mu, ntypes * ntypes)
    )
}

/// The paper's glass (Table 1): nu 0.24, rho 2500, friction 0.5, rolling
/// friction 0.05, restitution 0.2 at 1 m/s, gamma 0.05 J/m^2,
/// D_min 1.65 A, D_max 1 um. Pair style and a cohesionless floor-type wall
/// are written by the caller.
const PAPER_NU: f64 = 0.24;
const PAPER_RHO: f64 = 2500.0;
const PAPER_GAMMA: f64 = 0.05;
const D_MIN: f64 = 1.65e-10;
const D_MAX: f64 = 1e-6;
const PAPER_MODEL: &str = "model hertz/viscoelastic tangential history/paper cohesion vdw rolling_friction epsd/paper";
const PAPER_WALL: &str = "model hertz/viscoelastic tangential history/paper rolling_friction epsd/paper";

fn paper_props(y: f64, e_ref: f64, gamma: f64) -> String {
    format!(
        "{}fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.05\n\
         fix m6 all property/global restitutionReferenceVelocity scalar 1.0\n\
         fix m7 all property/global surfaceEnergy peratomtypepair 1 {gamma}\n\
         fix m8 all property/global vdwMinDistance scalar {D_MIN:e}\nfix m9 all property/global vdwCutoff scalar {D_MAX:e}\n",
        materials(1, y, PAPER_NU, &[e_ref], 0.5)
    )
}

/// `create_atoms` for each position, then diameter and density of type `t`.
fn atoms(t: usize, pos: &[V3], d: f64, rho: f64) -> String {
    let mut s = String::new();
    for x in pos {
        s += &format!("create_atoms {t} single {:.17e} {:.17e} {:.17e} units box\n", x.x, x.y, x.z);
    }
    s + &format!("set type {t} diameter {d:e}\nset type {t} density {rho}\n")
}

// -------------------------------------------------------- energy (analytic)

/// Effective modulus of two bodies of the same material (LIGGGHTS mixing:
/// 1/Y* = 2 (1 - nu^2) / Y).
fn y_star(y: f64, nu: f64) -> f64 {
    y / (2.0 * (1.0 - nu * nu))
}

/// Hertz elastic energy of an overlap: F = 4/3 Y* sqrt(R*) delta^{3/2}
/// integrates to U = 8/15 Y* sqrt(R*) delta^{5/2}.
fn hertz_energy(ys: f64, r_eff: f64, delta: f64) -> f64 {
    if delta > 0.0 {
        8.0 / 15.0 * ys * r_eff.sqrt() * delta.powf(2.5)
    } else {
        0.0
    }
}

/// Hamaker constant A_H = 24 pi D_min^2 gamma (paper Eq. 14).
fn hamaker(gamma: f64) -> f64 {
    24.0 * PI * D_MIN * D_MIN * gamma
}

/// Potential of the paper's van der Waals force (Eq. 13), zero beyond
/// D_max: F = A R*/(6 (D_min - delta)^2) across a gap (delta <= 0) integrates
/// to -A R*/6 (1/(D_min - delta) - 1/(D_min + D_max)); in contact the force
/// is the constant A R*/(6 D_min^2), so U continues linearly in delta.
fn vdw_energy(a_h: f64, r_eff: f64, delta: f64) -> f64 {
    let c = a_h * r_eff / 6.0;
    if delta < -D_MAX {
        0.0
    } else if delta <= 0.0 {
        -c * (1.0 / (D_MIN - delta) - 1.0 / (D_MIN + D_MAX))
    } else {
        -c * (1.0 / D_MIN - 1.0 / (D_MIN + D_MAX)) - c / (D_MIN * D_MIN) * delta
    }
}

/// What the test adds up beside the kinetic energy.
#[derive(Clone, Copy)]
struct Potential {
    /// Y* of particle pairs and of walls (same material).
    ys: f64,
    /// Hamaker constant of pairs (0 without cohesion).
    a_h: f64,
    /// Gravity along -z.
    g: f64,
    /// Plane walls as (axis, position).
    planes: &'static [(usize, f64)],
    /// Periodic box lengths (0 for a fixed axis).
    period: [f64; 3],
}

impl Potential {
    /// Kinetic + Hertz elastic (pairs and planes) + van der Waals + gravity.
    /// Tangential and rolling springs store non-negative energy that is left
    /// out, so this never exceeds the true total energy.
    fn total(&self, run: &Run) -> f64 {
        let p = run.p();
        let mut e = run.kinetic();
        for i in 0..p.len() {
            e += p.mass[i] * self.g * p.x[i].z;
            for &(axis, pos) in self.planes {
                e += hertz_energy(self.ys, p.radius[i], p.radius[i] - (p.x[i][axis] - pos).abs());
            }
            for j in i + 1..p.len() {
                let mut dx = p.x[i] - p.x[j];
                for k in 0..3 {
                    if self.period[k] > 0.0 {
                        dx[k] -= self.period[k] * (dx[k] / self.period[k]).round();
                    }
                }
                let delta = p.radius[i] + p.radius[j] - dx.norm();
                let r_eff = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
                e += hertz_energy(self.ys, r_eff, delta);
                if self.a_h > 0.0 {
                    e += vdw_energy(self.a_h, r_eff, delta);
                }
            }
        }
        e
    }
}

/// The paper's time step: 10 % of T_col = 3.21 (m*/k_n)^{2/5} v^{-1/5}
/// at v = 1 m/s, with k_n = 4/3 Y* sqrt(d/4) and m* = m/2.
fn paper_dt(d: f64, y: f64, nu: f64, rho: f64) -> f64 {
    let kn = 4.0 / 3.0 * y_star(y, nu) * (d / 4.0).sqrt();
    let meff = 0.5 * rho * PI * d.powi(3) / 6.0;
    0.1 * 3.21 * (meff / kn).powf(0.4)
}

/// Undamped Hertz contact duration 3.2145 (m*/k_n)^{2/5} v^{-1/5} for
/// F = k_n delta^{3/2} (Hertz; 2 * 1.6073).
fn hertz_tc(k_n: f64, m_eff: f64, v: f64) -> f64 {
    3.2145 * (m_eff / k_n).powf(0.4) * v.powf(-0.2)
}

fn mass(d: f64, rho: f64) -> f64 {
    rho * PI * d.powi(3) / 6.0
}

// ===================================================== paper extremes

/// 2x2x2 cube of d = 30 um glass (Y = 63 GPa) with gaps of 0.1 um (inside
/// D_max) moving towards the centre at 2-10 mm/s: van der Waals captures
/// them (capture speed sqrt(2 W / m*) ~ 1 cm/s for W = A R*/(6 D_min)), the
/// cluster stays together and its kinetic energy decays.
#[test]
fn paper_glass_cluster_with_vdw_sticks_and_cools() {
    let d: f64 = 30e-6;
    let y = 63e9;
    let gap = 0.1e-6;
    let s = 0.5 * (d + gap);
    let mut pos = Vec::new();
    for &i in &[-1.0, 1.0] {
        for &j in &[-1.0, 1.0] {
            for &k in &[-1.0, 1.0] {
                pos.push(V3::new(i * s, j * s, k * s));
            }
        }
    }
    let dt = paper_dt(d, y, PAPER_NU, PAPER_RHO);
    let deck = format!(
        "{}{}pair_style gran {PAPER_MODEL}\npair_coeff * *\ntimestep {dt:e}\n{}fix integr all nve/sphere\n",
        header("f f f", [-20.0 * d; 3], [20.0 * d; 3], 1, 0.1 * d),
        paper_props(y, 0.2, PAPER_GAMMA),
        atoms(1, &pos, d, PAPER_RHO)
    );
    let mut run = Run::new("cluster", &deck);
    // inward velocities of random size: no angular momentum; the mean is
    // removed (the cube is centred, so still no angular momentum)
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    {
        let p = &mut run.s.sim.particles;
        let mut mean = V3::zeros();
        for i in 0..p.len() {
            p.v[i] = -p.x[i].normalize() * (2e-3 + 8e-3 * rng.uniform());
            mean += p.v[i] / 8.0;
        }
        for i in 0..p.len() {
            p.v[i] -= mean;
        }
    }
    let pot = Potential { ys: y_star(y, PAPER_NU), a_h: hamaker(PAPER_GAMMA), g: 0.0, planes: &[], period: [0.0; 3] };
    let e0 = pot.total(&run);
    // the deepest the pair potential can go: U_min = -(W + 0.6 F0 delta_eq)
    // per pair at delta_eq = (F0/k_n)^{2/3}, F0 = A R*/(6 D_min^2); 12 bonds
    let r_eff = d / 4.0;
    let f0 = hamaker(PAPER_GAMMA) * r_eff / (6.0 * D_MIN * D_MIN);
    let kn = 4.0 / 3.0 * pot.ys * r_eff.sqrt();
    let delta_eq = (f0 / kn).powf(2.0 / 3.0);
    let u_min = -vdw_energy(hamaker(PAPER_GAMMA), r_eff, 0.0) + 0.6 * f0 * delta_eq;
    let n = steps(20_000, 400_000);
    let every = n / 200;
    let mut ke_max: f64 = run.kinetic();
    let mut k = 0;
    while k < n {
        run.run(every);
        k += every;
        run.assert_finite();
        let e = pot.total(&run);
        // velocity Verlet overshoots the energy of an oscillating bond by up
        // to (omega dt)^2/4 ~ 1 % (omega dt ~ 0.2 here); 2 % of the wells
        assert!(e <= e0 + 2e-2 * 12.0 * u_min, "cluster energy grew at step {k}: {e} > {e0}");
        ke_max = ke_max.max(run.kinetic());
        // at most all 28 pairs at the bottom of their wells
        assert!(run.kinetic() <= e0 + 28.0 * u_min, "kinetic energy above what the bonds can release");
    }
    run.done();
    let p = run.p();
    assert_eq!(p.len(), 8);
    // sticks: every particle within D_max of another, cluster compact
    for i in 0..8 {
        let nearest = (0..8).filter(|&j| j != i).map(|j| (p.x[i] - p.x[j]).norm() - d).fold(f64::INFINITY, f64::min);
        assert!(nearest < D_MAX, "atom {} left the cluster (gap {nearest})", p.tag[i]);
        assert!(p.x[i].norm() < 1.5 * d, "cluster not compact: atom {} at {:?}", p.tag[i], p.x[i]);
    }
    // cools: the kinetic energy at the end is a small part of the peak
    let ke = run.kinetic();
    eprintln!("cluster: KE max {ke_max:e}, end {ke:e}, e0 {e0:e}");
    assert!(ke < 0.02 * ke_max, "kinetic energy did not decay: {ke} of peak {ke_max}");
}

/// A confined square pyramid (3x3 base in a box of walls touching it, 2x2
/// in the hollows, 1 on top; all just touching) of the paper's model at
/// d = 1 mm with the template's softened Y = 1e7 Pa, under g = `g_level` g.
/// The pile holds: nothing moves by more than the Hertz compressions allow,
/// total energy (kinetic + gravity + Hertz + vdW) never rises above the
/// initial value, the pile comes to rest.
fn confined_pile(g_level: f64) {
    let d: f64 = 1e-3;
    let r = 0.5 * d;
    let y = 1e7;
    let g = 9.81 * g_level;
    let h = d / 2f64.sqrt();
    let mut pos = Vec::new();
    for i in -1..=1 {
        for j in -1..=1 {
            pos.push(V3::new(i as f64 * d, j as f64 * d, r));
        }
    }
    for &i in &[-0.5, 0.5] {
        for &j in &[-0.5, 0.5] {
            pos.push(V3::new(i * d, j * d, r + h));
        }
    }
    pos.push(V3::new(0.0, 0.0, r + 2.0 * h));
    static PLANES: [(usize, f64); 5] = [(0, -1.5e-3), (0, 1.5e-3), (1, -1.5e-3), (1, 1.5e-3), (2, 0.0)];
    let walls: String = [("xplane", -1.5e-3), ("xplane", 1.5e-3), ("yplane", -1.5e-3), ("yplane", 1.5e-3), ("zplane", 0.0)]
        .iter()
        .enumerate()
        .map(|(k, (s, v))| format!("fix w{k} all wall/gran {PAPER_WALL} primitive type 1 {s} {v:e}\n"))
        .collect();
    let dt = paper_dt(d, y, PAPER_NU, PAPER_RHO);
    let deck = format!(
        "{}{}pair_style gran {PAPER_MODEL}\npair_coeff * *\n{walls}timestep {dt:e}\n{}\
         fix grav all gravity {g:e} vector 0.0 0.0 -1.0\nfix integr all nve/sphere\n",
        header("f f f", [-3.0 * d, -3.0 * d, -d], [3.0 * d, 3.0 * d, 5.0 * d], 1, 0.2 * d),
        paper_props(y, 0.2, PAPER_GAMMA),
        atoms(1, &pos, d, PAPER_RHO)
    );
    let name = format!("pile at {g_level} g");
    let mut run = Run::new(&name, &deck);
    let pot = Potential { ys: y_star(y, PAPER_NU), a_h: hamaker(PAPER_GAMMA), g, planes: &PLANES, period: [0.0; 3] };
    let e0 = pot.total(&run);
    let m = mass(d, PAPER_RHO);
    // settling time scale sqrt(d/g); 20 of them (fast), 200 (long)
    let tg = (d / g).sqrt();
    let n = ((steps(10, 200) as f64 * tg / dt).ceil() as u64).max(5000);
    let every = (n / 200).max(1);
    let scale = 14.0 * m * g * d;
    // bonds: 0.6 F0 delta_p each (at most 40 in the pile and its walls);
    // Verlet overshoots an oscillating contact's energy by up to
    // (omega dt)^2/4 ~ 1 %, so 2 % of scale + bonds is allowed
    let f0 = hamaker(PAPER_GAMMA) * d / 4.0 / (6.0 * D_MIN * D_MIN);
    let kn_p = 4.0 / 3.0 * pot.ys * (d / 4.0).sqrt();
    let bonds = 40.0 * 0.6 * f0 * (f0 / kn_p).powf(2.0 / 3.0);
    let tol = 2e-2 * (scale + bonds);
    let mut k = 0;
    while k < n {
        run.run(every);
        k += every;
        run.assert_finite();
        let e = pot.total(&run);
        assert!(e <= e0 + tol, "{name}: energy grew at step {k}: {e} > {e0} (scale {scale})");
    }
    run.done();
    let p = run.p();
    assert_eq!(p.len(), 14, "{name}: particles lost");
    // Hertz compression under the whole pile's weight (14 m g on the floor
    // through 9 contacts): delta = (F / k_n)^{2/3} with the wall k_n; the
    // vdW pull F0 = 4 pi gamma R* between neighbours adds its own overlap.
    let kn_w = 4.0 / 3.0 * pot.ys * r.sqrt();
    let squeeze = (14.0 * m * g / kn_w).powf(2.0 / 3.0) + 3.0 * ((f0 + 14.0 * m * g) / kn_p).powf(2.0 / 3.0);
    for i in 0..p.len() {
        let moved = (p.x[i] - pos[(p.tag[i] - 1) as usize]).norm();
        assert!(moved < squeeze + 1e-3 * d, "{name}: atom {} moved {moved} (Hertz squeeze {squeeze})", p.tag[i]);
    }
    let ke = run.kinetic();
    eprintln!("{name}: squeeze {squeeze:e}, KE end {ke:e}, scale {scale:e}");
    assert!(ke < 1e-4 * (scale + bonds), "{name}: not at rest: KE {ke} vs m g d scale {scale}");
}

#[test]
fn paper_pile_at_0_06_g_holds() {
    confined_pile(0.06);
}

#[test]
fn paper_pile_at_100_g_holds() {
    confined_pile(100.0);
}

/// A 3x3 layer of touching d = 30 um glass spheres (Y = 63 GPa, vdW) just
/// touching the floor, under Earth gravity. It sinks into the floor by the
/// Hertz overlap delta_w = (m g / k_w)^{2/3} and the neighbours pull together
/// to delta_p = (F0 / k_n)^{2/3}; after that nothing may creep or heat up.
#[test]
fn paper_layer_rests_without_creep() {
    let d: f64 = 30e-6;
    let r = 0.5 * d;
    let y = 63e9;
    let g = 9.81;
    let mut pos = Vec::new();
    for i in -1..=1 {
        for j in -1..=1 {
            pos.push(V3::new(i as f64 * d, j as f64 * d, r));
        }
    }
    let dt = paper_dt(d, y, PAPER_NU, PAPER_RHO);
    let deck = format!(
        "{}{}pair_style gran {PAPER_MODEL}\npair_coeff * *\nfix floor all wall/gran {PAPER_WALL} primitive type 1 zplane 0.0\n\
         timestep {dt:e}\n{}fix grav all gravity {g} vector 0.0 0.0 -1.0\nfix integr all nve/sphere\n",
        header("f f f", [-5.0 * d, -5.0 * d, -d], [5.0 * d, 5.0 * d, 5.0 * d], 1, 0.1 * d),
        paper_props(y, 0.2, PAPER_GAMMA),
        atoms(1, &pos, d, PAPER_RHO)
    );
    let mut run = Run::new("resting layer", &deck);
    static FLOOR: [(usize, f64); 1] = [(2, 0.0)];
    let pot = Potential { ys: y_star(y, PAPER_NU), a_h: hamaker(PAPER_GAMMA), g, planes: &FLOOR, period: [0.0; 3] };
    let e0 = pot.total(&run);
    let m = mass(d, PAPER_RHO);
    let kn_w = 4.0 / 3.0 * pot.ys * r.sqrt();
    let delta_w = (m * g / kn_w).powf(2.0 / 3.0);
    let f0 = hamaker(PAPER_GAMMA) * (d / 4.0) / (6.0 * D_MIN * D_MIN);
    let kn_p = 4.0 / 3.0 * pot.ys * (d / 4.0).sqrt();
    let delta_p = ((f0 + m * g) / kn_p).powf(2.0 / 3.0);
    // energy the settling can release: 0.6 m g delta_w per sphere on the
    // floor, 0.6 F0 delta_p per bond (12 bonds in the 3x3 layer); the
    // kinetic energy can never exceed it
    let release = 9.0 * 0.6 * m * g * delta_w + 12.0 * 0.6 * (f0 + m * g) * delta_p;
    let n = steps(30_000, 1_000_000);
    let every = n / 100;
    let mut k = 0;
    let mut ke_late: f64 = 0.0;
    while k < n {
        run.run(every);
        k += every;
        run.assert_finite();
        let e = pot.total(&run);
        let ke = run.kinetic();
        assert!(e <= e0 + 2e-2 * release, "resting layer: energy grew at step {k}: {e} > {e0}");
        assert!(ke <= release, "resting layer: KE {ke} above the settling energy {release} at step {k}");
        if k > n / 2 {
            ke_late = ke_late.max(ke);
        }
        let p = run.p();
        for i in 0..p.len() {
            let x0 = pos[(p.tag[i] - 1) as usize];
            let dxy = ((p.x[i].x - x0.x).powi(2) + (p.x[i].y - x0.y).powi(2)).sqrt();
            // the outer spheres move in by at most twice the bond overlap
            // (dynamic overshoot of a Hertz spring released from rest:
            // 2.5^{2/3} = 1.84 times the static overlap)
            assert!(dxy <= 2.0 * 1.84 * delta_p, "resting layer: atom {} crept {dxy} m sideways by step {k} (bond overlap {delta_p})", p.tag[i]);
            let dz = x0.z - p.x[i].z;
            assert!(
                dz >= -1e-3 * delta_w && dz <= 1.84 * delta_w + 2.0 * 1.84 * delta_p,
                "resting layer: atom {} sank {dz} by step {k} (delta_w {delta_w})",
                p.tag[i]
            );
        }
    }
    run.done();
    assert_eq!(run.p().len(), 9);
    eprintln!("resting layer: release {release:e}, late KE max {ke_late:e}, delta_w {delta_w:e}, delta_p {delta_p:e}");
    assert!(ke_late < 1e-2 * release, "resting layer: still vibrating in the second half: {ke_late} of {release}");
}

// ====================================================== stiff two-sphere

/// Head-on impact of two d = 1 mm glass spheres (Y = 63 GPa) at 1 m/s with
/// dt = `frac` of the Hertz collision time. Returns the effective
/// restitution; asserts energy (kinetic + Hertz) never above its initial
/// value, up to velocity Verlet's overshoot of an oscillator's energy,
/// (omega dt)^2/4 of it, with omega Tc = pi (half a period per contact).
fn stiff_head_on(model: &str, e: f64, frac: f64) -> f64 {
    let verlet_tol = (PI * frac).powi(2) / 4.0;
    let d: f64 = 1e-3;
    let y = 63e9;
    let nu = 0.24;
    let v = 1.0;
    let ys = y_star(y, nu);
    let kn = 4.0 / 3.0 * ys * (d / 4.0).sqrt();
    let meff = 0.5 * mass(d, PAPER_RHO);
    let tc = hertz_tc(kn, meff, v);
    let dt = frac * tc;
    // start 2.5 steps apart from touching
    let gap = 2.5 * v * dt;
    let x = 0.5 * (d + gap);
    let props = if model.contains("viscoelastic") {
        // exact inversion of the collision (the Padé fit is 4 % off at 0.2)
        format!(
            "{}fix m6 all property/global restitutionReferenceVelocity scalar {v}\nfix m10 all property/global restitutionExact scalar 1\n",
            materials(1, y, nu, &[e], 0.5)
        )
    } else {
        materials(1, y, nu, &[e], 0.5)
    };
    let deck = format!(
        "{}{props}pair_style gran {model}\npair_coeff * *\ntimestep {dt:e}\n{}fix integr all nve/sphere\n\
         group a id 1\ngroup b id 2\nvelocity a set {} 0 0 units box\nvelocity b set {} 0 0 units box\n",
        header("f f f", [-0.01; 3], [0.01; 3], 1, 0.1 * d),
        atoms(1, &[V3::new(-x, 0.0, 0.0), V3::new(x, 0.0, 0.0)], d, PAPER_RHO),
        0.5 * v,
        -0.5 * v
    );
    let name = format!("head-on {model} e {e} dt {frac} Tc");
    let mut run = Run::new(&name, &deck);
    let pot = Potential { ys, a_h: 0.0, g: 0.0, planes: &[], period: [0.0; 3] };
    let e0 = pot.total(&run);
    let mut touched = false;
    let mut k = 0;
    loop {
        run.run(1);
        k += 1;
        run.assert_finite();
        let en = pot.total(&run);
        assert!(en <= e0 * (1.0 + verlet_tol), "{name}: energy {en} above initial {e0} at step {k}");
        let p = run.p();
        let touching = (p.x[1] - p.x[0]).norm() < d;
        touched |= touching;
        if touched && !touching {
            break;
        }
        assert!(k < 2000, "{name}: contact never ended");
    }
    run.run(3);
    let p = run.p();
    let (i, j) = if p.tag[0] == 1 { (0, 1) } else { (1, 0) };
    let e_eff = (p.v[j].x - p.v[i].x) / v;
    run.done();
    eprintln!("{name}: e_eff {e_eff}");
    e_eff
}

/// LIGGGHTS hertz: the damping is built so that the restitution is e at
/// every speed, but with 10 (3) steps per contact the discrete impact loses
/// a few % more. LIGGGHTS 3.8 itself, run on the same deck (`liggghts` with
/// `hard_particles yes`, dt = 0.1 and 0.3 Tc, relative vx printed by thermo)
/// gives e_eff = 0.47956065 and 0.47264354: demx must agree with it, and
/// both stay within 10 % of the requested e.
#[test]
fn stiff_hertz_head_on_at_10_and_30_percent_of_tc() {
    let m = "model hertz tangential history";
    let e1 = stiff_head_on(m, 0.5, 0.1);
    assert!((e1 - 0.47956065).abs() <= 1e-7, "dt = 0.1 Tc: e_eff {e1} vs LIGGGHTS 0.47956065");
    assert!((e1 - 0.5).abs() <= 0.1 * 0.5, "dt = 0.1 Tc: e_eff {e1}");
    let e3 = stiff_head_on(m, 0.5, 0.3);
    assert!((e3 - 0.47264354).abs() <= 1e-7, "dt = 0.3 Tc: e_eff {e3} vs LIGGGHTS 0.47264354");
    assert!((e3 - 0.5).abs() <= 0.1 * 0.5, "dt = 0.3 Tc: e_eff {e3}");
}

/// The paper's viscoelastic law at its reference speed returns e_ref = 0.2
/// when resolved (dt = 0.01 Tc, `restitutionExact`: within 2 %); at the paper's dt = 0.1 Tc the discrete impact
/// stays within 20 %; at 0.3 Tc the energy stays bounded and below the
/// initial value (restitution: see the ignored test below).
#[test]
fn stiff_viscoelastic_head_on_at_1_10_and_30_percent_of_tc() {
    let m = "model hertz/viscoelastic tangential history/paper";
    let e0 = stiff_head_on(m, 0.2, 0.01);
    assert!((e0 - 0.2).abs() <= 0.02 * 0.2, "dt = 0.01 Tc: e_eff {e0}");
    let e1 = stiff_head_on(m, 0.2, 0.1);
    assert!((e1 - 0.2).abs() <= 0.2 * 0.2, "dt = 0.1 Tc: e_eff {e1}");
    let e3 = stiff_head_on(m, 0.2, 0.3);
    assert!(e3 > 0.0 && e3 < 1.0, "dt = 0.3 Tc: e_eff {e3}");
}

/// At dt = 0.3 Tc one step moves the spheres by about the maximum Hertz
/// overlap (delta_max ~ 0.3 v Tc), so the viscoelastic damping, which grows
/// with sqrt(delta) and is evaluated at the step's half-kick velocity, is
/// sampled about twice per contact: e_eff = 0.74 instead of 0.2 (energy
/// still bounded). An integrator-resolution limit of the explicit scheme,
/// not a law bug: the paper's dt is 0.1 Tc.
#[test]
#[ignore = "viscoelastic restitution at dt = 0.3 Tc is 0.74 instead of 0.2: the contact is sampled ~2 times (resolution limit)"]
fn stiff_viscoelastic_restitution_at_30_percent_of_tc() {
    let e3 = stiff_head_on("model hertz/viscoelastic tangential history/paper", 0.2, 0.3);
    assert!((e3 - 0.2).abs() <= 0.3 * 0.2, "dt = 0.3 Tc: e_eff {e3}");
}

// ============================================================= Haff gas

/// 343 frictionless spheres (d = 1 mm, Y = 1e7 Pa, e = 0.99 between
/// particles, elastic walls of type 2) at solid fraction 0.1 in a closed
/// box, Maxwellian start. Haff: dT/dt = -(2 sqrt(pi)/3)(1 - e^2) n d^2 chi
/// sqrt(T/m) T (T = m <v_x^2>), so T = T0 / (1 + t/tau)^2 with
/// 1/tau = (2 sqrt(pi)/3)(1 - e^2) n d^2 chi sqrt(T0/m) and the Enskog
/// factor chi = (1 - phi/2)/(1 - phi)^3. sqrt(T0/T) must be a straight line
/// in t (fit), its slope 1/tau within 25 % of the formula, and the total
/// energy (kinetic + Hertz) must never rise.
#[test]
fn haff_cooling_of_a_nearly_elastic_gas() {
    let d: f64 = 1e-3;
    let y = 1e7;
    let nu = 0.3;
    let e = 0.99;
    let side = 7usize;
    let nat = side * side * side;
    let phi = 0.1;
    let l = (nat as f64 * PI * d.powi(3) / 6.0 / phi).cbrt();
    let a = l / side as f64;
    let mut pos = Vec::new();
    for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                pos.push(V3::new((i as f64 + 0.5) * a, (j as f64 + 0.5) * a, (k as f64 + 0.5) * a));
            }
        }
    }
    let m = mass(d, PAPER_RHO);
    let vx = 0.6; // sqrt(T0/m)
    let ys = y_star(y, nu);
    let kn = 4.0 / 3.0 * ys * (d / 4.0).sqrt();
    // typical relative normal speed ~ 2 vx; 15 steps per collision
    let dt = hertz_tc(kn, 0.5 * m, 2.0 * vx) / 15.0;
    let walls: String = (0..3)
        .flat_map(|ax| [0.0, l].map(move |v| (ax, v)))
        .enumerate()
        .map(|(k, (ax, v))| format!("fix w{k} all wall/gran model hertz tangential history primitive type 2 {}plane {v:e}\n", ["x", "y", "z"][ax]))
        .collect();
    let deck = format!(
        "{}{}pair_style gran model hertz tangential history\npair_coeff * *\n{walls}timestep {dt:e}\n{}fix integr all nve/sphere\n",
        header("f f f", [-0.1 * l; 3], [1.1 * l; 3], 2, 0.2 * d),
        materials(2, y, nu, &[e, 1.0, 1.0, 1.0], 0.0),
        atoms(1, &pos, d, PAPER_RHO)
    );
    let mut run = Run::new("Haff gas", &deck);
    let mut rng = Rng(12345);
    {
        let p = &mut run.s.sim.particles;
        let mut mean = V3::zeros();
        for i in 0..p.len() {
            p.v[i] = V3::new(rng.gauss(), rng.gauss(), rng.gauss()) * vx;
            mean += p.v[i] / nat as f64;
        }
        let mut mv2 = 0.0;
        for i in 0..p.len() {
            p.v[i] -= mean;
            mv2 += p.v[i].norm_squared();
        }
        // exactly T0 = m vx^2
        let s = (3.0 * nat as f64 * vx * vx / mv2).sqrt();
        for i in 0..p.len() {
            p.v[i] *= s;
        }
    }
    static WALLS: [(usize, f64); 0] = [];
    let pot = Potential { ys, a_h: 0.0, g: 0.0, planes: &WALLS, period: [0.0; 3] };
    let wall_energy = |run: &Run| -> f64 {
        let p = run.p();
        (0..p.len())
            .map(|i| {
                (0..3)
                    .map(|ax| hertz_energy(ys, p.radius[i], p.radius[i] - p.x[i][ax]) + hertz_energy(ys, p.radius[i], p.radius[i] - (l - p.x[i][ax])))
                    .sum::<f64>()
            })
            .sum()
    };
    let temp = |run: &Run| -> f64 {
        let p = run.p();
        (0..p.len()).map(|i| p.mass[i] * p.v[i].norm_squared()).sum::<f64>() / (3.0 * p.len() as f64)
    };
    let n_dens = nat as f64 / (l * l * l);
    let chi = (1.0 - 0.5 * phi) / (1.0 - phi).powi(3);
    let tau = 1.0 / (2.0 * PI.sqrt() / 3.0 * (1.0 - e * e) * n_dens * d * d * chi * vx);
    // long: 4 tau (T falls 25-fold); later the homogeneous cooling state
    // of a closed box gives way to clustering (Goldhirsch & Zanetti 1993)
    let n = steps((0.8 * tau / dt) as u64, (4.0 * tau / dt) as u64);
    let every = (n / 100).max(1);
    let t0 = temp(&run);
    let mut prev = pot.total(&run) + wall_energy(&run);
    let mut samples = vec![(0.0, t0)];
    let mut k = 0;
    while k < n {
        run.run(every);
        k += every;
        run.assert_finite();
        let en = pot.total(&run) + wall_energy(&run);
        // Verlet error on the energy stored in the contacts in progress
        // (~1 % of them per step, each ~(pi/15)^2 of its energy): 2e-3 E
        assert!(en <= prev * (1.0 + 2e-3), "Haff gas: energy rose at step {k}: {en} > {prev}");
        prev = prev.min(en);
        samples.push((run.time(), temp(&run)));
    }
    run.done();
    assert_eq!(run.p().len(), nat);
    for i in 0..nat {
        let x = run.p().x[i];
        assert!(x.iter().all(|&c| c > 0.0 && c < l), "Haff gas: atom {} escaped the box: {x:?}", run.p().tag[i]);
    }
    // least squares of y = sqrt(T0/T) = 1 + t/tau
    let pts: Vec<(f64, f64)> = samples.iter().map(|&(t, tt)| (t, (t0 / tt).sqrt())).collect();
    let nn = pts.len() as f64;
    let (sx, sy) = (pts.iter().map(|p| p.0).sum::<f64>(), pts.iter().map(|p| p.1).sum::<f64>());
    let (sxx, sxy) = (pts.iter().map(|p| p.0 * p.0).sum::<f64>(), pts.iter().map(|p| p.0 * p.1).sum::<f64>());
    let slope = (nn * sxy - sx * sy) / (nn * sxx - sx * sx);
    let icpt = (sy - slope * sx) / nn;
    let tau_fit = 1.0 / slope;
    let worst = pts.iter().map(|&(t, yy)| ((icpt + slope * t) - yy).abs() / yy).fold(0.0, f64::max);
    let (tend, tt_end) = *samples.last().unwrap();
    eprintln!(
        "Haff gas: tau theory {tau:e} s, fit {tau_fit:e} s, intercept {icpt}, worst rel. residual {worst}, T_end/T0 {} at t/tau {}",
        tt_end / t0,
        tend / tau
    );
    assert!(tt_end < 0.6 * t0, "Haff gas: did not cool: T_end/T0 = {}", tt_end / t0);
    assert!(worst < 0.03, "Haff gas: sqrt(T0/T) not linear in t: worst residual {worst}");
    assert!((icpt - 1.0).abs() < 0.03, "Haff gas: intercept {icpt}");
    assert!((tau_fit / tau - 1.0).abs() < 0.25, "Haff gas: tau {tau_fit} vs Haff-Enskog {tau}");
}

// ==================================================== overlapping release

/// 4x4x4 simple cubic lattice with spacing 0.8 d (overlap 0.2 d with each
/// of the 6 neighbours; next neighbours at 1.13 d do not touch), released at
/// once. Initial energy, analytically: 3 n^2 (n-1) bonds of
/// 8/15 Y* sqrt(d/4) (0.2 d)^{5/2}. The pack explodes; kinetic +
/// rotational + Hertz energy never exceeds that, momentum stays zero.
#[test]
fn overlapping_lattice_explodes_within_its_elastic_energy() {
    let d: f64 = 1e-3;
    let y = 1e7;
    let nu = 0.3;
    let side = 4usize;
    let a = 0.8 * d;
    let c = 0.5 * (side as f64 - 1.0) * a;
    let mut pos = Vec::new();
    for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                pos.push(V3::new(i as f64 * a - c, j as f64 * a - c, k as f64 * a - c));
            }
        }
    }
    let ys = y_star(y, nu);
    let bonds = 3 * side * side * (side - 1);
    let e_el = bonds as f64 * 8.0 / 15.0 * ys * (d / 4.0).sqrt() * (0.2 * d).powf(2.5);
    let m = mass(d, PAPER_RHO);
    // the fastest a particle can get: all of the energy in one particle
    let vmax = (2.0 * e_el / m).sqrt();
    let kn = 4.0 / 3.0 * ys * (d / 4.0).sqrt();
    let dt = hertz_tc(kn, 0.5 * m, vmax) / 50.0;
    let n = steps(3000, 30_000);
    let half = vmax * n as f64 * dt + 2.0 * d;
    let deck = format!(
        "{}{}pair_style gran model hertz tangential history\npair_coeff * *\ntimestep {dt:e}\n{}fix integr all nve/sphere\n",
        header("f f f", [-half; 3], [half; 3], 1, 0.2 * d),
        materials(1, y, nu, &[0.5], 0.5),
        atoms(1, &pos, d, PAPER_RHO)
    );
    let mut run = Run::new("overlapping lattice", &deck);
    let pot = Potential { ys, a_h: 0.0, g: 0.0, planes: &[], period: [0.0; 3] };
    let e0 = pot.total(&run);
    assert!((e0 - e_el).abs() < 1e-9 * e_el, "initial energy {e0} vs analytic {e_el}");
    let every = n / 100;
    let mut k = 0;
    while k < n {
        run.run(every);
        k += every;
        run.assert_finite();
        let en = pot.total(&run);
        assert!(en <= e_el * (1.0 + 1e-3), "overlapping lattice: energy {en} above the initial elastic energy {e_el} at step {k}");
        let p = run.p();
        let mom: V3 = (0..p.len()).map(|i| p.v[i] * p.mass[i]).sum();
        assert!(mom.norm() <= 1e-9 * (2.0 * 64.0 * m * e_el).sqrt(), "overlapping lattice: momentum {mom:?} at step {k}");
    }
    run.done();
    let p = run.p();
    assert_eq!(p.len(), 64, "overlapping lattice: particles lost");
    // exploded: the pack grew and holds kinetic energy
    let rg0: f64 = pos.iter().map(|x| x.norm_squared()).sum::<f64>();
    let rg: f64 = (0..p.len()).map(|i| p.x[i].norm_squared()).sum::<f64>();
    assert!(rg > 4.0 * rg0, "overlapping lattice: did not expand ({rg} vs {rg0})");
    let ke = run.kinetic();
    eprintln!("overlapping lattice: E0 {e_el:e}, KE end {ke:e}");
    assert!(ke > 0.01 * e_el && ke <= e_el, "overlapping lattice: kinetic energy {ke} of {e_el}");
}

// ============================================ corners, edges and vertices

/// Sphere (d = 10 mm, LIGGGHTS hertz e = 0.7) moving into a corner or edge
/// along `dir` at 0.5 m/s; returns (v before, v after, KE+rot before, after).
fn corner_impact(name: &str, walls: &str, x0: V3, dir: V3, lammps: bool, mu: f64) -> (V3, V3, f64, f64) {
    let d: f64 = 0.01;
    let v = dir.normalize() * 0.5;
    let dt = 1e-5;
    let deck = if lammps {
        format!(
            "units si\natom_style sphere\natom_modify map array\nboundary f f f\nnewton off\ncomm_modify vel yes\n\
             region box block -0.06 0.06 -0.06 0.06 -0.06 0.06 units box\ncreate_box 1 box\nneighbor 0.002 bin\nneigh_modify delay 0\n\
             pair_style gran/hertz/history 2e6 NULL 5000 NULL 0.5 1\npair_coeff * *\ntimestep {dt}\n\
             create_atoms 1 single {} {} {} units box\nset atom 1 diameter {d} density 2500\nvelocity all set {} {} {} units box\n\
             fix 1 all nve/sphere\n{walls}\n",
            x0.x, x0.y, x0.z, v.x, v.y, v.z
        )
    } else {
        format!(
            "{}{}pair_style gran model hertz tangential history\npair_coeff * *\ntimestep {dt}\n{walls}\n{}\
             velocity all set {} {} {} units box\nfix integr all nve/sphere\n",
            header("f f f", [-0.06; 3], [0.06; 3], 1, 0.002),
            materials(1, 5e6, 0.45, &[0.7], mu),
            atoms(1, &[x0], d, 2500.0),
            v.x,
            v.y,
            v.z
        )
    };
    let mut run = Run::new(name, &deck);
    let ke0 = run.kinetic();
    // 0.5 m/s over 4 mm plus a contact of a few ms, and away again
    run.run(3000);
    run.assert_finite();
    assert_eq!(run.p().len(), 1, "{name}: sphere lost");
    assert!(run.p().f[0].norm() == 0.0, "{name}: still in contact at the end");
    let ke1 = run.kinetic();
    run.done();
    (v, run.p().v[0], ke0, ke1)
}

/// Moving straight into a corner, the sphere's normal velocity is reversed
/// against each wall it touches, so it comes back along -dir with the speed
/// scaled by e (both walls act on orthogonal normal components).
fn assert_reverses(name: &str, vb: V3, va: V3, ke0: f64, ke1: f64, e: Option<f64>) {
    eprintln!("{name}: v before {vb:?}, after {va:?}, KE {ke0} -> {ke1}");
    assert!(ke1 <= ke0 * (1.0 + 1e-12), "{name}: energy grew {ke0} -> {ke1}");
    assert!(ke1 > 0.05 * ke0, "{name}: no rebound");
    let cos = -va.dot(&vb) / (va.norm() * vb.norm());
    assert!(cos > 0.9998, "{name}: rebound direction {va:?} not opposite to {vb:?} (cos {cos})");
    if let Some(e) = e {
        let ratio = va.norm() / vb.norm();
        assert!((ratio - e).abs() < 0.02 * e, "{name}: speed ratio {ratio} vs restitution {e}");
    }
}

#[test]
fn sphere_into_a_primitive_wall_corner() {
    // LIGGGHTS xplane 0 + zplane 0: a concave 90 degree edge, entered at 45
    let walls = "fix wx all wall/gran model hertz tangential history primitive type 1 xplane 0.0\n\
                 fix wz all wall/gran model hertz tangential history primitive type 1 zplane 0.0";
    // frictionless: each wall reverses its own normal component with e
    let (vb, va, k0, k1) = corner_impact("primitive edge", walls, V3::new(0.008, 0.0, 0.008), V3::new(-1.0, 0.0, -1.0), false, 0.0);
    assert_reverses("primitive edge", vb, va, k0, k1, Some(0.7));
    // with friction each wall also brakes the motion into the other one
    // (the tangential velocity at one wall is the normal one at the other):
    // still straight back by symmetry, slower than e
    let (vb, va, k0, k1) = corner_impact("primitive edge mu 0.5", walls, V3::new(0.008, 0.0, 0.008), V3::new(-1.0, 0.0, -1.0), false, 0.5);
    assert_reverses("primitive edge mu 0.5", vb, va, k0, k1, None);
    assert!(va.norm() < 0.7 * vb.norm(), "primitive edge mu 0.5: friction took no energy");
    // three planes: a concave corner, entered along the diagonal
    let walls3 = format!("{walls}\nfix wy all wall/gran model hertz tangential history primitive type 1 yplane 0.0");
    let (vb, va, k0, k1) = corner_impact("primitive corner", &walls3, V3::new(0.008, 0.008, 0.008), V3::new(-1.0, -1.0, -1.0), false, 0.0);
    assert_reverses("primitive corner", vb, va, k0, k1, Some(0.7));
}

#[test]
fn sphere_into_a_lammps_region_wall_corner() {
    // LAMMPS wall/gran/region on the inside of a block: three faces meet at
    // the corner (-0.05, -0.05, -0.05); hertz/history with gamma_n
    let walls = "region cage block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box\n\
                 fix w all wall/gran/region hertz/history 2e6 NULL 5000 NULL 0.5 1 region cage";
    let x0 = V3::new(-0.042, -0.042, -0.042);
    let (vb, va, k0, k1) = corner_impact("region corner", walls, x0, V3::new(-1.0, -1.0, -1.0), true, 0.5);
    assert_reverses("region corner", vb, va, k0, k1, None);
}

/// ASCII STL of the cube [0, a]^3 (12 outward triangles).
fn cube_stl(a: f64) -> String {
    let v = |i: usize| V3::new(if i & 1 != 0 { a } else { 0.0 }, if i & 2 != 0 { a } else { 0.0 }, if i & 4 != 0 { a } else { 0.0 });
    // faces as corner indices in counter-clockwise order seen from outside
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut s = String::from("solid cube\n");
    for f in faces {
        for tri in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
            let (p0, p1, p2) = (v(tri[0]), v(tri[1]), v(tri[2]));
            let n = (p1 - p0).cross(&(p2 - p0)).normalize();
            s += &format!("facet normal {} {} {}\nouter loop\n", n.x, n.y, n.z);
            for p in [p0, p1, p2] {
                s += &format!("vertex {} {} {}\n", p.x, p.y, p.z);
            }
            s += "endloop\nendfacet\n";
        }
    }
    s + "endsolid cube\n"
}

/// A sphere hitting a mesh cube's vertex along the body diagonal and an
/// edge along the face diagonal: the contact is sphere-point (sphere-line),
/// normal along the line of approach, so the sphere comes straight back with
/// speed ratio e (the Hertz law with R* = r as for a plane).
#[test]
fn sphere_onto_a_mesh_vertex_and_edge() {
    let dir = tempfile::tempdir().expect("tempdir");
    let stl = dir.path().join("cube.stl");
    std::fs::write(&stl, cube_stl(0.02)).expect("write stl");
    let walls = format!(
        "fix cad all mesh/surface file {} type 1\nfix w all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
        stl.display()
    );
    let c = 0.02 + 0.008 / 3f64.sqrt();
    let (vb, va, k0, k1) = corner_impact("mesh vertex", &walls, V3::new(c, c, c), V3::new(-1.0, -1.0, -1.0), false, 0.5);
    assert_reverses("mesh vertex", vb, va, k0, k1, Some(0.7));
    let c2 = 0.02 + 0.008 / 2f64.sqrt();
    let (vb, va, k0, k1) = corner_impact("mesh edge", &walls, V3::new(c2, 0.01, c2), V3::new(-1.0, 0.0, -1.0), false, 0.5);
    assert_reverses("mesh edge", vb, va, k0, k1, Some(0.7));
}

// ======================================================== grazing impacts

/// Sphere hitting the floor at `angle` degrees from the normal at 1 m/s,
/// in either dialect; returns (KE+rot before, after, vz after / vz before).
fn grazing(angle: f64, lammps: bool) -> (f64, f64, f64) {
    let d: f64 = 0.01;
    let th = angle.to_radians();
    let v = V3::new(th.sin(), 0.0, -th.cos());
    let dt = 1e-6;
    let z0 = 0.5 * d + 5.0 * dt * v.z.abs();
    let deck = if lammps {
        format!(
            "units si\natom_style sphere\natom_modify map array\nboundary f f f\nnewton off\ncomm_modify vel yes\n\
             region box block -0.06 0.06 -0.06 0.06 -0.02 0.06 units box\ncreate_box 1 box\nneighbor 0.002 bin\nneigh_modify delay 0\n\
             pair_style gran/hertz/history 2e6 NULL 5000 NULL 0.5 1\npair_coeff * *\ntimestep {dt}\n\
             create_atoms 1 single 0 0 {z0} units box\nset atom 1 diameter {d} density 2500\nvelocity all set {} 0 {} units box\n\
             fix 1 all nve/sphere\nfix w all wall/gran hertz/history 2e6 NULL 5000 NULL 0.5 1 zplane 0.0 NULL\n",
            v.x, v.z
        )
    } else {
        format!(
            "{}{}pair_style gran model hertz tangential history\npair_coeff * *\ntimestep {dt}\n\
             fix w all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n{}\
             velocity all set {} 0 {} units box\nfix integr all nve/sphere\n",
            header("f f f", [-0.06, -0.06, -0.02], [0.06, 0.06, 0.06], 1, 0.002),
            materials(1, 5e6, 0.45, &[0.7], 0.5),
            atoms(1, &[V3::new(0.0, 0.0, z0)], d, 2500.0),
            v.x,
            v.z
        )
    };
    let name = format!("grazing {angle} deg {}", if lammps { "LAMMPS" } else { "LIGGGHTS" });
    let mut run = Run::new(&name, &deck);
    let ke0 = run.kinetic();
    let mut touched = false;
    let mut k = 0;
    loop {
        run.run(10);
        k += 10;
        run.assert_finite();
        let touching = run.p().x[0].z < 0.5 * d;
        touched |= touching;
        if touched && !touching {
            break;
        }
        assert!(k < 200_000, "{name}: contact never ended");
    }
    let ke1 = run.kinetic();
    (ke0, ke1, -run.p().v[0].z / v.z)
}

/// Kinetic + rotational energy after a grazing impact never exceeds the
/// energy before (reported against LAMMPS' wall code). LIGGGHTS hertz keeps
/// the normal restitution e = 0.7 whatever the tangential part does.
#[test]
fn grazing_wall_impacts_do_not_create_energy() {
    for angle in [60.0, 70.0, 80.0, 85.0, 88.0, 89.0] {
        for lammps in [false, true] {
            let (k0, k1, ez) = grazing(angle, lammps);
            let what = format!("{angle} deg {}", if lammps { "LAMMPS wall/gran" } else { "LIGGGHTS primitive" });
            eprintln!("grazing {what}: KE+rot {k0} -> {k1}, vz ratio {ez}");
            assert!(k1 <= k0 * (1.0 + 1e-12), "grazing {what}: energy grew {k0} -> {k1}");
            assert!(ez > 0.0, "grazing {what}: did not bounce");
            if !lammps {
                assert!((ez - 0.7).abs() < 0.02 * 0.7, "grazing {what}: normal restitution {ez}");
            }
        }
    }
}

// ======================================================= vdW singularity

/// Two d = 30 um glass spheres of the paper's model at rest, atom 2 placed
/// at a sequence of overlaps from pressed (delta = +2 nm) through touching
/// (the Hamaker distance D_min) out beyond D_max. With no relative velocity
/// the force on atom 1 along +x is, by Eqs. 10 and 13,
///   delta > 0:            F0 - k_n delta^{3/2},  F0 = A R*/(6 D_min^2)
///   -D_max <= delta <= 0: A R*/(6 (D_min - delta)^2)
///   delta < -D_max:       0
/// with A = 24 pi D_min^2 gamma, k_n = 4/3 Y* sqrt(R*), R* = d/4.
#[test]
fn vdw_force_is_finite_at_d_min_and_zero_beyond_d_max() {
    let d: f64 = 30e-6;
    let y = 63e9;
    let dt = paper_dt(d, y, PAPER_NU, PAPER_RHO);
    let deck = format!(
        "{}{}pair_style gran {PAPER_MODEL}\npair_coeff * *\ntimestep {dt:e}\n{}run 0\n",
        header("f f f", [-5.0 * d; 3], [5.0 * d; 3], 1, 1e-7),
        paper_props(y, 0.2, PAPER_GAMMA),
        atoms(1, &[V3::new(-0.5 * d, 0.0, 0.0), V3::new(0.5 * d, 0.0, 0.0)], d, PAPER_RHO)
    );
    let mut run = Run::new("vdw scan", &deck);
    let a = hamaker(PAPER_GAMMA);
    let r_eff = d / 4.0;
    let f0 = a * r_eff / (6.0 * D_MIN * D_MIN);
    let kn = 4.0 / 3.0 * y_star(y, PAPER_NU) * r_eff.sqrt();
    let deltas = [2e-9, 1e-10, 1e-12, 0.0, -1e-12, -D_MIN, -1e-8, -0.5 * D_MAX, -0.999 * D_MAX, -1.001 * D_MAX, -3.0 * D_MAX];
    let mut last = f64::INFINITY;
    for &want_delta in &deltas {
        let x2 = 0.5 * d - want_delta;
        run.cmd(&format!("set atom 2 x {x2:.17e}\nrun 0 post no\n"));
        run.assert_finite();
        let p = run.p();
        let (i, j) = if p.tag[0] == 1 { (0, 1) } else { (1, 0) };
        let delta = d - (p.x[j].x - p.x[i].x);
        let want = if delta > 0.0 {
            f0 - kn * delta.powf(1.5)
        } else if delta >= -D_MAX {
            a * r_eff / (6.0 * (D_MIN - delta).powi(2))
        } else {
            0.0
        };
        let got = p.f[i].x;
        eprintln!("vdw scan: delta {delta:e}: fx {got:e}, expected {want:e}");
        assert!((got - want).abs() <= 1e-9 * f0, "delta {delta:e}: force {got:e}, expected {want:e}");
        assert!((p.f[i] + p.f[j]).norm() <= 1e-12 * f0, "delta {delta:e}: forces not opposite");
        if delta <= 0.0 {
            // attraction falls off monotonically with the gap
            assert!(got <= last * (1.0 + 1e-12), "delta {delta:e}: force {got} rose above {last}");
            last = got;
        }
        if delta == 0.0 {
            assert!((got - f0).abs() <= 1e-12 * f0, "touching: force {got} is not the Hamaker value {f0}");
        }
    }
}

/// The same pair pulled apart dynamically: pressed by the vdW equilibrium
/// overlap, separated at 0.5 m/s (well above the capture speed
/// sqrt(2 W/m*) ~ 1 cm/s). The force stays finite and bounded by F0 plus
/// the elastic force at the start, and the pair leaves D_max with a
/// relative speed below the energy bound sqrt(v0^2 + 2 U_el/m*).
#[test]
fn vdw_pair_pulled_apart_through_d_max() {
    let d: f64 = 30e-6;
    let y = 63e9;
    let dt = paper_dt(d, y, PAPER_NU, PAPER_RHO);
    let a = hamaker(PAPER_GAMMA);
    let r_eff = d / 4.0;
    let f0 = a * r_eff / (6.0 * D_MIN * D_MIN);
    let kn = 4.0 / 3.0 * y_star(y, PAPER_NU) * r_eff.sqrt();
    let delta0 = (f0 / kn).powf(2.0 / 3.0);
    let x = 0.5 * (d - delta0);
    let v0 = 0.5;
    let deck = format!(
        "{}{}pair_style gran {PAPER_MODEL}\npair_coeff * *\ntimestep {dt:e}\n{}fix integr all nve/sphere\n\
         group a id 1\ngroup b id 2\nvelocity a set {} 0 0 units box\nvelocity b set {} 0 0 units box\n",
        header("f f f", [-5.0 * d; 3], [5.0 * d; 3], 1, 1e-7),
        paper_props(y, 0.2, PAPER_GAMMA),
        atoms(1, &[V3::new(-x, 0.0, 0.0), V3::new(x, 0.0, 0.0)], d, PAPER_RHO),
        -0.5 * v0,
        0.5 * v0
    );
    let mut run = Run::new("vdw pull", &deck);
    let m = mass(d, PAPER_RHO);
    let fmax = f0 + kn * delta0.powf(1.5);
    let mut k = 0;
    loop {
        run.run(1);
        k += 1;
        run.assert_finite();
        let p = run.p();
        assert!(p.f[0].norm() <= fmax * (1.0 + 1e-9), "vdw pull: force {:?} above {fmax} at step {k}", p.f[0]);
        let gap = (p.x[1] - p.x[0]).norm() - d;
        if gap > 1.5 * D_MAX {
            assert_eq!(p.f[0].norm(), 0.0, "vdw pull: force beyond D_max");
            break;
        }
        assert!(k < 100_000, "vdw pull: never separated");
    }
    let p = run.p();
    let vrel = (p.v[1] - p.v[0]).norm();
    let u_el = hertz_energy(y_star(y, PAPER_NU), r_eff, delta0);
    // energy: m* v^2/2 after <= m* v0^2/2 + U_el(delta0) + U_vdw(delta0)
    // (U_vdw(delta0) = -(W + F0 delta0), W the gap part of the well)
    let w_gap = -vdw_energy(a, r_eff, 0.0);
    let vmax2 = v0 * v0 + 2.0 * (u_el - w_gap - f0 * delta0) / (0.5 * m);
    eprintln!("vdw pull: v0 {v0}, after {vrel}, energy bound {}", vmax2.sqrt());
    assert!(vrel * vrel <= vmax2 * (1.0 + 1e-6), "vdw pull: left faster ({vrel}) than the energy allows ({})", vmax2.sqrt());
    // and a real separation, not a stuck pair
    assert!(vrel > 0.1 * v0, "vdw pull: separation speed {vrel}");
    run.done();
}

// ==================================================== periodic high speed

/// 64 spheres in a periodic box of 8 d, all drifting at
/// (0.4, 0.3, 0.2) d per step plus a thermal part of 0.002 d per step:
/// crossing a boundary almost every few steps. Pair forces are equal and
/// opposite across images, so the total momentum is conserved; the centre
/// of mass (unwrapped with the image flags) moves uniformly; ids and count
/// are kept; positions stay inside the box; with e = 0.5 the energy in the
/// drifting frame (Galilean invariance) never exceeds its initial value.
#[test]
fn fast_particles_cross_periodic_boundaries() {
    let d: f64 = 1e-3;
    let y = 1e7;
    let nu = 0.3;
    let side = 4usize;
    let l = 8.0 * d;
    let a = l / side as f64;
    let mut pos = Vec::new();
    for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                pos.push(V3::new((i as f64 + 0.5) * a, (j as f64 + 0.5) * a, (k as f64 + 0.5) * a));
            }
        }
    }
    let m = mass(d, PAPER_RHO);
    let ys = y_star(y, nu);
    let kn = 4.0 / 3.0 * ys * (d / 4.0).sqrt();
    let vth = 0.05;
    let dt = hertz_tc(kn, 0.5 * m, 2.0 * vth) / 20.0;
    let drift = V3::new(0.4, 0.3, 0.2) * (d / dt);
    let deck = format!(
        // up to 0.4 d per step on purpose: the guard's travel limit (0.5 R) is off
        "{}{}pair_style gran model hertz tangential history\npair_coeff * *\ntimestep {dt:e}\n{}fix integr all nve/sphere\ndemx_guard travel off\n",
        header("p p p", [0.0; 3], [l; 3], 1, 0.2 * d),
        materials(1, y, nu, &[0.5], 0.5),
        atoms(1, &pos, d, PAPER_RHO)
    );
    let mut run = Run::new("periodic drift", &deck);
    let mut rng = Rng(777);
    {
        let p = &mut run.s.sim.particles;
        let mut mean = V3::zeros();
        for i in 0..p.len() {
            p.v[i] = V3::new(rng.gauss(), rng.gauss(), rng.gauss()) * vth;
            mean += p.v[i] / 64.0;
        }
        for i in 0..p.len() {
            p.v[i] += drift - mean;
        }
    }
    let period = [l; 3];
    let pot = Potential { ys, a_h: 0.0, g: 0.0, planes: &[], period };
    let comoving = |run: &Run| -> f64 {
        let p = run.p();
        let ke: f64 = (0..p.len()).map(|i| 0.5 * p.mass[i] * (p.v[i] - drift).norm_squared() + 0.5 * p.inertia(i) * p.omega[i].norm_squared()).sum();
        ke + pot.total(run) - run.kinetic()
    };
    let unwrapped_com = |run: &Run| -> V3 {
        let p = run.p();
        (0..p.len()).map(|i| p.x[i] + V3::new(p.image[i][0] as f64, p.image[i][1] as f64, p.image[i][2] as f64) * l).sum::<V3>() / p.len() as f64
    };
    let e0 = comoving(&run);
    let p0: V3 = (0..64).map(|i| run.p().v[i] * m).sum();
    let com0 = unwrapped_com(&run);
    let n = steps(4000, 100_000);
    let every = 20;
    let mut k = 0;
    while k < n {
        run.run(every);
        k += every;
        run.assert_finite();
        let p = run.p();
        assert_eq!(p.len(), 64, "periodic drift: atoms lost at step {k}");
        let mut tags = p.tag.clone();
        tags.sort();
        assert!(tags.iter().copied().eq(1..=64), "periodic drift: ids changed at step {k}");
        for i in 0..p.len() {
            assert!(p.x[i].iter().all(|&c| (0.0..l).contains(&c)), "periodic drift: atom {} outside the box: {:?}", p.tag[i], p.x[i]);
        }
        let mom: V3 = (0..p.len()).map(|i| p.v[i] * p.mass[i]).sum();
        assert!((mom - p0).norm() <= 1e-10 * p0.norm(), "periodic drift: momentum {mom:?} vs {p0:?} at step {k}");
        let com = unwrapped_com(&run);
        let want = com0 + p0 / (64.0 * m) * run.time();
        // rounding grows with the distance travelled (wraps, time sums)
        let travelled = (want - com0).norm();
        assert!((com - want).norm() <= 1e-9 * (l + travelled), "periodic drift: centre of mass {com:?} vs {want:?} at step {k}");
        let e = comoving(&run);
        assert!(e <= e0 * (1.0 + 1e-3), "periodic drift: energy in the drifting frame {e} > {e0} at step {k}");
    }
    run.done();
    let e = comoving(&run);
    eprintln!("periodic drift: comoving energy {e0:e} -> {e:e}");
    // the gas collided (e = 0.5): it lost a visible part of its energy
    assert!(e < 0.9 * e0, "periodic drift: no collisions happened ({e} of {e0})");
}
