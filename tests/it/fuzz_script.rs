//! Property test: generated and mutated decks never make the interpreter
//! panic, and every error renders.
//!
//! Seeds: every file under /work/shared/decks and the LIGGGHTS tutorial
//! decks, read at test time when present, plus built-in decks. Mutations use
//! a deterministic xorshift generator. `DEMX_FUZZ_CASES` sets the number of
//! cases (default 20000); `DEMX_FUZZ_SEED` the generator seed.

use demx::script::{Command, EvalContext, Host, Interpreter, SourceMap, Span, Variables};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

/// A host that accepts everything and answers a few thermo keywords.
struct Accept {
    step: i64,
}

impl EvalContext for Accept {
    fn thermo(&self, name: &str) -> Option<f64> {
        match name {
            "step" => Some(self.step as f64),
            "dt" => Some(1e-5),
            "atoms" => Some(3.0),
            _ => None,
        }
    }
    fn natoms(&self) -> usize {
        3
    }
    fn atom_vector(&self, _k: &str) -> Result<Vec<f64>, String> {
        Ok(vec![1.0, 2.0, 3.0])
    }
    fn run_bounds(&self) -> Option<(i64, i64)> {
        Some((0, 100))
    }
}

impl Host for Accept {
    fn execute(&mut self, cmd: &Command, vars: &mut Variables) -> demx::Result<()> {
        if cmd.name() == "run" {
            let n = cmd.args().first().and_then(|w| w.text.parse::<i64>().ok()).unwrap_or(0);
            self.step = self.step.saturating_add(n.clamp(0, 1000));
        }
        // exercise the evaluation API the simulation uses
        for w in cmd.args() {
            if let Some(name) = w.text.strip_prefix("v_") {
                let _ = vars.eval_equal(name, &*self);
                let _ = vars.eval_atom(name, &*self);
                let _ = vars.string_value(name, &*self);
            }
        }
        Ok(())
    }
    fn output(&mut self, _text: &str) {}
    fn set_log(&mut self, _p: Option<&str>, _a: bool, _s: Span) -> demx::Result<()> {
        Ok(())
    }
}

struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

const TOKENS: &[&str] = &[
    "${",
    "$(",
    "}",
    ")",
    "(",
    "\"\"\"",
    "\"",
    "'",
    "&",
    "&\n",
    "#",
    "\n",
    " ",
    "$",
    "$a",
    "${v}",
    "$(v_v*2)",
    "$(1/0)",
    "$(2^3:%.3f)",
    "jump SELF a\n",
    "label a\n",
    "next v\n",
    "variable v loop 3\n",
    "variable v index 1 2 3\n",
    "variable v equal v_v+1\n",
    "variable a equal sqrt(-1)\n",
    "if \"${v} > 1\" then \"jump SELF a\" else \"next v\"\n",
    "if ",
    " then ",
    " elif ",
    " else ",
    "print \"${v}\"\n",
    "run 10 every 3 \"print $(step)\"\n",
    "include in.none\n",
    "quit\n",
    "echo screen\n",
    "variable f format v %.3f\n",
    "variable s string \"a b\"\n",
    "v_v",
    "x[1]",
    "c_1[2]",
    "ramp(0,1)",
    "\u{e9}",
    "\r\n",
    "\"\"\"\nq\n\"\"\"",
    "variable w atom x*2\n",
    "v_w[2]",
];

fn seeds() -> Vec<Vec<u8>> {
    let mut out: Vec<Vec<u8>> = vec![
        b"variable a index x y z\nlabel top\nfix f${a} all nve\nnext a\njump SELF top\n".to_vec(),
        b"variable v equal 2\nif \"${v} > 1\" then \"print big\" elif \"${v} < 0\" \"print neg\" else \"print small\"\n".to_vec(),
        b"variable L loop 3 pad\nlabel l\nprint \"L=${L} $(v_L*2:%5.2f)\"\nnext L\njump SELF l\n".to_vec(),
        b"print \"\"\"multi\nline ${x}\"\"\" # c\nrun 100 every 25 \"print $(step)\" NULL\n".to_vec(),
    ];
    let mut files = Vec::new();
    collect(Path::new("/work/shared/decks"), &mut files, 0);
    if let Ok(rd) = std::fs::read_dir("/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public") {
        let mut dirs: Vec<_> = rd.flatten().map(|e| e.path()).collect();
        dirs.sort();
        for d in dirs {
            if let Ok(rd) = std::fs::read_dir(&d) {
                let mut f: Vec<_> =
                    rd.flatten().map(|e| e.path()).filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("in."))).collect();
                f.sort();
                files.extend(f);
            }
        }
    }
    for f in files {
        if let Ok(b) = std::fs::read(&f) {
            if !b.is_empty() && b.len() <= 64 * 1024 && !b.contains(&0) {
                out.push(b);
            }
        }
    }
    out
}

