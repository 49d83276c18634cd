//! Deck text -> commands: the LAMMPS/LIGGGHTS input language.
//!
//! Responsibility: read files, join `&` continuations, strip `#` comments,
//! substitute `$x`, `${name}` and `$(expr)`, split words (single, double and
//! triple quotes), and run the script-level commands itself (`variable`,
//! `next`, `label`, `jump`, `include`, `if`, `print`, `log`, `echo`, `quit`,
//! the `every` form of `run`). Every other command is handed, fully
//! substituted, to a [`Host`] (the simulation) as a [`Command`] whose words
//! keep the spans of the text the person wrote.
//!
//! The host is also the [`EvalContext`] of expressions: thermo keywords,
//! `c_ID`, `f_ID`, `x[5]`, group functions and per-atom vectors come from it.

pub mod expr;
pub mod interp;
pub mod lexer;
pub mod source;
pub mod vars;

pub use interp::Interpreter;
pub use source::{FileId, SourceMap, Span};
pub use vars::Variables;

use crate::error::Result;

/// One word of a command after substitution and quote removal.
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    /// The text (quotes removed).
    pub text: String,
    /// Where it came from in the original text. For words produced by a
    /// substitution, the span of the `$` reference.
    pub span: Span,
    /// Whether the word was quoted.
    pub quoted: bool,
}

impl Word {
    /// A word from text and span.
    pub fn new(text: impl Into<String>, span: Span) -> Word {
        Word { text: text.into(), span, quoted: false }
    }
    /// The text.
    pub fn as_str(&self) -> &str {
        &self.text
    }
}

/// A command ready to execute: name and arguments.
#[derive(Clone, Debug, PartialEq)]
pub struct Command {
    /// `words[0]` is the command name.
    pub words: Vec<Word>,
    /// Span of the whole logical line.
    pub span: Span,
}

impl Command {
    /// The command name (first word).
    pub fn name(&self) -> &str {
        self.words.first().map(|w| w.text.as_str()).unwrap_or("")
    }
    /// The arguments after the name.
    pub fn args(&self) -> &[Word] {
        if self.words.is_empty() {
            &[]
        } else {
            &self.words[1..]
        }
    }
    /// The command as text (words joined by spaces), for echo and logs.
    pub fn text(&self) -> String {
        self.words.iter().map(|w| w.text.as_str()).collect::<Vec<_>>().join(" ")
    }
}

/// Values expressions can read from the simulation. Every method has a
/// default that reports the value as unavailable, so a context without a
/// simulation (unit tests, `demx check` before a box exists) is trivial.
pub trait EvalContext {
    /// A thermo keyword (`step`, `elapsed`, `time`, `dt`, `atoms`, `ke`,
    /// `cpu`, `vol`, `lx`, `xlo`, ...). `None` if unknown.
    fn thermo(&self, _name: &str) -> Option<f64> {
        None
    }
    /// `c_ID` (index `None`), `c_ID[i]` or `c_ID[i][j]` (1-based) of a global compute.
    fn compute(&self, id: &str, _i: Option<usize>, _j: Option<usize>) -> std::result::Result<f64, String> {
        Err(format!("compute {id} is not available here"))
    }
    /// `f_ID`, `f_ID[i]`, `f_ID[i][j]` of a fix.
    fn fix(&self, id: &str, _i: Option<usize>, _j: Option<usize>) -> std::result::Result<f64, String> {
        Err(format!("fix {id} is not available here"))
    }
    /// A per-atom value of one atom by id: `x[5]`, `vx[1]`, `mass[3]`, `radius[2]`...
    fn atom_value(&self, keyword: &str, id: i64) -> std::result::Result<f64, String> {
        Err(format!("atom value {keyword}[{id}] is not available here"))
    }
    /// Group functions: `count(g)`, `mass(g)`, `xcm(g,dim)`, `vcm(g,dim)`,
    /// `ke(g)`, `bound(g,xmin)`, ... `args` are the words inside the parentheses.
    fn group_function(&self, name: &str, _args: &[&str]) -> std::result::Result<f64, String> {
        Err(format!("group function {name}() is not available here"))
    }
    /// Number of local atoms, for atom-style variables.
    fn natoms(&self) -> usize {
        0
    }
    /// A per-atom vector for atom-style variables: `x`, `vx`, `fx`, `mass`,
    /// `radius`, `type`, `id`, `omegax`, ... in storage order.
    fn atom_vector(&self, keyword: &str) -> std::result::Result<Vec<f64>, String> {
        Err(format!("per-atom value {keyword} is not available here"))
    }
    /// First and last step of the current run (`run N start S stop E` bounds),
    /// for `ramp()`, `vdisplace()`, `swiggle()`, `cwiggle()`. `None` outside a run.
    fn run_bounds(&self) -> Option<(i64, i64)> {
        None
    }
    /// Per-atom vector of a compute or fix (`c_ID`, `c_ID[i]`, `f_ID[i]`).
    fn peratom(&self, prefix: char, id: &str, _col: Option<usize>) -> std::result::Result<Vec<f64>, String> {
        Err(format!("per-atom {prefix}_{id} is not available here"))
    }
}

/// A context with no simulation.
pub struct NoContext;
impl EvalContext for NoContext {}

/// The simulation side of the interpreter.
pub trait Host: EvalContext {
    /// Execute one command that is not a script-level command.
    /// `vars` is the interpreter's variable store, for commands that evaluate
    /// variables while they run (thermo, fix print, fix addforce v_...).
    fn execute(&mut self, cmd: &Command, vars: &mut Variables) -> Result<()>;
    /// Text for the screen and the log file (`print`, `echo`, thermo).
    fn output(&mut self, text: &str);
    /// The `log` command: switch the log file (`append` for `log file append`),
    /// `None` for `log none`.
    fn set_log(&mut self, path: Option<&str>, append: bool, span: Span) -> Result<()>;
    /// Whether to write a checkpoint before the deck's `run` line about to
    /// execute (`demx run --checkpoint`).
    fn checkpoint_due(&mut self) -> bool {
        false
    }
    /// Write a checkpoint: the host's state with the interpreter's `saved`.
    /// Returns true when the run is to stop there (a stop was asked for).
    fn checkpoint(&mut self, _saved: &interp::SavedInterpreter) -> Result<bool> {
        Ok(false)
    }
}
