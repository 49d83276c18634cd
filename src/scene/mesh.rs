//! Triangle-mesh walls and region walls: `fix mesh/surface`,
//! `mesh/surface/planar`, `move/mesh`, LIGGGHTS `wall/gran ... mesh`, LAMMPS
//! `wall/gran/region`, and `dump mesh/stl`.
//!
//! A mesh lives in its `fix mesh/surface` (the registry is the fix list: see
//! [`find_mesh`]); walls, movers and dumps hold a [`SharedMesh`] to it. Mesh
//! walls apply the scene's contact laws through `ContactKernel::contact`
//! like the primitive walls of `scene/walls.rs`, with the LIGGGHTS
//! edge/corner activity and duplicate-contact rules of
//! `engine/mesh_surface.rs`.

use super::args::{self, Args};
use super::model::{self, NormalSpec, PairSpec, TangentialSpec};
use super::Session;
use crate::engine::fix::{Fix, Hook, Local};
use crate::engine::integrate::CHUNK;
use crate::engine::kernel::{ContactKernel, ParamTable};
use crate::engine::mesh_surface::{
    finnie_increment, resolve_among, resolve_particle, MeshHit, Pose, SharedMesh, Slots, StressSum, SurfaceMesh, TriStress, Wear,
    DEFAULT_CURVATURE_COS, MESH_SLOTS,
};
use crate::engine::output::Dump;
use crate::engine::sim::{Dialect, Sim};
use crate::error::{Error, Result};
use crate::geom::mesh::parse_mesh_transforms;
use crate::geom::{MeshMotion, Region, Triangle};
use crate::io::vtk::{MeshArray, MeshVtkOutput, VtkType};
use crate::physics::{Contact, V3};
use crate::script::{Command, Variables, Word};
use rayon::prelude::*;
use std::sync::{Arc, RwLock};

/// Parse a mesh- or region-wall fix.
pub fn fix(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args, vars: &mut Variables) -> Result<()> {
    let _ = vars;
    match style.text.as_str() {
        "mesh/surface" | "mesh/surface/planar" | "mesh/surface/stress" => mesh_surface(s, cmd, id, group, style, a),
        "wall/gran" => wall_gran_mesh(s, cmd, id, group, a),
        "move/mesh" => move_mesh(s, cmd, id, a),
        "wall/gran/region" => wall_gran_region(s, cmd, id, group, a),
        _ => Err(Error::unsupported(style.span, format!("fix {}", style.text))),
    }
}

fn lock_err() -> Error {
    Error::runtime("mesh state poisoned by an earlier failure")
}

// ---------------------------------------------------------------- registry

/// The fix holding a mesh (`fix mesh/surface`, `mesh/surface/stress`).
pub struct MeshSurfaceFix {
    id: String,
    style: String,
    /// The mesh.
    pub mesh: SharedMesh,
    summary: String,
}

impl MeshSurfaceFix {
    fn stressed(&self) -> bool {
        self.mesh.read().is_ok_and(|m| m.stress.is_some())
    }
}

impl Fix for MeshSurfaceFix {
    /// mesh/surface/stress clears its sums at the head of each step (the
    /// engine's pre_force; not at a run's setup, so a run's first line
    /// adds the setup's contacts to the last step's sums, as the engine's).
    fn local(&mut self, hook: Hook, _sim: &Sim, _vars: &Variables) -> Result<Local> {
        Ok(if hook == Hook::InitialIntegrate && self.stressed() { Local::Whole } else { Local::Nothing })
    }
    fn initial_integrate(&mut self, sim: &mut Sim) {
        if let Ok(mut m) = self.mesh.write() {
            if let Some(st) = m.stress.as_mut() {
                (st.force, st.torque) = (V3::zeros(), V3::zeros());
            }
            m.clear_tri_push(sim.time, false);
        }
    }
    /// The pushes per triangle (kept for `dump mesh/vtk`) are cleared at a
    /// run's setup too (the engine's `FixMesh::setup_pre_force`).
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        self.mesh.write().map_err(|_| lock_err())?.clear_tri_push(sim.time, true);
        Ok(())
    }
    /// `f_ID[1..9]` of mesh/surface/stress: the force on the mesh, its
    /// torque about the reference point, and that point (where the mesh
    /// has carried it).
    fn vector(&self, sim: &Sim, i: usize) -> Option<f64> {
        let m = self.mesh.read().ok()?;
        let st = m.stress.as_ref()?;
        let v = match i {
            1..=3 => st.force,
            4..=6 => st.torque,
            7..=9 => m.to_world(st.p_ref, sim.time),
            _ => return None,
        };
        Some(v[(i - 1) % 3])
    }
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        &self.style
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

/// The mesh of `fix mesh/surface` with id `id`, if defined.
pub fn find_mesh(s: &Session, id: &str) -> Option<SharedMesh> {
    s.sim.fixes.iter().filter(|f| f.id() == id).find_map(|f| f.as_any().and_then(|a| a.downcast_ref::<MeshSurfaceFix>()).map(|m| m.mesh.clone()))
}

pub(crate) fn need_mesh(s: &Session, w: &Word) -> Result<SharedMesh> {
    find_mesh(s, &w.text).ok_or_else(|| {
        let ids: Vec<&str> = s.sim.fixes.iter().filter(|f| f.style().starts_with("mesh/surface")).map(|f| f.id()).collect();
        let mut e = Error::deck(w.span, format!("fix mesh/surface '{}' does not exist", w.text));
        if let Some(h) = crate::error::did_you_mean(&w.text, ids) {
            e = e.with_hint(format!("did you mean '{h}'?"));
        }
        e
    })
}

// ---------------------------------------------------------- mesh/surface

