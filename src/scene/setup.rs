//! Setup commands: units, box, regions, lattices, atoms, groups, settings;
//! and the fixes that need geometry (walls, insertion).

use super::args::{bad_keyword, parse_f64, Args};
use super::{Session, Units};
use crate::engine::domain::{Domain, Side};
use crate::engine::particles::NewParticle;
use crate::engine::sim::Dialect;
use crate::error::{Error, Result};
use crate::geom::{parse_lattice, parse_region, Region, RegionParseCtx};
use crate::physics::V3;
use crate::script::{Command, Variables, Word};

/// Execute a setup command.
pub fn execute(s: &mut Session, cmd: &Command, vars: &mut Variables) -> Result<()> {
    let mut a = Args::new(cmd);
    match cmd.name() {
        "units" => {
            let u = a.choice("unit style", &["si", "lj", "cgs", "metal", "real", "micro", "nano", "electron"])?;
            s.units = match u.text.as_str() {
                "si" => Units::Si,
                "lj" => Units::Lj,
                "cgs" => Units::Cgs,
                other => return Err(Error::unsupported(u.span, format!("units {other}"))),
            };
            let (boltz, skin) = match s.units {
                // Boltzmann constants of both engines (CODATA 2006; LAMMPS 2022 `update.cpp`,
                // LIGGGHTS 3.8), not the 2019 SI value: temperatures and `velocity create`
                // then match theirs to the bit
                Units::Si => (1.3806504e-23, 0.001),
                Units::Lj => (1.0, 0.3),
                Units::Cgs => (1.3806504e-16, 0.1),
            };
            s.sim.boltz = boltz;
            s.sim.neigh.skin = skin;
            if !s.sim.thermo.norm_set {
                s.sim.thermo.norm = s.units == Units::Lj;
            }
            Ok(())
        }
        "atom_style" => {
            let st = a.word("atom style")?;
            match st.text.as_str() {
                "sphere" | "granular" => {
                    s.atom_style = Some(st.text.clone());
                    Ok(())
                }
                "hybrid" => {
                    let ok = a.rest().iter().all(|w| matches!(w.text.as_str(), "sphere" | "granular"));
                    if ok {
                        Ok(())
                    } else {
                        Err(Error::unsupported(st.span, format!("atom_style {}", cmd.text().trim_start_matches("atom_style "))))
                    }
                }
                "atomic"
                | "bond"
                | "angle"
                | "molecular"
                | "full"
                | "charge"
                | "body"
                | "line"
                | "tri"
                | "ellipsoid"
                | "superquadric"
                | "dipole"
                | "bpm/sphere"
                | "sph"
                | "peri"
                | "template"
                | "spin"
                | "wavepacket"
                | "electron"
                | "dpd"
                | "edpd"
                | "mdpd"
                | "tdpd"
                | "oxdna"
                | "dielectric"
                | "granular/multisphere"
                | "convexhull" => {
                    Err(Error::unsupported(st.span, format!("atom_style {}", st.text))
                        .with_hint("demx simulates spheres: atom_style sphere or granular"))
                }
                _ => Err(bad_keyword(st, "atom style", &["sphere", "granular"])),
            }
        }
        "boundary" => {
            let mut sides = [[Side::Periodic; 2]; 3];
            for d in 0..3 {
                let w = a.word("boundary")?;
                let chars: Vec<char> = w.text.chars().collect();
                let pair = match chars.len() {
                    1 => [chars[0], chars[0]],
                    2 => [chars[0], chars[1]],
                    _ => {
                        return Err(
                            Error::deck(w.span, format!("illegal boundary '{}'", w.text)).with_hint("use p, f, s, m or two of them such as fm")
                        )
                    }
                };
                for k in 0..2 {
                    sides[d][k] = Side::from_char(pair[k])
                        .ok_or_else(|| Error::deck(w.span, format!("illegal boundary letter '{}' (expected p, f, s, m)", pair[k])))?;
                }
                if (sides[d][0] == Side::Periodic) != (sides[d][1] == Side::Periodic) {
                    return Err(Error::deck(w.span, "both sides of a periodic dimension must be periodic"));
                }
            }
            match s.sim.domain.as_mut() {
                Some(d) => d.sides = sides,
                None => s.pending_sides = Some(sides),
            }
            Ok(())
        }
        "dimension" => {
            let d = a.i64("dimension")?;
            if d != 2 && d != 3 {
                return Err(a.err_prev("dimension must be 2 or 3"));
            }
            s.dimension = d as u8;
            Ok(())
        }
        "neighbor" => {
            let skin = a.f64("skin")?;
            // both engines stop on a negative skin ("Illegal neighbor
            // command"); demx's bins then grew without bound
            if skin < 0.0 {
                return Err(a
                    .err_prev(format!("neighbor: skin must be >= 0, not {skin}"))
                    .with_hint("LAMMPS and LIGGGHTS: Illegal neighbor command"));
            }
            s.sim.neigh.skin = skin;
            let st = a.word("neighbor style")?;
            match st.text.as_str() {
                "bin" | "nsq" | "multi" => Ok(()),
                _ => Err(bad_keyword(st, "neighbor style", &["bin", "nsq", "multi"])),
            }
        }
        "neigh_modify" => {
            while a.more() {
                let k = a.word("keyword")?;
                match k.text.as_str() {
                    "delay" => s.sim.neigh.delay = a.i64("delay")?,
                    "every" => s.sim.neigh.every = a.i64("every")?,
                    "check" => s.sim.neigh.check = a.yes_no("check")?,
                    "once" | "cluster" => {
                        a.yes_no(&k.text.clone())?;
                    }
                    "page" | "one" | "binsize" => {
                        a.f64(&k.text.clone())?;
                    }
                    "exclude" => {
                        let kind = a.choice("exclude style", &["type", "group", "molecule/intra", "molecule/inter", "none"])?;
                        match kind.text.as_str() {
                            "type" => {
                                let i = a.i64("type I")? as u32;
                                let j = a.i64("type J")? as u32;
                                s.sim.neigh.exclude_types.push((i, j));
                            }
                            "group" => {
                                let g1 = a.word("group 1")?;
                                let g2 = a.word("group 2")?;
                                let (b1, b2) = (s.group(g1)?, s.group(g2)?);
                                s.sim.neigh.exclude_groups.push((b1, b2));
                            }
                            "none" => {
                                s.sim.neigh.exclude_types.clear();
                                s.sim.neigh.exclude_groups.clear();
                            }
                            _ => return Err(Error::unsupported(kind.span, format!("neigh_modify exclude {}", kind.text))),
                        }
                    }
                    "contact_distance_factor" => {
                        a.f64("factor")?;
                    }
                    _ => {
                        return Err(bad_keyword(k, "neigh_modify keyword", &["delay", "every", "check", "once", "page", "one", "exclude", "binsize"]))
                    }
                }
            }
            Ok(())
        }
        "timestep" => {
            let dt = a.f64("timestep")?;
            if !(dt > 0.0) {
                return Err(a.err_prev("timestep must be positive"));
            }
            s.sim.dt = dt;
            Ok(())
        }
        "hard_particles" | "soft_particles" => {
            let on = a.yes_no(cmd.name())?;
            if cmd.name() == "hard_particles" {
                s.hard_particles = on;
            } else {
                s.soft_particles = on;
            }
            Ok(())
        }
        "reset_timestep" => {
            let n = a.i64("step")?;
            s.sim.step = n;
            Ok(())
        }
        "region" if cmd.args().get(1).is_some_and(|w| w.text == "delete") => {
            // `region ID delete`: later commands may define the ID afresh.
            // Fixes that took the region (insertion, forces) keep the copy
            // they took; a wall/gran/region, which LAMMPS looks up by name at
            // each run's start, takes the new definition then (or stops the
            // run if there is none): see `Session::refresh_regions`.
            let w = a.word("region id")?;
            let k = s
                .regions
                .iter()
                .position(|r| r.id == w.text)
                .ok_or_else(|| Error::deck(w.span, format!("region delete: region '{}' does not exist", w.text)))?;
            s.regions.remove(k);
            s.deleted_regions.push(w.text.clone());
            Ok(())
        }
        "region" => {
            let ctx = RegionParseCtx { lattice: lattice_spacing(s), box_bounds: box_bounds(s), regions: &s.regions };
            let r = parse_region(cmd, &ctx)?;
            let _ = vars;
            if s.regions.iter().any(|x| x.id == r.id) {
                return Err(Error::deck(cmd.args()[0].span, format!("region '{}' is already defined", r.id)));
            }
            s.regions.push(r);
            Ok(())
        }
        "lattice" => {
            let l = parse_lattice(cmd, s.units == Units::Lj, s.dimension as usize)?;
            s.lattice = Some(l);
            Ok(())
        }
        "create_box" => {
            if s.sim.domain.is_some() {
                return Err(Error::deck(cmd.words[0].span, "create_box: box already exists"));
            }
            let n = a.i64("number of atom types")?;
            if n < 1 {
                return Err(a.err_prev("create_box: need at least one atom type"));
            }
            if n > i64::from(i32::MAX) {
                return Err(a.err_prev(format!("create_box: {n} atom types is more than the engines' limit {}", i32::MAX)));
            }
            // the type-pair tables (pair and wall coefficients) hold (N+1)^2
            // entries: LAMMPS stops at `run` with "Failed to allocate
            // 80001600008 bytes for array neigh:cutneighsq" for 1e5 types
            let bytes = 2.0 * ((n + 1) as f64).powi(2) * std::mem::size_of::<crate::physics::PairParams>() as f64;
            if !crate::limits::fits(bytes) {
                return Err(a.err_prev(format!(
                    "create_box: {n} atom types need {} for the type-pair coefficient tables; {}",
                    crate::limits::human(bytes),
                    crate::limits::machine()
                )));
            }
            let rw = a.word("region")?;
            let r = region(s, rw)?;
            let (lo, hi) = r.bbox().ok_or_else(|| Error::deck(rw.span, format!("create_box: region '{}' has no finite bounding box", rw.text)))?;
            // both engines: "Box bounds are invalid or missing"
            if let Some(d) = (0..3).find(|&d| hi[d].is_nan() || lo[d].is_nan() || hi[d] <= lo[d]) {
                let axis = ["x", "y", "z"][d];
                return Err(Error::deck(
                    rw.span,
                    format!("create_box: region '{}' is empty in {axis} ({axis}lo {} >= {axis}hi {})", rw.text, lo[d], hi[d]),
                )
                .with_hint("LAMMPS and LIGGGHTS: Box bounds are invalid or missing"));
            }
            while a.more() {
                // LIGGGHTS/LAMMPS extra keywords (bond/types, extra/...): accept numbers
                a.word("keyword")?;
                if a.more() {
                    a.word("value")?;
                }
            }
            make_box(s, n as usize, lo, hi);
            Ok(())
        }
        "create_atoms" => create_atoms(s, cmd, &mut a),
        "group" => group_command(s, cmd, &mut a, vars),
        "set" => set_command(s, cmd, &mut a),
        "velocity" => velocity_command(s, cmd, &mut a, vars),
        "mass" => {
            a.word("type")?;
            a.f64("mass")?;
            s.notes.push((cmd.span, "mass: ignored for atom_style sphere (per-particle mass from density and radius)".into()));
            Ok(())
        }
        "delete_atoms" => delete_atoms(s, cmd, &mut a),
        "displace_atoms" => {
            s.need_box(cmd)?;
            let g = a.word("group")?;
            let bit = s.group(g)?;
            let k = a.choice("style", &["move", "ramp", "random", "rotate"])?;
            if k.text != "move" {
                return Err(Error::unsupported(k.span, format!("displace_atoms {}", k.text)));
            }
            let d = V3::new(a.f64("dx")?, a.f64("dy")?, a.f64("dz")?);
            let mut scale = lattice_spacing(s);
            while a.more() {
                a.choice("keyword", &["units"])?;
                if a.choice("units", &["box", "lattice"])?.text == "box" {
                    scale = V3::new(1.0, 1.0, 1.0);
                }
            }
            let d = d.component_mul(&scale);
            let p = &mut s.sim.particles;
            for i in 0..p.len() {
                if p.mask[i] & bit != 0 {
                    p.x[i] += d;
                }
            }
            s.sim.force_rebuild = true;
            Ok(())
        }
        "change_box" => change_box(s, cmd, &mut a),
        _ => unreachable!("setup::execute dispatched a command it does not handle"),
    }
}

