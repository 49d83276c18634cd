//! Output commands: thermo, thermo_style, thermo_modify, dump, dump_modify,
//! undump, compute, uncompute.

use super::args::{bad_keyword, Args};
use super::Session;
use crate::engine::compute::{Compute, ComputeKind};
use crate::engine::output::{Dump, LostPolicy};
use crate::engine::sim::{Dialect, Sim};
use crate::error::{Error, Result};
use crate::io::dump::{DumpOptions, DumpWriter, Engine, FormatSpec, Frame, SortBy};
use crate::script::{Command, Variables};

/// Execute an output command.
pub fn execute(s: &mut Session, cmd: &Command, vars: &mut Variables) -> Result<()> {
    let _ = vars;
    let mut a = Args::new(cmd);
    match cmd.name() {
        "thermo" => {
            let w = a.word("N")?;
            if let Some(v) = w.text.strip_prefix("v_") {
                return Err(Error::unsupported(w.span, format!("thermo v_{v} (variable thermo interval)")));
            }
            let every = super::args::parse_i64(w)?;
            // LAMMPS 29 Sep 2021 and LIGGGHTS 3.8 both stop on `thermo -1`
            // ("Illegal thermo command"); `thermo 0` (first and last step
            // only) is theirs too
            if !(0..=i64::from(i32::MAX)).contains(&every) {
                return Err(Error::deck(w.span, format!("thermo: N must be between 0 and {}, not {every}", i32::MAX))
                    .with_hint("LAMMPS and LIGGGHTS: Illegal thermo command"));
            }
            s.sim.thermo.every = every;
            Ok(())
        }
        "thermo_style" => {
            let st = a.choice("thermo style", &["one", "multi", "custom", "yaml"])?;
            match st.text.as_str() {
                "one" => s.sim.thermo.one = true,
                "custom" => {
                    let mut ks = vec![];
                    for w in a.rest() {
                        check_thermo_keyword(s, w)?;
                        ks.push(w.text.clone());
                    }
                    if ks.is_empty() {
                        return Err(Error::deck(a.end_span(), "thermo_style custom: no keywords"));
                    }
                    s.sim.thermo.keywords = ks;
                    s.sim.thermo.one = false;
                }
                other => return Err(Error::unsupported(st.span, format!("thermo_style {other}"))),
            }
            Ok(())
        }
        "thermo_modify" => {
            while a.more() {
                let k = a.word("keyword")?;
                match k.text.as_str() {
                    "lost" => {
                        let v = a.choice("lost policy", &["error", "warn", "ignore"])?;
                        s.sim.thermo.lost = match v.text.as_str() {
                            "error" => LostPolicy::Error,
                            "warn" => LostPolicy::Warn,
                            _ => LostPolicy::Ignore,
                        };
                    }
                    "norm" => {
                        s.sim.thermo.norm = a.yes_no("norm")?;
                        s.sim.thermo.norm_set = true;
                    }
                    "flush" | "line" => {
                        a.word("value")?;
                    }
                    "lost/bond" | "temp" | "press" => {
                        a.word("value")?;
                    }
                    "every" => {
                        a.word("value")?;
                    }
                    "format" => {
                        let what = a.word("format target")?;
                        let f = a.str("format")?.to_string();
                        match what.text.as_str() {
                            "line" => s.sim.thermo.format_line = Some(f),
                            "int" => s.sim.thermo.format_int = Some(f),
                            "float" => s.sim.thermo.format_float = Some(f),
                            "none" => {
                                s.sim.thermo.format_line = None;
                                s.sim.thermo.format_int = None;
                                s.sim.thermo.format_float = None;
                                s.sim.thermo.format_col.clear();
                            }
                            n => {
                                let col: usize = n.parse().map_err(|_| bad_keyword(what, "format target", &["line", "int", "float", "N"]))?;
                                s.sim.thermo.format_col.push((col, f));
                            }
                        }
                    }
                    _ => return Err(bad_keyword(k, "thermo_modify keyword", &["lost", "norm", "flush", "format", "line", "temp", "press"])),
                }
            }
            Ok(())
        }
        "compute" => compute_command(s, &mut a),
        "uncompute" => {
            let w = a.word("compute id")?;
            let before = s.sim.computes.len();
            if let Some(c) = s.sim.computes.iter().find(|c| c.id == w.text) {
                if let ComputeKind::DisplaceAtom { column } = &c.kind {
                    let p = &mut s.sim.particles;
                    if let Some(e) = p.extra_index(column) {
                        p.extra.remove(e);
                    }
                }
            }
            s.sim.computes.retain(|c| c.id != w.text);
            if s.sim.computes.len() == before {
                return Err(Error::deck(w.span, format!("uncompute: compute '{}' does not exist", w.text)));
            }
            Ok(())
        }
        "dump" => dump_command(s, cmd, &mut a, false),
        "write_dump" => write_dump(s, cmd),
        "dump_modify" => {
            let w = a.word("dump id")?;
            let k = s
                .sim
                .dumps
                .iter()
                .position(|d| d.id() == w.text)
                .ok_or_else(|| Error::deck(w.span, format!("dump_modify: dump '{}' does not exist", w.text)))?;
            let rest = a.rest();
            s.sim.dumps[k].modify(rest)
        }
        "undump" => {
            let w = a.word("dump id")?;
            let before = s.sim.dumps.len();
            s.sim.dumps.retain(|d| d.id() != w.text);
            if s.sim.dumps.len() == before {
                return Err(Error::deck(w.span, format!("undump: dump '{}' does not exist", w.text)));
            }
            Ok(())
        }
        _ => unreachable!("outputs::execute dispatched a command it does not handle"),
    }
}

