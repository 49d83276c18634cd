//! Variable store and formula evaluation through a fake simulation context.

use demx::script::vars::VarStyle;
use demx::script::{Command, EvalContext, Span, Variables, Word};

struct Sim;

impl EvalContext for Sim {
    fn thermo(&self, name: &str) -> Option<f64> {
        match name {
            "step" => Some(250.0),
            "dt" => Some(0.001),
            "atoms" => Some(3.0),
            _ => None,
        }
    }
    fn natoms(&self) -> usize {
        3
    }
    fn atom_vector(&self, k: &str) -> Result<Vec<f64>, String> {
        match k {
            "id" => Ok(vec![10.0, 20.0, 30.0]),
            "x" => Ok(vec![1.0, 2.0, 3.0]),
            "radius" => Ok(vec![0.5, 0.25, 0.125]),
            _ => Err(format!("no {k}")),
        }
    }
    fn atom_value(&self, k: &str, id: i64) -> Result<f64, String> {
        if k == "x" && id == 20 {
            Ok(2.0)
        } else {
            Err(format!("no atom {id}"))
        }
    }
    fn group_function(&self, name: &str, args: &[&str]) -> Result<f64, String> {
        match (name, args) {
            ("count", ["all"]) => Ok(3.0),
            ("xcm", ["all", "x"]) => Ok(2.0),
            _ => Err(format!("no {name}")),
        }
    }
    fn compute(&self, id: &str, i: Option<usize>, j: Option<usize>) -> Result<f64, String> {
        match (id, i, j) {
            ("ke", None, None) => Ok(4.0),
            ("t", Some(2), Some(3)) => Ok(23.0),
            _ => Err(format!("no compute {id}")),
        }
    }
    fn peratom(&self, prefix: char, id: &str, col: Option<usize>) -> Result<Vec<f64>, String> {
        match (prefix, id, col) {
            ('c', "pe", None) => Ok(vec![1.0, 0.0, -1.0]),
            _ => Err("none".into()),
        }
    }
    fn run_bounds(&self) -> Option<(i64, i64)> {
        Some((0, 1000))
    }
}

fn define(v: &mut Variables, line: &str) -> demx::Result<()> {
    // split like the lexer would for simple lines (no quotes needed here)
    let words = line.split_whitespace().map(|w| Word::new(w, Span::DUMMY)).collect();
    v.define(&Command { words, span: Span::DUMMY })
}

#[test]
fn atom_style_over_vectors() {
    let mut v = Variables::new();
    define(&mut v, "variable e equal 1").unwrap();
    define(&mut v, "variable a atom x*2+v_e").unwrap();
    define(&mut v, "variable m atom 4/3*PI*radius^3*2500").unwrap();
    define(&mut v, "variable p atom c_pe+c_ke").unwrap();
    define(&mut v, "variable b equal v_a[20]+x[20]").unwrap();
    assert_eq!(v.eval_atom("a", &Sim).unwrap(), vec![3.0, 5.0, 7.0]);
    let m = v.eval_atom("m", &Sim).unwrap();
    for (mi, r) in m.iter().zip([0.5f64, 0.25, 0.125]) {
        assert!((mi - 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * 2500.0).abs() < 1e-9);
    }
    assert_eq!(v.eval_atom("p", &Sim).unwrap(), vec![5.0, 4.0, 3.0]);
    assert_eq!(v.eval_equal("b", &Sim).unwrap(), 7.0);
    // equal-style cannot use a bare per-atom vector
    define(&mut v, "variable bad equal x*2").unwrap();
    assert!(v.eval_equal("bad", &Sim).unwrap_err().contains("per-atom vector 'x'"));
    // an equal variable in atom context is broadcast
    assert_eq!(v.eval_atom("e", &Sim).unwrap(), vec![1.0, 1.0, 1.0]);
    assert_eq!(v.style("a"), Some(VarStyle::Atom));
}

