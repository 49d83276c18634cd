//! `demx run --checkpoint DIR`: a run stopped at checkpoints (asked to
//! after K of them, or by SIGTERM) and continued by the same command, again
//! and again, writes exactly the files the uninterrupted run writes.
//!
//! The heap template is the campaign's deck: a script of label/jump loops
//! whose chunks insert (insert/pack with a shared particle distribution),
//! delete, group and measure, over a primitive floor with shear and rolling
//! history; the paper model adds van der Waals cohesion.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A short heap: few grains, soft, short relaxation (seconds of work).
fn heap_vars(model: &str) -> Vec<String> {
    let n = if model == "paper" { "80" } else { "150" };
    let v = [("d", "1e-3"), ("g", "1"), ("Y", "1e7"), ("N", n), ("model", model), ("relax", "4"), ("seed", "15485863")];
    v.iter().flat_map(|(k, x)| ["-var".to_string(), k.to_string(), x.to_string()]).collect()
}

fn demx(dir: &Path, deck: &Path, vars: &[String], extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir)
        .arg("run")
        .arg(deck)
        .args(vars)
        .args(["--quiet"])
        .args(extra)
        .output()
        .expect("run demx")
}

fn said(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Runs `deck` uninterrupted in one folder and in stops of `k` checkpoints
/// in another, resuming until it finishes; returns both folders and the
/// number of stops.
fn both(deck: &Path, vars: &[String], k: u32) -> (tempfile::TempDir, tempfile::TempDir, usize) {
    let a = tempfile::tempdir().unwrap();
    let o = demx(a.path(), deck, vars, &[]);
    assert!(o.status.success(), "uninterrupted run: {}", said(&o));
    let b = tempfile::tempdir().unwrap();
    let k = k.to_string();
    let mut stops = 0;
    loop {
        let o = demx(b.path(), deck, vars, &["--checkpoint", "ckpt", "--checkpoint-stop-after", &k]);
        match o.status.code() {
            Some(0) => break,
            Some(75) => {
                stops += 1;
                assert!(b.path().join("ckpt/checkpoint.json.gz").exists(), "a stop leaves its checkpoint");
                assert!(stops < 200, "the run does not finish");
            }
            _ => panic!("checkpointed run: {}", said(&o)),
        }
    }
    assert!(!b.path().join("ckpt/checkpoint.json.gz").exists(), "a finished run removes its checkpoint");
    (a, b, stops)
}

fn same_file(a: &Path, b: &Path, name: &str) {
    let x = std::fs::read(a.join(name)).unwrap_or_else(|e| panic!("{name} of the uninterrupted run: {e}"));
    let y = std::fs::read(b.join(name)).unwrap_or_else(|e| panic!("{name} of the resumed run: {e}"));
    assert!(!x.is_empty());
    assert!(x == y, "{name} differs between the uninterrupted and the resumed run");
}

#[test]
fn heap_stock_resumed_at_every_third_run_is_bitwise_the_uninterrupted_heap() {
    let deck = root().join("templates/heap/in.heap");
    let (a, b, stops) = both(&deck, &heap_vars("stock"), 3);
    assert!(stops >= 3, "stopped {stops} times");
    same_file(a.path(), b.path(), "dump.heap");
    // the heap is a heap: grains were poured and rest on the plate
    let dump = std::fs::read_to_string(a.path().join("dump.heap")).unwrap();
    let n: usize = dump.lines().nth(3).unwrap().trim().parse().unwrap();
    assert!(n >= 100, "{n} grains in the heap");
}

#[test]
fn heap_paper_model_resumed_at_every_run_is_bitwise_the_uninterrupted_heap() {
    // cohesion, the paper's tangential and rolling laws with history, on the floor too
    let deck = root().join("templates/heap/in.heap");
    let (a, b, stops) = both(&deck, &heap_vars("paper"), 1);
    same_file(a.path(), b.path(), "dump.heap");
    assert!(stops >= 5, "stopped {stops} times");
}

/// A dump open across the checkpoints: its file is cut back and appended to.
#[test]
fn dump_written_across_checkpoints_is_the_uninterrupted_dump() {
    let dir = tempfile::tempdir().unwrap();
    let deck = dir.path().join("in.column");
    let mut text = std::fs::read_to_string(root().join("tests/decks/restart/in.column")).unwrap();
    text = text.replace("restart ${restart_every} restart.*\nrun ${steps}\n", "");
    text.push_str("variable k loop 6\nlabel again\nrun 150\nnext k\njump SELF again\n");
    std::fs::write(&deck, text).unwrap();
    let vars: Vec<String> = ["-var", "every", "100", "-var", "name", "c"].map(String::from).to_vec();
    let (a, b, stops) = both(&deck, &vars, 2);
    assert!(stops >= 2, "stopped {stops} times");
    same_file(a.path(), b.path(), "dump.c");
    let frames = std::fs::read_to_string(a.path().join("dump.c")).unwrap().matches("ITEM: TIMESTEP").count();
    assert!(frames >= 9, "{frames} frames");
}

/// SIGTERM asks a run to stop: it writes a checkpoint at its next run line,
/// exits with 75, and the same command finishes it as if never stopped.
#[cfg(unix)]
#[test]
fn sigterm_stops_at_a_checkpoint_and_the_run_continues_exactly() {
    let deck = root().join("templates/heap/in.heap");
    let vars = heap_vars("stock");
    let a = tempfile::tempdir().unwrap();
    assert!(demx(a.path(), &deck, &vars, &[]).status.success());
    let b = tempfile::tempdir().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(b.path())
        .arg("run")
        .arg(&deck)
        .args(&vars)
        .args(["--checkpoint", "ckpt", "--log", "log.demx"])
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // wait until a few chunks are poured
    let t0 = std::time::Instant::now();
    while !std::fs::read_to_string(b.path().join("log.demx")).unwrap_or_default().contains("heap: chunk 3:") {
        assert!(t0.elapsed().as_secs() < 300, "the run did not reach chunk 3");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    let st = child.wait().unwrap();
    assert_eq!(st.code(), Some(75), "a run stopped by SIGTERM exits 75");
    assert!(b.path().join("ckpt/checkpoint.json.gz").exists());
    let o = demx(b.path(), &deck, &vars, &["--checkpoint", "ckpt", "--log", "log.demx"]);
    assert!(o.status.success(), "{}", said(&o));
    same_file(a.path(), b.path(), "dump.heap");
    let log = std::fs::read_to_string(b.path().join("log.demx")).unwrap();
    assert!(log.contains("demx: resumed from the checkpoint at step"), "the log tells the resume");
}

/// A run that dies after a run line ended (its "Loop time" summary in the
/// log) and before the next checkpoint: the resumed run does that run
/// again, and the log is cut back to the checkpoint, so the summary is there
/// once, as in the uninterrupted run (a Slurm task killed in that window had
/// counted the run twice in the campaign's particle-steps). Here the death
/// is an `include` of a file that is not there yet; it is there for the
/// resume.
#[test]
fn a_run_that_dies_between_checkpoints_logs_each_run_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut text = std::fs::read_to_string(root().join("tests/decks/restart/in.column")).unwrap();
    text = text.replace("restart ${restart_every} restart.*\nrun ${steps}\n", "");
    text.push_str("run 100\nrun 100\ninclude part2.in\nrun 100\n");
    std::fs::write(d.join("in.column"), text).unwrap();
    let vars: Vec<String> = ["-var", "every", "100", "-var", "name", "c"].map(String::from).to_vec();
    let args = ["--checkpoint", "ckpt", "--checkpoint-every", "0", "--log", "log.demx"];
    let o = demx(d, &d.join("in.column"), &vars, &args);
    assert_eq!(o.status.code(), Some(2), "the missing include ends the run: {}", said(&o));
    let died = std::fs::read_to_string(d.join("log.demx")).unwrap();
    assert_eq!(died.matches("Loop time of").count(), 2, "{died}");
    std::fs::write(d.join("part2.in"), "thermo 50\n").unwrap();
    let o = demx(d, &d.join("in.column"), &vars, &args);
    assert!(o.status.success(), "{}", said(&o));
    let log = std::fs::read_to_string(d.join("log.demx")).unwrap();
    assert_eq!(log.matches("Loop time of").count(), 3, "each run's summary once: {log}");
    assert!(log.contains("demx: resumed from the checkpoint at step 100 (the "), "{log}");
    // the dump and the log's thermo lines are the uninterrupted run's
    let a = tempfile::tempdir().unwrap();
    std::fs::copy(d.join("in.column"), a.path().join("in.column")).unwrap();
    std::fs::copy(d.join("part2.in"), a.path().join("part2.in")).unwrap();
    let o = demx(a.path(), &a.path().join("in.column"), &vars, &["--log", "log.demx"]);
    assert!(o.status.success(), "{}", said(&o));
    same_file(a.path(), d, "dump.c");
    let thermo = |t: &str| t.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).map(str::to_string).collect::<Vec<_>>();
    let whole = std::fs::read_to_string(a.path().join("log.demx")).unwrap();
    assert_eq!(thermo(&whole), thermo(&log));
    // the stretches' particle-steps (what a campaign reports, also when the
    // log of a stretch stayed on another machine) add up to the runs' count
    let segs: Vec<serde_json::Value> = serde_json::from_str(&std::fs::read_to_string(d.join("ckpt/segments.json")).unwrap()).unwrap();
    assert_eq!(segs.len(), 2, "{segs:?}");
    let counted: f64 = segs.iter().map(|s| s["particle_steps"].as_f64().expect("each stretch counts")).sum();
    assert_eq!(counted, demx::analysis::campaign::particle_steps(&whole), "{segs:?}");
    assert!(counted > 0.0);
}

