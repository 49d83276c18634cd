//! Variables (stub; the full implementation replaces this file).
use super::EvalContext;
/// The variable store.
#[derive(Default, Debug, Clone)]
pub struct Variables {}
impl Variables {
    /// Evaluate an equal-style variable.
    pub fn eval_equal(&self, name: &str, _ctx: &dyn EvalContext) -> Result<f64, String> {
        Err(format!("variable {name} is not defined"))
    }
    /// Evaluate an atom-style variable.
    pub fn eval_atom(&self, name: &str, _ctx: &dyn EvalContext) -> Result<Vec<f64>, String> {
        Err(format!("variable {name} is not defined"))
    }
}
impl Variables {
    /// Substitute `$x`, `${name}`, `$(expr)` in a text at run time (fix print).
    pub fn substitute_text(&self, text: &str, _ctx: &dyn EvalContext) -> Result<String, String> {
        Ok(text.to_string())
    }
}
