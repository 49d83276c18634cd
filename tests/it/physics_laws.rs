//! Unit checks of each contact law against hand-computed values (numbers
//! computed separately with Python from the engines' documented formulas, or
//! scalar formulas written out here), Coulomb caps and torque signs.

use demx::physics::mixing::*;
use demx::physics::normal::gran::{LammpsGranHertz, LammpsGranHooke};
use demx::physics::normal::granular::{GranularDamping, GranularNormal, LammpsGranular};
use demx::physics::normal::hertz::LiggghtsHertz;
use demx::physics::normal::hertz_stiffness::LiggghtsHertzStiffness;
use demx::physics::normal::hooke::LiggghtsHooke;
use demx::physics::normal::hooke_stiffness::LiggghtsHookeStiffness;
use demx::physics::tangential::gran::{LammpsGranHistory, LammpsGranNoHistory};
use demx::physics::tangential::granular::{GranularTangential, LammpsGranularHistory, LammpsLinearNoHistory};
use demx::physics::tangential::history::LiggghtsHistory;
use demx::physics::tangential::no_history::LiggghtsNoHistory;
use demx::physics::*;
use demx::script::source::SourceMap;
use demx::script::source::Span;

const R: f64 = 1e-3;
const M: f64 = 1.0471975511965977e-05; // 2500 kg/m^3 * 4/3 pi (1 mm)^3

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

fn dummy_span() -> Span {
    let map = SourceMap::new();
    let id = map.add("in.test", "pair_style gran".to_string());
    Span::new(id, 0, 4)
}

/// Two equal spheres along z, i above j, overlap `delta`, i moving with `v`.
fn pair(delta: f64, v: V3, wi: V3, wj: V3, dt: f64) -> Contact {
    let n = V3::new(0.0, 0.0, 1.0);
    Contact { n, r: 2.0 * R - delta, delta, ri: R, rj: R, r_eff: R / 2.0, mi: M, mj: M, m_eff: M / 2.0, vr: v, vn: v.dot(&n), wi, wj, dt }
}

/// Sphere i resting on a wall z = 0 (n = +z).
fn wall(delta: f64, v: V3, wi: V3, dt: f64) -> Contact {
    let n = V3::new(0.0, 0.0, 1.0);
    Contact {
        n,
        r: R - delta,
        delta,
        ri: R,
        rj: f64::INFINITY,
        r_eff: R,
        mi: M,
        mj: f64::INFINITY,
        m_eff: M,
        vr: v,
        vn: v.dot(&n),
        wi,
        wj: V3::zeros(),
        dt,
    }
}

fn liggghts_params(e: f64) -> PairParams {
    let mut m = LiggghtsMaterials::default();
    m.n_types = 1;
    m.youngs = Some(vec![1e7]);
    m.poisson = Some(vec![0.3]);
    m.restitution = Some(vec![e]);
    m.friction = Some(vec![0.5]);
    m.char_vel = Some(1.0);
    liggghts_pair_params(&m, &LiggghtsSettings::default(), dummy_span()).unwrap()[0]
}

#[test]
fn mixing_matches_liggghts_formulas() {
    let p = liggghts_params(0.5);
    assert!(rel(p.y_eff, 5494505.494505494) < 1e-14);
    assert!(rel(p.g_eff, 1131221.7194570135) < 1e-14);
    assert!(rel(p.beta, -0.2154537619662468) < 1e-14);
    // two different materials
    let y = liggghts_y_eff(1e7, 0.3, 7e10, 0.25);
    assert!(rel(y, 1.0 / (0.91 / 1e7 + 0.9375 / 7e10)) < 1e-14);
    assert_eq!(r_eff(1.0, f64::INFINITY), 1.0);
    assert_eq!(m_eff(2.0, f64::INFINITY), 2.0);
    assert!(rel(m_eff(2.0, 2.0), 1.0) < 1e-15);
}

