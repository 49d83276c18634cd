//! The pressure tensor (`thermo_style ... pxx pyy pzz pxy pxz pyz`) against
//! the real LAMMPS (`lmp`): LAMMPS's `compute pressure` vector, the kinetic
//! tensor sum m v_a v_b plus the pair virial sum r_ij (x) F_ij, over the
//! volume (the area in 2d, where the z components are 0). demx sums the
//! virial tensor only in the force passes of the steps that print it, or of
//! every step while a variable reads it: both paths are checked, in 3d on a
//! compressed periodic lattice with tangential history, and in 2d on
//! LAMMPS's granular chute example.

use crate::common;

use crate::common::{engine_and_demx, thermo_runs};

/// 216 spheres of diameter 1.05 on a simple cubic lattice of spacing 1, in a
/// periodic box: every neighbour pair overlaps, and random velocities shear
/// the contacts (tangential history, an asymmetric virial). A variable reads
/// pxy every 25 steps through `fix print`, between the thermo steps; in a
/// second run thermo no longer prints the tensor, so only the variable asks
/// for it.
const LATTICE: &str = "units lj\natom_style sphere\nboundary p p p\ncomm_modify vel yes\n\
lattice sc 1.0\nregion box block 0 6 0 6 0 6\ncreate_box 1 box\ncreate_atoms 1 box\n\
set group all diameter 1.05\nvelocity all create 0.5 4928 loop geom\n\
pair_style gran/hertz/history 2000.0 NULL 50.0 NULL 0.5 1\npair_coeff * *\n\
fix 1 all nve/sphere\ntimestep 0.0005\n\
variable sxy equal pxy\nfix pr all print 25 \"$(step) ${sxy}\" file print.txt screen no\n\
thermo_style custom step press pxx pyy pzz pxy pxz pyz\nthermo_modify format float %.15g\nthermo 50\nrun 400\n\
thermo_style custom step press\nrun 100\n";

/// Each thermo row of each run as numbers.
fn rows(out: &str) -> Vec<Vec<Vec<f64>>> {
    thermo_runs(out).into_iter().map(|run| run.iter().map(|r| r.iter().map(|w| w.parse().unwrap_or(f64::NAN)).collect()).collect()).collect()
}

/// Whether `ours` and `theirs` agree to `rel` of `scale`.
fn close(ours: f64, theirs: f64, scale: f64, rel: f64) -> bool {
    (ours - theirs).abs() <= rel * scale
}

#[test]
fn lattice_tensor_follows_lammps_on_thermo_steps_and_in_variables() {
    let both = engine_and_demx("lmp", "in.lattice", &[("in.lattice", LATTICE)]);
    let (ours, theirs) = (rows(&both.ours_out), rows(&both.theirs_out));
    assert_eq!(ours.len(), 2, "two runs: {}", both.ours_out);
    assert_eq!(ours[0].len(), 9, "thermo rows at steps 0, 50, ..., 400");
    assert_eq!(ours[0].len(), theirs[0].len());
    let mut asym = 0.0f64;
    for (r, s) in ours[0].iter().zip(&theirs[0]) {
        assert_eq!(r[0], s[0], "steps");
        // the sums' order differs (LAMMPS adds by neighbour list)
        let scale = s[2].abs() + s[3].abs() + s[4].abs();
        for k in 1..8 {
            assert!(close(r[k], s[k], scale, 1e-9), "step {}: column {k}: demx {} against LAMMPS {}", r[0], r[k], s[k]);
        }
        // the trace of the tensor is the pressure
        assert!(close((r[2] + r[3] + r[4]) / 3.0, r[1], scale, 1e-12), "step {}: trace {} against press {}", r[0], (r[2] + r[3] + r[4]) / 3.0, r[1]);
        asym = asym.max(s[5].abs() / scale);
    }
    // the scene is the one meant: compressed, and sheared enough that a
    // transposed xy (sum r_y F_x) would differ from LAMMPS's
    assert!(theirs[0][0][1] > 10.0, "LAMMPS's pressure: {:?}", theirs[0][0]);
    assert!(asym > 1e-6, "no shear stress to tell xy from yx: {asym}");
    // pxy read by a variable every 25 steps, between the thermo steps too,
    // and in the second run, where thermo does not read it
    let printed = |d: &std::path::Path| -> Vec<[f64; 2]> {
        let text = std::fs::read_to_string(d.join("print.txt")).expect("print.txt written");
        text.lines()
            .skip(1)
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
                [v[0], v[1]]
            })
            .collect()
    };
    let (a, b) = (printed(both.ours.path()), printed(both.theirs.path()));
    assert_eq!(a.len(), b.len(), "rows printed: demx {a:?} LAMMPS {b:?}");
    assert!(a.len() >= 21 && a.last().map(|r| r[0]) == Some(500.0), "rows at steps 0, 25, ..., 500: {a:?}");
    let scale = theirs[0][0][1].abs() * 3.0;
    for (r, s) in a.iter().zip(&b) {
        assert_eq!(r[0], s[0]);
        assert!(close(r[1], s[1], scale, 1e-9), "step {}: pxy by variable: demx {} against LAMMPS {}", r[0], r[1], s[1]);
    }
}

