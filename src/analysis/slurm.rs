//! The Slurm backend of `demx campaign` and `demx sweep` (`--slurm`): the
//! unfinished runs of a campaign go to the cluster's own scheduler as one
//! job array, one array task per run, each task running
//! `demx campaign FILE --only RUN` in the campaign's folder.
//!
//! A task checkpoints as the local runner does (`checkpoint_every_s`), and
//! Slurm is asked (`--signal=B:TERM@LEAD`) to tell it `LEAD` seconds before
//! its time limit, so that it stops at its deck's next `run` line with a
//! checkpoint instead of being killed. A task that stopped, hit its limit or
//! lost its node leaves a resumable run; submitting again (`--slurm` once
//! more) continues each from its checkpoint, bit for bit. Runs still queued
//! or running are not submitted twice: every submission is kept in
//! `slurm/jobs.json` beside the campaign file and `squeue` says which of its
//! tasks are alive. The job scripts (`slurm/array-*.sbatch`) and the tasks'
//! output (`slurm/JOB_TASK.out`) are kept there too.
//!
//! The demx executable, the campaign folder and the deck must be reachable
//! at the same paths on the compute nodes (a shared file system), as for
//! any Slurm job.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The options shared by `demx campaign` and `demx sweep`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SlurmOpts {
    /// Submit the unfinished runs to Slurm as one job array (sbatch), one task per run, instead of running them here.
    #[arg(long)]
    pub slurm: bool,
    /// With --slurm: write the job script and print it; submit nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// sbatch --partition.
    #[arg(long)]
    pub partition: Option<String>,
    /// sbatch --account.
    #[arg(long)]
    pub account: Option<String>,
    /// Time limit of each task ([D-]HH:MM:SS as sbatch takes it); default from the runs' estimates: 1.5x the largest remaining estimate plus the checkpoint lead, at least 30 minutes.
    #[arg(long)]
    pub time: Option<String>,
    /// sbatch --mem (per node, e.g. 2G).
    #[arg(long)]
    pub mem: Option<String>,
    /// sbatch --cpus-per-task (each run uses one thread; more only where a site requires it).
    #[arg(long, default_value_t = 1)]
    pub cpus_per_task: usize,
    /// A file of extra `#SBATCH ...` lines for the job script (a site's QOS, constraints, mail).
    #[arg(long)]
    pub sbatch_lines: Option<PathBuf>,
    /// Seconds before a task's time limit at which it is told (SIGTERM) to stop at its next checkpoint.
    #[arg(long, default_value_t = 300)]
    pub checkpoint_lead_s: u64,
}

/// One unfinished run to submit.
pub struct Task {
    /// The run's name (a plain folder name).
    pub name: String,
    /// Core-hours still expected (its estimate less what it has spent).
    pub remaining_h: f64,
}

/// One submission (`slurm/jobs.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Job {
    /// Slurm's job id.
    pub job: String,
    /// The runs, by array index.
    pub runs: Vec<String>,
    /// The job script, relative to the campaign folder.
    pub script: String,
    /// When it was submitted (seconds since the Unix epoch).
    pub submitted_unix: u64,
}

/// The folder of the backend's files inside a campaign folder.
pub fn folder(campaign_dir: &Path) -> PathBuf {
    campaign_dir.join("slurm")
}

