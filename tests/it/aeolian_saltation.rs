//! `demx saltation`: flux of SI Eq. 8 from a hand-written dump, and the
//! normalisations of SI Eqs. 9-10 against the physics note's numbers.

use demx::analysis::saltation::{q_hat, shields, Settings};
use std::process::Command;

#[test]
fn normalisations_match_the_note() {
    let s = Settings::default();
    // rho_p sqrt((s-1) g d_m^3) = 1.0916 kg/(m s) (note 1.6)
    assert!((q_hat(1.0916, &s) - 1.0).abs() < 1e-4);
    // Theta at u* = 0.3 / 0.4 / 0.5: 0.0212 / 0.0377 / 0.0589 (note 6.2)
    for (u, th) in [(0.3, 0.0212), (0.4, 0.0377), (0.5, 0.0589)] {
        assert!((shields(u, &s) - th).abs() < 1e-4, "{u}: {}", shields(u, &s));
    }
    // threshold u*t = 0.165 m/s <-> Theta_t ~ 0.0064 (SI S2)
    assert!((shields(0.165, &s) - 0.0064).abs() < 1e-4);
}

#[test]
fn flux_from_dump_frames() {
    let dir = tempfile::tempdir().unwrap();
    let frame = |step: u64, v1: f64, v2: f64| {
        format!(
            "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS pp pp ff\n0 0.01\n0 0.002\n0 0.1\n\
             ITEM: ATOMS id type x y z vx vy vz radius\n1 1 0.001 0.001 0.001 {v1} 0 0 1e-4\n2 1 0.002 0.001 0.003 {v2} 0 0 1.2e-4\n3 2 0.002 0.001 0.0 9.0 0 0 1e-4\n"
        )
    };
    let text = frame(0, 0.0, 0.0) + &frame(1000, 1.5, 4.0) + &frame(2000, 2.5, 6.0);
    std::fs::write(dir.path().join("d.dump"), text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["saltation", "--ustar", "0.4", "--dt", "1e-5", "--from", "0.01", "--group-type", "1", "-o", "q.csv", "d.dump"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.path().join("q.csv")).unwrap();
    let m = |r: f64| 2650.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let area = 0.01 * 0.002;
    let q1 = (m(1e-4) * 1.5 + m(1.2e-4) * 4.0) / area;
    let q2 = (m(1e-4) * 2.5 + m(1.2e-4) * 6.0) / area;
    let rows: Vec<Vec<f64>> =
        csv.lines().skip(1).filter(|l| !l.starts_with('#')).map(|l| l.split(',').map(|w| w.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 3);
    assert!((rows[1][2] - q1).abs() < 1e-8 * q1 && (rows[2][2] - q2).abs() < 1e-8 * q2);
    let summary = csv.lines().last().unwrap().trim_start_matches("# ");
    let f: Vec<&str> = summary.split(',').collect();
    assert_eq!(f[1], "2", "frames at t >= 0.01 s");
    let mean: f64 = f[2].parse().unwrap();
    assert!((mean - 0.5 * (q1 + q2)).abs() < 1e-8 * mean);
}

use demx::analysis::saltation::{eq16_delta_s, fit_decay, frame_layer, hops, liftoff_speed};
use demx::io::dump::DumpReader;

/// A dump frame: a simple cubic bed of `layers` layers of spheres of diameter
/// `d` (spacing d, so each bin of d/2 holds half spheres: solid fraction pi/6)
/// on the floor, type 2 when `rigid_first` for the bottom layer, plus the
/// extra grains given as (z, vx, vz), type 1.
fn bed_frame(d: f64, nx: usize, layers: usize, rigid_first: bool, extra: &[(f64, f64, f64)]) -> String {
    let mut rows = vec![];
    let mut id = 0;
    for k in 0..layers {
        for i in 0..nx {
            for j in 0..nx {
                id += 1;
                let t = if rigid_first && k == 0 { 2 } else { 1 };
                rows.push(format!("{id} {t} {} {} {} 0 0 0 {}", (i as f64 + 0.5) * d, (j as f64 + 0.5) * d, (k as f64 + 0.5) * d, d / 2.0));
            }
        }
    }
    for &(z, vx, vz) in extra {
        id += 1;
        rows.push(format!("{id} 1 {} {} {z} {vx} 0 {vz} {}", 0.3 * d, 0.7 * d, d / 2.0));
    }
    let l = nx as f64 * d;
    format!(
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS pp pp ff\n0 {l}\n0 {l}\n0 {}\nITEM: ATOMS id type x y z vx vy vz radius\n{}\n",
        rows.len(),
        100.0 * d,
        rows.join("\n")
    )
}

fn first_frame(text: String) -> demx::io::dump::Frame {
    let mut r = DumpReader::from_reader(Box::new(std::io::Cursor::new(text.into_bytes())), "test", false);
    r.next().unwrap().unwrap()
}

#[test]
fn bed_surface_and_thickness_of_a_lattice_bed() {
    let s = Settings::default();
    let d = s.d_m;
    let f = first_frame(bed_frame(d, 6, 5, false, &[]));
    let l = frame_layer(&f, &s).unwrap();
    // every bin of d/2 inside the bed holds half spheres: phi = pi/6; the bed
    // surface is where phi, interpolated between the top bed bin's centre
    // (5d - d/4) and the empty bin above (5d + d/4), falls to 0.3
    let phi = std::f64::consts::PI / 6.0;
    let expect = 5.0 * d - d / 4.0 + (phi - 0.3) / phi * (d / 2.0);
    assert!((l.zb - expect).abs() < 1e-9 * d, "z_b {} expected {}", l.zb, expect);
    assert_eq!(l.ground, 0.0, "no rigid grains: the box bottom");
    // with the bottom layer rigid (type 2), the ground is the top of that layer
    let s2 = Settings { rigid_type: Some(2.0), ..Settings::default() };
    let l2 = frame_layer(&first_frame(bed_frame(d, 6, 5, true, &[])), &s2).unwrap();
    assert!((l2.ground - d).abs() < 1e-12);
    assert!((l2.zb - expect).abs() < 1e-9 * d, "the rigid layer still counts in the bed's solid fraction");
}

#[test]
fn hop_samples_are_weighted_by_crossings() {
    let s = Settings::default();
    let d = s.d_m;
    let vth = liftoff_speed(&s);
    assert!((vth - (6.0 * 9.81 * 200e-6f64).sqrt()).abs() < 1e-15 && vth < 0.2);
    let top = 5.0 * d;
    let extra = [
        (top + 0.5 * d, 1.0, 0.5),  // ascending
        (top + 0.6 * d, 2.0, 1.5),  // ascending
        (top + 0.4 * d, 4.0, -1.0), // descending
        (top + 0.5 * d, 9.0, 0.05), // too slow to count as a hop
        (top + 3.0 * d, 9.0, 2.0),  // above the near-bed layer
    ];
    let l = frame_layer(&first_frame(bed_frame(d, 6, 5, false, &extra)), &s).unwrap();
    assert_eq!((l.n_up, l.n_down), (2, 1));
    let h = hops(l.up, l.down, l.n_up, l.n_down, s.g);
    // crossing-weighted: sum |vz| vx / sum |vz|, and sum vz^2 / sum |vz|
    assert!((h.u0_up - (0.5 * 1.0 + 1.5 * 2.0) / 2.0).abs() < 1e-12, "{}", h.u0_up);
    assert!((h.v0_up - (0.25 + 2.25) / 2.0).abs() < 1e-12);
    assert!((h.u0_down - 4.0).abs() < 1e-12);
    assert!((h.u0 - 0.5 * (4.0 + 1.75)).abs() < 1e-12, "Eq. 12");
    assert!((h.t_hop - 2.0 * 1.25 / 9.81).abs() < 1e-12, "Eq. 13");
    // Eq. 14's constant acceleration over t_hop: x = u0up t + (u0down - u0up) t / 2
    let x = h.u0_up * h.t_hop + 0.5 * (h.u0_down - h.u0_up) * h.t_hop;
    assert!((h.l_hop - x).abs() < 1e-12, "hop length {} vs integrated {}", h.l_hop, x);
    assert!((h.l_hop_eq15_printed - (4.0 - 1.75) * 1.25 / 9.81).abs() < 1e-12);
    // the profile above the bed counts all mobile grains above z_b
    assert_eq!(l.count.iter().sum::<u64>(), 5);
}

#[test]
fn decay_length_of_an_exponential_profile() {
    let l_nu = 7.3e-4;
    let z: Vec<f64> = (0..40).map(|k| (k as f64 + 0.5) * 1e-4).collect();
    let nu: Vec<f64> = z.iter().map(|z| 0.02 * (-z / l_nu).exp()).collect();
    let n: Vec<u64> = nu.iter().map(|v| (v * 1e5) as u64).collect();
    let (n0, l, bins, top) = fit_decay(&z, &nu, &n, 4e-4).unwrap();
    let used: Vec<f64> = z.iter().zip(&n).filter(|(z, n)| **z >= 4e-4 && **n >= 5).map(|(z, _)| *z).collect();
    assert_eq!(top, *used.last().unwrap(), "highest bin in the fit");
    assert!((l - l_nu).abs() < 1e-9 * l_nu && (n0 - 0.02).abs() < 1e-9, "{l} {n0}");
    assert!(bins >= 3 && z.iter().zip(&n).filter(|(z, n)| **z >= 4e-4 && **n >= 5).count() == bins);
    // too few bins, or a profile that does not decay, give no fit
    assert!(fit_decay(&z[..2], &nu[..2], &n[..2], 0.0).is_none());
    let flat = vec![0.01; 40];
    let many = vec![100; 40];
    assert!(fit_decay(&z, &flat, &many, 0.0).is_none());
}

#[test]
fn eq16_bed_thickness() {
    let s = Settings::default();
    // delta_s/d_m = delta_0/d_m - C_b u*/sqrt(g d_m), C_b = 0.02
    let e = 15.0 - 0.02 * 0.4 / (9.81f64 * 200e-6).sqrt();
    assert!((eq16_delta_s(15.0, 0.4, &s) - e).abs() < 1e-12);
    assert!((e - 14.8194).abs() < 1e-3);
    assert_eq!(eq16_delta_s(0.1, 0.4, &s), 0.0, "Heaviside: a layer thinner than the erosion is gone");
}

#[test]
fn json_summary_and_profile_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = 200e-6;
    let top = 5.0 * d;
    let extra = [(top + 0.5 * d, 1.0, 0.5), (top + 0.5 * d, 3.0, -0.8), (top + 4.0 * d, 5.0, 0.1)];
    std::fs::write(dir.path().join("d.dump"), bed_frame(d, 6, 5, true, &extra)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_demx"))
        .current_dir(dir.path())
        .args(["saltation", "--json", "--ustar", "0.4", "--rigid-type", "2", "--delta0", "4", "--profile", "p.csv", "d.dump"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["frames"], 1);
    // the mobile layer: 4 layers above the rigid one, to the bed surface; the
    // two grains centred d/2 above the lattice put half their volume each in
    // the bin above it (area 36 d^2, height d/2): phi there = 2 (pi/12) / 18
    let phi = std::f64::consts::PI / 6.0;
    let above = 2.0 * (std::f64::consts::PI / 12.0) / 18.0;
    let zb = 5.0 * d - d / 4.0 + (phi - 0.3) / (phi - above) * (d / 2.0);
    assert!((j["delta_s_dm"].as_f64().unwrap() - (zb - d) / d).abs() < 1e-6);
    assert!((j["delta_s_eq16_dm"].as_f64().unwrap() - (4.0 - 0.02 * 0.4 / (9.81f64 * d).sqrt())).abs() < 1e-9);
    assert!((j["hops"]["u0"].as_f64().unwrap() - 2.0).abs() < 1e-12);
    let p = std::fs::read_to_string(dir.path().join("p.csv")).unwrap();
    assert!(p.starts_with("z_above_bed,z_over_dm,nu,samples,nu_fit\n"));
    let samples: u64 = p.lines().skip(1).map(|l| l.split(',').nth(3).unwrap().parse::<u64>().unwrap()).sum();
    assert_eq!(samples, 3, "three mobile grains above the bed");
}
