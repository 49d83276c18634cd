//! Triangle-mesh walls as LIGGGHTS 3.8 treats them: the mesh of one
//! `fix mesh/surface` with its topology (which edges and corners may carry a
//! contact, which triangles count as coplanar neighbours), its rigid motion
//! (`fix move/mesh`), and the per-particle contact slots of a mesh wall.
//!
//! Facts reproduced (LIGGGHTS `SurfaceMesh::buildNeighbours`,
//! `TriMesh::resolveTriSphereContactBary`, `FixContactHistoryMesh`):
//! - Two triangles sharing an edge are coplanar when `|n_a . n_b| >= cos(c)`
//!   (`curvature c`, default 0.256235 deg, i.e. cos = 1 - 1e-5). A shared
//!   edge of coplanar triangles is inactive on both; a shared edge of
//!   non-coplanar triangles is active only on the triangle with the higher id.
//!   Boundary edges are active.
//! - A corner is active only on the highest-id triangle among those that
//!   share the node (walking edge neighbours), and only if no two distinct
//!   edges meeting there are colinear and at least one of them is active.
//! - A sphere whose projection lies inside the triangle (all barycentric
//!   coordinates > -1e-10) touches the face; otherwise the closest edge or
//!   corner, and an inactive edge or corner gives no contact.
//! - Duplicate rule: a new contact with triangle t is skipped when the
//!   particle already had a contact this step with a triangle that is a
//!   coplanar neighbour of t (sharing an edge or a node); a new contact takes
//!   over the history of a previous contact with a coplanar neighbour.

use crate::error::{Error, Result};
use crate::geom::mesh::closest_point_on_triangle;
use crate::geom::{rotate_sc, ContactKind, Mesh, MeshMotion, Triangle, TriangleBins};
use crate::physics::V3;
use std::sync::{Arc, RwLock};

/// Tolerance on barycentric coordinates for a face contact (LIGGGHTS `SMALL_TRIMESH`).
pub const SMALL_TRIMESH: f64 = 1.0e-10;
/// Contact slots per particle and mesh wall.
pub const MESH_SLOTS: usize = 8;
/// LIGGGHTS default `curvature`: cos(0.256235 deg) = 1 - 1e-5.
pub const DEFAULT_CURVATURE_COS: f64 = 1.0 - 1.0e-5;

/// A mesh shared between its `fix mesh/surface`, walls, movers and dumps.
pub type SharedMesh = Arc<RwLock<SurfaceMesh>>;

/// One triangle mesh with topology and motion.
#[derive(Clone, Debug)]
pub struct SurfaceMesh {
    /// Id of the defining `fix mesh/surface`.
    pub id: String,
    /// Material (atom) type of the wall.
    pub wall_type: u32,
    /// Triangles at the reference position (after scale/move/rotate).
    pub tris: Vec<Triangle>,
    /// Bins over the reference triangles.
    pub bins: TriangleBins,
    /// Edge i (v\[i\] -> v\[i+1\]) may carry a contact.
    pub edge_active: Vec<[bool; 3]>,
    /// Corner i may carry a contact.
    pub corner_active: Vec<[bool; 3]>,
    /// Sorted ids of the coplanar triangles sharing an edge or a node.
    pub coplanar: Vec<Vec<u32>>,
    /// How many triangles share an edge with each (LIGGGHTS `nNeighs`,
    /// `dump mesh/vtk ... nneighs`).
    pub nneighs: Vec<u32>,
    /// cos of the `curvature` angle.
    pub curvature_cos: f64,
    /// Rigid motion and the time it started (`fix move/mesh`).
    pub motion: Option<(MeshMotion, f64)>,
    /// Conveyor velocity (`surface_vel`).
    pub surface_vel: Option<V3>,
    /// The mover has made a step: node velocities are set. Before that
    /// (the setup right after `fix move/mesh`) LIGGGHTS sees a resting mesh.
    pub moving: bool,
    /// Counts the changes of the triangles ([`SurfaceMesh::bake`]): a cache
    /// of triangles near particles holds for one epoch.
    pub epoch: u64,
    /// What the grains push the mesh with (`fix mesh/surface/stress`).
    pub stress: Option<StressSum>,
}