#[test]
fn mixing_rejects_what_liggghts_rejects() {
    let mut m = LiggghtsMaterials::default();
    m.n_types = 1;
    m.youngs = Some(vec![1e6]);
    m.poisson = Some(vec![0.3]);
    assert!(liggghts_pair_params(&m, &LiggghtsSettings::default(), dummy_span()).is_err());
    m.youngs = Some(vec![1e7]);
    m.restitution = Some(vec![0.04]);
    assert!(liggghts_pair_params(&m, &LiggghtsSettings::default(), dummy_span()).is_err());
    m.restitution = Some(vec![0.5, 0.5]);
    assert!(liggghts_pair_params(&m, &LiggghtsSettings::default(), dummy_span()).is_err());
    m.restitution = Some(vec![0.5]);
    m.poisson = Some(vec![0.6]);
    assert!(liggghts_pair_params(&m, &LiggghtsSettings::default(), dummy_span()).is_err());
}

#[test]
fn liggghts_hertz_force_at_overlap() {
    let p = liggghts_params(0.5);
    let c = pair(1e-5, V3::new(0.0, 0.0, -0.5), V3::zeros(), V3::zeros(), 1e-7);
    let mut out = ContactOut::default();
    LiggghtsHertz.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_elastic, 0.0051802694592421065) < 1e-12);
    assert!(rel(out.fn_damp, 0.012545401779848678) < 1e-12);
    assert!(rel(out.kt, 639.9156390828484) < 1e-12);
    assert!(rel(out.gamma_t, 0.022769533212036418) < 1e-12);
    // leaving: damping attracts; limitForce clamps the total at 0
    let c2 = pair(1e-5, V3::new(0.0, 0.0, 5.0), V3::zeros(), V3::zeros(), 1e-7);
    LiggghtsHertz.normal(&c2, &p, &mut [], &mut out);
    assert!(out.fn_total() < 0.0);
    let mut pl = p;
    pl.limit_damping = 1.0;
    LiggghtsHertz.normal(&c2, &pl, &mut [], &mut out);
    assert_eq!(out.fn_total(), 0.0);
    // tangential_damping off
    let mut pt = p;
    pt.tangential_damping = 0.0;
    LiggghtsHertz.normal(&c, &pt, &mut [], &mut out);
    assert_eq!(out.gamma_t, 0.0);
}

#[test]
fn liggghts_hooke_force_at_overlap() {
    let p = liggghts_params(0.5);
    let c = pair(1e-5, V3::new(0.0, 0.0, -0.5), V3::zeros(), V3::zeros(), 1e-7);
    let mut out = ContactOut::default();
    LiggghtsHooke { kt_to_kn: false }.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.kn, 1090.821262460105) < 1e-12);
    assert!(rel(out.fn_elastic, 0.01090821262460105) < 1e-12);
    assert!(rel(out.fn_damp, 0.0162828412998761) < 1e-12);
    assert_eq!(out.kt, out.kn);
    assert!(rel(out.gamma_t, 0.0325656825997522) < 1e-12);
    LiggghtsHooke { kt_to_kn: true }.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.kt, 1090.821262460105 * 2.0 / 7.0) < 1e-8);
}

#[test]
fn liggghts_stiffness_models() {
    let mut p = PairParams::default();
    p.kn = 1000.0;
    p.kt = 300.0;
    p.gamma_n = 50.0;
    p.gamma_t = 20.0;
    p.tangential_damping = 1.0;
    let c = pair(1e-5, V3::new(0.0, 0.0, -0.5), V3::zeros(), V3::zeros(), 1e-7);
    let mut out = ContactOut::default();
    LiggghtsHookeStiffness { absolute_damping: false }.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_elastic, 1000.0 * 1e-5) < 1e-14);
    assert!(rel(out.fn_damp, 50.0 * M / 2.0 * 0.5) < 1e-14);
    assert!(rel(out.gamma_t, 20.0 * M / 2.0) < 1e-14);
    LiggghtsHookeStiffness { absolute_damping: true }.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_damp, 50.0 * 0.5) < 1e-14);
    assert!(rel(out.gamma_t, 20.0) < 1e-14);
    LiggghtsHertzStiffness.normal(&c, &p, &mut [], &mut out);
    let s = (R / 2.0 * 1e-5f64).sqrt();
    assert!(rel(out.fn_elastic, s * 1000.0 * 1e-5) < 1e-14);
    assert!(rel(out.fn_damp, s * M / 2.0 * 50.0 * 0.5) < 1e-14);
    assert!(rel(out.kt, s * 300.0) < 1e-14);
}