fn mesh_surface(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    s.set_dialect(Dialect::Liggghts);
    let mut file: Option<&Word> = None;
    let mut wall_type: Option<u32> = None;
    let mut heal = false;
    let mut precision = 1e-8;
    let mut curvature_cos = DEFAULT_CURVATURE_COS;
    let mut tolerant = false;
    let mut surface_vel = None;
    let mut transforms = Vec::new();
    // mesh/surface/stress sums the grains' push unless `stress off`
    let mut stress = style.text == "mesh/surface/stress";
    let mut wear: Option<&Word> = None;
    let mut p_ref = V3::zeros();
    let words = a.rest();
    let mut i = 0;
    let num = |i: usize, what: &str| -> Result<f64> {
        let w = words.get(i).ok_or_else(|| Error::deck(a.end_span(), format!("fix {}: missing {what}", style.text)))?;
        args::parse_f64(w)
    };
    let word = |i: usize, what: &str| -> Result<&Word> {
        words.get(i).ok_or_else(|| Error::deck(a.end_span(), format!("fix {}: missing {what}", style.text)))
    };
    while i < words.len() {
        let k = &words[i];
        match k.text.as_str() {
            "file" => {
                file = Some(word(i + 1, "file name")?);
                i += 2;
            }
            "type" => {
                let w = word(i + 1, "wall type")?;
                let t = args::parse_i64(w)?;
                if t < 1 || t as usize > s.sim.ntypes {
                    return Err(Error::deck(w.span, format!("wall type {t} out of range 1..{}", s.sim.ntypes)));
                }
                wall_type = Some(t as u32);
                i += 2;
            }
            "verbose" | "curvature_tolerant" => {
                let w = word(i + 1, "yes or no")?;
                let v = match w.text.as_str() {
                    "yes" => true,
                    "no" => false,
                    _ => return Err(args::bad_keyword(w, "value", &["yes", "no"])),
                };
                if k.text == "curvature_tolerant" {
                    tolerant = v;
                }
                i += 2;
            }
            "heal" => {
                let w = word(i + 1, "heal mode")?;
                heal = match w.text.as_str() {
                    "auto_remove_duplicates" => true,
                    "no" => false,
                    _ => return Err(args::bad_keyword(w, "heal mode", &["auto_remove_duplicates", "no"])),
                };
                i += 2;
            }
            "precision" => {
                precision = num(i + 1, "precision")?;
                if precision <= 0.0 {
                    return Err(Error::deck(words[i + 1].span, "precision must be > 0"));
                }
                i += 2;
            }
            "curvature" => {
                let c = num(i + 1, "curvature angle (degrees)")?;
                if !(0.0..=60.0).contains(&c) {
                    return Err(Error::deck(words[i + 1].span, "curvature must be between 0 and 60 degrees"));
                }
                curvature_cos = (c * std::f64::consts::PI / 180.0).cos();
                i += 2;
            }
            "temperature" | "mass_temperature" => {
                num(i + 1, &k.text)?;
                s.notes.push((k.span, format!("fix {}: `{}` accepted; demx conducts no heat between walls and grains", style.text, k.text)));
                i += 2;
            }
            "stress" | "reference_point" | "wear" if style.text != "mesh/surface/stress" => {
                return Err(Error::deck(k.span, format!("fix {}: `{}` belongs to fix mesh/surface/stress", style.text, k.text)));
            }
            "stress" => {
                let w = word(i + 1, "on or off")?;
                stress = match w.text.as_str() {
                    "on" => true,
                    "off" => false,
                    _ => return Err(args::bad_keyword(w, "stress", &["on", "off"])),
                };
                i += 2;
            }
            "reference_point" => {
                p_ref = V3::new(num(i + 1, "x")?, num(i + 2, "y")?, num(i + 3, "z")?);
                i += 4;
            }
            "wear" => {
                let w = word(i + 1, "finnie or off")?;
                match w.text.as_str() {
                    "off" => {}
                    "finnie" => wear = Some(w),
                    _ => return Err(args::bad_keyword(w, "wear", &["finnie", "off"])),
                }
                i += 2;
            }
            "surface_vel" => {
                surface_vel = Some(V3::new(num(i + 1, "vx")?, num(i + 2, "vy")?, num(i + 3, "vz")?));
                i += 4;
            }
            "move" | "rotate" | "scale" => {
                let n = match k.text.as_str() {
                    "move" => 4,
                    "rotate" => 7,
                    _ => 2,
                };
                let end = (i + n).min(words.len());
                let (t, _) = parse_mesh_transforms(cmd, &words[i..end])?;
                if t.len() != 1 {
                    return Err(Error::deck(k.span, format!("fix {}: malformed {}", style.text, k.text)));
                }
                transforms.extend(t);
                i = end;
            }
            "region" | "element_exclusion_list" | "min_feature_length" | "surface_ang_vel" | "extrude_planar" | "fix" | "reference_frame" => {
                return Err(Error::unsupported(k.span, format!("fix {} keyword {}", style.text, k.text)))
            }
            _ => {
                return Err(args::bad_keyword(
                    k,
                    &format!("fix {} keyword", style.text),
                    &[
                        "file",
                        "type",
                        "scale",
                        "move",
                        "rotate",
                        "curvature",
                        "heal",
                        "verbose",
                        "precision",
                        "surface_vel",
                        "temperature",
                        "stress",
                        "reference_point",
                        "wear",
                    ],
                ))
            }
        }
    }
    a.pos += words.len();
    let file = file.ok_or_else(|| Error::deck(style.span, format!("fix {}: missing `file F`", style.text)))?;
    let wall_type = wall_type.ok_or_else(|| Error::deck(style.span, format!("fix {}: missing `type T`", style.text)))?;
    let raw = crate::geom::read_stl(std::path::Path::new(&file.text), file.span)?;
    let tris = crate::geom::Mesh::new(raw).transformed(&transforms).tris;
    // duplicate elements (same three nodes)
    let mut kept: Vec<Triangle> = Vec::with_capacity(tris.len());
    let key = |t: &Triangle| {
        let mut v: Vec<[i64; 3]> = t.v.iter().map(|p| [0, 1, 2].map(|d| (p[d] / precision).round() as i64)).collect();
        v.sort_unstable();
        v
    };
    let mut seen = std::collections::HashMap::new();
    for (k, t) in tris.iter().enumerate() {
        match seen.get(&key(t)) {
            Some(j) if !heal => {
                return Err(Error::deck(file.span, format!("mesh '{}': elements {j} and {k} are duplicate; bad mesh, cannot continue", file.text))
                    .with_hint("LIGGGHTS: try re-running with 'heal auto_remove_duplicates'"))
            }
            Some(_) => continue,
            None => {
                seen.insert(key(t), k);
                kept.push(*t);
            }
        }
    }
    if !tolerant {
        for (k, t) in kept.iter().enumerate() {
            for c in 0..3 {
                let (e1, e2) = (t.e[c].normalize(), t.e[(c + 2) % 3].normalize());
                if -e1.dot(&e2) > curvature_cos {
                    return Err(Error::deck(file.span, format!("mesh '{}': an angle of element {k} is smaller than the curvature angle", file.text))
                        .with_hint("set 'curvature' lower, or 'curvature_tolerant yes'"));
                }
            }
        }
    }
    let mut mesh = SurfaceMesh::new(id, wall_type, kept, curvature_cos, precision);
    mesh.surface_vel = surface_vel;
    if style.text == "mesh/surface/stress" {
        // `stress off`: no grain counts, the sums stay zero (the engine's
        // f_ID then reads zeros too)
        let n = mesh.tris.len();
        let wear = match wear {
            None => None,
            // k_finnie[mesh type][atom type], a peratomtypepair property
            // stored as [N, v11, v12, ...]
            Some(w) => match s.props.get("k_finnie") {
                Some((_, v)) if v.len() > 1 && v[0] as usize == s.sim.ntypes && (wall_type as usize) <= s.sim.ntypes => {
                    let nt = s.sim.ntypes;
                    let row = 1 + (wall_type as usize - 1) * nt;
                    Some(Wear::new(group, v[row..row + nt].to_vec(), n))
                }
                _ => {
                    return Err(Error::deck(w.span, "fix mesh/surface/stress wear finnie needs the property k_finnie")
                        .with_hint(format!("define it first: fix ID all property/global k_finnie peratomtypepair {} VALUES...", s.sim.ntypes)))
                }
            },
        };
        mesh.stress = Some(StressSum { group: if stress { group } else { 0 }, p_ref, wear, ..Default::default() });
    }
    if style.text == "mesh/surface/planar" && !mesh.is_planar() {
        return Err(Error::deck(file.span, format!("fix mesh/surface/planar: mesh '{}' is not planar", file.text)));
    }
    let summary = format!("mesh/surface {id}: {} triangles from {}, type {wall_type}", mesh.tris.len(), file.text);
    s.add_fix(Box::new(MeshSurfaceFix { id: id.to_string(), style: style.text.clone(), mesh: Arc::new(RwLock::new(mesh)), summary }))
}

// ---------------------------------------------------------------- move/mesh

