//! `demx check` writes nothing, anywhere (trust issue, item 2): a deck
//! whose every kind of output would create or cut a file leaves its folder
//! as it was, byte for byte, and passes.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

fn listing(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .map(|e| {
            let body = if e.path().is_dir() { b"<folder>".to_vec() } else { std::fs::read(e.path()).unwrap() };
            (e.file_name().to_string_lossy().into_owned(), body)
        })
        .collect()
}

#[test]
fn check_leaves_every_file_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // the victims: files the deck's outputs name, which a run would cut
    let victim = "precious data\n".repeat(300);
    for f in ["victim.txt", "victim2.txt", "ave.txt", "dump.v", "log.v", "restart.v", "data.v", "appended.txt", "victim3.txt"] {
        std::fs::write(d.join(f), &victim).unwrap();
    }
    let deck = "shell mkdir post\nshell mkdir -p out/deep\nshell rm victim3.txt\nunits si\natom_style sphere\nboundary f f f\nregion box block 0 0.01 0 0.01 0 0.01\ncreate_box 1 box\n\
lattice sc 0.002\nregion fill block 0.001 0.009 0.001 0.009 0.001 0.009 units box\ncreate_atoms 1 region fill\nset type 1 diameter 0.001 density 2500\n\
pair_style gran/hooke 2e5 NULL 50 NULL 0.5 0\npair_coeff * *\n\
fix 1 all nve/sphere\nfix g all gravity 9.81 vector 0 0 -1\ntimestep 1e-5\n\
print \"x\" file victim.txt\nprint \"y\" append appended.txt\n\
fix p all print 10 hi file victim2.txt\ncompute k all ke\nfix av all ave/time 1 1 10 c_k file ave.txt\n\
dump d all custom 10 dump.v id x y z\nlog log.v\nrestart 10 restart.v\nrun 20\n\
write_restart restart.v\nwrite_data data.v\nprint \"new\" file brand_new.txt\nrun 10\n";
    std::fs::write(d.join("in.deck"), deck).unwrap();
    let before = listing(d);
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(d).args(["check", "in.deck"]).output().unwrap();
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    let after = listing(d);
    let changed: Vec<&String> =
        after.keys().filter(|k| before.get(*k) != after.get(*k)).chain(before.keys().filter(|k| !after.contains_key(*k))).collect();
    assert!(changed.is_empty(), "demx check wrote {changed:?}");
    // and the same deck run does write them (the check is not vacuous)
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(d).args(["run", "in.deck", "--quiet", "--log", "none"]).output().unwrap();
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    let ran = listing(d);
    for f in ["victim.txt", "victim2.txt", "ave.txt", "dump.v", "restart.v", "data.v", "appended.txt", "brand_new.txt", "post", "victim3.txt"] {
        assert!(ran.get(f) != before.get(f), "the run did not write {f}");
    }
    assert!(d.join("out/deep").is_dir(), "shell mkdir -p out/deep made no folder");
}

/// `shell` runs the engines' own file operations and nothing else: a
/// command the engine would hand to the system's shell stops with exit 3
/// at its line, before anything runs (and `check` says the same).
#[test]
fn shell_runs_no_system_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (line, col, what) in [("shell touch pwned", 7, "shell touch"), ("shell rm -rf post", 10, "option '-rf'"), ("shell cd post", 7, "shell cd")] {
        std::fs::write(d.join("in.deck"), format!("units si\nshell mkdir post\n{line}\nprint done\n")).unwrap();
        for sub in ["check", "run"] {
            let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(d).args([sub, "in.deck"]).output().unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(3), "{sub} {line}: {err}");
            assert!(err.contains(&format!("in.deck:3:{col}:")) && err.contains(what), "{sub} {line}: {err}");
            assert!(!String::from_utf8_lossy(&o.stdout).contains("done"), "{sub} {line}: the deck went on");
        }
        assert!(!d.join("pwned").exists());
    }
}
