//! Exact resume with grains resting on walls (trust issue, item 1): a run
//! continued from `restart N` agrees bit for bit with the uninterrupted run
//! at the first step after the restart and 10,000 steps later, with grains
//! resting and rolling on a primitive wall, a mesh wall (LIGGGHTS dialect)
//! and a region wall (LAMMPS dialect), each with shear and rolling history.
//!
//! Before the fix, the walls' histories were saved and put back, but the
//! first step after the resume treated the wall as being in a run's setup
//! (a per-wall flag set by every setup, consumed by the setup's force pass
//! that a resumed run skips), so the history did not advance at that step
//! and every grain touching a wall differed.

use demx::io::dump::{DumpReader, Frame};
use std::path::Path;
use std::process::Command;

use crate::common;

/// The restart step, the dump interval (frames at R + 1 and 2 R + 2 after
/// it) and the last step.
const R: u64 = 10000;
const EVERY: u64 = R + 1;
const END: u64 = 3 * EVERY;

fn demx(dir: &Path, deck: &str) {
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(["run", deck, "--log", "none", "--quiet"]).output().expect("run demx");
    assert!(o.status.success(), "demx run {deck}: {}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
}

fn frames(path: &Path) -> Vec<Frame> {
    DumpReader::open(path).expect("open dump").map(|f| f.expect("complete frame")).collect()
}

/// Runs `head + tail` uninterrupted with a restart at R, then `resume`
/// (read_restart of it) + `tail`; returns both dumps' frames.
fn full_and_resumed(files: &[(&str, &str)], head: &str, resume_head: &str, tail: &str) -> (Vec<Frame>, Vec<Frame>) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, text) in files {
        std::fs::write(d.join(name), text).unwrap();
    }
    let dump = |name: &str| {
        format!("dump d all custom {EVERY} dump.{name} id x y z vx vy vz fx fy fz omegax omegay omegaz\ndump_modify d format float %20.15g\n")
    };
    std::fs::write(d.join("in.full"), format!("{head}{tail}{}restart {R} restart.*\nrun {END}\n", dump("full"))).unwrap();
    std::fs::write(d.join("in.resumed"), format!("{resume_head}read_restart restart.{R}\n{tail}{}run {END} upto\n", dump("resumed"))).unwrap();
    demx(d, "in.full");
    assert!(d.join(format!("restart.{R}")).exists(), "restart written at step {R}");
    demx(d, "in.resumed");
    (frames(&d.join("dump.full")), frames(&d.join("dump.resumed")))
}

/// Every column of every particle of the frames at R + 1 and at the end is
/// the same bits; returns how many grains touch the floor at the end and
/// how many turn at the first step after the restart.
fn assert_bitwise(full: &[Frame], resumed: &[Frame], floor_z: f64, radius: f64) -> (usize, usize) {
    for step in [R + 1, END] {
        let a = full.iter().find(|f| f.timestep == step).unwrap_or_else(|| panic!("uninterrupted frame {step}"));
        let b = resumed.iter().find(|f| f.timestep == step).unwrap_or_else(|| panic!("resumed frame {step}"));
        assert_eq!(a.natoms, b.natoms, "step {step}: particle counts");
        let id = a.col("id").unwrap();
        for row in 0..a.natoms {
            let tag = a.get(row, id).unwrap() as u64;
            let rb = b.row_of_id(tag).expect("same ids");
            let (ra, rbv) = (a.row(row).unwrap(), b.row(rb).unwrap());
            let same = ra.iter().zip(rbv).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "step {step}: particle {tag} differs after resume:\n  {ra:?}\n  {rbv:?}");
        }
    }
    let last = full.iter().find(|f| f.timestep == END).unwrap();
    let z = last.column("z").unwrap();
    let on_floor = z.iter().filter(|&&z| z < floor_z + radius * (1.0 + 1e-3)).count();
    // turning across the restart: at its first step
    let first = full.iter().find(|f| f.timestep == R + 1).unwrap();
    let (wx, wy) = (first.column("omegax").unwrap(), first.column("omegay").unwrap());
    let turning = wx.iter().zip(&wy).filter(|(x, y)| x.abs() + y.abs() > 1e-3).count();
    (on_floor, turning)
}