#[test]
fn lammps_gran_normal_and_defaults() {
    // pair_style gran/hertz/history 2e5 NULL 50 NULL 0.5 1
    let p = lammps_gran_params(2e5, None, 50.0, None, 0.5, true, false);
    assert!(rel(p.kt, 2e5 * 2.0 / 7.0) < 1e-15);
    assert_eq!(p.gamma_t, 25.0);
    let p0 = lammps_gran_params(2e5, None, 50.0, None, 0.5, false, false);
    assert_eq!(p0.gamma_t, 0.0);
    let c = pair(1e-5, V3::new(0.0, 0.0, -0.5), V3::zeros(), V3::zeros(), 1e-7);
    let mut out = ContactOut::default();
    LammpsGranHooke.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_elastic, 2.0) < 1e-14);
    assert!(rel(out.fn_damp, M / 2.0 * 50.0 * 0.5) < 1e-14);
    LammpsGranHertz.normal(&c, &p, &mut [], &mut out);
    let ph = (1e-5f64 * R / 2.0).sqrt();
    assert!(rel(out.fn_elastic, ph * 2.0) < 1e-14);
    assert!(rel(out.fn_damp, ph * M / 2.0 * 50.0 * 0.5) < 1e-14);
    assert!(rel(out.kt, ph * 2e5 * 2.0 / 7.0) < 1e-14);
    assert!(rel(out.gamma_t, ph * M / 2.0 * 25.0) < 1e-14);
}

fn granular_coeff(normal: GranularNormal, damping: GranularDamping, k: f64, damp: f64) -> GranularCoeff {
    GranularCoeff {
        normal,
        damping,
        kn_or_e: k,
        damp,
        poisson: 0.3,
        tangential: GranularTangentialChoice::History(GranularTangential::Mindlin),
        kt: None,
        x_gamma_t: 1.0,
        mu: 0.5,
        rolling: None,
        twisting: None,
        limit_damping: false,
    }
}

#[test]
fn lammps_granular_normal_variants() {
    let c = pair(1e-5, V3::new(0.0, 0.0, -0.5), V3::zeros(), V3::zeros(), 1e-7);
    let a = (1e-5f64 * R / 2.0).sqrt();
    let ms = M / 2.0;
    let e_eff = 1e7 / (2.0 * (1.0 - 0.09));
    let cases = [
        (GranularDamping::Velocity, 1.0),
        (GranularDamping::MassVelocity, ms),
        (GranularDamping::Viscoelastic, a * ms),
        (GranularDamping::Tsuji, (ms * 4.0 / 3.0 * e_eff * a).sqrt()),
    ];
    for (d, factor) in cases {
        let gc = granular_coeff(GranularNormal::HertzMaterial, d, 1e7, 0.5);
        let p = lammps_granular_params(&gc, false, dummy_span()).unwrap();
        let mut out = ContactOut::default();
        LammpsGranular { model: GranularNormal::HertzMaterial, damping: d }.normal(&c, &p, &mut [], &mut out);
        assert!(rel(out.fn_elastic, 4.0 / 3.0 * e_eff * a * 1e-5) < 1e-13, "{d:?}");
        let eta = if d == GranularDamping::Tsuji {
            // alpha(0.5) from the published polynomial, evaluated by hand
            1.2728 - 4.2783 * 0.5 + 11.087 * 0.25 - 22.348 * 0.125 + 27.467 * 0.0625 - 18.022 * 0.03125 + 4.8218 * 0.015625
        } else {
            0.5
        };
        assert!(rel(out.fn_damp, eta * factor * 0.5) < 1e-12, "{d:?}");
        // mindlin NULL: k_t = 8 G_eff = 8 E / (4 (2 - nu)(1 + nu))
        assert!(rel(p.kt, 8.0 * 1e7 / (4.0 * 1.7 * 1.3)) < 1e-14);
    }
    // plain hooke with kn
    let mut gc = granular_coeff(GranularNormal::Hooke, GranularDamping::Velocity, 1000.0, 3.0);
    gc.kt = Some(500.0);
    let p = lammps_granular_params(&gc, false, dummy_span()).unwrap();
    let mut out = ContactOut::default();
    LammpsGranular { model: GranularNormal::Hooke, damping: GranularDamping::Velocity }.normal(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_elastic, 1000.0 * 1e-5) < 1e-14);
    assert!(rel(out.fn_damp, 1.5) < 1e-14);
    // the wall case of the 2021 build: E / (2 (1 - nu))
    let gc = granular_coeff(GranularNormal::HertzMaterial, GranularDamping::Velocity, 1e7, 0.0);
    let p = lammps_granular_params(&gc, true, dummy_span()).unwrap();
    assert!(rel(p.kn, 4.0 / 3.0 * 1e7 / 1.4) < 1e-14);
    // NULL kt without a material is an error, not a panic
    let gc = granular_coeff(GranularNormal::Hooke, GranularDamping::Velocity, 1000.0, 3.0);
    assert!(lammps_granular_params(&gc, false, dummy_span()).is_err());
}