/// `fix move/mesh`: sets the motion of a mesh; unfixing it freezes the mesh
/// where it is.
pub struct MoveMeshFix {
    id: String,
    mesh: SharedMesh,
    now: f64,
    started: bool,
}

impl Fix for MoveMeshFix {
    fn end_of_step_due(&self, _step: i64) -> bool {
        false
    }
    fn local(&mut self, hook: Hook, _sim: &Sim, _vars: &Variables) -> Result<Local> {
        // the mesh's clock advances in initial_integrate
        Ok(if hook == Hook::InitialIntegrate { Local::Whole } else { Local::Nothing })
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "move/mesh"
    }
    fn initial_integrate(&mut self, sim: &mut Sim) {
        self.now = sim.time;
        if !self.started {
            if let Ok(mut m) = self.mesh.write() {
                m.moving = true;
            }
            self.started = true;
        }
    }
}

impl Drop for MoveMeshFix {
    fn drop(&mut self) {
        if let Ok(mut m) = self.mesh.write() {
            m.bake(self.now);
        }
    }
}

fn move_mesh(s: &mut Session, cmd: &Command, id: &str, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    a.choice("keyword", &["mesh"])?;
    let mw = a.word("mesh id")?;
    let mesh = need_mesh(s, mw)?;
    let words = a.rest();
    let style = words.first().ok_or_else(|| Error::deck(a.end_span(), "fix move/mesh: missing motion style"))?;
    if !["linear", "rotate"].contains(&style.text.as_str()) {
        let known = ["linear/variable", "wiggle", "riggle", "rotate/variable", "viblin", "vibrot", "file"];
        if known.contains(&style.text.as_str()) {
            return Err(Error::unsupported(style.span, format!("fix move/mesh style {}", style.text)));
        }
        return Err(args::bad_keyword(style, "move/mesh style", &["linear", "rotate", "wiggle", "riggle", "viblin", "vibrot"]));
    }
    let motion = MeshMotion::parse(cmd, words)?;
    let used = if style.text == "linear" { 4 } else { 11 };
    if let Some(w) = words.get(used) {
        return Err(Error::deck(w.span, format!("fix move/mesh: unexpected '{}'", w.text)));
    }
    a.pos += words.len();
    {
        let mut m = mesh.write().map_err(|_| lock_err())?;
        if m.motion.is_some() {
            return Err(Error::unsupported(style.span, "superposed fix move/mesh motions on one mesh"));
        }
        m.motion = Some((motion, s.sim.time));
    }
    s.walls.push(format!("move/mesh {id}: mesh {} {:?}", mw.text, motion));
    let now = s.sim.time;
    s.add_fix(Box::new(MoveMeshFix { id: id.to_string(), mesh, now, started: false }))
}

// ---------------------------------------------------------- wall/gran mesh

struct WallMesh {
    mesh: SharedMesh,
    hist_name: String,
    /// Per particle, how many of its slots hold a contact (-1: not known
    /// yet, as for a particle just inserted or read from a restart).
    used_name: String,
    /// Per particle, the triangles within reach + 5/8 skin of its centre
    /// `anchor[i]` (mesh frame) when they were found, at pair-list build
    /// `near_at.0` of mesh epoch `near_at.1` for `near_at.2` particles (CSR:
    /// particle i's are `near[start[i]..start[i + 1]]`, increasing); see
    /// `post_force`.
    near: Vec<u32>,
    start: Vec<u32>,
    anchor: Vec<V3>,
    /// The particles to visit, chunk by chunk (CSR over chunks of `CHUNK`:
    /// chunk c's are `active[active_start[c]..active_start[c + 1]]`).
    active: Vec<u32>,
    active_start: Vec<u32>,
    /// The lists' key: pair-list build, mesh epoch, particle count, and
    /// whether every step checks for a build.
    near_at: Option<(u64, u64, usize, bool)>,
    /// When the lists were found, and how far from the axis of the mesh's
    /// rotation a particle within reach of it can be (for
    /// [`SurfaceMesh::drift`]).
    built: Option<(f64, f64)>,
}

/// LIGGGHTS `fix wall/gran ... mesh n_meshes N meshes ...`.
pub struct WallGranMesh {
    id: String,
    group: u32,
    meshes: Vec<WallMesh>,
    kernel: Box<dyn ContactKernel>,
    table: ParamTable,
    width: usize,
    summary: String,
}

impl WallGranMesh {
    fn slot_len(&self) -> usize {
        MESH_SLOTS * (1 + self.width)
    }
}

