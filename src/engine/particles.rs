//! Particle storage: structure of arrays.
//!
//! One place pushes, removes and permutes every column, including the
//! per-atom extra columns that fixes register (wall contact history, fix
//! property/atom values), so no column can fall out of step.

use crate::physics::V3;

/// A per-atom column registered by a fix or command (width values per atom).
#[derive(Clone, Debug)]
pub struct PerAtom {
    /// Name (the fix or property id).
    pub name: String,
    /// Values per atom.
    pub width: usize,
    /// `width * len` values.
    pub data: Vec<f64>,
    /// Value new atoms get.
    pub default: Vec<f64>,
    /// New atoms get their position instead of `default` (width 3: LAMMPS
    /// `compute displace/atom`'s `set_arrays`, the original of an atom
    /// created after the compute).
    pub from_position: bool,
}

/// All particles, one column per quantity.
#[derive(Clone, Debug, Default)]
pub struct Particles {
    /// Atom id (LAMMPS tag), unique, > 0.
    pub tag: Vec<i64>,
    /// Atom type, 1-based.
    pub kind: Vec<u32>,
    /// Group membership bits (bit 0 = group `all`).
    pub mask: Vec<u32>,
    /// Position (m).
    pub x: Vec<V3>,
    /// Velocity (m/s).
    pub v: Vec<V3>,
    /// Angular velocity (rad/s).
    pub omega: Vec<V3>,
    /// Force (N).
    pub f: Vec<V3>,
    /// Torque (N m).
    pub torque: Vec<V3>,
    /// Radius (m).
    pub radius: Vec<f64>,
    /// Mass (kg).
    pub mass: Vec<f64>,
    /// Density (kg/m^3), as given at creation.
    pub density: Vec<f64>,
    /// Periodic image counts.
    pub image: Vec<[i32; 3]>,
    /// Frozen for contacts (fix freeze): contact partners see infinite mass.
    pub frozen: Vec<bool>,
    /// Extra per-atom columns.
    pub extra: Vec<PerAtom>,
}

/// What a new particle is made of.
#[derive(Clone, Copy, Debug)]
pub struct NewParticle {
    /// Atom id.
    pub tag: i64,
    /// Atom type.
    pub kind: u32,
    /// Group bits.
    pub mask: u32,
    /// Position.
    pub x: V3,
    /// Velocity.
    pub v: V3,
    /// Angular velocity.
    pub omega: V3,
    /// Radius.
    pub radius: f64,
    /// Density.
    pub density: f64,
}

