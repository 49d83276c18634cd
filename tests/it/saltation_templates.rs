//! The aeolian templates end to end, small and short: a thin layer settled on
//! the frozen sheet (templates/saltation/in.bed.lammps), a kicked transport run
//! with two-way wind (in.transport.lammps) and `demx saltation --json` on its
//! dump. The long version is scripts/saltation_validation.py.

use std::path::Path;
use std::process::Command;

fn demx(dir: &Path, args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir).args(args).output().unwrap();
    assert!(o.status.success(), "demx {args:?}: {}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn thin_layer_on_the_sheet_is_blown_and_measured() {
    let dir = tempfile::tempdir().unwrap();
    let t = Path::new(env!("CARGO_MANIFEST_DIR")).join("templates/saltation");
    for f in ["in.bed.lammps", "in.transport.lammps"] {
        std::fs::copy(t.join(f), dir.path().join(f)).unwrap();
    }
    let d = dir.path();
    // 10 d_m x 5 d_m (multiples of the 250 um fill lattice and of the 200 um
    // sheet), delta_0 = 2 d_m on the sheet, settled briefly
    demx(
        d,
        &[
            "run",
            "in.bed.lammps",
            "--quiet",
            "-var",
            "delta0",
            "2",
            "-var",
            "sheet",
            "1",
            "-var",
            "lx",
            "0.002",
            "-var",
            "ly",
            "0.001",
            "-var",
            "settle",
            "30000",
            "-var",
            "rest",
            "10000",
        ],
    );
    let bed = std::fs::read_to_string(d.join("bed.data")).unwrap();
    assert!(bed.contains(" atoms"), "bed.data written");
    // 0.03 s of wind at u* = 0.5 after the kick, dumped every 0.01 s
    demx(d, &["run", "in.transport.lammps", "--quiet", "-var", "ustar", "0.5", "-var", "steps", "30000"]);
    let out = demx(
        d,
        &[
            "saltation",
            "--json",
            "--ustar",
            "0.5",
            "--dt",
            "1e-6",
            "--group-type",
            "1",
            "--rigid-type",
            "2",
            "--delta0",
            "2",
            "--plot",
            "s.png",
            "dump.salt",
        ],
    );
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["frames"], 4, "frames at 0, 0.01, 0.02, 0.03 s");
    // the sheet's top (centres at 100 um, 200 um grains) is the rigid ground
    assert!((j["ground"].as_f64().unwrap() - 200e-6).abs() < 1e-9, "{}", j["ground"]);
    // the settled mobile layer is about two grain layers thick
    let d0 = j["delta_first_dm"].as_f64().unwrap();
    assert!(d0 > 1.0 && d0 < 3.0, "first-frame thickness {d0} d_m");
    // the kicked grains move downwind: positive flux, upward and downward hops near the bed
    assert!(j["q_mean"].as_f64().unwrap() > 0.0, "{out}");
    let h = &j["hops"];
    assert!(h["samples_up"].as_u64().unwrap() + h["samples_down"].as_u64().unwrap() > 0, "{out}");
    for k in ["q_mean", "zb", "delta_s_dm"] {
        assert!(j[k].as_f64().is_some_and(f64::is_finite), "{k} not finite: {out}");
    }
    assert!(std::fs::metadata(d.join("s.png")).unwrap().len() > 1000);
}
