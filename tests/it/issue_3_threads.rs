//! Regression for the engine issue: results must not depend on the number of
//! threads. The settling column (1000 spheres, many simultaneous contacts,
//! wall, periodic images, neighbour rebuilds) run with `--threads 1` and
//! `--threads 2` must write byte-identical dump files, in both dialects.

use std::path::PathBuf;
use std::process::Command;

fn run(deck: &str, threads: usize) -> Vec<u8> {
    let dir = tempfile::tempdir().expect("tempdir");
    let deck = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(deck);
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", "--quiet", "--log", "none", "--threads", &threads.to_string()])
        // `--threads` is not yet wired to a thread pool (Session::threads is
        // unused); RAYON_NUM_THREADS sizes rayon's global pool meanwhile.
        .env("RAYON_NUM_THREADS", threads.to_string())
        .arg(&deck)
        .output()
        .expect("run demx");
    assert!(out.status.success(), "demx failed: {}", String::from_utf8_lossy(&out.stderr));
    std::fs::read(dir.path().join("dump.settle")).expect("dump written")
}

fn same_bytes(deck: &str) {
    let one = run(deck, 1);
    let two = run(deck, 2);
    assert!(one.len() > 100_000, "dump unexpectedly small");
    if one != two {
        let at = one.iter().zip(&two).position(|(a, b)| a != b).unwrap_or(one.len().min(two.len()));
        let line = one[..at].iter().filter(|&&c| c == b'\n').count() + 1;
        panic!("{deck}: --threads 1 and --threads 2 dumps differ from line {line}");
    }
}

#[test]
fn settle_liggghts_threads_1_and_2_identical() {
    same_bytes("templates/settle/in.settle.liggghts");
}

#[test]
fn settle_lammps_threads_1_and_2_identical() {
    same_bytes("templates/settle/in.settle.lammps");
}

/// 9,216 spheres: the pair pass splits into five blocks, the integrator and
/// the wall into three chunks, so two threads really share the work.
#[test]
fn bed_of_9216_threads_1_and_2_identical() {
    same_bytes("tests/decks/threads/in.bed9k.lammps");
}
