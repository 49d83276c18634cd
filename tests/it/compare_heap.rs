//! Heap statistics of `demx compare --heap` and the ensemble perturbation of
//! `demx run --perturb`, against values known without demx.

use demx::analysis::compare::Snap;
use demx::analysis::compare_stats::heap_stats;
use std::process::Command;

/// A cone of spheres on a simple cubic lattice (spacing d = 2r, touching):
/// every lattice site whose centre lies under the cone z < h - rho tan(theta).
fn cone(theta_deg: f64, h_layers: usize, r: f64) -> Snap {
    let d = 2.0 * r;
    let t = theta_deg.to_radians().tan();
    let h = h_layers as f64 * d;
    let m = (h / t / d).ceil() as i64 + 1;
    let mut x = vec![];
    for i in -m..=m {
        for j in -m..=m {
            for k in 0..h_layers as i64 {
                let p = [i as f64 * d, j as f64 * d, r + k as f64 * d];
                let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
                if p[2] < h - rho * t {
                    x.push(p);
                }
            }
        }
    }
    let n = x.len();
    Snap {
        timestep: 0,
        ids: (1..=n as u64).collect(),
        x,
        v: None,
        w: None,
        r: Some(vec![r; n]),
        m: None,
        lo: [-1.0; 3],
        hi: [1.0; 3],
        periodic: [false; 3],
    }
}

#[test]
fn heap_stats_of_a_lattice_cone() {
    // simple cubic packing fills pi/6 of space; a cone's side projection is a
    // triangle with the cone's base angle
    for theta in [20.0, 30.0] {
        let s = cone(theta, 14, 0.5e-3);
        let h = heap_stats(&s).expect("a heap");
        assert_eq!(h.count, s.ids.len());
        assert!((h.phi - std::f64::consts::PI / 6.0).abs() < 0.03, "phi {} for theta {theta}", h.phi);
        // the lattice staircase and the sphere caps shift the outline by < d
        assert!((h.theta - theta).abs() < 3.0, "theta {} vs {theta}", h.theta);
        assert!(h.theta_sd < 0.5, "the cone is symmetric: sd {}", h.theta_sd);
    }
    // a steeper cone measures steeper
    let (a, b) = (heap_stats(&cone(20.0, 14, 0.5e-3)).unwrap(), heap_stats(&cone(30.0, 14, 0.5e-3)).unwrap());
    assert!(b.theta > a.theta + 5.0);
}

fn demx() -> Command {
    Command::new(env!("CARGO_BIN_EXE_demx"))
}

fn positions(dump: &std::path::Path) -> Vec<(u64, [f64; 3], f64)> {
    let text = std::fs::read_to_string(dump).expect("dump");
    let lines: Vec<&str> = text.lines().collect();
    let start = lines.iter().position(|l| l.starts_with("ITEM: ATOMS")).expect("atoms") + 1;
    let mut out: Vec<(u64, [f64; 3], f64)> = lines[start..]
        .iter()
        .take_while(|l| !l.starts_with("ITEM"))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            (v[0] as u64, [v[1], v[2], v[3]], v[4])
        })
        .collect();
    out.sort_by_key(|p| p.0);
    out
}

/// `--perturb SEED:AMP` moves every particle by AMP of its radius before the
/// first run (|dx| = AMP r exactly, up to rounding), the same way every time,
/// and differently for another seed.
#[test]
fn perturb_moves_each_particle_by_the_amplitude() {
    let dir = tempfile::tempdir().unwrap();
    let deck = "units si\natom_style sphere\nboundary f f f\nregion b block 0 1 0 1 0 1\ncreate_box 1 b\n\
                lattice sc 0.25\nregion inner block 0.1 0.9 0.1 0.9 0.1 0.9 units box\ncreate_atoms 1 region inner\nset type 1 diameter 0.1\n\
                dump d all custom 1 dump.p id x y z radius\ndump_modify d format \"%d %.17g %.17g %.17g %.17g\"\nrun 0\n";
    std::fs::write(dir.path().join("in.p"), deck).unwrap();
    let run = |extra: &[&str], out: &str| {
        let st = demx().args(["run", "in.p", "--quiet", "--log", "none"]).args(extra).current_dir(dir.path()).status().unwrap();
        assert!(st.success());
        std::fs::rename(dir.path().join("dump.p"), dir.path().join(out)).unwrap();
        positions(&dir.path().join(out))
    };
    let base = run(&[], "a");
    let p1 = run(&["--perturb", "7:1e-3"], "b");
    let p1again = run(&["--perturb", "7:1e-3"], "c");
    let p2 = run(&["--perturb", "8:1e-3"], "d");
    assert_eq!(base.len(), 27);
    assert_eq!(p1, p1again);
    let mut differ = 0;
    for (k, b) in base.iter().enumerate() {
        let d: f64 = (0..3).map(|i| (p1[k].1[i] - b.1[i]).powi(2)).sum::<f64>().sqrt();
        assert!((d - 1e-3 * b.2).abs() < 1e-12, "particle {}: moved {d}", b.0);
        if p2[k].1 != p1[k].1 {
            differ += 1;
        }
    }
    assert_eq!(differ, 27);
    let bad = demx().args(["run", "in.p", "--perturb", "x"]).current_dir(dir.path()).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn compare_heap_needs_nothing_but_radii() {
    // a heap without radius column is "no heap", not a crash
    let mut s = cone(25.0, 6, 0.5e-3);
    s.r = None;
    assert!(heap_stats(&s).is_none());
}
