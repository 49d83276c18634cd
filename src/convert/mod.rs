//! `demx convert`: legacy LIGGGHTS 1.x/2.x decks to 3.x syntax, and LIGGGHTS
//! 3.x <-> LAMMPS granular dialects.
//!
//! The deck is rewritten as text, one logical line at a time: comments, blank
//! lines, variables and loops stay as written and nothing is evaluated (only
//! constant numbers and constant variables are read, to move material values
//! between `fix property/global` and `pair_coeff`). A line the target cannot
//! express is kept commented out after a `# demx:` line saying why.
//! Every legacy line first goes to 3.x ([`legacy`]); for `--to lammps` the
//! 3.x text is then mapped to LAMMPS, for `--to liggghts` LAMMPS commands are
//! mapped back ([`lammps`]).

pub mod deck;
pub mod lammps;
pub mod legacy;

use clap::Parser;
use deck::{logical_lines, Facts, Logical};
use std::collections::{HashMap, HashSet};
use std::path::PathBuf;
use std::process::ExitCode;

/// Target dialect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// LIGGGHTS 3.8.
    Liggghts,
    /// LAMMPS 29 Sep 2021.
    Lammps,
}

/// How much a note matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// Exact rewrite worth knowing about (split IDs, new seeds, moved values).
    Info,
    /// Converted, but the physics or behaviour differs in a stated way.
    Approx,
    /// The line cannot be expressed and is commented out.
    Dropped,
    /// The line uses a demx-only paper keyword.
    DemxOnly,
}

/// One conversion note, tied to a deck line.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Note {
    /// 1-based line of the original deck.
    pub line: usize,
    /// Severity.
    pub severity: Severity,
    /// Explanation.
    pub message: String,
}

/// Result of converting one deck.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Converted {
    /// The converted deck text.
    pub text: String,
    /// Notes in line order.
    pub notes: Vec<Note>,
}

impl Converted {
    /// 0 = exact, 4 = approximations or dropped lines.
    pub fn exit_code(&self) -> u8 {
        if self.notes.iter().any(|n| n.severity > Severity::Info) {
            4
        } else {
            0
        }
    }
    /// Whether any line used demx-only keywords.
    pub fn demx_only(&self) -> bool {
        self.notes.iter().any(|n| n.severity == Severity::DemxOnly)
    }
}

/// What a rule does with one command.
#[derive(Clone, Debug)]
pub enum Action {
    /// Leave the line as written.
    Keep,
    /// Replace by these command lines.
    Replace(Vec<String>),
    /// Comment the line out, with the reason; severity Info means the
    /// information moved elsewhere (not lost).
    Drop(String, Severity),
}

/// Conversion state shared by the rules.
pub struct Ctx<'a> {
    /// Deck-wide facts.
    pub facts: &'a Facts,
    notes: Vec<(Severity, String)>,
    /// Seeds in use.
    pub used_seeds: HashSet<u64>,
    next_seed: u64,
    /// Fix IDs split into several fixes.
    pub split_ids: HashMap<String, Vec<String>>,
    /// Fix IDs whose lines were dropped.
    pub dropped_fixes: HashSet<String>,
    model: Option<lammps::Model3>,
    wall_model: Option<lammps::Model3>,
    pair_done: bool,
    pair_dropped: bool,
    granular: bool,
    liggghts_walls: Option<(String, String)>,
    /// The force style a 2012-era LAMMPS `fix wall/gran` (coefficients
    /// first, no style) takes from the classic `pair_style gran/*` before it.
    legacy_wall_style: Option<String>,
    /// Words of every logical line of the deck, and the index of the line
    /// being converted (rules that need the commands that follow, e.g. the
    /// runs an insertion fix stays active for).
    pub all: &'a [Vec<String>],
    /// Index in `all` of the line being converted.
    pub pos: usize,
    /// Insertion fixes turned into `fix pour`: fix ID -> the LAMMPS
    /// variable that stands for their `f_ID[1]` (particles inserted).
    pub insert_counts: HashMap<String, String>,
    /// Insertion fixes converted so far.
    pub inserts_seen: usize,
    /// Lines to emit after the next `run` (e.g. the velocity of particles a
    /// converted insertion put in on that run's first step).
    pub after_run: Vec<String>,
    /// Repeated insertions emulated by packing passes between split runs.
    pub insert_schedules: Vec<lammps::InsertSchedule>,
}