fn make_box(s: &mut Session, ntypes: usize, lo: V3, hi: V3) {
    let sides = s.pending_sides.unwrap_or([[Side::Periodic; 2]; 3]);
    s.sim.domain = Some(Domain::new([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z], sides, s.dimension));
    s.sim.ntypes = ntypes;
}

/// Lattice spacings for `units lattice` (1,1,1 without a lattice).
pub fn lattice_spacing(s: &Session) -> V3 {
    s.lattice.as_ref().map(|l| l.spacing()).unwrap_or(V3::new(1.0, 1.0, 1.0))
}

fn box_bounds(s: &Session) -> Option<(V3, V3)> {
    s.sim.domain.as_ref().map(|d| (V3::new(d.lo[0], d.lo[1], d.lo[2]), V3::new(d.hi[0], d.hi[1], d.hi[2])))
}

/// A region by id, with a did-you-mean error.
pub fn region<'a>(s: &'a Session, w: &Word) -> Result<&'a Region> {
    s.regions.iter().find(|r| r.id == w.text).ok_or_else(|| {
        let mut e = Error::deck(w.span, format!("region '{}' does not exist", w.text));
        if let Some(h) = crate::error::did_you_mean(&w.text, s.regions.iter().map(|r| r.id.as_str())) {
            e = e.with_hint(format!("did you mean '{h}'?"));
        }
        e
    })
}

