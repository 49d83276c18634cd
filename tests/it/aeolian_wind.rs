//! Fast checks of `fix aeolian/wind` (issue 7; physics note
//! /work/shared/physics/aeolian.md section 5): the log profile with no grains,
//! the stress step, momentum bookkeeping between grains and wind, settling
//! speeds, the one-grain trajectory against real LAMMPS (Appendix A), rigid
//! bed grains (fix freeze + neigh_modify exclude), and a tiny two-way run.

use demx::engine::wind::{integrate_profile, WindParams};
use std::path::{Path, PathBuf};
use std::process::Command;

fn demx(dir: &Path, deck: &str) {
    std::fs::write(dir.join("in.deck"), deck).expect("write deck");
    let out =
        Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(["run", "--quiet", "--log", "none", "in.deck"]).output().expect("run demx");
    assert!(out.status.success(), "demx failed: {}\n{deck}", String::from_utf8_lossy(&out.stderr));
}

/// Rows of numbers of a whitespace table, skipping `#` lines.
fn table(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|w| w.parse::<f64>().expect("number")).collect())
        .collect()
}

const P: WindParams = WindParams { ustar: 0.4, kappa: 0.4, z0: 200e-6 / 30.0, rho_f: 1.225 };

#[test]
fn log_profile_without_grains_is_exact() {
    // stretched nodes from the bed up, no grain stress
    let mut zr = vec![0.0];
    let mut dz = 1e-4;
    while *zr.last().unwrap() < 0.4 {
        let z = zr.last().unwrap() + dz;
        zr.push(z);
        if z > 0.01 {
            dz *= 1.1;
        }
    }
    let u = integrate_profile(&zr, &vec![0.0; zr.len() - 1], &P);
    for (z, u) in zr.iter().zip(&u) {
        let exact = 0.4 / 0.4 * ((z + P.z0) / P.z0).ln();
        assert!((u - exact).abs() <= 1e-13 * exact.max(1.0), "z {z}: {u} vs {exact}");
    }
    // note table 2.1 (u* 0.4, z' = 10 cm): 9.6 m/s
    let k = zr.iter().position(|&z| z >= 0.1).unwrap();
    assert!((u[k] - 9.6).abs() < 0.4);
}

#[test]
fn log_profile_through_the_engine_without_grains() {
    let dir = tempfile::tempdir().unwrap();
    let deck = "units si\natom_style sphere\nboundary p p f\nregion box block 0 0.01 0 0.01 0 0.2\ncreate_box 1 box\n\
                fix w all aeolian/wind 0.4 6.666666666666667e-6 1.225 1.5e-5 grid uniform 1e-3 0.1 bed fixed 0.0 file prof.dat\n\
                timestep 1e-5\nrun 2\n";
    demx(dir.path(), deck);
    let rows = table(&dir.path().join("prof.dat"));
    assert_eq!(rows.len(), 3 * 100, "three records of 100 bins");
    for r in &rows {
        let exact = (r[0] + P.z0).ln() - P.z0.ln();
        assert!((r[1] - exact).abs() <= 2e-9 * exact, "z {}: {} vs {exact}", r[0], r[1]);
        assert_eq!(r[2], 0.0);
    }
}

#[test]
fn stress_step_changes_the_slope_below_h_only() {
    let zr: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-4).collect();
    let h = 50e-4;
    let tau = P.rho_f * P.ustar * P.ustar;
    let clean = |a: f64, b: f64| P.ustar / P.kappa * ((b + P.z0) / (a + P.z0)).ln();
    // f = 0.64 below h: slope 0.6 of the clean one, unchanged above
    let tg: Vec<f64> = zr[..200].iter().map(|&z| if z < h - 1e-12 { 0.64 * tau } else { 0.0 }).collect();
    let u = integrate_profile(&zr, &tg, &P);
    for (k, &z) in zr.iter().enumerate() {
        let exact = if z <= h { 0.6 * clean(0.0, z) } else { 0.6 * clean(0.0, h) + clean(h, z) };
        assert!((u[k] - exact).abs() <= 1e-12 * exact.max(1.0), "z {z}: {} vs {exact}", u[k]);
    }
    // f = 1.5 in a band [h, 2h]: the sign-preserving root makes u decrease
    // there with slope sqrt(0.5) of the clean one, clamped at 0
    let tg: Vec<f64> = zr[..200].iter().map(|&z| if z >= h - 1e-12 && z < 2.0 * h - 1e-12 { 1.5 * tau } else { 0.0 }).collect();
    let u = integrate_profile(&zr, &tg, &P);
    for (k, &z) in zr.iter().enumerate() {
        let exact = if z <= h {
            clean(0.0, z)
        } else if z <= 2.0 * h {
            (clean(0.0, h) - 0.5f64.sqrt() * clean(h, z)).max(0.0)
        } else {
            (clean(0.0, h) - 0.5f64.sqrt() * clean(h, 2.0 * h)).max(0.0) + clean(2.0 * h, z)
        };
        assert!((u[k] - exact).abs() <= 1e-12 * exact.max(1.0), "z {z}: {} vs {exact}", u[k]);
    }
    assert!(u[100] < u[50], "wind must slow down where tau_g > tau");
    // f > 1 from the bed: the root is negative, u stays clamped at 0 below h
    let tg: Vec<f64> = zr[..200].iter().map(|&z| if z < h - 1e-12 { 2.0 * tau } else { 0.0 }).collect();
    let u = integrate_profile(&zr, &tg, &P);
    for (k, &z) in zr.iter().enumerate() {
        let exact = if z <= h { 0.0 } else { clean(h, z) };
        assert!((u[k] - exact).abs() <= 1e-12 * exact.max(1.0));
    }
}

