//! Dump reader/writer against files written by the real LAMMPS 29 Sep 2021
//! and LIGGGHTS 3.8 (decks: tests/data/io/in.lammps, in.lammps_tri,
//! in.liggghts). Expected values are copied from those files' text.
use demx::io::dump::{self, DumpOptions, DumpReader, DumpWriter, Engine, FormatSpec, Frame, SortBy};
use std::path::{Path, PathBuf};
use std::process::Command;

const D: &str = "tests/data/io";

fn p(name: &str) -> PathBuf {
    Path::new(D).join(name)
}

fn read(name: &str) -> Vec<Frame> {
    dump::read_all(p(name)).unwrap_or_else(|e| panic!("{name}: {}", e.message()))
}

fn on_path(exe: &str) -> bool {
    let ok = Command::new("sh").arg("-c").arg(format!("command -v {exe}")).output().map(|o| o.status.success()).unwrap_or(false);
    if !ok {
        eprintln!("SKIP: '{exe}' is not on PATH; engine acceptance check skipped");
    }
    ok
}

#[test]
fn reads_lammps_custom_dump() {
    let f = read("lmp_custom.dump");
    assert_eq!(f.iter().map(|f| f.timestep).collect::<Vec<_>>(), [0, 100, 200, 300]);
    assert!(f.iter().all(|f| f.natoms == 6));
    let last = &f[3];
    assert_eq!(last.columns.len(), 19);
    assert_eq!(last.bounds.boundary, ["pp", "pp", "fm"]);
    assert_eq!(last.bounds.lo, [-2.0, -2.0, 0.0]);
    assert_eq!(last.bounds.hi, [2.0, 2.0, 4.0]);
    // "6 2 1.93 1.84 0.255 0.1 -0.2 -0.3 -4.32826e-18 0 -0.0353429 0 0 0 0.15 0.0353429 -2 3 0"
    assert_eq!(last.get(0, last.col("id").unwrap()), Some(6.0));
    let r = last.row_of_id(6).unwrap();
    assert_eq!(last.get(r, last.col("y").unwrap()), Some(1.84));
    assert_eq!(last.get(r, last.col("fx").unwrap()), Some(-4.32826e-18));
    assert_eq!(last.get(r, last.col("ix").unwrap()), Some(-2.0));
    assert_eq!(last.get(r, last.col("iy").unwrap()), Some(3.0));
    // "2 2 0.53 -0.06 1.155 ..."
    let r2 = last.row_of_id(2).unwrap();
    assert_eq!(last.row(r2).unwrap()[..5], [2.0, 2.0, 0.53, -0.06, 1.155]);
    assert_eq!(last.get(r2, 99), None);
}

#[test]
fn reads_liggghts_custom_dump_with_trailing_spaces() {
    let f = read("lig_custom.dump");
    assert_eq!(f.iter().map(|f| f.timestep).collect::<Vec<_>>(), [0, 1000, 2000, 3000]);
    let l = &f[3];
    assert_eq!(l.columns.last().map(String::as_str), Some("iz"));
    assert_eq!(l.bounds.boundary, ["pp", "pp", "ff"]);
    assert_eq!(l.bounds.hi, [0.02, 0.02, 0.04]);
    // "3 1 -0.00204209 -0.00291581 0.00204142 0.0713395 -0.142679 0.0751261 0 0 -0.000821841 71.246 35.623 0 ..."
    let r = l.row_of_id(3).unwrap();
    assert_eq!(l.get(r, l.col("x").unwrap()), Some(-0.00204209));
    assert_eq!(l.get(r, l.col("omegay").unwrap()), Some(35.623));
    let r6 = l.row_of_id(6).unwrap();
    assert_eq!(l.get(r6, l.col("ix").unwrap()), Some(1.0));
    assert_eq!(l.column("radius").unwrap().iter().filter(|&&x| x == 0.0015).count(), 3);
}

