//! `fix heat/gran` (LIGGGHTS 3.8): heat conduction between grains in
//! contact. Against the discrete solution for two grains at rest, against
//! the energy balance of heat sources, and against `liggghts` on a moving
//! bed of two materials with adiabatic grains.

use crate::common;

use std::process::Command;

const MATERIALS: &str = "fix m1 all property/global youngsModulus peratomtype 1e7 2e7\n\
fix m2 all property/global poissonsRatio peratomtype 0.3 0.3\n\
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5\n\
fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5\n\
fix ftco all property/global thermalConductivity peratomtype 100. 20.\n\
fix ftca all property/global thermalCapacity peratomtype 10. 40.\n\
pair_style gran model hertz tangential history\npair_coeff * *\nneighbor 0.0002 bin\n";

const HEAD: &str = "units si\natom_style granular\natom_modify map array\nboundary p p p\nnewton off\n\
communicate single vel yes\nregion box block 0 0.004 0 0.004 0 0.004 units box\ncreate_box 2 box\n";

fn demx(dir: &std::path::Path, deck: &str) -> String {
    std::fs::write(dir.join("in.deck"), deck).unwrap();
    common::run(dir, Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", "in.deck", "--log", "none"]))
}

/// Two equal grains at rest (no integrator), overlapping, at 300 K and 800
/// K. The contact area is the circle where the spheres meet, pi (R^2 -
/// r^2/4); h_c = 4 k k / (k + k) sqrt(A) = 2 k sqrt(A). Explicit Euler on
/// both temperatures makes their difference shrink by (1 - 2 h_c dt / (m
/// c)) per step and keeps their sum.
#[test]
fn two_grains_at_rest_follow_the_discrete_solution() {
    let (r, d, k, c, rho, dt, n) = (0.0005f64, 0.00095f64, 100.0f64, 10.0f64, 2500.0f64, 1e-6f64, 200);
    let deck = format!(
        "{HEAD}create_atoms 1 single 0.001 0.002 0.002 units box\ncreate_atoms 1 single {} 0.002 0.002 units box\n\
set group all diameter {} density {rho}\n{MATERIALS}fix heattransfer all heat/gran initial_temperature 300.\n\
run 0\nset atom 2 property/atom Temp 800.\ntimestep {dt}\nthermo_style custom step f_heattransfer\n\
thermo_modify format float %.15g\nthermo {n}\n\
dump d all custom {n} dump.t id f_Temp[0] f_heatFlux[0] f_directionalHeatFlux[1]\ndump_modify d format float %.17g\nrun {n}\n",
        0.001 + d,
        2.0 * r
    );
    let dir = tempfile::tempdir().unwrap();
    let out = demx(dir.path(), &deck);
    let frames = common::dump_frames(&dir.path().join("dump.t"));
    let (first, last) = (&frames[&0], &frames[&n]);
    // the engine sums no flux at a run's first force pass
    assert_eq!(first[&1][1], 0.0, "{out}");
    let m = rho * std::f64::consts::PI * 4.0 / 3.0 * r.powi(3);
    let area = std::f64::consts::PI * (r * r - d * d / 4.0);
    let hc = 2.0 * k * area.sqrt();
    let shrink = 1.0 - 2.0 * hc * dt / (m * c);
    let want_diff = 500.0 * shrink.powi(n as i32);
    let (t1, t2) = (last[&1][0], last[&2][0]);
    assert!(((t2 - t1) - want_diff).abs() <= 1e-9 * 500.0, "T2 - T1 = {} against {want_diff}", t2 - t1);
    assert!((t1 + t2 - 1100.0).abs() <= 1e-9 * 1100.0, "the sum of temperatures moved: {t1} + {t2}");
    // the continuous solution, exp(-2 h_c t / (m c)), within Euler's error
    let cont = 500.0 * (-2.0 * hc * dt * n as f64 / (m * c)).exp();
    assert!((t2 - t1 - cont).abs() < 0.01 * cont && want_diff < 0.9 * 500.0, "{} against exp: {cont}", t2 - t1);
    // the last step's flux into grain 1 is h_c times the difference before it
    let q = hc * want_diff / shrink;
    assert!((last[&1][1] - q).abs() <= 1e-9 * q && (last[&2][1] + q).abs() <= 1e-9 * q, "{:?} against {q}", last);
    // half the flux times the centre vector (grain 1 minus grain 2), the same for both grains
    let want_dir = 0.5 * q * -d;
    assert!((last[&1][2] - want_dir).abs() <= 1e-9 * want_dir.abs() && last[&2][2] == last[&1][2], "{:?}", last);
    // f_ID is the thermal energy c m (T1 + T2), kept
    let e: Vec<f64> = common::thermo_runs(&out).last().unwrap().iter().map(|row| row[1].parse().unwrap()).collect();
    for v in e {
        assert!((v - c * m * 1100.0).abs() <= 1e-12 * c * m * 1100.0, "{v}");
    }
}

/// Heat sources raise the thermal energy by their sum times the time,
/// whatever the contacts do (a bed of grains pressed together, every grain
/// in the group).
#[test]
fn sources_add_their_energy_and_contacts_keep_it() {
    let (s, dt, n) = (0.5f64, 1e-7f64, 2000);
    let deck = format!(
        "{HEAD}lattice sc 0.001\ncreate_atoms 1 box\nregion two block 0 0.002 0 0.002 0 0.004 units box\nset region two type 2\n\
set type 1 diameter 0.00108 density 2500\nset type 2 diameter 0.00102 density 4000\n{MATERIALS}\
fix heattransfer all heat/gran initial_temperature 300.\nrun 0\nregion src block 0.0025 0.004 0 0.004 0 0.004 units box\n\
set region src property/atom heatSource {s}\nfix 1 all nve/sphere\ntimestep {dt}\n\
thermo_style custom step f_heattransfer\nthermo_modify format float %.15g\nthermo 500\nrun {n}\n"
    );
    let dir = tempfile::tempdir().unwrap();
    let out = demx(dir.path(), &deck);
    // the x = 3 mm layer: 16 grains
    assert!(out.contains("  16 settings made for property/atom"), "{out}");
    let rows = common::thermo_runs(&out).last().unwrap().clone();
    let e0: f64 = rows[0][1].parse().unwrap();
    for row in &rows {
        let (step, e): (f64, f64) = (row[0].parse().unwrap(), row[1].parse().unwrap());
        let want = e0 + 16.0 * s * step * dt;
        assert!((e - want).abs() <= 1e-10 * e0, "step {step}: {e} against {want}");
    }
}

/// A bed of two materials pressed together, moving, with adiabatic grains
/// (outside the fix group), a hot half and sources: every grain's
/// temperature and flux, and the thermal energy, as LIGGGHTS computes them,
/// with each of the three contact areas.
#[test]
fn moving_bed_follows_liggghts() {
    // the last: LIGGGHTS stops reading the fix's keywords at a word it
    // does not know (a second temperature, in a deck of the corpus) and
    // ignores the rest, so that deck runs at 300 K with overlap areas
    for area in ["", " contact_area projection", " contact_area constant 2e-8", " 400. contact_area projection"] {
        moving_bed(area);
    }
}

fn moving_bed(area: &str) {
    let deck = format!(
        "{HEAD}lattice sc 0.001\ncreate_atoms 1 box\nregion two block 0 0.002 0 0.002 0 0.004 units box\nset region two type 2\n\
set type 1 diameter 0.00108 density 2500\nset type 2 diameter 0.00102 density 4000\n{MATERIALS}\
region adia block 0.0025 0.004 0.0025 0.004 0 0.0015 units box\ngroup adia region adia\ngroup cond subtract all adia\n\
fix heattransfer cond heat/gran initial_temperature 300.{area}\nrun 0\n\
region hot block 0 0.0015 0 0.004 0 0.004 units box\nset region hot property/atom Temp 800.\n\
region src block 0 0.004 0 0.004 0.0025 0.004 units box\nset region src property/atom heatSource 0.01\n\
fix 1 all nve/sphere\ntimestep 1e-7\nthermo_style custom step ke f_heattransfer\nthermo_modify format float %.15g\nthermo 500\n\
dump d all custom 500 dump.t id x y z f_Temp[0] f_heatFlux[0] f_directionalHeatFlux[1] f_directionalHeatFlux[2] f_directionalHeatFlux[3]\n\
dump_modify d sort id format \"%d %.15g %.15g %.15g %.15g %.15g %.15g %.15g %.15g\"\nrun 3000\n"
    );
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &deck)]);
    let (theirs, ours) = (common::dump_frames(&b.theirs.path().join("dump.t")), common::dump_frames(&b.ours.path().join("dump.t")));
    assert_eq!(theirs.keys().collect::<Vec<_>>(), ours.keys().collect::<Vec<_>>());
    let mut moved = 0.0f64;
    for (step, rows) in &theirs {
        for (id, t) in rows {
            let o = &ours[step][id];
            moved = moved.max((t[0] - (((id - 1) % 4) as f64) * 0.001).abs());
            // positions, then temperature, flux and the directional flux
            for (k, scale) in [(0, 1e-3), (1, 1e-3), (2, 1e-3), (3, 800.0), (4, 1.0), (5, 1e-3), (6, 1e-3), (7, 1e-3)] {
                assert!((t[k] - o[k]).abs() <= 1e-9 * scale, "{area}: step {step} atom {id} column {k}: liggghts {} demx {}", t[k], o[k]);
            }
        }
    }
    assert!(moved > 1e-7, "the bed did not move ({moved}): the deck is not the scene meant");
    // the hot half has warmed the cold one
    let last = theirs.values().last().unwrap();
    assert!(last.values().any(|t| t[3] > 300.5 && t[0] > 0.0025), "no heat reached the cold half");
    let (lt, dt) = (common::thermo_runs(&b.theirs_out), common::thermo_runs(&b.ours_out));
    let (lt, dt) = (lt.last().unwrap(), dt.last().unwrap());
    assert_eq!(lt.len(), dt.len());
    for (l, d) in lt.iter().zip(dt) {
        let (el, ed): (f64, f64) = (l[2].parse().unwrap(), d[2].parse().unwrap());
        assert!((el - ed).abs() <= 1e-12 * el, "step {}: f_heattransfer liggghts {el} demx {ed}", l[0]);
    }
}

