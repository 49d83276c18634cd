//! Analytic checks through the whole engine: decks written here are run with
//! `demx run` and their dumps compared with closed forms (free fall, LIGGGHTS
//! Hertz restitution, Hertz contact duration, elastic energy and momentum,
//! slip onset of a sphere on an incline). Complements the law-level checks in
//! tests/it/physics_collisions.rs.

use demx::io::dump::{DumpReader, Frame};
use std::f64::consts::PI;
use std::process::Command;

const RHO: f64 = 2500.0;
const Y: f64 = 1.0e7;
const NU: f64 = 0.3;

/// A LIGGGHTS deck: one type (wall type 1 shares it), box `[-b, b]^2 x [zlo, zhi]`.
fn liggghts_deck(e: f64, mu: f64, dt: f64, zlo: f64, body: &str) -> String {
    format!(
        "atom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\nunits si\n\
         region reg block -0.05 0.05 -0.05 0.05 {zlo} 1.0 units box\ncreate_box 1 reg\n\
         neighbor 0.0002 bin\nneigh_modify delay 0\n\
         fix m1 all property/global youngsModulus peratomtype {Y:e}\n\
         fix m2 all property/global poissonsRatio peratomtype {NU}\n\
         fix m3 all property/global coefficientRestitution peratomtypepair 1 {e}\n\
         fix m4 all property/global coefficientFriction peratomtypepair 1 {mu}\n\
         pair_style gran model hertz tangential history\npair_coeff * *\ntimestep {dt:e}\n{body}"
    )
}

fn dump_line(every: u64) -> String {
    format!(
        "dump d all custom {every} dump.out id type x y z vx vy vz omegax omegay omegaz fx fy fz radius\n\
         dump_modify d format \"%d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\n"
    )
}

fn run(deck: &str) -> Vec<Frame> {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("in.deck"), deck).expect("write deck");
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["run", "--quiet", "--log", "none", "in.deck"])
        .output()
        .expect("run demx");
    assert!(out.status.success(), "demx failed: {}\n{deck}", String::from_utf8_lossy(&out.stderr));
    DumpReader::open(dir.path().join("dump.out")).expect("dump").collect::<Result<Vec<_>, _>>().expect("frames")
}

fn val(f: &Frame, id: u64, col: &str) -> f64 {
    let r = f.row_of_id(id).unwrap_or_else(|| panic!("atom {id} missing"));
    f.get(r, f.col(col).expect("column")).expect("value")
}

fn mass(r: f64) -> f64 {
    RHO * 4.0 / 3.0 * PI * r * r * r
}

/// E* of two equal materials with F = 4/3 E* sqrt(R*) delta^3/2.
fn e_star() -> f64 {
    Y / (2.0 * (1.0 - NU * NU))
}

#[test]
fn free_fall_matches_parabola() {
    let (z0, v0, g, dt) = (0.5, 2.0, 9.81, 1e-4);
    let body = format!(
        "create_atoms 1 single 0.0 0.0 {z0} units box\nset atom 1 diameter 0.002\nset atom 1 density {RHO}\n\
         velocity all set 0.1 0.0 {v0} units box\nfix grav all gravity {g} vector 0.0 0.0 -1.0\nfix integr all nve/sphere\n{}run 2000\n",
        dump_line(100)
    );
    let frames = run(&liggghts_deck(0.5, 0.5, dt, 0.0, &body));
    assert_eq!(frames.len(), 21);
    for f in &frames {
        let t = f.timestep as f64 * dt;
        let z = z0 + v0 * t - 0.5 * g * t * t;
        let vz = v0 - g * t;
        assert!((val(f, 1, "z") - z).abs() <= 1e-9 * z.abs(), "z at {t}: {} vs {z}", val(f, 1, "z"));
        assert!((val(f, 1, "vz") - vz).abs() <= 1e-9 * v0, "vz at {t}: {} vs {vz}", val(f, 1, "vz"));
        assert!((val(f, 1, "x") - 0.1 * t).abs() <= 1e-9 * (0.1 * t).max(1e-3));
    }
}

/// Hertz contact duration estimate 2.87 (m*^2 / (R* E*^2 v))^(1/5), generous
/// enough to size runs (damping makes it longer by a few %).
fn tc_estimate(m_eff: f64, r_eff: f64, v: f64) -> f64 {
    2.87 * (m_eff * m_eff / (r_eff * e_star() * e_star() * v)).powf(0.2)
}