#[test]
fn reads_triclinic_and_gzip() {
    let t = read("lmp_tri_custom.dump");
    let b = &t[0].bounds;
    // "ITEM: BOX BOUNDS xy xz yz pp pp fm" / "-2 2.75 0.5" / "-2.1 2 0.25" / "0 4 -0.1" (deck: prism -2 2 -2 2 0 4 0.5 0.25 -0.1)
    assert_eq!(b.tilt, Some([0.5, 0.25, -0.1]));
    assert_eq!(b.lo, [-2.0, -2.0, 0.0]);
    assert_eq!(b.hi, [2.0, 2.0, 4.0]);
    let g = read("lmp_custom.dump.gz");
    assert_eq!(g.len(), 4);
    // "2 2 0.51 -0.02 1.195" at step 100
    let r = g[1].row_of_id(2).unwrap();
    assert_eq!(g[1].row(r).unwrap(), [2.0, 2.0, 0.51, -0.02, 1.195]);
    assert!(dump::info(p("lmp_custom.dump.gz")).unwrap().gzip);
}

/// Read an engine-written file and write it back with the same settings:
/// the bytes must be identical.
fn rewrite_same(name: &str, opts: DumpOptions, out_name: Option<&str>) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join(out_name.unwrap_or("out.dump"));
    let mut w = DumpWriter::create(&out, opts).unwrap();
    for f in read(name) {
        w.write_frame(&f).unwrap();
    }
    w.close().unwrap();
    let want = std::fs::read_to_string(p(name)).unwrap();
    let got = std::fs::read_to_string(&out).unwrap();
    assert_eq!(got, want, "rewriting {name} changed bytes");
}

const LMP_COLS: &[&str] =
    &["id", "type", "x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz", "omegax", "omegay", "omegaz", "radius", "mass", "ix", "iy", "iz"];

#[test]
fn writes_lammps_custom_and_atom_byte_for_byte() {
    rewrite_same("lmp_custom.dump", DumpOptions::custom(Engine::Lammps, 100, LMP_COLS), None);
    rewrite_same("lmp_atom.dump", DumpOptions::atom(Engine::Lammps, 100), None);
    let mut o = DumpOptions::atom(Engine::Lammps, 100);
    o.image = true;
    o.sort = Some(SortBy::Id);
    rewrite_same("lmp_atom_image.dump", o, None);
    let mut o = DumpOptions::atom(Engine::Lammps, 100);
    o.scale = false;
    rewrite_same("lmp_atom_unscaled.dump", o, None);
    rewrite_same("lmp_tri_custom.dump", DumpOptions::custom(Engine::Lammps, 10, &["id", "type", "x", "y", "z", "mass", "ix", "iy", "iz"]), None);
    let mut o = DumpOptions::atom(Engine::Lammps, 10);
    o.image = true;
    rewrite_same("lmp_tri_atom.dump", o, None);
}

#[test]
fn writes_lammps_dump_modify_formats_byte_for_byte() {
    let mut o = DumpOptions::custom(Engine::Lammps, 100, &["id", "type", "x", "y", "z"]);
    o.formats = vec![FormatSpec::Line("%5d %3d %10.4f %10.4f %10.4e".into())];
    rewrite_same("lmp_fmt_line.dump", o, None);
    let mut o = DumpOptions::custom(Engine::Lammps, 100, &["id", "type", "x", "vx", "mass"]);
    o.formats = vec![FormatSpec::Float("%12.6f".into()), FormatSpec::Int("%4d".into())];
    o.sort = Some(SortBy::Column(1, true));
    rewrite_same("lmp_fmt_float.dump", o, None);
    let mut o = DumpOptions::custom(Engine::Lammps, 100, &["id", "type", "x", "y", "z"]);
    o.formats = vec![FormatSpec::Line("%d %d %.3f %.3f %.3f".into()), FormatSpec::Column(3, "%8.3e".into())];
    o.sort = Some(SortBy::Id);
    rewrite_same("lmp_fmt_col.dump", o, None);
}

