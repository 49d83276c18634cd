//! The variable store: the `variable` and `next` commands, substitution
//! values, and evaluation of equal-style and atom-style formulas.
//!
//! Semantics follow LAMMPS (29 Sep 2021):
//! - `index`, `loop`, `world`, `universe` and `uloop` variables that already
//!   exist are left unchanged when defined again (so `-var NAME ...` on the
//!   command line overrides a deck's `variable NAME index ...`);
//! - `string`, `getenv`, `format`, `equal`, `atom` and `internal` may be
//!   redefined, but only with the same style (else an error);
//! - `next` advances; a variable that runs out of values is deleted and the
//!   interpreter skips the following `jump`;
//! - `${v}` of an equal-style variable is formatted `%.15g`, `$(expr)` `%.20g`.
//!
//! Formulas are compiled once when the variable is defined.

use super::expr::{self, apply_bin, apply_math, apply_step_fn, Expr};
use super::{Command, EvalContext, Span, Word};
use crate::error::{did_you_mean, Error, Result};
use crate::io::cfmt;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Style of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum VarStyle {
    /// `index v1 v2 ...`
    Index,
    /// `loop N` / `loop N1 N2` (optionally `pad`)
    Loop,
    /// `world v` (one partition)
    World,
    /// `universe v1 v2 ...`
    Universe,
    /// `uloop N`
    Uloop,
    /// `string text`
    String,
    /// `getenv NAME`
    Getenv,
    /// `format var fmt`
    Format,
    /// `equal formula`
    Equal,
    /// `atom formula`
    Atom,
    /// `internal value` (set by commands such as fix adapt or by the host)
    Internal,
}

impl VarStyle {
    /// The keyword of the style.
    pub fn keyword(self) -> &'static str {
        match self {
            VarStyle::Index => "index",
            VarStyle::Loop => "loop",
            VarStyle::World => "world",
            VarStyle::Universe => "universe",
            VarStyle::Uloop => "uloop",
            VarStyle::String => "string",
            VarStyle::Getenv => "getenv",
            VarStyle::Format => "format",
            VarStyle::Equal => "equal",
            VarStyle::Atom => "atom",
            VarStyle::Internal => "internal",
        }
    }
    /// Whether `next` may advance this style.
    pub fn is_list(self) -> bool {
        matches!(self, VarStyle::Index | VarStyle::Loop | VarStyle::World | VarStyle::Universe | VarStyle::Uloop)
    }
}

#[derive(Clone, Debug)]
enum Data {
    List { values: Vec<String>, which: usize },
    Loop { first: i64, last: i64, which: i64, pad: usize },
    Str(String),
    Getenv(String),
    Format { var: String, fmt: String },
    Formula { text: String, expr: Arc<Expr> },
    Internal(f64),
}

/// A variable's definition and position, as a checkpoint keeps it (a
/// formula by its text, compiled again when restored).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
enum SavedData {
    List { values: Vec<String>, which: usize },
    Loop { first: i64, last: i64, which: i64, pad: usize },
    Str(String),
    Getenv(String),
    Format { var: String, fmt: String },
    Formula(String),
    Internal(f64),
}

/// The whole variable store as a checkpoint keeps it: every variable with
/// its position in its list, and the state of `random()`/`normal()`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SavedVariables {
    vars: Vec<(String, VarStyle, SavedData)>,
    rng: Option<u64>,
}

#[derive(Clone, Debug)]
struct Var {
    style: VarStyle,
    data: Data,
}

/// Cache of compiled immediate formulas (`$(...)`, `eval_expr`).
#[derive(Default)]
struct ExprCache(Mutex<HashMap<String, Arc<Expr>>>);

impl Clone for ExprCache {
    fn clone(&self) -> Self {
        ExprCache::default()
    }
}
impl std::fmt::Debug for ExprCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ExprCache")
    }
}

/// State of the generator behind `random()` and `normal()`.
#[derive(Default, Debug)]
struct Rng(Mutex<Option<u64>>);
impl Clone for Rng {
    fn clone(&self) -> Self {
        Rng(Mutex::new(self.0.lock().map(|g| *g).unwrap_or(None)))
    }
}