impl<'a> Ctx<'a> {
    fn new(facts: &'a Facts, all: &'a [Vec<String>]) -> Ctx<'a> {
        Ctx {
            all,
            pos: 0,
            insert_counts: HashMap::new(),
            inserts_seen: 0,
            after_run: Vec::new(),
            insert_schedules: Vec::new(),
            facts,
            notes: Vec::new(),
            used_seeds: HashSet::new(),
            next_seed: 15485863,
            split_ids: HashMap::new(),
            dropped_fixes: HashSet::new(),
            model: None,
            wall_model: None,
            pair_done: false,
            pair_dropped: false,
            granular: false,
            liggghts_walls: None,
            legacy_wall_style: None,
        }
    }
    /// Add a note to the current line.
    pub fn note(&mut self, s: Severity, msg: String) {
        self.notes.push((s, msg));
    }
    /// A fresh prime seed > 10000 not used elsewhere in the deck.
    pub fn new_seed(&mut self) -> u64 {
        loop {
            let s = self.next_seed;
            self.next_seed += 1;
            if legacy::is_prime(s) && !self.used_seeds.contains(&s) {
                self.used_seeds.insert(s);
                return s;
            }
        }
    }
}

/// Paper-model keywords only demx implements.
const DEMX_ONLY: &[&str] = &["hertz/viscoelastic", "epsd/paper", "aeolian/wind"];

fn demx_only(w: &[String]) -> Option<String> {
    for (i, x) in w.iter().enumerate() {
        if DEMX_ONLY.contains(&x.as_str()) {
            return Some(x.clone());
        }
        if x == "cohesion" && w.get(i + 1).map(|s| s.as_str()) == Some("vdw") {
            return Some("cohesion vdw".into());
        }
    }
    None
}

/// Legacy (1.x/2.x) -> 3.x rules for one command.
fn legacy_rules(ctx: &mut Ctx, w: &[String], to: Target) -> Action {
    let r = match w[0].as_str() {
        "pair_style" => legacy::pair_style(ctx, w),
        "dump" => legacy::dump(ctx, w),
        "unfix" if w.len() == 2 => ctx.split_ids.get(&w[1]).map(|ids| Action::Replace(ids.iter().map(|i| format!("unfix {i}")).collect())),
        "set" if w.iter().any(|x| x == "property/peratom") => Some(Action::Replace(vec![w
            .iter()
            .map(|x| if x == "property/peratom" { "property/atom" } else { x.as_str() })
            .collect::<Vec<_>>()
            .join(" ")])),
        "fix" if w.len() >= 4 => {
            let style = w[3].as_str();
            if style.starts_with("wall/gran/") && style != "wall/gran/region" {
                legacy::wall(ctx, w)
            } else if style == "mesh/gran" || style == "mesh" {
                legacy::mesh(ctx, w)
            } else if style == "move/mesh/gran" {
                legacy::move_mesh(ctx, w)
            } else if style == "pour/legacy" || (style == "pour" && to == Target::Liggghts) {
                legacy::pour_to_insert(ctx, w)
            } else if style == "pour/dev" {
                legacy::pour_dev(ctx, w)
            } else if style == "heat/gran" {
                legacy::heat(ctx, w)
            } else if style == "heat/radiation" {
                Some(Action::Drop("heat/radiation is not part of LIGGGHTS 3.8".into(), Severity::Dropped))
            } else if to == Target::Liggghts {
                legacy::seeds(ctx, w)
            } else {
                None
            }
        }
        _ => None,
    };
    r.unwrap_or(Action::Keep)
}

