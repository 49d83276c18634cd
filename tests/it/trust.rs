//! Issue #53 "Trust": decks and files that must be refused before they run
//! away (exit 2 with the file, line and what is wrong), and analysis tools
//! that must not print a wrong answer.

use crate::common;

use std::process::Command;

/// A periodic 1 cm box with one grain of d = 2 mm, Hertz with history
/// (LIGGGHTS dialect); `extra` goes after the integrator.
fn deck(extra: &str) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary p p p\nnewton off\ncommunicate single vel yes\nunits si\n\
region reg block 0 0.01 0 0.01 0 0.01 units box\ncreate_box 1 reg\nneighbor 0.0002 bin\n\
fix m1 all property/global youngsModulus peratomtype 1.e7\nfix m2 all property/global poissonsRatio peratomtype 0.3\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 1e-6\n\
create_atoms 1 single 0.005 0.005 0.005 units box\nset atom 1 diameter 0.002 density 2500\nfix integr all nve/sphere\n{extra}\n"
    )
}

/// `deck(extra)` must stop as a deck error (exit 2) at line `line` of
/// `in.deck` with a message containing every one of `words`.
fn refused(extra: &str, line: usize, words: &[&str]) {
    let out = common::deck_error(&deck(extra));
    assert!(out.contains(&format!("in.deck:{line}:")), "{extra}: not at line {line}: {out}");
    for w in words {
        assert!(out.contains(w), "{extra}: no '{w}' in: {out}");
    }
}

/// Line of the first `extra` line in [`deck`].
const EXTRA: usize = 20;

#[test]
fn thermo_dump_run_outside_the_engines_limits_are_refused() {
    // both engines: "Illegal thermo command", "Invalid dump frequency",
    // "Invalid run command N value"
    refused("thermo -1\nrun 1", EXTRA, &["thermo: N must be between 0 and 2147483647, not -1"]);
    refused("dump d all custom 0 dump.x id x\nrun 1", EXTRA, &["dump d: N must be between 1", "not 0", "Invalid dump frequency"]);
    refused("dump d all custom -5 dump.x id x\nrun 1", EXTRA, &["not -5"]);
    refused("run 9223372036854775807", EXTRA, &["run: N must be between 0 and 2147483647", "Invalid run command N value"]);
    refused("run 2147483648", EXTRA, &["run: N must be between 0 and 2147483647"]);
    refused("run -1", EXTRA, &["run: N must be between 0 and 2147483647, not -1"]);
    // `thermo 0` and write_dump's one-off dump stay valid
    let (code, out) = common::demx_deck(&deck("thermo 0\nwrite_dump all custom one.dump id x\nrun 2"), &[]);
    assert_eq!(code, Some(0), "{out}");
}

#[test]
fn a_number_beyond_a_double_is_refused() {
    // both engines take atof's inf and run on; no deck means that
    refused("timestep 1e400\nrun 1", EXTRA, &["timestep: timestep: number '1e400' is too large for a double"]);
}

#[test]
fn set_values_the_engines_refuse_are_refused() {
    refused("set atom 1 density -2500", EXTRA, &["set density: density must be > 0, not -2500", "Invalid density in set command"]);
    refused("set atom 1 density 0", EXTRA, &["density must be > 0"]);
    refused("set atom 1 diameter -0.002", EXTRA, &["set diameter: diameter must be >= 0, not -0.002"]);
    refused("set atom 1 mass -1", EXTRA, &["set mass: mass must be > 0"]);
    refused("set atom 1 type 2", EXTRA, &["set type: type must be an atom type 1..1, not 2"]);
}

#[test]
fn a_box_of_zero_width_is_refused() {
    let d = deck("run 1").replace("region reg block 0 0.01 0 0.01 0 0.01", "region reg block 0 0.01 0 0 0 0.01");
    let out = common::deck_error(&d);
    assert!(out.contains("in.deck:8:") && out.contains("create_box: region 'reg' is empty in y"), "{out}");
}

#[test]
fn a_negative_neighbor_skin_is_refused() {
    // "neighbor -1 bin" grew to 11 GB in 40 s; both engines: Illegal neighbor command
    refused("neighbor -1 bin\nrun 1", EXTRA, &["neighbor: skin must be >= 0, not -1", "Illegal neighbor command"]);
}