fn collect(dir: &Path, out: &mut Vec<std::path::PathBuf>, depth: usize) {
    if depth > 8 {
        return;
    }
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<_> = rd.flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(&p, out, depth + 1);
        } else if p.is_file() {
            out.push(p);
        }
    }
}

fn mutate(rng: &mut XorShift, seeds: &[Vec<u8>], base: &[u8]) -> Vec<u8> {
    let mut d = base.to_vec();
    let n = 1 + rng.below(8);
    for _ in 0..n {
        let len = d.len();
        match rng.below(7) {
            0 if len > 0 => {
                let i = rng.below(len);
                d[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                let k = 1 + rng.below(16.min(len - i));
                d.drain(i..i + k);
            }
            2 if len > 0 => {
                let i = rng.below(len);
                let k = 1 + rng.below(64.min(len - i));
                let chunk = d[i..i + k].to_vec();
                let j = rng.below(d.len() + 1);
                d.splice(j..j, chunk);
            }
            3 => {
                let other = &seeds[rng.below(seeds.len())];
                if !other.is_empty() {
                    let a = rng.below(other.len());
                    let b = a + rng.below(other.len() - a + 1);
                    let j = rng.below(d.len() + 1);
                    d.splice(j..j, other[a..b].iter().copied());
                }
            }
            _ => {
                let t = TOKENS[rng.below(TOKENS.len())].as_bytes();
                let j = rng.below(d.len() + 1);
                d.splice(j..j, t.iter().copied());
            }
        }
    }
    d.truncate(128 * 1024);
    d
}

fn run_one(text: &str) -> Option<String> {
    let mut it = Interpreter::new(SourceMap::new(), vec![("cli".into(), vec!["1".into(), "2".into()])]);
    it.set_command_limit(300);
    it.set_file_access(false);
    let mut host = Accept { step: 0 };
    match it.run_text("in.fuzz", text, &mut host) {
        Ok(()) => None,
        Err(e) => Some(e.render(&it.sources)),
    }
}

/// `DEMX_FUZZ_REPLAY=path` runs one saved deck without catching panics.
#[test]
fn fuzz_replay() {
    if let Ok(p) = std::env::var("DEMX_FUZZ_REPLAY") {
        let text = demx::script::source::decode(&std::fs::read(p).unwrap());
        eprintln!("{:?}", run_one(&text));
    }
}

#[test]
fn fuzz_interpreter_never_panics() {
    let cases: usize = std::env::var("DEMX_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(20000);
    let seed: u64 = std::env::var("DEMX_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(0x5eed_d3c5);
    let seeds = seeds();
    let mut rng = XorShift(seed | 1);
    let t0 = std::time::Instant::now();
    let mut errors = 0usize;
    // the expected panics of this thread stay quiet; the other tests of the
    // binary (threads of the same process) keep their panic messages
    thread_local!(static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) });
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !QUIET.with(std::cell::Cell::get) {
            default(info)
        }
    }));
    QUIET.with(|q| q.set(true));
    for case in 0..cases {
        let base = &seeds[rng.below(seeds.len())];
        let deck = mutate(&mut rng, &seeds, base);
        let text = demx::script::source::decode(&deck);
        let r = catch_unwind(AssertUnwindSafe(|| match run_one(&text) {
            None => false,
            Some(r) => {
                assert!(!r.is_empty());
                true
            }
        }));
        match r {
            Ok(is_err) => errors += usize::from(is_err),
            Err(_) => {
                QUIET.with(|q| q.set(false));
                let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-panic.in");
                let _ = std::fs::write(&path, &deck);
                panic!("case {case} (seed {seed}) panicked; deck saved to {}", path.display());
            }
        }
    }
    QUIET.with(|q| q.set(false));
    eprintln!("{cases} cases ({errors} errors) from {} seeds in {:.1?}", seeds.len(), t0.elapsed());
    assert!(errors < cases || cases == 0, "every mutated deck failed: mutations too destructive");
}
