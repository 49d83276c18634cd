//! The arithmetic floor of one contact: the LIGGGHTS Hertz + tangential
//! history laws of bench deck (a) on lanes, with every input already in
//! registers or L1 (no pair walk, no gather, no force scatter). What a pair
//! pass spends per contact above this figure is data movement.
//!
//!     cargo run --release --example law_floor
use demx::engine::kernel::{contact_lanes, PairState};
use demx::engine::rng::Park;
use demx::physics::lanes::{BatchCoeffs, Vec3, F8, LANES};
use demx::physics::mixing::{liggghts_beta, liggghts_g_eff, liggghts_y_eff};
use demx::physics::normal::hertz::LiggghtsHertz;
use demx::physics::tangential::history::LiggghtsHistory;
use demx::physics::{NormalLaw, OutL, PairParams, TangentialLaw};
use std::time::Instant;

fn main() {
    // deck (a): E = 1e7, nu = 0.3, e = 0.5, mu = 0.5, d = 1 mm, rho = 2500
    let (e, nu) = (1e7, 0.3);
    let pp = PairParams {
        y_eff: liggghts_y_eff(e, nu, e, nu),
        g_eff: liggghts_g_eff(e, nu, e, nu),
        beta: liggghts_beta(0.5),
        mu: 0.5,
        tangential_damping: 1.0,
        ..PairParams::default()
    };
    let coeffs = BatchCoeffs { p: [&pp; LANES], uniform: true };
    let mut park = Park::new(12345);
    let mut rnd = move || park.uniform() - 0.5;
    let (rad, mass) = (5e-4, 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * 1.25e-10);
    let mut lanes = |scale: f64, off: f64| F8(std::array::from_fn(|_| off + scale * rnd()));
    let nb = 64;
    let mut states = vec![];
    let mut hist = vec![];
    for _ in 0..nb {
        let dir = Vec3 { x: lanes(2.0, 0.0), y: lanes(2.0, 0.0), z: lanes(2.0, 0.0) };
        let norm = dir.norm();
        let r = lanes(2e-6, 2.0 * rad - 2e-6);
        let v = |l: &mut dyn FnMut(f64, f64) -> F8| Vec3 { x: l(1e-3, 0.0), y: l(1e-3, 0.0), z: l(1e-3, 0.0) };
        let xi = Vec3 { x: lanes(1e-3, 0.0), y: lanes(1e-3, 0.0), z: lanes(1e-3, 0.0) };
        let xj = xi - dir * (r / norm);
        states.push(PairState {
            xi,
            xj,
            vi: v(&mut lanes),
            vj: v(&mut lanes),
            wi: v(&mut lanes),
            wj: v(&mut lanes),
            ri: F8([rad; LANES]),
            rj: F8([rad; LANES]),
            mi: F8([mass; LANES]),
            mj: F8([mass; LANES]),
        });
        hist.push([lanes(1e-7, 0.0), lanes(1e-7, 0.0), lanes(1e-7, 0.0)]);
    }
    let (normal, tangential) = (LiggghtsHertz, LiggghtsHistory);
    let reps = 20_000;
    let mut best = f64::INFINITY;
    let mut sum = 0.0;
    for _ in 0..5 {
        let t = Instant::now();
        for _ in 0..reps {
            for (s, h) in states.iter().zip(hist.iter_mut()) {
                let c = contact_lanes(s, 5e-6);
                let mut out = OutL::zeros();
                normal.normal_lanes(&c, &coeffs, &mut [], &mut out);
                tangential.tangential_lanes(&c, &coeffs, &mut h[..], &mut out);
                let f = out.force_i(&c);
                sum += f.x.0[0] + out.torque_i.y.0[1] + out.torque_j.z.0[2];
            }
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / (reps * nb * LANES) as f64;
        best = best.min(ns);
    }
    println!("laws on lanes, data in L1: {best:.2} ns per contact (checksum {sum:.3e})");
}
