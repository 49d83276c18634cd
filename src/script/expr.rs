//! The equal-style / atom-style formula language of the `variable` command.
//!
//! [`parse`] compiles a formula once into an [`Expr`] tree; [`Expr`] is then
//! evaluated as often as needed (fixes evaluate atom variables every step).
//! Operators and precedence follow LAMMPS (29 Sep 2021): unary `-` and `!`
//! bind tightest (so `-2^2` is 4), then `^`, then `* / %`, then `+ -`, then
//! `< <= > >=`, then `== !=`, then `&&`, then `|| |^`; all binary operators are
//! left-associative (`2^3^2` is 64). `round(x)` is `floor(x+0.5)`.
//!
//! Also [`eval_boolean`], the smaller language of the `if` command, where
//! operands may be strings compared with `==` and `!=`.

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while, take_while1};
use nom::character::complete::{digit0, digit1, one_of};
use nom::combinator::{opt, recognize};
use nom::sequence::{pair, tuple};
use nom::IResult;

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `%`
    Mod,
    /// `^`
    Pow,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `&&`
    And,
    /// `||`
    Or,
    /// `|^`
    Xor,
}

impl BinOp {
    fn precedence(self) -> u8 {
        use BinOp::*;
        match self {
            Or | Xor => 1,
            And => 2,
            Eq | Ne => 3,
            Lt | Le | Gt | Ge => 4,
            Add | Sub => 5,
            Mul | Div | Mod => 6,
            Pow => 7,
        }
    }
}

/// A compiled formula.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A number or constant.
    Num(f64),
    /// Unary minus.
    Neg(Box<Expr>),
    /// Logical not.
    Not(Box<Expr>),
    /// Binary operation.
    Bin(BinOp, Box<Expr>, Box<Expr>),
    /// Math function call (`sqrt(x)`, `atan2(y,x)`, `ramp(a,b)`, ...).
    Func(String, Vec<Expr>),
    /// Group (or other host) function with raw word arguments: `count(all)`, `xcm(g,x)`.
    Group(String, Vec<String>),
    /// `is_defined(kind,id)` and friends.
    Special(String, Vec<String>),
    /// `v_name` or `v_name[i]`.
    Var(String, Option<i64>),
    /// `c_ID`, `c_ID[i]`, `c_ID[i][j]`.
    Compute(String, Option<usize>, Option<usize>),
    /// `f_ID`, `f_ID[i]`, `f_ID[i][j]`.
    Fix(String, Option<usize>, Option<usize>),
    /// `x[5]`: one atom's value by id.
    AtomValue(String, i64),
    /// `x`, `vx`, `mass`... : the per-atom vector (atom-style only).
    AtomVec(String),
    /// Any other bare word: a thermo keyword.
    Thermo(String),
}

/// Math functions with numeric arguments, and their argument counts.
const MATH: &[(&str, usize)] = &[
    ("sqrt", 1),
    ("exp", 1),
    ("ln", 1),
    ("log", 1),
    ("abs", 1),
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("asin", 1),
    ("acos", 1),
    ("atan", 1),
    ("atan2", 2),
    ("random", 3),
    ("normal", 3),
    ("ceil", 1),
    ("floor", 1),
    ("round", 1),
    ("ternary", 3),
    ("ramp", 2),
    ("stagger", 2),
    ("logfreq", 3),
    ("logfreq2", 3),
    ("logfreq3", 3),
    ("stride", 3),
    ("vdisplace", 2),
    ("swiggle", 3),
    ("cwiggle", 3),
];

/// Group functions answered by [`super::EvalContext::group_function`].
const GROUP: &[&str] = &["count", "mass", "charge", "xcm", "vcm", "fcm", "bound", "gyration", "ke", "angmom", "torque", "inertia", "omega"];

/// Special functions that name things rather than compute numbers.
const SPECIAL: &[&str] = &["is_defined", "is_active", "is_available"];

/// Special functions LAMMPS has that demx does not evaluate.
const UNSUPPORTED: &[&str] =
    &["sum", "min", "max", "ave", "trap", "slope", "gmask", "rmask", "grmask", "next", "is_file", "extract_setting", "label2type"];

/// Per-atom vectors usable as bare words in atom-style formulas.
pub const ATOM_VECTORS: &[&str] = &["id", "mass", "type", "mol", "radius", "q", "x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz"];

