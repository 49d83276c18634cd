//! LIGGGHTS insert/pack: counts and masses against liggghts 3.8
//! (tests/decks/insert/insert_counts.txt), overlaps, seeds, deck errors.

use demx::scene::Session;
use demx::script::{Interpreter, SourceMap};
use std::path::{Path, PathBuf};

fn deck(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/decks/insert").join(name)
}

/// Run a deck through the library with `-var` style variables.
fn run(path: &Path, vars: &[(&str, &str)]) -> Session {
    let mut s = Session::new(false);
    s.sim.log.screen = false;
    let cli: Vec<(String, Vec<String>)> = vars.iter().map(|(k, v)| (k.to_string(), vec![v.to_string()])).collect();
    let mut it = Interpreter::new(SourceMap::new(), cli);
    it.run_file(path, &mut s).expect("deck runs");
    s
}

fn measured() -> Vec<(String, String, usize, f64)> {
    let text = std::fs::read_to_string(deck("insert_counts.txt")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w[0].to_string(), w[1].to_string(), w[2].parse().unwrap(), w[3].parse().unwrap())
        })
        .collect()
}

fn max_overlap_free(s: &Session) -> bool {
    let p = &s.sim.particles;
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            if (p.x[i] - p.x[j]).norm() < p.radius[i] + p.radius[j] {
                return false;
            }
        }
    }
    true
}

#[test]
fn volumefraction_counts_and_masses_match_liggghts() {
    for (seed, reg, n, mass) in measured() {
        let s = run(&deck("in.packing_short"), &[("seed", &seed), ("ireg", &reg)]);
        let p = &s.sim.particles;
        assert_eq!(p.len(), n, "seed {seed} region {reg}");
        let m: f64 = p.mass.iter().sum();
        assert!((m - mass).abs() < 5e-7 * mass, "seed {seed} region {reg}: mass {m} vs liggghts {mass}");
        // mass-based 30/70 distribution of r = 5 mm and 8 mm, rho 2500
        assert!(p.radius.iter().all(|&r| r == 0.005 || r == 0.008));
        assert!(p.density.iter().all(|&d| d == 2500.0));
        // ids 1..n, group nve_group + all, all_in: inside the region by a radius
        let mut tags = p.tag.clone();
        tags.sort();
        assert_eq!(tags, (1..=n as i64).collect::<Vec<_>>());
        let bit = s.sim.group_bit("nve_group").unwrap();
        assert!(p.mask.iter().all(|m| m & bit != 0 && m & 1 != 0));
        for i in 0..p.len() {
            let (x, r) = (p.x[i], p.radius[i]);
            if reg == "reg" {
                assert!(x.x.abs() <= 0.05 - r && x.y.abs() <= 0.05 - r && x.z >= r && x.z <= 0.15 - r, "{x:?}");
            } else {
                assert!((x.x * x.x + x.y * x.y).sqrt() <= 0.045 - r + 1e-12 && x.z >= 0.01 + r && x.z <= 0.14 - r, "{x:?}");
            }
        }
        assert!(max_overlap_free(&s), "overlap among inserted particles");
    }
}

#[test]
fn mass_split_follows_mass_fractions() {
    // liggghts mass 0.9409175 for 338 particles = 215 of r 5 mm + 123 of r 8 mm
    let s = run(&deck("in.packing_short"), &[]);
    let small = s.sim.particles.radius.iter().filter(|&&r| r == 0.005).count();
    assert_eq!((small, s.sim.particles.len() - small), (215, 123));
}

#[test]
fn same_seed_same_particles_other_seed_differs() {
    let a = run(&deck("in.packing_short"), &[]);
    let b = run(&deck("in.packing_short"), &[]);
    let c = run(&deck("in.packing_short"), &[("seed", "86028121")]);
    assert_eq!(a.sim.particles.x, b.sim.particles.x);
    assert_eq!(a.sim.particles.radius, b.sim.particles.radius);
    let n = a.sim.particles.len().min(c.sim.particles.len());
    assert!(n > 0);
    assert_ne!(a.sim.particles.x[..n], c.sim.particles.x[..n]);
}

fn check_err(text: &str) -> String {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let p = dir.path().join("in.bad");
    let base = std::fs::read_to_string(deck("in.packing_short")).unwrap();
    let cut = base.find("fix\t\tpts1").unwrap();
    std::fs::write(&p, format!("{}{}\n", &base[..cut], text)).unwrap();
    let mut s = Session::new(true);
    s.sim.log.screen = false;
    let mut it = Interpreter::new(SourceMap::new(), vec![]);
    match it.run_file(&p, &mut s) {
        Ok(()) => String::new(),
        Err(e) => format!("{e:?}"),
    }
}

#[test]
fn liggghts_deck_errors() {
    // liggghts: "Fix particletemplate/sphere (id pts1): invalid radius random style"
    let e = check_err("fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius gaussian 0.005 0.001");
    assert!(e.contains("invalid radius random style"), "{e}");
    // liggghts: seed must be a prime > 10000
    let e = check_err("fix pts1 all particletemplate/sphere 15485862 atom_type 1 density constant 2500 radius constant 0.005");
    assert!(e.contains("prime"), "{e}");
    // same seed for template and distribution
    let e = check_err(
        "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.005\n\
         fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0\n\
         fix ins all insert/pack seed 15485863 distributiontemplate pdd1 insert_every once region reg volumefraction_region 0.1",
    );
    assert!(e.contains("seeds"), "{e}");
    // LIGGGHTS reads vel before region: after it, an error
    let e = check_err(
        "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.005\n\
         fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0\n\
         fix ins all insert/pack seed 32452867 distributiontemplate pdd1 insert_every once region reg volumefraction_region 0.1 vel constant 0 0 0",
    );
    assert!(e.contains("unknown keyword"), "{e}");
    // two targets
    let e = check_err(
        "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.005\n\
         fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0\n\
         fix ins all insert/pack seed 32452867 distributiontemplate pdd1 insert_every once region reg volumefraction_region 0.1 particles_in_region 5",
    );
    assert!(e.contains("exactly one"), "{e}");
}