/// Normal output with a given normal force and tangential constants.
fn normal_out(fn_: f64, kt: f64, gamma_t: f64) -> ContactOut {
    let mut o = ContactOut::default();
    o.fn_elastic = fn_;
    o.fn_for_friction = fn_;
    o.kt = kt;
    o.gamma_t = gamma_t;
    o
}

#[test]
fn liggghts_history_stick_slip_and_torque() {
    let mut p = PairParams::default();
    p.mu = 0.5;
    let dt = 1e-6;
    // stick: sphere on a wall moving +x at 0.01 m/s, no rotation
    let c = wall(1e-5, V3::new(0.01, 0.0, 0.0), V3::zeros(), dt);
    let mut h = [0.0; 3];
    let mut out = normal_out(1.0, 1000.0, 0.01);
    LiggghtsHistory.tangential(&c, &p, &mut h, &mut out);
    let xi = 0.01 * dt;
    assert!(rel(h[0], xi) < 1e-12);
    assert!(rel(out.ft.x, -1000.0 * xi - 0.01 * 0.01) < 1e-12);
    // torque on i: lever R - delta/2, about +y for a -x force at the bottom
    let cr = R - 0.5e-5;
    assert!(rel(out.torque_i.y, cr * -out.ft.x) < 1e-12);
    assert_eq!(out.torque_j, V3::zeros());
    // slip: a large stored displacement is capped to mu Fn, no damping
    let mut h = [1e-2, 0.0, 0.0];
    let mut out = normal_out(1.0, 1000.0, 0.01);
    LiggghtsHistory.tangential(&c, &p, &mut h, &mut out);
    assert!(rel(out.ft.norm(), 0.5) < 1e-14);
    assert!(out.ft.x < 0.0);
    assert!(rel(h[0], 0.5 / 1000.0) < 1e-14);
    // normal component of the history is removed, not rescaled
    let mut h = [1e-7, 0.0, 1e-7];
    let c0 = wall(1e-5, V3::zeros(), V3::zeros(), dt);
    let mut out = normal_out(1.0, 1000.0, 0.0);
    LiggghtsHistory.tangential(&c0, &p, &mut h, &mut out);
    assert_eq!(h, [1e-7, 0.0, 0.0]);
    // rotation: rolling without slip on the wall gives no tangential velocity
    let w = 0.01 / cr;
    let c_roll = wall(1e-5, V3::new(0.01, 0.0, 0.0), V3::new(0.0, w, 0.0), dt);
    let mut h = [0.0; 3];
    let mut out = normal_out(1.0, 1000.0, 0.01);
    LiggghtsHistory.tangential(&c_roll, &p, &mut h, &mut out);
    assert!(out.ft.norm() < 1e-15);
}

#[test]
fn liggghts_no_history_is_capped_viscous() {
    let mut p = PairParams::default();
    p.mu = 0.5;
    let c = pair(1e-5, V3::new(0.2, 0.0, 0.0), V3::zeros(), V3::zeros(), 1e-6);
    let mut out = normal_out(1.0, 0.0, 2.0);
    LiggghtsNoHistory.tangential(&c, &p, &mut [], &mut out);
    assert!(rel(out.ft.x, -0.4) < 1e-14);
    // both spheres get torque -l n x F with l = R - delta/2
    let l = R - 0.5e-5;
    assert!(rel(out.torque_i.y, l * 0.4) < 1e-12);
    assert!(rel(out.torque_j.y, l * 0.4) < 1e-12);
    let c = pair(1e-5, V3::new(2.0, 0.0, 0.0), V3::zeros(), V3::zeros(), 1e-6);
    let mut out = normal_out(1.0, 0.0, 2.0);
    LiggghtsNoHistory.tangential(&c, &p, &mut [], &mut out);
    assert!(rel(out.ft.x, -0.5) < 1e-14);
}

