//! Velocity-Verlet for spheres (`fix nve/sphere`), in the same order of
//! operations as LAMMPS `FixNVESphere`, so demx and the engines stay in step.

use super::particles::Particles;

/// LAMMPS `INERTIA` for solid spheres.
pub const INERTIA: f64 = 0.4;

/// First half: v += dt/2 f/m; x += dt v; omega += dt/2 torque/I.
/// `group` is the fix's group bit; `dtf = 0.5 dt` (ftm2v = 1 in si/lj/cgs).
pub fn initial_integrate(p: &mut Particles, group: u32, dt: f64) {
    let dtf = 0.5 * dt;
    let dtfrot = dtf / INERTIA;
    for i in 0..p.len() {
        if p.mask[i] & group == 0 {
            continue;
        }
        let dtfm = dtf / p.mass[i];
        p.v[i] += p.f[i] * dtfm;
        p.x[i] += p.v[i] * dt;
        let dtirotate = dtfrot / (p.radius[i] * p.radius[i] * p.mass[i]);
        p.omega[i] += p.torque[i] * dtirotate;
    }
}

/// Second half: v += dt/2 f/m; omega += dt/2 torque/I.
pub fn final_integrate(p: &mut Particles, group: u32, dt: f64) {
    let dtf = 0.5 * dt;
    let dtfrot = dtf / INERTIA;
    for i in 0..p.len() {
        if p.mask[i] & group == 0 {
            continue;
        }
        let dtfm = dtf / p.mass[i];
        p.v[i] += p.f[i] * dtfm;
        let dtirotate = dtfrot / (p.radius[i] * p.radius[i] * p.mass[i]);
        p.omega[i] += p.torque[i] * dtirotate;
    }
}

/// `fix nve` first half: translation only (LAMMPS `FixNVE`); angular
/// velocity is left alone, so particles integrated this way do not rotate.
pub fn initial_integrate_nve(p: &mut Particles, group: u32, dt: f64) {
    let dtf = 0.5 * dt;
    for i in 0..p.len() {
        if p.mask[i] & group == 0 {
            continue;
        }
        let dtfm = dtf / p.mass[i];
        p.v[i] += p.f[i] * dtfm;
        p.x[i] += p.v[i] * dt;
    }
}

/// `fix nve` second half.
pub fn final_integrate_nve(p: &mut Particles, group: u32, dt: f64) {
    let dtf = 0.5 * dt;
    for i in 0..p.len() {
        if p.mask[i] & group == 0 {
            continue;
        }
        let dtfm = dtf / p.mass[i];
        p.v[i] += p.f[i] * dtfm;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::particles::NewParticle;
    use crate::physics::V3;

    #[test]
    fn free_fall_is_exact_for_constant_force() {
        // velocity Verlet integrates constant acceleration exactly:
        // z(t) = z0 + v0 t - g t^2 / 2
        let mut p = Particles::default();
        p.push(NewParticle { tag: 1, kind: 1, mask: 1, x: V3::new(0.0, 0.0, 10.0), v: V3::new(0.0, 0.0, 2.0), omega: V3::zeros(), radius: 0.01, density: 2500.0 });
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
}
