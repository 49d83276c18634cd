//! `velocity ... create` and `velocity ... scale`: thermal velocities drawn
//! from a seed and scaled to a temperature, as LAMMPS's `Velocity::create`
//! and `Velocity::scale` do (read for the facts: the order of the draws, the
//! mass factor, the momentum and rotation zeroing, the temperature's degrees
//! of freedom), so that a deck seeded in lmp gets the same velocities in demx.

use super::args::Args;
use super::Session;
use crate::engine::compute::unwrapped;
use crate::engine::rng::Park;
use crate::engine::sim::Sim;
use crate::error::{Error, Result};
use crate::physics::V3;
use crate::script::{Command, Word};

/// LAMMPS `WARMUP`: draws discarded before `loop local` uses its generator.
const WARMUP: usize = 100;

/// How the draws are handed to the atoms (`loop` keyword).
#[derive(Clone, Copy, PartialEq)]
enum Loop {
    /// One generator over atom IDs 1..N, so the velocities do not depend on
    /// the storage order (LAMMPS's default; needs consecutive IDs).
    All,
    /// One generator over the atoms as stored (seed + rank 0, after 100
    /// draws).
    Local,
    /// A generator per atom, seeded by the seed and its position
    /// (`RanPark::reset`).
    Geom,
}

/// The options after `create T seed` or `scale T`.
struct Options {
    gaussian: bool,
    sum: bool,
    mom: bool,
    rot: bool,
    lp: Loop,
    /// Group whose temperature is measured (`temp ID`); the velocity group
    /// by default.
    temp_group: Option<u32>,
}

fn options(s: &Session, a: &mut Args) -> Result<Options> {
    let mut o = Options { gaussian: false, sum: false, mom: true, rot: false, lp: Loop::All, temp_group: None };
    while a.more() {
        let k = a.choice("keyword", &["dist", "sum", "mom", "rot", "temp", "bias", "loop", "rigid", "units"])?;
        match k.text.as_str() {
            "dist" => o.gaussian = a.choice("distribution", &["uniform", "gaussian"])?.text == "gaussian",
            "sum" => o.sum = a.yes_no("sum")?,
            "mom" => o.mom = a.yes_no("mom")?,
            "rot" => o.rot = a.yes_no("rot")?,
            "loop" => {
                o.lp = match a.choice("loop style", &["all", "local", "geom"])?.text.as_str() {
                    "all" => Loop::All,
                    "local" => Loop::Local,
                    _ => Loop::Geom,
                }
            }
            "temp" => {
                let id = a.word("temperature compute ID")?;
                let c = s
                    .sim
                    .computes
                    .iter()
                    .find(|c| c.id == id.text)
                    .ok_or_else(|| Error::deck(id.span, format!("compute '{}' does not exist", id.text)))?;
                if c.style != "temp" {
                    return Err(Error::unsupported(id.span, format!("velocity temp with a compute of style {}", c.style)));
                }
                o.temp_group = Some(c.group);
            }
            "bias" => {
                if a.yes_no("bias")? {
                    return Err(Error::unsupported(k.span, "velocity bias yes"));
                }
            }
            "rigid" => return Err(Error::unsupported(k.span, "velocity rigid")),
            _ => {
                a.choice("units", &["box", "lattice"])?;
            }
        }
    }
    Ok(o)
}

/// `velocity G create T seed [options]` and `velocity G scale T [options]`.
pub fn thermal(s: &mut Session, cmd: &Command, style: &Word, a: &mut Args, bit: u32) -> Result<()> {
    let t_word = a.word("temperature")?;
    let t_want = super::args::parse_f64(t_word)?;
    let seed = if style.text == "create" {
        let w = a.word("seed")?;
        let seed = super::args::parse_i64(w)?;
        if seed <= 0 || seed > i32::MAX as i64 {
            return Err(Error::deck(w.span, format!("seed {seed} must be a positive integer below 2^31")));
        }
        Some(seed as i32)
    } else {
        None
    };
    let o = options(s, a)?;
    let span = cmd.words[0].span;
    let sim = &mut s.sim;
    if sim.particles.is_empty() {
        return Err(Error::deck(span, "velocity command with no atoms existing"));
    }
    if let Some(seed) = seed {
        let hold = o.sum.then(|| sim.particles.v.clone());
        draw(sim, bit, seed, &o, span)?;
        if o.mom {
            zero_momentum(sim, bit).map_err(|e| Error::deck(span, e))?;
        }
        if o.rot {
            zero_rotation(sim, bit).map_err(|e| Error::deck(span, e))?;
        }
        rescale(sim, bit, o.temp_group.unwrap_or(bit), t_want).map_err(|e| Error::deck(t_word.span, e))?;
        if let Some(hold) = hold {
            let p = &mut sim.particles;
            for i in 0..p.len() {
                if p.mask[i] & bit != 0 {
                    p.v[i] += hold[i];
                }
            }
        }
    } else {
        rescale(sim, bit, o.temp_group.unwrap_or(bit), t_want).map_err(|e| Error::deck(t_word.span, e))?;
    }
    Ok(())
}