fn check_thermo_keyword(s: &Session, w: &crate::script::Word) -> Result<()> {
    let k = w.text.as_str();
    if k.starts_with("c_") || k.starts_with("f_") || k.starts_with("v_") {
        return Ok(());
    }
    if crate::engine::output::thermo_keyword(&s.sim, k).is_some() || crate::engine::output::TENSOR_KEYWORDS.contains(&k) {
        return Ok(());
    }
    const OTHER: &[&str] = &[
        "enthalpy",
        "ecouple",
        "econserve",
        "xy",
        "xz",
        "yz",
        "fmax",
        "fnorm",
        "part",
        "timeremain",
        "tpcpu",
        "lat",
        "bonds",
        "angles",
        "dihedrals",
        "impropers",
        "cella",
        "cellb",
        "cellc",
        "cellalpha",
        "cellbeta",
        "cellgamma",
        "evdwl",
        "ecoul",
        "epair",
        "ebond",
        "eangle",
        "edihed",
        "eimp",
        "emol",
        "elong",
        "etail",
        "xlat",
        "ylat",
        "zlat",
        "nbuild",
        "ndanger",
    ];
    if OTHER.contains(&k) {
        return Err(Error::unsupported(w.span, format!("thermo keyword {k}")));
    }
    Err(Error::deck(w.span, format!("unknown thermo keyword '{k}'")))
}