#[test]
fn lammps_gran_history_caps_total_force() {
    let mut p = PairParams::default();
    p.mu = 0.5;
    let dt = 1e-6;
    let v = 0.3;
    let c = wall(1e-5, V3::new(v, 0.0, 0.0), V3::zeros(), dt);
    let (kt, gt) = (1000.0, 1.0);
    let mut h = [4e-4, 0.0, 0.0];
    let mut out = normal_out(1.0, kt, gt);
    LammpsGranHistory.tangential(&c, &p, &mut h, &mut out);
    // total (elastic + damping) capped to mu Fn
    assert!(rel(out.ft.x, -0.5) < 1e-14);
    // history consistent with the damping term: kt xi + gt v = 0.5
    assert!(rel(kt * h[0] + gt * v, 0.5) < 1e-12);
    // lever R: torque R * 0.5 about +y
    assert!(rel(out.torque_i.y, R * 0.5) < 1e-12);
    // gran/hooke without history
    let mut out = normal_out(1.0, 0.0, 1.0);
    LammpsGranNoHistory.tangential(&c, &p, &mut [], &mut out);
    assert!(rel(out.ft.x, -0.3) < 1e-14);
    // relative rotation uses the full radius: rolling at w = v / R cancels
    let c_roll = wall(1e-5, V3::new(v, 0.0, 0.0), V3::new(0.0, v / R, 0.0), dt);
    let mut h = [0.0; 3];
    let mut out = normal_out(1.0, kt, gt);
    LammpsGranHistory.tangential(&c_roll, &p, &mut h, &mut out);
    assert!(out.ft.norm() < 1e-15);
}

#[test]
fn lammps_granular_history_rotation_and_rescale() {
    let mut p = PairParams::default();
    p.mu = 0.5;
    p.kt = 1000.0;
    p.gamma_t = 0.0;
    let dt = 1e-6;
    // linear_history: history with a normal component is projected and rescaled to its magnitude
    let c = wall(1e-5, V3::zeros(), V3::zeros(), dt);
    let mut h = [3e-6, 0.0, 4e-6, 0.0];
    let mut out = normal_out(1.0, 0.0, 0.0);
    out.a = 1e-4;
    LammpsGranularHistory { model: GranularTangential::LinearHistory }.tangential(&c, &p, &mut h, &mut out);
    assert!(rel(h[0], 5e-6) < 1e-12);
    assert!(h[2].abs() < 1e-20);
    assert!(rel(out.ft.x, -1000.0 * 5e-6) < 1e-12);
    // fix wall/gran granular: torque lever R (lmp 2021)
    assert!(rel(out.torque_i.y, R * 1000.0 * 5e-6) < 1e-12);
    // mindlin_rescale: a shrinks from 2e-4 to 1e-4 -> history halves; k_t = kt a
    let mut h = [2e-6, 0.0, 0.0, 2e-4];
    let mut out = normal_out(1.0, 0.0, 0.0);
    out.a = 1e-4;
    LammpsGranularHistory { model: GranularTangential::MindlinRescale }.tangential(&c, &p, &mut h, &mut out);
    assert!(rel(h[0], 1e-6) < 1e-12);
    assert_eq!(h[3], 1e-4);
    assert!(rel(out.ft.x, -1000.0 * 1e-4 * 1e-6) < 1e-12);
    // mindlin/force: history is the force, decreases by kt a v dt
    let cv = wall(1e-5, V3::new(0.1, 0.0, 0.0), V3::zeros(), dt);
    let mut h = [0.0; 4];
    let mut out = normal_out(1.0, 0.0, 0.0);
    out.a = 1e-4;
    LammpsGranularHistory { model: GranularTangential::MindlinForce }.tangential(&cv, &p, &mut h, &mut out);
    assert!(rel(h[0], -1000.0 * 1e-4 * 0.1 * dt) < 1e-12);
    assert!(rel(out.ft.x, h[0]) < 1e-12);
    // slip caps the total force and sets the history consistently (damping x_gamma_t * eta_n)
    p.gamma_t = 2.0;
    let mut h = [1e-2, 0.0, 0.0, 0.0];
    let mut out = normal_out(1.0, 0.0, 0.0);
    out.gamma_n = 0.5;
    out.a = 1e-4;
    LammpsGranularHistory { model: GranularTangential::LinearHistory }.tangential(&cv, &p, &mut h, &mut out);
    assert!(rel(out.ft.x, -0.5) < 1e-14);
    assert!(rel(1000.0 * h[0] + 1.0 * 0.1, 0.5) < 1e-12);
    // linear_nohistory: min(mu Fn, x_gamma_t eta_n |v|)
    let mut out = normal_out(1.0, 0.0, 0.0);
    out.gamma_n = 0.5;
    LammpsLinearNoHistory.tangential(&cv, &p, &mut [], &mut out);
    assert!(rel(out.ft.x, -0.1) < 1e-14);
}