/// LIGGGHTS: grains on a primitive floor and on a mesh plate, Hertz with
/// shear history and epsd rolling friction (which keeps a rolling history).
#[test]
fn liggghts_primitive_and_mesh_walls_resume_bitwise() {
    let setup = "units si\natom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\n";
    let head_box = "region box block -0.001 0.009 -0.001 0.005 -0.001 0.006 units box\ncreate_box 1 box\nlattice sc 0.001\n\
region g1 block 0.0005 0.0035 0.0005 0.0035 0.0025 0.0045 units box\ncreate_atoms 1 region g1\n\
region g2 block 0.0045 0.0075 0.0005 0.0035 0.0005 0.0025 units box\ncreate_atoms 1 region g2\n\
set group all diameter 0.0009 density 2500\n";
    let model = "fix m1 all property/global youngsModulus peratomtype 1e7\nfix m2 all property/global poissonsRatio peratomtype 0.3\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n\
fix m6 all property/global coefficientRollingViscousDamping peratomtypepair 1 0.2\n\
pair_style gran model hertz tangential history rolling_friction epsd\npair_coeff * *\nneighbor 0.0002 bin\nneigh_modify delay 0\n";
    let tail = "fix cad all mesh/surface file plate.stl type 1\n\
fix wall all wall/gran model hertz tangential history rolling_friction epsd mesh n_meshes 1 meshes cad\n\
fix floor all wall/gran model hertz tangential history rolling_friction epsd primitive type 1 zplane 0.0\n\
fix g all gravity 9.81 vector 0.05 0.02 -1\nfix 1 all nve/sphere\ntimestep 2e-6\n";
    let head = format!("{setup}{head_box}{model}velocity all set 0.01 0.005 0\n");
    let resume_head = setup.to_string();
    // the plate covers x, y in [0, 0.004] at z = 0.002: half the grains land on it, half on the floor
    let files = [("plate.stl", common::plate_stl("0.002"))];
    let files: Vec<(&str, &str)> = files.iter().map(|(n, t)| (*n, t.as_str())).collect();
    let (full, resumed) = full_and_resumed(&files, &head, &resume_head.to_string(), tail);
    let (on_floor, turning) = assert_bitwise(&full, &resumed, 0.0, 0.00045);
    // the scene is the one meant: grains rest on both walls and turn
    let last = full.iter().find(|f| f.timestep == END).unwrap();
    let z = last.column("z").unwrap();
    let on_plate = z.iter().filter(|&&z| (z - 0.00245).abs() < 1e-5).count();
    assert!(on_floor >= 5 && on_plate >= 5, "grains on the floor {on_floor}, on the plate {on_plate}");
    assert!(turning >= 5, "grains turning {turning}");
}

/// LAMMPS: grains on a `wall/gran` floor and in a `wall/gran/region` box,
/// `pair_style granular` with Mindlin shear history and SDS rolling history.
#[test]
fn lammps_primitive_and_region_walls_resume_bitwise() {
    let setup = "units si\natom_style sphere\natom_modify map array\nboundary f f f\nnewton off\ncomm_modify vel yes\n";
    let head_box = "region box block -0.001 0.009 -0.001 0.005 -0.001 0.006 units box\ncreate_box 1 box\nlattice sc 0.001\n\
region g1 block 0.0005 0.0035 0.0005 0.0035 0.0025 0.0045 units box\ncreate_atoms 1 region g1\n\
region g2 block 0.0045 0.0075 0.0005 0.0035 0.0005 0.0025 units box\ncreate_atoms 1 region g2\n\
set group all diameter 0.0009 density 2500\n";
    let coeff = "hertz/material 1e7 0.5 0.3 tangential mindlin NULL 1.0 0.5 damping tsuji rolling sds 100 1e-4 0.1";
    let model = format!("pair_style granular\npair_coeff * * {coeff}\nneighbor 0.0002 bin\nneigh_modify delay 0\n");
    // a region box whose top face is a step 2 mm above the floor under half of the grains
    let tail = format!(
        "region step block 0.0 0.004 -0.002 0.006 -0.002 0.002 units box side out\n\
fix wall all wall/gran/region granular {coeff} region step\n\
fix floor all wall/gran granular {coeff} zplane 0.0 NULL\n\
fix g all gravity 9.81 vector 0.05 0.02 -1\nfix 1 all nve/sphere\ntimestep 2e-6\n"
    );
    let head = format!("{setup}{head_box}{model}velocity all set 0.01 0.005 0 units box\n");
    let (full, resumed) = full_and_resumed(&[], &head, setup, &tail);
    let (on_floor, turning) = assert_bitwise(&full, &resumed, 0.0, 0.00045);
    let last = full.iter().find(|f| f.timestep == END).unwrap();
    let z = last.column("z").unwrap();
    let on_step = z.iter().filter(|&&z| (z - 0.00245).abs() < 1e-5).count();
    assert!(on_floor >= 5 && on_step >= 5, "grains on the floor {on_floor}, on the step {on_step}");
    assert!(turning >= 5, "grains turning {turning}");
}