impl Fix for WallGranMesh {
    crate::post_force_only!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "wall/gran"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        for m in &self.meshes {
            sim.particles.add_extra(&m.hist_name, vec![0.0; self.slot_len()]);
            sim.particles.add_extra(&m.used_name, vec![-1.0]);
        }
        Ok(())
    }
    /// Each particle meets, in increasing index, the triangles that can
    /// touch it; those left out touch nothing, so any superset gives the
    /// same bits. LIGGGHTS keeps such a list per particle (`fix
    /// neighlist/mesh`), and so does demx: the triangles within reach + 5/8
    /// of the skin + M of an anchor, the particle's centre in the mesh's own
    /// frame when the lists were found, where M is the mesh's own allowance
    /// (half the skin; 0 for a mesh at rest). A triangle at distance D from
    /// the anchor is at least D - m from a centre m away from it, so a list
    /// holds every triangle within reach while m stays under (half the
    /// skin) + M; each step checks that per particle, and a particle past it
    /// searches the mesh's bins that step, and the lists are found again at
    /// the next. (The eighth of the skin left over, and a relative 1e-9 of
    /// the radius, cover the rounding of the distances.) The lists are found
    /// again at each pair-list build (particles may be reordered there),
    /// when the mesh changes, and when the mesh has moved (`move/mesh`,
    /// rigid) by M since.
    ///
    /// When every step checks for a pair-list build (delay 0, every 1, check
    /// yes), no particle is more than half the skin from where it was at the
    /// last build: the anchors are those places, seen from the mesh, and m
    /// stays under half the skin + M without a look. Then only the particles
    /// with triangles in their lists, or a contact to end, are visited at
    /// all: a pile far from the walls costs them nothing. Particles run in
    /// fixed chunks, in parallel from two chunks up: each touches only its
    /// own force, torque and slots, and the pushes on the mesh are summed in
    /// particle order within a chunk and in chunk order between them.
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        let len = self.slot_len();
        let time = sim.time;
        // dt = 0 leaves the history where it is (setup force evaluation)
        let setup = sim.setup_pass;
        let dt = if setup { 0.0 } else { sim.dt };
        let ns = &sim.neigh;
        let n = sim.particles.len();
        let steady = sim.pairs.x_built.len() == n && ns.check && ns.delay == 0 && ns.every <= 1;
        let (builds, skin) = (sim.pairs.builds, ns.skin);
        let x_built = &sim.pairs.x_built;
        let (group, width, kernel, table) = (self.group, self.width, &*self.kernel, &self.table);
        for wm in &mut self.meshes {
            let col = sim.particles.add_extra(&wm.hist_name, vec![0.0; len]);
            let ucol = sim.particles.add_extra(&wm.used_name, vec![-1.0]);
            let guard = wm.mesh.read().map_err(|_| lock_err())?;
            let mesh = &*guard;
            let pose = mesh.pose(time);
            let bounded = skin > 0.0;
            let allowance = if mesh.motion.is_some() { 0.5 * skin } else { 0.0 };
            let reach_skin = 0.625 * skin + allowance;
            let bound = 0.5 * skin + allowance;
            let bound2 = bound * bound;
            let crate::engine::particles::Particles { x, v, omega, f, torque, radius, mass, kind, mask, extra, .. } = &mut sim.particles;
            let (x, v, omega, radius, mass, kind, mask) = (&*x, &*v, &*omega, &*radius, &*mass, &*kind, &*mask);
            let key = (builds, mesh.epoch, n, steady);
            let moved = |wm: &WallMesh| wm.built.is_some_and(|(t0, far)| mesh.drift(t0, time, far) > allowance);
            if !bounded {
                wm.near_at = None;
            } else if wm.near_at != Some(key) || moved(wm) {
                let used = &extra[ucol].data;
                let find = |lo: usize, hi: usize| -> (Vec<u32>, Vec<u32>, Vec<V3>, Vec<u32>) {
                    let (mut tris, mut counts, mut anchors, mut active) = (vec![], Vec::with_capacity(hi - lo), Vec::with_capacity(hi - lo), vec![]);
                    for i in lo..hi {
                        let before = tris.len();
                        let pref = pose.to_reference(if steady { x_built[i] } else { x[i] });
                        if mask[i] & group != 0 {
                            tris.extend(mesh.near(pref, radius[i] * (1.0 + 1e-9) + reach_skin).map(|t| t as u32));
                            if !steady || tris.len() > before || used[i] != 0.0 {
                                active.push(i as u32);
                            }
                        }
                        counts.push((tris.len() - before) as u32);
                        anchors.push(pref);
                    }
                    (tris, counts, anchors, active)
                };
                let parts: Vec<(Vec<u32>, Vec<u32>, Vec<V3>, Vec<u32>)> = if n >= 2 * CHUNK {
                    (0..n.div_ceil(CHUNK)).into_par_iter().map(|c| find(c * CHUNK, ((c + 1) * CHUNK).min(n))).collect()
                } else {
                    (0..n.div_ceil(CHUNK).max(1)).map(|c| find(c * CHUNK, ((c + 1) * CHUNK).min(n))).collect()
                };
                wm.near.clear();
                wm.start.clear();
                wm.anchor.clear();
                wm.active.clear();
                wm.active_start.clear();
                wm.start.push(0);
                wm.active_start.push(0);
                for (tris, counts, anchors, active) in parts {
                    wm.near.extend(tris);
                    for c in counts {
                        wm.start.push(wm.start.last().copied().unwrap_or(0) + c);
                    }
                    wm.anchor.extend(anchors);
                    wm.active.extend(active);
                    wm.active_start.push(wm.active.len() as u32);
                }
                // how far from the mesh's axis a particle within reach can be
                // (a particle farther out stays farther out: a rotation keeps
                // its distance from the axis, and it moves under half a skin)
                let far = mesh.axis_reach() + radius.iter().fold(0.0f64, |m, &r| m.max(r)) + reach_skin + skin;
                wm.near_at = Some(key);
                wm.built = Some((time, far));
            }
            let (near, start, anchor, active, active_start) = (&wm.near[..], &wm.start[..], &wm.anchor[..], &wm.active[..], &wm.active_start[..]);
            // mesh/surface/stress: the grains of its group push the mesh
            // back; its reference point where the mesh is now
            let stress = mesh.stress.as_ref().map(|st| (st.group, pose.to_world(st.p_ref)));
            // the push on each triangle too, where a dump reads it
            let per_tri = mesh.stress.as_ref().is_some_and(|st| st.per_tri.is_some());
            let wear = mesh.stress.as_ref().and_then(|st| st.wear.as_ref());
            let step_dt = sim.dt;
            // each chunk's push on the mesh (and its triangles), summed in
            // chunk order below: the same bits on any thread count
            let body = |(c, (((fc, tc), hc), uc)): (usize, (((&mut [V3], &mut [V3]), &mut [f64]), &mut [f64]))| -> Result<ChunkPush> {
                let (mut push, mut moment, mut tri_push, mut tri_wear, mut strayed) = (V3::zeros(), V3::zeros(), Vec::new(), Vec::new(), false);
                // the chunk's particles to visit (all of them without lists)
                let all = c * CHUNK..c * CHUNK + fc.len();
                let visit: Box<dyn Iterator<Item = usize>> = if bounded {
                    Box::new(active[active_start[c] as usize..active_start[c + 1] as usize].iter().map(|&i| i as usize))
                } else {
                    Box::new(all.filter(|&i| mask[i] & group != 0))
                };
                for i in visit {
                    let q = i - c * CHUNK;
                    let (xi, ri, vi, wi, mi) = (x[i], radius[i], v[i], omega[i], mass[i]);
                    let pref = pose.to_reference(xi);
                    let listed = bounded && (pref - anchor[i]).norm_squared() < bound2;
                    let cands = if listed { &near[start[i] as usize..start[i + 1] as usize] } else { &[][..] };
                    // no triangle within reach and no contact to end (its
                    // slots are empty: `used` counts them, -1 = not known
                    // yet): nothing would change, so nothing is read
                    if listed && cands.is_empty() && uc[q] == 0.0 {
                        continue;
                    }
                    let pp = table.get(kind[i], mesh.wall_type);
                    let (mut fs, mut ts) = (V3::zeros(), V3::zeros());
                    let pushes = stress.filter(|&(g, _)| mask[i] & g != 0).map(|(_, at)| at);
                    let wears = wear.filter(|w| mask[i] & w.group != 0).map(|w| w.k[kind[i] as usize - 1]);
                    let slots = Slots { data: &mut hc[q * len..(q + 1) * len], width };
                    let apply = |hit: &MeshHit, hist: &mut [f64]| {
                        let nrm = pose.dir_to_world(hit.normal);
                        let point = pose.to_world(hit.point);
                        let vwall = pose.wall_velocity(point, mesh.tris[hit.tri].n);
                        let vr = vi - vwall;
                        let c = Contact::with_wall(nrm, ri - hit.delta, hit.delta, ri, ri, mi, vr, wi, dt);
                        let out = kernel.contact(&c, pp, hist);
                        let fi = out.force_i(&c);
                        fs += fi;
                        ts += out.torque_i;
                        if let Some(at) = pushes {
                            // the contact point is the triangle's point nearest the centre
                            push -= fi;
                            moment += (point - at).cross(&-fi);
                            if per_tri {
                                tri_push.push((hit.tri as u32, -fi));
                            }
                        }
                        if let Some(k) = wears {
                            let t = &mesh.tris[hit.tri];
                            let n = pose.dir_to_world(t.n);
                            tri_wear.push((hit.tri as u32, finnie_increment(point - xi, vr, n, k, fi.norm(), step_dt, t.area())));
                        }
                    };
                    let in_use = if listed {
                        resolve_among(mesh, cands.iter().map(|&t| t as usize), pref, ri, slots, apply)?
                    } else {
                        strayed |= bounded;
                        resolve_particle(mesh, pref, ri, slots, apply)?
                    };
                    uc[q] = in_use as f64;
                    fc[q] += fs;
                    tc[q] += ts;
                }
                Ok((push, moment, tri_push, tri_wear, strayed))
            };
            let (data, used) = two_columns(extra, col, ucol);
            let (data, used) = (&mut data[..n * len], &mut used[..n]);
            let done: Vec<Result<ChunkPush>> = if n >= 2 * CHUNK {
                f.par_chunks_mut(CHUNK)
                    .zip(torque.par_chunks_mut(CHUNK))
                    .zip(data.par_chunks_mut(CHUNK * len))
                    .zip(used.par_chunks_mut(CHUNK))
                    .enumerate()
                    .map(body)
                    .collect()
            } else {
                f.chunks_mut(CHUNK)
                    .zip(torque.chunks_mut(CHUNK))
                    .zip(data.chunks_mut(CHUNK * len))
                    .zip(used.chunks_mut(CHUNK))
                    .enumerate()
                    .map(body)
                    .collect()
            };
            let parts = done.into_iter().collect::<Result<Vec<ChunkPush>>>()?;
            if parts.iter().any(|p| p.4) {
                wm.near_at = None;
            }
            if stress.is_some() {
                drop(guard);
                let mut m = wm.mesh.write().map_err(|_| lock_err())?;
                if let Some(st) = m.stress.as_mut() {
                    for (push, moment, tri_push, tri_wear, _) in parts {
                        st.force += push;
                        st.torque += moment;
                        if let Some(ts) = st.per_tri.as_mut() {
                            for (t, p) in tri_push {
                                ts.f[t as usize] += p;
                            }
                        }
                        if let Some(w) = st.wear.as_mut() {
                            for (t, e) in tri_wear {
                                w.step[t as usize] += e;
                            }
                        }
                    }
                    if let Some(w) = st.wear.as_mut() {
                        w.live |= !setup;
                    }
                    // the step's stresses are those of these pushes (the
                    // engine derives them at final_integrate, not at setup)
                    if let Some(ts) = st.per_tri.as_mut() {
                        ts.live |= !setup;
                    }
                }
            }
        }
        Ok(())
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
    fn max_surface_overlap(&self, sim: &Sim) -> Option<(usize, f64)> {
        let p = &sim.particles;
        self.placed(sim, |placed| crate::engine::fix::deepest_overlap(sim, self.group, |i| deepest_triangle_overlap(placed, p.x[i], p.radius[i])))
    }
    fn surface_overlap(&self, sim: &Sim, i: usize) -> Option<f64> {
        self.placed(sim, |placed| deepest_triangle_overlap(placed, sim.particles.x[i], sim.particles.radius[i]))
    }
}