fn compute_command(s: &mut Session, a: &mut Args) -> Result<()> {
    let id = a.word("compute id")?;
    let g = a.word("group")?;
    let group = s.group(g)?;
    let style = a.word("compute style")?;
    let kind = match style.text.as_str() {
        "ke" => ComputeKind::Ke,
        "erotate/sphere" => ComputeKind::ErotateSphere,
        "temp" => ComputeKind::Temp,
        "com" => ComputeKind::Com,
        "reduce" => {
            let mode = a.choice("reduce mode", &["sum", "min", "max", "ave", "sumsq", "avesq", "sumabs", "aveabs"])?;
            let mut inputs = vec![];
            for w in a.rest() {
                if ["replace", "inputs"].contains(&w.text.as_str()) {
                    break;
                }
                if w.text.starts_with("v_") || w.text.starts_with("f_") {
                    return Err(Error::unsupported(w.span, format!("compute reduce of {}", w.text)));
                }
                uncomputed(s, w, "compute reduce of")?;
                inputs.push(w.text.clone());
            }
            ComputeKind::Reduce { mode: mode.text.clone(), inputs }
        }
        "property/atom" => {
            let mut names = vec![];
            for w in a.rest() {
                if !is_atom_property_name(&w.text) {
                    return Err(Error::unsupported(w.span, format!("compute property/atom {}", w.text)));
                }
                names.push(w.text.clone());
            }
            ComputeKind::PropertyAtom { names }
        }
        "displace/atom" => {
            // Originals: the group's unwrapped positions now, 0 elsewhere (the
            // compute reports 0 outside its group). Atoms created later get
            // their position at creation in LAMMPS (`set_arrays`); LIGGGHTS
            // 3.8 leaves them at 0, so their displacement is their position
            // (seen in its dumps of the liggghts-inl dump_custom_vtk deck). A
            // column restored from a restart keeps its originals, as the
            // engines' fix store does for the same compute id.
            if a.more() {
                let k = a.word("displace/atom keyword")?;
                return Err(Error::unsupported(k.span, format!("compute displace/atom keyword {}", k.text)));
            }
            let column = format!("displace/atom:{}", id.text);
            let fresh = s.sim.particles.extra_index(&column).is_none();
            let originals: Vec<f64> = (0..s.sim.particles.len())
                .flat_map(|i| if s.sim.particles.mask[i] & group != 0 { crate::engine::compute::unwrapped(&s.sim, i).into() } else { [0.0; 3] })
                .collect();
            let p = &mut s.sim.particles;
            let e = p.add_extra(&column, vec![0.0; 3]);
            // the dialect may be settled later in the deck: each run's start sets this again
            p.extra[e].from_position = s.sim.dialect == crate::engine::Dialect::Lammps;
            if fresh {
                p.extra[e].data = originals;
            }
            ComputeKind::DisplaceAtom { column }
        }
        // LIGGGHTS 3.8 and LAMMPS (GRANULAR) alike
        "contact/atom" => {
            if a.more() {
                a.choice("contact/atom keyword", &["skin"])?;
                let w = a.word("skin")?;
                if super::args::parse_f64(w)? != 0.0 {
                    return Err(Error::unsupported(w.span, "compute contact/atom skin other than 0 (contacts within a distance)"));
                }
            }
            ComputeKind::ContactAtom
        }
        // LIGGGHTS 3.8's form: a cutoff, then type ranges (one column each)
        "coord/atom" => {
            let cutoff = a.f64("coord/atom cutoff")?;
            if !(cutoff > 0.0) || !cutoff.is_finite() {
                return Err(a.err_prev(format!("compute coord/atom: cutoff must be positive, not {cutoff}")));
            }
            let ntypes = s.sim.ntypes.max(1) as u32;
            let mut types = vec![];
            while a.more() {
                let w = a.word("type range")?;
                if w.text == "group" || w.text == "cstyle" || w.text == "orientorder/atom" {
                    return Err(Error::unsupported(w.span, format!("compute coord/atom keyword {} (a later LAMMPS's)", w.text)));
                }
                let (lo, hi) = super::args::type_range(w, ntypes)?;
                types.push((lo, hi));
            }
            if types.is_empty() {
                types.push((1, ntypes));
            }
            ComputeKind::CoordAtom { cutoff, types }
        }
        // defined by decks that never read it (a deck reading it stops
        // there with exit 3: see `uncomputed`)
        "stress/atom" => ComputeKind::Other(style.text.clone()),
        other => {
            return Err(Error::unsupported(style.span, format!("compute {other}")));
        }
    };
    let c = Compute { id: id.text.clone(), group, kind, style: style.text.clone() };
    match s.sim.computes.iter().position(|x| x.id == c.id) {
        Some(k) => s.sim.computes[k] = c,
        None => s.sim.computes.push(c),
    }
    Ok(())
}