fn create_atoms(s: &mut Session, cmd: &Command, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    let t = a.i64("atom type")?;
    if t < 1 || t as usize > s.sim.ntypes {
        return Err(a.err_prev(format!("create_atoms: atom type {t} out of range 1..{}", s.sim.ntypes)));
    }
    let style = a.choice("style", &["box", "region", "single", "random"])?;
    let dom = s.sim.domain.clone().ok_or_else(|| Error::runtime("no box"))?;
    let mut points: Vec<V3> = vec![];
    let mut single_units_lattice = true;
    let mut region_filter: Option<Region> = None;
    match style.text.as_str() {
        "single" => {
            let p = V3::new(a.f64("x")?, a.f64("y")?, a.f64("z")?);
            points.push(p);
        }
        "box" => {}
        "region" => {
            let w = a.word("region")?;
            region_filter = Some(region(s, w)?.clone());
        }
        _ => {
            let n = a.i64("N")?;
            // LAMMPS 29 Sep 2021 and LIGGGHTS 3.8 read N and the seed as
            // 32-bit ints and stop on N < 0 or seed <= 0 ("Illegal
            // create_atoms command"); demx created nothing and went on
            if !(0..=i64::from(i32::MAX)).contains(&n) {
                return Err(a
                    .err_prev(format!("create_atoms random: N must be between 0 and {}, not {n}", i32::MAX))
                    .with_hint("LAMMPS and LIGGGHTS: Illegal create_atoms command"));
            }
            let bytes = (s.sim.particles.len() as f64 + n as f64) * crate::limits::BYTES_PER_PARTICLE;
            if !crate::limits::fits(bytes) {
                return Err(a.err_prev(format!(
                    "create_atoms random: {n} particles need at least {}; {}",
                    crate::limits::human(bytes),
                    crate::limits::machine()
                )));
            }
            let seed = a.i64("seed")?;
            if !(1..=i64::from(i32::MAX)).contains(&seed) {
                return Err(a
                    .err_prev(format!("create_atoms random: seed must be between 1 and {}, not {seed}", i32::MAX))
                    .with_hint("LAMMPS and LIGGGHTS: Illegal create_atoms command"));
            }
            let rw = a.word("region")?;
            if rw.text != "NULL" {
                region_filter = Some(region(s, rw)?.clone());
            }
            // uniform random points in the region's box (LAMMPS uses its own RNG: ids differ)
            let (lo, hi) = match &region_filter {
                Some(r) => r.bbox().unwrap_or((V3::from(dom.lo), V3::from(dom.hi))),
                None => (V3::from(dom.lo), V3::from(dom.hi)),
            };
            let mut rng = crate::engine::rng::Park::new(seed);
            let mut tries = 0;
            while (points.len() as i64) < n && tries < 1000 * n.max(1) {
                tries += 1;
                let p = V3::new(lo.x + rng.uniform() * (hi.x - lo.x), lo.y + rng.uniform() * (hi.y - lo.y), lo.z + rng.uniform() * (hi.z - lo.z));
                if region_filter.as_ref().is_none_or(|r| r.contains(p)) {
                    points.push(p);
                }
            }
        }
    }
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "units" => single_units_lattice = a.choice("units", &["box", "lattice"])?.text == "lattice",
            "basis" => {
                a.i64("basis")?;
                a.i64("type")?;
            }
            "overlap" | "maxtry" => {
                a.f64(&k.text.clone())?;
            }
            _ => return Err(Error::unsupported(k.span, format!("create_atoms keyword {}", k.text))),
        }
    }
    if style.text == "single" && single_units_lattice {
        let sp = lattice_spacing(s);
        points[0] = points[0].component_mul(&sp);
    }
    if style.text == "box" || style.text == "region" {
        let lat = s
            .lattice
            .as_ref()
            .ok_or_else(|| Error::deck(style.span, "create_atoms: no lattice defined").with_hint("define one with the lattice command"))?;
        let periodic = [dom.periodic(0), dom.periodic(1), dom.periodic(2)];
        let filter = region_filter.clone();
        let f = move |p: V3| filter.as_ref().is_none_or(|r| r.contains(p));
        let pts = lat.create_points(V3::from(dom.lo), V3::from(dom.hi), periodic, Some(&f)).map_err(|e| Error::deck(style.span, e.message()))?;
        points = pts.into_iter().map(|(p, _)| p).collect();
    }
    let bytes = (s.sim.particles.len() + points.len()) as f64 * crate::limits::BYTES_PER_PARTICLE;
    if !crate::limits::fits(bytes) {
        return Err(Error::deck(
            style.span,
            format!("create_atoms: {} particles need at least {}; {}", points.len(), crate::limits::human(bytes), crate::limits::machine()),
        ));
    }
    // LAMMPS default diameter 1, density 1 for atom_style sphere
    let base = s.sim.particles.max_tag();
    let n = points.len();
    for (k, p) in points.into_iter().enumerate() {
        let tag = base + k as i64 + 1;
        s.sim.particles.push(NewParticle { tag, kind: t as u32, mask: 1, x: p, v: V3::zeros(), omega: V3::zeros(), radius: 0.5, density: 1.0 });
    }
    s.sources.push(format!("create_atoms {} {}: {n} particles", t, style.text));
    s.sim.force_rebuild = true;
    s.sim.log.line(&format!("Created {n} atoms"));
    Ok(())
}