#[test]
fn lammps_granular_mix_2021_is_geometric() {
    let a =
        lammps_granular_params(&granular_coeff(GranularNormal::HertzMaterial, GranularDamping::Viscoelastic, 1e7, 0.0), false, dummy_span()).unwrap();
    let mut gb = granular_coeff(GranularNormal::HertzMaterial, GranularDamping::Viscoelastic, 4e7, 0.0);
    gb.poisson = 0.25;
    let b = lammps_granular_params(&gb, false, dummy_span()).unwrap();
    let m = lammps_granular_mix_2021(&a, &b);
    // lmp 29 Sep 2021, types 1-2 without pair_coeff, delta = 1e-4: F = 1443.55189856205 N
    assert!(rel(m.kn * 1e-4, 1443.55189856205) < 1e-12);
}

use demx::physics::cohesion::sjkr::LiggghtsSjkr;
use demx::physics::cohesion::sjkr2::LiggghtsSjkr2;
use demx::physics::rolling::cdt::LiggghtsCdt;
use demx::physics::rolling::epsd::LiggghtsEpsd;
use demx::physics::rolling::epsd2::LiggghtsEpsd2;
use demx::physics::rolling::epsd3::LiggghtsEpsd3;
use demx::physics::rolling::sds::LammpsSds;

#[test]
fn sjkr_areas_and_tangential_reduce() {
    let mut p = PairParams::default();
    p.cohesion = 3e5;
    let delta = 1e-5;
    let d = 2.0 * R - delta;
    let c = pair(delta, V3::zeros(), V3::zeros(), V3::zeros(), 1e-7);
    let mut out = normal_out(1.0, 0.0, 0.0);
    LiggghtsSjkr { tangential_reduce: false }.cohesion(&c, &p, &mut [], &mut out);
    // intersection circle of two equal spheres: a^2 = R^2 - d^2/4
    let f = -3e5 * std::f64::consts::PI * (R * R - d * d / 4.0);
    assert!(rel(out.fn_coh, f) < 1e-9);
    assert_eq!(out.fn_for_friction, 1.0);
    let mut out = normal_out(1.0, 0.0, 0.0);
    LiggghtsSjkr { tangential_reduce: true }.cohesion(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_for_friction, 1.0 + f) < 1e-12);
    let cw = wall(delta, V3::zeros(), V3::zeros(), 1e-7);
    let mut out = ContactOut::default();
    LiggghtsSjkr::default().cohesion(&cw, &p, &mut [], &mut out);
    let dw = R - delta;
    assert!(rel(out.fn_coh, -3e5 * std::f64::consts::PI * (R * R - dw * dw)) < 1e-9);
    let mut out = ContactOut::default();
    LiggghtsSjkr2::default().cohesion(&c, &p, &mut [], &mut out);
    assert!(rel(out.fn_coh, -3e5 * 2.0 * std::f64::consts::PI * R * delta) < 1e-12);
    let mut out = ContactOut::default();
    LiggghtsSjkr2::default().cohesion(&cw, &p, &mut [], &mut out);
    assert!(rel(out.fn_coh, -3e5 * 2.0 * std::f64::consts::PI * R * delta) < 1e-12);
}