const MATERIALS: &[&str] =
    &["youngsModulus", "poissonsRatio", "coefficientRestitution", "coefficientFriction", "kn", "kt", "gamman", "gammat", "characteristicVelocity"];

/// References to dropped fixes (`f_ID`, `f_ID[i]`).
fn refs_dropped(ctx: &Ctx, word: &str) -> bool {
    word.strip_prefix("f_")
        .map(|r| r.split('[').next().unwrap_or(r))
        .is_some_and(|id| ctx.dropped_fixes.contains(id) || !ctx.facts.fix_ids.contains(id))
}

/// `f_ID[1]` of an insertion fix that became `fix pour` (which has no
/// output) -> the variable counting the particles it inserted.
fn rewrite_insert_refs(ctx: &mut Ctx, w: &[String]) -> Option<Vec<String>> {
    if ctx.insert_counts.is_empty() || w[0] == "fix" {
        return None;
    }
    let mut hit = false;
    let out: Vec<String> = w
        .iter()
        .map(|x| {
            let mut x = x.clone();
            for (id, var) in &ctx.insert_counts {
                for pat in [format!("f_{id}[1]"), format!("f_{id}")] {
                    if x.contains(&pat) && !x.contains(&format!("f_{id}[2]")) {
                        x = x.replace(&pat, &format!("v_{var}"));
                        hit = true;
                    }
                }
            }
            x
        })
        .collect();
    if hit {
        ctx.note(Severity::Approx, "f_ID[1] of the insertion fix (particles inserted) -> a count of atoms since the fix was defined (fix pour has no output; lost atoms count against it)".into());
    }
    hit.then_some(out)
}

