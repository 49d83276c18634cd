//! `velocity ... create` and `scale` against the real LAMMPS (`lmp`): the
//! draws (uniform or Gaussian; by atom ID, by storage order or by position),
//! the 1/sqrt(m) factor, the momentum and rotation zeroing and the rescaling
//! to the temperature must give every atom lmp's velocity to the bit. The
//! decks also `set diameter` after `set density`, which keeps the mass in
//! LAMMPS (not in LIGGGHTS), so the mass column checks that too.

use crate::common;

/// 480 spheres on an fcc lattice, two types of different size and density.
const LJ: &str = "units lj\natom_style sphere\nboundary p p f\ncomm_modify vel yes\nlattice fcc 1.0\n\
region box block 0 6 0 5 0 4\ncreate_box 2 box\ncreate_atoms 1 region box\n\
region half block 0 3 INF INF INF INF\ngroup left region half\nset group left type 2\n\
set type 1 density 2.0\nset type 2 diameter 0.6\n\
pair_style gran/hooke/history 2000 NULL 50 NULL 0.5 0\npair_coeff * *\n";

/// 80 disks on a square lattice.
const LJ_2D: &str = "units lj\natom_style sphere\ndimension 2\nboundary p p p\ncomm_modify vel yes\n\
lattice sq 0.8\nregion box block 0 10 0 8 -0.5 0.5\ncreate_box 1 box\ncreate_atoms 1 region box\n\
pair_style gran/hooke/history 2000 NULL 50 NULL 0.5 0\npair_coeff * *\n";

/// 240 grains of 2 mm in SI units: the inertia tensor's determinant is far
/// below LAMMPS's 1e-6, so `rot yes` solves for w in its principal axes.
const SI: &str = "units si\natom_style sphere\nboundary p p f\ncomm_modify vel yes\nlattice sc 0.0025\n\
region box block 0 8 0 6 0 5\ncreate_box 1 box\ncreate_atoms 1 region box\n\
set group all diameter 0.002 density 2500\npair_style gran/hertz/history 1e6 NULL 0 NULL 0.5 0\npair_coeff * *\n";

const DUMP: &str = "dump d all custom 1 v.dump id mass vx vy vz\n\
dump_modify d sort id format line \"%d %.17g %.17g %.17g %.17g\"\nrun 0\n";

/// The dump's atom rows, as written, after running `setup` + `velocity` in
/// lmp and in demx.
fn rows(setup: &str, velocity: &str) -> (Vec<String>, Vec<String>) {
    let deck = format!("{setup}{velocity}\n{DUMP}");
    let b = common::engine_and_demx("lmp", "in.deck", &[("in.deck", &deck)]);
    let read = |d: &std::path::Path| -> Vec<String> {
        let text = std::fs::read_to_string(d.join("v.dump")).expect("v.dump written");
        text.split_once("ITEM: ATOMS").expect("an atoms section").1.lines().skip(1).map(String::from).collect()
    };
    (read(b.theirs.path()), read(b.ours.path()))
}

#[test]
fn velocities_follow_lammps_to_the_bit() {
    let cases = [
        (LJ, "velocity all create 1.44 87287 loop geom"),
        (LJ, "velocity all create 3.0 87287"),
        (LJ, "velocity all create 1.0 4928459 dist gaussian rot yes"),
        (LJ, "velocity left create 1.0 593849 loop local dist gaussian mom no"),
        (LJ, "velocity all create 1.0 4928459 dist gaussian\nvelocity all scale 2.5"),
        (LJ, "velocity all set 0.1 0.2 0.3\nvelocity left create 1.0 593849 sum yes rot yes"),
        (LJ, "velocity all create 1.0 4928459 dist gaussian mom no\nvelocity all zero angular\nvelocity all zero linear"),
        (LJ_2D, "velocity all create 1.0 4928459 dist gaussian rot yes"),
    ];
    for (setup, velocity) in cases {
        let (want, got) = rows(setup, velocity);
        assert!(want.len() >= 80, "{velocity}: lmp dumped {} atoms", want.len());
        let differ: Vec<_> = want.iter().zip(&got).filter(|(a, b)| a != b).collect();
        assert!(
            want.len() == got.len() && differ.is_empty(),
            "{velocity}: {} of {} rows differ from lmp's, first {:?}",
            differ.len(),
            want.len(),
            differ.first()
        );
    }
}

