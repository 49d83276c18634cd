//! `demx compare A B` on dumps: identity, one particle moved by 0.01 d,
//! different particle sets, missing frames, bad input, globs and folders.
//! The input is the stored LIGGGHTS head-on reference dump
//! (reference/liggghts/headon/dump.gz: two spheres of d = 2 mm, ids 1 and 2,
//! frames every 5 steps from 0 to 400).

use serde_json::Value;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

fn headon_text() -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference/liggghts/headon/dump.gz");
    let mut s = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(p).expect("reference dump")).read_to_string(&mut s).expect("gunzip");
    s
}

/// Apply `f(timestep, line)` to every atom line; it returns the new line (or None to drop it).
fn edit(text: &str, f: impl Fn(u64, &str) -> Option<String>) -> String {
    let mut out = String::new();
    let mut ts = 0;
    let mut prev = "";
    let mut in_atoms = false;
    for l in text.lines() {
        if prev == "ITEM: TIMESTEP" {
            ts = l.trim().parse().unwrap();
        }
        if l.starts_with("ITEM:") {
            in_atoms = l.starts_with("ITEM: ATOMS");
            out.push_str(l);
            out.push('\n');
        } else if in_atoms {
            if let Some(n) = f(ts, l) {
                out.push_str(&n);
                out.push('\n');
            }
        } else {
            out.push_str(l);
            out.push('\n');
        }
        prev = l;
    }
    out
}

fn demx(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).arg("compare").args(args).output().expect("run demx");
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

#[test]
fn a_dump_with_itself_has_zero_deviation() {
    let dir = tempfile::tempdir().unwrap();
    let a = write(dir.path(), "a.dump", &headon_text());
    let (code, out, err) = demx(&[&a, &a, "--json"]);
    assert_eq!(code, 0, "{out}{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let c = &v["comparisons"][0];
    assert_eq!(c["frames"].as_array().unwrap().len(), 81);
    for f in c["frames"].as_array().unwrap() {
        assert_eq!(f["pos_max"].as_f64(), Some(0.0));
        assert_eq!(f["vel_max"].as_f64(), Some(0.0));
        assert_eq!(f["omega_max"].as_f64(), Some(0.0));
        assert_eq!(f["a"]["ke"], f["b"]["ke"]);
    }
    assert!(c["divergence"].is_null());
    // KE per unit density at step 0: two spheres of r = 1 mm at 1 m/s: 2 * 1/2 * 4/3 pi r^3 * 1
    let ke0 = c["frames"][0]["a"]["ke"].as_f64().unwrap();
    let want = 4.0 / 3.0 * std::f64::consts::PI * 1e-9;
    assert!((ke0 - want).abs() < 1e-12 * want, "{ke0} vs {want}");
}

#[test]
fn one_particle_moved_by_a_hundredth_diameter_is_named_with_its_frame() {
    let dir = tempfile::tempdir().unwrap();
    let text = headon_text();
    let a = write(dir.path(), "a.dump", &text);
    // move particle 2 by 0.01 d = 2e-5 m in y from timestep 200 on
    let moved = edit(&text, |ts, l| {
        let mut w: Vec<String> = l.split_whitespace().map(str::to_string).collect();
        if ts >= 200 && w[0] == "2" {
            let y: f64 = w[3].parse().unwrap();
            w[3] = format!("{:.17e}", y + 2e-5);
        }
        Some(w.join(" "))
    });
    let b = write(dir.path(), "b.dump", &moved);
    let (code, out, err) = demx(&[&a, &b]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("FAIL: trajectories differ from timestep 200: particle 2 is off by 1.000e-2 diameters"), "{out}");
    assert!(out.contains("divergence: first frame beyond tolerance at timestep 200 (particle 2"), "{out}");
    let (code, out, _) = demx(&[&a, &b, "--json"]);
    assert_eq!(code, 1);
    let v: Value = serde_json::from_str(&out).unwrap();
    let d = &v["comparisons"][0]["divergence"];
    assert_eq!(d[0].as_u64(), Some(200));
    assert_eq!(d[1].as_u64(), Some(2));
    assert!((d[2].as_f64().unwrap() - 0.01).abs() < 1e-9);
    // frame 200 RMS over two particles: 0.01 / sqrt(2)
    let f = v["comparisons"][0]["frames"].as_array().unwrap().iter().find(|f| f["timestep"] == 200).unwrap().clone();
    assert!((f["pos_rms"].as_f64().unwrap() - 0.01 / 2f64.sqrt()).abs() < 1e-9);
    // a looser tolerance accepts it
    let (code, _, _) = demx(&[&a, &b, "--tol", "0.02"]);
    assert_eq!(code, 0);
}

#[test]
fn different_particle_sets_and_missing_frames_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let text = headon_text();
    let a = write(dir.path(), "a.dump", &text);
    // B: particle 2 renamed 7 (so 2 is only in A, 7 only in B)
    let renamed = edit(&text, |_, l| Some(if let Some(rest) = l.strip_prefix("2 ") { format!("7 {rest}") } else { l.to_string() }));
    let b = write(dir.path(), "b.dump", &renamed);
    let (code, out, err) = demx(&[&a, &b]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("particles only in A: 2 (from step 0)"), "{out}");
    assert!(out.contains("particles only in B: 7 (from step 0)"), "{out}");
    assert!(out.contains("FAIL: particle sets differ: 1 only in A, 1 only in B"), "{out}");
    // B without its last frame (timestep 400)
    let cut = text.rfind("ITEM: TIMESTEP").unwrap();
    let c = write(dir.path(), "c.dump", &text[..cut]);
    let (code, out, _) = demx(&[&a, &c]);
    assert_eq!(code, 1);
    assert!(out.contains("timesteps only in A: [400]"), "{out}");
}