impl WallGranMesh {
    /// `f` of the meshes, each read-locked and placed at its pose once.
    fn placed<R>(&self, sim: &Sim, f: impl FnOnce(&[(&SurfaceMesh, Pose)]) -> R) -> R {
        let guards: Vec<_> = self.meshes.iter().filter_map(|wm| wm.mesh.read().ok()).collect();
        let placed: Vec<(&SurfaceMesh, Pose)> = guards.iter().map(|m| (&**m, m.pose(sim.time))).collect();
        f(&placed)
    }
}

/// Two different per-atom columns, both writable.
fn two_columns(extra: &mut [crate::engine::particles::PerAtom], a: usize, b: usize) -> (&mut [f64], &mut [f64]) {
    assert_ne!(a, b, "two_columns: the same column twice");
    if a < b {
        let (lo, hi) = extra.split_at_mut(b);
        (&mut lo[a].data, &mut hi[0].data)
    } else {
        let (lo, hi) = extra.split_at_mut(a);
        (&mut hi[0].data, &mut lo[b].data)
    }
}

/// The deepest triangle contact of a sphere (centre `x`, world) with the
/// meshes, each at its pose, read only (no history slots touched).
fn deepest_triangle_overlap(placed: &[(&SurfaceMesh, Pose)], x: V3, r: f64) -> Option<f64> {
    let mut deepest: Option<f64> = None;
    for (mesh, pose) in placed {
        let pref = pose.to_reference(x);
        for t in mesh.bins.candidates(pref, r) {
            if let Some((delta, _, _)) = mesh.triangle_contact(t, pref, r) {
                if delta > 0.0 && deepest.is_none_or(|d| delta > d) {
                    deepest = Some(delta);
                }
            }
        }
    }
    deepest
}

fn wall_gran_mesh(s: &mut Session, cmd: &Command, id: &str, group: u32, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    s.set_dialect(Dialect::Liggghts);
    let words = a.rest().to_vec();
    let end = words
        .iter()
        .position(|w| w.text == "mesh")
        .ok_or_else(|| Error::deck(a.end_span(), "fix wall/gran: missing `mesh n_meshes N meshes ...`"))?;
    let mut spec = PairSpec::new(cmd.span, true);
    if end > 0 {
        let model_cmd = Command { words: std::iter::once(cmd.words[0].clone()).chain(words[..end].iter().cloned()).collect(), span: cmd.span };
        let mut ma = Args::new(&model_cmd);
        model::parse_liggghts_model(&mut ma, &mut spec)?;
    }
    a.pos += end + 1;
    a.choice("keyword", &["n_meshes"])?;
    let n = a.i64("number of meshes")?;
    if n < 1 {
        return Err(a.err_prev("n_meshes must be >= 1"));
    }
    a.choice("keyword", &["meshes"])?;
    let mut meshes = Vec::new();
    let mut names = Vec::new();
    for _ in 0..n {
        let w = a.word("mesh id")?;
        let m = need_mesh(s, w)?;
        let hist_name = format!("mesh_history:{id}:{}", w.text);
        let used_name = format!("{hist_name}:used");
        meshes.push(WallMesh {
            mesh: m,
            hist_name,
            used_name,
            near: vec![],
            start: vec![],
            anchor: vec![],
            active: vec![],
            active_start: vec![],
            near_at: None,
            built: None,
        });
        names.push(w.text.clone());
    }
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "store_force" | "store_force_contact" | "store_force_contact_stress" => {
                if a.yes_no(&k.text)? {
                    return Err(Error::unsupported(k.span, format!("fix wall/gran {} yes", k.text)));
                }
            }
            "meshes" if a.peek().is_some() => {
                return Err(Error::deck(k.span, format!("fix wall/gran: more mesh ids than n_meshes {n}")));
            }
            "shear" | "temperature" | "track_energy" | "contact_area" => {
                return Err(Error::unsupported(k.span, format!("fix wall/gran keyword {}", k.text)))
            }
            _ => {
                if find_mesh(s, &k.text).is_some() {
                    return Err(Error::deck(k.span, format!("fix wall/gran: more mesh ids than n_meshes {n}")));
                }
                return Err(Error::deck(k.span, format!("fix wall/gran: unknown keyword '{}'", k.text)));
            }
        }
    }
    let table = model::fill_table(s, &spec, cmd.span)?;
    let kernel = model::build_kernel(&spec)?;
    let width = kernel.history_width();
    let summary = format!("wall/gran {id} (mesh {}): {}", names.join(" "), spec.summary());
    s.walls.push(summary.clone());
    s.add_fix(Box::new(WallGranMesh { id: id.to_string(), group, meshes, kernel, table, width, summary }))
}

// ------------------------------------------------------- wall/gran/region

/// Slots per particle of a region wall: `[nx, ny, nz, used, history...]`.
const REGION_SLOTS: usize = 6;

/// LAMMPS `fix wall/gran/region`.
pub struct WallGranRegion {
    id: String,
    group: u32,
    region: Region,
    kernel: Box<dyn ContactKernel>,
    table: ParamTable,
    width: usize,
    hist_name: String,
    summary: String,
    /// Displacement and angle at the previous step (wall velocity by differences, as LAMMPS).
    prev: Option<(i64, V3, f64)>,
}