#[test]
fn host_values_and_functions() {
    let v = Variables::new();
    assert_eq!(v.eval_expr("count(all)*xcm(all,x)+c_ke+c_t[2][3]", &Sim).unwrap(), 3.0 * 2.0 + 4.0 + 23.0);
    assert_eq!(v.eval_expr("step/atoms", &Sim).unwrap(), 250.0 / 3.0);
    // ramp over a run from 0 to 1000 at step 250: 10 + 0.25*(20-10)
    assert_eq!(v.eval_expr("ramp(10,20)", &Sim).unwrap(), 12.5);
    // stagger(100,10) at 250 -> 300; stride(0,1000,100) -> 300
    // logfreq(10,4,10): 10 20 30 40 100 200 300 ...; logfreq(10,2,10): 10 20 100 200 1000 (LAMMPS variable doc)
    assert_eq!(v.eval_expr("stagger(100,10)", &Sim).unwrap(), 300.0);
    assert_eq!(v.eval_expr("logfreq(10,4,10)", &Sim).unwrap(), 300.0);
    assert_eq!(v.eval_expr("logfreq(10,2,10)", &Sim).unwrap(), 1000.0);
    assert_eq!(v.eval_expr("stride(0,1000,100)", &Sim).unwrap(), 300.0);
    // vdisplace(1,2) = 1 + 2*dt*(step-begin) = 1 + 2*0.001*250
    assert!((v.eval_expr("vdisplace(1,2)", &Sim).unwrap() - 1.5).abs() < 1e-12);
    let e = v.eval_expr("temp*2", &Sim).unwrap_err();
    assert!(e.contains("unknown keyword 'temp'"), "{e}");
    assert_eq!(v.eval_expr("is_defined(variable,zz)", &Sim).unwrap(), 0.0);
    let r = v.eval_expr("random(0,1,12345)", &Sim).unwrap();
    assert!((0.0..1.0).contains(&r));
}

#[test]
fn styles_and_errors() {
    let mut v = Variables::new();
    // cargo sets it for the tests (setting one here would change the
    // environment of every test in this process)
    define(&mut v, "variable g getenv CARGO_PKG_NAME").unwrap();
    assert_eq!(v.string_value("g", &Sim).unwrap(), env!("CARGO_PKG_NAME"));
    define(&mut v, "variable i internal 2.5").unwrap();
    v.set_internal("i", 4.0);
    assert_eq!(v.eval_equal("i", &Sim).unwrap(), 4.0);
    define(&mut v, "variable w world only").unwrap();
    assert!(define(&mut v, "variable w2 world a b").is_err());
    define(&mut v, "variable u universe a b").unwrap();
    define(&mut v, "variable ul uloop 2").unwrap();
    assert_eq!(v.string_value("ul", &Sim).unwrap(), "1");
    for s in ["python", "file", "atomfile", "vector"] {
        let e = define(&mut v, &format!("variable z {s} x")).unwrap_err();
        assert_eq!(e.exit_code(), 3, "{s}");
        assert!(e.message().contains(s));
    }
    let e = define(&mut v, "variable z equl 1").unwrap_err();
    assert_eq!(e.message(), "unknown variable style 'equl'");
    define(&mut v, "variable z delete").unwrap();
    define(&mut v, "variable g delete").unwrap();
    assert!(!v.is_defined("g"));
    let e = v.string_value("ii", &Sim).unwrap_err();
    assert!(e.contains("did you mean 'i'"), "{e}");
    define(&mut v, "variable f format f %g").unwrap();
    assert!(v.string_value("f", &Sim).is_err());
}

#[test]
fn hosts_substitute_fix_print_text() {
    let mut v = Variables::new();
    define(&mut v, "variable h equal 0.25").unwrap();
    let w = Word::new("step $(step) h=${h} $h", Span::DUMMY);
    assert_eq!(v.substitute_word(&w, &Sim).unwrap(), "step 250 h=0.25 0.25");
    let bad = Word::new("${nope}", Span::DUMMY);
    assert_eq!(v.substitute_word(&bad, &Sim).unwrap_err().message(), "variable 'nope' is not defined");
}