/// Missing materials, unknown properties and wrong columns name their line.
#[test]
fn bad_heat_commands_are_deck_errors() {
    let base = format!("{HEAD}lattice sc 0.001\ncreate_atoms 1 box\nset group all diameter 0.00105 density 2500\n");
    let line = |deck: &str| deck.lines().count();
    // no thermalCapacity
    let deck = format!("{base}fix ftco all property/global thermalConductivity peratomtype 100. 20.\nfix h all heat/gran initial_temperature 300.\n");
    let err = common::deck_error(&deck);
    assert!(err.contains(&format!("in.deck:{}:", line(&deck))) && err.contains("thermalCapacity"), "{err}");
    // a property no fix defines
    let deck = format!("{base}set group all property/atom Temp 800.\n");
    let err = common::deck_error(&deck);
    assert!(err.contains(&format!("in.deck:{}:", line(&deck))) && err.contains("no per-atom property 'Temp'"), "{err}");
    // Temp has one value per atom: [1] is not a column
    let deck = format!("{base}{MATERIALS}fix h all heat/gran initial_temperature 300.\ndump d all custom 10 d.txt id f_Temp[1]\n");
    let err = common::deck_error(&deck);
    assert!(err.contains(&format!("in.deck:{}:", line(&deck))) && err.contains("f_Temp[0]"), "{err}");
    // area_correction needs youngsModulusOriginal: not run yet (exit 3)
    let deck = format!("{base}{MATERIALS}fix h all heat/gran initial_temperature 300. area_correction yes\n");
    let (code, err) = common::demx_deck(&deck, &[]);
    assert!(code == Some(3) && err.contains("area_correction"), "{err}");
}