/// A fix whose state a checkpoint cannot keep yet: no checkpoint is taken
/// (the log says why, once), and the run goes on to its end.
#[test]
fn a_fix_a_checkpoint_cannot_carry_prevents_checkpoints_not_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let deck = dir.path().join("in.column");
    let mut text = std::fs::read_to_string(root().join("tests/decks/restart/in.column")).unwrap();
    text = text.replace("restart ${restart_every} restart.*\nrun ${steps}\n", "");
    text.push_str("compute k all ke\nfix av all ave/time 10 5 50 c_k file ave.txt\nrun 100\nrun 100\nrun 100\n");
    std::fs::write(&deck, text).unwrap();
    let vars: Vec<String> = ["-var", "every", "100", "-var", "name", "c"].map(String::from).to_vec();
    let o = demx(dir.path(), &deck, &vars, &["--checkpoint", "ckpt", "--checkpoint-stop-after", "1", "--log", "log.demx"]);
    assert!(o.status.success(), "{}", said(&o));
    let log = std::fs::read_to_string(dir.path().join("log.demx")).unwrap();
    assert_eq!(log.matches("no checkpoint at step").count(), 1, "said once: {log}");
    assert!(log.contains("fix av (ave/time)"), "{log}");
    assert!(!dir.path().join("ckpt/checkpoint.json.gz").exists());
    // asked to stop (DIR/STOP) it still stops, at the next run line, without a checkpoint
    std::fs::create_dir_all(dir.path().join("ckpt")).unwrap();
    std::fs::write(dir.path().join("ckpt/STOP"), "").unwrap();
    let o = demx(dir.path(), &deck, &vars, &["--checkpoint", "ckpt", "--log", "log.demx"]);
    assert_eq!(o.status.code(), Some(75), "{}", said(&o));
    let log = std::fs::read_to_string(dir.path().join("log.demx")).unwrap();
    assert!(log.contains("without a new checkpoint (fix av (ave/time)"), "{log}");
    assert!(!dir.path().join("ckpt/checkpoint.json.gz").exists());
}

