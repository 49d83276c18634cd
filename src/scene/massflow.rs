//! `fix ID group massflow/mesh mesh MESH vec_side X Y Z [count once|multiple]
//! [file F | append F] [writeTime] [screen yes|no]` (LIGGGHTS 3.8): the mass
//! and number of grains that pass through a planar face, from the side
//! opposite `vec_side` to its side, as LIGGGHTS's `FixMassflowMesh` counts
//! them (read from its source, src/fix_massflow_mesh.cpp, for the facts):
//!
//! - the face's plane is that of its first triangle at the fix's creation
//!   (its first node, its normal turned towards `vec_side`); the face must
//!   be planar;
//! - after each step's positions (LIGGGHTS's `post_integrate`; demx reads the
//!   same positions and half-step velocities at `post_force`), every grain of
//!   the group near the face (its surface within the neighbor skin of one of
//!   the face's triangles) is looked at: the first time, it only records its
//!   side; after that it counts when it is on `vec_side`'s side and was on
//!   the other the last time it was near. With `count once` a grain counts
//!   once at most;
//! - the global vector: [1] mass counted, [2] grains counted, [3] and [4]
//!   mass and grains per time since the previous query of the vector (the
//!   first query: since the start), [5] [6] mass and grains deleted (0:
//!   `delete_atoms` is not supported yet);
//! - `file` writes a header and a line per counted grain: id, (time),
//!   diameter, position and velocity (`%4.4g`).
//!
//! What demx does not run yet (`point_at_outlet`, `inside_out`,
//! `delete_atoms yes`, `sum_property`) is refused with exit 3.

use super::args::Args;
use super::fix_styles::FixCall;
use super::Session;
use crate::engine::fix::{Fix, FixState};
use crate::engine::mesh_surface::SharedMesh;
use crate::engine::sim::Sim;
use crate::error::{Error, Result};
use crate::geom::mesh::{closest_point_on_triangle, Triangle};
use crate::physics::V3;
use crate::script::Variables;
use std::cell::Cell;
use std::collections::HashMap;
use std::io::Write;

/// Where a grain was the last time it was near the face (LIGGGHTS's
/// per-atom counter: 0 on the far side, 1 on `vec_side`'s, 2 counted once).
#[derive(Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
enum Side {
    Far,
    Near,
    Done,
}

/// The fix.
pub struct MassflowMesh {
    id: String,
    group: u32,
    mesh: SharedMesh,
    /// A point of the plane and its unit normal (towards `vec_side`).
    p_ref: V3,
    normal: V3,
    once: bool,
    file: Option<std::fs::File>,
    write_time: bool,
    screen: bool,
    /// Side of each grain (by id) seen near the face.
    side: HashMap<i64, Side>,
    mass: f64,
    count: u64,
    /// Time since the last query, and the totals at that query.
    t_count: f64,
    mass_last: f64,
    count_last: u64,
    /// A query happened since the last step: the next step starts a new
    /// window (LIGGGHTS's `reset_t_count_`, false after a query).
    window_open: Cell<bool>,
    /// The length of the window of the last query.
    delta_t: Cell<f64>,
}