#[test]
fn momentum_bookkeeping_grains_and_wind() {
    // Grains at rest above and below a fixed bed height; two-way wind. The
    // drag on each group is read back from fix freeze (the only force), and
    // A tau_g(z_b) must equal the drag on the grains above z_b every step.
    let dir = tempfile::tempdir().unwrap();
    let mut atoms = String::new();
    for (k, z) in [0.0003, 0.0008, 0.0012, 0.0015, 0.0021, 0.0033, 0.0052, 0.009].iter().enumerate() {
        atoms += &format!("create_atoms 1 single {} {} {z} units box\n", 0.0003 + 0.002 * k as f64, 0.0002 + 0.001 * k as f64);
    }
    let deck = format!(
        "units si\natom_style sphere\natom_modify map array\nboundary p p f\nregion box block 0 0.02 0 0.01 0 0.1\ncreate_box 1 box\n{atoms}\
         set type 1 diameter 200e-6 density 2650\n\
         region lo block INF INF INF INF INF 0.001 units box\ngroup down region lo\ngroup up subtract all down\n\
         fix w all aeolian/wind 0.4 6.667e-6 1.225 1.5e-5 grid uniform 1e-4 0.05 bed fixed 0.001\n\
         velocity down set 0.1 0 0.05\nvelocity up set 0.0 0 -0.2\nfix fu up freeze\nfix fd down freeze\n\
         variable lhs equal f_w[2]*1.225*0.16*lx*ly\nvariable up equal f_fu[1]\nvariable tot equal f_w[4]*lx*ly\nvariable dn equal f_fd[1]\n\
         fix p all print 1 \"$(step) $(v_lhs:%.17g) $(v_up:%.17g) $(v_tot:%.17g) $(v_dn:%.17g)\" file book.dat screen no\n\
         timestep 1e-5\nrun 5\n"
    );
    demx(dir.path(), &deck);
    let rows = table(&dir.path().join("book.dat"));
    assert!(rows.len() >= 5);
    for r in &rows {
        assert!(r[2] > 0.0 && r[4] < 0.0, "grains above z_b are pushed, those below (u = 0, moving) are held back: {r:?}");
        assert!((r[1] - r[2]).abs() <= 1e-12 * r[2].abs(), "A tau_g(z_b) {} vs drag above z_b {}", r[1], r[2]);
        assert!((r[3] - (r[2] + r[4])).abs() <= 1e-12 * r[3].abs(), "total drag {} vs {} + {}", r[3], r[2], r[4]);
    }
    // feedback slows the wind near the grains: drag decreases after the first update
    assert!(rows.last().unwrap()[2] < rows[0][2]);
}