/// The submissions recorded in `slurm/jobs.json` (none when it is absent).
pub fn jobs(campaign_dir: &Path) -> Result<Vec<Job>, String> {
    let path = folder(campaign_dir).join("jobs.json");
    match std::fs::read_to_string(&path) {
        Ok(text) => serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(vec![]),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

fn save_jobs(campaign_dir: &Path, jobs: &[Job]) -> Result<(), String> {
    let path = folder(campaign_dir).join("jobs.json");
    let text = serde_json::to_string_pretty(jobs).map_err(|e| e.to_string())?;
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, text + "\n").and_then(|_| std::fs::rename(&tmp, &path)).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The runs of recorded submissions that Slurm still holds, with their task
/// id and state (`12_3 RUNNING`). A job Slurm no longer knows holds nothing.
/// `Err` when squeue cannot be asked at all (no Slurm here).
pub fn alive(jobs: &[Job]) -> Result<BTreeMap<String, String>, String> {
    let mut out = BTreeMap::new();
    for j in jobs {
        let o = std::process::Command::new("squeue")
            .args(["-h", "-r", "-j", &j.job, "-o", "%i %T"])
            .output()
            .map_err(|e| format!("cannot run squeue: {e}"))?;
        if !o.status.success() {
            // "Invalid job id specified": finished and forgotten
            continue;
        }
        for line in String::from_utf8_lossy(&o.stdout).lines() {
            let mut w = line.split_whitespace();
            let (Some(id), Some(st)) = (w.next(), w.next()) else { continue };
            let Some(task) = id.rsplit_once('_').and_then(|(_, t)| t.parse::<usize>().ok()) else { continue };
            if let Some(run) = j.runs.get(task) {
                out.insert(run.clone(), format!("{id} {st}"));
            }
        }
    }
    Ok(out)
}

/// `[D-]HH:MM:SS` for a number of seconds.
pub fn slurm_time(s: u64) -> String {
    let (d, h, m, sec) = (s / 86400, s / 3600 % 24, s / 60 % 60, s % 60);
    if d > 0 {
        format!("{d}-{h:02}:{m:02}:{sec:02}")
    } else {
        format!("{h:02}:{m:02}:{sec:02}")
    }
}

/// A path quoted for bash.
fn quote(p: &Path) -> String {
    format!("'{}'", p.to_string_lossy().replace('\'', r"'\''"))
}

/// The job array script for `tasks` of the campaign `file` (absolute), run
/// by the demx executable `exe` (absolute).
pub fn script(o: &SlurmOpts, file: &Path, exe: &Path, tasks: &[Task]) -> Result<String, String> {
    let dir = file.parent().unwrap_or(Path::new("/"));
    let name = dir.file_name().map_or("campaign".into(), |n| n.to_string_lossy().into_owned());
    let name: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || "_-.".contains(c) { c } else { '_' }).collect();
    let time = match &o.time {
        Some(t) => {
            if t.is_empty() || !t.chars().all(|c| c.is_ascii_digit() || c == ':' || c == '-') {
                return Err(format!("--time '{t}': expected [D-]HH:MM:SS"));
            }
            t.clone()
        }
        None => {
            let worst = tasks.iter().map(|t| t.remaining_h).fold(0.0, f64::max);
            slurm_time(((1.5 * worst * 3600.0) as u64 + o.checkpoint_lead_s).max(1800))
        }
    };
    let mut s = String::from("#!/bin/bash\n");
    s += &format!("# demx campaign {}: one array task per unfinished run; written by `demx ... --slurm`\n", file.display());
    s += &format!("#SBATCH --job-name=demx-{name}\n");
    s += &format!("#SBATCH --array=0-{}\n", tasks.len().saturating_sub(1));
    s += "#SBATCH --ntasks=1\n";
    s += &format!("#SBATCH --cpus-per-task={}\n", o.cpus_per_task.max(1));
    s += &format!("#SBATCH --time={time}\n");
    // the batch shell is demx itself (exec): it gets the signal and has its
    // run checkpoint and stop
    s += &format!("#SBATCH --signal=B:TERM@{}\n", o.checkpoint_lead_s);
    s += &format!("#SBATCH --output={}/%A_%a.out\n", folder(dir).display());
    s += "#SBATCH --open-mode=append\n";
    for (key, v) in [("partition", &o.partition), ("account", &o.account), ("mem", &o.mem)] {
        if let Some(v) = v {
            if v.is_empty() || v.chars().any(|c| c.is_whitespace()) {
                return Err(format!("--{key} '{v}': expected one word"));
            }
            s += &format!("#SBATCH --{key}={v}\n");
        }
    }
    if let Some(f) = &o.sbatch_lines {
        let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
        for (k, line) in text.lines().enumerate() {
            let l = line.trim();
            if l.is_empty() || (l.starts_with('#') && !l.starts_with("#SBATCH")) {
                continue;
            }
            if !l.starts_with("#SBATCH ") {
                return Err(format!("{}:{}:1: error: expected an '#SBATCH ...' line, got '{l}'", f.display(), k + 1));
            }
            s += l;
            s.push('\n');
        }
    }
    s += "set -euo pipefail\n";
    s += &format!("runs=({})\n", tasks.iter().map(|t| t.name.as_str()).collect::<Vec<_>>().join(" "));
    s += &format!("cd {}\n", quote(dir));
    s += &format!("exec {} campaign {} --only \"${{runs[$SLURM_ARRAY_TASK_ID]}}\"\n", quote(exe), quote(file));
    Ok(s)
}

/// Write the script for `tasks` and (unless `--dry-run`) submit it;
/// returns the script's path and the job id (`None` on a dry run), or the
/// exit code and message: 2 for a bad option or `--sbatch-lines` file, 1
/// when Slurm or the file system failed.
pub fn submit(o: &SlurmOpts, file: &Path, tasks: &[Task]) -> Result<(PathBuf, Option<String>), (u8, String)> {
    let file = file.canonicalize().map_err(|e| (2, format!("{}: {e}", file.display())))?;
    let exe = std::env::current_exe().and_then(|e| e.canonicalize()).map_err(|e| (1, format!("cannot find the demx executable: {e}")))?;
    let text = script(o, &file, &exe, tasks).map_err(|e| (2, e))?;
    record(o, &file, tasks, &text).map_err(|e| (1, e))
}

fn record(o: &SlurmOpts, file: &Path, tasks: &[Task], text: &str) -> Result<(PathBuf, Option<String>), String> {
    let dir = file.parent().unwrap_or(Path::new("/")).to_path_buf();
    let sdir = folder(&dir);
    std::fs::create_dir_all(&sdir).map_err(|e| format!("cannot create {}: {e}", sdir.display()))?;
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let mut path = sdir.join(format!("array-{now}.sbatch"));
    let mut k = 1;
    while path.exists() {
        path = sdir.join(format!("array-{now}-{k}.sbatch"));
        k += 1;
    }
    std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    if o.dry_run {
        return Ok((path, None));
    }
    let out = std::process::Command::new("sbatch").arg("--parsable").arg(&path).output().map_err(|e| format!("cannot run sbatch: {e}"))?;
    if !out.status.success() {
        return Err(format!("sbatch {} failed: {}", path.display(), String::from_utf8_lossy(&out.stderr).trim()));
    }
    // "ID" or "ID;cluster"
    let stdout = String::from_utf8_lossy(&out.stdout);
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(format!("sbatch printed no job id: '{}'", stdout.trim()));
    }
    let mut all = jobs(&dir)?;
    let rel = path.strip_prefix(&dir).unwrap_or(&path).to_string_lossy().into_owned();
    all.push(Job { job: id.clone(), runs: tasks.iter().map(|t| t.name.clone()).collect(), script: rel, submitted_unix: now });
    save_jobs(&dir, &all)?;
    Ok((path, Some(id)))
}

