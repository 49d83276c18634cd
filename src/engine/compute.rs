//! Computes (`compute ID group style ...`) and per-atom properties.

use super::sim::Sim;

/// What a compute computes.
#[derive(Clone, Debug, serde::Serialize)]
pub enum ComputeKind {
    /// `ke`: translational kinetic energy of the group.
    Ke,
    /// `erotate/sphere`: rotational kinetic energy.
    ErotateSphere,
    /// `temp`: temperature (translational, dof 3N-3).
    Temp,
    /// `reduce MODE value ...` (`sum`, `min`, `max`, `ave`, `sumsq`, `avesq`).
    Reduce {
        /// Reduction mode.
        mode: String,
        /// Inputs: `x`, `vx`, `c_ID`, `c_ID[i]`, `v_name`, `f_ID[i]`.
        inputs: Vec<String>,
    },
    /// `property/atom name ...`: per-atom columns.
    PropertyAtom {
        /// Column names.
        names: Vec<String>,
    },
    /// `com`: centre of mass (vector of 3).
    Com,
    /// `displace/atom`: each atom's displacement from its original unwrapped
    /// position (dx, dy, dz, |d|), the originals kept in the particles' extra
    /// column `column` so that they follow sorting, deletion and restarts.
    DisplaceAtom {
        /// Name of the extra per-atom column of originals.
        column: String,
    },
    /// `contact/atom` (LIGGGHTS): each atom's number of particle contacts,
    /// distance <= r_i + r_j (compute_contact_atom.cpp: a pair counts for
    /// both atoms when the atom whose neighbour list holds it is in the
    /// group; demx counts a pair when either atom of it is the group's,
    /// the same for group `all`). Walls are not counted.
    ContactAtom,
    /// `coord/atom cutoff [typeN ...]` (LAMMPS's compute_coord_atom.cpp in
    /// the form LIGGGHTS 3.8 has): for each atom of the group, the other
    /// atoms of any group whose centre is closer than `cutoff` (strictly),
    /// one column per type range (`2`, `1*3`, `*`); all types without any.
    /// Atoms outside the group get 0.
    CoordAtom {
        /// Cutoff distance.
        cutoff: f64,
        /// Inclusive type ranges, one per column.
        types: Vec<(u32, u32)>,
    },
    /// A style demx records (for `demx check`) but cannot evaluate.
    Other(String),
}

/// A defined compute.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Compute {
    /// Id.
    pub id: String,
    /// Group bit.
    pub group: u32,
    /// Style.
    pub kind: ComputeKind,
    /// Style name as written.
    pub style: String,
}

impl Compute {
    /// Global scalar (`i` None) or vector element.
    pub fn global(&self, sim: &Sim, i: Option<usize>) -> Result<f64, String> {
        match (&self.kind, i) {
            (ComputeKind::Ke, None) => Ok(sim.kinetic_energy(self.group)),
            (ComputeKind::ErotateSphere, None) => Ok(sim.rotational_energy(self.group)),
            (ComputeKind::Temp, None) => Ok(sim.temperature()),
            (ComputeKind::Com, Some(k @ 1..=3)) => {
                let p = &sim.particles;
                let (mut m, mut s) = (0.0, 0.0);
                for j in 0..p.len() {
                    if p.mask[j] & self.group != 0 {
                        m += p.mass[j];
                        s += p.mass[j] * unwrapped(sim, j)[k - 1];
                    }
                }
                Ok(if m > 0.0 { s / m } else { 0.0 })
            }
            (ComputeKind::Reduce { mode, inputs }, idx) => {
                let k = idx.unwrap_or(1);
                if idx.is_none() && inputs.len() != 1 {
                    return Err(format!("compute {} reduces {} values: use c_{}[i]", self.id, inputs.len(), self.id));
                }
                let input = inputs.get(k - 1).ok_or_else(|| format!("compute {} has no value {k}", self.id))?;
                let vals = self.input_values(sim, input)?;
                let p = &sim.particles;
                let sel: Vec<f64> = vals.iter().enumerate().filter(|(j, _)| p.mask[*j] & self.group != 0).map(|(_, &v)| v).collect();
                let n = sel.len() as f64;
                Ok(match mode.as_str() {
                    "sum" => sel.iter().sum(),
                    "sumsq" => sel.iter().map(|v| v * v).sum(),
                    "ave" => {
                        if n > 0.0 {
                            sel.iter().sum::<f64>() / n
                        } else {
                            0.0
                        }
                    }
                    "avesq" => {
                        if n > 0.0 {
                            sel.iter().map(|v| v * v).sum::<f64>() / n
                        } else {
                            0.0
                        }
                    }
                    "min" => sel.iter().cloned().fold(f64::INFINITY, f64::min),
                    "max" => sel.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
                    "sumabs" => sel.iter().map(|v| v.abs()).sum(),
                    "aveabs" => {
                        if n > 0.0 {
                            sel.iter().map(|v| v.abs()).sum::<f64>() / n
                        } else {
                            0.0
                        }
                    }
                    m => return Err(format!("unknown reduce mode {m}")),
                })
            }
            _ => Err(format!("compute {} ({}) has no such global value", self.id, self.style)),
        }
    }

