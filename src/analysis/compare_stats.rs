//! Statistics of one dump frame that do not need matching trajectories:
//! particle count, centre of mass, kinetic energies, coordination number
//! from positions and radii, and the two-sample Kolmogorov-Smirnov test on
//! speed distributions.

use super::compare::Snap;
use serde::Serialize;

/// Statistics of one frame.
#[derive(Clone, Debug, Default, Serialize)]
pub struct FrameStats {
    /// Number of particles.
    pub count: usize,
    /// Centre of mass (mass-weighted; volume-weighted without masses).
    pub com: [f64; 3],
    /// Translational kinetic energy sum m v^2 / 2 (J; per unit density when
    /// the dump has no mass column and no density was given).
    pub ke: f64,
    /// Rotational kinetic energy sum I w^2 / 2 with I = 2/5 m r^2.
    pub ke_rot: f64,
    /// Mean coordination number (overlapping neighbour pairs x 2 / count).
    pub coordination: f64,
}

/// Mass of particle `i`: mass column, else density x sphere volume (density 1 if unknown).
pub fn mass(s: &Snap, i: usize, density: f64) -> f64 {
    if let Some(m) = &s.m {
        return m[i];
    }
    let r = s.r.as_ref().map_or(0.5, |r| r[i]);
    density * 4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

fn norm2(a: [f64; 3]) -> f64 {
    a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
}

/// Statistics of a frame; `density` is used when there is no mass column.
pub fn frame_stats(s: &Snap, density: f64) -> FrameStats {
    let n = s.ids.len();
    let mut st = FrameStats { count: n, ..Default::default() };
    let mut mt = 0.0;
    for i in 0..n {
        let m = mass(s, i, density);
        mt += m;
        for k in 0..3 {
            st.com[k] += m * s.x[i][k];
        }
        if let Some(v) = &s.v {
            st.ke += 0.5 * m * norm2(v[i]);
        }
        if let (Some(w), Some(r)) = (&s.w, &s.r) {
            st.ke_rot += 0.5 * 0.4 * m * r[i] * r[i] * norm2(w[i]);
        }
    }
    if mt > 0.0 {
        for k in 0..3 {
            st.com[k] /= mt;
        }
    }
    st.coordination = if n > 0 && s.r.is_some() { 2.0 * contacts(s) as f64 / n as f64 } else { 0.0 };
    st
}

/// Number of overlapping pairs (|xi - xj| < ri + rj), minimum image across
/// periodic dimensions; binned, so linear in the particle count.
pub fn contacts(s: &Snap) -> usize {
    let Some(r) = &s.r else { return 0 };
    let n = s.ids.len();
    let rmax = r.iter().cloned().fold(0.0, f64::max);
    if n < 2 || !(rmax > 0.0) || !rmax.is_finite() {
        return 0;
    }
    let cell = 2.0 * rmax;
    let lo = s.lo;
    let len = [s.hi[0] - s.lo[0], s.hi[1] - s.lo[1], s.hi[2] - s.lo[2]];
    let mut dims = [1i64; 3];
    for k in 0..3 {
        if len[k] > 0.0 && len[k].is_finite() {
            dims[k] = ((len[k] / cell).floor() as i64).clamp(1, 1 << 20);
        }
    }
    let cidx = |x: [f64; 3]| -> [i64; 3] {
        let mut c = [0i64; 3];
        for k in 0..3 {
            let f = if len[k] > 0.0 { (x[k] - lo[k]) / len[k] } else { 0.0 };
            c[k] = ((f * dims[k] as f64).floor() as i64).clamp(0, dims[k] - 1);
        }
        c
    };
    let mut bins: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
    for i in 0..n {
        bins.entry(cidx(s.x[i])).or_default().push(i);
    }
    let mut count = 0;
    for i in 0..n {
        let c = cidx(s.x[i]);
        let mut seen: Vec<[i64; 3]> = Vec::with_capacity(27);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let mut nb = [c[0] + dx, c[1] + dy, c[2] + dz];
                    let mut skip = false;
                    for k in 0..3 {
                        if nb[k] < 0 || nb[k] >= dims[k] {
                            if s.periodic[k] {
                                nb[k] = nb[k].rem_euclid(dims[k]);
                            } else {
                                skip = true;
                            }
                        }
                    }
                    if skip || seen.contains(&nb) {
                        continue;
                    }
                    seen.push(nb);
                    if let Some(list) = bins.get(&nb) {
                        for &j in list {
                            if j <= i {
                                continue;
                            }
                            let d = s.delta(s.x[i], s.x[j]);
                            let rr = r[i] + r[j];
                            if norm2(d) < rr * rr {
                                count += 1;
                            }
                        }
                    }
                }
            }
        }
    }
    count
}