#[test]
fn writes_padded_multi_file_dumps_like_lammps() {
    let dir = tempfile::tempdir().unwrap();
    let mut o = DumpOptions::custom(Engine::Lammps, 150, &["id", "x"]);
    o.pad = 5;
    o.first = true;
    let mut w = DumpWriter::create(dir.path().join("lmp_pad_*.dump"), o).unwrap();
    assert!(w.is_due(0, true) && w.is_due(150, false) && !w.is_due(100, false));
    for name in ["lmp_pad_00000.dump", "lmp_pad_00150.dump", "lmp_pad_00300.dump"] {
        for f in read(name) {
            w.write_frame(&f).unwrap();
        }
        assert_eq!(std::fs::read_to_string(dir.path().join(name)).unwrap(), std::fs::read_to_string(p(name)).unwrap());
    }
}

#[test]
fn writes_liggghts_custom_byte_for_byte() {
    rewrite_same("lig_custom.dump", DumpOptions::custom(Engine::Liggghts, 1000, LMP_COLS), None);
    let mut o = DumpOptions::custom(Engine::Liggghts, 1000, &["id", "type", "x", "y", "z"]);
    o.sort = Some(SortBy::Id);
    rewrite_same("lig_sorted.dump", o, None);
    let mut o = DumpOptions::custom(Engine::Liggghts, 1000, &["id", "type", "x", "y", "z"]);
    o.formats = vec![FormatSpec::Line("%5d %3d %10.4f %10.4f %10.4e".into())];
    rewrite_same("lig_fmt.dump", o, None);
    assert!(DumpWriter::create(std::env::temp_dir().join("x.dump"), DumpOptions::atom(Engine::Liggghts, 1)).is_err());
}

#[test]
fn gzip_round_trip_matches_lammps_gzip_content() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("round.dump.gz");
    let mut w = DumpWriter::create(&out, DumpOptions::custom(Engine::Lammps, 100, &["id", "type", "x", "y", "z"])).unwrap();
    let src = read("lmp_custom.dump.gz");
    for f in &src {
        w.write_frame(f).unwrap();
    }
    w.close().unwrap();
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[..2], &[0x1f, 0x8b], "not gzip");
    let mut d = flate2::read::MultiGzDecoder::new(&bytes[..]);
    let mut text = String::new();
    std::io::Read::read_to_string(&mut d, &mut text).unwrap();
    let mut want = String::new();
    std::io::Read::read_to_string(&mut flate2::read::MultiGzDecoder::new(std::fs::File::open(p("lmp_custom.dump.gz")).unwrap()), &mut want).unwrap();
    assert_eq!(text, want);
    assert_eq!(dump::read_all(&out).unwrap(), src);
}

#[test]
fn killed_gzip_run_leaves_complete_frames_readable() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("killed.dump.gz");
    let src = read("lmp_custom.dump");
    let mut w = DumpWriter::create(&out, DumpOptions::custom(Engine::Lammps, 100, LMP_COLS)).unwrap();
    w.write_frame(&src[0]).unwrap();
    w.write_frame(&src[1]).unwrap();
    // Snapshot the file as a kill would leave it: no gzip trailer.
    let snapshot = std::fs::read(&out).unwrap();
    drop(w);
    let killed = dir.path().join("snap.dump.gz");
    std::fs::write(&killed, snapshot).unwrap();
    let got: Vec<Frame> = DumpReader::open(&killed).unwrap().collect::<Result<_, _>>().unwrap();
    assert_eq!(got, src[..2].to_vec());
}