/// The campaign's packing deck settles in chunks continued without a setup
/// (`run N pre no post no`) so that checkpoints can be taken between them:
/// the same bits as the template's one run.
#[test]
fn packing_in_chunks_is_bitwise_the_one_run_of_the_template() {
    let vars: Vec<String> = [("d", "1e-3"), ("Y", "1e7"), ("H", "12"), ("settle", "5"), ("model", "paper")]
        .iter()
        .flat_map(|(k, x)| ["-var".to_string(), k.to_string(), x.to_string()])
        .collect();
    let a = tempfile::tempdir().unwrap();
    let o = demx(a.path(), &root().join("templates/packing/in.packing"), &vars, &[]);
    assert!(o.status.success(), "{}", said(&o));
    let b = tempfile::tempdir().unwrap();
    let o = demx(b.path(), &root().join("validation/campaign/paper/in.packing"), &vars, &[]);
    assert!(o.status.success(), "{}", said(&o));
    same_file(a.path(), b.path(), "dump.packing");
    let runs = |d: &Path| std::fs::read_to_string(d.join("log.demx")).unwrap().matches("Step ").count();
    assert!(runs(b.path()) >= runs(a.path()) + 2, "the settling ran in chunks: {} runs against {}", runs(b.path()), runs(a.path()));
}

