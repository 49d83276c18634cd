//! Every fix style demx knows, each declared once in [`FIX_STYLES`]: the
//! scene's `fix` dispatch, the did-you-mean of an unknown style and the
//! lists of styles that run and that do not yet are read from it. Adding a
//! fix style is one line here plus its parser (in the module the line
//! names) and its runtime (`impl Fix`, in `engine/` where it is more than a
//! few lines).

use super::args::Args;
use super::{fixes, Session};
use crate::error::{Error, Result};
use crate::script::{Command, Variables, Word};

/// The words of one `fix ID group style args` command the handler gets.
pub struct FixCall<'a> {
    /// The whole command.
    pub cmd: &'a Command,
    /// The fix id.
    pub id: &'a str,
    /// The group's bit.
    pub group: u32,
    /// The style word.
    pub style: &'a Word,
}

/// Parses a fix's arguments (after the style) and adds it to the scene.
pub type Handler = fn(&mut Session, &FixCall<'_>, &mut Args, &mut Variables) -> Result<()>;

/// How demx treats a fix style.
#[derive(Clone, Copy)]
pub enum FixKind {
    /// Parsed by the handler (its module's `fix` function matches the style
    /// for the details) and run.
    Runs(Handler),
    /// A style of LIGGGHTS 3.8 or LAMMPS demx does not run yet: exit 3
    /// naming it, with the hint when there is one.
    Unsupported(&'static str),
}

/// One fix style.
pub struct FixStyleDef {
    /// Its name in a deck.
    pub name: &'static str,
    /// How demx treats it.
    pub kind: FixKind,
}

macro_rules! fix_styles {
    ($($name:literal => $kind:expr,)*) => {
        /// Every fix style demx knows.
        pub const FIX_STYLES: &[FixStyleDef] = &[$(FixStyleDef { name: $name, kind: $kind },)*];
    };
}

use FixKind::{Runs, Unsupported};

/// Not yet, without a hint.
const NOT_YET: FixKind = Unsupported("");
/// The simple fixes of `scene/fixes.rs` (integration, forces, output).
const SIMPLE: FixKind = Runs(simple);
/// Model properties and checks (`scene/model.rs`).
const MODEL: FixKind = Runs(|s, c, a, _| super::model::fix_command(s, c.cmd, c.id, c.style, a));
/// Meshes and region walls (`scene/mesh.rs`).
const MESH: FixKind = Runs(|s, c, a, v| super::mesh::fix(s, c.cmd, c.id, c.group, c.style, a, v));
/// Insertion, templates, distributions, growth (`scene/insert.rs`).
const INSERT: FixKind = Runs(|s, c, a, v| super::insert::fix(s, c.cmd, c.id, c.group, c.style, a, v));
/// Heat conduction (`scene/heat.rs`).
const HEAT: FixKind = Runs(|s, c, a, _| super::heat::fix(s, c.cmd, c.id, c.group, c.style, a));

fix_styles! {
    // integration, forces, output
    "nve/sphere" => SIMPLE, "nve" => SIMPLE, "gravity" => SIMPLE, "freeze" => SIMPLE, "addforce" => SIMPLE,
    "setforce" => SIMPLE, "viscous" => SIMPLE, "print" => SIMPLE, "ave/time" => SIMPLE,
    "balance" => Runs(balance),
    // material properties and checks
    "property/global" => MODEL, "property/atom" => MODEL, "check/timestep/gran" => MODEL, "enforce2d" => MODEL,
    "momentum" => MODEL,
    // walls and meshes
    "wall/gran" => Runs(wall_gran), "wall/gran/region" => MESH, "mesh/surface" => MESH,
    "mesh/surface/planar" => MESH, "mesh/surface/stress" => MESH, "move/mesh" => MESH,
    "massflow/mesh" => Runs(super::massflow::fix),
    // particles in
    "particletemplate/sphere" => INSERT, "particledistribution/discrete" => INSERT,
    "particledistribution/discrete/numberbased" => INSERT, "particledistribution/discrete/massbased" => INSERT,
    "insert/pack" => INSERT, "insert/rate/region" => INSERT, "insert/stream" => INSERT, "pour" => INSERT,
    "adapt" => INSERT,
    // the wind and heat
    "aeolian/wind" => Runs(|s, c, a, v| super::wind::fix(s, c.cmd, c.id, c.group, c.style, a, v)),
    "heat/gran" => HEAT, "heat/gran/conduction" => HEAT,
    // not yet
    "particletemplate/multisphere" => Unsupported("only spheres are supported"),
    "particletemplate/superquadric" => Unsupported("only spheres are supported"),
    "particletemplate/multiplespheres" => Unsupported("only spheres are supported"),
    "insert/stream/predefined" => NOT_YET, "mesh/surface/stress/servo" => NOT_YET, "couple/cfd" => NOT_YET,
    "couple/cfd/force" => NOT_YET, "couple/cfd/force/implicit" => NOT_YET, "multisphere" => NOT_YET,
    "ave/euler" => NOT_YET, "property/atom/tracer" => NOT_YET,
    "property/atom/tracer/stream" => NOT_YET, "wall/region/sph" => NOT_YET, "insert/pack/dense" => NOT_YET,
    "nve/sphere/omp" => NOT_YET, "ave/chunk" => NOT_YET, "ave/atom" => NOT_YET, "ave/histo" => NOT_YET,
    "ave/correlate" => NOT_YET, "deform" => NOT_YET, "rigid" => NOT_YET, "rigid/small" => NOT_YET,
    "spring" => NOT_YET, "langevin" => NOT_YET, "nvt" => NOT_YET, "npt" => NOT_YET, "nph" => NOT_YET,
    "wall/reflect" => NOT_YET, "wall/region" => NOT_YET, "store/state" => NOT_YET, "heat/flow" => NOT_YET,
    "temp/rescale" => NOT_YET, "dt/reset" => NOT_YET, "python/invoke" => NOT_YET, "wiggle/mesh" => NOT_YET,
    "mesh/gran" => NOT_YET, "recenter" => NOT_YET, "setforce/region" => NOT_YET, "lineforce" => NOT_YET,
    "planeforce" => NOT_YET, "efield" => NOT_YET, "wall/lj93" => NOT_YET, "nve/limit" => NOT_YET,
    "nve/asphere" => NOT_YET, "bond/create" => NOT_YET, "bond/break" => NOT_YET,
    "wall/gran/hertz/history" => NOT_YET, "wall/gran/hooke/history" => NOT_YET, "wall/gran/hooke" => NOT_YET,
    "pour/legacy" => NOT_YET, "pour/dev" => NOT_YET, "move/mesh/gran" => NOT_YET, "heat/radiation" => NOT_YET,
    "nve/superquadric" => NOT_YET, "contactproperty/atom" => NOT_YET, "contacthistory" => NOT_YET,
    "sph" => NOT_YET, "diam/max" => NOT_YET, "box/relax" => NOT_YET, "viscous/sphere" => NOT_YET,
    "damping/cundall" => NOT_YET, "wall/gran/old" => NOT_YET,
}

/// The fix style named `name`.
pub fn find(name: &str) -> Option<&'static FixStyleDef> {
    FIX_STYLES.iter().find(|f| f.name == name)
}

/// Parse `fix ID group style args` with the style's handler, or say why not.
pub fn dispatch(s: &mut Session, c: &FixCall<'_>, a: &mut Args, vars: &mut Variables) -> Result<()> {
    let t = c.style.text.as_str();
    match find(t).map(|f| f.kind) {
        Some(Runs(h)) => h(s, c, a, vars),
        Some(Unsupported("")) => Err(Error::unsupported(c.style.span, format!("fix {t}"))),
        Some(Unsupported(hint)) => Err(Error::unsupported(c.style.span, format!("fix {t} ({hint})"))),
        None => {
            let mut e = Error::deck(c.style.span, format!("unknown fix style '{t}'"));
            if let Some(h) = crate::error::did_you_mean(t, FIX_STYLES.iter().map(|f| f.name)) {
                e = e.with_hint(format!("did you mean '{h}'?"));
            }
            Err(e)
        }
    }
}

fn simple(s: &mut Session, c: &FixCall<'_>, a: &mut Args, _: &mut Variables) -> Result<()> {
    match fixes::parse_simple(&s.sim, c.id, c.group, &c.style.text, a, c.cmd)? {
        Some(f) => s.add_fix(f),
        None => Err(Error::unsupported(c.style.span, format!("fix {}", c.style.text))),
    }
}

/// LAMMPS `fix ID group balance Nfreq thresh style args ...`: how MPI ranks
/// share the box, nothing a single process does; kept under its id.
fn balance(s: &mut Session, c: &FixCall<'_>, a: &mut Args, _: &mut Variables) -> Result<()> {
    a.i64("Nfreq")?;
    a.f64("thresh")?;
    a.choice("balance style", &["shift", "rcb"])?;
    s.notes.push((c.cmd.span, "fix balance: accepted; changes nothing in demx (single process, deterministic threads)".into()));
    s.add_fix(Box::new(fixes::Noop { id: c.id.to_string(), style: c.style.text.clone() }))
}

/// `fix wall/gran`: a primitive wall (`scene/walls.rs`) or, with `mesh`, a
/// mesh wall (`scene/mesh.rs`).
fn wall_gran(s: &mut Session, c: &FixCall<'_>, a: &mut Args, v: &mut Variables) -> Result<()> {
    if a.rest().iter().any(|w| w.text == "mesh") {
        super::mesh::fix(s, c.cmd, c.id, c.group, c.style, a, v)
    } else {
        super::walls::wall_gran(s, c.cmd, c.id, c.group, c.style, a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_fix_style_is_declared_once() {
        for (k, f) in FIX_STYLES.iter().enumerate() {
            assert!(FIX_STYLES[..k].iter().all(|g| g.name != f.name), "{} declared twice", f.name);
        }
    }
}