fn change_box(s: &mut Session, cmd: &Command, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    let g = a.word("group")?;
    s.group(g)?;
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "boundary" => {
                let mut sides = [[Side::Periodic; 2]; 3];
                for d in 0..3 {
                    let w = a.word("boundary")?;
                    let cs: Vec<char> = w.text.chars().collect();
                    let pair = if cs.len() == 1 {
                        [cs[0], cs[0]]
                    } else if cs.len() == 2 {
                        [cs[0], cs[1]]
                    } else {
                        return Err(Error::deck(w.span, "illegal boundary"));
                    };
                    for q in 0..2 {
                        sides[d][q] = Side::from_char(pair[q]).ok_or_else(|| Error::deck(w.span, "illegal boundary letter"))?;
                    }
                }
                if let Some(d) = s.sim.domain.as_mut() {
                    d.sides = sides;
                }
            }
            "x" | "y" | "z" => {
                let d = (k.text.as_bytes()[0] - b'x') as usize;
                let how = a.choice("change style", &["final", "delta", "scale", "volume"])?;
                let dom = s.sim.domain.as_mut().ok_or_else(|| Error::runtime("no box"))?;
                match how.text.as_str() {
                    "final" => {
                        dom.lo[d] = a.f64("lo")?;
                        dom.hi[d] = a.f64("hi")?;
                    }
                    "delta" => {
                        dom.lo[d] += a.f64("dlo")?;
                        dom.hi[d] += a.f64("dhi")?;
                    }
                    _ => return Err(Error::unsupported(how.span, format!("change_box {} {}", k.text, how.text))),
                }
                dom.lo0[d] = dom.lo[d];
                dom.hi0[d] = dom.hi[d];
            }
            "units" => {
                a.choice("units", &["box", "lattice"])?;
            }
            "remap" => {}
            _ => return Err(Error::unsupported(k.span, format!("change_box {}", k.text))),
        }
    }
    s.sim.force_rebuild = true;
    Ok(())
}