/// The force and torque that the grains of a group put on a mesh, summed
/// by its walls' contacts (LIGGGHTS `fix mesh/surface/stress`: each contact
/// adds the opposite of its force on the grain, and that force's moment
/// about the reference point, taken at the contact point).
#[derive(Clone, Debug, Default)]
pub struct StressSum {
    /// Group bit of the grains that count.
    pub group: u32,
    /// Reference point of the torque, at the mesh's reference position (it
    /// moves with the mesh).
    pub p_ref: V3,
    /// Force on the mesh.
    pub force: V3,
    /// Torque on the mesh about the reference point.
    pub torque: V3,
    /// The push on each triangle, kept only when a `dump mesh/vtk` reads
    /// the mesh's stresses.
    pub per_tri: Option<TriStress>,
    /// Finnie's wear of each triangle (`wear finnie`).
    pub wear: Option<Wear>,
}

/// Finnie's wear of each triangle of a mesh (LIGGGHTS `fix
/// mesh/surface/stress ... wear finnie`): each contact of a grain of the
/// fix's group adds [`finnie_increment`] to its triangle's sum of the step,
/// which the engine adds to the triangle's wear at the step's
/// final_integrate. The sum of a run's setup is cleared at the first step
/// without being added. demx adds a step's sum when the next step clears
/// it, and reads the wear as the total plus the sum of a finished step.
#[derive(Clone, Debug, Default)]
pub struct Wear {
    /// Group bit of the grains that wear the mesh.
    pub group: u32,
    /// `k_finnie` of the mesh's type against each atom type (index type - 1).
    pub k: Vec<f64>,
    /// This step's wear of each triangle.
    pub step: Vec<f64>,
    /// Wear of each triangle up to the last cleared step.
    pub total: Vec<f64>,
    /// `step` holds a finished step's wear (not a setup's).
    pub live: bool,
}

impl Wear {
    /// No wear yet on `n` triangles.
    pub fn new(group: u32, k: Vec<f64>, n: usize) -> Wear {
        Wear { group, k, step: vec![0.0; n], total: vec![0.0; n], live: false }
    }

    /// Each triangle's wear as the engine holds it after the step.
    pub fn current(&self) -> Vec<f64> {
        if self.live {
            self.total.iter().zip(&self.step).map(|(t, s)| t + s).collect()
        } else {
            self.total.clone()
        }
    }

    /// Start a step's (or a setup's) sums: a finished step's go into the
    /// totals, a setup's are dropped.
    pub fn clear(&mut self) {
        if self.live {
            for (t, s) in self.total.iter_mut().zip(&self.step) {
                *t += s;
            }
        }
        self.step.fill(0.0);
        self.live = false;
    }
}

/// Finnie's wear of one contact in one step, per unit area (LIGGGHTS
/// `MeshModuleStress::add_particle_contribution`, after Finnie 1960): with
/// γ the angle between the grain's velocity relative to the wall `v_rel`
/// and the face (unit normal `n`), E = sin 2γ - 3 sin²γ where tan γ <= 1/3
/// and cos²γ/3 (0.33333 in the engine) above, times 2 k |v_rel| |F| dt /
/// area. Zero while the grain moves away from its contact point (`c`, from
/// its centre) or below a relative speed of 1e-7.
#[allow(clippy::too_many_arguments)]
pub fn finnie_increment(c: V3, v_rel: V3, n: V3, k: f64, force: f64, dt: f64, area: f64) -> f64 {
    if c.dot(&v_rel) < 0.0 {
        return 0.0;
    }
    let speed = v_rel.norm();
    if speed < 1e-7 {
        return 0.0;
    }
    let sin_g = (v_rel.dot(&n).abs() / speed).min(1.0);
    let cos_g = (v_rel.cross(&n).norm() / speed).min(1.0);
    let e = if cos_g < 1e-4 || 3.0 * sin_g > cos_g { 0.33333 * cos_g * cos_g } else { 2.0 * sin_g * cos_g - 3.0 * sin_g * sin_g };
    e * (2.0 * k * speed * force) * dt / area
}