/// Particle speeds of a frame (empty without velocities).
pub fn speeds(s: &Snap) -> Vec<f64> {
    s.v.as_ref().map_or(vec![], |v| v.iter().map(|a| norm2(*a).sqrt()).collect())
}

/// Two-sample Kolmogorov-Smirnov test: (D, asymptotic p-value).
/// Returns None when either sample is empty.
pub fn ks_two_sample(a: &[f64], b: &[f64]) -> Option<(f64, f64)> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let mut a: Vec<f64> = a.iter().cloned().filter(|x| x.is_finite()).collect();
    let mut b: Vec<f64> = b.iter().cloned().filter(|x| x.is_finite()).collect();
    if a.is_empty() || b.is_empty() {
        return None;
    }
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    let (n, m) = (a.len(), b.len());
    let (mut i, mut j, mut d) = (0usize, 0usize, 0.0f64);
    while i < n && j < m {
        let x = a[i].min(b[j]);
        while i < n && a[i] <= x {
            i += 1;
        }
        while j < m && b[j] <= x {
            j += 1;
        }
        d = d.max((i as f64 / n as f64 - j as f64 / m as f64).abs());
    }
    let ne = (n * m) as f64 / (n + m) as f64;
    let lambda = (ne.sqrt() + 0.12 + 0.11 / ne.sqrt()) * d;
    Some((d, kolmogorov_q(lambda)))
}

/// Kolmogorov distribution tail Q(lambda) = 2 sum (-1)^(k-1) exp(-2 k^2 lambda^2).
fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda < 1e-3 {
        return 1.0;
    }
    let mut sum = 0.0;
    let mut sign = 1.0;
    for k in 1..=200 {
        let t = sign * (-2.0 * (k * k) as f64 * lambda * lambda).exp();
        sum += t;
        if t.abs() < 1e-12 {
            break;
        }
        sign = -sign;
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ks_identical_and_disjoint() {
        let a: Vec<f64> = (0..100).map(|i| i as f64).collect();
        let (d, p) = ks_two_sample(&a, &a).unwrap();
        assert_eq!(d, 0.0);
        assert_eq!(p, 1.0);
        let b: Vec<f64> = (0..100).map(|i| 1000.0 + i as f64).collect();
        let (d, p) = ks_two_sample(&a, &b).unwrap();
        assert_eq!(d, 1.0);
        assert!(p < 1e-20);
    }

    #[test]
    fn kolmogorov_tail_known_values() {
        // Q(1.36) = 0.049 (the 5 % critical value), Q(1.63) = 0.010
        assert!((kolmogorov_q(1.358) - 0.05).abs() < 1e-3);
        assert!((kolmogorov_q(1.628) - 0.01).abs() < 1e-3);
    }
}

/// Heap statistics of a frame: the angle of repose the paper's way
/// (`demx repose`) and the packing fraction of the heap's core.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct HeapStats {
    /// Particles in the frame.
    pub count: usize,
    /// Angle of repose, mean of the x-z and y-z projections (degrees).
    pub theta: f64,
    /// Half the difference of the two projections' angles times sqrt 2 (degrees).
    pub theta_sd: f64,
    /// Solid fraction in the core cylinder (see [`heap_stats`]).
    pub phi: f64,
}