/// Effective restitution of a head-on sphere-sphere impact at relative speed `v`.
fn restitution_pair(e: f64, v: f64) -> f64 {
    let r = 0.001;
    let gap = 1e-6;
    let dt = 2e-7;
    let tc = tc_estimate(0.5 * mass(r), 0.5 * r, v);
    let steps = ((gap / v + 1.5 * tc) / dt).ceil() as u64;
    let body = format!(
        "create_atoms 1 single {} 0.0 0.0 units box\ncreate_atoms 1 single {} 0.0 0.0 units box\n\
         set atom 1*2 diameter {}\nset atom 1*2 density {RHO}\ngroup a id 1\ngroup b id 2\n\
         velocity a set {} 0.0 0.0 units box\nvelocity b set {} 0.0 0.0 units box\nfix integr all nve/sphere\n{}run {steps}\n",
        -(r + gap / 2.0),
        r + gap / 2.0,
        2.0 * r,
        v / 2.0,
        -v / 2.0,
        dump_line(steps)
    );
    let frames = run(&liggghts_deck(e, 0.5, dt, -0.05, &body));
    let last = frames.last().expect("frames");
    assert_eq!(val(last, 1, "fx"), 0.0, "still in contact at the end");
    (val(last, 2, "vx") - val(last, 1, "vx")) / v
}

/// Effective restitution of a sphere hitting the zplane wall at speed `v`.
fn restitution_wall(e: f64, v: f64) -> f64 {
    let r = 0.001;
    let gap = 1e-6;
    let dt = 2e-7;
    let tc = tc_estimate(mass(r), r, v);
    let steps = ((gap / v + 1.5 * tc) / dt).ceil() as u64;
    let body = format!(
        "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n\
         create_atoms 1 single 0.0 0.0 {} units box\nset atom 1 diameter {}\nset atom 1 density {RHO}\n\
         velocity all set 0.0 0.0 {} units box\nfix integr all nve/sphere\n{}run {steps}\n",
        r + gap,
        2.0 * r,
        -v,
        dump_line(steps)
    );
    let frames = run(&liggghts_deck(e, 0.5, dt, 0.0, &body));
    let last = frames.last().expect("frames");
    assert_eq!(val(last, 1, "fz"), 0.0, "still in contact at the end");
    val(last, 1, "vz") / v
}

#[test]
fn liggghts_hertz_restitution_sphere_sphere() {
    for v in [0.1, 1.0, 5.0] {
        let e = restitution_pair(0.5, v);
        eprintln!("sphere-sphere e_eff at {v} m/s: {e}");
        assert!((e - 0.5).abs() <= 0.005 * 0.5, "sphere-sphere at {v} m/s: e = {e}");
    }
}

#[test]
fn liggghts_hertz_restitution_sphere_wall() {
    for v in [0.1, 1.0, 5.0] {
        let e = restitution_wall(0.5, v);
        eprintln!("sphere-wall e_eff at {v} m/s: {e}");
        assert!((e - 0.5).abs() <= 0.005 * 0.5, "sphere-wall at {v} m/s: e = {e}");
    }
}