/// 3.x -> LAMMPS rules for one command.
fn lammps_rules(ctx: &mut Ctx, w: &[String]) -> Action {
    if let Some(v) = rewrite_insert_refs(ctx, w) {
        return match lammps_rules(ctx, &v) {
            Action::Keep => Action::Replace(vec![v.join(" ")]),
            a => a,
        };
    }
    let r = match w[0].as_str() {
        "atom_style" if w.get(1).map(|s| s.as_str()) == Some("granular") => {
            Some(Action::Replace(vec![if ctx.facts.has_adapt { "atom_style sphere 1".into() } else { "atom_style sphere".into() }]))
        }
        "atom_modify" if ctx.facts.has_insertion && w.windows(2).any(|p| p[0] == "map" && p[1] == "array") => {
            ctx.note(
                Severity::Info,
                "atom_modify map array -> map hash: LAMMPS 29Sep2021 fix pour segfaults in Atom::map_set with map array (observed)".into(),
            );
            Some(Action::Replace(vec![w.iter().map(|x| if x == "array" { "hash" } else { x.as_str() }).collect::<Vec<_>>().join(" ")]))
        }
        "run" if !ctx.insert_schedules.is_empty() => lammps::split_run(ctx, w).or_else(|| {
            ctx.note(Severity::Approx, "this run is not a constant: the repeated insertion is not carried into it".into());
            None
        }),
        "unfix" if w.len() == 2 && ctx.insert_schedules.iter().any(|sc| sc.id == w[1]) => {
            ctx.insert_schedules.retain(|sc| sc.id != w[1]);
            Some(Action::Drop("the insertion ends here (its packing passes were placed between the runs above)".into(), Severity::Info))
        }
        "run" if !ctx.after_run.is_empty() => {
            let mut v = vec![w.join(" ")];
            v.append(&mut ctx.after_run);
            Some(Action::Replace(v))
        }
        // LIGGGHTS (old LAMMPS) takes the whole-line format string
        "dump_modify"
            if w.get(2).map(|s| s.as_str()) == Some("format")
                && w.get(3).is_some_and(|x| !matches!(x.as_str(), "line" | "int" | "float" | "none")) =>
        {
            let mut v = w.to_vec();
            v.insert(3, "line".into());
            Some(Action::Replace(vec![v.join(" ")]))
        }
        "hard_particles" | "soft_particles" => {
            Some(Action::Drop(format!("{}: a LIGGGHTS switch for large overlaps; LAMMPS has none", w[0]), Severity::Info))
        }
        "communicate" => {
            if w.windows(2).any(|p| p[0] == "vel" && p[1] == "yes") {
                Some(Action::Replace(vec!["comm_modify vel yes".into()]))
            } else {
                Some(Action::Replace(vec![format!(
                    "comm_modify {}",
                    w[1..].iter().filter(|x| *x != "single").cloned().collect::<Vec<_>>().join(" ")
                )]))
            }
        }
        "pair_style" => {
            lammps::note_classic_style(ctx, w);
            lammps::pair_style_to_lammps(ctx, w)
        }
        "pair_coeff" => lammps::pair_coeff_to_lammps(ctx, w),
        "compute_modify" if w.iter().any(|x| x == "dynamic") => {
            Some(Action::Replace(vec![w.iter().map(|x| if x == "dynamic" { "dynamic/dof" } else { x.as_str() }).collect::<Vec<_>>().join(" ")]))
        }
        "dump" if w.get(3).map(|s| s.as_str()) == Some("custom") && w.iter().skip(6).any(|x| refs_dropped(ctx, x)) => {
            let kept: Vec<String> = w.iter().enumerate().filter(|(i, x)| *i < 6 || !refs_dropped(ctx, x)).map(|(_, x)| x.clone()).collect();
            ctx.note(Severity::Approx, "dump columns of dropped or implicit LIGGGHTS fixes removed".into());
            Some(Action::Replace(vec![kept.join(" ")]))
        }
        "dump" if w.len() >= 4 => match w[3].as_str() {
            "custom/vtk" => {
                ctx.note(Severity::Approx, "dump custom/vtk written as a LAMMPS text dump custom (Debian LAMMPS has no VTK dumps)".into());
                let mut v = w.to_vec();
                v[3] = "custom".into();
                if let Some(f) = v.get_mut(5) {
                    *f = f.replace(".vtk", ".txt");
                }
                Some(Action::Replace(vec![v.join(" ")]))
            }
            "mesh/stl" | "mesh/vtk" | "local/gran/vtk" | "mesh/vtm" | "stl" | "mesh/gran/VTK" | "custom/vtm" | "atom/vtk" | "euler/vtk"
            | "decomposition/vtk" => {
                ctx.dropped_fixes.insert(w[1].clone());
                Some(Action::Drop(format!("dump {} has no LAMMPS counterpart", w[3]), Severity::Dropped))
            }
            _ => None,
        },
        "dump_modify" | "undump" if ctx.dropped_fixes.contains(w.get(1).map(|s| s.as_str()).unwrap_or("")) => {
            Some(Action::Drop("refers to a dropped dump".into(), Severity::Info))
        }
        "unfix" if w.len() == 2 && ctx.dropped_fixes.contains(&w[1]) => Some(Action::Drop("refers to a dropped fix".into(), Severity::Info)),
        "thermo_style" if w.iter().any(|x| refs_dropped(ctx, x)) => {
            let kept: Vec<String> = w.iter().filter(|x| !refs_dropped(ctx, x)).cloned().collect();
            ctx.note(Severity::Approx, "thermo columns of dropped fixes removed".into());
            Some(Action::Replace(vec![kept.join(" ")]))
        }
        "fix" if w.len() >= 4 => {
            let style = w[3].as_str();
            let r = match style {
                "property/global" => {
                    let name = w.get(4).map(|s| s.as_str()).unwrap_or("");
                    if MATERIALS.contains(&name) {
                        Some(Action::Drop("material value moved into the pair_coeff / wall coefficients".into(), Severity::Info))
                    } else {
                        Some(Action::Drop(format!("property/global {name} has no LAMMPS counterpart"), Severity::Dropped))
                    }
                }
                "wall/gran" => lammps::legacy_wall_to_lammps(ctx, w).or_else(|| lammps::wall_to_lammps(ctx, w)),
                "insert/pack" | "insert/rate/region" if ctx.facts.gravity.is_none() => {
                    Some(Action::Drop("LAMMPS fix pour (the only insertion fix) needs fix gravity".into(), Severity::Dropped))
                }
                "insert/pack" | "insert/rate/region" => lammps::insert_to_pour(ctx, w),
                "pour" | "pour/legacy" => lammps::pour_to_lammps(ctx, w),
                s if s.starts_with("particletemplate/") || s.starts_with("particledistribution/") => {
                    Some(Action::Drop("template folded into fix pour".into(), Severity::Info))
                }
                s if s.starts_with("mesh/surface")
                    || s.starts_with("move/mesh")
                    || s.starts_with("insert/")
                    || s.starts_with("couple/")
                    || s.starts_with("heat/")
                    || s.starts_with("check/timestep")
                    || s == "property/atom"
                    || s.starts_with("massflow")
                    || s.starts_with("multisphere") =>
                {
                    Some(Action::Drop(format!("fix {s} has no LAMMPS counterpart"), Severity::Dropped))
                }
                _ => None,
            };
            if let Some(Action::Drop(..)) = &r {
                ctx.dropped_fixes.insert(w[1].clone());
            }
            r
        }
        _ => None,
    };
    r.unwrap_or(Action::Keep)
}

