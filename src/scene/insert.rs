//! Particle insertion: LIGGGHTS particletemplate/sphere,
//! particledistribution/discrete, insert/pack, insert/rate/region,
//! insert/stream; LAMMPS fix pour. (In progress.)

use super::args::Args;
use super::Session;
use crate::error::{Error, Result};
use crate::script::{Command, Variables, Word};

/// Parse an insertion-related fix.
pub fn fix(s: &mut Session, cmd: &Command, id: &str, group: u32, style: &Word, a: &mut Args, vars: &mut Variables) -> Result<()> {
    let _ = (s, cmd, id, group, a, vars);
    Err(Error::unsupported(style.span, format!("fix {}", style.text)))
}
