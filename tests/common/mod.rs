//! Helpers shared by the integration tests (`tests/it`), e.g. for running a real engine (`lmp`, `liggghts`) and demx
//! on the same deck: a test file says `use crate::common;`.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use tempfile::TempDir;

/// Runs `cmd` in `dir`; panics with its output unless it exits 0. Returns
/// stdout and stderr together.
pub fn run(dir: &Path, cmd: &mut Command) -> String {
    let o = cmd.current_dir(dir).output().expect("run the engine");
    let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "{cmd:?} failed: {text}");
    text
}

/// One deck run by an engine and by demx, each in a fresh directory.
pub struct Both {
    pub theirs: TempDir,
    pub ours: TempDir,
    /// The engine's screen output.
    pub theirs_out: String,
    /// demx's screen output.
    pub ours_out: String,
}

/// Writes `files` (name, text) into two fresh directories and runs the deck
/// `deck` (one of them) with `engine -in deck` in the first and `demx run
/// deck` in the second.
pub fn engine_and_demx(engine: &str, deck: &str, files: &[(&str, &str)]) -> Both {
    let (theirs, ours) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for d in [&theirs, &ours] {
        for (name, text) in files {
            std::fs::write(d.path().join(name), text).unwrap();
        }
    }
    let theirs_out = run(theirs.path(), Command::new(engine).args(["-in", deck, "-log", "none", "-echo", "none"]));
    let ours_out = run(ours.path(), Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", deck, "--log", "none"]));
    Both { theirs, ours, theirs_out, ours_out }
}

/// A text dump's frames: step -> atom id -> the row's values after the id.
pub fn dump_frames(path: &Path) -> BTreeMap<i64, BTreeMap<i64, Vec<f64>>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = BTreeMap::new();
    let mut lines = text.lines().peekable();
    let mut step = 0;
    while let Some(l) = lines.next() {
        if l.starts_with("ITEM: TIMESTEP") {
            step = lines.next().unwrap().trim().parse().unwrap();
        } else if l.starts_with("ITEM: ATOMS") {
            let rows: &mut BTreeMap<i64, Vec<f64>> = out.entry(step).or_default();
            while lines.peek().is_some_and(|l| !l.starts_with("ITEM")) {
                let v: Vec<f64> = lines.next().unwrap().split_whitespace().map(|w| w.parse().unwrap()).collect();
                rows.insert(v[0] as i64, v[1..].to_vec());
            }
        }
    }
    out
}

/// The thermo rows (words) of each run in a screen output, from a `Step`
/// header to `Loop time`.
pub fn thermo_runs(out: &str) -> Vec<Vec<Vec<String>>> {
    let mut runs = vec![];
    let mut cur: Option<Vec<Vec<String>>> = None;
    for l in out.lines() {
        if l.trim_start().starts_with("Step ") {
            cur = Some(vec![]);
        } else if l.starts_with("Loop time") {
            runs.extend(cur.take());
        } else if let Some(rows) = cur.as_mut() {
            rows.push(l.split_whitespace().map(String::from).collect());
        }
    }
    runs
}

