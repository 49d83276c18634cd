//! Between builds the pair list keeps only the pairs within a small buffer
//! of touching, pruned again from the full list whenever a particle has
//! moved half that buffer (src/engine/neighbor.rs, `PairList::prune`). That
//! must change no bit: a pair left out is apart by more than the buffer, so
//! it adds nothing and holds no history, and the pairs kept are summed in
//! the same order.
//!
//! A bed of 2,304 slightly overlapping spheres (more than one block of the
//! pair pass, so pairs cross blocks) jostles under gravity on a frictional
//! floor for 2,000 steps: slowly enough that the list is pruned tens of
//! times between builds, and long enough that contacts open and close. Its
//! dump (positions, velocities, spins, forces) is compared byte for byte
//! with the run whose list stays full: with LIGGGHTS Hertz, tangential
//! history and epsd2 rolling resistance on the batched pass, the same on the
//! per-contact pass, and the paper's model, whose van der Waals attraction
//! reaches across gaps (the prune adds that reach).

use demx::cli::{run_deck, DeckArgs};
use demx::engine::kernel::with_scalar_pass;
use demx::engine::neighbor::{with_every_prune, without_pruning};

/// 16 x 16 x 9 spheres of 1 mm radius, 1.995 mm apart (overlapping by
/// 5 um), with random velocities up to 10 cm/s and spins.
fn data() -> String {
    let (k, h) = (16, 9);
    let n = k * k * h;
    let mut s = format!("jostling bed\n\n{n} atoms\n1 atom types\n\n-0.016 0.016 xlo xhi\n-0.016 0.016 ylo yhi\n0.0 0.03 zlo zhi\n\nAtoms\n\n");
    let frac = |i: usize, a: f64| (i as f64 * a).fract();
    for i in 0..n {
        let at = |c: usize| -0.01496 + 0.001995 * c as f64;
        let (x, y, z) = (at(i % k), at((i / k) % k), 0.001 + 0.001995 * (i / (k * k)) as f64);
        s += &format!("{} 1 0.002 2500 {x} {y} {z}\n", i + 1);
    }
    s += "\nVelocities\n\n";
    for i in 0..n {
        let v = |a: f64| 0.2 * (frac(i, a) - 0.5);
        let w = |a: f64| 40.0 * (frac(i, a) - 0.5);
        s += &format!("{} {} {} {} {} {} {}\n", i + 1, v(0.414_214), v(0.732_051), v(0.236_068), w(0.317_1), w(0.576_3), w(0.913_7));
    }
    s
}

const STOCK: &str = "fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n\
    pair_style gran model hertz tangential history rolling_friction epsd2\npair_coeff * *\n\
    fix floor all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 1 zplane 0.0\n";

/// The paper's model (templates/packing): van der Waals reaches 10 um
/// beyond touching.
const PAPER: &str = "fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n\
    fix m6 all property/global restitutionReferenceVelocity scalar 1.0\n\
    fix m7 all property/global surfaceEnergy peratomtypepair 1 0.05\n\
    fix m8 all property/global vdwMinDistance scalar 1.65e-10\n\
    fix m9 all property/global vdwCutoff scalar 1e-5\n\
    pair_style gran model hertz/viscoelastic tangential history/paper cohesion vdw rolling_friction epsd/paper\npair_coeff * *\n\
    fix floor all wall/gran model hertz/viscoelastic tangential history/paper rolling_friction epsd/paper primitive type 1 zplane 0.0\n";

fn deck(dir: &str, model: &str) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary p p f\nnewton off\ncommunicate single vel yes\nunits si\n\
         read_data {dir}/data.bed\nneighbor 0.0001 bin\nneigh_modify delay 0\n\
         fix m1 all property/global youngsModulus peratomtype 1.e7\n\
         fix m2 all property/global poissonsRatio peratomtype 0.3\n\
         fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
         fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
         {model}timestep 5e-6\n\
         fix grav all gravity 9.81 vector 0.0 0.0 -1.0\nfix integr all nve/sphere\n\
         dump d all custom 500 {dir}/dump.bed id x y z vx vy vz omegax omegay omegaz fx fy fz\n\
         dump_modify d sort id format \"%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\n\
         thermo 500\nthermo_style custom step atoms ke\nrun 2000\n"
    )
}

/// The dump of one run on 2 threads, its pair-list builds and prunes.
fn run(model: &str, pruned: bool, scalar: bool) -> (Vec<u8>, u64, u64) {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path().to_str().unwrap().to_string();
    std::fs::write(dir.path().join("data.bed"), data()).unwrap();
    std::fs::write(dir.path().join("in.bed"), deck(&d, model)).unwrap();
    let args = DeckArgs { deck: dir.path().join("in.bed"), var: vec![], perturb: None, var_groups: vec![] };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let go = || {
        let (session, _, r) = run_deck(&args, false, 2, None, true, None, Default::default(), None);
        (r, session.sim.pairs.builds, session.sim.pairs.prunes)
    };
    let go = || if scalar { with_scalar_pass(go) } else { go() };
    // every prune the buffer allows: a bed this small and lively keeps too
    // many pairs for prunes to pay, and demx would leave its list full
    let (r, builds, prunes) = pool.install(|| if pruned { with_every_prune(go) } else { without_pruning(go) });
    assert!(r.is_ok(), "demx failed: {:?}", r.err());
    (std::fs::read(dir.path().join("dump.bed")).expect("dump written"), builds, prunes)
}

fn same(model: &str, scalar: bool, what: &str) {
    let (a, builds_a, prunes) = run(model, true, scalar);
    let (b, builds_b, none) = run(model, false, scalar);
    assert_eq!(none, 0, "{what}: the list was pruned with pruning off");
    assert!(prunes >= 20, "{what}: only {prunes} prunes: pruning went untested");
    assert!(builds_a >= 2, "{what}: only {builds_a} builds: contacts did not change much");
    assert_eq!(builds_a, builds_b, "{what}: pair-list builds differ");
    if a != b {
        let at = a.iter().zip(&b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
        let line = a[..at].iter().filter(|&&c| c == b'\n').count() + 1;
        panic!("{what}: the pruned run's dump differs from the full list's at line {line}");
    }
}

#[test]
fn pruning_changes_no_bit_on_the_batched_pass() {
    same(STOCK, false, "hertz/history/epsd2, batched");
}

#[test]
fn pruning_changes_no_bit_on_the_per_contact_pass() {
    same(STOCK, true, "hertz/history/epsd2, per contact");
}

#[test]
fn pruning_changes_no_bit_with_van_der_waals_across_gaps() {
    same(PAPER, false, "paper model with van der Waals");
}
