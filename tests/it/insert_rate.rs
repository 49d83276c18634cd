//! LIGGGHTS insert/rate/region: per-insertion counts, masses and steps
//! against liggghts 3.8 (numbers in the deck header).

use demx::scene::Session;
use demx::script::{Interpreter, SourceMap};
use std::path::Path;

#[test]
fn rate_region_counts_steps_and_masses_match_liggghts() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/decks/insert/in.rate_region");
    let mut s = Session::new(false);
    s.sim.log.screen = false;
    s.sim.log.captured = Some(String::new());
    let mut it = Interpreter::new(SourceMap::new(), vec![]);
    it.run_file(&p, &mut s).expect("deck runs");
    let log = s.sim.log.captured.clone().unwrap_or_default();
    let got: Vec<String> = log
        .lines()
        .filter(|l| l.contains("particle templates (mass") && l.starts_with("INFO"))
        .map(|l| l.split(": ").nth(2).unwrap_or("").to_string())
        .collect();
    let want = [
        "inserted 32 particle templates (mass 9.051976e-02) at step 1",
        "inserted 31 particle templates (mass 8.515810e-02) at step 101",
        "inserted 31 particle templates (mass 8.921076e-02) at step 201",
        "inserted 6 particle templates (mass 1.595929e-02) at step 301",
    ];
    assert_eq!(got, want, "log:\n{log}");
    assert_eq!(s.sim.particles.len(), 100);
}