/// Parse the fix (after the style word).
pub fn fix(s: &mut Session, c: &FixCall<'_>, a: &mut Args, _vars: &mut Variables) -> Result<()> {
    s.need_box(c.cmd)?;
    s.set_dialect(crate::engine::Dialect::Liggghts);
    let mut mesh = None;
    let mut side: Option<(V3, crate::script::Span)> = None;
    let mut once = false;
    let mut file = None;
    let mut write_time = false;
    let mut screen = false;
    const KEYWORDS: &[&str] =
        &["mesh", "vec_side", "count", "file", "append", "writeTime", "screen", "delete_atoms", "point_at_outlet", "inside_out", "sum_property"];
    while a.more() {
        let k = a.choice("massflow/mesh keyword", KEYWORDS)?;
        match k.text.as_str() {
            "mesh" => {
                let w = a.word("mesh id")?;
                mesh = Some(super::mesh::need_mesh(s, w)?);
            }
            "vec_side" => {
                let v = V3::new(a.f64("vec_side x")?, a.f64("vec_side y")?, a.f64("vec_side z")?);
                if v.norm() == 0.0 {
                    return Err(a.err_prev("fix massflow/mesh: vec_side > 0 required"));
                }
                side = Some((v, k.span));
            }
            "count" => once = a.choice("count", &["once", "multiple"])?.text == "once",
            "file" | "append" => {
                let w = a.word("file name")?;
                // `demx check` (and a checkpoint's replay) writes nothing
                if !s.sim.dry {
                    let f = if k.text == "file" {
                        std::fs::File::create(&w.text)
                    } else {
                        std::fs::OpenOptions::new().create(true).append(true).open(&w.text)
                    };
                    file = Some(f.map_err(|e| Error::io(w.span, format!("cannot open '{}'", w.text), &e))?);
                }
            }
            "writeTime" => write_time = true,
            "screen" => screen = a.yes_no("screen")?,
            "delete_atoms" => {
                if a.yes_no("delete_atoms")? {
                    return Err(Error::unsupported(k.span, "fix massflow/mesh delete_atoms yes".to_string()));
                }
            }
            _ => return Err(Error::unsupported(k.span, format!("fix massflow/mesh keyword {}", k.text))),
        }
    }
    let Some(mesh) = mesh else {
        return Err(Error::deck(a.end_span(), "fix massflow/mesh: expecting keyword 'mesh'"));
    };
    let Some((vec_side, side_span)) = side else {
        return Err(Error::deck(a.end_span(), "fix massflow/mesh: expecting keyword 'vec_side'"));
    };
    let tris = triangles(&mesh, s.sim.time);
    let Some(first) = tris.first() else {
        return Err(Error::deck(c.style.span, "fix massflow/mesh: the mesh has no triangles"));
    };
    let (p_ref, mut normal) = (first.v[0], first.n);
    // LIGGGHTS refuses a face that is not planar (without point_at_outlet)
    let size = tris.iter().flat_map(|t| t.v).map(|v| (v - p_ref).norm()).fold(0.0, f64::max);
    let planar =
        tris.iter().all(|t| t.n.cross(&normal).norm() < 1e-6 && t.v.iter().all(|v| (v - p_ref).dot(&normal).abs() <= 1e-10 * size.max(1e-300)));
    if !planar {
        return Err(Error::deck(c.style.span, "fix massflow/mesh requires a planar face (its triangles do not lie in one plane)"));
    }
    let dot = normal.dot(&vec_side);
    if dot.abs() < 1e-6 {
        return Err(Error::deck(side_span, "fix massflow/mesh: need to change 'vec_side', it is currently in or too close to the mesh plane"));
    }
    if dot < 0.0 {
        normal = -normal;
    }
    if let Some(f) = &mut file {
        // LIGGGHTS's header line
        let _ = writeln!(f, "# ID{} diameter x y z u v w  (ex ey ez, color)", if write_time { " time " } else { "" });
    }
    s.add_fix(Box::new(MassflowMesh {
        id: c.id.to_string(),
        group: c.group,
        mesh,
        p_ref,
        normal,
        once,
        file,
        write_time,
        screen,
        side: HashMap::new(),
        mass: 0.0,
        count: 0,
        t_count: 0.0,
        mass_last: 0.0,
        count_last: 0,
        window_open: Cell::new(true),
        delta_t: Cell::new(0.0),
    }))
}

/// The mesh's triangles at `time`.
fn triangles(mesh: &SharedMesh, time: f64) -> Vec<Triangle> {
    let m = mesh.read().unwrap_or_else(|e| e.into_inner());
    let v = |p: [f64; 3]| V3::new(p[0], p[1], p[2]);
    m.current_triangles(time).into_iter().map(|[a, b, c]| Triangle::new(v(a), v(b), v(c))).collect()
}

/// `%4.4g`.
fn g4(x: f64) -> String {
    format!("{:>4}", crate::io::cfmt::fmt_g(x, 4))
}

impl MassflowMesh {
    /// The window's rate of a total.
    fn rate(&self, now: f64, last: f64) -> f64 {
        let dt = self.delta_t.get();
        if dt == 0.0 {
            0.0
        } else {
            (now - last) / dt
        }
    }
}

/// What a checkpoint keeps.
#[derive(serde::Serialize, serde::Deserialize)]
struct Saved {
    side: Vec<(i64, Side)>,
    mass: f64,
    count: u64,
    t_count: f64,
    mass_last: f64,
    count_last: u64,
    window_open: bool,
    delta_t: f64,
}