#[test]
fn settling_speeds_match_the_note() {
    // d = 160/200/240 um, rho_p 2650, still air (u* = 0), Cheng drag, nu 1.5e-5:
    // 0.87 / 1.15 / 1.41 m/s (physics note 2.2), within 1%.
    let dir = tempfile::tempdir().unwrap();
    let deck = "units si\natom_style sphere\natom_modify map array\nboundary p p f\nregion box block 0 0.01 0 0.01 0 2.0\ncreate_box 1 box\n\
                create_atoms 1 single 0.001 0.005 1.9 units box\ncreate_atoms 1 single 0.004 0.005 1.9 units box\ncreate_atoms 1 single 0.007 0.005 1.9 units box\n\
                set atom 1 diameter 160e-6\nset atom 2 diameter 200e-6\nset atom 3 diameter 240e-6\nset type 1 density 2650\n\
                fix 1 all nve/sphere\nfix 2 all gravity 9.81 vector 0 0 -1\n\
                fix w all aeolian/wind 0.0 6.667e-6 1.225 1.5e-5 feedback no bed fixed 0.0\n\
                variable v1 equal vz[1]\nvariable v2 equal vz[2]\nvariable v3 equal vz[3]\n\
                fix p all print 80000 \"${v1} ${v2} ${v3}\" file vs.dat screen no\ntimestep 1e-5\nrun 80000\n";
    demx(dir.path(), deck);
    let rows = table(&dir.path().join("vs.dat"));
    let last = rows.last().unwrap();
    for (v, want) in last.iter().zip([0.87, 1.15, 1.41]) {
        assert!((-v - want).abs() <= 0.01 * want, "settling speed {} vs {want}", -v);
    }
}

fn lammps_reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/aeolian")
}

fn compare_traj(demx_rows: &[Vec<f64>], ref_rows: &[Vec<f64>], n: usize) {
    assert!(demx_rows.len() >= n && ref_rows.len() >= n, "{} / {} rows", demx_rows.len(), ref_rows.len());
    // scales: x, z ~ 1e-2 m, v ~ 1 m/s; relative 1e-4 of the value or of the scale
    let scale = [1.0, 1e-2, 1e-2, 1.0, 1.0];
    for (a, b) in demx_rows[..n].iter().zip(&ref_rows[..n]) {
        for c in 0..5 {
            let tol = 1e-4 * b[c].abs().max(scale[c] * 1e-2);
            assert!((a[c] - b[c]).abs() <= tol, "t {}: column {c}: demx {} vs LAMMPS {}", b[0], a[c], b[c]);
        }
    }
}

#[test]
fn one_grain_in_a_fixed_wind_matches_lammps() {
    let dir = tempfile::tempdir().unwrap();
    let data = lammps_reference();
    let deck = std::fs::read_to_string(data.join("in.grain.demx")).unwrap();
    demx(dir.path(), &deck);
    let mine = table(&dir.path().join("traj.dat"));
    let reference = table(&data.join("traj.dat"));
    assert_eq!(reference.len(), 28);
    compare_traj(&mine, &reference, 28);
    // note 5.5: apex near t = 0.0575 s at z = 23.48 mm, x - x0 = 0.4020 m at 0.1 s
    assert!((reference[20][1] - 0.001 - 0.4020).abs() < 1e-4);
    // rerun the real engine when it is installed (shortened to 0.05 s to stay fast)
    if Command::new("lmp").arg("-h").output().is_ok() {
        let ldir = tempfile::tempdir().unwrap();
        let ldeck = std::fs::read_to_string(data.join("in.grain")).unwrap().replace("run 135000", "run 50000");
        std::fs::write(ldir.path().join("in.grain"), ldeck).unwrap();
        let out = Command::new("lmp").current_dir(ldir.path()).args(["-in", "in.grain", "-log", "none", "-screen", "none"]).output().unwrap();
        assert!(out.status.success(), "lmp failed: {}", String::from_utf8_lossy(&out.stderr));
        let fresh = table(&ldir.path().join("traj.dat"));
        assert_eq!(fresh.len(), 11);
        compare_traj(&mine, &fresh, 11);
        compare_traj(&fresh, &reference, 11);
    }
}