/// The push of the grains on each triangle of a mesh (LIGGGHTS's element
/// properties `f`, `sigma_n` and `sigma_t` of mesh/surface/stress).
///
/// The engine clears `f` at a run's setup and at every step's head, adds
/// each contact's push during the wall forces, and derives the stresses
/// from `f` at the step's final_integrate alone: a dump at a run's setup
/// shows the setup's `f` beside the stresses of the step before. demx
/// derives them when they are read, from `f` while `live`, and keeps them
/// in `sigma` when a setup clears `f`.
#[derive(Clone, Debug, Default)]
pub struct TriStress {
    /// Force of the grains of the fix's group on each triangle.
    pub f: Vec<V3>,
    /// Normal and shear stress of each triangle when not `live`.
    pub sigma: Vec<[f64; 2]>,
    /// The stresses are those of `f` (a step's walls have added to it).
    pub live: bool,
}

impl TriStress {
    /// Zeroed sums for `n` triangles.
    pub fn new(n: usize) -> TriStress {
        TriStress { f: vec![V3::zeros(); n], sigma: vec![[0.0; 2]; n], live: false }
    }
}

/// Normal and shear stress of a triangle pushed by `f`, with unit normal
/// `n` and area `a`: |f.n|/a and |f - (f.n) n|/a (LIGGGHTS
/// `MeshModuleStress::calc_total_force`; absolute values since a mesh's
/// normal may point either way).
pub fn stresses(f: V3, n: V3, a: f64) -> [f64; 2] {
    let fn_ = f.dot(&n);
    let ft = f - n * fn_;
    let inv = 1.0 / a;
    [fn_.abs() * inv, ft.norm() * inv]
}

fn bits(v: V3) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