    fn input_values(&self, sim: &Sim, input: &str) -> Result<Vec<f64>, String> {
        use crate::script::EvalContext;
        if let Some(rest) = input.strip_prefix("c_") {
            let (id, col) = split_index(rest);
            return sim.peratom('c', id, col);
        }
        if let Some(rest) = input.strip_prefix("v_") {
            return Err(format!("atom-style variable v_{rest} in compute reduce must be evaluated by the caller"));
        }
        sim.atom_vector(input)
    }

    /// Per-atom values (property/atom column `col`, 1-based; None = the only one).
    pub fn peratom(&self, sim: &Sim, col: Option<usize>) -> Result<Vec<f64>, String> {
        match &self.kind {
            ComputeKind::PropertyAtom { names } => {
                let k = col.unwrap_or(1);
                let name = names.get(k - 1).ok_or_else(|| format!("compute {} has no column {k}", self.id))?;
                (0..sim.particles.len()).map(|i| atom_property(sim, name, i).ok_or_else(|| format!("unknown property {name}"))).collect()
            }
            ComputeKind::DisplaceAtom { column } => {
                let k = col.ok_or_else(|| format!("compute {} ({}) has 4 values per atom: use c_{}[1..4]", self.id, self.style, self.id))?;
                if !(1..=4).contains(&k) {
                    return Err(format!("compute {} has no column {k} (displace/atom has 4)", self.id));
                }
                let p = &sim.particles;
                let e = p.extra_index(column).map(|e| &p.extra[e]).ok_or_else(|| format!("compute {}: its originals are gone", self.id))?;
                Ok((0..p.len())
                    .map(|i| {
                        if p.mask[i] & self.group == 0 {
                            return 0.0;
                        }
                        let x = unwrapped(sim, i);
                        let d = [x.x - e.data[3 * i], x.y - e.data[3 * i + 1], x.z - e.data[3 * i + 2]];
                        if k == 4 {
                            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
                        } else {
                            d[k - 1]
                        }
                    })
                    .collect())
            }
            ComputeKind::ContactAtom => Ok(contacts_per_atom(sim, self.group)),
            ComputeKind::CoordAtom { cutoff, types } => {
                let k = match col {
                    None if types.len() == 1 => 1,
                    None => {
                        return Err(format!(
                            "compute {} ({}) has {} columns: use c_{}[1..{}]",
                            self.id,
                            self.style,
                            types.len(),
                            self.id,
                            types.len()
                        ))
                    }
                    Some(k) if (1..=types.len()).contains(&k) => k,
                    Some(k) => return Err(format!("compute {} has no column {k} (coord/atom here has {})", self.id, types.len())),
                };
                Ok(coordination(sim, self.group, *cutoff, types[k - 1]))
            }
            _ => Err(format!("compute {} ({}) has no per-atom values", self.id, self.style)),
        }
    }
}

/// Contacts per particle: the pair list holds every pair that can touch
/// before its next build, so the pairs in contact now are all in it.
fn contacts_per_atom(sim: &Sim, group: u32) -> Vec<f64> {
    let p = &sim.particles;
    let pairs = &sim.pairs;
    let mut n = vec![0.0; p.len()];
    for k in 0..pairs.len() {
        let (a, b) = (pairs.a[k] as usize, pairs.b[k] as usize);
        if a >= p.len() || b >= p.len() || (p.mask[a] | p.mask[b]) & group == 0 {
            continue;
        }
        let d = p.x[a] - (p.x[b] + pairs.shift(k));
        let rs = p.radius[a] + p.radius[b];
        if d.norm_squared() <= rs * rs {
            n[a] += 1.0;
            n[b] += 1.0;
        }
    }
    n
}

