//! A static primitive wall tries only the particles that were within reach
//! plus the skin of it at the last pair-list build (no particle moves more
//! than half the skin before the next build when every step checks). This
//! must change no bit: 5,041 spheres, too far apart to touch each other,
//! fall from different heights with spin and sideways speed onto a
//! frictional floor with rolling resistance and bounce; the run with a wide
//! skin (the candidate list reused for many steps, on 2 threads: more than
//! one chunk of candidates) must write the same dump bytes as the run with
//! `neigh_modify check no`, which rebuilds every step and so tries every
//! particle against the wall every step.
//!
//! The same fall checks the wall's batches: the floor's contacts run on
//! lanes, eight at a time (`ContactKernel::wall_contacts`), and must give
//! the bits of the contact-by-contact laws, with LIGGGHTS Hertz, history and
//! epsd2, and with the paper's model on the wall.

use demx::cli::{run_deck, DeckArgs};
use demx::engine::kernel::with_scalar_pass;
use std::process::Command;

/// 71 x 71 spheres of 1 mm, 3 mm apart, 0.6-3.6 mm above the floor.
fn data() -> String {
    let k = 71;
    let n = k * k;
    let mut s = format!("spheres over a floor\n\n{n} atoms\n1 atom types\n\n-0.11 0.11 xlo xhi\n-0.11 0.11 ylo yhi\n0.0 0.02 zlo zhi\n\nAtoms\n\n");
    let frac = |i: usize, a: f64| (i as f64 * a).fract();
    for i in 0..n {
        let (x, y) = (-0.105 + 0.003 * (i % k) as f64, -0.105 + 0.003 * (i / k) as f64);
        s += &format!("{} 1 0.001 2500 {x} {y} {}\n", i + 1, 0.0011 + 0.003 * frac(i, 0.618_034));
    }
    s += "\nVelocities\n\n";
    for i in 0..n {
        let (vx, vy, vz) = (0.2 * (frac(i, 0.414_214) - 0.5), 0.2 * (frac(i, 0.732_051) - 0.5), -0.3 * frac(i, 0.236_068));
        let (wx, wy, wz) = (200.0 * (frac(i, 0.317_1) - 0.5), 200.0 * (frac(i, 0.576_3) - 0.5), 50.0 * (frac(i, 0.913_7) - 0.5));
        s += &format!("{} {vx} {vy} {vz} {wx} {wy} {wz}\n", i + 1);
    }
    s
}

const STOCK: &str = "pair_style gran model hertz tangential history rolling_friction epsd2\npair_coeff * *\n\
    fix floor all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 1 zplane 0.0\n";

/// The paper's model (templates/heap, model paper); the wall has no
/// cohesion.
const PAPER: &str = "fix m6 all property/global restitutionReferenceVelocity scalar 1.0\n\
    fix m7 all property/global surfaceEnergy peratomtypepair 1 0.05\n\
    fix m8 all property/global vdwMinDistance scalar 1.65e-10\nfix m9 all property/global vdwCutoff scalar 1e-5\n\
    pair_style gran model hertz/viscoelastic tangential history/paper cohesion vdw rolling_friction epsd/paper\npair_coeff * *\n\
    fix floor all wall/gran model hertz/viscoelastic tangential history/paper rolling_friction epsd/paper primitive type 1 zplane 0.0\n";

/// The deck, reading and writing in `dir`.
fn deck(neigh: &str, model: &str, dir: &str) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary p p f\nnewton off\ncommunicate single vel yes\nunits si\n\
         read_data {dir}/data.spheres\n{neigh}\n\
         fix m1 all property/global youngsModulus peratomtype 1.e7\n\
         fix m2 all property/global poissonsRatio peratomtype 0.3\n\
         fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
         fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
         fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n\
         {model}timestep 5e-6\n\
         fix grav all gravity 9.81 vector 0.0 0.0 -1.0\nfix integr all nve/sphere\n\
         dump d all custom 500 {dir}/dump.spheres id x y z vx vy vz omegax omegay omegaz\n\
         dump_modify d sort id format \"%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\n\
         run 6000\n"
    )
}