impl SurfaceMesh {
    /// Build the mesh and its topology. Nodes are identical when their
    /// coordinates are within `precision` (LIGGGHTS default 1e-8).
    pub fn new(id: &str, wall_type: u32, tris: Vec<Triangle>, curvature_cos: f64, precision: f64) -> SurfaceMesh {
        let n = tris.len();
        // node ids by merging coordinates within precision (snap to a grid, then compare neighbours)
        let mut nodes: Vec<V3> = Vec::new();
        let mut map: std::collections::HashMap<[i64; 3], Vec<usize>> = std::collections::HashMap::new();
        let q = if precision > 0.0 { precision } else { 1e-300 };
        let mut node_of = vec![[0usize; 3]; n];
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let p = tri.v[k];
                let key = [0, 1, 2].map(|d| (p[d] / q).floor() as i64);
                let mut found = None;
                'search: for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            if let Some(list) = map.get(&[key[0] + dx, key[1] + dy, key[2] + dz]) {
                                for &j in list {
                                    let d = nodes[j] - p;
                                    if d.abs().max() <= precision || bits(nodes[j]) == bits(p) {
                                        found = Some(j);
                                        break 'search;
                                    }
                                }
                            }
                        }
                    }
                }
                let j = found.unwrap_or_else(|| {
                    nodes.push(p);
                    map.entry(key).or_default().push(nodes.len() - 1);
                    nodes.len() - 1
                });
                node_of[t][k] = j;
            }
        }
        let mut edge_active = vec![[true; 3]; n];
        let mut edge_neigh: Vec<Vec<usize>> = vec![Vec::new(); n];
        let coplanar_pair = |a: usize, b: usize| tris[a].n.dot(&tris[b].n).abs() >= curvature_cos;
        // shared edges
        let mut edges: std::collections::HashMap<(usize, usize), Vec<(usize, usize)>> = std::collections::HashMap::new();
        for t in 0..n {
            for e in 0..3 {
                let (a, b) = (node_of[t][e], node_of[t][(e + 1) % 3]);
                edges.entry((a.min(b), a.max(b))).or_default().push((t, e));
            }
        }
        let mut keys: Vec<_> = edges.keys().copied().collect();
        keys.sort_unstable();
        for k in keys {
            let list = &edges[&k];
            for x in 0..list.len() {
                for y in x + 1..list.len() {
                    let ((i, ie), (j, je)) = (list[x], list[y]);
                    edge_neigh[i].push(j);
                    edge_neigh[j].push(i);
                    let overlap = {
                        // coplanar triangles on the same side of the shared edge overlap
                        let p0 = tris[i].v[ie];
                        let en = tris[i].e[ie].cross(&tris[i].n);
                        let a = (tris[i].v[(ie + 2) % 3] - p0).dot(&en);
                        let b = (tris[j].v[(je + 2) % 3] - p0).dot(&en);
                        a * b > 0.0
                    };
                    if !coplanar_pair(i, j) || overlap {
                        let (lo, hi) = if i < j { ((i, ie), (j, je)) } else { ((j, je), (i, ie)) };
                        edge_active[lo.0][lo.1] = false;
                        edge_active[hi.0][hi.1] = true;
                    } else {
                        edge_active[i][ie] = false;
                        edge_active[j][je] = false;
                    }
                }
            }
        }
        // triangles by node
        let mut by_node: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
        for t in 0..n {
            for k in 0..3 {
                by_node[node_of[t][k]].push(t);
            }
        }
        // corners: walk edge neighbours holding the node
        let mut corner_active = vec![[false; 3]; n];
        for t in 0..n {
            for k in 0..3 {
                let node = node_of[t][k];
                let mut seen = vec![t];
                let mut stack = vec![t];
                let mut holders = Vec::new();
                while let Some(s) = stack.pop() {
                    if !node_of[s].contains(&node) {
                        continue;
                    }
                    holders.push(s);
                    for &nb in &edge_neigh[s] {
                        if !seen.contains(&nb) {
                            seen.push(nb);
                            stack.push(nb);
                        }
                    }
                }
                let mut dirs: Vec<(V3, usize)> = Vec::new();
                let mut any_active = false;
                for &s in &holders {
                    let kk = node_of[s].iter().position(|&x| x == node).unwrap_or(0);
                    let prev = (kk + 2) % 3;
                    dirs.push((tris[s].e[kk].normalize(), node_of[s][(kk + 1) % 3]));
                    dirs.push((tris[s].e[prev].normalize(), node_of[s][prev]));
                    any_active |= edge_active[s][kk] || edge_active[s][prev];
                }
                let mut colinear = false;
                for a in 0..dirs.len() {
                    for b in a + 1..dirs.len() {
                        if dirs[a].0.dot(&dirs[b].0).abs() > curvature_cos && dirs[a].1 != dirs[b].1 {
                            colinear = true;
                        }
                    }
                }
                let max_id = holders.iter().copied().max().unwrap_or(t);
                corner_active[t][k] = !colinear && any_active && max_id == t;
            }
        }
        // coplanar neighbours sharing an edge or a node
        let nneighs = edge_neigh.iter().map(|e| e.len() as u32).collect();
        let mut coplanar = vec![Vec::new(); n];
        for t in 0..n {
            let mut c: Vec<u32> = Vec::new();
            for k in 0..3 {
                for &s in &by_node[node_of[t][k]] {
                    if s != t && tris[t].n.dot(&tris[s].n).abs() > curvature_cos {
                        c.push(s as u32);
                    }
                }
            }
            c.sort_unstable();
            c.dedup();
            coplanar[t] = c;
        }
        let mesh = Mesh::new(tris.clone());
        let cell = if n == 0 {
            1.0
        } else {
            tris.iter()
                .map(|t| {
                    let (a, b) = t.bounds();
                    (b - a).max()
                })
                .sum::<f64>()
                / n as f64
        };
        let bins = TriangleBins::new(&mesh, cell);
        SurfaceMesh {
            id: id.to_string(),
            wall_type,
            tris,
            bins,
            edge_active,
            corner_active,
            coplanar,
            nneighs,
            curvature_cos,
            motion: None,
            surface_vel: None,
            moving: false,
            epoch: 0,
            stress: None,
        }
    }

    /// Whether all triangles lie in one plane within the curvature
    /// tolerance (`mesh/surface/planar`).
    pub fn is_planar(&self) -> bool {
        let Some(t0) = self.tris.first() else { return true };
        self.tris.iter().all(|t| t.n.dot(&t0.n).abs() >= self.curvature_cos && t0.n.dot(&(t.v[0] - t0.v[0])).abs() <= 1e-8 * (1.0 + t.v[0].norm()))
    }

    /// Whether triangles a and b are coplanar neighbours.
    pub fn are_coplanar(&self, a: usize, b: usize) -> bool {
        self.coplanar.get(a).map(|c| c.binary_search(&(b as u32)).is_ok()).unwrap_or(false)
    }

    /// The mesh's placement at `time`, its trigonometry done once: the
    /// functions below are its methods for one point.
    pub fn pose(&self, time: f64) -> Pose {
        let motion = match self.motion {
            None => PoseMotion::Rest,
            Some((MeshMotion::Linear(v), t0)) => PoseMotion::Linear { shift: v * (time - t0), v },
            Some((MeshMotion::Rotate { origin, axis, period }, t0)) => {
                // the angle of `MeshMotion::position`; back is its exact negative
                let angle = 2.0 * std::f64::consts::PI * (time - t0) / period;
                PoseMotion::Rotate {
                    origin,
                    axis,
                    fwd: angle.sin_cos(),
                    back: (-angle).sin_cos(),
                    omega: axis * (2.0 * std::f64::consts::PI / period),
                }
            }
        };
        Pose { motion, moving: self.moving, surface_vel: self.surface_vel }
    }

    /// The largest distance of a vertex from the axis of the mesh's
    /// rotation (0 for other motions).
    pub fn axis_reach(&self) -> f64 {
        match self.motion {
            Some((MeshMotion::Rotate { origin, axis, .. }, _)) => self
                .tris
                .iter()
                .flat_map(|t| t.v)
                .map(|p| {
                    let d = p - origin;
                    (d - axis * axis.dot(&d)).norm()
                })
                .fold(0.0f64, f64::max),
            _ => 0.0,
        }
    }

    /// An upper bound on how far a world point at most `rho` from the axis
    /// of rotation moves in the mesh's frame from time `t0` to `t1` (its
    /// rigid motion over that time, whenever it started: the bound holds
    /// for a motion added since `t0`). A rotation moves such a point by at
    /// most rho times the angle.
    pub fn drift(&self, t0: f64, t1: f64, rho: f64) -> f64 {
        let dt = (t1 - t0).abs();
        match self.motion {
            None => 0.0,
            Some((MeshMotion::Linear(v), _)) => v.norm() * dt * (1.0 + 1e-9),
            // a little over, for the rounding of the bound itself
            Some((MeshMotion::Rotate { period, .. }, _)) => rho * (2.0 * std::f64::consts::PI * dt / period.abs()) * (1.0 + 1e-9),
        }
    }

    /// World point -> reference frame at `time`.
    pub fn to_reference(&self, p: V3, time: f64) -> V3 {
        self.pose(time).to_reference(p)
    }

    /// Reference point -> world at `time`.
    pub fn to_world(&self, p: V3, time: f64) -> V3 {
        self.pose(time).to_world(p)
    }

    /// Reference direction -> world at `time`.
    pub fn dir_to_world(&self, d: V3, time: f64) -> V3 {
        self.pose(time).dir_to_world(d)
    }

    /// Velocity of the wall at world point `p` on triangle `tri` (see
    /// [`Pose::wall_velocity`]).
    pub fn wall_velocity(&self, p: V3, tri: usize, time: f64) -> V3 {
        self.pose(time).wall_velocity(p, self.tris[tri].n)
    }

    /// Normal and shear stress of each triangle at `time` (None unless a
    /// `dump mesh/vtk` keeps the pushes per triangle).
    pub fn tri_stresses(&self, time: f64) -> Option<Vec<[f64; 2]>> {
        let ts = self.stress.as_ref()?.per_tri.as_ref()?;
        if !ts.live {
            return Some(ts.sigma.clone());
        }
        Some(self.tris.iter().zip(&ts.f).map(|(t, &f)| stresses(f, self.dir_to_world(t.n, time), t.area())).collect())
    }

    /// Clear the pushes (and the wear sums) per triangle: at each step's
    /// head, and at a run's setup (`setup`), which keeps the last step's
    /// stresses.
    pub fn clear_tri_push(&mut self, time: f64, setup: bool) {
        if setup {
            if let Some(sigma) = self.tri_stresses(time) {
                if let Some(ts) = self.stress.as_mut().and_then(|s| s.per_tri.as_mut()) {
                    (ts.sigma, ts.live) = (sigma, false);
                }
            }
        }
        if let Some(ts) = self.stress.as_mut().and_then(|s| s.per_tri.as_mut()) {
            ts.f.fill(V3::zeros());
        }
        if let Some(w) = self.stress.as_mut().and_then(|s| s.wear.as_mut()) {
            w.clear();
        }
    }

    /// Velocity of each triangle's nodes at `time` (None for a mesh that
    /// neither moves nor has a surface velocity: LIGGGHTS gives such a mesh
    /// no `v` property). At a run's `setup` a moved mesh shows zeros: the
    /// engine's move/mesh clears them after the setup's wall forces and
    /// sets them again at the first step. Zeros are +0, as the engine's
    /// sums give them.
    pub fn node_velocities(&self, time: f64, setup: bool) -> Option<Vec<[V3; 3]>> {
        if self.motion.is_none() && self.surface_vel.is_none() {
            return None;
        }
        if setup && self.motion.is_some() {
            return Some(vec![[V3::zeros(); 3]; self.tris.len()]);
        }
        Some((0..self.tris.len()).map(|t| self.tris[t].v.map(|p| self.wall_velocity(self.to_world(p, time), t, time) + V3::zeros())).collect())
    }

    /// Triangles at `time` as plain arrays (for `dump mesh/stl`).
    pub fn current_triangles(&self, time: f64) -> Vec<[[f64; 3]; 3]> {
        self.tris
            .iter()
            .map(|t| {
                t.v.map(|p| {
                    let w = self.to_world(p, time);
                    [w.x, w.y, w.z]
                })
            })
            .collect()
    }

    /// Freeze the motion at `time`: the current position becomes the reference.
    pub fn bake(&mut self, time: f64) {
        if self.motion.is_none() {
            return;
        }
        let tris: Vec<Triangle> = self
            .tris
            .iter()
            .map(|t| {
                let v = t.v.map(|p| self.to_world(p, time));
                Triangle::new(v[0], v[1], v[2])
            })
            .collect();
        self.tris = tris;
        let cell = self.bins_cell();
        self.bins = TriangleBins::new(&Mesh::new(self.tris.clone()), cell);
        self.motion = None;
        self.moving = false;
        self.epoch += 1;
    }

    fn bins_cell(&self) -> f64 {
        let n = self.tris.len().max(1) as f64;
        self.tris
            .iter()
            .map(|t| {
                let (a, b) = t.bounds();
                (b - a).max()
            })
            .sum::<f64>()
            / n
    }

    /// The triangles (increasing) closer than `reach` to point `p`
    /// (reference frame): every triangle that a sphere centred within
    /// `reach - r` of `p` can touch with radius `r`.
    pub fn near(&self, p: V3, reach: f64) -> impl Iterator<Item = usize> + '_ {
        self.bins
            .candidates(p, reach)
            .into_iter()
            .filter(move |&t| (p - closest_point_on_triangle(p, &self.tris[t]).0).norm_squared() < reach * reach)
    }

    /// Contact of a sphere (reference frame) with triangle `t` under the
    /// LIGGGHTS feature rules: `(overlap, unit normal into the sphere,
    /// closest point)`, None without overlap or on an inactive feature.
    pub fn triangle_contact(&self, t: usize, p: V3, radius: f64) -> Option<(f64, V3, V3)> {
        let tri = &self.tris[t];
        let [a, b, c] = tri.v;
        let n = tri.n;
        let dn = n.dot(&(p - a));
        let q = p - n * dn;
        // barycentric coordinates of the projection
        let (v0, v1, v2) = (b - a, c - a, q - a);
        let d00 = v0.dot(&v0);
        let d01 = v0.dot(&v1);
        let d11 = v1.dot(&v1);
        let d20 = v2.dot(&v0);
        let d21 = v2.dot(&v1);
        let den = d00 * d11 - d01 * d01;
        let face = if den > 0.0 {
            let l1 = (d11 * d20 - d01 * d21) / den;
            let l2 = (d00 * d21 - d01 * d20) / den;
            let l0 = 1.0 - l1 - l2;
            l0 > -SMALL_TRIMESH && l1 > -SMALL_TRIMESH && l2 > -SMALL_TRIMESH
        } else {
            false
        };
        let point = if face {
            q
        } else {
            let (cp, kind) = closest_point_on_triangle(p, tri);
            let ok = match kind {
                ContactKind::Face => true,
                ContactKind::Edge(e) => self.edge_active[t][e as usize],
                ContactKind::Vertex(k) => self.corner_active[t][k as usize],
            };
            if !ok {
                return None;
            }
            cp
        };
        let d = (p - point).norm();
        if d >= radius {
            return None;
        }
        let normal = if d > 0.0 { (p - point) / d } else { n };
        Some((radius - d, normal, point))
    }
}