fn group_command(s: &mut Session, cmd: &Command, a: &mut Args, vars: &Variables) -> Result<()> {
    let name = a.word("group name")?;
    let style = a.word("group style")?;
    if style.text == "delete" {
        if let Some(k) = s.sim.groups.iter().position(|g| g == &name.text) {
            s.sim.groups[k] = String::new();
        }
        return Ok(());
    }
    let bit = match s.sim.group_bit(&name.text) {
        Some(b) => b,
        None => {
            if s.sim.groups.len() >= 32 {
                return Err(Error::deck(name.span, "too many groups (32 at most)"));
            }
            s.sim.groups.push(name.text.clone());
            1u32 << (s.sim.groups.len() - 1)
        }
    };
    // `variable NAME`: the atoms whose atom-style variable is non-zero now
    // (LAMMPS `group ID variable`), evaluated before the group's bits change
    let by_var = if style.text == "variable" {
        let v = a.word("variable name")?;
        let vals = vars.eval_atom(&v.text, &s.sim).map_err(|e| Error::deck(v.span, e))?;
        Some(vals)
    } else {
        None
    };
    let p = &mut s.sim.particles;
    let mut select = vec![false; p.len()];
    match style.text.as_str() {
        "variable" => {
            for (sel, v) in select.iter_mut().zip(by_var.unwrap_or_default()) {
                *sel = v != 0.0;
            }
        }
        "type" | "id" | "molecule" => {
            let field: Vec<i64> = if style.text == "type" { p.kind.iter().map(|&k| k as i64).collect() } else { p.tag.clone() };
            let rest = a.rest();
            if let Some(op) = rest.first().filter(|w| ["<", ">", "<=", ">=", "==", "!=", "<>"].contains(&w.text.as_str())) {
                let v1 = rest.get(1).map(super::args::parse_i64).transpose()?.ok_or_else(|| Error::deck(op.span, "missing value"))?;
                let v2 = rest.get(2).map(super::args::parse_i64).transpose()?;
                for (i, &f) in field.iter().enumerate() {
                    select[i] = match op.text.as_str() {
                        "<" => f < v1,
                        ">" => f > v1,
                        "<=" => f <= v1,
                        ">=" => f >= v1,
                        "==" => f == v1,
                        "!=" => f != v1,
                        _ => f >= v1 && f <= v2.unwrap_or(v1),
                    };
                }
            } else {
                for w in rest {
                    let (lo, hi, step) = parse_range(w)?;
                    for (i, &f) in field.iter().enumerate() {
                        if f >= lo && f <= hi && (f - lo) % step == 0 {
                            select[i] = true;
                        }
                    }
                }
            }
        }
        "region" => {
            let rw = a.word("region")?;
            let r = s.regions.iter().find(|r| r.id == rw.text).ok_or_else(|| Error::deck(rw.span, format!("region '{}' does not exist", rw.text)))?;
            let p = &s.sim.particles;
            for i in 0..p.len() {
                select[i] = r.contains(p.x[i]);
            }
        }
        "empty" => {}
        "clear" => {
            for m in &mut s.sim.particles.mask {
                *m &= !bit;
            }
        }
        "subtract" | "union" | "intersect" => {
            let mut bits = vec![];
            for w in a.rest() {
                bits.push(s.group(w)?);
            }
            let p = &s.sim.particles;
            for i in 0..p.len() {
                let has = |b: u32| p.mask[i] & b != 0;
                select[i] = match style.text.as_str() {
                    "union" => bits.iter().any(|&b| has(b)),
                    "intersect" => bits.iter().all(|&b| has(b)),
                    _ => !bits.is_empty() && has(bits[0]) && !bits[1..].iter().any(|&b| has(b)),
                };
            }
        }
        "dynamic" | "static" | "include" => return Err(Error::unsupported(style.span, format!("group {}", style.text))),
        _ => {
            return Err(bad_keyword(
                style,
                "group style",
                &["type", "id", "region", "empty", "clear", "subtract", "union", "intersect", "variable", "delete"],
            ))
        }
    }
    let _ = cmd;
    let p = &mut s.sim.particles;
    let mut count = 0;
    for i in 0..p.len() {
        if select[i] {
            p.mask[i] |= bit;
        }
        if p.mask[i] & bit != 0 {
            count += 1;
        }
    }
    s.sim.log.line(&format!("{count} atoms in group {}", name.text));
    Ok(())
}