/// Elastic Hertz impact of unequal spheres (e = 1, so LIGGGHTS damping is
/// zero): contact duration 2 (delta_max / v) I with
/// I = integral_0^1 dx / sqrt(1 - x^(5/2)) and
/// delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5); kinetic energy and
/// momentum conserved.
#[test]
fn elastic_hertz_duration_energy_momentum() {
    let (r1, r2) = (0.001, 0.0008);
    let (v1, v2) = (1.0, -1.5);
    let dt = 1e-7;
    let gap = 1e-7;
    let body = format!(
        "create_atoms 1 single {} 0.0 0.0 units box\ncreate_atoms 1 single {} 0.0 0.0 units box\n\
         set atom 1 diameter {}\nset atom 2 diameter {}\nset atom 1*2 density {RHO}\ngroup a id 1\ngroup b id 2\n\
         velocity a set {v1} 0.0 0.0 units box\nvelocity b set {v2} 0.0 0.0 units box\nfix integr all nve/sphere\n{}run 2400\n",
        -r1 - gap / 2.0,
        r2 + gap / 2.0,
        2.0 * r1,
        2.0 * r2,
        dump_line(1)
    );
    let frames = run(&liggghts_deck(1.0, 0.5, dt, -0.05, &body));
    let touching: Vec<u64> = frames.iter().filter(|f| val(f, 1, "fx") != 0.0).map(|f| f.timestep).collect();
    let (first, last) = (*touching.first().expect("contact"), *touching.last().expect("contact"));
    assert_eq!(touching.len() as u64, last - first + 1, "contact not continuous");
    assert!(last < frames.last().unwrap().timestep, "contact did not end");
    let measured = (last - first + 1) as f64 * dt;
    let (m1, m2) = (mass(r1), mass(r2));
    let m_eff = m1 * m2 / (m1 + m2);
    let r_eff = r1 * r2 / (r1 + r2);
    let v = v1 - v2;
    let delta_max = (15.0 * m_eff * v * v / (16.0 * e_star() * r_eff.sqrt())).powf(0.4);
    // midpoint rule with substitution x = 1 - u^2 to remove the end singularity
    let n = 200_000;
    let mut integral = 0.0;
    for k in 0..n {
        let u = (k as f64 + 0.5) / n as f64;
        let x: f64 = 1.0 - u * u;
        integral += 2.0 * u / (1.0 - x.powf(2.5)).sqrt() / n as f64;
    }
    let tc = 2.0 * delta_max / v * integral;
    eprintln!("contact duration {measured} s, Hertz {tc} s");
    assert!((measured - tc).abs() <= 0.01 * tc, "contact duration {measured} vs Hertz {tc}");
    let first_f = &frames[0];
    let last_f = frames.last().unwrap();
    let ke = |f: &Frame| 0.5 * m1 * val(f, 1, "vx").powi(2) + 0.5 * m2 * val(f, 2, "vx").powi(2);
    let p = |f: &Frame| m1 * val(f, 1, "vx") + m2 * val(f, 2, "vx");
    let (k0, k1) = (ke(first_f), ke(last_f));
    assert!((k1 - k0).abs() <= 1e-6 * k0, "energy {k0} -> {k1}");
    let pscale = m1 * v1.abs() + m2 * v2.abs();
    assert!((p(last_f) - p(first_f)).abs() <= 1e-6 * pscale, "momentum {} -> {}", p(first_f), p(last_f));
    // and the spheres really exchanged momentum (v1' = ((m1-m2) v1 + 2 m2 v2)/(m1+m2))
    let v1_after = ((m1 - m2) * v1 + 2.0 * m2 * v2) / (m1 + m2);
    assert!((val(last_f, 1, "vx") - v1_after).abs() <= 1e-6 * v, "v1' {} vs {v1_after}", val(last_f, 1, "vx"));
}

/// Slip velocity at the contact point of a sphere resting on the zplane
/// wall under gravity tilted by `theta_deg` in x, after the run.
fn incline_slip(mu: f64, theta_deg: f64) -> (f64, f64) {
    let r = 0.001;
    let th = theta_deg.to_radians();
    let body = format!(
        "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n\
         create_atoms 1 single 0.0 0.0 {r} units box\nset atom 1 diameter {}\nset atom 1 density {RHO}\n\
         fix grav all gravity 9.81 vector {} 0.0 {}\nfix integr all nve/sphere\n{}run 20000\n",
        2.0 * r,
        th.sin(),
        -th.cos(),
        dump_line(20000)
    );
    let frames = run(&liggghts_deck(0.5, mu, 1e-6, 0.0, &body));
    let f = frames.last().unwrap();
    let vx = val(f, 1, "vx");
    // contact point at -r z: v_c = v + omega x (-r z) -> x component vx - r omega_y
    (vx - r * val(f, 1, "omegay"), vx)
}

/// A free sphere on an incline rolls without slipping while
/// tan(theta) <= 7/2 mu (the friction needed for rolling, 2/7 m g sin(theta),
/// reaches mu m g cos(theta)); above that it slips with slip acceleration
/// g (sin(theta) - 7/2 mu cos(theta)). Checked 1 degree either side.
#[test]
fn sphere_on_incline_slips_at_tan_theta_of_seven_halves_mu() {
    let mu: f64 = 0.2;
    let theta_c = (3.5 * mu).atan().to_degrees();
    let (slip_below, v_below) = incline_slip(mu, theta_c - 1.0);
    let (slip_above, v_above) = incline_slip(mu, theta_c + 1.0);
    eprintln!("theta_c {theta_c}: slip {slip_below} (v {v_below}) below, {slip_above} (v {v_above}) above");
    assert!(v_below > 0.05 && v_above > 0.05, "not moving down the slope: {v_below} {v_above}");
    assert!(slip_below.abs() < 1e-3 * v_below, "slips below the threshold: {slip_below} at v {v_below}");
    let th = (theta_c + 1.0).to_radians();
    let t = 0.02;
    let expect = 9.81 * (th.sin() - 3.5 * mu * th.cos()) * t;
    assert!(slip_above > 0.5 * expect, "does not slip above the threshold: {slip_above} (expected about {expect})");
}
