//! Restart and kill safety (engine issue): a resumed run continues bitwise as
//! the uninterrupted one, and a run killed with SIGKILL leaves every complete
//! dump frame readable.

use demx::io::dump::DumpReader;
use std::path::{Path, PathBuf};
use std::process::Command;

fn deck_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/decks/restart")
}

fn demx(dir: &Path, deck: &str, vars: &[(&str, &str)]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_demx"));
    c.current_dir(dir).arg("run").arg(deck_dir().join(deck)).arg("--log").arg("none").arg("--quiet");
    for (k, v) in vars {
        c.arg("-var").arg(k).arg(v);
    }
    c
}

fn last_frame(path: &Path) -> demx::io::dump::Frame {
    let frames: Vec<_> = DumpReader::open(path).expect("open dump").filter_map(|f| f.ok()).collect();
    frames.last().cloned().expect("at least one frame")
}

#[test]
fn resumed_run_is_bitwise_identical_to_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let full = demx(d, "in.column", &[("every", "300"), ("name", "full"), ("restart_every", "300"), ("steps", "600")]).status().unwrap();
    assert!(full.success());
    assert!(d.join("restart.300").exists(), "restart file written at step 300");
    let resumed = demx(d, "in.resume", &[("file", "restart.300"), ("every", "300"), ("name", "resumed"), ("steps", "600")]).status().unwrap();
    assert!(resumed.success());
    let a = last_frame(&d.join("dump.full"));
    let b = last_frame(&d.join("dump.resumed"));
    assert_eq!(a.timestep, 600);
    assert_eq!(b.timestep, 600);
    // match by id: the values must be identical to the last bit
    for row in 0..a.natoms {
        let id = a.get(row, a.col("id").unwrap()).unwrap() as u64;
        let rb = b.row_of_id(id).expect("same ids");
        assert_eq!(a.row(row).unwrap(), b.row(rb).unwrap(), "particle {id} differs after resume");
    }
    // and the particles did move and collide (the test can fail)
    let z = a.column("vz").unwrap();
    assert!(z.iter().any(|v| v.abs() > 1e-3));
}

#[cfg(unix)]
#[test]
fn killed_run_leaves_complete_frames_and_resumes_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // a long run, killed once it has written a few frames and restarts
    let mut child = demx(d, "in.column", &[("every", "100"), ("name", "killed"), ("restart_every", "200"), ("steps", "1000000")]).spawn().unwrap();
    let dump = d.join("dump.killed");
    let t0 = std::time::Instant::now();
    loop {
        std::thread::sleep(std::time::Duration::from_millis(20));
        let frames = DumpReader::open(&dump).map(|r| r.filter_map(|f| f.ok()).count()).unwrap_or(0);
        if frames >= 5 || t0.elapsed().as_secs() > 120 {
            break;
        }
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let frames: Vec<_> = DumpReader::open(&dump).unwrap().collect();
    let complete: Vec<_> = frames.iter().filter_map(|f| f.as_ref().ok()).collect();
    assert!(complete.len() >= 5, "complete frames readable after SIGKILL: {}", complete.len());
    for (k, f) in complete.iter().enumerate() {
        assert_eq!(f.natoms, complete[0].natoms);
        assert_eq!(f.timestep, 100 * k as u64, "frames in order, none missing");
    }
    // the newest restart written before the kill
    let mut restarts: Vec<i64> =
        std::fs::read_dir(d).unwrap().filter_map(|e| e.ok()?.file_name().to_str()?.strip_prefix("restart.")?.parse().ok()).collect();
    restarts.sort();
    let last = *restarts.last().expect("a restart file was written before the kill");
    assert!(last >= 200 && last % 200 == 0, "restart step {last}");
    let end = (last + 400).to_string();
    let file = format!("restart.{last}");
    assert!(demx(d, "in.resume", &[("file", &file), ("every", "100"), ("name", "cont"), ("steps", &end)]).status().unwrap().success());
    // reference: the same deck uninterrupted to the same step
    assert!(demx(d, "in.column", &[("every", "100"), ("name", "ref"), ("restart_every", "100000000"), ("steps", &end)]).status().unwrap().success());
    let a = last_frame(&d.join("dump.ref"));
    let b = last_frame(&d.join("dump.cont"));
    assert_eq!(a.timestep, (last + 400) as u64);
    assert_eq!(b.timestep, (last + 400) as u64);
    for row in 0..a.natoms {
        let id = a.get(row, 0).unwrap() as u64;
        assert_eq!(a.row(row).unwrap(), b.row(b.row_of_id(id).unwrap()).unwrap(), "particle {id}");
    }
}