/// Parse a formula into an [`Expr`].
pub fn parse(text: &str) -> Result<Expr, String> {
    let mut p = Parser { s: text, pos: 0, nodes: 0 };
    let e = p.expr(0)?;
    p.skip_ws();
    if p.pos < p.s.len() {
        return Err(format!("invalid syntax in variable formula '{}' at '{}'", text, &p.s[p.pos..]));
    }
    Ok(e)
}

struct Parser<'a> {
    s: &'a str,
    pos: usize,
    /// Nodes made so far; bounded so evaluation cannot run out of stack.
    nodes: usize,
}

/// Most nodes one formula may have.
const MAX_NODES: usize = 2000;

fn number(i: &str) -> IResult<&str, &str> {
    recognize(tuple((
        alt((recognize(pair(digit1, opt(pair(tag("."), digit0)))), recognize(pair(tag("."), digit1)))),
        opt(tuple((one_of("eE"), opt(one_of("+-")), digit1))),
    )))(i)
}

fn ident(i: &str) -> IResult<&str, &str> {
    recognize(pair(take_while1(|c: char| c.is_ascii_alphabetic() || c == '_'), take_while(|c: char| c.is_ascii_alphanumeric() || c == '_')))(i)
}

fn index(i: &str) -> IResult<&str, &str> {
    let (i, _) = tag("[")(i)?;
    let (i, n) = recognize(pair(opt(one_of("+-")), digit1))(i)?;
    let (i, _) = tag("]")(i)?;
    Ok((i, n))
}

