//! `demx saltation`: flux of SI Eq. 8 from a hand-written dump, and the
//! normalisations of SI Eqs. 9-10 against the physics note's numbers.

use demx::analysis::saltation::{q_hat, shields, Settings};
use std::process::Command;

#[test]
fn normalisations_match_the_note() {
    let s = Settings::default();
    // rho_p sqrt((s-1) g d_m^3) = 1.0916 kg/(m s) (note 1.6)
    assert!((q_hat(1.0916, &s) - 1.0).abs() < 1e-4);
    // Theta at u* = 0.3 / 0.4 / 0.5: 0.0212 / 0.0377 / 0.0589 (note 6.2)
    for (u, th) in [(0.3, 0.0212), (0.4, 0.0377), (0.5, 0.0589)] {
        assert!((shields(u, &s) - th).abs() < 1e-4, "{u}: {}", shields(u, &s));
    }
    // threshold u*t = 0.165 m/s <-> Theta_t ~ 0.0064 (SI S2)
    assert!((shields(0.165, &s) - 0.0064).abs() < 1e-4);
}

#[test]
fn flux_from_dump_frames() {
    let dir = tempfile::tempdir().unwrap();
    let frame = |step: u64, v1: f64, v2: f64| {
        format!(
            "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS pp pp ff\n0 0.01\n0 0.002\n0 0.1\n\
             ITEM: ATOMS id type x y z vx vy vz radius\n1 1 0.001 0.001 0.001 {v1} 0 0 1e-4\n2 1 0.002 0.001 0.003 {v2} 0 0 1.2e-4\n3 2 0.002 0.001 0.0 9.0 0 0 1e-4\n"
        )
    };
    let text = frame(0, 0.0, 0.0) + &frame(1000, 1.5, 4.0) + &frame(2000, 2.5, 6.0);
    std::fs::write(dir.path().join("d.dump"), text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["saltation", "--ustar", "0.4", "--dt", "1e-5", "--from", "0.01", "--group-type", "1", "-o", "q.csv", "d.dump"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.path().join("q.csv")).unwrap();
    let m = |r: f64| 2650.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let area = 0.01 * 0.002;
    let q1 = (m(1e-4) * 1.5 + m(1.2e-4) * 4.0) / area;
    let q2 = (m(1e-4) * 2.5 + m(1.2e-4) * 6.0) / area;
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').map(|w| w.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    assert!((rows[1][2] - q1).abs() < 1e-8 * q1 && (rows[2][2] - q2).abs() < 1e-8 * q2);
    let summary = csv.lines().last().unwrap().trim_start_matches("# ");
    let f: Vec<&str> = summary.split(',').collect();
    assert_eq!(f[1], "2", "frames at t >= 0.01 s");
    let mean: f64 = f[2].parse().unwrap();
    assert!((mean - 0.5 * (q1 + q2)).abs() < 1e-8 * mean);
}
