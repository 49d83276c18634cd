//! `fix wall/gran` with primitive shapes, in both dialects. The wall runs the
//! same laws as particle pairs (its own kernel, chosen once), with the wall as
//! a partner of infinite mass and radius; per-particle contact history lives
//! in a per-atom column so it follows particles through reordering.

use super::args::Args;
use super::model::{self, NormalSpec, PairSpec, TangentialSpec};
use super::Session;
use crate::engine::fix::Fix;
use crate::engine::kernel::{ContactKernel, ParamTable};
use crate::engine::sim::{Dialect, Sim};
use crate::error::{Error, Result};
use crate::geom::{PrimitiveWall, WallMotion};
use crate::physics::{Contact, V3};
use crate::script::{Command, Variables, Word};

/// A granular wall of primitive shape.
pub struct WallGran {
    id: String,
    group: u32,
    wall: PrimitiveWall,
    motion: WallMotion,
    kernel: Box<dyn ContactKernel>,
    table: ParamTable,
    /// Wall type (LIGGGHTS `primitive type T`); LAMMPS walls use row 1.
    wall_type: u32,
    width: usize,
    hist_name: String,
    summary: String,
    /// Time the wall motion started.
    t0: f64,
    /// The next post_force is the setup force evaluation: history does not
    /// advance (LAMMPS/LIGGGHTS `update->setupflag`).
    in_setup: bool,
}