/// Where a mesh is at one time ([`SurfaceMesh::pose`]): its rigid motion
/// evaluated once, with the sines and cosines of a rotation, so that a
/// step's many points pay no trigonometry. Each method gives the bits of
/// the motion's own formula (`MeshMotion::position`, `velocity`).
#[derive(Clone, Copy, Debug)]
pub struct Pose {
    motion: PoseMotion,
    moving: bool,
    surface_vel: Option<V3>,
}

#[derive(Clone, Copy, Debug)]
enum PoseMotion {
    Rest,
    Linear { shift: V3, v: V3 },
    Rotate { origin: V3, axis: V3, fwd: (f64, f64), back: (f64, f64), omega: V3 },
}

impl Pose {
    /// World point -> reference frame.
    pub fn to_reference(&self, p: V3) -> V3 {
        match self.motion {
            PoseMotion::Rest => p,
            PoseMotion::Linear { shift, .. } => p - shift,
            PoseMotion::Rotate { origin, axis, back: (s, c), .. } => origin + rotate_sc(p - origin, axis, s, c),
        }
    }

    /// Reference point -> world.
    pub fn to_world(&self, p: V3) -> V3 {
        match self.motion {
            PoseMotion::Rest => p,
            PoseMotion::Linear { shift, .. } => p + shift,
            PoseMotion::Rotate { origin, axis, fwd: (s, c), .. } => origin + rotate_sc(p - origin, axis, s, c),
        }
    }

