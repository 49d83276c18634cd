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

fn deck(neigh: &str) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary p p f\nnewton off\ncommunicate single vel yes\nunits si\n\
         read_data data.spheres\n{neigh}\n\
         fix m1 all property/global youngsModulus peratomtype 1.e7\n\
         fix m2 all property/global poissonsRatio peratomtype 0.3\n\
         fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
         fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
         fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n\
         pair_style gran model hertz tangential history rolling_friction epsd2\npair_coeff * *\ntimestep 5e-6\n\
         fix floor all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 1 zplane 0.0\n\
         fix grav all gravity 9.81 vector 0.0 0.0 -1.0\nfix integr all nve/sphere\n\
         dump d all custom 500 dump.spheres id x y z vx vy vz omegax omegay omegaz\n\
         dump_modify d sort id format \"%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\n\
         run 6000\n"
    )
}

/// The dump and the number of pair-list builds of one run.
fn run(neigh: &str, threads: usize) -> (Vec<u8>, u64) {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("data.spheres"), data()).unwrap();
    std::fs::write(dir.path().join("in.spheres"), deck(neigh)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", "--log", "none", "--threads", &threads.to_string(), "in.spheres"])
        .output()
        .expect("run demx");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "demx failed: {}", String::from_utf8_lossy(&out.stderr));
    let builds = text
        .lines()
        .filter_map(|l| l.strip_prefix("Neighbor list builds = "))
        .map(|v| v.trim().parse::<u64>().expect("build count"))
        .sum();
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