#[test]
fn truncated_last_frame_keeps_complete_frames() {
    let text = std::fs::read_to_string(p("lmp_custom.dump")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // Cut inside the 4th frame (timestep 300): after its 2nd atom line, and in the middle of a line.
    let start4 = text.match_indices("ITEM: TIMESTEP").nth(3).unwrap().0;
    let atoms4 = start4 + text[start4..].find("ITEM: ATOMS").unwrap();
    let line_ends: Vec<usize> = text[atoms4..].match_indices('\n').map(|(i, _)| atoms4 + i + 1).collect();
    for (cut, what) in [
        (line_ends[2], "2 of 6 atom lines"),
        (line_ends[3] - 7, "2 of 6 atom lines present, the next one is cut"),
        (start4 + 20, "file ends in the middle of a line"),
    ] {
        let f = dir.path().join("cut.dump");
        std::fs::write(&f, &text[..cut]).unwrap();
        let mut r = DumpReader::open(&f).unwrap();
        let mut ok = 0;
        let mut err = None;
        for x in &mut r {
            match x {
                Ok(fr) => {
                    assert_eq!(fr.natoms, 6);
                    ok += 1
                }
                Err(e) => err = Some(e.message()),
            }
        }
        assert_eq!(ok, 3, "cut at {cut}");
        let err = err.expect("truncation must be reported");
        assert!(err.contains("frame 4 (timestep 300)") && err.contains(what), "{err}");
        assert!(r.truncated());
        let inf = dump::info(&f).unwrap();
        assert_eq!(inf.timesteps, [0, 100, 200]);
        assert!(inf.render().contains("truncated: yes"), "{}", inf.render());
    }
}

#[test]
fn malformed_input_is_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("bad.dump");
    let text = std::fs::read_to_string(p("lmp_custom.dump")).unwrap().replacen("0.0837758 1 0 0", "0.0837758 oops 0 0", 1);
    std::fs::write(&f, text).unwrap();
    let items: Vec<_> = DumpReader::open(&f).unwrap().collect();
    assert_eq!(items.len(), 1);
    let msg = items[0].as_ref().unwrap_err().message();
    assert!(msg.contains("bad.dump:11: 'oops' is not a number"), "{msg}");
    assert!(dump::info(&f).is_err() || dump::info(&f).is_ok()); // info counts fields only; never panics
    std::fs::write(&f, b"\x00\xff garbage\n").unwrap();
    assert!(DumpReader::open(&f).unwrap().next().unwrap().is_err());
}

#[test]
fn info_renders_summary() {
    let inf = dump::info(p("lig_custom.dump")).unwrap();
    assert_eq!(inf.frames(), 4);
    assert_eq!(inf.atoms, [7, 7, 7, 7]);
    let r = inf.render();
    assert!(r.contains("frames: 4 complete, timesteps 0 .. 3000 every 1000"), "{r}");
    assert!(r.contains("atoms: 7 per frame"), "{r}");
    assert!(r.contains("boundary pp pp ff"), "{r}");
    assert!(r.contains("truncated: no"), "{r}");
}

fn run_engine(exe: &str, dir: &Path, deck: &str) -> String {
    std::fs::write(dir.join("in.check"), deck).unwrap();
    let out = Command::new(exe).args(["-in", "in.check", "-log", "none", "-echo", "none"]).current_dir(dir).output().unwrap();
    let s = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !s.contains("ERROR"), "{exe} failed:\n{s}");
    s
}

fn positions(f: &Frame) -> Vec<[i64; 3]> {
    let (x, y, z) = (f.col("x").unwrap(), f.col("y").unwrap(), f.col("z").unwrap());
    let mut v: Vec<[i64; 3]> = (0..f.natoms).map(|r| [x, y, z].map(|c| (f.get(r, c).unwrap() * 1e6).round() as i64)).collect();
    v.sort();
    v
}

