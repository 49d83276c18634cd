//! Stability guards (issue #9 item 2): a run that blows up stops with exit
//! code 1, a message naming the particle, the step, the contact and the likely
//! cause, and leaves the last good state as a data file; `demx_guard off`
//! lets the same run finish; a sane deck runs bitwise as with the guard off.
//! An overlap with a time step that resolves the contacts is a warning (the
//! engines run such decks) unless the deck sets the limit.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Two spheres (d = 2 mm, rho = 2500, Y = 1e7, nu = 0.3) at x = -/+ 6 mm
/// moving towards each other at 1 m/s each, in a fixed box whose lost
/// particles are ignored (so that only the guard can stop the run).
fn headon(dt: f64, extra: &str) -> String {
    format!(
        "atom_style granular
atom_modify map array
boundary f f f
newton off
units si
region reg block -0.02 0.02 -0.02 0.02 -0.02 0.02 units box
create_box 1 reg
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 1.e7
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep {dt}
create_atoms 1 single -0.006 0.0 0.0 units box
create_atoms 1 single 0.006 0.0 0.0 units box
set atom 1*2 diameter 0.002
set atom 1*2 density 2500
group a id 1
group b id 2
velocity a set 1.0 0.0 0.0 units box
velocity b set -1.0 0.0 0.0 units box
fix integr all nve/sphere
thermo 10
thermo_style custom step atoms ke
thermo_modify lost ignore
{extra}
run 200
"
    )
}

/// Hertz collision time 2.87 (m*^2 / (R* E*^2 v))^(1/5) of the head-on pair,
/// with v = 1 m/s (the fastest particle, as `demx check` takes it).
fn hertz_time() -> f64 {
    let (r, rho, y, nu) = (1e-3_f64, 2500.0, 1e7, 0.3);
    let m = 4.0 / 3.0 * PI * r.powi(3) * rho;
    let (m_eff, r_eff, e_eff) = (0.5 * m, 0.5 * r, y / (2.0 * (1.0 - nu * nu)));
    2.87 * (m_eff * m_eff / (r_eff * e_eff * e_eff * 1.0)).powf(0.2)
}

fn run_deck(dir: &Path, name: &str, text: &str, args: &[&str]) -> Output {
    let deck = dir.join(name);
    std::fs::write(&deck, text).expect("write deck");
    Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(args).arg(&deck).output().expect("run demx")
}