#[test]
fn epsd_family_spring_dashpot_cap_and_signs() {
    let mut p = PairParams::default();
    p.mu_r = 0.1;
    p.eta_r = 0.3;
    p.k_r_coeff = 4.0;
    let dt = 1e-6;
    let w = 2.0;
    // pair: i spins about +x, j at rest; n = +z
    let c = pair(1e-5, V3::zeros(), V3::new(w, 0.0, 0.0), V3::zeros(), dt);
    let (kn, kt) = (1000.0, 800.0);
    let rs = R / 2.0;
    let mut out = normal_out(1.0, kt, 0.0);
    out.kn = kn;
    let mut h = [0.0; 3];
    LiggghtsEpsd::default().rolling(&c, &p, &mut h, &mut out);
    let k_r = 2.25 * kn * 0.01 * rs * rs;
    let i_r = 1.4 * (M * R * R) * (M * R * R) / (2.0 * M * R * R);
    let m = k_r * w * dt + 0.3 * 2.0 * (i_r * k_r).sqrt() * w;
    assert!(rel(h[0], k_r * w * dt) < 1e-12);
    assert!(rel(out.torque_i.x, -m) < 1e-12);
    assert!(rel(out.torque_j.x, m) < 1e-12);
    // at the cap: |M| = mu_r R* |Fn|, stored capped, no dashpot
    let mut h = [1.0, 0.0, 0.0];
    let mut out = normal_out(-2.0, kt, 0.0);
    out.kn = kn;
    LiggghtsEpsd::default().rolling(&c, &p, &mut h, &mut out);
    assert!(rel(out.torque_i.x, -0.1 * rs * 2.0) < 1e-12);
    assert!(rel(h[0], 0.1 * rs * 2.0) < 1e-12);
    // twisting about n is ignored unless torsionTorque
    let ct = pair(1e-5, V3::zeros(), V3::new(0.0, 0.0, w), V3::zeros(), dt);
    let mut h = [0.0; 3];
    let mut out = normal_out(1.0, kt, 0.0);
    out.kn = kn;
    LiggghtsEpsd::default().rolling(&ct, &p, &mut h, &mut out);
    assert_eq!(out.torque_i, V3::zeros());
    LiggghtsEpsd { torsion_torque: true }.rolling(&ct, &p, &mut h, &mut out);
    assert!(out.torque_i.z < 0.0);
    // epsd2: k_r = kt R*^2, no dashpot
    let mut h = [0.0; 3];
    let mut out = normal_out(1.0, kt, 0.0);
    LiggghtsEpsd2::default().rolling(&c, &p, &mut h, &mut out);
    assert!(rel(out.torque_i.x, -kt * rs * rs * w * dt) < 1e-12);
    // epsd3: rollingStiffness replaces 2.25
    let mut h = [0.0; 3];
    let mut out = normal_out(1.0, kt, 0.0);
    out.kn = kn;
    LiggghtsEpsd3::default().rolling(&c, &p, &mut h, &mut out);
    let k_r3 = 4.0 * kn * 0.01 * rs * rs;
    assert!(rel(h[0], k_r3 * w * dt) < 1e-12);
    assert!(rel(out.torque_i.x, -(k_r3 * w * dt + 0.3 * 2.0 * (i_r * k_r3).sqrt() * w)) < 1e-12);
}

#[test]
fn cdt_constant_torque() {
    let mut p = PairParams::default();
    p.mu_r = 0.1;
    let c = pair(1e-5, V3::zeros(), V3::new(0.0, 3.0, 0.0), V3::new(0.0, -1.0, 0.0), 1e-6);
    let mut out = ContactOut::default();
    out.kn = 1000.0;
    LiggghtsCdt.rolling(&c, &p, &mut [], &mut out);
    let m = 0.1 * 1000.0 * 1e-5 * R / 2.0;
    assert!(rel(out.torque_i.y, -m) < 1e-12);
    assert!(rel(out.torque_j.y, m) < 1e-12);
    // wall: lever R - delta/2
    let cw = wall(1e-5, V3::zeros(), V3::new(0.0, 3.0, 0.0), 1e-6);
    let mut out = ContactOut::default();
    out.kn = 1000.0;
    LiggghtsCdt.rolling(&cw, &p, &mut [], &mut out);
    assert!(rel(out.torque_i.y, -0.1 * 1000.0 * 1e-5 * (R - 0.5e-5)) < 1e-12);
}