    /// Reference direction -> world.
    pub fn dir_to_world(&self, d: V3) -> V3 {
        match self.motion {
            PoseMotion::Rotate { axis, fwd: (s, c), .. } => rotate_sc(d, axis, s, c),
            _ => d,
        }
    }

    /// Velocity of the wall at world point `p` on a triangle of reference
    /// normal `n`: the rigid motion's (once the mover has made a step) plus
    /// the conveyor velocity projected into the face, keeping its magnitude.
    pub fn wall_velocity(&self, p: V3, n: V3) -> V3 {
        let mut v = match self.motion {
            PoseMotion::Linear { v, .. } if self.moving => v,
            PoseMotion::Rotate { origin, omega, .. } if self.moving => omega.cross(&(p - origin)),
            _ => V3::zeros(),
        };
        if let Some(sv) = self.surface_vel {
            let n = self.dir_to_world(n);
            let vt = sv - n * n.dot(&sv);
            let l = vt.norm();
            if l > 0.0 {
                v += vt * (sv.norm() / l);
            }
        }
        v
    }
}

/// One particle's contact slots for one mesh wall: `MESH_SLOTS` records of
/// `[triangle id + 1 (0 = empty), history...]`.
pub struct Slots<'a> {
    /// The particle's slot data, `MESH_SLOTS * (1 + width)` values.
    pub data: &'a mut [f64],
    /// History width of the contact laws.
    pub width: usize,
}