/// LAMMPS -> LIGGGHTS 3.x rules for one command.
fn liggghts_rules(ctx: &mut Ctx, w: &[String], coeffs: &[Vec<String>]) -> Action {
    let r = match w[0].as_str() {
        "comm_modify" => {
            if w.windows(2).any(|p| p[0] == "vel" && p[1] == "yes") {
                Some(Action::Replace(vec!["communicate single vel yes".into()]))
            } else {
                Some(Action::Drop("comm_modify without vel yes: LIGGGHTS uses communicate".into(), Severity::Info))
            }
        }
        "newton" if w.get(1).map(|s| s.as_str()) == Some("on") => {
            ctx.note(Severity::Info, "newton off (LIGGGHTS granular pair styles with history require it)".into());
            Some(Action::Replace(vec!["newton off".into()]))
        }
        "pair_style" => lammps::classic_to_liggghts(ctx, w).or_else(|| lammps::granular_to_liggghts(ctx, w)),
        "pair_coeff" => lammps::granular_coeff_to_liggghts(ctx, w, coeffs),
        "compute_modify" if w.iter().any(|x| x == "dynamic/dof") => {
            Some(Action::Replace(vec![w.iter().map(|x| if x == "dynamic/dof" { "dynamic" } else { x.as_str() }).collect::<Vec<_>>().join(" ")]))
        }
        "dump_modify" if w.iter().any(|x| x == "format") && w.iter().any(|x| x == "float") => {
            Some(Action::Drop("LIGGGHTS accepts only a whole-line dump format".into(), Severity::Approx))
        }
        "fix" if w.len() >= 4 => match w[3].as_str() {
            "wall/gran" => lammps::wall_to_liggghts(ctx, w),
            "pour" => lammps::pour_to_liggghts(ctx, w),
            "wall/gran/region" => Some(Action::Drop("LIGGGHTS has no granular region walls (use mesh/surface)".into(), Severity::Dropped)),
            _ => None,
        },
        _ => None,
    };
    r.unwrap_or(Action::Keep)
}

/// One output item.
enum Item {
    Line(String),
    Comment(String, Vec<String>),
}

