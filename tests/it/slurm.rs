//! The Slurm backend (`demx campaign --slurm`, `demx sweep --slurm`)
//! against a real one-node Slurm cluster: `scripts/slurm_local.sh` starts
//! one on this machine (scripts/test.sh does, after installing Debian's
//! slurm-wlm and munge in scripts/setup.sh). The cluster test fails where
//! no cluster answers: it is the one thing here that says the backend works.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn said(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

fn demx(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(args).output().expect("run demx")
}

/// Four short heaps (soft, few grains; the last, the one killed, five
/// times as many, ~4 s in a release build), one checkpoint at every `run`
/// line of the deck, so that a task killed mid-run leaves a checkpoint.
fn heap_campaign(dir: &Path) {
    let runs: Vec<serde_json::Value> = ["15485863", "49979687", "67867967", "86028121"]
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let n = if k == 3 { "1000" } else { "200" };
            serde_json::json!({ "name": format!("r{k}"), "vars": { "seed": s, "N": n }, "estimate_core_h": 0.01 })
        })
        .collect();
    let spec = serde_json::json!({
        "deck": root().join("templates/heap/in.heap"),
        "checkpoint_every_s": 0,
        "vars": { "d": "1e-3", "g": "1", "Y": "1e7", "N": "200", "model": "stock", "relax": "4" },
        "runs": runs,
    });
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("c.json"), serde_json::to_string_pretty(&spec).unwrap()).unwrap();
}

fn final_frame(run: &Path) -> String {
    let mut s = String::new();
    let f = std::fs::File::open(run.join("final.dump.gz")).unwrap_or_else(|e| panic!("{}: {e}", run.display()));
    std::io::Read::read_to_string(&mut flate2::read::GzDecoder::new(f), &mut s).unwrap();
    s
}

fn result(run: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(run.join("result.json")).unwrap_or_else(|e| panic!("{}: {e}", run.display()))).unwrap()
}

/// The array tasks of `job` that Slurm still holds.
fn live_tasks(job: &str) -> Vec<String> {
    let o = Command::new("squeue").args(["-h", "-r", "-j", job, "-o", "%i %T"]).output().expect("squeue");
    String::from_utf8_lossy(&o.stdout).lines().map(str::to_string).collect()
}

