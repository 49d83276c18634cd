//! fix ave/time writes the same file as LAMMPS on the same deck.

use std::path::Path;
use std::process::Command;

#[test]
fn ave_time_file_matches_lammps() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/ave_time");
    let dir = tempfile::tempdir().unwrap();
    let st = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", data.join("in.ave").to_str().unwrap(), "--log", "none", "--quiet"])
        .status()
        .unwrap();
    assert!(st.success());
    let ours = std::fs::read_to_string(dir.path().join("ave.txt")).unwrap();
    let stored = std::fs::read_to_string(data.join("ave.lmp")).unwrap();
    assert_eq!(ours, stored);
    // and against a fresh LAMMPS run when the engine is installed
    if Command::new("lmp").arg("-h").output().is_ok() {
        let d2 = tempfile::tempdir().unwrap();
        let ok = Command::new("lmp").current_dir(d2.path()).args(["-in", data.join("in.ave").to_str().unwrap(), "-log", "none"]).output().unwrap();
        assert!(ok.status.success());
        assert_eq!(std::fs::read_to_string(d2.path().join("ave.txt")).unwrap(), ours);
    } else {
        eprintln!("SKIP: lmp not on PATH; compared with the stored output only");
    }
}
