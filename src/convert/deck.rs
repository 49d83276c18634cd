//! Deck text as logical lines that keep their original bytes, and the facts a
//! converter needs from the whole deck before rewriting any line (types,
//! materials, constant variables, regions, timestep, gravity).
//!
//! Nothing here runs the script: a value is known only when it is written as
//! a number or as an equal/index variable built from numbers.

use std::collections::HashMap;

/// One logical line: one or more physical lines joined by a trailing `&`.
#[derive(Clone, Debug)]
pub struct Logical {
    /// 1-based number of the first physical line.
    pub line: usize,
    /// Byte offset of the first physical line in the source.
    pub offset: usize,
    /// The physical lines without their line ends.
    pub physical: Vec<String>,
    /// Line end of the last physical line (`\n`, `\r\n` or empty).
    pub eol: String,
    /// Leading blanks of the first physical line.
    pub indent: String,
    /// Command text: lines joined, comment removed, trimmed.
    pub command: String,
    /// Trailing comment including its `#`, if any.
    pub comment: Option<String>,
}

impl Logical {
    /// The command's words (blank separated; quotes kept as written).
    pub fn words(&self) -> Vec<String> {
        split_words(&self.command)
    }
}

/// Split a command at blanks, keeping quoted words whole.
pub fn split_words(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quote: Option<char> = None;
    for c in s.chars() {
        match quote {
            Some(q) => {
                cur.push(c);
                if c == q {
                    quote = None;
                }
            }
            None if c == '"' || c == '\'' => {
                quote = Some(c);
                cur.push(c);
            }
            None if c.is_whitespace() => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            None => cur.push(c),
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Split source text into logical lines (LAMMPS `&` joining, `#` comments
/// outside quotes).
pub fn logical_lines(src: &str) -> Vec<Logical> {
    let mut out = Vec::new();
    let mut offset = 0usize;
    let mut pending: Option<Logical> = None;
    let mut joined = String::new();
    for (k, raw) in src.split_inclusive('\n').enumerate() {
        let lineno = k + 1;
        let start = offset;
        offset += raw.len();
        let (body, eol) = if let Some(b) = raw.strip_suffix("\r\n") {
            (b, "\r\n")
        } else if let Some(b) = raw.strip_suffix('\n') {
            (b, "\n")
        } else {
            (raw, "")
        };
        let lg = pending.get_or_insert_with(|| Logical {
            line: lineno,
            offset: start,
            physical: Vec::new(),
            eol: String::new(),
            indent: body.chars().take_while(|c| *c == ' ' || *c == '\t').collect(),
            command: String::new(),
            comment: None,
        });
        lg.physical.push(body.to_string());
        lg.eol = eol.to_string();
        let t = body.trim_end();
        if let Some(stripped) = t.strip_suffix('&') {
            joined.push_str(stripped);
            continue;
        }
        joined.push_str(body);
        let mut lg = pending.take().unwrap_or_else(|| unreachable_logical(lineno, start));
        let (cmd, comment) = strip_comment(&joined);
        lg.command = cmd.trim().to_string();
        lg.comment = comment;
        out.push(lg);
        joined.clear();
    }
    if let Some(mut lg) = pending.take() {
        let (cmd, comment) = strip_comment(&joined);
        lg.command = cmd.trim().to_string();
        lg.comment = comment;
        out.push(lg);
    }
    out
}

fn unreachable_logical(line: usize, offset: usize) -> Logical {
    Logical { line, offset, physical: Vec::new(), eol: String::new(), indent: String::new(), command: String::new(), comment: None }
}

/// Split at the first `#` outside quotes.
fn strip_comment(s: &str) -> (String, Option<String>) {
    let mut quote: Option<char> = None;
    for (i, c) in s.char_indices() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '"' || c == '\'' => quote = Some(c),
            None if c == '#' => return (s[..i].to_string(), Some(s[i..].trim_end().to_string())),
            None => {}
        }
    }
    (s.to_string(), None)
}

/// A `fix property/global` entry.
#[derive(Clone, Debug)]
pub struct Property {
    /// Fix ID.
    pub id: String,
    /// `peratomtype`, `peratomtypepair`, `scalar`, ...
    pub style: String,
    /// Values as written (for pair styles the leading N is removed).
    pub values: Vec<String>,
}

/// A region as written.
#[derive(Clone, Debug)]
pub struct RegionDef {
    /// Style (`block`, `cylinder`, ...).
    pub style: String,
    /// Arguments after the style.
    pub args: Vec<String>,
}

/// A particle template (LIGGGHTS `particletemplate/sphere`).
#[derive(Clone, Debug)]
pub struct Template {
    /// Atom type.
    pub atom_type: String,
    /// Density word.
    pub density: String,
    /// Radius word.
    pub radius: String,
}

/// Whole-deck facts gathered before conversion.
#[derive(Clone, Debug, Default)]
pub struct Facts {
    /// Number of atom types from `create_box N`.
    pub ntypes: Option<usize>,
    /// property/global by name.
    pub props: HashMap<String, Property>,
    /// Constant numeric variables.
    pub vars: HashMap<String, f64>,
    /// Regions by ID.
    pub regions: HashMap<String, RegionDef>,
    /// Simulation box region ID.
    pub box_region: Option<String>,
    /// Timestep if literal.
    pub dt: Option<f64>,
    /// Gravity magnitude if literal.
    pub gravity: Option<f64>,
    /// Particle templates by fix ID.
    pub templates: HashMap<String, Template>,
    /// Discrete distributions: fix ID -> (template ID, weight word).
    pub distributions: HashMap<String, Vec<(String, String)>>,
    /// Whether the deck sets `newton off` / `communicate` / `comm_modify`.
    pub has_newton_off: bool,
    /// LAMMPS `comm_modify` with vel yes seen.
    pub has_comm: bool,
    /// The deck inserts particles (insert/*, pour).
    pub has_insertion: bool,
    /// The deck changes radii with fix adapt.
    pub has_adapt: bool,
    /// IDs of all fixes the deck defines.
    pub fix_ids: std::collections::HashSet<String>,
}

impl Facts {
    /// Gather facts from all logical lines.
    pub fn gather(lines: &[Logical]) -> Facts {
        let mut f = Facts::default();
        for lg in lines {
            let w = lg.words();
            if w.is_empty() {
                continue;
            }
            match w[0].as_str() {
                "variable" if w.len() >= 4 && (w[2] == "equal" || w[2] == "index") => {
                    let expr = w[3..].join(" ");
                    let expr = expr.trim_matches('"').trim_matches('\'');
                    if let Some(v) = f.eval(expr) {
                        f.vars.entry(w[1].clone()).or_insert(v);
                    }
                }
                "create_box" if w.len() >= 3 => {
                    f.ntypes = f.num(&w[1]).map(|x| x as usize);
                    f.box_region = Some(w[2].clone());
                }
                "region" if w.len() >= 3 => {
                    f.regions.insert(w[1].clone(), RegionDef { style: w[2].clone(), args: w[3..].to_vec() });
                }
                "timestep" if w.len() >= 2 => f.dt = f.num(&w[1]),
                "newton" if w.len() >= 2 => f.has_newton_off = w[1] == "off",
                "comm_modify" | "communicate" => f.has_comm = true,
                "fix" if w.len() >= 4 => match (f.fix_ids.insert(w[1].clone()), w[3].as_str()).1 {
                    "property/global" if w.len() >= 6 => {
                        let style = w[5].clone();
                        let mut values = w[6..].to_vec();
                        if (style.contains("pair") || style == "peratomtype") && style.contains("pair") && !values.is_empty() {
                            values.remove(0);
                        }
                        f.props.insert(w[4].clone(), Property { id: w[1].clone(), style, values });
                    }
                    "gravity" if w.len() >= 5 => f.gravity = f.num(&w[4]),
                    s if s.starts_with("insert/") || s.starts_with("pour") => f.has_insertion = true,
                    "adapt" => f.has_adapt = true,
                    "particletemplate/sphere" => {
                        let get = |k: &str| w.iter().position(|x| x == k).and_then(|i| w.get(i + 2)).cloned();
                        let ty = w.iter().position(|x| x == "atom_type").and_then(|i| w.get(i + 1)).cloned();
                        if let (Some(t), Some(d), Some(r)) = (ty, get("density"), get("radius")) {
                            f.templates.insert(w[1].clone(), Template { atom_type: t, density: d, radius: r });
                        }
                    }
                    s if s.starts_with("particledistribution/discrete") && w.len() >= 6 => {
                        let n = f.num(&w[5]).unwrap_or(0.0) as usize;
                        let mut v = Vec::new();
                        for k in 0..n {
                            if let (Some(t), Some(p)) = (w.get(6 + 2 * k), w.get(7 + 2 * k)) {
                                v.push((t.clone(), p.clone()));
                            }
                        }
                        f.distributions.insert(w[1].clone(), v);
                    }
                    _ => {}
                },
                _ => {}
            }
        }
        f
    }

    /// Substitute known `${v}`, `$v` and `v_name` references.
    fn subst(&self, s: &str) -> Option<String> {
        let mut out = String::new();
        let b = s.as_bytes();
        let mut i = 0;
        while i < b.len() {
            if b[i] == b'$' {
                let (name, len) = if s[i + 1..].starts_with('{') {
                    let end = s[i + 2..].find('}')?;
                    (&s[i + 2..i + 2 + end], end + 3)
                } else {
                    (s.get(i + 1..i + 2)?, 2)
                };
                out.push_str(&format!("{}", self.vars.get(name)?));
                i += len;
            } else if s[i..].starts_with("v_") && (i == 0 || !(b[i - 1] as char).is_alphanumeric() && b[i - 1] != b'_') {
                let rest = &s[i + 2..];
                let n = rest.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(rest.len());
                out.push_str(&format!("{}", self.vars.get(&rest[..n])?));
                i += 2 + n;
            } else {
                let c = s[i..].chars().next()?;
                out.push(c);
                i += c.len_utf8();
            }
        }
        Some(out)
    }

    /// Value of a constant expression (numbers, known variables).
    pub fn eval(&self, s: &str) -> Option<f64> {
        let t = self.subst(s)?;
        if let Ok(v) = t.trim().parse::<f64>() {
            return Some(v);
        }
        crate::script::Variables::new().eval_expr(&t, &crate::script::NoContext).ok().filter(|v| v.is_finite())
    }

    /// Numeric value of one word.
    pub fn num(&self, w: &str) -> Option<f64> {
        self.eval(w)
    }

    /// Values of a per-type property, numbers only.
    pub fn per_type(&self, name: &str) -> Option<Vec<f64>> {
        let p = self.props.get(name)?;
        p.values.iter().map(|v| self.num(v)).collect()
    }

    /// Value of a per-type-pair property for 1-based types i, j.
    pub fn pair_value(&self, name: &str, i: usize, j: usize) -> Option<f64> {
        let p = self.props.get(name)?;
        let n = self.ntypes.unwrap_or(1).max(1);
        let v: Vec<f64> = p.values.iter().map(|v| self.num(v)).collect::<Option<_>>()?;
        if v.len() == 1 {
            return v.first().copied();
        }
        let n = if v.len() == n * n { n } else { (v.len() as f64).sqrt().round() as usize };
        v.get((i - 1) * n + (j - 1)).copied()
    }

    /// Scalar property value.
    pub fn scalar(&self, name: &str) -> Option<f64> {
        let p = self.props.get(name)?;
        self.num(p.values.first()?)
    }

    /// Volume of a block or cylinder region (other styles: None).
    pub fn region_volume(&self, id: &str) -> Option<f64> {
        let r = self.regions.get(id)?;
        match r.style.as_str() {
            "block" => {
                let a: Vec<f64> = r.args.iter().take(6).map(|w| self.num(w)).collect::<Option<_>>()?;
                (a.len() == 6).then(|| (a[1] - a[0]) * (a[3] - a[2]) * (a[5] - a[4]))
            }
            "cylinder" => {
                // dim c1 c2 radius lo hi
                let a: Vec<f64> = r.args.iter().skip(1).take(5).map(|w| self.num(w)).collect::<Option<_>>()?;
                (a.len() == 5).then(|| std::f64::consts::PI * a[2] * a[2] * (a[4] - a[3]).abs())
            }
            _ => None,
        }
    }

    /// Height (extent along z) of a block or z-cylinder region, for pour timing.
    pub fn region_height(&self, id: &str) -> Option<f64> {
        let r = self.regions.get(id)?;
        match r.style.as_str() {
            "block" => Some(self.num(r.args.get(5)?)? - self.num(r.args.get(4)?)?),
            "cylinder" if r.args.first().map(|s| s.as_str()) == Some("z") => Some(self.num(r.args.get(5)?)? - self.num(r.args.get(4)?)?),
            _ => None,
        }
    }

    /// Box bounds along `axis` (0..3) from the create_box region (block only).
    pub fn box_bounds(&self, axis: usize) -> Option<(f64, f64)> {
        let r = self.regions.get(self.box_region.as_ref()?)?;
        if r.style != "block" {
            return None;
        }
        Some((self.num(r.args.get(2 * axis)?)?, self.num(r.args.get(2 * axis + 1)?)?))
    }
}

/// Format a number: 12 significant digits, shortest form.
pub fn fmt(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let r: f64 = format!("{x:.11e}").parse().unwrap_or(x);
    let a = r.abs();
    if (1e-4..1e7).contains(&a) {
        format!("{r}")
    } else {
        format!("{r:e}")
    }
}

/// Whether a word is a number literal.
pub fn is_number(w: &str) -> bool {
    w.parse::<f64>().is_ok()
}