fn wait_until(what: &str, secs: u64, mut done: impl FnMut() -> bool) {
    let t0 = Instant::now();
    while !done() {
        assert!(t0.elapsed().as_secs() < secs, "waited {secs} s for {what}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The step of `run`'s checkpoint, from `demx campaign --status`.
fn resumable_step(dir: &Path, run: &str) -> Option<i64> {
    let st = demx(dir, &["campaign", "c.json", "--status"]);
    let text = String::from_utf8_lossy(&st.stdout).to_string();
    let line = text.lines().find(|l| l.starts_with(&format!("{run} ")) && l.contains("resumable"))?;
    line.split("at step ").nth(1)?.split(',').next()?.trim().parse().ok()
}

fn job_id(submitted: &Output) -> String {
    let text = String::from_utf8_lossy(&submitted.stdout);
    let rest = text.split("submitted Slurm job ").nth(1).unwrap_or_else(|| panic!("no job id in: {}", said(submitted)));
    rest.split(':').next().unwrap().to_string()
}

/// A 4-run campaign through Slurm: one array of four tasks, one task killed
/// (SIGKILL, as a lost node) after its run's first checkpoints, the campaign
/// submitted again (only that run goes), and every run ends with the same
/// last frame and theta_r, to the bit, as the local backend's.
#[test]
fn slurm_array_with_a_killed_task_matches_the_local_backend() {
    let up = Command::new("sinfo").args(["-h", "-o", "%t"]).output();
    let states = up.as_ref().map(|o| String::from_utf8_lossy(&o.stdout).to_string()).unwrap_or_default();
    assert!(
        up.as_ref().is_ok_and(|o| o.status.success()) && ["idle", "mix", "alloc"].iter().any(|s| states.contains(s)),
        "no Slurm cluster answers here (sinfo: {states:?}): `bash scripts/slurm_local.sh` starts the one-node cluster this test needs"
    );
    let top = tempfile::tempdir().unwrap();
    let local = top.path().join("local");
    let slurm = top.path().join("slurm");
    heap_campaign(&local);
    heap_campaign(&slurm);

    let o = demx(&slurm, &["campaign", "c.json", "--slurm", "--time", "00:20:00"]);
    assert!(o.status.success(), "{}", said(&o));
    let job = job_id(&o);
    let script =
        std::fs::read_dir(slurm.join("slurm")).unwrap().filter_map(|e| e.ok()).find(|e| e.file_name().to_string_lossy().ends_with(".sbatch"));
    let script = std::fs::read_to_string(script.expect("the job script is kept").path()).unwrap();
    assert!(script.contains("#SBATCH --array=0-3\n") && script.contains("#SBATCH --time=00:20:00\n"), "{script}");
    // submitting again while the tasks are queued or running adds nothing
    let again = demx(&slurm, &["campaign", "c.json", "--slurm"]);
    assert!(String::from_utf8_lossy(&again.stdout).contains("nothing to submit"), "{}", said(&again));

    // the local backend meanwhile (its two jobs share the cores with Slurm's tasks)
    let lo = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(&local)
        .args(["campaign", "c.json", "--jobs", "2"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start the local campaign");

    // the victim: the last task, its runner and its run killed with SIGKILL
    // (as when its node is lost) once the run has checkpointed past its start
    let victim = slurm.join("runs/r3");
    wait_until("run r3 to checkpoint under Slurm", 900, || {
        victim.join("result.json").exists() || resumable_step(&slurm, "r3").is_some_and(|s| s > 1)
    });
    assert!(!victim.join("result.json").exists(), "run r3 finished before it could be killed; the test's heaps are too short");
    let file = slurm.join("c.json").canonicalize().unwrap();
    let ckpt = victim.join("ckpt").canonicalize().unwrap();
    for pattern in [format!("{} --only r3", file.display()), format!("--checkpoint {}", ckpt.display())] {
        let kill = Command::new("pkill").args(["-KILL", "-f", "--", &pattern]).output().unwrap();
        assert!(kill.status.success(), "no process matched {pattern}: {}", said(&kill));
    }
    wait_until("the first array to end", 900, || live_tasks(&job).is_empty());
    assert!(!victim.join("result.json").exists(), "run r3 was killed, not finished");
    let st = demx(&slurm, &["campaign", "c.json", "--status"]);
    assert!(String::from_utf8_lossy(&st.stdout).contains("3 done, 1 resumable"), "{}", said(&st));

    // the next submission continues only r3, from its checkpoint
    let o = demx(&slurm, &["campaign", "c.json", "--slurm", "--time", "00:20:00"]);
    assert!(o.status.success(), "{}", said(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("1 tasks (r3)"), "{}", said(&o));
    let job2 = job_id(&o);
    wait_until("the resubmitted task to end", 900, || live_tasks(&job2).is_empty());
    let st = demx(&slurm, &["campaign", "c.json", "--status"]);
    assert!(String::from_utf8_lossy(&st.stdout).contains("4 done"), "{}", said(&st));

    let lo = lo.wait_with_output().unwrap();
    assert!(lo.status.success(), "the local backend: {}", said(&lo));
    for k in 0..4 {
        let (a, b) = (local.join(format!("runs/r{k}")), slurm.join(format!("runs/r{k}")));
        assert!(final_frame(&a) == final_frame(&b), "run r{k}: the Slurm run's last frame differs from the local one's");
        let (ra, rb) = (result(&a), result(&b));
        assert_eq!(ra["theta_deg"], rb["theta_deg"], "run r{k}");
        assert_eq!(ra["particle_steps"], rb["particle_steps"], "run r{k}");
    }
    let segs = result(&victim)["segments"].as_array().unwrap().len();
    assert!(segs >= 2, "r3 ran in two stretches (killed, then resumed): {segs} segments");
}

/// `demx sweep --slurm --dry-run`: the matrix becomes a campaign in the
/// sweep's folder and one array script with one task per (d, g, seed), the
/// site's options and extra lines in it; nothing is submitted, so it runs
/// where no Slurm is.
#[test]
fn sweep_slurm_dry_run_writes_the_array_script() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("site.txt"), "# our QOS\n#SBATCH --qos=long\n").unwrap();
    let deck = root().join("templates/heap/in.heap");
    let deck = deck.to_str().unwrap();
    let args = [
        "sweep",
        deck,
        "--d",
        "1e-3,5e-4",
        "--g",
        "1,0.5",
        "--out",
        "sw",
        "-var",
        "Y",
        "1e7",
        "--slurm",
        "--dry-run",
        "--partition",
        "short",
        "--mem",
        "2G",
        "--sbatch-lines",
        "site.txt",
    ];
    let o = demx(d, &args);
    assert!(o.status.success(), "{}", said(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for line in [
        "#SBATCH --array=0-3\n",
        "#SBATCH --partition=short\n",
        "#SBATCH --mem=2G\n",
        "#SBATCH --qos=long\n",
        "#SBATCH --cpus-per-task=1\n",
        "#SBATCH --signal=B:TERM@300\n",
    ] {
        assert!(out.contains(line), "missing {line:?} in:\n{out}");
    }
    assert!(out.contains("not submitted"), "{out}");
    assert!(!d.join("sw/slurm/jobs.json").exists(), "a dry run records no job");
    let c: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("sw/campaign.json")).unwrap()).unwrap();
    let runs = c["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 4);
    assert_eq!(c["vars"]["Y"], "1e7");
    // the task list names each run folder of the campaign
    let names: Vec<&str> = runs.iter().map(|r| r["name"].as_str().unwrap()).collect();
    assert!(out.contains(&format!("runs=({})\n", names.join(" "))), "{out}");
    // nothing finished yet: --collect measures nothing and says so
    let o = demx(d, &["sweep", deck, "--d", "1e-3,5e-4", "--g", "1,0.5", "--out", "sw", "-var", "Y", "1e7", "--collect"]);
    assert_eq!(o.status.code(), Some(1), "{}", said(&o));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not finished"), "{}", said(&o));
    // a bad extra line is refused with its place
    std::fs::write(d.join("bad.txt"), "--qos=long\n").unwrap();
    let o = demx(d, &["campaign", "sw/campaign.json", "--slurm", "--dry-run", "--sbatch-lines", "bad.txt"]);
    assert_eq!(o.status.code(), Some(2), "{}", said(&o));
    assert!(String::from_utf8_lossy(&o.stderr).contains("bad.txt:1:1: error"), "{}", said(&o));
}