/// The dump and the number of pair-list builds of one run.
fn run(neigh: &str, threads: usize) -> (Vec<u8>, u64) {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("data.spheres"), data()).unwrap();
    std::fs::write(dir.path().join("in.spheres"), deck(neigh, STOCK, ".")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", "--log", "none", "--threads", &threads.to_string(), "in.spheres"])
        .output()
        .expect("run demx");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "demx failed: {}", String::from_utf8_lossy(&out.stderr));
    let builds = text.lines().filter_map(|l| l.strip_prefix("Neighbor list builds = ")).map(|v| v.trim().parse::<u64>().expect("build count")).sum();
    (std::fs::read(dir.path().join("dump.spheres")).expect("dump written"), builds)
}

#[test]
fn wall_candidates_change_no_bit() {
    let (every, all_builds) = run("neighbor 0.0005 bin\nneigh_modify delay 0 every 1 check no", 1);
    let (reused, builds) = run("neighbor 0.0005 bin\nneigh_modify delay 0 every 1 check yes", 2);
    // the wide skin really reuses its list: far fewer builds than steps
    assert!(all_builds >= 6000, "check no built {all_builds} times");
    assert!(builds > 5 && builds < 600, "check yes built {builds} times");
    // the spheres reached the floor and bounced: some move up in the last frame
    let text = String::from_utf8_lossy(&reused);
    let last = text.rsplit("ITEM: ATOMS").next().unwrap();
    let up = last.lines().skip(1).filter(|l| l.split_whitespace().nth(6).is_some_and(|v| v.parse::<f64>().unwrap() > 0.0)).count();
    assert!(up > 100, "only {up} spheres moving up at the end");
    if every != reused {
        let at = every.iter().zip(&reused).position(|(a, b)| a != b).unwrap_or(every.len().min(reused.len()));
        let line = every[..at].iter().filter(|&&c| c == b'\n').count() + 1;
        panic!("wall candidates changed the dump from line {line}");
    }
}

/// The dump of the fall on 2 threads, in process, with the wall's contacts
/// (and the pairs') on lanes or one by one.
fn run_in_process(model: &str, scalar: bool) -> Vec<u8> {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path().to_str().unwrap().to_string();
    std::fs::write(dir.path().join("data.spheres"), data()).unwrap();
    std::fs::write(dir.path().join("in.spheres"), deck("neighbor 0.0005 bin\nneigh_modify delay 0", model, &d)).unwrap();
    let args = DeckArgs { deck: dir.path().join("in.spheres"), var: vec![], perturb: None, var_groups: vec![] };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let go = || run_deck(&args, false, 2, None, true, None, Default::default(), None).2;
    let r = pool.install(|| if scalar { with_scalar_pass(go) } else { go() });
    assert!(r.is_ok(), "demx failed: {:?}", r.err());
    std::fs::read(dir.path().join("dump.spheres")).expect("dump written")
}

fn lanes_change_no_bit(model: &str, what: &str) {
    let lanes = run_in_process(model, false);
    let one = run_in_process(model, true);
    // many spheres (radius 0.5 mm) press into the floor at once in some
    // frame: the batches were full
    let text = String::from_utf8_lossy(&lanes);
    let touching = |frame: &str| {
        frame.lines().skip(1).filter(|l| l.split_whitespace().nth(3).and_then(|z| z.parse::<f64>().ok()).is_some_and(|z| z < 0.0005)).count()
    };
    let most = text.split("ITEM: ATOMS").skip(1).map(touching).max().unwrap_or(0);
    assert!(most > 50, "{what}: at most {most} spheres touch the floor at once");
    if lanes != one {
        let at = lanes.iter().zip(&one).position(|(a, b)| a != b).unwrap_or(lanes.len().min(one.len()));
        let line = lanes[..at].iter().filter(|&&c| c == b'\n').count() + 1;
        panic!("{what}: the wall's contacts on lanes changed the dump from line {line}");
    }
}

#[test]
fn wall_contacts_on_lanes_change_no_bit() {
    lanes_change_no_bit(STOCK, "hertz/history/epsd2");
}

#[test]
fn wall_contacts_on_lanes_change_no_bit_with_the_paper_model() {
    lanes_change_no_bit(PAPER, "paper model");
}
