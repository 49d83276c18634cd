//! `demx sweep` (issue 4): the paper's fits on synthetic data generated from
//! known parameters, argument errors, a tiny sweep end to end with resume;
//! and the `insert_every once` regression (a second `run` after a one-shot
//! insert/pack, in `demx run` and `demx check`).

use demx::analysis::sweep::{atan_model, fit_all, fit_atan, fit_power, RunResult, G_EARTH};
use std::path::Path;
use std::process::Command;

fn demx(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(args).output().expect("run demx")
}

const MU: f64 = 0.447;
const DE: f64 = 87e-6;
const SIZES: [f64; 7] = [30e-6, 50e-6, 70e-6, 100e-6, 200e-6, 500e-6, 1000e-6];

#[test]
fn eq1_fit_recovers_exact_parameters() {
    let x: Vec<f64> = SIZES.iter().map(|d| 1.0 / d).collect();
    let t: Vec<f64> = SIZES.iter().map(|d| (MU * (1.0 + DE / d)).atan()).collect();
    let f = fit_atan(&x, &t, None).unwrap();
    assert!((f.mu - MU).abs() < 1e-9 * MU, "mu {}", f.mu);
    assert!((f.c - DE).abs() < 1e-9 * DE, "D {}", f.c);
    assert!(f.r2 > 1.0 - 1e-12);
}

#[test]
fn eq1_fit_with_noise_brackets_the_truth() {
    // alternating +-0.5 degree errors: the fit moves, the truth stays within 3 SE
    let x: Vec<f64> = SIZES.iter().map(|d| 1.0 / d).collect();
    let t: Vec<f64> =
        SIZES.iter().enumerate().map(|(i, d)| (MU * (1.0 + DE / d)).atan() + if i % 2 == 0 { 0.5f64 } else { -0.5 }.to_radians()).collect();
    let f = fit_atan(&x, &t, None).unwrap();
    assert!(f.mu_se > 0.0 && f.c_se > 0.0);
    assert!((f.mu - MU).abs() < 3.0 * f.mu_se, "mu {} +- {}", f.mu, f.mu_se);
    assert!((f.c - DE).abs() < 3.0 * f.c_se, "D {} +- {}", f.c, f.c_se);
    assert!((f.mu - MU).abs() > 1e-6, "noise must move the fit");
}

#[test]
fn fixed_mu_fit_finds_d() {
    // the paper's Fig. 3A fits: mu fixed to 0.447, D free; g = 0.06 -> D = D_E / sqrt(0.06)
    let d_true = DE / 0.06f64.sqrt();
    let x: Vec<f64> = SIZES.iter().map(|d| 1.0 / d).collect();
    let t: Vec<f64> = x.iter().map(|xi| atan_model(MU, d_true, *xi)).collect();
    let f = fit_atan(&x[..2], &t[..2], Some(MU)).unwrap();
    assert_eq!(f.mu, MU);
    assert!((f.c - d_true).abs() < 1e-9 * d_true);
}

#[test]
fn eq2_eq3_eq4_fits_over_g_levels() {
    let (gamma, rho) = (0.05, 2500.0);
    let mut runs = vec![];
    for g in [0.06, 1.0, 10.0] {
        for d in SIZES {
            let theta = (MU * (1.0 + DE / (d * f64::sqrt(g)))).atan().to_degrees();
            runs.push(RunResult { d, g, seed: 1, theta, sd: 0.0, n: 100, y: String::new(), wall: 0.0 });
        }
    }
    let f = fit_all(&runs, gamma, rho);
    let e3 = f.eq3.unwrap();
    assert!((e3.mu - MU).abs() < 1e-8 && (e3.c - DE).abs() < 1e-8 * DE, "{e3:?}");
    assert_eq!(f.eq1.len(), 3);
    for (g, e) in &f.eq1 {
        assert!((e.c - DE / g.sqrt()).abs() < 1e-7 * DE / g.sqrt(), "g {g}: {e:?}");
    }
    // Eq. 2: D = D_E / g^0.5 exactly
    let (d0, _, alpha, _) = f.power.unwrap();
    assert!((alpha - 0.5).abs() < 1e-7 && (d0 - DE).abs() < 1e-7 * DE);
    // Eq. 4 is Eq. 3 with beta sqrt(Bo) = D_E / (d sqrt(g~)), Bo = 12 gamma / (d^2 g rho): beta = D_E / sqrt(12 gamma / (rho g_E))
    let beta = DE / (12.0 * gamma / (rho * G_EARTH)).sqrt();
    let e4 = f.eq4.unwrap();
    assert!((e4.c - beta).abs() < 1e-7 * beta && (e4.mu - MU).abs() < 1e-8, "{e4:?} vs beta {beta}");
}