/// The three values of one draw: uniform in (-1/2, 1/2) or standard normal.
fn triple(r: &mut Park, gaussian: bool) -> [f64; 3] {
    if gaussian {
        [r.gaussian(), r.gaussian(), r.gaussian()]
    } else {
        [r.uniform() - 0.5, r.uniform() - 0.5, r.uniform() - 0.5]
    }
}

/// Sets each group atom's velocity to a draw times 1/sqrt(m), z = 0 in 2d.
fn draw(sim: &mut Sim, bit: u32, seed: i32, o: &Options, span: crate::script::Span) -> Result<()> {
    let dim3 = sim.domain.as_ref().is_none_or(|d| d.dimension == 3);
    let p = &mut sim.particles;
    let set = |p: &mut crate::engine::particles::Particles, i: usize, d: [f64; 3]| {
        let factor = 1.0 / p.mass[i].sqrt();
        p.v[i] = V3::new(d[0] * factor, d[1] * factor, if dim3 { d[2] * factor } else { 0.0 });
    };
    match o.lp {
        Loop::All => {
            // draws for IDs 1..N in turn, each kept by the atom of that ID
            let n = p.len();
            let mut by_tag = vec![usize::MAX; n + 1];
            for i in 0..n {
                match usize::try_from(p.tag[i]) {
                    Ok(t) if (1..=n).contains(&t) => by_tag[t] = i,
                    _ => {
                        let msg = format!("atom IDs must be consecutive (1 to {n}) for velocity create loop all (atom ID {})", p.tag[i]);
                        return Err(Error::deck(span, msg).with_hint("use loop geom, whose draws do not depend on IDs"));
                    }
                }
            }
            let mut r = Park::new(seed as i64);
            for &i in &by_tag[1..] {
                let d = triple(&mut r, o.gaussian);
                if p.mask[i] & bit != 0 {
                    set(p, i, d);
                }
            }
        }
        Loop::Local => {
            let mut r = Park::new(seed as i64);
            for _ in 0..WARMUP {
                r.uniform();
            }
            for i in 0..p.len() {
                if p.mask[i] & bit != 0 {
                    let d = triple(&mut r, o.gaussian);
                    set(p, i, d);
                }
            }
        }
        Loop::Geom => {
            for i in 0..p.len() {
                if p.mask[i] & bit != 0 {
                    let x = p.x[i];
                    let d = triple(&mut Park::from_point(seed, [x[0], x[1], x[2]]), o.gaussian);
                    set(p, i, d);
                }
            }
        }
    }
    Ok(())
}

/// The group's mass and centre-of-mass velocity, summed in storage order
/// (LAMMPS `Group::mass`, `Group::vcm`).
fn group_vcm(sim: &Sim, bit: u32) -> (f64, V3) {
    let p = &sim.particles;
    let (mut m, mut mv) = (0.0, V3::zeros());
    for i in 0..p.len() {
        if p.mask[i] & bit != 0 {
            m += p.mass[i];
            mv += p.v[i] * p.mass[i];
        }
    }
    (m, if m > 0.0 { mv / m } else { mv })
}

/// Subtracts the group's centre-of-mass velocity (LAMMPS `zero_momentum`).
pub fn zero_momentum(sim: &mut Sim, bit: u32) -> std::result::Result<(), String> {
    if !(0..sim.particles.len()).any(|i| sim.particles.mask[i] & bit != 0) {
        return Err("cannot zero the momentum of no atoms".into());
    }
    let (_, vc) = group_vcm(sim, bit);
    let p = &mut sim.particles;
    for i in 0..p.len() {
        if p.mask[i] & bit != 0 {
            p.v[i] -= vc;
        }
    }
    Ok(())
}

/// LAMMPS `Group::omega`'s threshold on the inertia tensor's determinant,
/// below which it solves L = I w in the tensor's principal axes.
const EPSILON: f64 = 1.0e-6;

/// Subtracts the group's rigid rotation w x r about its centre of mass, with w
/// from L = I w (LAMMPS `zero_rotation`, `Group::xcm`, `angmom`, `inertia`,
/// `omega`), on unwrapped positions.
pub fn zero_rotation(sim: &mut Sim, bit: u32) -> std::result::Result<(), String> {
    let n = sim.particles.len();
    let members: Vec<usize> = (0..n).filter(|&i| sim.particles.mask[i] & bit != 0).collect();
    if members.is_empty() {
        return Err("cannot zero the rotation of no atoms".into());
    }
    let xu: Vec<V3> = members.iter().map(|&i| unwrapped(sim, i)).collect();
    let p = &sim.particles;
    let mut mass = 0.0;
    let mut cm = V3::zeros();
    for (k, &i) in members.iter().enumerate() {
        mass += p.mass[i];
        cm += xu[k] * p.mass[i];
    }
    if mass > 0.0 {
        cm /= mass;
    }
    let (mut l, mut ione) = (V3::zeros(), [[0.0f64; 3]; 3]);
    for (k, &i) in members.iter().enumerate() {
        let (d, m, v) = (xu[k] - cm, p.mass[i], p.v[i]);
        l[0] += m * (d[1] * v[2] - d[2] * v[1]);
        l[1] += m * (d[2] * v[0] - d[0] * v[2]);
        l[2] += m * (d[0] * v[1] - d[1] * v[0]);
        ione[0][0] += m * (d[1] * d[1] + d[2] * d[2]);
        ione[1][1] += m * (d[0] * d[0] + d[2] * d[2]);
        ione[2][2] += m * (d[0] * d[0] + d[1] * d[1]);
        ione[0][1] -= m * d[0] * d[1];
        ione[1][2] -= m * d[1] * d[2];
        ione[0][2] -= m * d[0] * d[2];
    }
    ione[1][0] = ione[0][1];
    ione[2][1] = ione[1][2];
    ione[2][0] = ione[0][2];
    let w = omega(l, &ione);
    let p = &mut sim.particles;
    for (k, &i) in members.iter().enumerate() {
        let d = xu[k] - cm;
        p.v[i][0] -= w[1] * d[2] - w[2] * d[1];
        p.v[i][1] -= w[2] * d[0] - w[0] * d[2];
        p.v[i][2] -= w[0] * d[1] - w[1] * d[0];
    }
    Ok(())
}

