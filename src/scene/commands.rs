//! The commands a deck may give, each declared once in [`COMMANDS`]: the
//! scene's dispatch, the did-you-mean of an unknown command and the lists
//! of supported, accepted and not-yet-supported commands are read from it.
//! Adding a command is one line here (plus its handler).

use super::{restart, setup, Session};
use crate::error::Result;
use crate::script::{Command, Variables};

/// A scene handler: runs one command.
pub type Handler = fn(&mut Session, &Command, &mut Variables) -> Result<()>;

/// How demx treats a command.
#[derive(Clone, Copy)]
pub enum Kind {
    /// Run by the scene.
    Scene(Handler),
    /// Run by the script interpreter (variables, control flow, files of
    /// commands, text output); it never reaches the scene.
    Script,
    /// Accepted with a note; changes nothing in demx (it tunes MPI,
    /// communication or memory, which a single process with deterministic
    /// threads does not have).
    Noop,
    /// Known to LAMMPS or LIGGGHTS, not yet to demx: exit 3, naming it.
    Unsupported,
}

/// One command.
pub struct CommandDef {
    /// Its name in a deck.
    pub name: &'static str,
    /// How demx treats it.
    pub kind: Kind,
}

macro_rules! commands {
    ($($name:literal => $kind:expr,)*) => {
        /// Every command demx knows, in the order of a deck's sections.
        pub const COMMANDS: &[CommandDef] = &[$(CommandDef { name: $name, kind: $kind },)*];
    };
}

use Kind::{Noop, Script, Unsupported};

const SETUP: Kind = Kind::Scene(setup::execute);
const RESTART: Kind = Kind::Scene(restart::execute);
const OUTPUT: Kind = Kind::Scene(super::outputs::execute);

commands! {
    // the script language
    "variable" => Script, "print" => Script, "include" => Script, "jump" => Script, "label" => Script,
    "next" => Script, "if" => Script, "log" => Script, "echo" => Script, "quit" => Script,
    // the box, the atoms, the settings
    "units" => SETUP, "atom_style" => SETUP, "boundary" => SETUP, "dimension" => SETUP,
    "neighbor" => SETUP, "neigh_modify" => SETUP, "timestep" => Kind::Scene(Session::timestep_command),
    "hard_particles" => SETUP, "soft_particles" => SETUP, "region" => SETUP, "create_box" => SETUP,
    "lattice" => SETUP, "create_atoms" => SETUP, "group" => SETUP, "set" => SETUP, "velocity" => SETUP,
    "delete_atoms" => SETUP, "displace_atoms" => SETUP, "reset_timestep" => SETUP, "mass" => SETUP,
    "change_box" => SETUP,
    "atom_modify" => Kind::Scene(Session::atom_modify),
    // files of state
    "read_data" => RESTART, "write_data" => RESTART, "read_restart" => RESTART, "write_restart" => RESTART,
    "restart" => RESTART,
    // the contact model, fixes, outputs
    "pair_style" => Kind::Scene(|s, c, _| super::model::execute(s, c)),
    "pair_coeff" => Kind::Scene(|s, c, _| super::model::execute(s, c)),
    "fix" => Kind::Scene(Session::fix_command), "unfix" => Kind::Scene(Session::fix_command),
    "compute" => OUTPUT, "uncompute" => OUTPUT, "compute_modify" => Kind::Scene(|s, c, _| s.compute_modify(c)),
    "thermo" => OUTPUT, "thermo_style" => OUTPUT, "thermo_modify" => OUTPUT,
    "dump" => OUTPUT, "dump_modify" => OUTPUT, "undump" => OUTPUT, "write_dump" => OUTPUT,
    // running
    "run" => Kind::Scene(Session::run_command), "run_style" => Kind::Scene(Session::run_style),
    "demx_guard" => Kind::Scene(|s, c, _| s.guard_command(c)),
    "shell" => Kind::Scene(|s, c, _| super::shell::execute(s, c)),
    // MPI, communication and memory
    "processors" => Noop, "communicate" => Noop, "comm_modify" => Noop, "comm_style" => Noop,
    "newton" => Noop, "partition" => Noop, "package" => Noop, "suffix" => Noop, "balance" => Noop,
    "sort" => Noop, "timer" => Noop, "kspace_style" => Noop, "special_bonds" => Noop, "thermo_log" => Noop,
    "modify_timing" => Noop,
    // not yet
    "minimize" => Unsupported, "min_style" => Unsupported, "min_modify" => Unsupported, "rerun" => Unsupported,
    "read_dump" => Unsupported, "replicate" => Unsupported, "create_bonds" => Unsupported,
    "bond_style" => Unsupported, "bond_coeff" => Unsupported, "angle_style" => Unsupported,
    "angle_coeff" => Unsupported, "molecule" => Unsupported, "kspace_modify" => Unsupported,
    "python" => Unsupported, "fix_modify" => Unsupported, "region_modify" => Unsupported, "info" => Unsupported,
    "clear" => Unsupported, "write_coeff" => Unsupported, "pair_modify" => Unsupported,
    "reset_atom_ids" => Unsupported, "delete_bonds" => Unsupported,
}

/// The command named `name`.
pub fn find(name: &str) -> Option<&'static CommandDef> {
    COMMANDS.iter().find(|c| c.name == name)
}

/// The names of the commands of one kind (`Scene` for all that run).
pub fn names(pick: fn(&Kind) -> bool) -> impl Iterator<Item = &'static str> {
    COMMANDS.iter().filter(move |c| pick(&c.kind)).map(|c| c.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_command_is_declared_once() {
        for (k, c) in COMMANDS.iter().enumerate() {
            assert!(COMMANDS[..k].iter().all(|d| d.name != c.name), "{} declared twice", c.name);
        }
    }
}