#[test]
fn engines_read_dump_accepts_written_files() {
    let dir = tempfile::tempdir().unwrap();
    if on_path("lmp") {
        let src = read("lmp_custom.dump");
        let mut w = DumpWriter::create(dir.path().join("w.dump"), DumpOptions::custom(Engine::Lammps, 100, LMP_COLS)).unwrap();
        for f in &src {
            w.write_frame(f).unwrap();
        }
        w.close().unwrap();
        let log = run_engine(
            "lmp",
            dir.path(),
            "atom_style sphere\nboundary p p fm\nregion reg block -2 2 -2 2 0 4 units box\ncreate_box 2 reg\n\
             read_dump w.dump 200 x y z vx vy vz box yes add yes\nwrite_dump all custom back.dump id type x y z\n",
        );
        assert!(log.contains("6 atoms added"), "{log}");
        let back = dump::read_all(dir.path().join("back.dump")).unwrap();
        assert_eq!(positions(&back[0]), positions(&src[2]));
    }
    if on_path("liggghts") {
        let src = read("lig_custom.dump");
        let mut w = DumpWriter::create(dir.path().join("wl.dump"), DumpOptions::custom(Engine::Liggghts, 1000, LMP_COLS)).unwrap();
        for f in &src {
            w.write_frame(f).unwrap();
        }
        w.close().unwrap();
        let log = run_engine(
            "liggghts",
            dir.path(),
            "atom_style granular\nboundary p p f\nregion reg block -0.02 0.02 -0.02 0.02 0 0.04 units box\ncreate_box 2 reg\n\
             read_dump wl.dump 3000 x y z vx vy vz radius box yes add yes\nwrite_dump all custom backl.dump id type x y z\n",
        );
        assert!(log.contains("7 atoms added"), "{log}");
        let back = dump::read_all(dir.path().join("backl.dump")).unwrap();
        assert_eq!(positions(&back[0]), positions(&src[3]));
    }
}

/// A LIGGGHTS deck dumping into a folder that does not exist: LIGGGHTS 3.8
/// creates it when the dump is defined (custom and custom/vtk alike), so
/// demx does too and writes the same files; LAMMPS 2021 stops ("Cannot open
/// dump file"), and so does demx on a LAMMPS deck. `demx check` creates
/// nothing.
#[test]
fn liggghts_dumps_create_their_folders_as_the_engine_does() {
    let deck = "atom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\n\
region reg block 0 0.01 0 0.01 0 0.01 units box\ncreate_box 1 reg\nneighbor 0.0002 bin\n\
fix m1 all property/global youngsModulus peratomtype 1.e7\nfix m2 all property/global poissonsRatio peratomtype 0.3\n\
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\nfix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 1e-6\n\
create_atoms 1 single 0.005 0.005 0.005 units box\nset atom 1 diameter 0.002 density 2500\nfix integr all nve/sphere\n\
dump d all custom 5 post/deep/d*.txt id x y z\nrun 10\n";
    let b = crate::common::engine_and_demx("liggghts", "in.deck", &[("in.deck", deck)]);
    let names = |d: &Path| -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(d.join("post/deep")).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    };
    assert_eq!(names(b.theirs.path()), ["d0.txt", "d10.txt", "d5.txt"], "LIGGGHTS made the folder and wrote three frames");
    assert_eq!(names(b.ours.path()), names(b.theirs.path()));
    // check writes nothing: no folder either
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("in.deck"), deck).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir.path()).args(["check", "in.deck"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!dir.path().join("post").exists(), "demx check created the dump's folder");
    // a LAMMPS deck does not get its folder (the engine stops)
    let lammps = "units si\natom_style sphere\nboundary f f f\nregion box block 0 0.01 0 0.01 0 0.01\ncreate_box 1 box\n\
create_atoms 1 single 0.005 0.005 0.005\nset type 1 diameter 0.001 density 2500\ncomm_modify vel yes\n\
pair_style gran/hooke 2e5 NULL 50 NULL 0.5 0\npair_coeff * *\nfix 1 all nve/sphere\ntimestep 1e-5\n\
dump d all custom 5 sub/d.txt id x\nrun 10\n";
    std::fs::write(dir.path().join("in.lammps"), lammps).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_demx")).current_dir(dir.path()).args(["run", "in.lammps", "--log", "none"]).output().unwrap();
    assert!(!o.status.success() && !dir.path().join("sub").exists(), "a LAMMPS deck's dump folder was made: {}", String::from_utf8_lossy(&o.stderr));
}
