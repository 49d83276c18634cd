//! A block (a sphere that cannot rotate, `fix nve`) on a frictional floor
//! starts sliding at tan(theta) = mu: at 1 degree below the threshold it
//! stays put, at 1 degree above it accelerates at g (sin - mu cos).

use std::process::Command;

fn run(theta: f64) -> (f64, f64) {
    let deck = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/decks/incline/in.incline");
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", deck.to_str().unwrap(), "--log", "none", "-var", "theta", &theta.to_string()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.starts_with("FINAL")).expect("final line");
    let v: Vec<f64> = line.split_whitespace().skip(1).map(|w| w.parse().unwrap()).collect();
    (v[0], v[1])
}

#[test]
fn sliding_starts_at_tan_theta_equal_mu() {
    let mu: f64 = 0.3;
    let threshold = mu.atan().to_degrees(); // 16.70 degrees
    let t = 40000.0 * 2e-6;
    let (x_below, v_below) = run(threshold - 1.0);
    let (x_above, v_above) = run(threshold + 1.0);
    // below: the elastic tangential spring holds it (only the settling creep)
    assert!(x_below.abs() < 1e-5 && v_below.abs() < 1e-4, "below threshold it moved: x {x_below} v {v_below}");
    // above: Coulomb sliding, a = g (sin - mu cos)
    let th = (threshold + 1.0).to_radians();
    let a = 9.81 * (th.sin() - mu * th.cos());
    assert!(v_above > 0.5 * a * t, "above threshold it did not slide: v {v_above} (expected about {})", a * t);
    assert!((v_above - a * t).abs() < 0.1 * a * t, "sliding speed {v_above} vs Coulomb {}", a * t);
    assert!(x_above > 0.0);
}