#[test]
fn chute_example_tensor_follows_lammps_in_2d() {
    // LAMMPS's granular chute example (2d, granular hertz with linear
    // history, a granular wall), its first run cut to 3000 steps
    let path = "/work/shared/decks/lammps/granular/in.chute";
    let src = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("the LAMMPS granular chute example {path}: {e}"));
    let first = src.find("run                 60000").expect("the example's first run");
    let deck = src[..first].replace("thermo              1000", "thermo_modify       format float %.15g\nthermo              500") + "run 3000\n";
    let both = engine_and_demx("lmp", "in.chute", &[("in.chute", &deck)]);
    let (ours, theirs) = (rows(&both.ours_out), rows(&both.theirs_out));
    assert_eq!(ours.len(), 1, "one run: {}", both.ours_out);
    assert_eq!(ours[0].len(), 7, "thermo rows at steps 0, 500, ..., 3000");
    assert_eq!(ours[0].len(), theirs[0].len());
    // step ke press vol pxx pyy pxy
    for (r, s) in ours[0].iter().zip(&theirs[0]) {
        assert_eq!(r[0], s[0], "steps");
        let scale = s[4].abs() + s[5].abs();
        for k in [2, 4, 5, 6] {
            assert!(close(r[k], s[k], scale, 1e-7), "step {}: column {k}: demx {} against LAMMPS {}", r[0], r[k], s[k]);
        }
        assert_eq!(r[3], s[3], "the area");
        // in 2d the pressure is the mean of xx and yy
        assert!(close((r[4] + r[5]) / 2.0, r[2], scale, 1e-12), "step {}: 2d trace", r[0]);
    }
    // the grains settle onto the wall: a pressure to compare
    assert!(theirs[0].last().unwrap()[5] > 0.0, "LAMMPS's pyy: {:?}", theirs[0].last());
}

/// A resumed run's first thermo line prints the pressure of the force pass
/// the restart saved, as the run that wrote it printed it at that step (the
/// resumed run reuses the saved forces; before, it printed the kinetic part
/// alone), and the tensor with it.
#[test]
fn resumed_run_prints_the_saved_virial() {
    let dir = tempfile::tempdir().unwrap();
    let first = LATTICE.split("variable sxy").next().unwrap().to_string()
        + "thermo_style custom step press pxx pxy\nthermo_modify format float %.15g\nthermo 50\nrun 100\nwrite_restart r.100\n";
    let second = "read_restart r.100\nfix 1 all nve/sphere\ntimestep 0.0005\n\
thermo_style custom step press pxx pxy\nthermo_modify format float %.15g\nthermo 50\nrun 50\n";
    std::fs::write(dir.path().join("in.first"), first).unwrap();
    std::fs::write(dir.path().join("in.second"), second).unwrap();
    let demx = |deck: &str| common::run(dir.path(), std::process::Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", deck, "--log", "none"]));
    let (a, b) = (rows(&demx("in.first")), rows(&demx("in.second")));
    let wrote = a[0].last().unwrap();
    let resumed = &b[0][0];
    assert_eq!(wrote[0], 100.0);
    assert_eq!(resumed, wrote, "the resumed run's first line against the last line of the run that wrote the restart");
    assert!(resumed[1] > 10.0, "the pair virial is in the pressure: {resumed:?}");
}

/// Without a pair style the tensor is the kinetic one alone: two atoms of
/// mass m in a periodic box of volume V, with velocities (1, 2, 3) and
/// (-1, 0.5, 0), give pxx = m (1 + 1) / V, pxy = m (2 - 0.5) / V, and so on
/// (LAMMPS's compute pressure with thermo_temp's kinetic tensor).
#[test]
fn kinetic_tensor_without_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let deck = "units lj\natom_style sphere\nboundary p p p\nregion box block 0 2 0 3 0 4\ncreate_box 1 box\n\
create_atoms 1 single 0.5 0.5 0.5\ncreate_atoms 1 single 1.5 1.5 1.5\nset atom 1 mass 2.0\nset atom 2 mass 2.0\n\
velocity all set 1 2 3\nset atom 2 vx -1 vy 0.5 vz 0\n\
thermo_style custom step pxx pyy pzz pxy pxz pyz\nthermo_modify format float %.15g\nrun 0\n";
    std::fs::write(dir.path().join("in.gas"), deck).unwrap();
    let out = common::run(dir.path(), std::process::Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", "in.gas", "--log", "none"]));
    let r = &rows(&out)[0][0];
    let (m, v) = (2.0, 24.0);
    let want = [m * (1.0 + 1.0) / v, m * (4.0 + 0.25) / v, m * 9.0 / v, m * (2.0 - 0.5) / v, m * 3.0 / v, m * 6.0 / v];
    for k in 0..6 {
        assert!((r[k + 1] - want[k]).abs() <= 1e-15, "component {k}: {} against {}: {out}", r[k + 1], want[k]);
    }
}
