//! Engine-side helpers for particle insertion: a hash grid for overlap
//! checks against existing and freshly placed spheres (periodic axes use
//! the minimum image), random points in regions (LIGGGHTS
//! `Region::generate_random`, optionally shrunk by a radius for `all_in`),
//! the Monte Carlo region volume LIGGGHTS uses for `insert/pack`, and the
//! LIGGGHTS seed rule (prime, > 10000).

use super::domain::Domain;
use super::rng::Park;
use crate::geom::Region;
use crate::physics::V3;
use std::collections::HashMap;

/// Spheres binned on a cubic grid; answers "does a sphere at x with radius
/// r touch or overlap any stored sphere?" in O(1) per query.
#[derive(Clone, Debug)]
pub struct OverlapGrid {
    cell: f64,
    map: HashMap<[i64; 3], Vec<u32>>,
    pts: Vec<(V3, f64)>,
    /// (lo, length) of periodic axes.
    periodic: [Option<(f64, f64)>; 3],
}

impl OverlapGrid {
    /// A grid whose cell is at least `reach`, the largest sum of two radii
    /// that will be compared; periodic axes are taken from `domain`.
    pub fn new(reach: f64, domain: Option<&Domain>) -> OverlapGrid {
        let cell = if reach.is_finite() && reach > 0.0 { reach } else { 1.0 };
        let mut periodic = [None; 3];
        if let Some(d) = domain {
            for (k, p) in periodic.iter_mut().enumerate() {
                if d.periodic(k) && d.len(k) > 0.0 {
                    *p = Some((d.lo[k], d.len(k)));
                }
            }
        }
        OverlapGrid { cell, map: HashMap::new(), pts: Vec::new(), periodic }
    }

    fn key(&self, x: &V3) -> [i64; 3] {
        let f = |v: f64| {
            let q = (v / self.cell).floor();
            if q.is_finite() {
                q.clamp(-1e15, 1e15) as i64
            } else {
                0
            }
        };
        [f(x.x), f(x.y), f(x.z)]
    }

    /// Number of stored spheres.
    pub fn len(&self) -> usize {
        self.pts.len()
    }
    /// Whether no sphere is stored.
    pub fn is_empty(&self) -> bool {
        self.pts.is_empty()
    }

    /// Store a sphere.
    pub fn add(&mut self, x: V3, r: f64) {
        let k = self.key(&x);
        self.map.entry(k).or_default().push(self.pts.len() as u32);
        self.pts.push((x, r));
    }

    /// Whether a sphere at `x` with radius `r` overlaps or touches a stored
    /// one (`|dx|^2 <= (r + rj)^2`, as LAMMPS fix pour tests).
    pub fn overlaps(&self, x: V3, r: f64) -> bool {
        // images of x within reach of a periodic boundary
        let mut shifts: Vec<V3> = vec![V3::zeros()];
        for d in 0..3 {
            if let Some((lo, len)) = self.periodic[d] {
                let mut more = Vec::new();
                for s in &shifts {
                    let mut e = V3::zeros();
                    if x[d] - lo < self.cell {
                        e[d] = len;
                        more.push(s + e);
                    }
                    if lo + len - x[d] < self.cell {
                        e[d] = -len;
                        more.push(s + e);
                    }
                }
                shifts.extend(more);
            }
        }
        for s in shifts {
            let y = x + s;
            let k = self.key(&y);
            for i in -1..=1 {
                for j in -1..=1 {
                    for l in -1..=1 {
                        if let Some(v) = self.map.get(&[k[0] + i, k[1] + j, k[2] + l]) {
                            for &m in v {
                                let (p, rp) = self.pts[m as usize];
                                let rs = r + rp;
                                if (y - p).norm_squared() <= rs * rs {
                                    return true;
                                }
                            }
                        }
                    }
                }
            }
        }
        false
    }
}