impl WallGranRegion {
    fn slot_len(&self) -> usize {
        REGION_SLOTS * (4 + self.width)
    }
}

impl Fix for WallGranRegion {
    crate::post_force_only!();
    fn region(&self) -> Option<&str> {
        Some(&self.region.id)
    }
    fn replace_region(&mut self, region: &Region) {
        // LAMMPS resets the wall's motion when its region changed between runs
        self.region = region.clone();
        self.prev = None;
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "wall/gran/region"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        sim.particles.add_extra(&self.hist_name, vec![0.0; self.slot_len()]);
        Ok(())
    }
    fn post_force(&mut self, sim: &mut Sim, vars: &Variables) -> Result<()> {
        // region position now, and its velocity from the previous step
        let (mut vmove, mut omega) = (V3::zeros(), 0.0);
        let mut rot = None;
        if self.region.is_dynamic() {
            let ctx: &Sim = sim;
            let label = format!("fix {} region {}", self.id, self.region.id);
            self.region.update(sim.time, &|name: &str, _t: f64| {
                vars.eval_equal(name, ctx).map_err(|e| Error::runtime(format!("{label}: variable {name}: {e}")))
            })?;
            let (d, th) = (self.region.disp, self.region.angle);
            if let Some((step, pd, pth)) = self.prev {
                if step != sim.step && sim.dt > 0.0 {
                    let k = (sim.step - step) as f64 * sim.dt;
                    vmove = (d - pd) / k;
                    omega = (th - pth) / k;
                }
            }
            self.prev = Some((sim.step, d, th));
            if let Some((_, pnt, axis)) = self.region.motion.as_ref().and_then(|m| m.rotate.clone()) {
                rot = Some((pnt + d, axis));
            }
        }
        let len = self.slot_len();
        let w = 4 + self.width;
        let col = sim.particles.add_extra(&self.hist_name, vec![0.0; len]);
        let setup = sim.setup_pass;
        let dt = if setup { 0.0 } else { sim.dt };
        let p = &mut sim.particles;
        for i in 0..p.len() {
            if p.mask[i] & self.group == 0 {
                continue;
            }
            let (xi, ri) = (p.x[i], p.radius[i]);
            let contacts = self.region.surface_contacts(xi, ri);
            let data = &mut p.extra[col].data[i * len..(i + 1) * len];
            let mut used = [false; REGION_SLOTS];
            let pp = self.table.get(p.kind[i], 1);
            for sc in contacts {
                let delta = ri - sc.distance;
                if delta <= 0.0 {
                    continue;
                }
                let n = sc.normal;
                // the slot of this face: the stored normal closest to n
                let mut best: Option<(usize, f64)> = None;
                for k in 0..REGION_SLOTS {
                    if data[k * w + 3] != 0.0 && !used[k] {
                        let d = n.dot(&V3::new(data[k * w], data[k * w + 1], data[k * w + 2]));
                        if d > 0.5 && best.is_none_or(|(_, b)| d > b) {
                            best = Some((k, d));
                        }
                    }
                }
                let k = match best {
                    Some((k, _)) => k,
                    None => {
                        let Some(k) = (0..REGION_SLOTS).find(|&k| data[k * w + 3] == 0.0) else {
                            return Err(Error::runtime(format!("fix {}: a particle touches more than {REGION_SLOTS} region faces", self.id)));
                        };
                        data[k * w + 4..(k + 1) * w].fill(0.0);
                        k
                    }
                };
                used[k] = true;
                data[k * w] = n.x;
                data[k * w + 1] = n.y;
                data[k * w + 2] = n.z;
                data[k * w + 3] = 1.0;
                let mut vwall = vmove;
                if let Some((c, axis)) = rot {
                    vwall += (axis * omega).cross(&(sc.point - c));
                }
                let mi = p.mass[i];
                let vr = p.v[i] - vwall;
                let c = Contact::with_wall(n, sc.distance, delta, ri, ri, mi, vr, p.omega[i], dt);
                let out = self.kernel.contact(&c, pp, &mut data[k * w + 4..(k + 1) * w]);
                p.f[i] += out.force_i(&c);
                p.torque[i] += out.torque_i;
            }
            // free the slots of faces left; a free slot is all zeros already
            for k in 0..REGION_SLOTS {
                if !used[k] && data[k * w + 3] != 0.0 {
                    data[k * w..(k + 1) * w].fill(0.0);
                }
            }
        }
        Ok(())
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
}

fn wall_gran_region(s: &mut Session, cmd: &Command, id: &str, group: u32, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    s.set_dialect(Dialect::Lammps);
    let first = a.word("wall style")?;
    let mut spec = PairSpec::new(cmd.span, true);
    let mut granular_table = None;
    match first.text.as_str() {
        "hooke" | "hooke/history" | "hertz/history" => {
            let kn = a.f64("Kn")?;
            let ktw = a.word("Kt")?;
            let gn = a.f64("gamma_n")?;
            let gtw = a.word("gamma_t")?;
            let xmu = a.f64("xmu")?;
            let damp = a.i64("dampflag")?;
            if damp != 0 && damp != 1 {
                return Err(a.err_prev("dampflag must be 0 or 1"));
            }
            let kt = if ktw.text == "NULL" { 2.0 / 7.0 * kn } else { args::parse_f64(ktw)? };
            let gt = if gtw.text == "NULL" { 0.5 * gn } else { args::parse_f64(gtw)? };
            if a.peek().map(|w| w.text == "limit_damping").unwrap_or(false) {
                a.pos += 1;
                spec.limit_damping = true;
            }
            spec.gran = Some([kn, kt, gn, if damp == 0 { 0.0 } else { gt }, xmu]);
            spec.tangential_damping = damp == 1;
            spec.normal = if first.text == "hertz/history" { NormalSpec::GranHertz } else { NormalSpec::GranHooke };
            spec.tangential = if first.text == "hooke" { TangentialSpec::GranNoHistory } else { TangentialSpec::GranHistory };
        }
        "granular" => {
            // the coefficient block as for `fix wall/gran granular`, up to `region`
            let (gspec, table) = super::walls::granular_coeffs(s, cmd, a, first)?;
            if matches!(gspec.normal, NormalSpec::GranularCohesive(model::CohesiveNormal::Jkr, _)) {
                return Err(Error::unsupported(first.span, "fix wall/gran/region granular jkr (contacts beyond touching at region walls)"));
            }
            granular_table = Some(table);
            spec = gspec;
        }
        _ => return Err(args::bad_keyword(first, "wall/gran/region style", &["hooke", "hooke/history", "hertz/history", "granular"])),
    }
    a.choice("keyword", &["region"])?;
    let rw = a.word("region id")?;
    let region = super::setup::region(s, rw)?.clone();
    while a.more() {
        let k = a.word("keyword")?;
        if k.text != "contacts" {
            return Err(Error::deck(k.span, format!("fix wall/gran/region: unknown keyword '{}'", k.text)));
        }
    }
    spec.has_coeff = true;
    let table = match granular_table {
        Some(t) => t,
        None => model::fill_table(s, &spec, cmd.span)?,
    };
    let kernel = model::build_kernel(&spec)?;
    let width = kernel.history_width();
    let summary = format!("wall/gran/region {id} (region {}): {}", rw.text, spec.summary());
    s.walls.push(summary.clone());
    s.add_fix(Box::new(WallGranRegion {
        id: id.to_string(),
        group,
        region,
        kernel,
        table,
        width,
        hist_name: format!("wall_history:{id}"),
        summary,
        prev: None,
    }))
}

/// What one chunk of grains pushes a mesh with: force, its moment about
/// the reference point, the push on each triangle touched and the wear of
/// each, in contact order (when kept); and whether a grain strayed beyond
/// its triangle list's bound.
type ChunkPush = (V3, V3, Vec<(u32, V3)>, Vec<(u32, f64)>, bool);

// ------------------------------------------------------------ dump mesh/stl

/// What the mesh dumps share: id, interval, file pattern (`*` becomes the
/// step) and the step of the last frame.
struct MeshFrames {
    id: String,
    every: i64,
    path: String,
    last_step: Option<i64>,
}

impl MeshFrames {
    fn due(&self, step: i64, first: bool) -> bool {
        if self.last_step == Some(step) {
            return false;
        }
        (self.every > 0 && step % self.every == 0) || first
    }

