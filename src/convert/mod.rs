//! `demx convert`: legacy LIGGGHTS decks to current syntax, and LIGGGHTS <->
//! LAMMPS granular dialects (not implemented yet).

use std::process::ExitCode;

/// Entry point: `args` are the words after `convert`.
pub fn cli(args: Vec<String>) -> ExitCode {
    let _ = args;
    eprintln!("error: demx convert is not implemented yet");
    ExitCode::from(3)
}