#[test]
fn create_atoms_random_counts_and_seeds_are_bounded() {
    refused("create_atoms 1 random -5 123 NULL", EXTRA, &["create_atoms random: N must be between 0 and 2147483647, not -5"]);
    refused("create_atoms 1 random 9223372036854775807 123 NULL", EXTRA, &["N must be between 0 and 2147483647"]);
    refused("create_atoms 1 random 1000000000000 123 NULL", EXTRA, &["N must be between 0 and 2147483647"]);
    refused("create_atoms 1 random 5 0 NULL", EXTRA, &["seed must be between 1 and 2147483647, not 0"]);
    // within the engines' int but beyond any machine's memory (400 B each)
    refused("create_atoms 1 random 2000000000 123 NULL", EXTRA, &["2000000000 particles need at least 800.0 GB", "of memory"]);
    // 0 is LAMMPS's too ("Created 0 atoms")
    let (code, out) = common::demx_deck(&deck("create_atoms 1 random 0 123 NULL\nrun 1"), &[]);
    assert_eq!(code, Some(0), "{out}");
}

#[test]
fn create_box_types_are_bounded_by_memory() {
    for (n, what) in [("100000", "atom types need"), ("2000000000", "atom types need"), ("3000000000", "more than the engines' limit")] {
        let d = deck("run 1").replace("create_box 1 reg", &format!("create_box {n} reg"));
        let out = common::deck_error(&d);
        assert!(out.contains("in.deck:8:") && out.contains(what), "{n}: {out}");
    }
}

