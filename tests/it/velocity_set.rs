//! `velocity GROUP set vx vy vz` with `v_name` components (LAMMPS: equal- or
//! atom-style variables; the lattice scale applies to numbers only), against
//! the real `lmp` on the same deck, and the deck error for a missing variable.

use demx::io::dump::read_all;
use std::path::Path;
use std::process::Command;

const DECK: &str = "units si
atom_style sphere
atom_modify map array
boundary p p f
region box block 0 8 0 8 0 8 units box
create_box 1 box
lattice sc 2.0
create_atoms 1 box
set type 1 diameter 0.5 density 1000
variable va atom 0.5*z+x
variable ve equal 0.25
velocity all set v_va v_ve 3.0 units lattice
region up block INF INF INF INF 4.5 INF units box
group up region up
velocity up set NULL NULL v_va sum yes units box
write_dump all custom dump.v id x y z vx vy vz
";

fn run(dir: &Path, prog: &str) -> std::process::Output {
    std::fs::write(dir.join("in.deck"), DECK).unwrap();
    let mut c = if prog == "lmp" {
        let mut c = Command::new("lmp");
        c.args(["-in", "in.deck", "-log", "none", "-screen", "none"]);
        c
    } else {
        let mut c = Command::new(env!("CARGO_BIN_EXE_demx"));
        c.args(["run", "in.deck", "--log", "none", "--quiet"]);
        c
    };
    c.current_dir(dir).output().unwrap_or_else(|e| panic!("cannot start {prog} ({e}); bash scripts/setup.sh installs LAMMPS"))
}

#[test]
fn atom_and_equal_style_components_as_lammps() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let o = run(a.path(), "demx");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(b.path(), "lmp");
    assert!(o.status.success(), "lmp: {}", String::from_utf8_lossy(&o.stdout));
    let d = &read_all(a.path().join("dump.v")).unwrap()[0];
    let l = &read_all(b.path().join("dump.v")).unwrap()[0];
    assert_eq!(d.natoms, 64);
    assert_eq!(d.natoms, l.natoms);
    let (mut lifted, mut checked) = (0, 0);
    for r in 0..d.natoms {
        let id = d.get(r, d.col("id").unwrap()).unwrap() as u64;
        let lr = l.row_of_id(id).unwrap();
        let g = |f: &demx::io::dump::Frame, row: usize, c: &str| f.get(row, f.col(c).unwrap()).unwrap();
        let (x, z) = (g(d, r, "x"), g(d, r, "z"));
        // the deck: vx = 0.5 z + x, vy = 0.25, vz = 3 lattice spacings (2 m)
        // = 6, plus 0.5 z + x above z = 4.5 (sum yes)
        let vz = 6.0 + if z > 4.5 { 0.5 * z + x } else { 0.0 };
        for (c, want) in [("vx", 0.5 * z + x), ("vy", 0.25), ("vz", vz)] {
            assert!((g(d, r, c) - want).abs() < 1e-12, "id {id} {c}: {} vs {want}", g(d, r, c));
            assert!((g(d, r, c) - g(l, lr, c)).abs() < 1e-12, "id {id} {c}: demx {} lmp {}", g(d, r, c), g(l, lr, c));
        }
        lifted += (z > 4.5) as usize;
        checked += 1;
    }
    assert_eq!((checked, lifted), (64, 16));
}

#[test]
fn missing_variable_is_a_deck_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.bad"), DECK.replace("velocity all set v_va", "velocity all set v_nope")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir.path()).args(["run", "in.bad", "--log", "none"]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("in.bad:12:18: error:") && err.contains("nope"), "{err}");
}