#[test]
fn rotation_zeroed_in_principal_axes_follows_lammps() {
    let (want, got) = rows(SI, "velocity all create 1e17 4928459 dist gaussian rot yes loop geom");
    let parse = |r: &String| -> Vec<f64> { r.split_whitespace().map(|w| w.parse().unwrap()).collect() };
    let (want, got): (Vec<_>, Vec<_>) = (want.iter().map(parse).collect(), got.iter().map(parse).collect());
    assert_eq!(want.len(), 240);
    let vmax = want.iter().flat_map(|r| r[2..5].to_vec()).fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(vmax > 0.1, "speeds of order 1 at this temperature: {vmax}");
    for (a, b) in want.iter().zip(&got) {
        assert_eq!(a[..2], b[..2], "id and mass");
        for k in 2..5 {
            // the principal axes come from another eigen solver: rounding only
            assert!((a[k] - b[k]).abs() <= 1e-15 * vmax, "atom {}: lmp {:?} demx {:?}", a[0], a, b);
        }
    }
}

#[test]
fn bad_velocity_commands_are_deck_errors() {
    let line = LJ.lines().count() + 1;
    let err = common::deck_error(&format!("{LJ}velocity all create 1.0 0\n{DUMP}"));
    assert!(err.contains(&format!("in.deck:{line}:")) && err.contains("seed 0 must be a positive integer"), "{err}");
    let err = common::deck_error(&format!("{LJ}velocity all scale 1.0\n{DUMP}"));
    assert!(err.contains(&format!("in.deck:{line}:")) && err.contains("cannot rescale a temperature of 0"), "{err}");
    // IDs 1..N with a gap: loop all cannot hand the draws out by ID
    let err = common::deck_error(&format!("{LJ}group one id 7\ndelete_atoms group one compress no\nvelocity all create 1.0 87287\n{DUMP}"));
    assert!(err.contains(&format!("in.deck:{}:", line + 2)) && err.contains("consecutive") && err.contains("loop geom"), "{err}");
}

/// `velocity ... set` with numbers and no `units`: LAMMPS scales them by the
/// lattice spacings (units lattice), LIGGGHTS 3.8 does not (its velocity.cpp
/// defaults to box). A lattice of spacing 1 mm in SI, set to 0.01 m/s in x:
/// each engine's kinetic energy, and demx's on each dialect, must agree.
#[test]
fn velocity_set_units_default_follows_each_engine() {
    let liggghts = "units si\natom_style granular\natom_modify map array\nboundary p p p\nnewton off\n\
communicate single vel yes\nregion box block 0 0.006 0 0.006 0 0.006 units box\ncreate_box 1 box\nlattice sc 0.001\n\
create_atoms 1 box\nset group all diameter 0.00105 density 2500\nvelocity all set 0.01 0 0\n\
fix m1 all property/global youngsModulus peratomtype 1e7\nfix m2 all property/global poissonsRatio peratomtype 0.3\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\nneighbor 0.0002 bin\nfix 1 all nve/sphere\ntimestep 1e-7\n\
thermo_style custom step ke\nthermo_modify format float %.15g\nrun 0\n";
    let lammps = "units si\natom_style sphere\nboundary p p p\ncomm_modify vel yes\nlattice sc 0.001\n\
region box block 0 6 0 6 0 6\ncreate_box 1 box\ncreate_atoms 1 box\nset group all diameter 0.00105 density 2500\n\
velocity all set 0.01 0 0\npair_style gran/hertz/history 1e6 NULL 0 NULL 0.5 0\npair_coeff * *\n\
thermo_style custom step ke\nthermo_modify format float %.15g\nrun 0\n";
    // 216 grains of 1.05 mm and 2500 kg/m^3 at 0.01 m/s, or at 1e-5 m/s
    let m = 2500.0 * std::f64::consts::PI / 6.0 * 0.00105f64.powi(3);
    for (engine, deck, v) in [("liggghts", liggghts, 0.01), ("lmp", lammps, 0.01 * 0.001)] {
        let b = common::engine_and_demx(engine, "in.deck", &[("in.deck", deck)]);
        let ke = |out: &str| -> f64 { common::thermo_runs(out)[0][0][1].parse().unwrap() };
        let (theirs, ours) = (ke(&b.theirs_out), ke(&b.ours_out));
        let want = 0.5 * 216.0 * m * v * v;
        assert!((theirs - want).abs() <= 1e-9 * want, "{engine}'s ke {theirs} against {want}: the deck is not the scene meant");
        assert!((ours - theirs).abs() <= 1e-12 * theirs, "{engine} deck: demx's ke {ours} against {theirs}");
    }
}