fn parse_range(w: &Word) -> Result<(i64, i64, i64)> {
    let t = &w.text;
    let bad = || Error::deck(w.span, format!("bad id/type range '{t}'"));
    if let Some((a, b)) = t.split_once(':') {
        let (b, step) = match b.split_once(':') {
            Some((b, c)) => (b, c.parse::<i64>().map_err(|_| bad())?),
            None => (b, 1),
        };
        Ok((a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?, step.max(1)))
    } else if let Some(k) = t.find('*') {
        let lo = if k == 0 { 1 } else { t[..k].parse().map_err(|_| bad())? };
        let hi = if k + 1 == t.len() { i64::MAX } else { t[k + 1..].parse().map_err(|_| bad())? };
        Ok((lo, hi, 1))
    } else {
        let v = t.parse().map_err(|_| bad())?;
        Ok((v, v, 1))
    }
}

fn set_command(s: &mut Session, cmd: &Command, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    let style = a.choice("set style", &["atom", "type", "group", "region", "mol", "type/fraction"])?;
    let what = a.word("ids")?;
    let p = &s.sim.particles;
    let select: Vec<bool> = match style.text.as_str() {
        "atom" | "type" => {
            let (lo, hi, _) = parse_range(what)?;
            (0..p.len())
                .map(|i| {
                    let f = if style.text == "atom" { p.tag[i] } else { p.kind[i] as i64 };
                    f >= lo && f <= hi
                })
                .collect()
        }
        "group" => {
            let b = s.group(what)?;
            (0..p.len()).map(|i| p.mask[i] & b != 0).collect()
        }
        "region" => {
            let r = region(s, what)?;
            (0..p.len()).map(|i| r.contains(p.x[i])).collect()
        }
        _ => return Err(Error::unsupported(style.span, format!("set {}", style.text))),
    };
    let mut count = 0;
    while a.more() {
        let k = a.word("keyword")?;
        if k.text == "property/atom" || k.text == "property/peratom" {
            // LIGGGHTS: the named per-atom property of a fix property/atom
            // (or of a fix that keeps one, as heat/gran's Temp), one value
            // per column
            let name = a.word("property name")?;
            let Some(e) = s.sim.particles.extra_index(&name.text) else {
                return Err(Error::deck(name.span, format!("set {}: no per-atom property '{}'", k.text, name.text))
                    .with_hint("a fix property/atom (or fix heat/gran for Temp and heatSource) defines it before the set"));
            };
            let width = s.sim.particles.extra[e].width;
            let mut vals = Vec::with_capacity(width);
            for _ in 0..width {
                vals.push(a.f64("value")?);
            }
            let data = &mut s.sim.particles.extra[e].data;
            count = 0;
            for (i, _) in select.iter().enumerate().filter(|(_, &on)| on) {
                data[i * width..(i + 1) * width].copy_from_slice(&vals);
                count += 1;
            }
            s.sim.log.line(&format!("  {count} settings made for {}", k.text));
            continue;
        }
        if k.text == "type/fraction" {
            // LAMMPS set.cpp TYPE_FRACTION: each selected atom draws from a
            // generator seeded by the seed and its position, and takes the new
            // type when the draw is at most the fraction
            let newtype = a.i64("type")?;
            let fraction = a.f64("fraction")?;
            let seed = a.i64("seed")?;
            let ntypes = s.sim.ntypes as i64;
            if newtype < 1 || newtype > ntypes {
                return Err(a.err_prev(format!("set type/fraction: type {newtype} is not between 1 and {ntypes}")));
            }
            if !(0.0..=1.0).contains(&fraction) {
                return Err(a.err_prev(format!("set type/fraction: fraction {fraction} is not between 0 and 1")));
            }
            if seed <= 0 || seed > i32::MAX as i64 {
                return Err(a.err_prev(format!("set type/fraction: seed {seed} must be a positive 32-bit integer")));
            }
            let p = &mut s.sim.particles;
            count = 0;
            for i in 0..p.len() {
                if select[i] && crate::engine::rng::Park::from_point(seed as i32, [p.x[i].x, p.x[i].y, p.x[i].z]).uniform() <= fraction {
                    p.kind[i] = newtype as u32;
                    count += 1;
                }
            }
            s.sim.log.line(&format!("  {count} settings made for type/fraction"));
            continue;
        }
        let v = a.word("value")?;
        let val = parse_f64(v)?;
        // the engines' own limits (LAMMPS 29 Sep 2021 set.cpp, LIGGGHTS 3.8
        // set.cpp): "Invalid density/diameter/mass in set command", "Invalid
        // value in set command" for a type outside the box's types
        let bad = match k.text.as_str() {
            "density" if val.is_nan() || val <= 0.0 => Some("density must be > 0".to_string()),
            "diameter" if val.is_nan() || val < 0.0 => Some("diameter must be >= 0".to_string()),
            "mass" if val.is_nan() || val <= 0.0 => Some("mass must be > 0".to_string()),
            "type" if val.fract() != 0.0 || val < 1.0 || val > s.sim.ntypes as f64 => Some(format!("type must be an atom type 1..{}", s.sim.ntypes)),
            _ => None,
        };
        if let Some(why) = bad {
            let what = if k.text == "type" { "value" } else { k.text.as_str() };
            return Err(Error::deck(v.span, format!("set {}: {why}, not {}", k.text, v.text))
                .with_hint(format!("LAMMPS and LIGGGHTS: Invalid {what} in set command")));
        }
        // LAMMPS's `set diameter` keeps the mass ("does not adjust the
        // particle mass", set command doc); LIGGGHTS's keeps the density
        let diameter_keeps_mass = s.dialect_now() == Dialect::Lammps;
        let p = &mut s.sim.particles;
        count = 0;
        for i in 0..p.len() {
            if !select[i] {
                continue;
            }
            count += 1;
            match k.text.as_str() {
                "diameter" if diameter_keeps_mass => {
                    p.radius[i] = 0.5 * val;
                    p.density[i] = p.mass[i] / crate::engine::particles::Particles::sphere_mass(p.radius[i], 1.0);
                }
                "diameter" => {
                    p.radius[i] = 0.5 * val;
                    p.mass[i] = crate::engine::particles::Particles::sphere_mass(p.radius[i], p.density[i]);
                }
                "density" => {
                    p.density[i] = val;
                    p.mass[i] = crate::engine::particles::Particles::sphere_mass(p.radius[i], val);
                }
                "mass" => {
                    p.mass[i] = val;
                    p.density[i] = val / crate::engine::particles::Particles::sphere_mass(p.radius[i], 1.0);
                }
                "type" => p.kind[i] = val as u32,
                "vx" => p.v[i].x = val,
                "vy" => p.v[i].y = val,
                "vz" => p.v[i].z = val,
                // LIGGGHTS 3.8 set.cpp: one angular velocity component each
                "omegax" => p.omega[i].x = val,
                "omegay" => p.omega[i].y = val,
                "omegaz" => p.omega[i].z = val,
                "omega" => return Err(Error::unsupported(k.span, "set omega (use omegax, omegay, omegaz)")),
                "x" => p.x[i].x = val,
                "y" => p.x[i].y = val,
                "z" => p.x[i].z = val,
                _ => return Err(Error::unsupported(k.span, format!("set keyword {}", k.text))),
            }
        }
        s.sim.log.line(&format!("  {count} settings made for {}", k.text));
    }
    let _ = count;
    s.sim.force_rebuild = true;
    Ok(())
}