/// Neighbours closer than `cutoff` of each atom of `group`, counting those
/// with a type in `types` (any group), by a grid of cells of side `cutoff`
/// (periodic sides by the nearest image).
fn coordination(sim: &Sim, group: u32, cutoff: f64, types: (u32, u32)) -> Vec<f64> {
    let p = &sim.particles;
    let n = p.len();
    let mut out = vec![0.0; n];
    if n == 0 || !(cutoff > 0.0) {
        return out;
    }
    let (lo, hi, periodic) = match &sim.domain {
        Some(d) => (d.lo, d.hi, [0, 1, 2].map(|k| d.periodic(k))),
        None => ([0.0; 3], [0.0; 3], [false; 3]),
    };
    // cells of at least the cutoff, at most ~ one per atom and 2^20 in all
    let cap = (n.max(1) as f64).cbrt().ceil().clamp(1.0, 100.0);
    let cells: [usize; 3] = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / cutoff).floor()).clamp(1.0, cap) as usize);
    let size: [f64; 3] = [0, 1, 2].map(|k| (hi[k] - lo[k]) / cells[k] as f64);
    let cell_of = |x: &crate::physics::V3| -> [usize; 3] {
        [0, 1, 2].map(|k| if size[k] > 0.0 { (((x[k] - lo[k]) / size[k]).floor().max(0.0) as usize).min(cells[k] - 1) } else { 0 })
    };
    let flat = |c: [usize; 3]| (c[2] * cells[1] + c[1]) * cells[0] + c[0];
    // atoms by cell (counting sort)
    let mut start = vec![0usize; cells[0] * cells[1] * cells[2] + 1];
    let own: Vec<usize> = p.x.iter().map(|x| flat(cell_of(x))).collect();
    for &c in &own {
        start[c + 1] += 1;
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    let mut fill = start.clone();
    let mut atoms = vec![0usize; n];
    for (i, &c) in own.iter().enumerate() {
        atoms[fill[c]] = i;
        fill[c] += 1;
    }
    // the distinct cells next to cell c along one side
    let around = |k: usize, c: usize| -> Vec<usize> {
        let m = cells[k];
        let mut v: Vec<usize> = if m <= 3 {
            (0..m).collect()
        } else if periodic[k] {
            vec![(c + m - 1) % m, c, (c + 1) % m]
        } else {
            (c.saturating_sub(1)..=(c + 1).min(m - 1)).collect()
        };
        v.dedup();
        v
    };
    let len = [0, 1, 2].map(|k| hi[k] - lo[k]);
    let cut2 = cutoff * cutoff;
    for i in 0..n {
        if p.mask[i] & group == 0 {
            continue;
        }
        let c = cell_of(&p.x[i]);
        let mut count = 0u64;
        for cz in around(2, c[2]) {
            for cy in around(1, c[1]) {
                for cx in around(0, c[0]) {
                    let f = flat([cx, cy, cz]);
                    for &j in &atoms[start[f]..start[f + 1]] {
                        if j == i || p.kind[j] < types.0 || p.kind[j] > types.1 {
                            continue;
                        }
                        let mut d = p.x[i] - p.x[j];
                        for k in 0..3 {
                            if periodic[k] && len[k] > 0.0 {
                                d[k] -= len[k] * (d[k] / len[k]).round();
                            }
                        }
                        if d.norm_squared() < cut2 {
                            count += 1;
                        }
                    }
                }
            }
        }
        out[i] = count as f64;
    }
    out
}

fn split_index(s: &str) -> (&str, Option<usize>) {
    if let Some(b) = s.find('[') {
        let idx = s[b + 1..].trim_end_matches(']').parse().ok();
        (&s[..b], idx)
    } else {
        (s, None)
    }
}

/// Unwrapped position of particle i (x + image * L).
pub fn unwrapped(sim: &Sim, i: usize) -> crate::physics::V3 {
    let p = &sim.particles;
    let mut x = p.x[i];
    if let Some(d) = &sim.domain {
        for k in 0..3 {
            x[k] += p.image[i][k] as f64 * d.len(k);
        }
    }
    x
}