/// `demx campaign`: two heaps, every run stopped at every other checkpoint
/// and the campaign moved to another folder half way (a fresh clone
/// continues from committed checkpoints); each finishes with the last frame
/// and theta_r of its uninterrupted run.
#[test]
fn campaign_resumes_from_its_folder_anywhere_and_matches_uninterrupted_runs() {
    let deck = root().join("templates/heap/in.heap");
    let runs = [("a", "15485863"), ("b", "49979687")];
    let spec = serde_json::json!({
        "deck": deck,
        "vars": { "d": "1e-3", "g": "1", "Y": "1e7", "N": "120", "model": "stock", "relax": "4" },
        "runs": runs.iter().map(|(n, s)| serde_json::json!({ "name": n, "vars": { "seed": s }, "estimate_core_h": 0.01 })).collect::<Vec<_>>(),
    });
    let top = tempfile::tempdir().unwrap();
    let first = top.path().join("first");
    std::fs::create_dir_all(&first).unwrap();
    std::fs::write(first.join("c.json"), serde_json::to_string_pretty(&spec).unwrap()).unwrap();
    let campaign = |dir: &Path, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(["campaign", "c.json"]).args(extra).output().expect("demx campaign")
    };
    let stop = ["--run-arg=--checkpoint-stop-after", "--run-arg=2"];
    // one round of starts in the first folder, then the rest in a copy of it
    let o = campaign(&first, &stop);
    assert!(o.status.success(), "{}", said(&o));
    let ck = first.join("runs/a/ckpt/checkpoint.json.gz");
    assert!(ck.exists(), "run a stopped with a checkpoint: {}", said(&o));
    let second = top.path().join("second");
    std::fs::create_dir_all(second.join("runs")).unwrap();
    std::fs::copy(first.join("c.json"), second.join("c.json")).unwrap();
    for (n, _) in &runs {
        // only what is committed: the checkpoint folder, not work/
        let from = first.join("runs").join(n).join("ckpt");
        if from.exists() {
            let to = second.join("runs").join(n).join("ckpt");
            std::fs::create_dir_all(&to).unwrap();
            for e in std::fs::read_dir(&from).unwrap() {
                let e = e.unwrap();
                std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
            }
        }
    }
    std::fs::remove_dir_all(&first).unwrap();
    // a runner of one run (as a Slurm task is) prints that run's line and the totals
    let o = campaign(&second, &["--only", "b", "--run-arg=--checkpoint-stop-after", "--run-arg=1"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && out.lines().any(|l| l.starts_with("b ")) && !out.lines().any(|l| l.starts_with("a ")), "{}", said(&o));
    assert!(out.contains("pending") || out.contains("resumable"), "{out}");
    let mut rounds = 0;
    loop {
        let st = campaign(&second, &["--status"]);
        if String::from_utf8_lossy(&st.stdout).contains("2 done") {
            break;
        }
        rounds += 1;
        assert!(rounds < 100, "the campaign does not finish: {}", said(&st));
        let o = campaign(&second, &stop);
        assert!(o.status.success(), "{}", said(&o));
    }
    for (n, seed) in &runs {
        let dir = second.join("runs").join(n);
        assert!(!dir.join("ckpt/checkpoint.json.gz").exists(), "a finished run's checkpoint is removed");
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("result.json")).unwrap()).unwrap();
        assert!(r["segments"].as_array().unwrap().len() >= 3, "run {n} ran in several stretches: {r}");
        assert!(r["particle_steps"].as_f64().unwrap() > 0.0);
        // the uninterrupted run
        let u = tempfile::tempdir().unwrap();
        let vars: Vec<String> = [("d", "1e-3"), ("g", "1"), ("Y", "1e7"), ("N", "120"), ("model", "stock"), ("relax", "4"), ("seed", seed)]
            .iter()
            .flat_map(|(k, x)| ["-var".to_string(), k.to_string(), x.to_string()])
            .collect();
        let o = demx(u.path(), &deck, &vars, &["--log", "log.demx"]);
        assert!(o.status.success(), "{}", said(&o));
        // counted by the stretches, though the first folder's logs are gone
        let whole = demx::analysis::campaign::particle_steps(&std::fs::read_to_string(u.path().join("log.demx")).unwrap());
        assert_eq!(r["particle_steps"].as_f64(), Some(whole), "run {n}: particle-steps of the uninterrupted run");
        let full = std::fs::read_to_string(u.path().join("dump.heap")).unwrap();
        let last = &full[full.rfind("ITEM: TIMESTEP").unwrap()..];
        let mut kept = String::new();
        std::io::Read::read_to_string(&mut flate2::read::GzDecoder::new(std::fs::File::open(dir.join("final.dump.gz")).unwrap()), &mut kept).unwrap();
        assert!(kept == last, "run {n}: the kept frame is not the uninterrupted run's last frame");
        let rep = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(u.path()).args(["repose", "dump.heap", "--json"]).output().unwrap();
        let rep: serde_json::Value = serde_json::from_slice(&rep.stdout).unwrap();
        assert_eq!(r["theta_deg"].as_f64(), rep["repose"]["theta"].as_f64(), "run {n}: theta_r as `demx repose` measures the uninterrupted heap");
    }
}