fn velocity_command(s: &mut Session, cmd: &Command, a: &mut Args, vars: &Variables) -> Result<()> {
    s.need_box(cmd)?;
    let g = a.word("group")?;
    let bit = s.group(g)?;
    let style = a.choice("velocity style", &["set", "create", "zero", "ramp", "scale"])?;
    match style.text.as_str() {
        "set" => {
            use super::fixes::Component;
            // each component: a number, NULL, or v_name (equal- or atom-style,
            // as LAMMPS; the lattice scale applies to numbers only)
            let mut comps = vec![];
            for what in ["vx", "vy", "vz"] {
                let span = a.peek().map_or(cmd.span, |w| w.span);
                comps.push((super::fixes::component(a, what)?, span));
            }
            let mut sum = false;
            // LAMMPS scales numbers by the lattice spacings unless `units
            // box`; LIGGGHTS 3.8's velocity command defaults to box
            // (`scale_flag = 0` in its velocity.cpp)
            let liggghts = if s.dialect_known { s.sim.dialect == Dialect::Liggghts } else { s.dialect_hint == Some(Dialect::Liggghts) };
            let mut scale = if liggghts { V3::new(1.0, 1.0, 1.0) } else { lattice_spacing(s) };
            while a.more() {
                let k = a.choice("keyword", &["units", "sum", "dist", "mom", "rot", "loop", "temp", "bias", "rigid"])?;
                match k.text.as_str() {
                    "units" => {
                        scale = if a.choice("units", &["box", "lattice"])?.text == "box" { V3::new(1.0, 1.0, 1.0) } else { lattice_spacing(s) };
                    }
                    "sum" => sum = a.yes_no("sum")?,
                    _ => {
                        a.word("value")?;
                    }
                }
            }
            let mut comp: [Option<Vec<f64>>; 3] = [None, None, None];
            for d in 0..3 {
                let (c, span) = &comps[d];
                comp[d] = super::fixes::component_values(c, vars, &s.sim).map_err(|e| Error::deck(*span, e))?;
                if let (Component::Const(_), Some(v)) = (c, comp[d].as_mut()) {
                    v.iter_mut().for_each(|x| *x *= scale[d]);
                }
            }
            let p = &mut s.sim.particles;
            for i in 0..p.len() {
                if p.mask[i] & bit == 0 {
                    continue;
                }
                for d in 0..3 {
                    if let Some(v) = comp[d].as_ref().map(|c| c[i]) {
                        if sum {
                            p.v[i][d] += v;
                        } else {
                            p.v[i][d] = v;
                        }
                    }
                }
            }
            Ok(())
        }
        "zero" => {
            let k = a.choice("zero what", &["linear", "angular"])?;
            if a.more() && a.choice("keyword", &["rigid"])?.text == "rigid" {
                return Err(Error::unsupported(a.prev().map_or(cmd.span, |w| w.span), "velocity zero ... rigid"));
            }
            let done =
                if k.text == "linear" { super::velocity::zero_momentum(&mut s.sim, bit) } else { super::velocity::zero_rotation(&mut s.sim, bit) };
            done.map_err(|e| Error::deck(k.span, e))
        }
        "create" | "scale" => super::velocity::thermal(s, cmd, style, a, bit),
        _ => Err(Error::unsupported(style.span, format!("velocity {}", style.text))),
    }
}