/// Whether a deck is written for LIGGGHTS 1.x/2.x: a `pair_style
/// gran/hooke...` or `gran/hertz/history`, or a `fix wall/gran/STYLE`, whose
/// words are not LAMMPS's numbers (a word with `$` or `v_` counts as a
/// number), or a `fix mesh/gran` or `move/mesh/gran`. LIGGGHTS 3.8 rejects
/// such decks; `demx run` converts them in memory.
pub fn is_legacy_liggghts(src: &str) -> bool {
    let numbers = |w: &[String]| w.iter().all(|x| deck::is_number(x) || x == "NULL" || x.contains('$') || x.starts_with("v_"));
    logical_lines(src).iter().any(|l| {
        let w = l.words();
        match w.first().map(String::as_str) {
            Some("pair_style") if w.len() >= 2 && matches!(w[1].as_str(), "gran/hooke" | "gran/hooke/history" | "gran/hertz/history") => {
                !(w.len() >= 7 && numbers(&w[2..7]))
            }
            Some("fix") if w.len() >= 4 => {
                let style = w[3].as_str();
                (style.starts_with("wall/gran/") && style != "wall/gran/region" && !(w.len() >= 9 && numbers(&w[4..9])))
                    || style == "mesh/gran"
                    || style == "move/mesh/gran"
            }
            _ => false,
        }
    })
}

/// Convert deck text to `to`. Never fails on deck content: what cannot be
/// converted is commented out and noted.
pub fn convert(src: &str, to: Target) -> Converted {
    let lines = logical_lines(src);
    let facts = Facts::gather(&lines);
    let all: Vec<Vec<String>> = lines.iter().map(|l| l.words()).collect();
    let mut ctx = Ctx::new(&facts, &all);
    // seeds already valid in the deck are reserved
    for lg in &lines {
        for x in lg.words() {
            if let Ok(v) = x.parse::<u64>() {
                if v > 10000 && legacy::is_prime(v) {
                    ctx.used_seeds.insert(v);
                }
            }
        }
    }
    let coeffs: Vec<Vec<String>> = lines.iter().map(|l| l.words()).filter(|w| w.first().map(|s| s.as_str()) == Some("pair_coeff")).collect();
    let mut out = String::new();
    let mut notes = Vec::new();
    for (pos, lg) in lines.iter().enumerate() {
        ctx.pos = pos;
        let w = lg.words();
        let mut items = Vec::new();
        if w.is_empty() {
            emit_original(&mut out, lg);
            continue;
        }
        if let Some(k) = demx_only(&w) {
            ctx.note(Severity::DemxOnly, format!("'{k}' is a demx-only paper model: neither LIGGGHTS nor LAMMPS has it"));
            items.push(Item::Comment(format!("'{k}' is demx-only"), lg.physical.clone()));
        } else {
            let first = legacy_rules(&mut ctx, &w, to);
            let stage1: Vec<(String, bool)> = match first {
                Action::Keep => vec![(lg.command.clone(), false)],
                Action::Replace(v) => v.into_iter().map(|l| (l, true)).collect(),
                Action::Drop(why, sev) => {
                    push_drop(&mut ctx, &mut items, lg, &why, sev, None);
                    Vec::new()
                }
            };
            for (line, changed) in stage1 {
                let ww = deck::split_words(&line);
                let a = match to {
                    Target::Lammps => lammps_rules(&mut ctx, &ww),
                    Target::Liggghts => liggghts_rules(&mut ctx, &ww, &coeffs),
                };
                match a {
                    Action::Keep if !changed => items.push(Item::Line(String::new())),
                    Action::Keep => items.push(Item::Line(line)),
                    Action::Replace(v) => items.extend(v.into_iter().map(Item::Line)),
                    Action::Drop(why, sev) => push_drop(&mut ctx, &mut items, lg, &why, sev, changed.then_some(line)),
                }
            }
        }
        for (s, m) in ctx.notes.drain(..) {
            notes.push(Note { line: lg.line, severity: s, message: m });
        }
        // unchanged single line: copy the bytes
        if items.len() == 1 && matches!(&items[0], Item::Line(l) if l.is_empty()) {
            emit_original(&mut out, lg);
            continue;
        }
        let mut comment_used = false;
        for it in items {
            match it {
                Item::Line(l) if l.is_empty() => emit_original(&mut out, lg),
                Item::Line(l) => {
                    out.push_str(&lg.indent);
                    out.push_str(&l);
                    if let (Some(c), false) = (&lg.comment, comment_used) {
                        out.push(' ');
                        out.push_str(c);
                        comment_used = true;
                    }
                    out.push_str(eol(lg));
                }
                Item::Comment(why, text) => {
                    out.push_str(&format!("# demx: {why}{}", eol(lg)));
                    for t in text {
                        out.push_str("# ");
                        out.push_str(&t);
                        out.push_str(eol(lg));
                    }
                }
            }
        }
    }
    Converted { text: out, notes }
}

