//! `demx tradeoff` and the `demx run --dt-fraction/--youngs-scale` overrides
//! it varies, on the two-sphere head-on template (d = 2 mm, rho = 2500,
//! Y = 1e7, nu = 0.3, e = 0.5, +-1 m/s): the time step the override sets is
//! the Hertz time computed here independently, the restitution converges to
//! the requested e as the step shrinks, and softening by S stretches the
//! collision by S^(2/5).

use std::path::{Path, PathBuf};
use std::process::Command;

fn deck() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("templates/two_sphere/in.headon.liggghts")
}

/// LIGGGHTS check/timestep/gran Hertz time of two equal spheres of the
/// template at the fastest particle speed (1 m/s):
/// 2.87 (m*^2 / (R* E*^2 v))^(1/5), E* = Y / (2 (1 - nu^2)).
fn hertz_time(y: f64) -> f64 {
    let (r, rho, nu, v) = (1e-3_f64, 2500.0, 0.3, 1.0);
    let m = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * rho;
    let (m_eff, r_eff) = (0.5 * m, 0.5 * r);
    let e_eff = y / (2.0 * (1.0 - nu * nu));
    2.87 * (m_eff * m_eff / (r_eff * e_eff * e_eff * v)).powf(0.2)
}

fn tradeoff(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).arg("tradeoff").args(args).output().expect("run demx tradeoff");
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn restitution_error_shrinks_with_the_time_step() {
    let d = deck();
    let (code, out, err) =
        tradeoff(&[d.to_str().unwrap(), "--vary", "dt_fraction=0.02,0.05,0.1,0.2", "--metric", "restitution", "--reference", "0.5", "--json"]);
    assert_eq!(code, 0, "{out}\n{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let rows = v["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 4);
    let th = hertz_time(1e7);
    let mut errors = vec![];
    for (row, f) in rows.iter().zip([0.02, 0.05, 0.1, 0.2]) {
        assert_eq!(row["label"], format!("dt_fraction={f}"));
        let dt = row["timestep"].as_f64().expect("timestep");
        assert!((dt / (f * th) - 1.0).abs() < 1e-6, "dt {dt} vs {}", f * th);
        let e = row["mean"].as_f64().expect("mean");
        let error = row["error"].as_f64().unwrap();
        assert!((error - (e - 0.5).abs()).abs() < 1e-12);
        errors.push(error);
    }
    // The error is not monotone in dt step by step: where the first step of
    // the contact falls (the overlap then jumps by up to v dt, 17% of the
    // peak overlap at dt_fraction 0.05) makes it scatter. Its envelope
    // shrinks: the finest step is the most accurate, within 1% of e, and the
    // coarse steps are off by more than 1%.
    assert!(errors[1..].iter().all(|&e| e > errors[0]), "the finest step is not the most accurate: {errors:?}");
    assert!(errors[0] / 0.5 < 0.01, "finest step: e off by {} (> 1%)", errors[0]);
    assert!(errors[1..].iter().cloned().fold(0.0, f64::max) / 0.5 > 0.01, "coarse steps as accurate as the finest: {errors:?}");
    // the reference here is an exact value: no setting is the reference
    assert!(rows.iter().all(|r| r["reference"] == false));
    assert!(v["reference"].as_str().unwrap().contains("0.5"));
}

/// Contact start and end times (s) from a dump: the separation crossing 2r,
/// interpolated linearly between frames.
fn contact_times(dump: &Path, dt: f64) -> (f64, f64) {
    let frames = demx::io::dump::read_all(dump).expect("dump");
    let gap = |f: &demx::io::dump::Frame| {
        let x = f.column("x").unwrap();
        (x[1] - x[0]).abs() - 2e-3
    };
    let mut start = None;
    let mut end = None;
    for w in frames.windows(2) {
        let (g0, g1) = (gap(&w[0]), gap(&w[1]));
        let (t0, t1) = (w[0].timestep as f64 * dt, w[1].timestep as f64 * dt);
        let cross = t0 + (t1 - t0) * g0 / (g0 - g1);
        if g0 > 0.0 && g1 <= 0.0 && start.is_none() {
            start = Some(cross);
        }
        if g0 <= 0.0 && g1 > 0.0 && start.is_some() && end.is_none() {
            end = Some(cross);
        }
    }
    (start.expect("no contact"), end.expect("contact does not end"))
}

fn run_scaled(scale: &str) -> (f64, f64) {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::copy(deck(), tmp.path().join("in.headon")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(tmp.path())
        .args(["run", "--quiet", "--dt-fraction", "0.02", "--youngs-scale", scale, "in.headon"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let log = std::fs::read_to_string(tmp.path().join("log.demx")).unwrap();
    let line = log.lines().find(|l| l.starts_with("demx: --dt-fraction")).expect("override logged");
    let dt: f64 = line.split("timestep ").nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap();
    let (a, b) = contact_times(&tmp.path().join("dump.headon"), dt);
    (dt, b - a)
}

#[test]
fn youngs_scale_stretches_the_collision_as_y_to_the_minus_two_fifths() {
    let (dt1, tc1) = run_scaled("1");
    let (dt10, tc10) = run_scaled("10");
    let ratio = 10f64.powf(0.4);
    // the override's Hertz time uses the scaled modulus
    assert!((dt1 / (0.02 * hertz_time(1e7)) - 1.0).abs() < 1e-6, "{dt1}");
    assert!((dt10 / (0.02 * hertz_time(1e6)) - 1.0).abs() < 1e-6, "{dt10}");
    // (the log gives dt to 7 significant digits)
    assert!((dt10 / dt1 / ratio - 1.0).abs() < 1e-6, "dt ratio {}", dt10 / dt1);
    // the collision itself: t_c ~ Y^(-2/5) (same e: LIGGGHTS damping scales with the stiffness)
    assert!((tc10 / tc1 / ratio - 1.0).abs() < 0.01, "contact {tc1} s -> {tc10} s, ratio {} vs {ratio}", tc10 / tc1);
    // and it lasts about the Hertz time at the relative speed 2 m/s (damped: within 10%)
    let th2 = hertz_time(1e7) * 2f64.powf(-0.2);
    assert!((tc1 / th2 - 1.0).abs() < 0.1, "contact {tc1} s vs Hertz {th2} s");
}

#[test]
fn bad_vary_name_exits_2_with_the_valid_names() {
    let d = deck();
    let (code, out, err) = tradeoff(&[d.to_str().unwrap(), "--vary", "dtfrac=0.1,0.2", "--metric", "restitution"]);
    assert_eq!(code, 2, "{out}\n{err}");
    for n in ["dt_fraction", "youngs_scale", "var:NAME"] {
        assert!(err.contains(n), "missing '{n}' in: {err}");
    }
    let (code, _, err) = tradeoff(&[d.to_str().unwrap(), "--vary", "dt_fraction=0.1", "--metric", "speed"]);
    assert_eq!(code, 2);
    assert!(err.contains("restitution") && err.contains("custom:NAME"), "{err}");
}

#[test]
fn run_rejects_a_nonpositive_override() {
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).args(["run", "--dt-fraction", "0", deck().to_str().unwrap()]).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
}