fn delete_atoms(s: &mut Session, cmd: &Command, a: &mut Args) -> Result<()> {
    s.need_box(cmd)?;
    let style = a.choice("style", &["group", "region", "overlap", "porosity"])?;
    let w = a.word("argument")?;
    let p = &s.sim.particles;
    let remove: Vec<bool> = match style.text.as_str() {
        "group" => {
            let b = s.group(w)?;
            (0..p.len()).map(|i| p.mask[i] & b != 0).collect()
        }
        "region" => {
            let r = region(s, w)?;
            (0..p.len()).map(|i| r.contains(p.x[i])).collect()
        }
        "overlap" => {
            let cut = super::args::parse_f64(w)?;
            if cut <= 0.0 {
                return Err(Error::deck(w.span, "delete_atoms overlap: the cutoff must be positive"));
            }
            let (g1, g2) = (s.group(a.word("group1")?)?, s.group(a.word("group2")?)?);
            overlap_victims(&s.sim.particles, cut, g1, g2)
        }
        _ => return Err(Error::unsupported(style.span, format!("delete_atoms {}", style.text))),
    };
    let mut compress = true;
    while a.more() {
        let k = a.choice("keyword", &["compress", "bond", "mol"])?;
        let on = a.yes_no(&k.text)?;
        if k.text == "compress" {
            compress = on;
        } else if on {
            return Err(Error::unsupported(k.span, format!("delete_atoms {} yes (no molecules in granular decks)", k.text)));
        }
    }
    let n = s.sim.particles.remove_where(&remove);
    s.sim.log.line(&format!("Deleted {n} atoms, new total = {}", s.sim.particles.len()));
    if compress {
        // LAMMPS/LIGGGHTS default: ids renumbered 1..N in id order
        let p = &mut s.sim.particles;
        let mut order: Vec<usize> = (0..p.len()).collect();
        order.sort_by_key(|&i| p.tag[i]);
        let mut map = std::collections::HashMap::new();
        for (rank, &i) in order.iter().enumerate() {
            let new = rank as i64 + 1;
            if p.tag[i] != new {
                map.insert(p.tag[i], new);
                p.tag[i] = new;
            }
        }
        if !map.is_empty() {
            s.sim.pairs.retag(&map);
        }
    }
    s.sim.force_rebuild = true;
    Ok(())
}

/// `delete_atoms overlap CUT G1 G2` (LAMMPS semantics): an atom of G1 goes
/// if an atom of G2 not already deleted lies closer than CUT; of a pair in
/// both groups only one goes. Atoms are visited in id order (LAMMPS: in
/// storage order), so the outcome does not depend on storage.
fn overlap_victims(p: &crate::engine::particles::Particles, cut: f64, g1: u32, g2: u32) -> Vec<bool> {
    use std::collections::HashMap;
    let n = p.len();
    let cell = |x: &crate::physics::V3| -> (i64, i64, i64) { ((x.x / cut).floor() as i64, (x.y / cut).floor() as i64, (x.z / cut).floor() as i64) };
    let mut bins: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for i in 0..n {
        if p.mask[i] & g2 != 0 {
            bins.entry(cell(&p.x[i])).or_default().push(i);
        }
    }
    let mut order: Vec<usize> = (0..n).filter(|&i| p.mask[i] & g1 != 0).collect();
    order.sort_by_key(|&i| p.tag[i]);
    let mut gone = vec![false; n];
    for i in order {
        let c = cell(&p.x[i]);
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &j in bins.get(&(c.0 + dx, c.1 + dy, c.2 + dz)).map(|v| v.as_slice()).unwrap_or(&[]) {
                        if j != i && !gone[j] && (p.x[i] - p.x[j]).norm() < cut {
                            gone[i] = true;
                            break 'search;
                        }
                    }
                }
            }
        }
    }
    gone
}