fn eol(lg: &Logical) -> &str {
    if lg.eol.is_empty() {
        "\n"
    } else {
        &lg.eol
    }
}

fn push_drop(ctx: &mut Ctx, items: &mut Vec<Item>, lg: &Logical, why: &str, sev: Severity, generated: Option<String>) {
    ctx.note(sev.max(Severity::Info), why.to_string());
    let text = match generated {
        Some(g) => vec![g],
        None => lg.physical.clone(),
    };
    items.push(Item::Comment(why.to_string(), text));
}

fn emit_original(out: &mut String, lg: &Logical) {
    let n = lg.physical.len();
    for (i, p) in lg.physical.iter().enumerate() {
        out.push_str(p);
        if i + 1 < n {
            out.push_str(if lg.eol == "\r\n" { "\r\n" } else { "\n" });
        } else {
            out.push_str(&lg.eol);
        }
    }
}

/// Command line of `demx convert`.
#[derive(Parser, Debug)]
#[command(name = "demx convert", about = "Convert a LIGGGHTS 1.x/2.x/3.x or LAMMPS granular deck")]
struct Args {
    /// Input deck.
    deck: PathBuf,
    /// Target dialect.
    #[arg(long, value_enum)]
    to: Target,
    /// Output file (default: standard output).
    #[arg(short = 'o', long = "output")]
    out: Option<PathBuf>,
    /// Print a JSON report (with the text when no -o is given).
    #[arg(long)]
    json: bool,
}

/// Entry point: `args` are the words after `convert`.
pub fn cli(args: Vec<String>) -> ExitCode {
    let argv = std::iter::once("demx convert".to_string()).chain(args);
    let a = match Args::try_parse_from(argv) {
        Ok(a) => a,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let bytes = match std::fs::read(&a.deck) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error: cannot read {}: {e}", a.deck.display());
            return ExitCode::from(2);
        }
    };
    if bytes.contains(&0) {
        eprintln!("error: {} is not a text deck (NUL bytes)", a.deck.display());
        return ExitCode::from(2);
    }
    let src = crate::script::source::decode(&bytes);
    let c = convert(&src, a.to);
    for n in &c.notes {
        if n.severity > Severity::Info {
            let kind = match n.severity {
                Severity::Approx => "approximated",
                Severity::Dropped => "dropped",
                _ => "demx-only",
            };
            eprintln!("warning: {}:{}: {kind}: {}", a.deck.display(), n.line, n.message);
        }
    }
    if c.demx_only() {
        eprintln!("warning: {} uses demx-only paper models; the converted deck will not reproduce them", a.deck.display());
    }
    if let Some(o) = &a.out {
        if let Err(e) = std::fs::write(o, &c.text) {
            eprintln!("error: cannot write {}: {e}", o.display());
            return ExitCode::from(1);
        }
    }
    if a.json {
        let v = serde_json::json!({
            "deck": a.deck.display().to_string(),
            "to": match a.to { Target::Liggghts => "liggghts", Target::Lammps => "lammps" },
            "exit": c.exit_code(),
            "demx_only": c.demx_only(),
            "notes": c.notes,
            "text": if a.out.is_none() { Some(c.text.clone()) } else { None },
        });
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else if a.out.is_none() {
        print!("{}", c.text);
    }
    ExitCode::from(c.exit_code())
}