    /// Write one frame's file whole (through a temporary file: a run that
    /// is killed leaves no half-written frame).
    fn write(&mut self, step: i64, text: &str) -> Result<()> {
        self.last_step = Some(step);
        let path = self.path.replace('*', &step.to_string());
        crate::io::write_atomic(&path, text.as_bytes()).map_err(|e| Error::runtime(format!("dump {}: {e}", self.id)))
    }

    fn modify(args: &[Word], style: &str) -> Result<()> {
        match args.first() {
            Some(w) => Err(Error::unsupported(w.span, format!("dump_modify {} for dump {style}", w.text))),
            None => Ok(()),
        }
    }
}

/// `dump ID group STYLE N file` of a mesh dump (the group is checked, not
/// read, as in LIGGGHTS): its frames and the arguments after the file.
fn mesh_dump_head<'c>(s: &Session, cmd: &'c Command, styles: &[&str]) -> Result<(MeshFrames, &'c Word, Args<'c>)> {
    let mut a = Args::new(cmd);
    let id = a.word("dump id")?;
    let g = a.word("group")?;
    s.group(g)?;
    a.choice("dump style", styles)?;
    let every = a.i64("N")?;
    if every <= 0 {
        return Err(a.err_prev(format!("dump {}: N must be > 0", styles[0])));
    }
    let file = a.word("file")?;
    Ok((MeshFrames { id: id.text.clone(), every, path: file.text.clone(), last_step: None }, file, a))
}

/// Every mesh of the scene, in the order of their fixes, with their ids
/// (a mesh dump without mesh ids writes them all).
fn all_meshes(s: &Session) -> (Vec<SharedMesh>, Vec<String>) {
    s.sim.fixes.iter().filter_map(|f| f.as_any().and_then(|x| x.downcast_ref::<MeshSurfaceFix>())).map(|m| (m.mesh.clone(), m.id.clone())).unzip()
}

/// `dump ID group mesh/stl N file [mesh ids]`: the current (moved) meshes as
/// ASCII STL, one file per frame (`*` in the file name becomes the step;
/// LIGGGHTS requires the `*`).
pub struct DumpMeshStl {
    frames: MeshFrames,
    meshes: Vec<SharedMesh>,
    summary: String,
}

impl Dump for DumpMeshStl {
    fn due(&self, step: i64, first: bool) -> bool {
        self.frames.due(step, first)
    }
    fn write(&mut self, sim: &Sim) -> Result<()> {
        if sim.dry {
            return Ok(());
        }
        let mut tris = Vec::new();
        for m in &self.meshes {
            tris.extend(m.read().map_err(|_| lock_err())?.current_triangles(sim.time));
        }
        self.frames.write(sim.step, &crate::io::vtk::format_stl(&tris))
    }
    fn id(&self) -> &str {
        &self.frames.id
    }
    fn modify(&mut self, args: &[Word]) -> Result<()> {
        MeshFrames::modify(args, "mesh/stl")
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
}

/// Parse `dump ID group mesh/stl N file [mesh ids...]` (all meshes when no id
/// is given; `stl` is LIGGGHTS's alias) into a dump;
/// `s.sim.dumps.push(Box::new(...))` is the caller's.
pub fn dump_mesh_stl(s: &Session, cmd: &Command) -> Result<DumpMeshStl> {
    let (frames, file, mut a) = mesh_dump_head(s, cmd, &["mesh/stl", "stl"])?;
    if !file.text.contains('*') {
        return Err(Error::deck(file.span, "dump mesh/stl: use a file name like 'dump*.stl' (one file per time step, as LIGGGHTS requires)"));
    }
    let (mut meshes, mut names) = (Vec::new(), Vec::new());
    while a.more() {
        let w = a.word("mesh id")?;
        meshes.push(need_mesh(s, w)?);
        names.push(w.text.clone());
    }
    if meshes.is_empty() {
        (meshes, names) = all_meshes(s);
    }
    let summary = format!("dump {} mesh/stl every {} -> {} (meshes {})", frames.id, frames.every, file.text, names.join(" "));
    Ok(DumpMeshStl { frames, meshes, summary })
}

// ------------------------------------------------------------ dump mesh/vtk

/// What `dump mesh/vtk` may write of each triangle, in the order LIGGGHTS
/// writes the arrays (whatever the order of the command's words).
const MESH_VTK_PROPS: [&str; 11] = ["stress", "stresscomponents", "id", "vel", "wear", "owner", "area", "aedges", "acorners", "index", "nneighs"];

/// `dump ID group mesh/vtk N file [output face|interpolate|original]
/// props... [mesh ids...]` (LIGGGHTS 3.8): the meshes as one legacy VTK
/// polydata file per frame, with the chosen properties of each triangle.
pub struct DumpMeshVtk {
    frames: MeshFrames,
    output: MeshVtkOutput,
    /// Which of [`MESH_VTK_PROPS`] are written.
    props: [bool; 11],
    meshes: Vec<SharedMesh>,
    summary: String,
}

impl DumpMeshVtk {
    fn wants(&self, prop: &str) -> bool {
        MESH_VTK_PROPS.iter().position(|&p| p == prop).is_some_and(|k| self.props[k])
    }

