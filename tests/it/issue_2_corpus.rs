//! Foundation issue: `demx check` on every deck of ../shared/decks and of
//! Debian's LIGGGHTS/LAMMPS granular examples, from the deck's own folder.
//! None may panic; each exits 0, 2 or 3, and a failure names file:line:col;
//! at least 90% get through the script-language level.

use std::path::{Path, PathBuf};
use std::process::Command;

fn corpus() -> Vec<PathBuf> {
    let mut out = vec![];
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/decks");
    if let Ok(text) = std::fs::read_to_string(shared.join("MANIFEST.csv")) {
        for line in text.lines().skip(1) {
            if let Some(p) = line.split(',').next() {
                out.push(shared.join(p));
            }
        }
    }
    let globs = [
        "/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public",
        "/usr/share/lammps/examples/pour",
        "/usr/share/lammps/examples/granular",
        "/usr/share/lammps/examples/granregion",
    ];
    for g in globs {
        let Ok(rd) = std::fs::read_dir(g) else { continue };
        let mut entries: Vec<_> = rd.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        entries.sort();
        for e in entries {
            if e.is_dir() {
                if let Ok(sub) = std::fs::read_dir(&e) {
                    let mut s: Vec<_> = sub.filter_map(|x| x.ok()).map(|x| x.path()).filter(|p| is_deck(p)).collect();
                    s.sort();
                    out.extend(s);
                }
            } else if is_deck(&e) {
                out.push(e);
            }
        }
    }
    out
}

fn is_deck(p: &Path) -> bool {
    p.is_file() && p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("in."))
}

fn check(deck: &Path, extra: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(deck.parent().unwrap())
        .arg("check")
        .arg(deck.file_name().unwrap())
        .args(extra)
        .output()
        .expect("run demx");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).to_string())
}

#[test]
fn every_corpus_deck_gets_a_clear_answer_and_most_pass_the_script_level() {
    let decks = corpus();
    if decks.len() < 20 {
        eprintln!("SKIP: deck corpus not found ({} decks)", decks.len());
        return;
    }
    let mut script_ok = 0;
    for d in &decks {
        let (code, err) = check(d, &[]);
        assert!([0, 2, 3].contains(&code), "{}: exit {code}\n{err}", d.display());
        assert!(!err.contains("panicked"), "{}: panic\n{err}", d.display());
        if code != 0 {
            let first = err.lines().next().unwrap_or("");
            // file:line:col: error|unsupported: ...
            let parts: Vec<&str> = first.splitn(4, ':').collect();
            assert!(
                parts.len() == 4 && parts[1].trim().parse::<u32>().is_ok() && parts[2].trim().parse::<u32>().is_ok(),
                "{}: message does not name file:line:col: {first}",
                d.display()
            );
        }
        let (sc, _) = check(d, &["--script-only"]);
        if sc == 0 {
            script_ok += 1;
        }
    }
    let frac = script_ok as f64 / decks.len() as f64;
    assert!(frac >= 0.9, "only {script_ok}/{} decks pass the script-language level", decks.len());
}

#[test]
fn a_bad_deck_points_at_the_word_with_a_hint() {
    let dir = tempfile::tempdir().unwrap();
    let deck = dir.path().join("in.bad");
    std::fs::write(&deck, "units si\natom_style sphere\npair_style gran model hertz tangential histroy\n").unwrap();
    let (code, err) = check(&deck, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.starts_with("in.bad:3:40: error: unknown tangential model 'histroy'"), "{err}");
    assert!(err.contains("hint: did you mean 'history'?"), "{err}");
    assert!(err.contains("^^^^^^^"), "{err}");
}
