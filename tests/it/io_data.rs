//! Data files against LAMMPS 29 Sep 2021 / LIGGGHTS 3.8 `write_data` output
//! (tests/data/io/lmp_data.sphere, lmp_tri_data.sphere, lig_data.sphere).
use demx::io::data::{format_data, read_data, write_data};
use demx::io::dump::Engine;
use std::path::Path;
use std::process::Command;

const D: &str = "tests/data/io";

#[test]
fn reads_lammps_and_liggghts_data() {
    let d = read_data(Path::new(D).join("lmp_data.sphere")).unwrap();
    assert_eq!(d.atoms.len(), 6);
    assert_eq!(d.atom_types, 2);
    assert_eq!((d.lo, d.hi), ([-2.0, -2.0, 0.0], [2.0, 2.0, 4.0]));
    // "6 2 0.3 2.5 1.9299999999999966 1.8400000000000065 0.2549999999999999 -2 3 0"
    let a = &d.atoms[0];
    assert_eq!((a.id, a.kind, a.diameter, a.density), (6, 2, 0.3, 2.5));
    assert_eq!(a.x, [1.9299999999999966, 1.8400000000000065, 0.2549999999999999]);
    assert_eq!(a.image, [-2, 3, 0]);
    assert!(d.has_velocities);
    let t = read_data(Path::new(D).join("lmp_tri_data.sphere")).unwrap();
    assert_eq!(t.tilt, Some([0.5, 0.25, -0.1]));
    assert_eq!(t.atoms[2].v, [0.1, -0.2, 0.05]);
    let l = read_data(Path::new(D).join("lig_data.sphere")).unwrap();
    assert_eq!(l.atoms.len(), 7);
    // LIGGGHTS: "4.0000000000000001e-03 2.5000000000000000e+03" and omega of atom 3 "7.1246040602584202e+01"
    let a3 = l.atoms.iter().find(|a| a.id == 3).unwrap();
    assert_eq!((a3.diameter, a3.density), (0.004, 2500.0));
    assert_eq!(a3.omega[0], 7.124_604_060_258_42e1);
}

#[test]
fn writer_reproduces_write_data_bytes() {
    for (name, eng, step) in [("lmp_data.sphere", Engine::Lammps, 300), ("lmp_tri_data.sphere", Engine::Lammps, 20)] {
        let text = std::fs::read_to_string(Path::new(D).join(name)).unwrap();
        let d = read_data(Path::new(D).join(name)).unwrap();
        assert_eq!(format_data(&d, eng, step), text, "{name}");
    }
    // LIGGGHTS: all but the title line (which names the build date).
    let text = std::fs::read_to_string(Path::new(D).join("lig_data.sphere")).unwrap();
    let d = read_data(Path::new(D).join("lig_data.sphere")).unwrap();
    let got = format_data(&d, Engine::Liggghts, 3000);
    assert_eq!(got.split_once('\n').unwrap().1, text.split_once('\n').unwrap().1);
}

fn have(exe: &str) -> bool {
    let ok = Command::new("sh").arg("-c").arg(format!("command -v {exe}")).output().map(|o| o.status.success()).unwrap_or(false);
    if !ok {
        eprintln!("SKIP: '{exe}' is not on PATH; engine check skipped");
    }
    ok
}

fn run(exe: &str, dir: &Path, deck: &str) {
    std::fs::write(dir.join("in.d"), deck).unwrap();
    let out = Command::new(exe).args(["-in", "in.d", "-log", "none", "-echo", "none"]).current_dir(dir).output().unwrap();
    let s = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !s.contains("ERROR"), "{exe}:\n{s}");
}

#[test]
fn round_trip_through_engines_read_data() {
    let dir = tempfile::tempdir().unwrap();
    if have("lmp") {
        for name in ["lmp_data.sphere", "lmp_tri_data.sphere", "lig_data.sphere"] {
            let d = read_data(Path::new(D).join(name)).unwrap();
            write_data(dir.path().join("mine.data"), &d, Engine::Lammps, 0).unwrap();
            run("lmp", dir.path(), "atom_style sphere\nread_data mine.data\nwrite_data again.data\n");
            let back = std::fs::read_to_string(dir.path().join("again.data")).unwrap();
            if d.tilt.is_none() {
                // LAMMPS write_data of what it read = our text (same content, same order).
                assert_eq!(back, format_data(&d, Engine::Lammps, 0), "{name}");
            } else {
                // Triclinic: LAMMPS remaps positions through fractional
                // coordinates on read, which moves the last bits.
                let b = read_data(dir.path().join("again.data")).unwrap();
                assert_eq!(b.tilt, d.tilt);
                for (p, q) in b.atoms.iter().zip(&d.atoms) {
                    assert_eq!((p.id, p.kind, p.image, p.v), (q.id, q.kind, q.image, q.v));
                    for k in 0..3 {
                        assert!((p.x[k] - q.x[k]).abs() < 1e-14, "{name}: {:?} vs {:?}", p.x, q.x);
                    }
                }
            }
        }
    }
    if have("liggghts") {
        let d = read_data(Path::new(D).join("lig_data.sphere")).unwrap();
        for eng in [Engine::Liggghts, Engine::Lammps] {
            write_data(dir.path().join("mine.data"), &d, eng, 0).unwrap();
            run("liggghts", dir.path(), "atom_style granular\nread_data mine.data\nwrite_data again.data\n");
            let back = read_data(dir.path().join("again.data")).unwrap();
            assert_eq!(back.atoms, d.atoms, "{eng:?}");
            assert_eq!((back.lo, back.hi), (d.lo, d.hi));
        }
    }
}