/// `demx campaign --stop` from another shell: the running campaign asks its
/// runs to stop, each stops at its next checkpoint (exit 75 for the
/// campaign), and the next start finishes the run from there.
#[test]
fn campaign_stop_reaches_a_running_campaign_and_it_resumes() {
    let deck = root().join("templates/heap/in.heap");
    let spec = serde_json::json!({
        "deck": deck,
        "vars": { "d": "1e-3", "g": "1", "Y": "1e7", "N": "300", "model": "stock", "relax": "4", "seed": "15485863" },
        "runs": [{ "name": "a", "estimate_core_h": 0.01 }],
    });
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("c.json"), serde_json::to_string_pretty(&spec).unwrap()).unwrap();
    let demx = || {
        let mut c = Command::new(env!("CARGO_BIN_EXE_demx"));
        c.current_dir(d).args(["campaign", "c.json"]);
        c
    };
    let mut runner = demx().stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap();
    // the run has started (its folder holds its log)
    let t0 = std::time::Instant::now();
    while !d.join("runs/a/work/log.demx").exists() {
        assert!(t0.elapsed().as_secs() < 60, "the run did not start");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let o = demx().arg("--stop").output().unwrap();
    assert!(o.status.success(), "{}", said(&o));
    let t1 = std::time::Instant::now();
    let status = loop {
        if let Some(s) = runner.try_wait().unwrap() {
            break s;
        }
        assert!(t1.elapsed().as_secs() < 300, "the campaign did not stop");
        std::thread::sleep(std::time::Duration::from_millis(100));
    };
    let out = runner.wait_with_output().unwrap();
    assert_eq!(status.code(), Some(75), "{}", said(&out));
    assert!(d.join("runs/a/ckpt/checkpoint.json.gz").exists(), "no checkpoint: {}", said(&out));
    assert!(!d.join("STOP").exists() && !d.join("runs/a/ckpt/STOP").exists(), "a stop request is left behind");
    let st = demx().arg("--status").output().unwrap();
    assert!(String::from_utf8_lossy(&st.stdout).contains("resumable"), "{}", said(&st));
    let o = demx().output().unwrap();
    assert!(o.status.success(), "{}", said(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("runs/a/result.json")).unwrap()).unwrap();
    assert_eq!(r["segments"].as_array().unwrap().len(), 2, "two stretches: {r}");
}
