//! `fix massflow/mesh` against LIGGGHTS 3.8: grains fall through a square
//! face (some beside it), bounce on a floor and fall through it again; the
//! counted mass and number, the rates between queries, with `count once` and
//! `count multiple`, and the file of counted grains are LIGGGHTS's.

use crate::common;

fn deck() -> String {
    let atoms = "lattice sc 0.001\nregion grains block 0.0005 0.0065 0.0005 0.0035 0.004 0.0045 units box\ncreate_atoms 1 region grains\n\
set group all diameter 0.0006 density 2500\n";
    common::hertz_grains("-0.001 0.008 -0.001 0.005 0 0.007", atoms, 0.9)
        + "fix face all mesh/surface file face.stl type 1\n\
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n\
fix g all gravity 9.81 vector 0 0 -1\nfix 1 all nve/sphere\ntimestep 1e-5\n\
fix many all massflow/mesh mesh face vec_side 0 0 -1 file many.txt writeTime\n\
fix one all massflow/mesh mesh face vec_side 0 0 -1 count once\n\
thermo_style custom step atoms f_many[1] f_many[2] f_many[3] f_many[4] f_one[2]\nthermo_modify format float %.15g\nthermo 500\n\
run 9000\n"
}

#[test]
fn massflow_counts_and_file_like_liggghts() {
    let deck = deck();
    let b = common::engine_and_demx("liggghts", "in.flow", &[("in.flow", &deck), ("face.stl", &common::plate_stl("0.002"))]);
    let (theirs, ours) = (common::thermo_runs(&b.theirs_out), common::thermo_runs(&b.ours_out));
    assert_eq!(theirs.len(), 1, "{}", b.theirs_out);
    assert_eq!(theirs[0].len(), ours[0].len(), "{}", b.ours_out);
    for (t, o) in theirs[0].iter().zip(&ours[0]) {
        assert_eq!(t.len(), o.len());
        for (x, y) in t.iter().zip(o) {
            let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-12), "liggghts {t:?}\ndemx     {o:?}");
        }
    }
    // the grains over the face (4 x 3 columns, one layer) passed twice, the
    // others never: the counts measure what the test says
    let last = &theirs[0].last().unwrap();
    let (many, once): (f64, f64) = (last[3].parse().unwrap(), last[6].parse().unwrap());
    assert_eq!(once, 12.0, "{last:?}");
    assert_eq!(many, 24.0, "{last:?}");
    // the file: same rows, a step's rows in any order
    let rows = |d: &std::path::Path| {
        let text = std::fs::read_to_string(d.join("many.txt")).unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let head = lines.remove(0);
        lines.sort();
        (head, lines)
    };
    let (th, tr) = rows(b.theirs.path());
    let (oh, or) = rows(b.ours.path());
    assert_eq!(th, oh);
    assert_eq!(tr.len(), 24);
    assert_eq!(tr, or);
}

#[test]
fn massflow_deck_errors_and_what_is_not_run_yet() {
    let stl = common::plate_stl("0.002");
    let with = |line: &str| {
        deck().replace("fix one all massflow/mesh mesh face vec_side 0 0 -1 count once\n", &format!("{line}\n")).replace(" f_one[2]", "")
    };
    for (line, code, said) in [
        ("fix one all massflow/mesh mesh face vec_side 1 0 0", 2, "vec_side"),
        ("fix one all massflow/mesh mesh nope vec_side 0 0 1", 2, "fix mesh/surface 'nope' does not exist"),
        ("fix one all massflow/mesh mesh face", 2, "expecting keyword 'vec_side'"),
        ("fix one all massflow/mesh mesh face vec_side 0 0 1 count once delete_atoms yes", 3, "delete_atoms yes"),
        ("fix one all massflow/mesh mesh face vec_side 0 0 1 count once point_at_outlet 0 0 0", 3, "point_at_outlet"),
    ] {
        let (c, out) = common::demx_deck(&with(line), &[("face.stl", &stl)]);
        assert_eq!(c, Some(code), "{line}: {out}");
        assert!(out.contains(said), "{line}: {out}");
    }
}
