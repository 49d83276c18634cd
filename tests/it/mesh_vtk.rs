//! `dump mesh/vtk` (LIGGGHTS 3.8 with VTK 9.1): the meshes as legacy VTK
//! polydata with per-triangle stresses, velocities and topology, in the
//! three `output` modes, against `liggghts` on the same deck.

use crate::common;

use std::path::Path;

/// The plate at height `z`.
fn plate(z: &str) -> String {
    common::plate_stl(z)
}

/// [`common::plate_deck`] with the plate turning about z and a second plate
/// at rest and without stresses above; `dumps` are the deck's dump lines,
/// `between` lines between its two runs.
fn deck(dumps: &str, between: &str) -> String {
    common::plate_deck(
        " reference_point 0.001 0.0015 0",
        "fix top all mesh/surface file top.stl type 1\n",
        &format!(
            "fix turn all move/mesh mesh cad rotate origin 0.002 0.002 0 axis 0 0 1 period 0.01\nthermo 100\n{dumps}\nrun 1250\n{between}\nrun 300\n"
        ),
    )
}

/// A file's words: numbers as numbers, the rest as text.
#[derive(Debug, PartialEq)]
enum Word {
    Num(f64),
    Text(String),
}

fn words(path: &Path) -> Vec<Vec<Word>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().map(|l| l.split_whitespace().map(|w| w.parse().map(Word::Num).unwrap_or_else(|_| Word::Text(w.to_string()))).collect()).collect()
}

/// Every line alike, word for word: text equal, and each number within
/// `rel` of the largest number on its line (so a zero beside a stress of
/// 1e3 may be 1e-10 in one file and 0 in the other).
fn same_file(theirs: &Path, ours: &Path, rel: f64) {
    let (t, o) = (words(theirs), words(ours));
    assert_eq!(t.len(), o.len(), "{}: line counts differ", ours.display());
    for (k, (lt, lo)) in t.iter().zip(&o).enumerate() {
        assert_eq!(lt.len(), lo.len(), "{} line {}: {lt:?} against {lo:?}", ours.display(), k + 1);
        let scale = lt.iter().chain(lo).filter_map(|w| if let Word::Num(x) = w { Some(x.abs()) } else { None }).fold(0.0, f64::max);
        for (a, b) in lt.iter().zip(lo) {
            match (a, b) {
                (Word::Num(x), Word::Num(y)) => assert!((x - y).abs() <= rel * scale, "{} line {}: {x} against {y}", ours.display(), k + 1),
                _ => assert_eq!(a, b, "{} line {}", ours.display(), k + 1),
            }
        }
    }
}

/// The numbers of the array `name` in a file.
fn array(path: &Path, name: &str) -> Vec<f64> {
    let w = words(path);
    let at = w.iter().position(|l| l.first() == Some(&Word::Text(name.to_string()))).unwrap_or_else(|| panic!("{name} in {}", path.display()));
    let count = match (&w[at][1], &w[at][2]) {
        (Word::Num(c), Word::Num(n)) => (c * n) as usize,
        _ => panic!("{name}: header"),
    };
    w[at + 1..].iter().flatten().take(count).map(|x| if let Word::Num(v) = x { *v } else { panic!("{name}: {x:?}") }).collect()
}