impl Particles {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.tag.len()
    }
    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.tag.is_empty()
    }
    /// Mass of a sphere of radius r and density rho (LAMMPS and LIGGGHTS use
    /// sphere masses also in 2d unless `disc` is given).
    pub fn sphere_mass(radius: f64, density: f64) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * radius * radius * radius * density
    }
    /// Append one particle.
    pub fn push(&mut self, p: NewParticle) {
        self.tag.push(p.tag);
        self.kind.push(p.kind);
        self.mask.push(p.mask | 1);
        self.x.push(p.x);
        self.v.push(p.v);
        self.omega.push(p.omega);
        self.f.push(V3::zeros());
        self.torque.push(V3::zeros());
        self.radius.push(p.radius);
        self.mass.push(Self::sphere_mass(p.radius, p.density));
        self.density.push(p.density);
        self.image.push([0; 3]);
        self.frozen.push(false);
        for e in &mut self.extra {
            if e.from_position {
                e.data.extend_from_slice(&[p.x.x, p.x.y, p.x.z]);
            } else {
                e.data.extend_from_slice(&e.default);
            }
        }
    }
    /// Remove particle `i` by moving the last one into its place (LAMMPS
    /// `avec->copy(nlocal-1, i)`).
    pub fn swap_remove(&mut self, i: usize) {
        let last = self.len() - 1;
        self.tag.swap_remove(i);
        self.kind.swap_remove(i);
        self.mask.swap_remove(i);
        self.x.swap_remove(i);
        self.v.swap_remove(i);
        self.omega.swap_remove(i);
        self.f.swap_remove(i);
        self.torque.swap_remove(i);
        self.radius.swap_remove(i);
        self.mass.swap_remove(i);
        self.density.swap_remove(i);
        self.image.swap_remove(i);
        self.frozen.swap_remove(i);
        for e in &mut self.extra {
            let w = e.width;
            if i != last {
                for k in 0..w {
                    e.data[i * w + k] = e.data[last * w + k];
                }
            }
            e.data.truncate(last * w);
        }
    }
    /// Remove every particle for which `remove[i]` is true, keeping the
    /// swap-remove order deterministic (highest index first).
    pub fn remove_where(&mut self, remove: &[bool]) -> usize {
        let mut n = 0;
        for i in (0..remove.len()).rev() {
            if remove[i] {
                self.swap_remove(i);
                n += 1;
            }
        }
        n
    }
    /// Reorder all columns: new index k holds old particle `order[k]`.
    pub fn permute(&mut self, order: &[usize]) {
        fn p<T: Clone>(v: &mut Vec<T>, order: &[usize]) {
            let nv: Vec<T> = order.iter().map(|&o| v[o].clone()).collect();
            *v = nv;
        }
        p(&mut self.tag, order);
        p(&mut self.kind, order);
        p(&mut self.mask, order);
        p(&mut self.x, order);
        p(&mut self.v, order);
        p(&mut self.omega, order);
        p(&mut self.f, order);
        p(&mut self.torque, order);
        p(&mut self.radius, order);
        p(&mut self.mass, order);
        p(&mut self.density, order);
        p(&mut self.image, order);
        p(&mut self.frozen, order);
        for e in &mut self.extra {
            let w = e.width;
            let mut nd = Vec::with_capacity(e.data.len());
            for &o in order {
                nd.extend_from_slice(&e.data[o * w..o * w + w]);
            }
            e.data = nd;
        }
    }
    /// Register (or find) an extra per-atom column; returns its index.
    pub fn add_extra(&mut self, name: &str, default: Vec<f64>) -> usize {
        if let Some(k) = self.extra.iter().position(|e| e.name == name) {
            return k;
        }
        let width = default.len();
        let mut data = Vec::with_capacity(width * self.len());
        for _ in 0..self.len() {
            data.extend_from_slice(&default);
        }
        self.extra.push(PerAtom { name: name.to_string(), width, data, default, from_position: false });
        self.extra.len() - 1
    }
    /// Index of an extra column by name.
    pub fn extra_index(&self, name: &str) -> Option<usize> {
        self.extra.iter().position(|e| e.name == name)
    }
    /// Largest id in use (0 if none).
    pub fn max_tag(&self) -> i64 {
        self.tag.iter().copied().max().unwrap_or(0)
    }
    /// Moment of inertia of particle i (solid sphere, 0.4 m r^2).
    #[inline(always)]
    pub fn inertia(&self, i: usize) -> f64 {
        0.4 * self.mass[i] * self.radius[i] * self.radius[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn np(tag: i64) -> NewParticle {
        NewParticle { tag, kind: 1, mask: 1, x: V3::new(tag as f64, 0.0, 0.0), v: V3::zeros(), omega: V3::zeros(), radius: 0.5, density: 1000.0 }
    }

    #[test]
    fn columns_stay_in_step_through_remove_and_permute() {
        let mut p = Particles::default();
        p.add_extra("hist", vec![0.0, 0.0]);
        for t in 1..=5 {
            p.push(np(t));
            let k = p.len() - 1;
            p.extra[0].data[2 * k] = t as f64 * 10.0;
        }
        p.swap_remove(1); // tag 2 goes, tag 5 moves to index 1
        assert_eq!(p.tag, vec![1, 5, 3, 4]);
        assert_eq!(p.x[1].x, 5.0);
        assert_eq!(p.extra[0].data[2], 50.0);
        p.permute(&[3, 2, 1, 0]);
        assert_eq!(p.tag, vec![4, 3, 5, 1]);
        assert_eq!(p.extra[0].data[0], 40.0);
        assert_eq!(p.extra[0].data.len(), 8);
        let m = Particles::sphere_mass(0.5, 1000.0);
        assert!((m - 4.0 / 3.0 * std::f64::consts::PI * 0.125 * 1000.0).abs() < 1e-12);
    }
}