#[test]
fn power_law_fit_of_d_over_g() {
    // the paper's D_0 = 76 um, alpha = 0.454
    let g = [0.06, 0.38, 1.0, 10.0, 100.0];
    let d: Vec<f64> = g.iter().map(|x| 76e-6 / f64::powf(*x, 0.454)).collect();
    let (d0, _, a, _) = fit_power(&g, &d).unwrap();
    assert!((d0 - 76e-6).abs() < 1e-12 && (a - 0.454).abs() < 1e-12);
    assert!(fit_power(&[1.0], &[1e-4]).is_none());
}

#[test]
fn argument_errors_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.x"), "print hi\n").unwrap();
    for args in [
        vec!["sweep", "in.x", "--g", "1"],
        vec!["sweep", "in.x", "--d", "1e-3"],
        vec!["sweep", "in.x", "--d", "1e-3,-2e-3", "--g", "1"],
        vec!["sweep", "in.x", "--d", "1e-3", "--g", "0"],
        vec!["sweep", "in.x", "--d", "1e-3", "--g", "1", "--seeds", "0"],
        vec!["sweep", "in.x", "--d", "1e-3", "--g", "1", "--jobs", "0"],
        vec!["sweep", "in.x", "--d", "1e-3", "--g", "1", "-var", "d", "1e-3"],
        vec!["sweep", "in.x", "--d", "1e-3", "--g", "1", "-var", "Y"],
        vec!["sweep", "missing.deck", "--d", "1e-3", "--g", "1"],
        vec!["sweep", "in.x", "--d", "abc", "--g", "1"],
    ] {
        let out = demx(dir.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    }
    assert!(!dir.path().join("sweep").exists(), "no runs on bad arguments");
}

/// A tiny pour: 40 spheres dropped from a column onto a plate; -var d/g/seed.
const TINY: &str = "variable d index 1e-3\nvariable g index 1\nvariable seed index 15485863\nvariable N index 40\n\
variable r equal 0.5*${d}\nvariable gacc equal 9.81*${g}\nvariable L equal 8*${d}\nvariable H equal 12*${d}\n\
variable c equal 1.5*${d}\nvariable dt equal 1e-3*sqrt(${d}/${gacc})\nvariable steps equal ceil(10*sqrt(${d}/${gacc})/${dt})\n\
atom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\n\
region box block -${L} ${L} -${L} ${L} 0 ${H} units box\ncreate_box 1 box\nneighbor ${r} bin\nneigh_modify delay 0\n\
fix m1 all property/global youngsModulus peratomtype 5e6\nfix m2 all property/global poissonsRatio peratomtype 0.24\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.2\nfix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\ntimestep ${dt}\n\
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\nfix gravi all gravity ${gacc} vector 0 0 -1\n\
fix pts all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius constant ${r}\n\
fix pdd all particledistribution/discrete 32452843 1 pts 1.0\n\
region col block -${c} ${c} -${c} ${c} ${d} ${H} units box\n\
fix ins all insert/pack seed ${seed} distributiontemplate pdd insert_every once overlapcheck yes all_in yes vel constant 0 0 0 region col particles_in_region ${N}\n\
fix integr all nve/sphere\nthermo_modify lost ignore norm no\nrun ${steps}\n\
dump dmp all custom 1 dump.heap id type radius x y z\nrun 0\n";

