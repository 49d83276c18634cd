//! The step's head (every fix's initial_integrate and the skin check of
//! the pair list) and its tail (the cross-block shares of the pair forces,
//! every fix's post_force, every fix's final_integrate) run fused, chunk by
//! chunk, where the fixes act particle by particle; when nothing is output
//! and no fix has an end_of_step at a step, its tail and the next step's
//! head run as one pass. That must change no bit (nor any pair-list build, which would reorder sums): a bed of
//! 3,375 overlapping spheres (more than one block of the pair pass, so pairs
//! cross blocks) bursts apart and falls with spin onto a frictional floor
//! with rolling resistance, under gravity, on 2 threads; the fused run and
//! the run with every hook called on its own write the same dump bytes. A
//! second deck gives gravity a variable magnitude, which its hook evaluates
//! itself (not fused), between fused stages; a third adds a moving mesh,
//! whose initial_integrate needs the whole simulation; a fourth freezes the
//! bottom layer and spheres among the others (`fix freeze`), whose partners
//! then weigh as walls.

use demx::cli::{run_deck, DeckArgs};
use demx::engine::sim::with_unfused_tail;

/// 15 x 15 x 15 spheres of 1 mm radius, 1.98 mm apart (overlapping), with
/// sideways speed and spin, from 1.2 mm above the floor.
fn data() -> String {
    let k = 15;
    let n = k * k * k;
    let mut s =
        format!("overlapping spheres\n\n{n} atoms\n1 atom types\n\n-0.016 0.016 xlo xhi\n-0.016 0.016 ylo yhi\n0.0 0.06 zlo zhi\n\nAtoms\n\n");
    let frac = |i: usize, a: f64| (i as f64 * a).fract();
    for i in 0..n {
        let (x, y, z) = (-0.0139 + 0.00198 * (i % k) as f64, -0.0139 + 0.00198 * ((i / k) % k) as f64, 0.0012 + 0.00198 * (i / (k * k)) as f64);
        s += &format!("{} 1 0.002 2500 {x} {y} {z}\n", i + 1);
    }
    s += "\nVelocities\n\n";
    for i in 0..n {
        let (vx, vy) = (0.5 * (frac(i, 0.414_214) - 0.5), 0.5 * (frac(i, 0.732_051) - 0.5));
        let (wx, wy, wz) = (200.0 * (frac(i, 0.317_1) - 0.5), 200.0 * (frac(i, 0.576_3) - 0.5), 50.0 * (frac(i, 0.913_7) - 0.5));
        s += &format!("{} {vx} {vy} 0 {wx} {wy} {wz}\n", i + 1);
    }
    s
}

fn deck(dir: &str, gravity: &str, after: &str) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary p p f\nnewton off\ncommunicate single vel yes\nunits si\n\
         read_data {dir}/data.spheres\nneighbor 0.0003 bin\nneigh_modify delay 0\n\
         fix m1 all property/global youngsModulus peratomtype 1.e7\n\
         fix m2 all property/global poissonsRatio peratomtype 0.3\n\
         fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n\
         fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n\
         fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n\
         pair_style gran model hertz tangential history rolling_friction epsd2\npair_coeff * *\ntimestep 5e-6\n\
         fix floor all wall/gran model hertz tangential history rolling_friction epsd2 primitive type 1 zplane 0.0\n\
         {gravity}\nfix integr all nve/sphere\n{after}\n\
         dump d all custom 100 {dir}/dump.spheres id x y z vx vy vz omegax omegay omegaz fx fy fz\n\
         dump_modify d sort id format \"%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\n\
         thermo 100\nthermo_style custom step atoms ke\nrun 600\n"
    )
}

/// The dump of one run on 2 threads, fused or not, and its pair-list
/// builds; `after` goes after the integrator.
fn run(gravity: &str, after: &str, fused: bool) -> (Vec<u8>, u64) {
    let (dump, _, builds) = run_with(gravity, after, fused);
    (dump, builds)
}

/// As [`run`], with the file `DIR/print.txt` that `after` may write
/// (empty when it writes none).
fn run_with(gravity: &str, after: &str, fused: bool) -> (Vec<u8>, Vec<u8>, u64) {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path().to_str().unwrap().to_string();
    std::fs::write(dir.path().join("data.spheres"), data()).unwrap();
    std::fs::write(dir.path().join("in.spheres"), deck(&d, gravity, &after.replace("DIR", &d))).unwrap();
    std::fs::write(dir.path().join("tilt.stl"), TILT).unwrap();
    let args = DeckArgs { deck: dir.path().join("in.spheres"), var: vec![], perturb: None, var_groups: vec![] };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let go = || {
        let (session, _, r) = run_deck(&args, false, 2, None, true, None, Default::default(), None);
        (r, session.sim.pairs.builds)
    };
    let (r, builds) = pool.install(|| if fused { go() } else { with_unfused_tail(go) });
    assert!(r.is_ok(), "demx failed: {:?}", r.err());
    let printed = std::fs::read(dir.path().join("print.txt")).unwrap_or_default();
    (std::fs::read(dir.path().join("dump.spheres")).expect("dump written"), printed, builds)
}