#[test]
fn rigid_grain_acts_with_infinite_mass() {
    // A 200 um grain hits a frozen grain head-on (gran/hooke/history, gamma_n in
    // 1/s, no gravity). With m_eff = m_i (SI S1.2) the normal motion is
    // delta'' + gamma_n delta' + (k_n/m) delta = 0: restitution
    // e = exp(-gamma_n/2 * pi/omega), omega = sqrt(k_n/m - gamma_n^2/4).
    // Two frozen grains overlap and are excluded from each other.
    let dir = tempfile::tempdir().unwrap();
    let (kn, gn, v0) = (157.0, 2.0e4, 0.5);
    let deck = format!(
        "units si\natom_style sphere\natom_modify map array\nboundary f f f\nregion box block -0.001 0.001 -0.001 0.001 -0.001 0.002\ncreate_box 2 box\n\
         create_atoms 1 single 0 0 0.00025 units box\ncreate_atoms 2 single 0 0 0 units box\ncreate_atoms 2 single 0.00015 0 0 units box\n\
         set type 1 diameter 200e-6\nset type 2 diameter 200e-6\nset type 1 density 2650\nset type 2 density 2650\n\
         group rigid type 2\ngroup sand type 1\n\
         pair_style gran/hooke/history {kn} 52 {gn} {gn} 0.0 0\npair_coeff * *\nneighbor 5e-5 bin\nneigh_modify exclude type 2 2\n\
         fix frz rigid freeze\nfix nve all nve/sphere\nvelocity sand set 0 0 -{v0}\n\
         variable vz1 equal vz[1]\nvariable z2 equal z[2]\nvariable x3 equal x[3]\n\
         timestep 1e-8\nfix p all print 20000 \"$(v_vz1:%.17g) $(v_z2:%.17g) $(v_x3:%.17g)\" file e.dat screen no\nrun 20000\n"
    );
    demx(dir.path(), &deck);
    let rows = table(&dir.path().join("e.dat"));
    let last = rows.last().unwrap();
    let m = 2650.0 * std::f64::consts::PI / 6.0 * 200e-6f64.powi(3);
    let omega = (kn / m - gn * gn / 4.0).sqrt();
    let e = (-gn / 2.0 * std::f64::consts::PI / omega).exp();
    assert!((last[0] / v0 - e).abs() < 2e-3, "restitution {} vs {e} (m_eff = m_i)", last[0] / v0);
    assert_eq!(last[1], 0.0, "frozen grain moved");
    assert_eq!(last[2], 0.00015, "frozen grain moved");
}

#[test]
fn tiny_two_way_run_stays_physical() {
    let dir = tempfile::tempdir().unwrap();
    let deck = "units si\natom_style sphere\natom_modify map array\nboundary p p f\ncomm_modify vel yes\n\
                region box block 0 0.002 0 0.0008 0 0.05\ncreate_box 2 box\nlattice sc 200e-6\n\
                region sheet block 0 0.002 0 0.0008 0 0.0001 units box\nregion bed block 0 0.002 0 0.0008 0.0001 0.0008 units box\n\
                create_atoms 2 region sheet\ncreate_atoms 1 region bed\nset type 1 diameter 199e-6 density 2650\nset type 2 diameter 200e-6 density 2650\n\
                group sand type 1\ngroup rigid type 2\npair_style gran/hooke/history 157 52 5000 5000 0.3 1\npair_coeff * *\n\
                neighbor 5e-5 bin\nneigh_modify exclude type 2 2\nfix frz rigid freeze\nfix nve sand nve/sphere\nfix grav sand gravity 9.81 vector 0 0 -1\n\
                fix wind sand aeolian/wind 0.4 6.667e-6 1.225 1.5e-5 bed fixed 0.0007 grid uniform 1e-4 0.05 relax 0.05 file wind.prof fileevery 500\n\
                variable Q equal f_wind[5]\nvariable tg equal f_wind[2]\n\
                fix p all print 500 \"$(step) $(v_Q:%.17g) $(v_tg:%.17g)\" file q.dat screen no\ntimestep 1e-6\nrun 2000\n";
    demx(dir.path(), deck);
    let q = table(&dir.path().join("q.dat"));
    assert!(q.len() >= 4);
    // step 0 is the raw log wind on a dense top layer (tau_g >> tau); after
    // the relaxed feedback the grain-borne stress at the bed is about tau
    for r in &q {
        assert!(r.iter().all(|v| v.is_finite()), "NaN in {r:?}");
    }
    for r in &q[1..] {
        assert!(r[2] > 0.0 && r[2] < 1.5, "tau_g(z_b)/tau = {} at step {}", r[2], r[0]);
    }
    assert!(q.last().unwrap()[1] > 0.0, "no downwind flux");
    let prof = table(&dir.path().join("wind.prof"));
    assert!(!prof.is_empty());
    for r in &prof {
        assert!(r.iter().all(|v| v.is_finite()) && r[1] >= 0.0, "bad bin {r:?}");
    }
    // the grains take momentum from the wind: u at the top of the grid is below the clean log law
    let top = prof.last().unwrap();
    let clean = (top[0] - 0.0007 + 6.667e-6f64).ln() - 6.667e-6f64.ln();
    assert!(top[1] < clean, "u {} vs clean {clean}", top[1]);
}