#[test]
fn bad_input_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let a = write(dir.path(), "a.dump", &headon_text());
    let junk = write(dir.path(), "junk", "hello\n");
    assert_eq!(demx(&[&a, "/nonexistent/dump"]).0, 2);
    assert_eq!(demx(&[&a, &junk]).0, 2);
    assert_eq!(demx(&[&a]).0, 2);
    assert_eq!(demx(&[&a, &a, "--tol"]).0, 2);
}

#[test]
fn globs_and_folders() {
    let dir = tempfile::tempdir().unwrap();
    let text = headon_text();
    // split into one file per frame, as `dump ... dump.*.txt` does
    let multi = dir.path().join("multi");
    std::fs::create_dir(&multi).unwrap();
    let mut frames: Vec<&str> = text.split("ITEM: TIMESTEP\n").filter(|s| !s.is_empty()).collect();
    frames.reverse();
    for fr in &frames {
        let ts: u64 = fr.lines().next().unwrap().trim().parse().unwrap();
        std::fs::write(multi.join(format!("dump.{ts}.txt")), format!("ITEM: TIMESTEP\n{fr}")).unwrap();
    }
    let single = dir.path().join("single");
    std::fs::create_dir(&single).unwrap();
    std::fs::write(single.join("dump.headon"), &text).unwrap();
    std::fs::write(single.join("in.deck"), "run 0\n").unwrap();
    let glob = format!("{}/dump.*.txt", multi.display());
    let (code, out, err) = demx(&[&single.to_string_lossy(), &glob]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("frames: 81 in both"), "{out}");
    let (code, out, err) = demx(&[&multi.to_string_lossy(), &single.to_string_lossy(), "--csv", &dir.path().join("o.csv").to_string_lossy()]);
    assert_eq!(code, 0, "{out}{err}");
    let csv = std::fs::read_to_string(dir.path().join("o.csv")).unwrap();
    assert_eq!(csv.lines().count(), 82);
}