/// Each mode's files, frame by frame, as liggghts writes them: the same
/// arrays in the same order, stresses and velocities within 1e-8.
#[test]
fn mesh_vtk_follows_liggghts() {
    let props = "id stress stresscomponents vel area owner aedges acorners index nneighs";
    let dumps = format!(
        "dump a all mesh/vtk 50 a*.vtk {props}\ndump b all mesh/vtk 50 b*.vtk output interpolate {props}\n\
dump c all mesh/vtk 50 c*.vtk output original {props}\ndump d all mesh/vtk 100 d*.vtk top cad vel stress id"
    );
    let (p, t) = (plate("0"), plate("0.0035"));
    let b = common::engine_and_demx(
        "liggghts",
        "in.deck",
        &[("in.deck", &deck(&dumps, "dump e all mesh/vtk 50 e*.vtk stress stresscomponents vel")), ("plate.stl", &p), ("top.stl", &t)],
    );
    // a grain slides on the turning plate across the run break: the
    // setup's force must leave its history as it was (a reset to the
    // setup's friction cap made the next step's tangential force 2e-6 off)
    let rel = |_: i64| 1e-8;
    let (mut frames, mut pushed) = (0, 0);
    for step in (0..=1550).step_by(50) {
        for (mode, every) in [("a", 50), ("b", 50), ("c", 50), ("d", 100)] {
            if step % every != 0 {
                continue;
            }
            let name = format!("{mode}{step}.vtk");
            same_file(&b.theirs.path().join(&name), &b.ours.path().join(&name), rel(step));
            frames += 1;
        }
        if array(&b.ours.path().join(format!("a{step}.vtk")), "normal_stress_average").iter().any(|&s| s > 0.0) {
            pushed += 1;
        }
    }
    // a dump defined between the runs writes at the second run's setup:
    // the setup's pushes beside the last step's stresses
    for step in (1250..=1550).step_by(50) {
        let name = format!("e{step}.vtk");
        same_file(&b.theirs.path().join(&name), &b.ours.path().join(&name), rel(step));
    }
    assert_eq!(frames, 32 * 3 + 16);
    // the scene is the one meant: the grains press the plate in several
    // frames, and it turns (its nodes move at ω r, up to 628 * 2.83e-3)
    assert!(pushed >= 4, "{pushed} frames with a stress");
    let v = array(&b.ours.path().join("b1000.vtk"), "v");
    let fastest = v.chunks(3).map(|c| (c[0] * c[0] + c[1] * c[1]).sqrt()).fold(0.0, f64::max);
    assert!((fastest - 2.0 * std::f64::consts::PI / 0.01 * 0.002 * 2f64.sqrt()).abs() < 1e-9, "{fastest}");
}

/// Finnie's wear of each triangle (`wear finnie`, dumped as `wear`) on a
/// plate at rest, over two runs: the setup's contacts add no wear.
#[test]
fn finnie_wear_follows_liggghts() {
    let dumps = "dump a all mesh/vtk 50 a*.vtk wear stress";
    let d = deck(dumps, "")
        .replace("fix turn all move/mesh mesh cad rotate origin 0.002 0.002 0 axis 0 0 1 period 0.01\n", "")
        .replace("reference_point 0.001 0.0015 0", "reference_point 0.001 0.0015 0 wear finnie")
        .replace("pair_style gran", "fix m5 all property/global k_finnie peratomtypepair 1 0.7\npair_style gran");
    let (p, t) = (plate("0"), plate("0.0035"));
    let b = common::engine_and_demx("liggghts", "in.deck", &[("in.deck", &d), ("plate.stl", &p), ("top.stl", &t)]);
    let mut last = 0.0;
    for step in (0..=1550).step_by(50) {
        let name = format!("a{step}.vtk");
        same_file(&b.theirs.path().join(&name), &b.ours.path().join(&name), 1e-8);
        let wear: f64 = array(&b.ours.path().join(&name), "wear").iter().sum();
        assert!(wear >= last, "step {step}: wear fell from {last} to {wear}");
        last = wear;
    }
    // both columns of grains wore the plate (its two triangles, then the
    // top mesh's two without wear), which the deck meant
    let w = array(&b.ours.path().join("a1550.vtk"), "wear");
    assert!(w.len() == 4 && w[0] > 0.0 && w[1] > 0.0 && w[2] == 0.0 && w[3] == 0.0, "{w:?}");
}

/// Deck errors name their line; what demx does not write yet stops with
/// exit 3.
#[test]
fn mesh_vtk_deck_errors() {
    let (p, t) = (plate("0"), plate("0.0035"));
    let files = [("plate.stl", p.as_str()), ("top.stl", t.as_str())];
    let line_of = |d: &str| d.lines().position(|l| l.starts_with("dump x")).unwrap() + 1;
    for (dump, code, says) in [
        ("dump x all mesh/vtk 10 m*.vtk id strss", 2, "'strss' is neither a property nor a fix mesh/surface"),
        ("dump x all mesh/vtk 10 m*.vtk cad", 2, "no property to dump"),
        ("dump x all mesh/vtk 10 m*.vtk output faces id", 2, "faces"),
        ("dump x all mesh/vtk 10 m*.vtk temp", 3, "dump mesh/vtk property temp"),
        ("dump x all mesh/vtk 10 m*.vtp id", 3, ".vtp"),
    ] {
        let d = deck(dump, "");
        let (c, out) = common::demx_deck(&d, &files);
        assert!(c == Some(code) && out.contains(&format!("in.deck:{}:", line_of(&d))) && out.contains(says), "{dump}: {out}");
    }
    let (c, out) = common::demx_deck(&deck("dump x all mesh/vtk 10 m*.vtk id strss", ""), &files);
    assert!(c == Some(2) && out.contains("did you mean 'stress'"), "{out}");
}