/// w from L = I w: by the adjugate when det I > EPSILON (LAMMPS's order of
/// operations), otherwise in I's principal axes, dropping the axes whose
/// moment is below EPSILON times the largest (a line of atoms has no rotation
/// about itself). The second branch is also taken for a non-singular tensor
/// whose determinant is small in the deck's units (grains in SI); there it
/// is the same w, to rounding.
fn omega(l: V3, i: &[[f64; 3]; 3]) -> V3 {
    let det = i[0][0] * i[1][1] * i[2][2] + i[0][1] * i[1][2] * i[2][0] + i[0][2] * i[1][0] * i[2][1]
        - i[0][0] * i[1][2] * i[2][1]
        - i[0][1] * i[1][0] * i[2][2]
        - i[2][0] * i[1][1] * i[0][2];
    if det > EPSILON {
        let mut inv = [
            [i[1][1] * i[2][2] - i[1][2] * i[2][1], -(i[0][1] * i[2][2] - i[0][2] * i[2][1]), i[0][1] * i[1][2] - i[0][2] * i[1][1]],
            [-(i[1][0] * i[2][2] - i[1][2] * i[2][0]), i[0][0] * i[2][2] - i[0][2] * i[2][0], -(i[0][0] * i[1][2] - i[0][2] * i[1][0])],
            [i[1][0] * i[2][1] - i[1][1] * i[2][0], -(i[0][0] * i[2][1] - i[0][1] * i[2][0]), i[0][0] * i[1][1] - i[0][1] * i[1][0]],
        ];
        for row in inv.iter_mut() {
            for v in row.iter_mut() {
                *v /= det;
            }
        }
        return V3::new(
            inv[0][0] * l[0] + inv[0][1] * l[1] + inv[0][2] * l[2],
            inv[1][0] * l[0] + inv[1][1] * l[1] + inv[1][2] * l[2],
            inv[2][0] * l[0] + inv[2][1] * l[1] + inv[2][2] * l[2],
        );
    }
    let m = nalgebra::Matrix3::from_fn(|r, c| i[r][c]);
    let eig = nalgebra::SymmetricEigen::new(m);
    let max = eig.eigenvalues.iter().fold(0.0f64, |a, &b| a.max(b));
    let mut w = V3::zeros();
    for k in 0..3 {
        let (moment, axis) = (eig.eigenvalues[k], eig.eigenvectors.column(k));
        if moment >= EPSILON * max && moment > 0.0 {
            let along = axis[0] * l[0] + axis[1] * l[1] + axis[2] * l[2];
            for d in 0..3 {
                w[d] += along / moment * axis[d];
            }
        }
    }
    w
}

/// Scales the group's velocities by sqrt(T / T_now), T_now measured on
/// `temp_bit` as LAMMPS's `compute temp`: sum (v.v) m in storage order, times
/// 1 / (dof kB), dof = dim N - dim (`Velocity::rescale`, `ComputeTemp`).
fn rescale(sim: &mut Sim, bit: u32, temp_bit: u32, t_want: f64) -> std::result::Result<(), String> {
    let p = &sim.particles;
    let (mut sum, mut count) = (0.0, 0usize);
    for i in 0..p.len() {
        if p.mask[i] & temp_bit != 0 {
            let v = p.v[i];
            sum += (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * p.mass[i];
            count += 1;
        }
    }
    let dim = sim.domain.as_ref().map_or(3, |d| d.dimension) as f64;
    let dof = dim * count as f64 - dim;
    let tfactor = if dof > 0.0 { 1.0 / (dof * sim.boltz) } else { 0.0 };
    let t_now = sum * tfactor;
    if t_now == 0.0 {
        return Err("cannot rescale a temperature of 0 (one atom, or all at rest)".into());
    }
    let factor = (t_want / t_now).sqrt();
    let p = &mut sim.particles;
    for i in 0..p.len() {
        if p.mask[i] & bit != 0 {
            p.v[i] *= factor;
        }
    }
    Ok(())
}