/// Whether `n` is prime (trial division; seeds are below 2^31).
pub fn is_prime(n: i64) -> bool {
    if n < 2 {
        return false;
    }
    if n % 2 == 0 {
        return n == 2;
    }
    let mut d = 3i64;
    while d * d <= n {
        if n % d == 0 {
            return false;
        }
        d += 2;
    }
    true
}

/// Whether `x` lies in the box (`lo <= x < hi` on every axis).
pub fn in_box(domain: &Domain, x: &V3) -> bool {
    (0..3).all(|d| x[d] >= domain.lo[d] && x[d] < domain.hi[d])
}

/// LIGGGHTS `Region::volume_mc`: `n` points uniform in the region's
/// bounding box (three draws each, x then y then z); the volume is the
/// fraction inside both the box and the region times the bounding-box
/// volume. None if the region has no bounding box.
pub fn region_volume_mc(region: &Region, domain: &Domain, rng: &mut Park, n: usize) -> Option<f64> {
    let (lo, hi) = region.bbox()?;
    let ext = hi - lo;
    let mut hits = 0usize;
    for _ in 0..n {
        let x = lo.x + rng.uniform() * ext.x;
        let y = lo.y + rng.uniform() * ext.y;
        let z = lo.z + rng.uniform() * ext.z;
        let p = V3::new(x, y, z);
        if in_box(domain, &p) && region.contains(p) {
            hits += 1;
        }
    }
    Some(hits as f64 / n.max(1) as f64 * ext.x * ext.y * ext.z)
}

/// Whether `p` is in the region at least `cut` away from its surface
/// (LIGGGHTS `match_shrinkby_cut`).
pub fn inside_shrunk(region: &Region, p: V3, cut: f64) -> bool {
    region.contains(p) && (cut <= 0.0 || region.surface_contacts(p, cut).is_empty())
}

/// A random point in the region (and in the box), uniform over the region's
/// bounding box with rejection, as LIGGGHTS `generate_random`; with
/// `shrink > 0` the point keeps that distance from the region surface
/// (`generate_random_shrinkby_cut`). None after `maxtry` rejections.
pub fn random_point(region: &Region, domain: &Domain, rng: &mut Park, shrink: f64, maxtry: usize) -> Option<V3> {
    let (mut lo, mut hi) = region.bbox()?;
    if shrink > 0.0 {
        lo += V3::repeat(shrink);
        hi -= V3::repeat(shrink);
        if (0..3).any(|d| hi[d] < lo[d]) {
            return None;
        }
    }
    let ext = hi - lo;
    for _ in 0..maxtry {
        let p = V3::new(lo.x + rng.uniform() * ext.x, lo.y + rng.uniform() * ext.y, lo.z + rng.uniform() * ext.z);
        if in_box(domain, &p) && inside_shrunk(region, p, shrink) {
            return Some(p);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::domain::Side;

    #[test]
    fn primes() {
        assert!(is_prime(15485863) && is_prime(32452843) && is_prime(10007));
        assert!(!is_prime(15485862) && !is_prime(1) && !is_prime(10001));
    }

    #[test]
    fn grid_finds_touching_and_periodic_images() {
        let s = [[Side::Periodic; 2], [Side::Fixed; 2], [Side::Fixed; 2]];
        let d = Domain::new([0.0; 3], [10.0; 3], s, 3);
        let mut g = OverlapGrid::new(2.0, Some(&d));
        g.add(V3::new(0.2, 5.0, 5.0), 0.5);
        assert!(g.overlaps(V3::new(1.2, 5.0, 5.0), 0.5)); // exactly touching counts
        assert!(!g.overlaps(V3::new(1.3, 5.0, 5.0), 0.5));
        assert!(g.overlaps(V3::new(9.5, 5.0, 5.0), 0.5)); // across x periodic boundary
        assert!(!g.overlaps(V3::new(5.0, 9.5, 5.0), 0.5));
    }
}