#[test]
fn lammps_sds_rolling_and_twisting() {
    let mut p = PairParams::default();
    p.k_roll = 500.0;
    p.gamma_roll = 0.2;
    p.mu_r = 0.1;
    p.k_twist = 300.0;
    p.gamma_twist = 0.1;
    p.mu_twist = 0.05;
    let dt = 1e-6;
    let w = 2.0;
    // sphere on a wall rolling about +y: v_roll = R w x n = R w (+x)
    let c = wall(1e-5, V3::zeros(), V3::new(0.0, w, 0.0), dt);
    let mut h = [0.0; 4];
    let mut out = normal_out(1.0, 0.0, 0.0);
    LammpsSds { twisting: true }.rolling(&c, &p, &mut h, &mut out);
    let v = R * w;
    assert!(rel(h[0], v * dt) < 1e-12);
    let fr = -(500.0 * v * dt + 0.2 * v);
    // torque R n x F_r: z x (fr x) = fr y, opposing the spin
    assert!(rel(out.torque_i.y, R * fr) < 1e-12);
    assert!(out.torque_i.y < 0.0);
    // cap: large history -> |F_r| = mu_roll F_n, history consistent
    let mut h = [1.0, 0.0, 0.0, 0.0];
    let mut out = normal_out(1.0, 0.0, 0.0);
    LammpsSds { twisting: false }.rolling(&c, &p, &mut h, &mut out);
    assert!(rel(out.torque_i.y, -R * 0.1) < 1e-12);
    assert!(rel(500.0 * h[0] + 0.2 * v, 0.1) < 1e-12);
    // twisting about n: M = -k phi - gamma w_t, capped at mu_twist F_n
    let ct = wall(1e-5, V3::zeros(), V3::new(0.0, 0.0, w), dt);
    let mut h = [0.0; 4];
    let mut out = normal_out(1.0, 0.0, 0.0);
    LammpsSds { twisting: true }.rolling(&ct, &p, &mut h, &mut out);
    let m = -300.0 * w * dt - 0.1 * w;
    assert!(rel(out.torque_i.z, -0.05f64.min(-m)) < 1e-12);
}

#[test]
fn torque_levers_match_the_engines() {
    // lmp 29 Sep 2021 and liggghts 3.8, `run 0`: sphere 1 (R = 1 mm, z = 0.9 mm,
    // vx = 0.5) on sphere 2 (R = 1.5 mm, z = -1.5 mm), delta = 0.1 mm,
    // tangential force 5e-4 N: torques 4.75e-7 (i) and 7.25e-7 (j) N m in both
    // `pair_style granular ... linear_nohistory` and LIGGGHTS `no_history`;
    // LAMMPS `gran/hooke/history` uses the full radii.
    let (r1, r2, delta) = (1e-3, 1.5e-3, 1e-4);
    let n = V3::new(0.0, 0.0, 1.0);
    let vr = V3::new(0.5, 0.0, 0.0);
    let c = Contact {
        n,
        r: r1 + r2 - delta,
        delta,
        ri: r1,
        rj: r2,
        r_eff: r1 * r2 / (r1 + r2),
        mi: M,
        mj: M * 3.375,
        m_eff: M * 3.375 / 4.375,
        vr,
        vn: 0.0,
        wi: V3::zeros(),
        wj: V3::zeros(),
        dt: 1e-7,
    };
    let mut p = PairParams::default();
    p.mu = 0.5;
    p.gamma_t = 1.0;
    let mut out = normal_out(0.1, 0.0, 0.0);
    out.gamma_n = 1e-3;
    LammpsLinearNoHistory.tangential(&c, &p, &mut [], &mut out);
    assert!(rel(out.ft.x, -5e-4) < 1e-12);
    assert!(rel(out.torque_i.y, 4.75e-7) < 1e-9);
    assert!(rel(out.torque_j.y, 7.25e-7) < 1e-9);
    let mut out = normal_out(0.1, 0.0, 1e-3);
    LiggghtsNoHistory.tangential(&c, &p, &mut [], &mut out);
    assert!(rel(out.torque_i.y, 4.75e-7) < 1e-9);
    assert!(rel(out.torque_j.y, 7.25e-7) < 1e-9);
    let mut out = normal_out(0.1, 0.0, 1e-3);
    LammpsGranNoHistory.tangential(&c, &p, &mut [], &mut out);
    assert!(rel(out.torque_i.y, 5e-7) < 1e-9);
    assert!(rel(out.torque_j.y, 7.5e-7) < 1e-9);
}
