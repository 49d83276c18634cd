//! The interpreter: drives a deck through a [`super::Host`].
use super::{Host, SourceMap, Variables};
use crate::error::Result;
use std::path::Path;

/// Runs deck files command by command.
pub struct Interpreter {
    /// The variable store.
    pub vars: Variables,
    /// All files read.
    pub sources: SourceMap,
}

impl Interpreter {
    /// A new interpreter with `-var` variables from the command line.
    pub fn new(sources: SourceMap, cli_vars: Vec<(String, Vec<String>)>) -> Interpreter {
        let _ = cli_vars;
        Interpreter { vars: Variables::default(), sources }
    }
    /// Run a deck file to its end (or `quit`).
    pub fn run_file(&mut self, path: &Path, host: &mut dyn Host) -> Result<()> {
        let _ = (path, host);
        Ok(())
    }
}