/// Runs `demx run in.deck --log none` on `deck` (and `files`) in a fresh
/// directory: its exit code and its output, stdout then stderr.
pub fn demx_deck(deck: &str, files: &[(&str, &str)]) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.deck"), deck).unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", "in.deck", "--log", "none"]).current_dir(dir.path()).output().unwrap();
    (o.status.code(), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

/// [`demx_deck`] on a deck that must stop as a deck error (exit 2): its output.
pub fn deck_error(deck: &str) -> String {
    let (code, out) = demx_deck(deck, &[]);
    assert_eq!(code, Some(2), "{out}");
    out
}

/// A square plate of two triangles at height `z` (4 mm a side, at x, y in
/// [0, 0.004]), as an ASCII STL.
pub fn plate_stl(z: &str) -> String {
    format!(
        "solid plate\nfacet normal 0 0 1\nouter loop\nvertex 0 0 {z}\nvertex 0.004 0 {z}\nvertex 0.004 0.004 {z}\nendloop\nendfacet\n\
facet normal 0 0 1\nouter loop\nvertex 0 0 {z}\nvertex 0.004 0.004 {z}\nvertex 0 0.004 {z}\nendloop\nendfacet\nendsolid plate\n"
    )
}

/// Nine grains thrown at the plate of `plate.stl` (fix `cad`, a
/// mesh/surface/stress with `cad_args`, walled by Hertz with history), the
/// middle column faster and sideways, so that the two columns hit at
/// different times with friction in x and y. `meshes` are fix lines put
/// before the wall, `tail` everything after the time step.
pub fn plate_deck(cad_args: &str, meshes: &str, tail: &str) -> String {
    let atoms = "lattice sc 0.001\nregion grains block 0.0005 0.0035 0.0005 0.0035 0.0005 0.0015 units box\ncreate_atoms 1 region grains\n\
set group all diameter 0.0009 density 2500\n";
    format!(
        "{}fix cad all mesh/surface/stress file plate.stl type 1{cad_args}\n{meshes}\
fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad\n\
fix g all gravity 9.81 vector 0 0 -1\nregion fast block 0.0015 0.0025 INF INF INF INF units box\n\
velocity all set 0.1 0 -0.5\ngroup fast region fast\nvelocity fast set 0 0.2 -0.8\nfix 1 all nve/sphere\ntimestep 1e-6\n{tail}",
        hertz_grains("-0.001 0.005 -0.001 0.005 -0.001 0.004", atoms, 0.5)
    )
}

/// The opening of a LIGGGHTS deck of one atom type in a fixed box (`bounds`:
/// xlo xhi ylo yhi zlo zhi, m): `atoms` (the lines that create and size the
/// grains), then Y = 1e7, nu = 0.3, the given restitution, friction 0.5,
/// Hertz with tangential history, neighbor 0.2 mm.
pub fn hertz_grains(bounds: &str, atoms: &str, restitution: f64) -> String {
    format!(
        "units si\natom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\n\
region box block {bounds} units box\ncreate_box 1 box\n{atoms}\
fix m1 all property/global youngsModulus peratomtype 1e7\nfix m2 all property/global poissonsRatio peratomtype 0.3\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 {restitution}\n\
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\nneighbor 0.0002 bin\n"
    )
}

/// 320 beads (d = 1 mm) on an fcc lattice falling onto a floor, periodic in
/// x and y, of `ntypes` types (all type 1 at creation), a LIGGGHTS deck up
/// to the integrator; `tail` follows it (computes, outputs, the run).
pub fn settling_beads(ntypes: usize, tail: &str) -> String {
    let per_type = |v: &str| vec![v; ntypes].join(" ");
    let per_pair = |v: &str| format!("{ntypes} {}", vec![v; ntypes * ntypes].join(" "));
    format!(
        "atom_style granular\natom_modify map array\nboundary p p f\nnewton off\ncommunicate single vel yes\nunits si\n\
region box block 0 0.006 0 0.006 0 0.02 units box\ncreate_box {ntypes} box\nneighbor 0.0002 bin\nneigh_modify delay 0\n\
fix m1 all property/global youngsModulus peratomtype {}\nfix m2 all property/global poissonsRatio peratomtype {}\n\
fix m3 all property/global coefficientRestitution peratomtypepair {}\nfix m4 all property/global coefficientFriction peratomtypepair {}\n\
pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 0.000005\nfix gravi all gravity 9.81 vector 0.0 0.0 -1.0\n\
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\nlattice fcc 0.0015\n\
region pts block 0 0.006 0 0.006 0.0006 0.008 units box\ncreate_atoms 1 region pts\nset group all diameter 0.001 density 2500\n\
fix integr all nve/sphere\n{tail}",
        per_type("5.e6"),
        per_type("0.45"),
        per_pair("0.3"),
        per_pair("0.5"),
    )
}

/// The frames of dump `name` of both runs of `b`, equal atom by atom
/// (panics naming the step where they differ); the engine's frames.
pub fn same_dump_frames(b: &Both, name: &str) -> BTreeMap<i64, BTreeMap<i64, Vec<f64>>> {
    let theirs = dump_frames(&b.theirs.path().join(name));
    let ours = dump_frames(&b.ours.path().join(name));
    assert_eq!(theirs.keys().collect::<Vec<_>>(), ours.keys().collect::<Vec<_>>(), "the same frames of {name}");
    for (step, rows) in &theirs {
        assert_eq!(rows, &ours[step], "step {step}: {name} differs atom by atom");
    }
    theirs
}