/// Runs `demx ARGS` in `dir`: exit code and stdout + stderr.
fn demx(dir: &std::path::Path, args: &[&str]) -> (Option<i32>, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).args(args).current_dir(dir).output().unwrap();
    (o.status.code(), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

/// A text dump: one frame per entry of `frames` (timestep, rows of `id x y z radius`).
fn dump_text(frames: &[(u64, Vec<[f64; 5]>)]) -> String {
    let mut t = String::new();
    for (step, rows) in frames {
        t.push_str(&format!(
            "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS pp pp ff\n0 0.1\n0 0.1\n0 0.1\nITEM: ATOMS id x y z radius\n",
            rows.len()
        ));
        for r in rows {
            t.push_str(&format!("{} {} {} {} {}\n", r[0], r[1], r[2], r[3], r[4]));
        }
    }
    t
}

/// 30 grains of a small heap, ids 1..=30.
fn heap_rows() -> Vec<[f64; 5]> {
    (0..30)
        .map(|k| {
            let (i, j) = ((k % 6) as f64, (k / 6) as f64);
            [k as f64 + 1.0, 0.03 + 0.008 * i, 0.05, 0.001 + 0.004 * j + 0.001 * (i - 2.5).abs(), 0.001]
        })
        .collect()
}

#[test]
fn compare_refuses_repeated_ids_naming_file_frame_and_particle() {
    let dir = tempfile::tempdir().unwrap();
    let rows = heap_rows();
    let mut ones = rows.clone();
    for r in ones.iter_mut() {
        r[0] = 1.0;
    }
    std::fs::write(dir.path().join("a.dump"), dump_text(&[(0, rows.clone()), (100, rows.clone())])).unwrap();
    std::fs::write(dir.path().join("b.dump"), dump_text(&[(0, rows.clone()), (100, ones)])).unwrap();
    let (code, out) = demx(dir.path(), &["compare", "a.dump", "b.dump"]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("b.dump: frame 2 (timestep 100), atom line 2: particle id 1 appears 30 times"), "{out}");
    assert!(!out.contains("PASS"), "{out}");
}

#[test]
fn compare_refuses_non_finite_positions_and_fails_on_other_ids() {
    let dir = tempfile::tempdir().unwrap();
    let rows = heap_rows();
    let mut nan = rows.clone();
    nan[4][2] = f64::NAN;
    std::fs::write(dir.path().join("a.dump"), dump_text(&[(0, rows.clone())])).unwrap();
    std::fs::write(dir.path().join("b.dump"), dump_text(&[(0, nan)])).unwrap();
    let (code, out) = demx(dir.path(), &["compare", "a.dump", "b.dump"]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("b.dump: frame 1 (timestep 0), atom line 5: particle 5 has a position that is not finite"), "{out}");
    // same count, one id renumbered: statistics mode (30 > 10 particles) must fail
    let mut other = rows.clone();
    other[29][0] = 31.0;
    std::fs::write(dir.path().join("c.dump"), dump_text(&[(0, other)])).unwrap();
    let (code, out) = demx(dir.path(), &["compare", "a.dump", "c.dump"]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("FAIL: particle ids differ: 1 only in A, 1 only in B") && out.contains("verdict: FAIL"), "{out}");
}

#[test]
fn repose_and_packing_refuse_bad_positions_and_radii() {
    let dir = tempfile::tempdir().unwrap();
    let rows = heap_rows();
    let (mut nan, mut inf, mut neg) = (rows.clone(), rows.clone(), rows.clone());
    nan[3][1] = f64::NAN;
    inf[3][3] = f64::INFINITY;
    neg[7][4] = -0.001;
    for (name, rows) in [("nan.dump", nan), ("inf.dump", inf), ("neg.dump", neg)] {
        std::fs::write(dir.path().join(name), dump_text(&[(0, rows.clone()), (50, rows)])).unwrap();
    }
    for tool in ["repose", "packing"] {
        let (code, out) = demx(dir.path(), &[tool, "nan.dump"]);
        assert_eq!(code, Some(2), "{tool}: {out}");
        assert!(out.contains("nan.dump: frame 1 (timestep 50), atom line 4: particle 4 has position (NaN"), "{tool}: {out}");
        let (code, out) = demx(dir.path(), &[tool, "inf.dump", "--frame", "0"]);
        assert_eq!(code, Some(2), "{tool}: {out}");
        assert!(out.contains("inf.dump: frame 0 (timestep 0), atom line 4: particle 4 has position") && out.contains("inf)"), "{tool}: {out}");
        let (code, out) = demx(dir.path(), &[tool, "neg.dump"]);
        assert_eq!(code, Some(2), "{tool}: {out}");
        assert!(out.contains("neg.dump: frame 1 (timestep 50), atom line 8: particle 8 has radius -0.001"), "{tool}: {out}");
    }
}

#[test]
fn dump_headers_claiming_more_than_the_file_holds_do_not_allocate_it() {
    let dir = tempfile::tempdir().unwrap();
    // 4 kB that claim 16.7M atoms of 2,015 columns: aborted allocating 270 GB
    let cols: Vec<String> = (0..2015).map(|k| format!("c{k}")).collect();
    let text =
        format!("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n16777216\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\nITEM: ATOMS {}\n", cols.join(" "));
    std::fs::write(dir.path().join("big.dump"), &text).unwrap();
    let (code, out) = demx(dir.path(), &["compare", "big.dump", "big.dump"]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("truncated") || out.contains("0 of 16777216 atom lines"), "{out}");
}

#[test]
fn reference_engines_are_not_started_on_decks_that_run_commands() {
    let dir = tempfile::tempdir().unwrap();
    for (name, line) in [
        ("in.shell", "shell touch pwned"),
        ("in.if", "if \"1 > 0\" then \"shell touch pwned\""),
        ("in.py", "python hello here \"open('pwned','w')\""),
    ] {
        std::fs::write(dir.path().join(name), deck(&format!("{line}\nrun 1"))).unwrap();
        for args in [vec!["compare", name, "--against", "lammps"], vec!["reference", name, "--engine", "lammps", "--out", "ref"]] {
            let (code, out) = demx(dir.path(), &args);
            assert_eq!(code, Some(2), "{args:?}: {out}");
            assert!(out.contains(&format!("{name}:20:")) && out.contains("pass --allow-shell"), "{args:?}: {out}");
            assert!(!dir.path().join("pwned").exists(), "{args:?} ran the deck's command");
        }
    }
}

#[test]
fn a_particle_too_far_to_wrap_is_lost_not_a_hang() {
    // with the guard off a 1e300 m/s grain left the periodic box by 1e294 m
    // and Domain::wrap subtracted the box length forever
    let (code, out) = common::demx_deck(&deck("demx_guard off\nvelocity all set 1e300 0 0 units box\nrun 5"), &[]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("Lost atoms") && out.contains("inf"), "{out}");
}

#[test]
fn messages_escape_control_characters_and_clip_huge_tokens() {
    let out = common::deck_error(&deck("fix_bogus\u{1b}[31m all\nrun 1"));
    assert!(out.contains("unknown command 'fix_bogus\\x1b[31m'") && !out.contains('\u{1b}'), "{out}");
    let token = "x".repeat(10_000_000);
    let t0 = std::time::Instant::now();
    let out = common::deck_error(&deck(&format!("{token}\nrun 1")));
    assert!(t0.elapsed().as_secs() < 10, "{:?}", t0.elapsed());
    assert!(out.len() < 2000 && out.contains("characters]") && out.contains("in.deck:20:"), "{} bytes: {}", out.len(), &out[..out.len().min(600)]);
}

#[test]
fn dump_info_on_a_missing_file_exits_2_like_the_other_tools() {
    let dir = tempfile::tempdir().unwrap();
    let (code, out) = demx(dir.path(), &["dump", "info", "missing.dump"]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("missing.dump"), "{out}");
}

/// A restart file crafted or damaged in one value is refused with exit 2
/// naming what is wrong, before anything runs: values that hung the run
/// (mass 0, an inverted box) or panicked it (a short or zero-width
/// per-atom column, a type above ntypes, 2^40 types), and a replay list
/// that would run a command a restart does not carry (a `fix print ...
/// file` creating a file).
#[test]
fn crafted_restart_files_are_refused_before_they_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // a valid restart with a per-atom property column
    let write = deck("fix pa all property/atom tag1 scalar yes no no 0.\nrun 10\nwrite_restart r.json");
    std::fs::write(d.join("in.write"), write).unwrap();
    // what a write killed half way leaves: the next write of the name replaces it
    std::fs::write(d.join(".r.json.tmp"), "{\"format\": ").unwrap();
    let (code, out) = demx(d, &["run", "in.write", "--log", "none"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(!d.join(".r.json.tmp").exists(), "a killed write's temporary file is left behind");
    let valid: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
    let read = "atom_style granular\natom_modify map array\nnewton off\ncommunicate single vel yes\nunits si\nread_restart r.bad\n\
neighbor 0.0002 bin\nfix integr all nve/sphere\nrun 10\n";
    std::fs::write(d.join("in.read"), read).unwrap();
    // the untouched file reads and runs
    std::fs::write(d.join("r.bad"), valid.to_string()).unwrap();
    let (code, out) = demx(d, &["run", "in.read", "--log", "none"]);
    assert_eq!(code, Some(0), "the valid restart: {out}");
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit, &str); 8] = [
        ("mass 0", |v| v["mass"][0] = 0.0.into(), "mass 0"),
        ("inverted box", |v| v["hi"][2] = (-1.0).into(), "lo < hi"),
        ("type above ntypes", |v| v["kind"][0] = 7.into(), "type 7"),
        ("2^40 types", |v| v["ntypes"] = (1u64 << 40).into(), "atom types"),
        ("short per-atom column", |v| v["extra"][0]["data"] = serde_json::json!([]), "per-atom property"),
        ("per-atom width 0", |v| v["extra"][0]["width"] = 0.into(), "width 0"),
        ("negative time step", |v| v["dt"] = (-1e-6).into(), "dt > 0"),
        (
            "a replayed command that writes a file",
            |v| v["replay"].as_array_mut().unwrap().push("fix p all print 1 hi file pwned.txt".into()),
            "does not carry",
        ),
    ];
    for (what, edit, expect) in cases {
        let mut v = valid.clone();
        edit(&mut v);
        std::fs::write(d.join("r.bad"), v.to_string()).unwrap();
        let (code, out) = demx(d, &["run", "in.read", "--log", "none"]);
        assert_eq!(code, Some(2), "{what}: {out}");
        assert!(out.contains("in.read:6:") && out.contains(expect), "{what}: {out}");
    }
    assert!(!d.join("pwned.txt").exists(), "the replayed fix print ran");
}