/// Ask Slurm to stop the campaign's live tasks: running ones get SIGTERM
/// (their runs stop at the next checkpoint), pending ones are cancelled.
pub fn stop(campaign_dir: &Path) -> Result<usize, String> {
    let all = jobs(campaign_dir)?;
    let live = alive(&all)?;
    let mut ids: Vec<&str> = live.values().filter_map(|v| v.split_whitespace().next()).filter_map(|id| id.split('_').next()).collect();
    ids.sort();
    ids.dedup();
    for id in &ids {
        for args in [&["--state=PENDING", id][..], &["--signal=TERM", "--batch", "--state=RUNNING", id][..]] {
            let _ = std::process::Command::new("scancel").args(args).status();
        }
    }
    Ok(live.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_formats_as_sbatch_takes_it() {
        assert_eq!(slurm_time(59), "00:00:59");
        assert_eq!(slurm_time(3600 + 62), "01:01:02");
        assert_eq!(slurm_time(2 * 86400 + 3 * 3600), "2-03:00:00");
    }

    #[test]
    fn script_has_one_task_per_run_and_the_limits() {
        let o = SlurmOpts { partition: Some("short".into()), checkpoint_lead_s: 120, ..Default::default() };
        let tasks = [Task { name: "a".into(), remaining_h: 2.0 }, Task { name: "b_1".into(), remaining_h: 0.5 }];
        let s = script(&o, Path::new("/c/x y/c.json"), Path::new("/bin/demx"), &tasks).unwrap();
        assert!(s.contains("#SBATCH --array=0-1\n"), "{s}");
        // 1.5 x 2 h + 120 s
        assert!(s.contains(&format!("#SBATCH --time={}\n", slurm_time(3 * 3600 + 120))), "{s}");
        assert!(s.contains("#SBATCH --signal=B:TERM@120\n") && s.contains("#SBATCH --partition=short\n"), "{s}");
        assert!(s.contains("runs=(a b_1)\n") && s.contains("cd '/c/x y'\n"), "{s}");
        let bad = SlurmOpts { time: Some("1h; rm".into()), ..Default::default() };
        assert!(script(&bad, Path::new("/c/c.json"), Path::new("/bin/demx"), &tasks).is_err());
    }
}