/// A per-atom property by LAMMPS name (dump custom / atom variables).
pub fn atom_property(sim: &Sim, name: &str, i: usize) -> Option<f64> {
    let p = &sim.particles;
    Some(match name {
        "id" => p.tag[i] as f64,
        "type" => p.kind[i] as f64,
        "mass" => p.mass[i],
        "radius" => p.radius[i],
        "diameter" => 2.0 * p.radius[i],
        "density" => p.density[i],
        "x" => p.x[i].x,
        "y" => p.x[i].y,
        "z" => p.x[i].z,
        "xu" => unwrapped(sim, i).x,
        "yu" => unwrapped(sim, i).y,
        "zu" => unwrapped(sim, i).z,
        "ix" => p.image[i][0] as f64,
        "iy" => p.image[i][1] as f64,
        "iz" => p.image[i][2] as f64,
        "vx" => p.v[i].x,
        "vy" => p.v[i].y,
        "vz" => p.v[i].z,
        "fx" => p.f[i].x,
        "fy" => p.f[i].y,
        "fz" => p.f[i].z,
        "omegax" | "wx" => p.omega[i].x,
        "omegay" | "wy" => p.omega[i].y,
        "omegaz" | "wz" => p.omega[i].z,
        "tqx" => p.torque[i].x,
        "tqy" => p.torque[i].y,
        "tqz" => p.torque[i].z,
        "angmomx" => p.inertia(i) * p.omega[i].x,
        "angmomy" => p.inertia(i) * p.omega[i].y,
        "angmomz" => p.inertia(i) * p.omega[i].z,
        "mol" => 0.0,
        "q" => 0.0,
        "xs" | "ys" | "zs" => {
            let d = sim.domain.as_ref()?;
            let k = (name.as_bytes()[0] - b'x') as usize;
            (p.x[i][k] - d.lo[k]) / d.len(k)
        }
        _ => return None,
    })
}

/// Group functions of the variable language: count, mass, xcm, vcm, ke, bound.
pub fn group_function(sim: &Sim, name: &str, args: &[&str]) -> Result<f64, String> {
    group_function_in(sim, name, args, &|_| true)
}

/// Group functions restricted to the particles `inside` accepts (the
/// optional region argument, e.g. `count(all,col)`, resolved by the caller
/// and removed from `args`).
pub fn group_function_in(sim: &Sim, name: &str, args: &[&str], inside: &dyn Fn(usize) -> bool) -> Result<f64, String> {
    let g = args.first().ok_or_else(|| format!("{name}() needs a group"))?;
    let bit = sim.group_bit(g).ok_or_else(|| format!("group {g} does not exist"))?;
    let p = &sim.particles;
    let members = || (0..p.len()).filter(move |&i| p.mask[i] & bit != 0 && inside(i));
    let dim = |s: Option<&&str>| -> Result<usize, String> {
        match s.copied() {
            Some("x") => Ok(0),
            Some("y") => Ok(1),
            Some("z") => Ok(2),
            other => Err(format!("{name}() needs a dimension x, y or z, not {other:?}")),
        }
    };
    Ok(match name {
        "count" => members().count() as f64,
        "mass" => members().map(|i| p.mass[i]).sum(),
        "ke" => members().map(|i| 0.5 * p.mass[i] * p.v[i].norm_squared()).sum(),
        "xcm" | "vcm" | "fcm" => {
            let k = dim(args.get(1))?;
            let m: f64 = members().map(|i| p.mass[i]).sum();
            if name == "fcm" {
                return Ok(members().map(|i| p.f[i][k]).sum());
            }
            if m == 0.0 {
                return Ok(0.0);
            }
            let s: f64 = members().map(|i| p.mass[i] * if name == "xcm" { unwrapped(sim, i)[k] } else { p.v[i][k] }).sum();
            s / m
        }
        "bound" => {
            let which = args.get(1).ok_or("bound() needs xmin/xmax/...")?;
            let k = match &which[..1] {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                _ => return Err(format!("bad bound {which}")),
            };
            let it = members().map(|i| p.x[i][k]);
            if which.ends_with("min") {
                it.fold(f64::INFINITY, f64::min)
            } else {
                it.fold(f64::NEG_INFINITY, f64::max)
            }
        }
        _ => return Err(format!("unknown group function {name}()")),
    })
}