impl Fix for MassflowMesh {
    crate::post_force_only!();
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "massflow/mesh"
    }
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        // a query since the last step closed the window: a new one starts
        if !self.window_open.get() {
            self.t_count = 0.0;
            self.mass_last = self.mass;
            self.count_last = self.count;
            self.window_open.set(true);
        }
        self.t_count += sim.dt;
        let tris = triangles(&self.mesh, sim.time);
        let skin = sim.neigh.skin;
        let (mut lo, mut hi) = (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY));
        for t in &tris {
            let (a, b) = t.bounds();
            lo = lo.inf(&a);
            hi = hi.sup(&b);
        }
        let p = &sim.particles;
        let mut lines = vec![];
        for i in 0..p.len() {
            if p.mask[i] & self.group == 0 {
                continue;
            }
            let (x, reach) = (p.x[i], p.radius[i] + skin);
            if (0..3).any(|k| x[k] < lo[k] - reach || x[k] > hi[k] + reach) {
                continue;
            }
            if !tris.iter().any(|t| (closest_point_on_triangle(x, t).0 - x).norm() < reach) {
                continue;
            }
            let tag = p.tag[i];
            let on = (x - self.p_ref).dot(&self.normal) > 0.0;
            let Some(was) = self.side.get(&tag).copied() else {
                self.side.insert(tag, if on { Side::Near } else { Side::Far });
                continue;
            };
            if was == Side::Done {
                continue;
            }
            if !on {
                self.side.insert(tag, Side::Far);
                continue;
            }
            if was == Side::Far {
                self.mass += p.mass[i];
                self.count += 1;
                if self.file.is_some() || self.screen {
                    let v = p.v[i];
                    let vals = [2.0 * p.radius[i], x.x, x.y, x.z, v.x, v.y, v.z].map(g4).join(" ");
                    lines.push((tag, vals));
                }
            }
            self.side.insert(tag, if self.once { Side::Done } else { Side::Near });
        }
        for (tag, vals) in lines {
            if self.screen {
                sim.log.line(&format!(" {tag} {vals} "));
            }
            if let Some(f) = &mut self.file {
                let time = if self.write_time { format!("  {} ", g4(sim.dt * sim.step as f64)) } else { String::new() };
                let _ = writeln!(f, "{tag}{time} {vals}");
                let _ = f.flush();
            }
        }
        Ok(())
    }
    fn vector(&self, _sim: &Sim, i: usize) -> Option<f64> {
        if !(1..=6).contains(&i) {
            return None;
        }
        // a query closes the window (LIGGGHTS compute_vector)
        if self.window_open.get() {
            self.delta_t.set(self.t_count);
            // the time of the next window counts from the next step (post_force)
            self.window_open.set(false);
        }
        Some(match i {
            1 => self.mass,
            2 => self.count as f64,
            3 => self.rate(self.mass, self.mass_last),
            4 => self.rate(self.count as f64, self.count_last as f64),
            _ => 0.0,
        })
    }
    fn save_state(&self) -> FixState {
        if self.file.is_some() {
            // a file it writes would be opened anew (and cut) by the resumed run
            return FixState::Unsupported;
        }
        let mut side: Vec<(i64, Side)> = self.side.iter().map(|(k, v)| (*k, *v)).collect();
        side.sort_by_key(|x| x.0);
        let s = Saved {
            side,
            mass: self.mass,
            count: self.count,
            t_count: self.t_count,
            mass_last: self.mass_last,
            count_last: self.count_last,
            window_open: self.window_open.get(),
            delta_t: self.delta_t.get(),
        };
        serde_json::to_value(s).map_or(FixState::Unsupported, FixState::Saved)
    }
    fn load_state(&mut self, state: &serde_json::Value) -> std::result::Result<(), String> {
        let s: Saved = serde_json::from_value(state.clone()).map_err(|e| e.to_string())?;
        self.side = s.side.into_iter().collect();
        (self.mass, self.count, self.t_count, self.mass_last, self.count_last) = (s.mass, s.count, s.t_count, s.mass_last, s.count_last);
        self.window_open.set(s.window_open);
        self.delta_t.set(s.delta_t);
        Ok(())
    }
}
