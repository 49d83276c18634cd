//! cfmt against glibc: every line of tests/data/io/cfmt_cases.tsv was printed
//! by glibc `printf` (generator: tests/data/io/cfmt_gen.c).
use demx::io::cfmt::{fmt_g, sprintf, CArg};

fn parse_hex_float(s: &str) -> f64 {
    match s {
        "inf" => return f64::INFINITY,
        "-inf" => return f64::NEG_INFINITY,
        "nan" => return f64::NAN,
        "-nan" => return -f64::NAN,
        _ => {}
    }
    let (neg, s) = s.strip_prefix('-').map_or((false, s), |r| (true, r));
    let s = s.strip_prefix("0x").expect("hex float");
    let (mant, exp) = s.split_once('p').expect("p exponent");
    let exp: i32 = exp.parse().unwrap();
    let (ip, fp) = mant.split_once('.').unwrap_or((mant, ""));
    let mut m: u128 = u128::from_str_radix(ip, 16).unwrap();
    for c in fp.chars() {
        m = m * 16 + c.to_digit(16).unwrap() as u128;
    }
    let e = exp - 4 * fp.len() as i32;
    // Exact: m has at most 53 significant bits; scale in two steps to avoid overflow/underflow.
    let v = (m as f64) * 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
    if neg {
        -v
    } else {
        v
    }
}

#[test]
fn matches_glibc_table() {
    let text = std::fs::read_to_string("tests/data/io/cfmt_cases.tsv").unwrap();
    let mut n = 0;
    let mut bad = Vec::new();
    for line in text.lines() {
        let mut it = line.splitn(4, '\t');
        let (fmt, kind, arg, out) = (it.next().unwrap(), it.next().unwrap(), it.next().unwrap(), it.next().unwrap());
        let want = &out[1..out.len() - 1];
        let got = if kind == "f" { sprintf(fmt, &[CArg::Float(parse_hex_float(arg))]) } else { sprintf(fmt, &[CArg::Int(arg.parse().unwrap())]) };
        match got {
            Ok(g) if g == want => {}
            other => bad.push(format!("{fmt} {arg}: want [{want}] got {other:?}")),
        }
        n += 1;
    }
    assert!(n > 2000, "table too short: {n}");
    assert!(bad.is_empty(), "{} mismatches:\n{}", bad.len(), bad.join("\n"));
}

#[test]
fn fmt_g_is_percent_dot_g() {
    // printf("%.3g|%.6g|%.15g", 0.0005, 1e300, 0.1) in C
    assert_eq!(fmt_g(0.0005, 3), "0.0005");
    assert_eq!(fmt_g(9.9995, 3), "10");
    assert_eq!(fmt_g(1e300, 6), "1e+300");
    assert_eq!(fmt_g(0.1, 15), "0.1");
    assert_eq!(fmt_g(0.1, 17), "0.10000000000000001");
    assert_eq!(fmt_g(f64::NAN, 6), "nan");
}