impl<'a> Parser<'a> {
    fn rest(&self) -> &'a str {
        &self.s[self.pos..]
    }
    fn skip_ws(&mut self) {
        let r = self.rest();
        self.pos += r.len() - r.trim_start().len();
    }
    fn err(&self, what: &str) -> String {
        if self.pos >= self.s.len() {
            format!("invalid syntax in variable formula '{}': {} at end", self.s, what)
        } else {
            format!("invalid syntax in variable formula '{}': {} at '{}'", self.s, what, self.rest())
        }
    }

    fn binop(&mut self) -> Option<BinOp> {
        self.skip_ws();
        let r = self.rest();
        let two =
            [("<=", BinOp::Le), (">=", BinOp::Ge), ("==", BinOp::Eq), ("!=", BinOp::Ne), ("&&", BinOp::And), ("||", BinOp::Or), ("|^", BinOp::Xor)];
        for (t, op) in two {
            if r.starts_with(t) {
                return Some(op);
            }
        }
        let op = match r.as_bytes().first()? {
            b'+' => BinOp::Add,
            b'-' => BinOp::Sub,
            b'*' => BinOp::Mul,
            b'/' => BinOp::Div,
            b'%' => BinOp::Mod,
            b'^' => BinOp::Pow,
            b'<' => BinOp::Lt,
            b'>' => BinOp::Gt,
            _ => return None,
        };
        Some(op)
    }

    fn op_len(op: BinOp) -> usize {
        use BinOp::*;
        match op {
            Le | Ge | Eq | Ne | And | Or | Xor => 2,
            _ => 1,
        }
    }

    fn expr(&mut self, min_prec: u8) -> Result<Expr, String> {
        let mut lhs = self.unary()?;
        while let Some(op) = self.binop() {
            let prec = op.precedence();
            if prec <= min_prec {
                break;
            }
            self.pos += Self::op_len(op);
            let rhs = self.expr(prec)?;
            lhs = Expr::Bin(op, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Expr, String> {
        self.nodes += 1;
        if self.nodes > MAX_NODES {
            return Err(format!("variable formula is too long (more than {MAX_NODES} terms)"));
        }
        self.skip_ws();
        let r = self.rest();
        if r.starts_with('-') {
            self.pos += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        if r.starts_with('!') && !r.starts_with("!=") {
            self.pos += 1;
            return Ok(Expr::Not(Box::new(self.unary()?)));
        }
        self.primary()
    }

    fn args(&mut self) -> Result<Vec<String>, String> {
        // raw comma-separated words up to the matching ')'; self.pos is after '('
        let r = self.rest();
        let mut depth = 0usize;
        for (k, c) in r.char_indices() {
            match c {
                '(' => depth += 1,
                ')' if depth == 0 => {
                    let inner = &r[..k];
                    self.pos += k + 1;
                    if inner.trim().is_empty() {
                        return Ok(Vec::new());
                    }
                    let mut out = Vec::new();
                    let mut d = 0usize;
                    let mut last = 0;
                    for (j, ch) in inner.char_indices() {
                        match ch {
                            '(' => d += 1,
                            ')' => d = d.saturating_sub(1),
                            ',' if d == 0 => {
                                out.push(inner[last..j].trim().to_string());
                                last = j + 1;
                            }
                            _ => {}
                        }
                    }
                    out.push(inner[last..].trim().to_string());
                    return Ok(out);
                }
                ')' => depth -= 1,
                _ => {}
            }
        }
        Err(self.err("unbalanced parentheses"))
    }

    fn primary(&mut self) -> Result<Expr, String> {
        self.skip_ws();
        let r = self.rest();
        if r.starts_with('(') {
            self.pos += 1;
            self.nodes += 20; // nesting costs stack: bound it harder than terms
            if self.nodes > MAX_NODES {
                return Err("variable formula is nested too deeply".into());
            }
            let e = self.expr(0)?;
            self.skip_ws();
            if !self.rest().starts_with(')') {
                return Err(self.err("expected ')'"));
            }
            self.pos += 1;
            return Ok(e);
        }
        if let Ok((rest, num)) = number(r) {
            self.pos += r.len() - rest.len();
            return num.parse::<f64>().map(Expr::Num).map_err(|_| self.err("invalid number"));
        }
        let Ok((rest, word)) = ident(r) else {
            return Err(self.err("expected a number, name or '('"));
        };
        self.pos += r.len() - rest.len();
        // function call?
        if rest.starts_with('(') {
            self.pos += 1;
            self.nodes += 20; // nesting costs stack: bound it harder than terms
            if self.nodes > MAX_NODES {
                return Err("variable formula is nested too deeply".into());
            }
            if let Some(&(_, n)) = MATH.iter().find(|(f, _)| *f == word) {
                let raw = self.args()?;
                if raw.len() != n {
                    return Err(format!("function {word}() takes {n} argument(s), got {}", raw.len()));
                }
                let mut args = Vec::with_capacity(n);
                for a in &raw {
                    let mut sub = Parser { s: a, pos: 0, nodes: self.nodes };
                    let e = sub.expr(0)?;
                    sub.skip_ws();
                    if sub.pos < a.len() {
                        return Err(sub.err("unexpected text"));
                    }
                    self.nodes = sub.nodes;
                    args.push(e);
                }
                return Ok(Expr::Func(word.to_string(), args));
            }
            if GROUP.contains(&word) {
                return Ok(Expr::Group(word.to_string(), self.args()?));
            }
            if SPECIAL.contains(&word) {
                return Ok(Expr::Special(word.to_string(), self.args()?));
            }
            if UNSUPPORTED.contains(&word) {
                return Err(format!("special function {word}() is not supported in variable formulas yet"));
            }
            return Err(format!("invalid math/group/special function '{word}()' in variable formula"));
        }
        // indices
        let mut idx: Vec<i64> = Vec::new();
        while let Ok((rest2, n)) = index(self.rest()) {
            let len = self.rest().len() - rest2.len();
            idx.push(n.parse::<i64>().map_err(|_| self.err("invalid index"))?);
            self.pos += len;
            if idx.len() > 2 {
                return Err(self.err("too many indices"));
            }
        }
        if self.rest().starts_with('[') {
            return Err(self.err("invalid index (expected an integer in [])"));
        }
        let uidx = |k: usize| -> Result<Option<usize>, String> {
            match idx.get(k) {
                None => Ok(None),
                Some(&v) if v >= 1 => Ok(Some(v as usize)),
                Some(&v) => Err(format!("index {v} of {word} must be >= 1")),
            }
        };
        if let Some(name) = word.strip_prefix("v_") {
            if idx.len() > 1 {
                return Err(format!("variable v_{name} takes at most one index"));
            }
            return Ok(Expr::Var(name.to_string(), idx.first().copied()));
        }
        if let Some(id) = word.strip_prefix("c_") {
            return Ok(Expr::Compute(id.to_string(), uidx(0)?, uidx(1)?));
        }
        if let Some(id) = word.strip_prefix("f_") {
            return Ok(Expr::Fix(id.to_string(), uidx(0)?, uidx(1)?));
        }
        if !idx.is_empty() {
            if idx.len() > 1 {
                return Err(format!("atom value {word} takes one index"));
            }
            return Ok(Expr::AtomValue(word.to_string(), idx[0]));
        }
        let constant = match word {
            "PI" => Some(std::f64::consts::PI),
            "version" => Some(20210929.0),
            "on" | "true" | "yes" => Some(1.0),
            "off" | "false" | "no" => Some(0.0),
            _ => None,
        };
        if let Some(c) = constant {
            return Ok(Expr::Num(c));
        }
        if ATOM_VECTORS.contains(&word) {
            return Ok(Expr::AtomVec(word.to_string()));
        }
        Ok(Expr::Thermo(word.to_string()))
    }
}

/// Evaluate the Boolean expression of an `if` command (after substitution).
/// Operands are numbers or strings; strings compare only with `==`/`!=`.
pub fn eval_boolean(text: &str) -> Result<f64, String> {
    #[derive(Clone, Debug)]
    enum Tok {
        Val(String, bool), // text, is a number
        Op(BinOp),
        Not,
        Open,
        Close,
    }
    let bad = || format!("invalid Boolean syntax in if command: '{text}'");
    let b = text.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let two: &[u8] = b.get(i..i + 2).unwrap_or(b"");
        let op2 = match two {
            b"<=" => Some(BinOp::Le),
            b">=" => Some(BinOp::Ge),
            b"==" => Some(BinOp::Eq),
            b"!=" => Some(BinOp::Ne),
            b"&&" => Some(BinOp::And),
            b"||" => Some(BinOp::Or),
            b"|^" => Some(BinOp::Xor),
            _ => None,
        };
        if let Some(op) = op2 {
            toks.push(Tok::Op(op));
            i += 2;
            continue;
        }
        match c {
            b'(' => toks.push(Tok::Open),
            b')' => toks.push(Tok::Close),
            b'!' => toks.push(Tok::Not),
            b'<' => toks.push(Tok::Op(BinOp::Lt)),
            b'>' => toks.push(Tok::Op(BinOp::Gt)),
            _ => {
                let start = i;
                while i < b.len() && !b[i].is_ascii_whitespace() && !b"()!<>=&|".contains(&b[i]) {
                    i += 1;
                }
                if i == start {
                    return Err(bad());
                }
                let w = &text[start..i];
                let first = w.as_bytes()[0];
                let numeric = first.is_ascii_digit() || first == b'.' || first == b'-' || first == b'+';
                if numeric && w.parse::<f64>().is_err() {
                    return Err(bad());
                }
                toks.push(Tok::Val(w.to_string(), numeric));
                continue;
            }
        }
        i += 1;
    }
    // precedence climbing over tokens; values: (num, Option<string>)
    #[derive(Clone)]
    enum V {
        N(f64),
        S(String),
    }
    fn num(v: V, bad: &dyn Fn() -> String) -> Result<f64, String> {
        match v {
            V::N(x) => Ok(x),
            V::S(_) => Err(bad()),
        }
    }
    fn prim(t: &[Tok], k: &mut usize, bad: &dyn Fn() -> String, depth: usize) -> Result<V, String> {
        if depth > 200 {
            return Err(bad());
        }
        match t.get(*k) {
            Some(Tok::Not) => {
                *k += 1;
                let v = prim(t, k, bad, depth + 1)?;
                Ok(V::N(if num(v, bad)? == 0.0 { 1.0 } else { 0.0 }))
            }
            Some(Tok::Open) => {
                *k += 1;
                let v = climb(t, k, 0, bad, depth + 1)?;
                if !matches!(t.get(*k), Some(Tok::Close)) {
                    return Err(bad());
                }
                *k += 1;
                Ok(v)
            }
            Some(Tok::Val(s, true)) => {
                *k += 1;
                Ok(V::N(s.parse::<f64>().map_err(|_| bad())?))
            }
            Some(Tok::Val(s, false)) => {
                *k += 1;
                Ok(V::S(s.clone()))
            }
            _ => Err(bad()),
        }
    }
    fn climb(t: &[Tok], k: &mut usize, min: u8, bad: &dyn Fn() -> String, depth: usize) -> Result<V, String> {
        let mut lhs = prim(t, k, bad, depth)?;
        while let Some(Tok::Op(op)) = t.get(*k) {
            let op = *op;
            if op.precedence() <= min {
                break;
            }
            *k += 1;
            let rhs = climb(t, k, op.precedence(), bad, depth + 1)?;
            let r = match (lhs, rhs) {
                (V::S(a), V::S(b)) => match op {
                    BinOp::Eq => f64::from(u8::from(a == b)),
                    BinOp::Ne => f64::from(u8::from(a != b)),
                    _ => return Err(bad()),
                },
                (V::N(a), V::N(b)) => apply_bin(op, a, b)?,
                _ => return Err(bad()),
            };
            lhs = V::N(r);
        }
        Ok(lhs)
    }
    if toks.is_empty() {
        return Err(bad());
    }
    let mut k = 0;
    let v = climb(&toks, &mut k, 0, &bad, 0)?;
    if k != toks.len() {
        return Err(bad());
    }
    Ok(match v {
        V::N(x) => x,
        V::S(_) => 0.0,
    })
}

fn truth(x: bool) -> f64 {
    if x {
        1.0
    } else {
        0.0
    }
}

/// Apply a binary operator to two numbers, with LAMMPS' error checks.
pub fn apply_bin(op: BinOp, a: f64, b: f64) -> Result<f64, String> {
    use BinOp::*;
    Ok(match op {
        Add => a + b,
        Sub => a - b,
        Mul => a * b,
        Div => {
            if b == 0.0 {
                return Err("divide by 0 in variable formula".into());
            }
            a / b
        }
        Mod => {
            if b == 0.0 {
                return Err("modulo 0 in variable formula".into());
            }
            a % b
        }
        Pow => {
            if b == 0.0 {
                1.0
            } else if a == 0.0 && b < 0.0 {
                return Err("invalid power expression in variable formula".into());
            } else {
                a.powf(b)
            }
        }
        Lt => truth(a < b),
        Le => truth(a <= b),
        Gt => truth(a > b),
        Ge => truth(a >= b),
        Eq => truth(a == b),
        Ne => truth(a != b),
        And => truth(a != 0.0 && b != 0.0),
        Or => truth(a != 0.0 || b != 0.0),
        Xor => truth((a == 0.0) != (b == 0.0)),
    })
}

/// Apply a math function (not the step-dependent ones) to numbers.
pub fn apply_math(name: &str, a: &[f64]) -> Result<f64, String> {
    let x = a.first().copied().unwrap_or(0.0);
    let y = a.get(1).copied().unwrap_or(0.0);
    let z = a.get(2).copied().unwrap_or(0.0);
    Ok(match name {
        "sqrt" => {
            if x < 0.0 {
                return Err("sqrt of negative value in variable formula".into());
            }
            x.sqrt()
        }
        "exp" => x.exp(),
        "ln" => {
            if x <= 0.0 {
                return Err("log of zero/negative value in variable formula".into());
            }
            x.ln()
        }
        "log" => {
            if x <= 0.0 {
                return Err("log of zero/negative value in variable formula".into());
            }
            x.log10()
        }
        "abs" => x.abs(),
        "sin" => x.sin(),
        "cos" => x.cos(),
        "tan" => x.tan(),
        "asin" => {
            if !(-1.0..=1.0).contains(&x) {
                return Err("arcsin of invalid value in variable formula".into());
            }
            x.asin()
        }
        "acos" => {
            if !(-1.0..=1.0).contains(&x) {
                return Err("arccos of invalid value in variable formula".into());
            }
            x.acos()
        }
        "atan" => x.atan(),
        "atan2" => x.atan2(y),
        "ceil" => x.ceil(),
        "floor" => x.floor(),
        "round" => (x + 0.5).floor(),
        "ternary" => {
            if x != 0.0 {
                y
            } else {
                z
            }
        }
        _ => return Err(format!("function {name}() needs a running simulation")),
    })
}

/// The step-dependent functions: `ramp`, `stagger`, `logfreq`, `logfreq2`,
/// `logfreq3`, `stride`, `vdisplace`, `swiggle`, `cwiggle`, given the current
/// step, the run's begin and end steps and the timestep size.
pub fn apply_step_fn(name: &str, a: &[f64], step: i64, begin: i64, end: i64, dt: f64) -> Result<f64, String> {
    let x = a.first().copied().unwrap_or(0.0);
    let y = a.get(1).copied().unwrap_or(0.0);
    let z = a.get(2).copied().unwrap_or(0.0);
    let int = |v: f64, what: &str| -> Result<i64, String> {
        if v.is_finite() && v.abs() < 9.0e18 {
            Ok(v as i64)
        } else {
            Err(format!("invalid {what}() argument in variable formula"))
        }
    };
    let (xi, yi, zi) = (int(x, name)?, int(y, name)?, int(z, name)?);
    let elapsed = (step - begin) as f64;
    Ok(match name {
        "ramp" => {
            let span = (end - begin) as f64;
            let f = if span == 0.0 { 0.0 } else { elapsed / span };
            x + f * (y - x)
        }
        "vdisplace" => x + y * dt * elapsed,
        "swiggle" | "cwiggle" => {
            if z == 0.0 {
                return Err(format!("invalid {name}() period in variable formula"));
            }
            let arg = 2.0 * std::f64::consts::PI * dt * elapsed / z;
            if name == "swiggle" {
                x + y * arg.sin()
            } else {
                x + y * (1.0 - arg.cos())
            }
        }
        "stagger" => {
            if xi < 1 || yi < 1 || yi >= xi {
                return Err("invalid stagger() arguments in variable formula".into());
            }
            let lower = step / xi * xi;
            if step - lower < yi {
                (lower + yi) as f64
            } else {
                (lower + xi) as f64
            }
        }
        "logfreq" | "logfreq3" | "logfreq2" => {
            if xi <= 0 || yi <= 0 || zi <= 1 || (name == "logfreq" && yi >= zi) {
                return Err(format!("invalid {name}() arguments in variable formula"));
            }
            if name == "logfreq3" {
                return Err("logfreq3() is not supported yet".into());
            }
            if step < xi {
                xi as f64
            } else {
                let mut lower = xi;
                while step >= zi.saturating_mul(lower) {
                    lower = lower.saturating_mul(zi);
                }
                if name == "logfreq" {
                    let multiple = step / lower;
                    if multiple < yi {
                        ((multiple + 1) * lower) as f64
                    } else {
                        (lower * zi) as f64
                    }
                } else {
                    // logfreq2: y outputs evenly spaced between lower and z*lower
                    let delta = ((zi - 1) * lower / yi).max(1);
                    let count = (step - lower) / delta;
                    ((lower + (count + 1) * delta).min(lower * zi)) as f64
                }
            }
        }
        "stride" => {
            if xi < 0 || yi < 0 || zi <= 0 || xi > yi {
                return Err("invalid stride() arguments in variable formula".into());
            }
            if step < xi {
                xi as f64
            } else if step < yi {
                let v = xi + (step - xi) / zi * zi + zi;
                if v > yi {
                    i64::MAX as f64
                } else {
                    v as f64
                }
            } else {
                i64::MAX as f64
            }
        }
        _ => return Err(format!("unknown function {name}()")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_as_lammps() {
        let e = parse("-2^2").unwrap();
        assert_eq!(e, Expr::Bin(BinOp::Pow, Box::new(Expr::Neg(Box::new(Expr::Num(2.0)))), Box::new(Expr::Num(2.0))));
        assert!(parse("1 2").is_err());
        assert!(parse("1+").is_err());
        assert!(parse("step()").is_err());
        assert_eq!(parse("x[5]").unwrap(), Expr::AtomValue("x".into(), 5));
        assert_eq!(parse("c_t[2][3]").unwrap(), Expr::Compute("t".into(), Some(2), Some(3)));
        assert_eq!(parse("count(all)").unwrap(), Expr::Group("count".into(), vec!["all".into()]));
    }

    #[test]
    fn booleans_as_lammps() {
        assert_eq!(eval_boolean("abc == abc").unwrap(), 1.0);
        assert_eq!(eval_boolean("-1 < 0").unwrap(), 1.0);
        assert_eq!(eval_boolean("a == a && 1").unwrap(), 1.0);
        assert_eq!(eval_boolean("(1 < 2) && !(3 < 2)").unwrap(), 1.0);
        assert_eq!(eval_boolean("abc").unwrap(), 0.0);
        assert!(eval_boolean("a < b").is_err());
        assert!(eval_boolean("a b == a b").is_err());
        assert!(eval_boolean("1+1 == 2").is_err());
        // found by the fuzz test: a multi-byte character after a digit
        assert!(eval_boolean("2\u{e9} > 1").is_err());
        assert_eq!(eval_boolean("\u{e9}t\u{e9} == \u{e9}t\u{e9}").unwrap(), 1.0);
    }
}