/// A `c_ID` reference to a compute demx defines but does not compute yet
/// (`ComputeKind::Other`): exit 3 where it is read.
fn uncomputed(s: &Session, w: &crate::script::Word, what: &str) -> Result<()> {
    let Some(rest) = w.text.strip_prefix("c_") else {
        return Ok(());
    };
    let cid = rest.split('[').next().unwrap_or("");
    match s.sim.computes.iter().find(|c| c.id == cid).map(|c| &c.kind) {
        Some(ComputeKind::Other(style)) => Err(Error::unsupported(w.span, format!("{what} {} (compute {style} is not computed yet)", w.text))),
        _ => Ok(()),
    }
}

fn is_atom_property_name(n: &str) -> bool {
    matches!(
        n,
        "id" | "type"
            | "mass"
            | "radius"
            | "diameter"
            | "density"
            | "x"
            | "y"
            | "z"
            | "xu"
            | "yu"
            | "zu"
            | "xs"
            | "ys"
            | "zs"
            | "ix"
            | "iy"
            | "iz"
            | "vx"
            | "vy"
            | "vz"
            | "fx"
            | "fy"
            | "fz"
            | "omegax"
            | "omegay"
            | "omegaz"
            | "tqx"
            | "tqy"
            | "tqz"
            | "angmomx"
            | "angmomy"
            | "angmomz"
            | "mol"
            | "q"
    )
}

/// `dump custom` / `dump atom` through [`DumpWriter`].
pub struct DumpText {
    id: String,
    group: u32,
    columns: Vec<String>,
    writer: Option<DumpWriter>,
    opts: DumpOptions,
    path: String,
    last_step: Option<i64>,
    summary: String,
}

impl DumpText {
    fn ensure_open(&mut self) -> Result<&mut DumpWriter> {
        if self.writer.is_none() {
            self.writer = Some(DumpWriter::create(&self.path, self.opts.clone())?);
        }
        Ok(self.writer.as_mut().expect("just opened"))
    }
}