fn same((a, builds_a): &(Vec<u8>, u64), (b, builds_b): &(Vec<u8>, u64), what: &str) {
    // the skin check decides the same builds (one fused into the head)
    assert_eq!(builds_a, builds_b, "{what}: pair-list builds differ");
    assert!(*builds_a > 3, "{what}: only {builds_a} pair-list builds: the skin check went untested");
    if a != b {
        let at = a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
        let line = a[..at].iter().filter(|&&c| c == b'\n').count() + 1;
        panic!("{what}: the fused step changed the dump from line {line}");
    }
}

#[test]
fn fused_head_and_tail_change_no_bit() {
    let gravity = "fix grav all gravity 9.81 vector 0.0 0.0 -1.0";
    let fused = run(gravity, "", true);
    same(&fused, &run(gravity, "", false), "constant gravity");
    // the spheres pushed each other apart and the bottom layer met the
    // floor: in the last frame some move up and many spin
    let text = String::from_utf8_lossy(&fused.0);
    let last = text.rsplit("ITEM: ATOMS").next().unwrap();
    let rows: Vec<Vec<f64>> = last.lines().skip(1).map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 3375);
    assert!(rows.iter().all(|r| r.iter().all(|v| v.is_finite())));
    let up = rows.iter().filter(|r| r[6] > 0.0).count();
    assert!(up > 100, "only {up} spheres moving up at the end");
    let var = "variable g equal 9.81*(1+step/1000)\nfix grav all gravity v_g vector 0.0 0.0 -1.0";
    let fused_var = run(var, "", true);
    same(&fused_var, &run(var, "", false), "variable gravity");
    assert_ne!(fused_var, fused, "the variable gravity changed nothing");
    // a moving mesh: its initial_integrate (after the integrator's) needs
    // the whole simulation, so the step's tail and the next step's head,
    // fused, must run the integrator's halves on either side of it
    let mesh = "fix cad all mesh/surface file DIR/tilt.stl type 1\n\
                fix w all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad\n\
                fix mv all move/mesh mesh cad linear 0.5 0 0";
    let fused_mesh = run(gravity, mesh, true);
    same(&fused_mesh, &run(gravity, mesh, false), "moving mesh");
    assert_ne!(fused_mesh, fused, "the mesh changed nothing");
    // frozen spheres (the bottom layer and every seventh sphere above it):
    // the fused pass, like the pass of the hooks on their own, gives their
    // partners an infinite mass, and the force the fix takes off them
    // (f_fr, in particle order whichever chunks took it; unequal forces,
    // whose sum's bits depend on its order) has the same bits, printed
    // every 50 steps
    let freeze = "group bottom id <= 225\ngroup spread id 1:3375:7\ngroup low union bottom spread\n\
                  velocity low set 0 0 0\nfix fr low freeze\n\
                  fix pr all print 50 \"$(f_fr[1]:%.17g) $(f_fr[2]:%.17g) $(f_fr[3]:%.17g)\" file DIR/print.txt screen no";
    let (dump, printed, builds) = run_with(gravity, freeze, true);
    let (dump_u, printed_u, builds_u) = run_with(gravity, freeze, false);
    same(&(dump.clone(), builds), &(dump_u, builds_u), "frozen layer");
    assert_ne!((dump, builds), fused, "the frozen layer changed nothing");
    let printed = String::from_utf8(printed).expect("text");
    assert_eq!(printed, String::from_utf8(printed_u).expect("text"), "the freeze's removed force differs when fused");
    // the frozen spheres bear the weight of the others, downwards
    let fz: Vec<f64> = printed.lines().filter_map(|l| l.split_whitespace().nth(2)?.parse().ok()).collect();
    assert!(fz.len() >= 10 && fz.iter().filter(|&&f| f < 0.0).count() > fz.len() / 2, "removed force not printed as expected: {printed}");
}

/// A tilted square across the box, 0.1-0.4 mm above the floor: it touches
/// through the bottom layer of spheres.
const TILT: &str = "solid tilt\nfacet normal 0 0 1\nouter loop\nvertex -0.016 -0.016 0.0001\nvertex 0.016 -0.016 0.0004\n\
vertex 0.016 0.016 0.0004\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -0.016 -0.016 0.0001\n\
vertex 0.016 0.016 0.0004\nvertex -0.016 0.016 0.0001\nendloop\nendfacet\nendsolid tilt\n";
