//! A reader that stops early (`demx run in.x | head`) ends demx the way it
//! ends other Unix tools: by SIGPIPE, never by a failed print and a panic.

use std::io::Read;
use std::process::{Command, Stdio};

#[cfg(unix)]
#[test]
fn closed_stdout_ends_demx_without_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let deck = dir.path().join("in.print");
    std::fs::write(&deck, "variable i loop 1000000\nlabel l\nprint \"line $i of many\"\nnext i\njump SELF l\n").unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", "in.print", "--log", "none"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = child.stdout.take().unwrap();
    let mut head = [0u8; 64];
    out.read_exact(&mut head).unwrap();
    assert!(String::from_utf8_lossy(&head).contains("line 1 of many"));
    drop(out); // the reader is gone
    let done = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(!err.contains("panicked"), "demx panicked on a closed pipe:\n{err}");
    assert_eq!(done.status.signal(), Some(13), "ended by SIGPIPE: {:?}\n{err}", done.status);
}