/// A contact found by [`resolve_particle`], in the reference frame.
#[derive(Clone, Copy, Debug)]
pub struct MeshHit {
    /// Triangle index.
    pub tri: usize,
    /// Overlap.
    pub delta: f64,
    /// Unit normal from the wall into the particle (reference frame).
    pub normal: V3,
    /// Closest point (reference frame).
    pub point: V3,
}

/// Resolve all contacts of one particle (centre `p` in the mesh's
/// reference frame) with the mesh, maintaining its slots with the
/// LIGGGHTS duplicate rule; `apply(hit, history)` is called for every
/// contact that produces a force, in increasing triangle order. Returns
/// how many slots hold a contact afterwards.
pub fn resolve_particle(mesh: &SurfaceMesh, p: V3, radius: f64, slots: Slots, apply: impl FnMut(&MeshHit, &mut [f64])) -> Result<usize> {
    resolve_among(mesh, mesh.bins.candidates(p, radius), p, radius, slots, apply)
}

/// [`resolve_particle`] over the triangles `cands` (increasing), which
/// must include every triangle within `radius` of `p` (the others find no
/// contact and change nothing).
pub fn resolve_among(
    mesh: &SurfaceMesh,
    cands: impl IntoIterator<Item = usize>,
    p: V3,
    radius: f64,
    slots: Slots,
    mut apply: impl FnMut(&MeshHit, &mut [f64]),
) -> Result<usize> {
    let w = 1 + slots.width;
    let data = slots.data;
    let mut touched = [false; MESH_SLOTS];
    for t in cands {
        let Some((delta, normal, point)) = mesh.triangle_contact(t, p, radius) else { continue };
        let idv = (t + 1) as f64;
        let slot_id = |k: usize| data[k * w];
        let k = match (0..MESH_SLOTS).find(|&k| slot_id(k) == idv) {
            Some(k) => k,
            None => {
                let dup = (0..MESH_SLOTS).any(|k| {
                    let s = slot_id(k);
                    touched[k] && s > 0.0 && s != idv && mesh.are_coplanar(s as usize - 1, t)
                });
                if dup {
                    continue;
                }
                let Some(k) = (0..MESH_SLOTS).find(|&k| slot_id(k) == 0.0) else {
                    return Err(Error::runtime(format!("mesh wall '{}': a particle touches more than {MESH_SLOTS} triangles at once", mesh.id)));
                };
                data[k * w] = idv;
                data[k * w + 1..(k + 1) * w].fill(0.0);
                for k2 in 0..MESH_SLOTS {
                    let s = data[k2 * w];
                    if k2 != k && s > 0.0 && mesh.are_coplanar(s as usize - 1, t) {
                        let (src, dst) = (k2 * w + 1, k * w + 1);
                        for j in 0..slots.width {
                            data[dst + j] = data[src + j];
                        }
                    }
                }
                k
            }
        };
        touched[k] = true;
        apply(&MeshHit { tri: t, delta, normal, point }, &mut data[k * w + 1..(k + 1) * w]);
    }
    for k in 0..MESH_SLOTS {
        if !touched[k] && data[k * w] != 0.0 {
            data[k * w..(k + 1) * w].fill(0.0);
        }
    }
    Ok(touched.iter().filter(|&&t| t).count())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64) -> Vec<Triangle> {
        let (a, b, c, d) = (V3::new(-1.0, -1.0, z), V3::new(1.0, -1.0, z), V3::new(1.0, 1.0, z), V3::new(-1.0, 1.0, z));
        vec![Triangle::new(a, b, c), Triangle::new(a, c, d)]
    }

    #[test]
    fn coplanar_shared_edge_is_inactive_and_boundary_edges_active() {
        let m = SurfaceMesh::new("m", 1, square(0.0), DEFAULT_CURVATURE_COS, 1e-8);
        // triangle 0 edges: a-b (boundary), b-c (boundary), c-a (diagonal, shared)
        assert_eq!(m.edge_active[0], [true, true, false]);
        // triangle 1 edges: a-c (shared), c-d, d-a
        assert_eq!(m.edge_active[1], [false, true, true]);
        assert!(m.are_coplanar(0, 1) && m.are_coplanar(1, 0));
        // corners a and c are shared: active only on triangle 1 (higher id)
        assert_eq!(m.corner_active[0], [false, true, false]);
        assert_eq!(m.corner_active[1], [true, true, true]);
    }

    #[test]
    fn folded_edge_is_active_on_higher_id_only() {
        let (a, b) = (V3::new(0.0, 0.0, 0.0), V3::new(0.0, 1.0, 0.0));
        let t0 = Triangle::new(a, b, V3::new(-1.0, 0.5, 0.0));
        let t1 = Triangle::new(b, a, V3::new(1.0, 0.5, 1.0));
        let m = SurfaceMesh::new("m", 1, vec![t0, t1], DEFAULT_CURVATURE_COS, 1e-8);
        assert!(!m.edge_active[0][0]);
        assert!(m.edge_active[1][0]);
        assert!(!m.are_coplanar(0, 1));
    }

    #[test]
    fn sphere_over_shared_edge_gets_one_contact_with_the_plane_overlap() {
        let m = SurfaceMesh::new("m", 1, square(0.0), DEFAULT_CURVATURE_COS, 1e-8);
        // centre exactly above the diagonal
        let p = V3::new(0.3, 0.3, 0.09);
        let mut data = vec![0.0; MESH_SLOTS * 2];
        let mut hits = Vec::new();
        resolve_particle(&m, p, 0.1, Slots { data: &mut data, width: 1 }, |h, _| hits.push(*h)).unwrap();
        assert_eq!(hits.len(), 1);
        assert!((hits[0].delta - 0.01).abs() < 1e-15);
        assert!((hits[0].normal - V3::new(0.0, 0.0, 1.0)).norm() < 1e-15);
    }
}