#[test]
fn tiny_sweep_end_to_end_and_resume() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    std::fs::write(p.join("in.tiny"), TINY).unwrap();
    let args = [
        "sweep",
        "in.tiny",
        "--d",
        "1e-3,2e-3",
        "--g",
        "1",
        "--jobs",
        "2",
        "--out",
        "runs",
        "--csv",
        "t.csv",
        "--markdown",
        "t.md",
        "--plot",
        "t.png",
        "-var",
        "N",
        "30",
    ];
    let out = demx(p, &args);
    assert!(out.status.success(), "{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(p.join("t.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], "d,g,seed,theta_deg,sd_deg,n,Y,wall_s");
    assert_eq!(rows.len(), 3, "{csv}");
    // each row's angle and particle count are what `demx repose` measures on that run's dump
    for (row, d) in rows[1..].iter().zip(["1e-3", "2e-3"]) {
        let f: Vec<&str> = row.split(',').collect();
        assert_eq!((f[0], f[1], f[2]), (d, "1", "15485863"), "{row}");
        let dump = p.join("runs").join(format!("d{d}_g1_s15485863")).join("dump.heap");
        let rep = demx(p, &["repose", dump.to_str().unwrap(), "--json"]);
        let v: serde_json::Value = serde_json::from_slice(&rep.stdout).unwrap();
        let theta = v["repose"]["theta"].as_f64().unwrap();
        let n = v["repose"]["particles"].as_u64().unwrap();
        assert!(n > 10 && n <= 30 && f[5] == n.to_string(), "{row} vs {n} particles");
        assert!((f[3].parse::<f64>().unwrap() - theta).abs() < 6e-5, "{row} vs {theta}");
    }
    let md = std::fs::read_to_string(p.join("t.md")).unwrap();
    assert!(md.contains("## Angle of repose sweep") && md.contains("| Eq. 3 (all g) | D_E (µm) |"), "{md}");
    assert!(p.join("runs/fits.csv").exists());
    // plotting is a warning while the backend is missing, never a failure
    // resume: a finished run is reused (its result.json is read, not rerun)
    let res = p.join("runs/d1e-3_g1_s15485863/result.json");
    let mut r: RunResult = serde_json::from_str(&std::fs::read_to_string(&res).unwrap()).unwrap();
    r.theta = 33.25;
    std::fs::write(&res, serde_json::to_string(&r).unwrap()).unwrap();
    std::fs::remove_file(p.join("runs/d1e-3_g1_s15485863/dump.heap")).unwrap();
    let out = demx(p, &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(p.join("t.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().contains(",33.2500,"), "{csv}");
}

/// One-shot insert/pack followed by more runs and a second one-shot fix.
/// LIGGGHTS 3.8 runs it: 20 particles at step 1, 10 more (topping the region
/// up to 30) at step 41, 30 atoms at the end.
const ONCE: &str = "atom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\n\
region domain block -0.01 0.01 -0.01 0.01 0.0 0.02 units box\ncreate_box 1 domain\nneighbor 0.0002 bin\nneigh_modify delay 0\n\
fix m1 all property/global youngsModulus peratomtype 1e7\nfix m2 all property/global poissonsRatio peratomtype 0.24\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.2\nfix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 1e-5\n\
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\nfix gravi all gravity 9.81 vector 0.0 0.0 -1.0\n\
fix pts all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius constant 0.001\n\
fix pdd all particledistribution/discrete 32452843 1 pts 1.0\n\
region col block -0.005 0.005 -0.005 0.005 0.005 0.015 units box\n\
fix ins all insert/pack seed 15485863 distributiontemplate pdd insert_every once overlapcheck yes all_in yes vel constant 0.0 0.0 0.0 region col particles_in_region 20\n\
fix integr all nve/sphere\nthermo_style custom step atoms ke\nthermo 10\nthermo_modify lost ignore norm no\n\
run 20\nprint \"after1 $(atoms)\"\nrun 20\nprint \"after2 $(atoms)\"\nunfix ins\n\
fix ins2 all insert/pack seed 15485863 distributiontemplate pdd insert_every once overlapcheck yes all_in yes vel constant 0.0 0.0 0.0 region col particles_in_region 30\n\
run 20\nrun 20\nprint \"after4 $(atoms)\"\n";

#[test]
fn insert_once_then_more_runs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.once"), ONCE).unwrap();
    let out = demx(dir.path(), &["run", "--log", "none", "in.once"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("after1 20\n") && text.contains("after2 20\n") && text.contains("after4 30\n"), "{text}");
    assert!(text.contains("inserted 10 particle templates") && text.contains("at step 41"), "{text}");
    let out = demx(dir.path(), &["check", "in.once"]);
    assert!(out.status.success(), "check: {}", String::from_utf8_lossy(&out.stderr));
}