impl Fix for WallGran {
    fn id(&self) -> &str {
        &self.id
    }
    fn style(&self) -> &str {
        "wall/gran"
    }
    fn setup(&mut self, sim: &mut Sim) -> Result<()> {
        sim.particles.add_extra(&self.hist_name, vec![0.0; self.width.max(1)]);
        self.in_setup = true;
        Ok(())
    }
    fn post_force(&mut self, sim: &mut Sim, _vars: &Variables) -> Result<()> {
        let col = sim.particles.add_extra(&self.hist_name, vec![0.0; self.width.max(1)]);
        let t = sim.time - self.t0;
        let axis = self.wall.axis();
        let shift = self.motion.shift(axis, t);
        let vwall = self.motion.velocity(t);
        let dt = if std::mem::take(&mut self.in_setup) { 0.0 } else { sim.dt };
        let p = &mut sim.particles;
        let w = self.width.max(1);
        for i in 0..p.len() {
            if p.mask[i] & self.group == 0 {
                continue;
            }
            let hist = &mut p.extra[col].data[i * w..i * w + self.width];
            let Some((delta, n, _pt)) = self.wall.contact(p.x[i], p.radius[i], shift) else {
                hist.fill(0.0);
                continue;
            };
            if delta <= 0.0 {
                hist.fill(0.0);
                continue;
            }
            let mi = p.mass[i];
            let vr = p.v[i] - vwall;
            let c = Contact {
                n,
                r: p.radius[i] - delta,
                delta,
                ri: p.radius[i],
                rj: f64::INFINITY,
                r_eff: p.radius[i],
                mi,
                mj: f64::INFINITY,
                m_eff: mi,
                vr,
                vn: vr.dot(&n),
                wi: p.omega[i],
                wj: V3::zeros(),
                dt,
            };
            let pp = self.table.get(p.kind[i], self.wall_type);
            let out = self.kernel.contact(&c, pp, hist);
            p.f[i] += out.force_i(&c);
            p.torque[i] += out.torque_i;
        }
        Ok(())
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
}

/// Parse `fix ID group wall/gran ...` in either dialect.
pub fn wall_gran(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    let first = a.word("wall model")?;
    let rest_after = |a: &Args| a.rest().to_vec();
    let (spec, table, wall_type, wall, motion) = if first.text == "model" {
        s.set_dialect(Dialect::Liggghts);
        a.pos -= 1;
        let mut spec = PairSpec::new(cmd.span, true);
        // the model block ends at `primitive` or `mesh`
        let words = rest_after(a);
        let end = words.iter().position(|w| w.text == "primitive" || w.text == "mesh").ok_or_else(|| {
            Error::deck(a.end_span(), "fix wall/gran: missing `primitive type T <shape>` or `mesh n_meshes N meshes ...`")
        })?;
        let model_cmd = Command { words: std::iter::once(cmd.words[0].clone()).chain(words[..end].iter().cloned()).collect(), span: cmd.span };
        let mut ma = Args::new(&model_cmd);
        model::parse_liggghts_model(&mut ma, &mut spec)?;
        a.pos += end;
        let kind = a.word("primitive or mesh")?;
        if kind.text == "mesh" {
            return Err(Error::unsupported(kind.span, "fix wall/gran ... mesh (triangle-mesh walls)"));
        }
        a.choice("keyword", &["type"])?;
        let wt = a.i64("wall type")?;
        if wt < 1 || wt as usize > s.sim.ntypes {
            return Err(a.err_prev(format!("wall type {wt} out of range 1..{}", s.sim.ntypes)));
        }
        let words = a.rest().to_vec();
        let (wall, used) = PrimitiveWall::parse_liggghts(cmd, &words)?;
        a.pos += used;
        while a.more() {
            let k = a.word("keyword")?;
            match k.text.as_str() {
                // LIGGGHTS 3.8 takes model keywords after the geometry too
                "tangential_damping" => spec.tangential_damping = a.yes_no("tangential_damping")?,
                "limitForce" => spec.limit_damping = a.yes_no("limitForce")?,
                "shear" | "store_force" | "store_force_contact" | "temperature" | "track_energy" | "contact_area" => {
                    return Err(Error::unsupported(k.span, format!("fix wall/gran keyword {}", k.text)))
                }
                _ => return Err(Error::deck(k.span, format!("fix wall/gran: unknown keyword '{}'", k.text))),
            }
        }
        let table = model::fill_table(s, &spec, cmd.span)?;
        spec.has_coeff = true;
        (spec, table, wt as u32, wall, WallMotion::None)
    } else {
        s.set_dialect(Dialect::Lammps);
        let mut spec = PairSpec::new(cmd.span, true);
        // 2012-era LAMMPS: `fix wall/gran Kn Kt gn gt xmu dampflag wallstyle ...`
        // takes its force style from the pair style.
        let legacy = super::args::parse_f64(first).is_ok();
        let style_name: String = if legacy {
            a.pos -= 1;
            match s.pair.as_ref().map(|p| p.normal) {
                Some(NormalSpec::GranHertz) => "hertz/history".into(),
                Some(NormalSpec::GranHooke) if s.pair.as_ref().map(|p| p.tangential) == Some(TangentialSpec::GranNoHistory) => "hooke".into(),
                Some(NormalSpec::GranHooke) => "hooke/history".into(),
                _ => {
                    return Err(Error::deck(first.span, "fix wall/gran without a force style needs a gran/* pair style defined first")
                        .with_hint("write the style explicitly, e.g. `fix ID all wall/gran hooke/history Kn Kt gn gt xmu dampflag zplane lo hi`"))
                }
            }
        } else {
            first.text.clone()
        };
        match style_name.as_str() {
            "hooke" | "hooke/history" | "hertz/history" => {
                let kn = a.f64("Kn")?;
                let ktw = a.word("Kt")?;
                let gn = a.f64("gamma_n")?;
                let gtw = a.word("gamma_t")?;
                let xmu = a.f64("xmu")?;
                let damp = a.i64("dampflag")?;
                let kt = if ktw.text == "NULL" { 2.0 / 7.0 * kn } else { super::args::parse_f64(ktw)? };
                let gt = if gtw.text == "NULL" { 0.5 * gn } else { super::args::parse_f64(gtw)? };
                if a.peek().map(|w| w.text == "limit_damping").unwrap_or(false) {
                    a.pos += 1;
                    spec.limit_damping = true;
                }
                spec.gran = Some([kn, kt, gn, if damp == 0 { 0.0 } else { gt }, xmu]);
                spec.tangential_damping = damp == 1;
                spec.normal = if style_name == "hertz/history" { NormalSpec::GranHertz } else { NormalSpec::GranHooke };
                spec.tangential = if style_name == "hooke" { TangentialSpec::GranNoHistory } else { TangentialSpec::GranHistory };
            }
            "granular" => return Err(Error::unsupported(first.span, "fix wall/gran granular")),
            _ => {
                return Err(super::args::bad_keyword(first, "wall/gran style", &["model", "hooke", "hooke/history", "hertz/history", "granular"])
                    .with_hint("LIGGGHTS 2.x `wall/gran/hertz/history` forms are converted by `demx convert`"))
            }
        }
        let words = a.rest().to_vec();
        let (wall, motion, used) = PrimitiveWall::parse_lammps(cmd, &words)?;
        a.pos += used;
        while a.more() {
            let k = a.word("keyword")?;
            if k.text == "contacts" {
                continue;
            }
            return Err(Error::deck(k.span, format!("fix wall/gran: unknown keyword '{}'", k.text)));
        }
        spec.has_coeff = true;
        let table = model::fill_table(s, &spec, cmd.span)?;
        (spec, table, 1, wall, motion)
    };
    let _ = style;
    let kernel = model::build_kernel(&spec)?;
    let width = kernel.history_width();
    let summary = format!("wall/gran {} ({:?}): {}", id, wall, spec.summary());
    s.walls.push(summary.clone());
    let t0 = s.sim.time;
    s.add_fix(Box::new(WallGran {
        id: id.to_string(),
        group,
        wall,
        motion,
        kernel,
        table,
        wall_type,
        width,
        hist_name: format!("wall_history:{id}"),
        summary,
        t0,
        in_setup: false,
    }))
}

