//! `demx repose` (not implemented yet).

use std::process::ExitCode;

/// Entry point: `args` are the words after the subcommand name.
pub fn cli(args: Vec<String>) -> ExitCode {
    let _ = args;
    eprintln!("error: demx repose is not implemented yet");
    ExitCode::from(3)
}