impl Rng {
    /// Uniform in (0,1); seeded by `seed` on first use (as LAMMPS seeds once).
    fn uniform(&self, seed: f64) -> std::result::Result<f64, String> {
        if seed.is_nan() || seed < 1.0 {
            return Err("invalid seed for random()/normal() in variable formula (must be > 0)".into());
        }
        let mut g = self.0.lock().map_err(|_| "random generator poisoned".to_string())?;
        let mut s = g.unwrap_or(seed as u64 ^ 0x9E37_79B9_7F4A_7C15);
        // splitmix64
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        *g = Some(s);
        Ok(((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64)
    }
}

/// The variable store.
#[derive(Default, Debug, Clone)]
pub struct Variables {
    vars: HashMap<String, Var>,
    cache: ExprCache,
    rng: Rng,
}

/// A value during evaluation: scalar or per-atom vector.
#[derive(Clone, Debug)]
enum Val {
    S(f64),
    V(Vec<f64>),
}

/// How deep evaluation may recurse (formula nesting plus variables referring
/// to variables) before it is called circular; keeps the stack bounded.
const MAX_DEPTH: usize = 1500;

fn valid_name(name: &str) -> bool {
    !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

fn parse_int(w: &Word) -> Result<i64> {
    w.text.parse::<i64>().map_err(|_| Error::deck(w.span, format!("expected an integer, got '{}'", w.text)))
}

impl Variables {
    /// An empty store.
    pub fn new() -> Variables {
        Variables::default()
    }

    /// Everything the store holds, for a checkpoint (sorted by name, so the
    /// same store gives the same text).
    pub fn save(&self) -> SavedVariables {
        let mut vars: Vec<(String, VarStyle, SavedData)> = self
            .vars
            .iter()
            .map(|(name, v)| {
                let data = match &v.data {
                    Data::List { values, which } => SavedData::List { values: values.clone(), which: *which },
                    Data::Loop { first, last, which, pad } => SavedData::Loop { first: *first, last: *last, which: *which, pad: *pad },
                    Data::Str(s) => SavedData::Str(s.clone()),
                    Data::Getenv(s) => SavedData::Getenv(s.clone()),
                    Data::Format { var, fmt } => SavedData::Format { var: var.clone(), fmt: fmt.clone() },
                    Data::Formula { text, .. } => SavedData::Formula(text.clone()),
                    Data::Internal(x) => SavedData::Internal(*x),
                };
                (name.clone(), v.style, data)
            })
            .collect();
        vars.sort_by(|a, b| a.0.cmp(&b.0));
        SavedVariables { vars, rng: self.rng.0.lock().map(|g| *g).unwrap_or(None) }
    }

    /// The store a checkpoint kept ([`Variables::save`]).
    pub fn restore(saved: &SavedVariables) -> std::result::Result<Variables, String> {
        let mut out = Variables::default();
        for (name, style, data) in &saved.vars {
            let data = match data {
                SavedData::List { values, which } => Data::List { values: values.clone(), which: *which },
                SavedData::Loop { first, last, which, pad } => Data::Loop { first: *first, last: *last, which: *which, pad: *pad },
                SavedData::Str(s) => Data::Str(s.clone()),
                SavedData::Getenv(s) => Data::Getenv(s.clone()),
                SavedData::Format { var, fmt } => Data::Format { var: var.clone(), fmt: fmt.clone() },
                SavedData::Formula(text) => {
                    let e = expr::parse(text).map_err(|m| format!("variable {name}: {m}"))?;
                    Data::Formula { text: text.clone(), expr: Arc::new(e) }
                }
                SavedData::Internal(x) => Data::Internal(*x),
            };
            out.vars.insert(name.clone(), Var { style: *style, data });
        }
        out.rng = Rng(Mutex::new(saved.rng));
        Ok(out)
    }

    /// The style of a variable, `None` if it is not defined.
    pub fn style(&self, name: &str) -> Option<VarStyle> {
        self.vars.get(name).map(|v| v.style)
    }

    /// Whether a variable is defined.
    pub fn is_defined(&self, name: &str) -> bool {
        self.vars.contains_key(name)
    }

    /// Names of all defined variables (sorted), for hints.
    pub fn names(&self) -> Vec<&str> {
        let mut v: Vec<&str> = self.vars.keys().map(|s| s.as_str()).collect();
        v.sort_unstable();
        v
    }

    /// Whether some formula variable reads one of the thermo keywords
    /// `names` (as a bare word of its formula).
    pub fn reads_thermo(&self, names: &[&str]) -> bool {
        fn reads(e: &Expr, names: &[&str]) -> bool {
            match e {
                Expr::Thermo(k) => names.contains(&k.as_str()),
                Expr::Neg(a) | Expr::Not(a) => reads(a, names),
                Expr::Bin(_, a, b) => reads(a, names) || reads(b, names),
                Expr::Func(_, args) => args.iter().any(|a| reads(a, names)),
                _ => false,
            }
        }
        self.vars.values().any(|v| matches!(&v.data, Data::Formula { expr, .. } if reads(expr, names)))
    }

    /// `" (did you mean 'x'?)"`-style hint text for an unknown name, if any.
    pub fn suggest(&self, name: &str) -> Option<String> {
        did_you_mean(name, self.vars.keys().map(|s| s.as_str())).map(|s| format!("did you mean '{s}'?"))
    }

    /// Define an index variable unless one of that name exists (what
    /// `-var NAME V1 V2 ...` on the command line does).
    pub fn define_index(&mut self, name: &str, values: Vec<String>) {
        if !self.vars.contains_key(name) && !values.is_empty() {
            self.vars.insert(name.to_string(), Var { style: VarStyle::Index, data: Data::List { values, which: 0 } });
        }
    }

    /// Set (creating if needed) an internal-style variable.
    pub fn set_internal(&mut self, name: &str, value: f64) {
        self.vars.insert(name.to_string(), Var { style: VarStyle::Internal, data: Data::Internal(value) });
    }

    /// Remove a variable (no-op if absent).
    pub fn delete(&mut self, name: &str) {
        self.vars.remove(name);
    }

    /// Execute a `variable` command (`cmd.words[0]` is `variable`).
    pub fn define(&mut self, cmd: &Command) -> Result<()> {
        let a = cmd.args();
        if a.len() < 2 {
            return Err(Error::deck(cmd.words.first().map_or(cmd.span, |w| w.span), "illegal variable command: expected 'variable NAME STYLE ...'"));
        }
        let name = a[0].text.as_str();
        let style_w = &a[1];
        let rest = &a[2..];
        if !valid_name(name) {
            return Err(Error::deck(a[0].span, format!("variable name '{name}' must be alphanumeric or underscore characters")));
        }
        let need = |n: usize| -> Result<()> {
            if rest.len() != n {
                let sp = rest.get(n).map_or(style_w.span, |w| w.span);
                Err(Error::deck(sp, format!("illegal variable command: style {} takes {} argument(s), got {}", style_w.text, n, rest.len())))
            } else {
                Ok(())
            }
        };
        let style = match style_w.text.as_str() {
            "delete" => {
                if !rest.is_empty() {
                    return Err(Error::deck(rest[0].span, "illegal variable command: delete takes no arguments"));
                }
                self.vars.remove(name);
                return Ok(());
            }
            "index" => VarStyle::Index,
            "loop" => VarStyle::Loop,
            "world" => VarStyle::World,
            "universe" => VarStyle::Universe,
            "uloop" => VarStyle::Uloop,
            "string" => VarStyle::String,
            "getenv" => VarStyle::Getenv,
            "format" => VarStyle::Format,
            "equal" => VarStyle::Equal,
            "atom" => VarStyle::Atom,
            "internal" => VarStyle::Internal,
            s @ ("python" | "file" | "atomfile" | "vector" | "timer") => {
                return Err(Error::unsupported(style_w.span, format!("variable style '{s}'")));
            }
            s => {
                let styles = [
                    "delete", "index", "loop", "world", "universe", "uloop", "string", "getenv", "format", "equal", "atom", "internal", "python",
                    "file", "atomfile", "vector", "timer",
                ];
                let e = Error::deck(style_w.span, format!("unknown variable style '{s}'"));
                return Err(match did_you_mean(s, styles) {
                    Some(h) => e.with_hint(format!("did you mean '{h}'?")),
                    None => e,
                });
            }
        };
        if let Some(old) = self.vars.get(name) {
            if style.is_list() {
                // exists: the command is ignored (command-line -var wins)
                return Ok(());
            }
            if old.style != style {
                return Err(Error::deck(
                    style_w.span,
                    format!("cannot redefine variable '{name}' as a different style ({} -> {})", old.style.keyword(), style.keyword()),
                ));
            }
        }
        let data = match style {
            VarStyle::Index | VarStyle::Universe => {
                if rest.is_empty() {
                    return Err(Error::deck(style_w.span, format!("illegal variable command: {} needs at least one value", style.keyword())));
                }
                Data::List { values: rest.iter().map(|w| w.text.clone()).collect(), which: 0 }
            }
            VarStyle::World => {
                need(1)?;
                Data::List { values: vec![rest[0].text.clone()], which: 0 }
            }
            VarStyle::Loop | VarStyle::Uloop => {
                let mut r = rest;
                let mut pad = false;
                if r.last().map(|w| w.text.as_str()) == Some("pad") {
                    pad = true;
                    r = &r[..r.len() - 1];
                }
                let (first, last) = match r {
                    [n] if style == VarStyle::Loop || style == VarStyle::Uloop => (1, parse_int(n)?),
                    [n1, n2] if style == VarStyle::Loop => (parse_int(n1)?, parse_int(n2)?),
                    _ => {
                        let sp = r.get(2).or(r.first()).map_or(style_w.span, |w| w.span);
                        return Err(Error::deck(
                            sp,
                            format!(
                                "illegal variable command: expected '{} N [pad]'{}",
                                style.keyword(),
                                if style == VarStyle::Loop { " or 'loop N1 N2 [pad]'" } else { "" }
                            ),
                        ));
                    }
                };
                if last < first || last < 1 || first < 0 {
                    return Err(Error::deck(
                        style_w.span.to(rest.last().map_or(style_w.span, |w| w.span)),
                        format!("illegal variable command: invalid loop range {first}..{last}"),
                    ));
                }
                let pad = if pad { last.to_string().len() } else { 0 };
                Data::Loop { first, last, which: 0, pad }
            }
            VarStyle::String => {
                need(1)?;
                Data::Str(rest[0].text.clone())
            }
            VarStyle::Getenv => {
                need(1)?;
                Data::Getenv(rest[0].text.clone())
            }
            VarStyle::Format => {
                need(2)?;
                let f = &rest[1].text;
                let convs = f.matches('%').count() - 2 * f.matches("%%").count();
                if convs != 1 || !f.trim_end().ends_with(['f', 'g', 'e', 'G', 'E']) {
                    return Err(Error::deck(rest[1].span, format!("incorrect conversion in format string '{f}' (expected one %f, %g or %e)")));
                }
                Data::Format { var: rest[0].text.clone(), fmt: f.clone() }
            }
            VarStyle::Equal | VarStyle::Atom => {
                need(1)?;
                let text = rest[0].text.clone();
                let e = expr::parse(&text).map_err(|m| Error::deck(rest[0].span, m))?;
                Data::Formula { text, expr: Arc::new(e) }
            }
            VarStyle::Internal => {
                need(1)?;
                let v = rest[0].text.parse::<f64>().map_err(|_| Error::deck(rest[0].span, format!("expected a number, got '{}'", rest[0].text)))?;
                Data::Internal(v)
            }
        };
        self.vars.insert(name.to_string(), Var { style, data });
        Ok(())
    }

    /// Execute `next v1 v2 ...`. Returns `true` when a variable ran out of
    /// values (it is deleted and the next `jump` must be skipped).
    pub fn next(&mut self, names: &[Word]) -> Result<bool> {
        if names.is_empty() {
            return Err(Error::deck(Span::DUMMY, "illegal next command: no variables named"));
        }
        let mut style = None;
        for w in names {
            let Some(v) = self.vars.get(&w.text) else {
                let e = Error::deck(w.span, format!("invalid variable name '{}' in next command", w.text));
                return Err(match self.suggest(&w.text) {
                    Some(h) => e.with_hint(h),
                    None => e,
                });
            };
            if !v.style.is_list() {
                return Err(Error::deck(w.span, format!("invalid variable style '{}' with next command", v.style.keyword())));
            }
            if *style.get_or_insert(v.style) != v.style {
                return Err(Error::deck(w.span, "all variables in next command must be same style"));
            }
        }
        let mut exhausted = false;
        for w in names {
            let Some(v) = self.vars.get_mut(&w.text) else { continue };
            let done = match &mut v.data {
                Data::List { values, which } => {
                    *which += 1;
                    *which >= values.len()
                }
                Data::Loop { first, last, which, .. } => {
                    *which += 1;
                    *first + *which > *last
                }
                _ => false,
            };
            if done {
                exhausted = true;
                self.vars.remove(&w.text);
            }
        }
        Ok(exhausted)
    }

    /// The text `${name}` is replaced by. `Ok(None)` if the variable is not defined.
    pub fn retrieve(&self, name: &str, ctx: &dyn EvalContext) -> std::result::Result<Option<String>, String> {
        self.retrieve_depth(name, ctx, 0)
    }

    fn retrieve_depth(&self, name: &str, ctx: &dyn EvalContext, depth: usize) -> std::result::Result<Option<String>, String> {
        if depth > MAX_DEPTH {
            return Err(format!("variable '{name}' has a circular dependency (or is nested too deeply)"));
        }
        let Some(v) = self.vars.get(name) else { return Ok(None) };
        Ok(Some(match &v.data {
            Data::List { values, which } => values.get(*which).cloned().unwrap_or_default(),
            Data::Loop { first, which, pad, .. } => format!("{:0width$}", first + which, width = *pad),
            Data::Str(s) => s.clone(),
            Data::Getenv(k) => std::env::var(k).unwrap_or_default(),
            Data::Format { var, fmt } => {
                let x = self.eval_equal_depth(var, ctx, depth + 1)?;
                cfmt::sprintf(fmt, &[cfmt::CArg::Float(x)])?
            }
            Data::Formula { .. } if v.style == VarStyle::Atom => {
                return Err(format!("atom-style variable '{name}' cannot be substituted with $"));
            }
            Data::Formula { .. } | Data::Internal(_) => cfmt::fmt_g(self.eval_equal_depth(name, ctx, depth + 1)?, 15),
        }))
    }

    /// Substitute `$x`, `${name}` and `$(expr)` in text, as `print` and
    /// `fix print` do when they run (quoted parts are left as they are).
    /// Errors point at the word.
    pub fn substitute_word(&self, w: &Word, ctx: &dyn EvalContext) -> Result<String> {
        let t = super::lexer::Text::uniform(&w.text, w.span);
        let (out, _) = super::lexer::substitute(&t, &mut |r, sp| resolve_reference(self, r, sp, ctx))?;
        Ok(out.s)
    }

    /// The value of a variable as text (what `${name}` gives).
    pub fn string_value(&self, name: &str, ctx: &dyn EvalContext) -> std::result::Result<String, String> {
        self.retrieve(name, ctx)?.ok_or_else(|| self.undefined(name))
    }

    fn undefined(&self, name: &str) -> String {
        match self.suggest(name) {
            Some(h) => format!("variable '{name}' is not defined ({h})"),
            None => format!("variable '{name}' is not defined"),
        }
    }

    /// Evaluate a variable as a number (equal-style formula, internal, or a
    /// numeric value of any other non-atom style).
    pub fn eval_equal(&self, name: &str, ctx: &dyn EvalContext) -> std::result::Result<f64, String> {
        self.eval_equal_depth(name, ctx, 0)
    }

    fn eval_equal_depth(&self, name: &str, ctx: &dyn EvalContext, depth: usize) -> std::result::Result<f64, String> {
        if depth > MAX_DEPTH {
            return Err(format!("variable '{name}' has a circular dependency (or is nested too deeply)"));
        }
        let Some(v) = self.vars.get(name) else { return Err(self.undefined(name)) };
        match &v.data {
            Data::Formula { expr, .. } if v.style == VarStyle::Equal => match self.eval(expr, ctx, false, depth + 1)? {
                Val::S(x) => Ok(x),
                Val::V(_) => Err(format!("variable '{name}': per-atom value in equal-style formula")),
            },
            Data::Formula { .. } => Err(format!("atom-style variable '{name}' used where a single number is needed")),
            Data::Internal(x) => Ok(*x),
            Data::Format { var, .. } if var == name => Err(format!("format variable '{name}' formats itself (circular dependency)")),
            _ => {
                let s = self.retrieve_depth(name, ctx, depth + 1)?.unwrap_or_default();
                s.trim().parse::<f64>().map_err(|_| format!("variable '{name}' has the non-numeric value '{s}'"))
            }
        }
    }

    /// Evaluate an atom-style (or any numeric) variable for every local atom.
    pub fn eval_atom(&self, name: &str, ctx: &dyn EvalContext) -> std::result::Result<Vec<f64>, String> {
        let Some(v) = self.vars.get(name) else { return Err(self.undefined(name)) };
        match &v.data {
            Data::Formula { expr, .. } => match self.eval(expr, ctx, true, 1)? {
                Val::S(x) => Ok(vec![x; ctx.natoms()]),
                Val::V(v) => Ok(v),
            },
            _ => Ok(vec![self.eval_equal(name, ctx)?; ctx.natoms()]),
        }
    }

    /// Evaluate formula text (as `$(...)` does); compiled formulas are cached.
    pub fn eval_expr(&self, text: &str, ctx: &dyn EvalContext) -> std::result::Result<f64, String> {
        let e = self.compile(text)?;
        match self.eval(&e, ctx, false, 0)? {
            Val::S(x) => Ok(x),
            Val::V(_) => Err(format!("per-atom value in formula '{text}'")),
        }
    }

    /// Evaluate formula text per atom (atom-style).
    pub fn eval_expr_atom(&self, text: &str, ctx: &dyn EvalContext) -> std::result::Result<Vec<f64>, String> {
        let e = self.compile(text)?;
        match self.eval(&e, ctx, true, 0)? {
            Val::S(x) => Ok(vec![x; ctx.natoms()]),
            Val::V(v) => Ok(v),
        }
    }

    /// The formula text of an equal- or atom-style variable.
    pub fn formula(&self, name: &str) -> Option<&str> {
        match &self.vars.get(name)?.data {
            Data::Formula { text, .. } => Some(text),
            _ => None,
        }
    }

    fn compile(&self, text: &str) -> std::result::Result<Arc<Expr>, String> {
        if let Ok(c) = self.cache.0.lock() {
            if let Some(e) = c.get(text) {
                return Ok(e.clone());
            }
        }
        let e = Arc::new(expr::parse(text)?);
        if let Ok(mut c) = self.cache.0.lock() {
            if c.len() > 4096 {
                c.clear();
            }
            c.insert(text.to_string(), e.clone());
        }
        Ok(e)
    }

    fn eval(&self, e: &Expr, ctx: &dyn EvalContext, atom: bool, depth: usize) -> std::result::Result<Val, String> {
        if depth > MAX_DEPTH {
            return Err("variable formula nested too deeply (circular dependency between variables?)".into());
        }
        let depth = depth + 1;
        Ok(match e {
            Expr::Num(x) => Val::S(*x),
            Expr::Neg(a) => map1(self.eval(a, ctx, atom, depth)?, |x| Ok(-x))?,
            Expr::Not(a) => map1(self.eval(a, ctx, atom, depth)?, |x| Ok(if x == 0.0 { 1.0 } else { 0.0 }))?,
            Expr::Bin(op, a, b) => {
                let a = self.eval(a, ctx, atom, depth)?;
                let b = self.eval(b, ctx, atom, depth)?;
                map2(a, b, |x, y| apply_bin(*op, x, y))?
            }
            Expr::Func(name, args) => {
                let mut vals = Vec::with_capacity(args.len());
                for a in args {
                    vals.push(self.eval(a, ctx, atom, depth)?);
                }
                self.func(name, vals, ctx)?
            }
            Expr::Group(name, args) => {
                let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
                Val::S(ctx.group_function(name, &a)?)
            }
            Expr::Special(name, args) => {
                if name == "is_defined" && args.len() == 2 && args[0] == "variable" {
                    Val::S(if self.vars.contains_key(&args[1]) { 1.0 } else { 0.0 })
                } else {
                    let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
                    Val::S(ctx.group_function(name, &a)?)
                }
            }
            Expr::Var(name, idx) => {
                if depth > MAX_DEPTH {
                    return Err(format!("variable '{name}' has a circular dependency"));
                }
                let Some(v) = self.vars.get(name) else { return Err(self.undefined(name)) };
                match (v.style, idx) {
                    (VarStyle::Atom, None) if atom => match &v.data {
                        Data::Formula { expr, .. } => self.eval(expr, ctx, true, depth + 1)?,
                        _ => unreachable_val()?,
                    },
                    (VarStyle::Atom, None) => {
                        return Err(format!("atom-style variable v_{name} in an equal-style formula (use v_{name}[ID])"));
                    }
                    (VarStyle::Atom, Some(id)) => {
                        let vals = match &v.data {
                            Data::Formula { expr, .. } => self.eval(expr, ctx, true, depth + 1)?,
                            _ => unreachable_val()?,
                        };
                        let ids = ctx.atom_vector("id")?;
                        let k = ids.iter().position(|&x| x == *id as f64).ok_or_else(|| format!("v_{name}[{id}]: no atom with ID {id}"))?;
                        match vals {
                            Val::S(x) => Val::S(x),
                            Val::V(v) => Val::S(v.get(k).copied().ok_or_else(|| format!("v_{name}[{id}]: atom index out of range"))?),
                        }
                    }
                    (_, Some(_)) => return Err(format!("variable v_{name} is not a vector or atom-style variable and takes no index")),
                    (_, None) => Val::S(self.eval_equal_depth(name, ctx, depth + 1)?),
                }
            }
            Expr::Compute(id, i, j) => {
                if atom && j.is_none() {
                    if let Ok(v) = ctx.peratom('c', id, *i) {
                        return Ok(Val::V(v));
                    }
                }
                Val::S(ctx.compute(id, *i, *j)?)
            }
            Expr::Fix(id, i, j) => {
                if atom && j.is_none() {
                    if let Ok(v) = ctx.peratom('f', id, *i) {
                        return Ok(Val::V(v));
                    }
                }
                Val::S(ctx.fix(id, *i, *j)?)
            }
            Expr::AtomValue(kw, id) => Val::S(ctx.atom_value(kw, *id)?),
            Expr::AtomVec(kw) => {
                if !atom {
                    return Err(format!("per-atom vector '{kw}' in an equal-style formula (use {kw}[ID] for one atom)"));
                }
                Val::V(ctx.atom_vector(kw)?)
            }
            Expr::Thermo(kw) => Val::S(
                ctx.thermo(kw).ok_or_else(|| format!("unknown keyword '{kw}' in variable formula (or a value the last step did not compute)"))?,
            ),
        })
    }

    fn func(&self, name: &str, vals: Vec<Val>, ctx: &dyn EvalContext) -> std::result::Result<Val, String> {
        match name {
            "random" | "normal" => {
                let scal: Vec<f64> = vals
                    .iter()
                    .map(|v| if let Val::S(x) = v { Ok(*x) } else { Err(format!("{name}() needs scalar arguments")) })
                    .collect::<std::result::Result<_, _>>()?;
                let (a, b, seed) = (scal[0], scal[1], scal[2]);
                let draw = |_: usize| -> std::result::Result<f64, String> {
                    if name == "random" {
                        Ok(a + (b - a) * self.rng.uniform(seed)?)
                    } else {
                        if b < 0.0 {
                            return Err("invalid normal() standard deviation in variable formula".into());
                        }
                        let u1 = self.rng.uniform(seed)?;
                        let u2 = self.rng.uniform(seed)?;
                        Ok(a + b * (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos())
                    }
                };
                Ok(Val::S(draw(0)?))
            }
            "ramp" | "stagger" | "logfreq" | "logfreq2" | "logfreq3" | "stride" | "vdisplace" | "swiggle" | "cwiggle" => {
                let step = ctx.thermo("step").ok_or_else(|| format!("{name}() needs the current timestep"))? as i64;
                let (begin, end) = match name {
                    "ramp" | "vdisplace" | "swiggle" | "cwiggle" => {
                        ctx.run_bounds().ok_or_else(|| format!("cannot use {name}() in variable formula between runs"))?
                    }
                    _ => (0, 0),
                };
                let dt = ctx.thermo("dt").unwrap_or(0.0);
                mapn(vals, |a| apply_step_fn(name, a, step, begin, end, dt))
            }
            _ => mapn(vals, |a| apply_math(name, a)),
        }
    }
}

/// The text a `$` reference stands for: `${v}` as [`Variables::retrieve`]
/// gives it, `$(expr)` formatted `%.20g` or with its `:%fmt`.
pub fn resolve_reference(vars: &Variables, r: &super::lexer::Reference, span: Span, ctx: &dyn EvalContext) -> Result<String> {
    use super::lexer::Reference;
    match r {
        Reference::Var(name) => match vars.retrieve(name, ctx) {
            Ok(Some(s)) => Ok(s),
            Ok(None) => {
                let e = Error::deck(span, format!("variable '{name}' is not defined"));
                Err(match vars.suggest(name) {
                    Some(h) => e.with_hint(h),
                    None => e,
                })
            }
            Err(m) => Err(Error::deck(span, m)),
        },
        Reference::Immediate(text, fmt) => {
            let x = vars.eval_expr(text, ctx).map_err(|m| Error::deck(span, m))?;
            match fmt {
                None => Ok(cfmt::fmt_g(x, 20)),
                Some(f) => cfmt::sprintf(f, &[cfmt::CArg::Float(x)])
                    .map_err(|m| Error::deck(span, format!("invalid format '{f}' in immediate variable: {m}"))),
            }
        }
    }
}

fn unreachable_val() -> std::result::Result<Val, String> {
    Err("internal error: atom variable without formula".into())
}

fn map1(v: Val, f: impl Fn(f64) -> std::result::Result<f64, String>) -> std::result::Result<Val, String> {
    Ok(match v {
        Val::S(x) => Val::S(f(x)?),
        Val::V(v) => Val::V(v.into_iter().map(f).collect::<std::result::Result<_, _>>()?),
    })
}

fn map2(a: Val, b: Val, f: impl Fn(f64, f64) -> std::result::Result<f64, String>) -> std::result::Result<Val, String> {
    Ok(match (a, b) {
        (Val::S(x), Val::S(y)) => Val::S(f(x, y)?),
        (Val::V(v), Val::S(y)) => Val::V(v.into_iter().map(|x| f(x, y)).collect::<std::result::Result<_, _>>()?),
        (Val::S(x), Val::V(v)) => Val::V(v.into_iter().map(|y| f(x, y)).collect::<std::result::Result<_, _>>()?),
        (Val::V(v), Val::V(w)) => {
            if v.len() != w.len() {
                return Err(format!("per-atom vectors of different lengths ({} and {})", v.len(), w.len()));
            }
            Val::V(v.into_iter().zip(w).map(|(x, y)| f(x, y)).collect::<std::result::Result<_, _>>()?)
        }
    })
}

fn mapn(vals: Vec<Val>, f: impl Fn(&[f64]) -> std::result::Result<f64, String>) -> std::result::Result<Val, String> {
    let n = vals.iter().find_map(|v| if let Val::V(v) = v { Some(v.len()) } else { None });
    match n {
        None => {
            let a: Vec<f64> = vals.iter().map(|v| if let Val::S(x) = v { *x } else { 0.0 }).collect();
            Ok(Val::S(f(&a)?))
        }
        Some(n) => {
            let mut out = Vec::with_capacity(n);
            let mut a = vec![0.0; vals.len()];
            for k in 0..n {
                for (slot, v) in a.iter_mut().zip(&vals) {
                    *slot = match v {
                        Val::S(x) => *x,
                        Val::V(v) => *v.get(k).ok_or("per-atom vectors of different lengths")?,
                    };
                }
                out.push(f(&a)?);
            }
            Ok(Val::V(out))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::NoContext;

    fn cmd(s: &str) -> Command {
        Command { words: s.split_whitespace().map(|w| Word::new(w, Span::DUMMY)).collect(), span: Span::DUMMY }
    }

    #[test]
    fn redefinition_rules() {
        let mut v = Variables::new();
        v.define(&cmd("variable n index 5")).unwrap();
        v.define(&cmd("variable n index 6")).unwrap();
        assert_eq!(v.string_value("n", &NoContext).unwrap(), "5");
        v.define(&cmd("variable s string abc")).unwrap();
        v.define(&cmd("variable s string def")).unwrap();
        assert_eq!(v.string_value("s", &NoContext).unwrap(), "def");
        assert!(v.define(&cmd("variable n equal 3")).is_err());
        assert!(v.define(&cmd("variable q equal 1 + 2")).is_err());
        assert!(matches!(v.define(&cmd("variable q python f")), Err(Error::Unsupported { .. })));
    }

    #[test]
    fn equal_values() {
        let mut v = Variables::new();
        v.define(&cmd("variable a equal 2^3^2-7%3")).unwrap();
        assert_eq!(v.eval_equal("a", &NoContext).unwrap(), 63.0);
        v.define(&cmd("variable b equal v_a/v_a+round(-2.5)")).unwrap();
        assert_eq!(v.eval_equal("b", &NoContext).unwrap(), -1.0);
        v.define(&cmd("variable c equal v_c+1")).unwrap();
        assert!(v.eval_equal("c", &NoContext).unwrap_err().contains("circular"));
        assert!(v.eval_expr("1/0", &NoContext).unwrap_err().contains("divide by 0"));
        assert_eq!(v.eval_expr("atan2(1,1)*4", &NoContext).unwrap(), std::f64::consts::PI);
    }

    #[test]
    fn loop_pad_and_next() {
        let mut v = Variables::new();
        v.define(&cmd("variable L loop 8 12 pad")).unwrap();
        assert_eq!(v.string_value("L", &NoContext).unwrap(), "08");
        let w = [Word::new("L", Span::DUMMY)];
        for _ in 0..4 {
            assert!(!v.next(&w).unwrap());
        }
        assert_eq!(v.string_value("L", &NoContext).unwrap(), "12");
        assert!(v.next(&w).unwrap());
        assert!(!v.is_defined("L"));
    }
}