impl Dump for DumpText {
    fn due(&self, step: i64, first: bool) -> bool {
        if self.last_step == Some(step) {
            return false;
        }
        let every = self.opts.every as i64;
        (every > 0 && step % every == 0) || (first && self.opts.first)
    }
    fn write(&mut self, sim: &Sim) -> Result<()> {
        if sim.dry {
            return Ok(());
        }
        self.last_step = Some(sim.step);
        let input_cols: Vec<String> = match self.opts.style {
            crate::io::dump::DumpStyle::Custom => self.columns.clone(),
            crate::io::dump::DumpStyle::Atom => ["id", "type", "x", "y", "z", "ix", "iy", "iz"].iter().map(|s| s.to_string()).collect(),
        };
        let frame = make_frame(sim, self.group, input_cols)?;
        self.ensure_open()?.write_frame(&frame)
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn modify(&mut self, args: &[crate::script::Word]) -> Result<()> {
        self.modify_opts(args)
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
    fn checkpoint_file(&self) -> crate::engine::output::DumpFile {
        use crate::engine::output::DumpFile;
        if self.path.contains('*') || self.writer.is_none() {
            DumpFile::Fresh
        } else if self.path.ends_with(".gz") {
            // a gzip stream cannot be cut back at a frame and appended to
            DumpFile::Unsupported
        } else {
            DumpFile::Appended(self.path.clone().into())
        }
    }
    fn last_step(&self) -> Option<i64> {
        self.last_step
    }
    fn resume_at(&mut self, last_step: Option<i64>, append: bool) {
        self.last_step = last_step;
        self.opts.append |= append;
    }
}

/// The frame of group `group` with the given columns at the current step.
fn make_frame(sim: &Sim, group: u32, input_cols: Vec<String>) -> Result<Frame> {
    {
        let p = &sim.particles;
        let rows: Vec<usize> = (0..p.len()).filter(|&i| p.mask[i] & group != 0).collect();
        let mut values = Vec::with_capacity(rows.len() * input_cols.len());
        let mut col_vals: Vec<Vec<f64>> = Vec::with_capacity(input_cols.len());
        for c in &input_cols {
            col_vals.push(column_values(sim, c)?);
        }
        for &i in &rows {
            for cv in &col_vals {
                values.push(cv[i]);
            }
        }
        let d = sim.domain.as_ref().ok_or_else(|| Error::runtime("dump before the box exists"))?;
        let b = d.boundary_strings();
        let bounds = crate::io::dump::BoxBounds::orthogonal(d.lo, d.hi, &format!("{} {} {}", b[0], b[1], b[2]));
        Ok(Frame { timestep: sim.step.max(0) as u64, time: Some(sim.time), natoms: rows.len(), bounds, columns: input_cols, values })
    }
}

/// LIGGGHTS `dump custom/vtk`: one legacy VTK file per frame (`*` in the
/// name becomes the step) plus the `*_boundingBox_*` file of the box.
pub struct DumpVtk {
    id: String,
    group: u32,
    columns: Vec<String>,
    every: i64,
    first: bool,
    path: String,
    last_step: Option<i64>,
    summary: String,
}

impl Dump for DumpVtk {
    fn due(&self, step: i64, first: bool) -> bool {
        if self.last_step == Some(step) {
            return false;
        }
        (self.every > 0 && step % self.every == 0) || (first && self.first)
    }
    fn write(&mut self, sim: &Sim) -> Result<()> {
        if sim.dry {
            return Ok(());
        }
        self.last_step = Some(sim.step);
        let frame = make_frame(sim, self.group, self.columns.clone())?;
        let file = self.path.replace('*', &sim.step.to_string());
        crate::io::vtk::write_particles_vtk(&file, &frame)?;
        if self.path.contains('*') {
            if let Some(d) = &sim.domain {
                use crate::io::vtk::{format_bounding_box_vtk, format_bounding_box_vtr, VtkFormat};
                let bb = self.path.replace('*', &format!("boundingBox_{}", sim.step));
                let (lo, hi) = ([d.lo[0], d.lo[1], d.lo[2]], [d.hi[0], d.hi[1], d.hi[2]]);
                let (bb, text) = match VtkFormat::of(&bb) {
                    VtkFormat::Legacy => (bb, format_bounding_box_vtk(lo, hi)),
                    // beside .vtp and .vtu files, a .vtr
                    _ => (format!("{}.vtr", &bb[..bb.len() - 4]), format_bounding_box_vtr(lo, hi)),
                };
                crate::io::write_atomic(&bb, text.as_bytes())?;
            }
        }
        Ok(())
    }
    fn id(&self) -> &str {
        &self.id
    }
    fn modify(&mut self, args: &[crate::script::Word]) -> Result<()> {
        let mut k = 0;
        while k < args.len() {
            let w = &args[k];
            let v = args.get(k + 1).ok_or_else(|| Error::deck(w.span, format!("dump_modify {}: missing value", w.text)))?;
            match w.text.as_str() {
                "first" => self.first = matches!(v.text.as_str(), "yes" | "on"),
                "every" => self.every = super::args::parse_i64(v)?.max(0),
                "sort" | "flush" | "pad" | "precision" | "binary" | "label" | "compressor" | "format" => {}
                _ => return Err(Error::unsupported(w.span, format!("dump_modify {} for dump custom/vtk", w.text))),
            }
            k += 2;
        }
        Ok(())
    }
    fn summary(&self) -> String {
        self.summary.clone()
    }
}

impl DumpText {
    fn modify_opts(&mut self, args: &[crate::script::Word]) -> Result<()> {
        let mut k = 0;
        while k < args.len() {
            let w = &args[k];
            let val = |n: usize| args.get(k + n).ok_or_else(|| Error::deck(w.span, format!("dump_modify {}: missing value", w.text)));
            match w.text.as_str() {
                "format" => {
                    let what = val(1)?;
                    match what.text.as_str() {
                        "line" => {
                            self.opts.formats.push(FormatSpec::Line(val(2)?.text.clone()));
                            k += 3;
                        }
                        "float" => {
                            self.opts.formats.push(FormatSpec::Float(val(2)?.text.clone()));
                            k += 3;
                        }
                        "int" => {
                            self.opts.formats.push(FormatSpec::Int(val(2)?.text.clone()));
                            k += 3;
                        }
                        "none" => {
                            self.opts.formats.push(FormatSpec::None);
                            k += 2;
                        }
                        n => match n.parse::<usize>() {
                            Ok(c) => {
                                self.opts.formats.push(FormatSpec::Column(c, val(2)?.text.clone()));
                                k += 3;
                            }
                            Err(_) => {
                                // LIGGGHTS: `format "%d %d %g ..."` (whole line)
                                self.opts.formats.push(FormatSpec::Line(what.text.clone()));
                                k += 2;
                            }
                        },
                    }
                }
                "sort" => {
                    let v = val(1)?;
                    self.opts.sort = match v.text.as_str() {
                        "off" => None,
                        "id" => Some(SortBy::Id),
                        t => {
                            let n: i64 = t.parse().map_err(|_| Error::deck(v.span, "dump_modify sort: expected off, id or a column number"))?;
                            Some(SortBy::Column(n.unsigned_abs() as usize, n < 0))
                        }
                    };
                    k += 2;
                }
                "scale" | "image" | "first" | "append" => {
                    let v = val(1)?;
                    let on = matches!(v.text.as_str(), "yes" | "on");
                    match w.text.as_str() {
                        "scale" => self.opts.scale = on,
                        "image" => self.opts.image = on,
                        "first" => self.opts.first = on,
                        _ => self.opts.append = on,
                    }
                    k += 2;
                }
                "pad" => {
                    self.opts.pad = super::args::parse_i64(val(1)?)?.max(0) as usize;
                    k += 2;
                }
                "every" => {
                    self.opts.every = super::args::parse_i64(val(1)?)?.max(0) as u64;
                    k += 2;
                }
                "flush" | "units" | "time" | "precision" | "colname" | "header" | "delay" => {
                    k += 2;
                }
                "label" | "element" | "region" | "thresh" | "refresh" | "fileper" | "nfile" => {
                    return Err(Error::unsupported(w.span, format!("dump_modify {}", w.text)));
                }
                _ => {
                    return Err(bad_keyword(
                        w,
                        "dump_modify keyword",
                        &["format", "sort", "scale", "image", "first", "append", "pad", "every", "flush"],
                    ))
                }
            }
        }
        // a reopened writer picks the new options up
        if self.writer.is_some() && self.writer.as_ref().map(|w| w.frames_written()).unwrap_or(0) == 0 {
            self.writer = None;
        }
        Ok(())
    }
}

/// `ID[k]` as (ID, Some(k)), `ID` as (ID, None).
fn split_index(rest: &str) -> (&str, Option<usize>) {
    match rest.find('[') {
        Some(b) => (&rest[..b], rest[b + 1..].trim_end_matches(']').parse().ok()),
        None => (rest, None),
    }
}

fn column_values(sim: &Sim, c: &str) -> Result<Vec<f64>> {
    use crate::script::EvalContext;
    for (prefix, kind) in [("c_", 'c'), ("f_", 'f')] {
        if let Some(rest) = c.strip_prefix(prefix) {
            let (id, col) = split_index(rest);
            return sim.peratom(kind, id, col).map_err(|e| Error::runtime(format!("dump column {c}: {e}")));
        }
    }
    sim.atom_vector(c).map_err(|e| Error::runtime(format!("dump column {c}: {e}")))
}

/// `write_dump group style file columns... [modify args...]`: one frame now,
/// written by a one-off dump of the same style (LAMMPS semantics).
fn write_dump(s: &mut Session, cmd: &Command) -> Result<()> {
    let w = &cmd.words;
    if w.len() < 4 {
        return Err(Error::deck(cmd.span, "write_dump: expected `write_dump group style file ...`"));
    }
    let (cols, modify) = match w.iter().position(|x| x.text == "modify") {
        Some(k) => (&w[4..k], &w[k + 1..]),
        None => (&w[4..], &w[w.len()..]),
    };
    let word = |text: &str, at: &crate::script::Word| crate::script::Word { text: text.to_string(), span: at.span, quoted: false };
    // dump demx_write_dump GROUP STYLE 0 FILE COLUMNS...
    let mut words = vec![word("dump", &w[0]), word("demx_write_dump", &w[0]), w[1].clone(), w[2].clone(), word("0", &w[2]), w[3].clone()];
    words.extend(cols.iter().cloned());
    let dump_cmd = Command { words, span: cmd.span };
    let mut a = Args::new(&dump_cmd);
    dump_command(s, &dump_cmd, &mut a, true)?;
    let Some(k) = s.sim.dumps.iter().position(|x| x.id() == "demx_write_dump") else {
        return Ok(());
    };
    let mut d = s.sim.dumps.remove(k);
    if !modify.is_empty() {
        d.modify(modify)?;
    }
    if !s.check {
        d.write(&s.sim)?;
    }
    Ok(())
}

/// `dump ID group style N file ...`; `one_off` for the dump that
/// `write_dump` makes (N = 0: written once, never due).
fn dump_command(s: &mut Session, cmd: &Command, a: &mut Args, one_off: bool) -> Result<()> {
    let id = a.word("dump id")?;
    let g = a.word("group")?;
    let group = s.group(g)?;
    let style = a.word("dump style")?;
    let every = a.i64("N")?;
    // LAMMPS 29 Sep 2021 and LIGGGHTS 3.8 stop on N <= 0 ("Invalid dump
    // frequency"); demx wrote no file and went on. N is an int there.
    if !one_off && !(1..=i64::from(i32::MAX)).contains(&every) {
        return Err(a
            .err_prev(format!("dump {}: N must be between 1 and {}, not {every}", id.text, i32::MAX))
            .with_hint("LAMMPS and LIGGGHTS: Invalid dump frequency"));
    }
    let file = a.word("file")?;
    let engine = if s.sim.dialect == Dialect::Liggghts { Engine::Liggghts } else { Engine::Lammps };
    // LIGGGHTS 3.8 creates the folders of a dump's file name when the dump
    // is defined (`dump ... post/dump*.vtk` with no post/: the engine makes
    // it, seen with custom and custom/vtk); LAMMPS stops with "Cannot open
    // dump file". demx check writes nothing.
    if engine == Engine::Liggghts && !(s.check || s.sim.dry || s.replaying) {
        if let Some(dir) = std::path::Path::new(&file.text).parent().filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| Error::io(file.span, format!("dump {}: cannot create the folder {}", id.text, dir.display()), &e))?;
        }
    }
    let (opts, columns) = match style.text.as_str() {
        "custom" | "custom/gz" | "custom/vtk" => {
            let mut cols = vec![];
            for w in a.rest() {
                let t = w.text.as_str();
                let known = is_atom_property_name(t) || t.starts_with("c_") || t.starts_with("f_") || t.starts_with("v_");
                if !known {
                    return Err(Error::deck(w.span, format!("dump custom: unknown column '{t}'")));
                }
                if let Some(rest) = t.strip_prefix("f_") {
                    // per-atom properties demx keeps by name (fix
                    // property/atom, heat/gran's Temp...); other fixes'
                    // per-atom values are not available yet
                    let (fid, col) = split_index(rest);
                    if s.sim.particles.extra_index(fid).is_none() {
                        return Err(Error::unsupported(w.span, format!("dump custom column {t}")));
                    }
                    s.sim.extra_column(fid, col).map_err(|e| Error::deck(w.span, format!("dump custom: {e}")))?;
                }
                if t.starts_with("v_") {
                    return Err(Error::unsupported(w.span, format!("dump custom column {t}")));
                }
                if let Some(rest) = t.strip_prefix("c_") {
                    let cid = rest.split('[').next().unwrap_or("");
                    if !s.sim.computes.iter().any(|c| c.id == cid) {
                        return Err(Error::deck(w.span, format!("dump custom: compute '{cid}' does not exist")));
                    }
                    uncomputed(s, w, "dump custom column")?;
                }
                cols.push(t.to_string());
            }
            if cols.is_empty() {
                return Err(Error::deck(a.end_span(), "dump custom: no columns"));
            }
            let refs: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
            (DumpOptions::custom(engine, every.max(0) as u64, &refs), cols)
        }
        "atom" | "atom/gz" => (DumpOptions::atom(engine, every.max(0) as u64), vec![]),
        // `stl` and `mesh/gran/VTK` are LIGGGHTS 3.8's own aliases (its
        // DumpStyle lines), kept from 2.x
        "mesh/stl" | "stl" | "mesh/vtk" | "mesh/gran/VTK" => {
            if s.sim.dumps.iter().any(|x| x.id() == id.text) {
                return Err(Error::deck(id.span, format!("dump '{}' already exists", id.text)).with_hint("undump it first"));
            }
            let d: Box<dyn crate::engine::output::Dump> = if style.text.ends_with("stl") {
                Box::new(super::mesh::dump_mesh_stl(s, cmd)?)
            } else {
                Box::new(super::mesh::dump_mesh_vtk(s, cmd)?)
            };
            s.sim.dumps.push(d);
            return Ok(());
        }
        "local/gran/vtk" | "local" | "image" | "movie" | "xyz" | "cfg" | "vtk" | "decomposition/vtk" | "euler/vtk" => {
            return Err(Error::unsupported(style.span, format!("dump {}", style.text)));
        }
        _ => return Err(bad_keyword(style, "dump style", &["custom", "atom", "custom/vtk", "mesh/stl", "mesh/vtk"])),
    };
    let summary = format!("dump {} {} every {} -> {}", id.text, style.text, every, file.text);
    if s.sim.dumps.iter().any(|x| x.id() == id.text) {
        return Err(Error::deck(id.span, format!("dump '{}' already exists", id.text)).with_hint("undump it first"));
    }
    if style.text == "custom/vtk" {
        // the points are the positions whether or not the deck lists them (LIGGGHTS)
        let mut columns = columns;
        for c in ["x", "y", "z"] {
            if !columns.iter().any(|x| x == c) {
                columns.push(c.to_string());
            }
        }
        let d = DumpVtk { id: id.text.clone(), group, columns, every, first: false, path: file.text.clone(), last_step: None, summary };
        s.sim.dumps.push(Box::new(d));
        return Ok(());
    }
    let d = DumpText { id: id.text.clone(), group, columns, writer: None, opts, path: file.text.clone(), last_step: None, summary };
    if let Some(k) = s.sim.dumps.iter().position(|x| x.id() == id.text) {
        return Err(Error::deck(id.span, format!("dump '{}' already exists (k={k})", id.text)).with_hint("undump it first"));
    }
    s.sim.dumps.push(Box::new(d));
    Ok(())
}