/// θr and core packing fraction of a heap resting on a plate (the plate is
/// the lowest sphere bottom). The core is a vertical cylinder on the heap's
/// axis (the particles' mean x, y) of radius a quarter of the base radius
/// h/tan θr, from one mean diameter above the plate (skipping the layering
/// at the plate) to half the heap height h; the cylinder then lies wholly
/// under the conical surface. Its solid fraction is counted on a grid of
/// points d/10 apart. None when the frame has no radii or no heap shape.
pub fn heap_stats(s: &Snap) -> Option<HeapStats> {
    let r = s.r.as_ref()?;
    let n = r.len();
    if n == 0 {
        return None;
    }
    let plate = (0..n).map(|i| s.x[i][2] - r[i]).fold(f64::INFINITY, f64::min);
    let zh: Vec<f64> = (0..n).map(|i| s.x[i][2] - plate).collect();
    let xs: Vec<f64> = s.x.iter().map(|p| p[0]).collect();
    let ys: Vec<f64> = s.x.iter().map(|p| p[1]).collect();
    let rmin = r.iter().cloned().fold(f64::INFINITY, f64::min);
    let txz = super::repose::projection_angle(&xs, &zh, r, rmin / 5.0)?;
    let tyz = super::repose::projection_angle(&ys, &zh, r, rmin / 5.0)?;
    let theta = 0.5 * (txz + tyz);
    let h = (0..n).map(|i| zh[i] + r[i]).fold(0.0, f64::max);
    let d = 2.0 * r.iter().sum::<f64>() / n as f64;
    let (cx, cy) = (xs.iter().sum::<f64>() / n as f64, ys.iter().sum::<f64>() / n as f64);
    let rc = 0.25 * h / theta.to_radians().tan().max(1e-6);
    let (z0, z1) = (d, 0.5 * h);
    let mut phi = 0.0;
    if z1 > z0 && rc > 0.0 {
        // bin the spheres near the core by (x, y) cells of size 2 rmax
        let rmax = r.iter().cloned().fold(0.0, f64::max);
        let cell = 2.0 * rmax;
        let m = ((2.0 * (rc + cell)) / cell).ceil() as usize + 1;
        let (ox, oy) = (cx - rc - cell, cy - rc - cell);
        let mut bins: Vec<Vec<usize>> = vec![vec![]; m * m];
        for i in 0..n {
            let (bx, by) = (((xs[i] - ox) / cell).floor(), ((ys[i] - oy) / cell).floor());
            if bx >= 0.0 && by >= 0.0 && (bx as usize) < m && (by as usize) < m {
                bins[by as usize * m + bx as usize].push(i);
            }
        }
        let step = d / 10.0;
        let (mut inside, mut total) = (0usize, 0usize);
        let k = (rc / step).ceil() as i64;
        let kz = ((z1 - z0) / step).ceil() as i64;
        for a in -k..=k {
            for b in -k..=k {
                let (px, py) = (cx + a as f64 * step, cy + b as f64 * step);
                if (px - cx).powi(2) + (py - cy).powi(2) > rc * rc {
                    continue;
                }
                let (bx, by) = (((px - ox) / cell).floor() as i64, ((py - oy) / cell).floor() as i64);
                for c in 0..kz {
                    let pz = plate + z0 + (c as f64 + 0.5) * step;
                    total += 1;
                    let hit = (bx - 1..=bx + 1).any(|u| {
                        (by - 1..=by + 1).any(|v| {
                            u >= 0
                                && v >= 0
                                && (u as usize) < m
                                && (v as usize) < m
                                && bins[v as usize * m + u as usize].iter().any(|&i| {
                                    let q = s.x[i];
                                    (q[0] - px).powi(2) + (q[1] - py).powi(2) + (q[2] - pz).powi(2) < r[i] * r[i]
                                })
                        })
                    });
                    inside += hit as usize;
                }
            }
        }
        if total > 0 {
            phi = inside as f64 / total as f64;
        }
    }
    Some(HeapStats { count: n, theta, theta_sd: (txz - tyz).abs() / std::f64::consts::SQRT_2, phi })
}
