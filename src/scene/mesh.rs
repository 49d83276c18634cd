//! Triangle-mesh walls and region walls: fix mesh/surface, mesh/surface/planar,
//! move/mesh, wall/gran ... mesh, LAMMPS wall/gran/region. (In progress.)

use super::args::Args;
use super::Session;
use crate::error::{Error, Result};
use crate::script::{Command, Variables, Word};

/// Parse a mesh- or region-wall fix.
pub fn fix(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args, vars: &mut Variables) -> Result<()> {
    let _ = (s, cmd, id, group, a, vars);
    Err(Error::unsupported(style.span, format!("fix {}", style.text)))
}