    /// One mesh's triangle and node arrays, as LIGGGHTS's `DumpMesh`
    /// builds them: a property the mesh does not have (stresses of a mesh
    /// without mesh/surface/stress, velocities of a mesh at rest, wear) is
    /// left out.
    fn arrays(&self, m: &SurfaceMesh, time: f64, setup: bool) -> (Vec<MeshArray>, Vec<MeshArray>) {
        let n = m.tris.len();
        let (mut cells, mut nodes) = (Vec::new(), Vec::new());
        let arr = |name: &str, ncomp: usize, ty: VtkType, values: Vec<f64>| MeshArray { name: name.to_string(), ncomp, ty, values };
        let ints = |f: &dyn Fn(usize) -> usize| (0..n).map(|t| f(t) as f64).collect::<Vec<f64>>();
        if self.wants("stress") {
            if let Some(sigma) = m.tri_stresses(time) {
                cells.push(arr("normal_stress_average", 1, VtkType::Double, sigma.iter().map(|s| s[0]).collect()));
                cells.push(arr("shear_stress_average", 1, VtkType::Double, sigma.iter().map(|s| s[1]).collect()));
            }
        }
        if self.wants("stresscomponents") {
            if let Some(ts) = m.stress.as_ref().and_then(|st| st.per_tri.as_ref()) {
                // the push over the area, as the engine's f * (1/area)
                let values = m.tris.iter().zip(&ts.f).flat_map(|(t, f)| {
                    let inv = 1.0 / t.area();
                    [f.x * inv, f.y * inv, f.z * inv]
                });
                cells.push(arr("stress", 3, VtkType::Double, values.collect()));
            }
        }
        if self.wants("id") {
            cells.push(arr("meshid", 1, VtkType::Int, ints(&|t| t)));
        }
        if self.wants("vel") {
            if let Some(v) = m.node_velocities(time, setup) {
                nodes.push(arr("v", 3, VtkType::Double, v.iter().flatten().flat_map(|p| [p.x, p.y, p.z]).collect()));
            }
        }
        if self.wants("wear") {
            if let Some(w) = m.stress.as_ref().and_then(|st| st.wear.as_ref()) {
                cells.push(arr("wear", 1, VtkType::Double, w.current()));
            }
        }
        if self.wants("owner") {
            cells.push(arr("owner", 1, VtkType::Int, vec![0.0; n]));
        }
        if self.wants("area") {
            cells.push(arr("area", 1, VtkType::Double, m.tris.iter().map(|t| t.area()).collect()));
        }
        if self.wants("aedges") {
            cells.push(arr("active_edges", 1, VtkType::Int, ints(&|t| m.edge_active[t].iter().filter(|&&a| a).count())));
        }
        if self.wants("acorners") {
            cells.push(arr("active_corners", 1, VtkType::Int, ints(&|t| m.corner_active[t].iter().filter(|&&a| a).count())));
        }
        if self.wants("index") {
            cells.push(arr("index", 1, VtkType::Int, ints(&|t| t)));
        }
        if self.wants("nneighs") {
            cells.push(arr("nneighs", 1, VtkType::Int, ints(&|t| m.nneighs[t] as usize)));
        }
        (cells, nodes)
    }
}

/// The arrays of several meshes as one: each name where it first appears,
/// its values mesh after mesh, zeros for a mesh without it (as LIGGGHTS
/// merges its meshes' blocks). `per` is each mesh's tuple count.
fn merge_arrays(blocks: Vec<Vec<MeshArray>>, per: &[usize]) -> Vec<MeshArray> {
    let mut out: Vec<MeshArray> = Vec::new();
    for b in &blocks {
        for a in b {
            if !out.iter().any(|o| o.name == a.name) {
                out.push(MeshArray { values: Vec::new(), ..a.clone() });
            }
        }
    }
    for o in &mut out {
        for (b, &count) in blocks.iter().zip(per) {
            match b.iter().find(|a| a.name == o.name) {
                Some(a) => o.values.extend_from_slice(&a.values),
                None => o.values.extend(std::iter::repeat_n(0.0, count * o.ncomp)),
            }
        }
    }
    out
}

impl Dump for DumpMeshVtk {
    fn due(&self, step: i64, first: bool) -> bool {
        self.frames.due(step, first)
    }
    fn write(&mut self, sim: &Sim) -> Result<()> {
        if sim.dry {
            return Ok(());
        }
        let (mut tris, mut cells, mut nodes, mut ntri, mut nnode) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for m in &self.meshes {
            let m = m.read().map_err(|_| lock_err())?;
            tris.extend(m.current_triangles(sim.time));
            // a frame at a run's start is written by its setup
            let (c, p) = self.arrays(&m, sim.time, sim.step == sim.run_start);
            cells.push(c);
            nodes.push(p);
            ntri.push(m.tris.len());
            nnode.push(3 * m.tris.len());
        }
        let text = crate::io::vtk::format_mesh_vtk(&tris, merge_arrays(cells, &ntri), merge_arrays(nodes, &nnode), self.output);
        self.frames.write(sim.step, &text)
    }
    fn id(&self) -> &str {
        &self.frames.id
    }
    fn modify(&mut self, args: &[Word]) -> Result<()> {
        MeshFrames::modify(args, "mesh/vtk")
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
}

/// Parse `dump ID group mesh/vtk N file [output face|interpolate|original]
/// props... [mesh ids...]` (all meshes when no id is given; the group is
/// not read, as in LIGGGHTS). A mesh/surface/stress mesh whose stresses
/// are dumped keeps its pushes per triangle from now on.
pub fn dump_mesh_vtk(s: &Session, cmd: &Command) -> Result<DumpMeshVtk> {
    let (frames, file, mut a) = mesh_dump_head(s, cmd, &["mesh/vtk", "mesh/gran/VTK"])?;
    if file.text.ends_with(".vtp") || file.text.ends_with(".pvtp") {
        return Err(Error::unsupported(file.span, "dump mesh/vtk to a .vtp or .pvtp file (XML); demx writes legacy .vtk"));
    }
    let mut output = MeshVtkOutput::Face;
    let mut props = [false; 11];
    let (mut meshes, mut names) = (Vec::new(), Vec::new());
    while a.more() {
        let w = a.word("mesh/vtk keyword")?;
        if w.text == "output" {
            let m = a.choice("output", &["face", "interpolate", "original"])?;
            output = match m.text.as_str() {
                "face" => MeshVtkOutput::Face,
                "interpolate" => MeshVtkOutput::Interpolate,
                _ => MeshVtkOutput::Original,
            };
        } else if let Some(m) = find_mesh(s, &w.text) {
            meshes.push(m);
            names.push(w.text.clone());
        } else if let Some(k) = MESH_VTK_PROPS.iter().position(|&p| p == w.text) {
            props[k] = true;
        } else if ["temp", "distaa", "liquid"].contains(&w.text.as_str()) {
            return Err(Error::unsupported(w.span, format!("dump mesh/vtk property {}", w.text)));
        } else {
            let mut e = Error::deck(w.span, format!("dump mesh/vtk: '{}' is neither a property nor a fix mesh/surface", w.text));
            let known = MESH_VTK_PROPS.iter().copied().chain(s.sim.fixes.iter().filter(|f| f.style().starts_with("mesh/surface")).map(|f| f.id()));
            if let Some(h) = crate::error::did_you_mean(&w.text, known) {
                e = e.with_hint(format!("did you mean '{h}'?"));
            }
            return Err(e);
        }
    }
    if !props.iter().any(|&p| p) {
        return Err(
            Error::deck(cmd.span, "dump mesh/vtk: no property to dump").with_hint(format!("name one or more of: {}", MESH_VTK_PROPS.join(" ")))
        );
    }
    if meshes.is_empty() {
        (meshes, names) = all_meshes(s);
    }
    let d = DumpMeshVtk { frames, output, props, meshes, summary: String::new() };
    if d.wants("stress") || d.wants("stresscomponents") {
        for m in &d.meshes {
            let mut m = m.write().map_err(|_| lock_err())?;
            let n = m.tris.len();
            if let Some(st) = m.stress.as_mut() {
                st.per_tri.get_or_insert_with(|| TriStress::new(n));
            }
        }
    }
    let chosen: Vec<&str> = MESH_VTK_PROPS.iter().zip(props).filter(|&(_, on)| on).map(|(&p, _)| p).collect();
    let summary =
        format!("dump {} mesh/vtk every {} -> {} ({}; meshes {})", d.frames.id, d.frames.every, file.text, chosen.join(" "), names.join(" "));
    Ok(DumpMeshVtk { summary, ..d })
}