fn run(dir: &Path, text: &str) -> Output {
    run_deck(dir, "in.deck", text, &["run", "--quiet", "--log", "none"])
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The step the guard names: "at step N" or "(step N)".
fn stop_step(msg: &str) -> i64 {
    let at = msg.find("at step ").map(|k| k + 8).or_else(|| msg.find("(step ").map(|k| k + 6)).expect("message names the step");
    msg[at..].split(|c: char| !c.is_ascii_digit()).next().and_then(|s| s.parse().ok()).expect("step number")
}

#[test]
fn timestep_twice_the_hertz_time_is_stopped_at_the_first_collision() {
    let dir = tempfile::tempdir().expect("tempdir");
    let th = hertz_time();
    assert!((th - 2.04e-4).abs() < 0.01e-4, "Hertz time {th}");
    let dt = 2.0 * th;
    let out = run(dir.path(), &headon(dt, ""));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(msg.contains("stability guard"), "{msg}");
    assert!(msg.contains("particle 1") || msg.contains("particle 2"), "{msg}");
    assert!(msg.contains("timestep too large for the stiffness"), "{msg}");
    // the gap of 10 mm closes at 2 m/s: first contact after 5 ms
    let first_contact = (5e-3 / dt).ceil() as i64;
    let step = stop_step(&msg);
    assert!(step >= first_contact && step <= first_contact + 20, "stopped at step {step}, contact at {first_contact}: {msg}");
    // dt / t_Hertz = 2 is reported as 200%
    assert!(msg.contains("200% of the Hertz time"), "{msg}");
    // the last good state: a data file demx reads, from a check before the
    // contact, when both spheres still fly freely: |x| = 6 mm - n dt * 1 m/s
    let file = dir.path().join("demx.lastgood.data");
    assert!(msg.contains("demx.lastgood.data"), "{msg}");
    let df = demx::io::data::read_data(&file).expect("last good state readable");
    let n: i64 = df.title.rsplit(' ').next().and_then(|s| s.parse().ok()).expect("timestep in title");
    assert!(n < first_contact && n % 20 == 0, "last good step {n}");
    assert_eq!(df.atoms.len(), 2);
    for a in &df.atoms {
        let expect = 0.006 - n as f64 * dt;
        assert!((a.x[0].abs() - expect).abs() < 1e-12, "atom {} at {:?}, expected |x| = {expect}", a.id, a.x);
        assert!((a.v[0].abs() - 1.0).abs() < 1e-12);
        assert_eq!(a.diameter, 0.002);
    }
}

#[test]
fn guard_off_lets_the_bad_run_finish() {
    let dir = tempfile::tempdir().expect("tempdir");
    let deck = headon(2.0 * hertz_time(), "demx_guard off") + "write_data final.data\n";
    let out = run(dir.path(), &deck);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(!dir.path().join("demx.lastgood.data").exists());
    // the blow-up happened: both spheres left the 4 cm box (lost, ignored)
    let df = demx::io::data::read_data(dir.path().join("final.data")).expect("final state");
    assert_eq!(df.atoms.len(), 0, "{:?}", df.atoms);
}

#[test]
fn small_timestep_collision_passes_and_matches_the_unguarded_run() {
    // dt = 1e-6 is 0.5% of the Hertz time: the collision is resolved
    let dir = tempfile::tempdir().expect("tempdir");
    let dump = "dump d all custom 50 dump.out id x y z vx vy vz\ndump_modify d format \"%d %.17g %.17g %.17g %.17g %.17g %.17g\"";
    // start 0.1 mm apart: contact after 50 steps, lasting about 200
    let deck = |g: &str| {
        headon(1e-6, &format!("{g}\n{dump}"))
            .replace("run 200", "run 1000")
            .replace("single -0.006", "single -0.00105")
            .replace("single 0.006", "single 0.00105")
    };
    let on = run(dir.path(), &deck(""));
    assert_eq!(on.status.code(), Some(0), "{}", stderr(&on));
    let a = std::fs::read(dir.path().join("dump.out")).expect("dump");
    let off = run(dir.path(), &deck("demx_guard off"));
    assert_eq!(off.status.code(), Some(0), "{}", stderr(&off));
    let b = std::fs::read(dir.path().join("dump.out")).expect("dump");
    assert!(a == b && a.len() > 1000, "guard on/off dumps differ");
    // the spheres did collide and rebound (not a test that cannot fail)
    let text = String::from_utf8_lossy(&a);
    let last = text.lines().last().unwrap_or("");
    let vx: f64 = last.split_whitespace().nth(4).and_then(|s| s.parse().ok()).expect("vx");
    assert!(vx.abs() > 0.2 && vx.abs() < 0.9, "after the collision |vx| = e * 1 m/s-ish: {last}");
    // a tight overlap limit does trip on the same run: the checks do run
    let tight = run(dir.path(), &deck("demx_guard overlap 0.001 file none"));
    let msg = stderr(&tight);
    assert_eq!(tight.status.code(), Some(1), "{msg}");
    assert!(msg.contains("particles 1 and 2 overlap"), "{msg}");
    assert!(msg.contains("contacts of particle 1 (radius 0.001; overlaps as fractions of the smaller radius): particle 2 (overlap "), "{msg}");
}

/// An overlapping placement with a time step that resolves the contact:
/// LIGGGHTS and LAMMPS run it, so demx warns (once, naming the pair and the
/// cause) and runs on; a limit the deck sets stops it there.
#[test]
fn overlapping_placement_is_warned_and_stopped_where_the_deck_sets_the_limit() {
    // centres 1.2 R apart: overlap 0.8 R
    let dir = tempfile::tempdir().expect("tempdir");
    let deck = |extra: &str| {
        headon(1e-6, extra)
            .replace("create_atoms 1 single -0.006", "create_atoms 1 single -0.0006")
            .replace("create_atoms 1 single 0.006", "create_atoms 1 single 0.0006")
    };
    let out = run(dir.path(), &deck(""));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{msg}");
    let said = "particles 1 and 2 overlap by 80% of the smaller radius at the start of the run (step 0)";
    assert_eq!(msg.matches("WARNING (demx): stability guard: ").count(), 1, "{msg}");
    assert!(msg.contains(said) && msg.contains("overlapping placement") && msg.contains("not checked again in this run"), "{msg}");
    assert!(!dir.path().join("demx.lastgood.data").exists());
    // the pair was pushed apart: the run went on
    let out = run(dir.path(), &(deck("") + "write_data end.data\n"));
    let df = demx::io::data::read_data(dir.path().join("end.data")).expect("final state");
    assert!((df.atoms[0].x[0] - df.atoms[1].x[0]).abs() > 0.0012, "{:?} {}", df.atoms, stderr(&out));
    let out = run(dir.path(), &deck("demx_guard overlap 0.75"));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(msg.contains(said), "{msg}");
    assert!(msg.contains("overlapping placement"), "{msg}");
    assert!(!msg.contains("timestep too large"), "{msg}");
    let df = demx::io::data::read_data(dir.path().join("demx.lastgood.data")).expect("state written");
    assert_eq!(df.atoms.len(), 2);
}

#[test]
fn nan_from_a_variable_is_caught() {
    let dir = tempfile::tempdir().expect("tempdir");
    // inf - inf = NaN through fix addforce on particle 1 only
    let extra = "variable f equal (1e308*10)-(1e308*10)\nfix af a addforce v_f 0 0";
    let out = run(dir.path(), &headon(1e-6, extra));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(msg.contains("particle 1 has a non-finite"), "{msg}");
    assert!(msg.contains("velocity"), "{msg}");
    assert!(stop_step(&msg) <= 20, "{msg}");
    assert!(msg.contains("a non-finite value from outside the contact law"), "{msg}");
    // last good = the start of the run, still finite
    let df = demx::io::data::read_data(dir.path().join("demx.lastgood.data")).expect("state written");
    assert!(df.title.ends_with("timestep = 0"), "{}", df.title);
    assert!(df.atoms.iter().all(|a| a.x.iter().chain(&a.v).all(|c| c.is_finite())));
}

#[test]
fn demx_guard_syntax() {
    let dir = tempfile::tempdir().expect("tempdir");
    let check = |extra: &str| run_deck(dir.path(), "in.check", &headon(1e-6, extra), &["check"]);
    for ok in ["demx_guard overlap 0.5 travel 0.5 speed 50 every 10", "demx_guard off", "demx_guard on file none", "demx_guard speed off overlap off"]
    {
        let o = check(ok);
        assert_eq!(o.status.code(), Some(0), "{ok}: {}", stderr(&o));
    }
    let o = check("demx_guard overlap 0.5 sped 50");
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{msg}");
    assert!(
        msg.contains("in.check:29:24: error: unknown demx_guard keyword 'sped' (expected on, off, overlap, travel, speed, every, file)"),
        "{msg}"
    );
    assert!(msg.contains("did you mean 'speed'?"), "{msg}");
    let o = check("demx_guard every 0");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = check("demx_guard overlap -1");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn settle_deck_is_bitwise_unchanged_by_the_guard() {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("templates/settle/in.settle.liggghts");
    let text = std::fs::read_to_string(src).expect("settle deck");
    let args = ["run", "--quiet", "--log", "none", "--max-steps", "1000"];
    let on = run_deck(dir.path(), "in.on", &text, &args);
    assert_eq!(on.status.code(), Some(0), "{}", stderr(&on));
    let a = std::fs::read(dir.path().join("dump.settle")).expect("dump");
    let off = run_deck(dir.path(), "in.off", &text.replace("run             8000", "demx_guard off\nrun 8000"), &args);
    assert_eq!(off.status.code(), Some(0), "{}", stderr(&off));
    let b = std::fs::read(dir.path().join("dump.settle")).expect("dump");
    assert!(a.len() > 100_000 && a == b, "settle dumps differ with the guard on and off");
    assert!(!dir.path().join("demx.lastgood.data").exists());
}

/// One sphere (d = 2 mm) above a LIGGGHTS primitive zplane wall at z = 0,
/// at height `z0` moving down at 1 m/s.
fn wall_deck(dt: f64, z0: f64) -> String {
    headon(dt, "")
        .replace("create_atoms 1 single 0.006 0.0 0.0 units box\n", "")
        .replace("create_atoms 1 single -0.006 0.0 0.0 units box", &format!("create_atoms 1 single 0.0 0.0 {z0} units box"))
        .replace("set atom 1*2", "set atom 1")
        .replace("group b id 2\n", "")
        .replace("velocity b set -1.0 0.0 0.0 units box\n", "")
        .replace(
            "velocity a set 1.0 0.0 0.0 units box",
            "velocity a set 0.0 0.0 -1.0 units box\nfix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
        )
}

#[test]
fn deep_wall_overlap_is_stopped_and_names_the_wall() {
    // placed 0.8 R into the wall: a warning, naming the wall; with the
    // limit set in the deck, stopped before the first step
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run(dir.path(), &wall_deck(1e-6, 0.0002));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{msg}");
    assert!(msg.contains("WARNING (demx): stability guard: particle 1 overlaps wall (fix floor"), "{msg}");
    let out = run(dir.path(), &wall_deck(1e-6, 0.0002).replace("run 200", "demx_guard overlap 0.75\nrun 200"));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(msg.contains("particle 1 overlaps wall (fix floor"), "{msg}");
    assert!(msg.contains("80%"), "{msg}");
    // hitting the wall with the time step at 1.5 x the wall's Hertz time
    // (m* = m, R* = R: 2^(1/5) x the pair's; 0.35 R of travel per step, under
    // the travel limit): stopped at the impact, not after the run
    let th = hertz_time() * 2f64.powf(0.2);
    let dt = 1.5 * th;
    let z0 = 0.0015;
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run(dir.path(), &wall_deck(dt, z0));
    let msg = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(msg.contains("stability guard") && msg.contains("timestep too large for the stiffness"), "{msg}");
    let contact = ((z0 - 0.001) / dt).ceil() as i64;
    let step = stop_step(&msg);
    assert!(step >= contact && step <= contact + 20, "stopped at step {step}, contact at {contact}: {msg}");
    // the same run with a sane step bounces and finishes
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run(dir.path(), &wall_deck(0.02 * th, z0));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// Grains placed deep into walls (a mesh plate and a primitive plane, 78% to
/// 100% of their radius), as decks that insert with `all_in no` have them:
/// LIGGGHTS 3.8 runs the deck and pushes them out; demx warns once and
/// follows it step for step (issue #52: the guard stopped such decks).
#[test]
fn grains_placed_into_walls_run_as_liggghts_resolves_them() {
    use crate::common;
    let atoms = "create_atoms 1 single 0.001 0.001 0.0001 units box\ncreate_atoms 1 single 0.003 0.003 0.00003 units box\n\
create_atoms 1 single 0.006 0.002 -0.00131 units box\ncreate_atoms 1 single 0.007 0.003 -0.001375 units box\n\
set group all diameter 0.0009 density 2500\n";
    let deck = common::hertz_grains("-0.001 0.009 -0.001 0.005 -0.002 0.05", atoms, 0.5)
        + "fix cad all mesh/surface file plate.stl type 1\n\
fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad\n\
fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.0014\n\
fix g all gravity 9.81 vector 0 0 -1\nvelocity all set 0.01 0.02 0\nfix 1 all nve/sphere\ntimestep 1e-6\n\
thermo 500\nthermo_style custom step atoms ke\n\
dump d all custom 500 dump.walls id x y z vx vy vz\ndump_modify d format \"%d %.17g %.17g %.17g %.17g %.17g %.17g\"\n\
run 3000\n";
    let b = common::engine_and_demx("liggghts", "in.walls", &[("in.walls", &deck), ("plate.stl", &common::plate_stl("0"))]);
    assert_eq!(b.ours_out.matches("WARNING (demx): stability guard: ").count(), 1, "{}", b.ours_out);
    assert!(b.ours_out.contains("overlaps wall (fix "), "{}", b.ours_out);
    let (theirs, ours) = (common::dump_frames(&b.theirs.path().join("dump.walls")), common::dump_frames(&b.ours.path().join("dump.walls")));
    assert_eq!(theirs.len(), 7, "frames");
    assert_eq!(theirs.keys().collect::<Vec<_>>(), ours.keys().collect::<Vec<_>>());
    for (step, rows) in &theirs {
        assert_eq!(rows.len(), 4, "step {step}");
        for (id, t) in rows {
            let o = &ours[step][id];
            for k in 0..6 {
                let scale = if k < 3 { 1e-3 } else { t[3..].iter().fold(1e-3_f64, |m, v| m.max(v.abs())) };
                assert!((t[k] - o[k]).abs() <= 1e-9 * scale, "step {step} atom {id} column {k}: liggghts {} demx {}", t[k], o[k]);
            }
        }
    }
    // pushed out: every grain ends above its wall and touches it no deeper than 10% of its radius
    let last = &theirs[&3000];
    for (id, t) in last {
        let wall = if t[0] < 0.0045 { 0.0 } else { -0.0014 };
        assert!(t[2] - wall > 0.9 * 0.00045, "atom {id} at z {} over the wall at {wall}", t[2]);
    }
}
