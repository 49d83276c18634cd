//! C printf-style number formatting, as LAMMPS and LIGGGHTS use for dumps,
//! thermo output and `$(expr:%fmt)`.
//!
//! The output follows glibc byte for byte for the conversions `d i u x X o
//! e E f F g G s c %`, the flags `- + space 0 #`, width and precision (no `*`).
//! Digits come from Rust's exact float formatting, which like glibc rounds the
//! exact binary value half-to-even, so `%.3g` of 0.0005 or `%.0f` of 2.5 agree.
//! [`fmt_shortest`] is the `{}` formatting of the {fmt} library that LAMMPS
//! 29 Sep 2021 `write_data` uses (shortest text that reads back exactly).

use std::fmt::Write as _;

/// One printf argument.
#[derive(Clone, Copy, Debug)]
pub enum CArg<'a> {
    /// Integer (for %d, %i).
    Int(i64),
    /// Float (for %g, %e, %f).
    Float(f64),
    /// String (for %s).
    Str(&'a str),
}

/// What kind of argument a conversion consumes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArgKind {
    /// `d i u x X o c`.
    Int,
    /// `e E f F g G`.
    Float,
    /// `s`.
    Str,
}

/// One parsed `%...` conversion.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Spec {
    left: bool,
    plus: bool,
    space: bool,
    zero: bool,
    alt: bool,
    width: usize,
    precision: Option<usize>,
    /// Number of `l` (or `j`, `z`, `t`, `q`, `L` counted as 2) modifiers.
    long: u8,
    conv: u8,
}

#[derive(Clone, Debug, PartialEq, Eq)]
enum Piece {
    Lit(String),
    Conv(Spec),
}

/// A parsed printf format string, reusable for many calls.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CFormat {
    pieces: Vec<Piece>,
}

impl CFormat {
    /// Parse `fmt`; errors name what is wrong (unknown conversion, `*`, a
    /// trailing lone `%`).
    pub fn parse(fmt: &str) -> Result<CFormat, String> {
        let b = fmt.as_bytes();
        let mut pieces = Vec::new();
        let mut lit = String::new();
        let mut i = 0;
        while i < b.len() {
            // Copy literal text up to the next '%' (keeps UTF-8 intact).
            let start = i;
            while i < b.len() && b[i] != b'%' {
                i += 1;
            }
            lit.push_str(&fmt[start..i]);
            if i >= b.len() {
                break;
            }
            let pct = i;
            i += 1;
            if i < b.len() && b[i] == b'%' {
                lit.push('%');
                i += 1;
                continue;
            }
            let mut s = Spec { left: false, plus: false, space: false, zero: false, alt: false, width: 0, precision: None, long: 0, conv: 0 };
            while i < b.len() {
                match b[i] {
                    b'-' => s.left = true,
                    b'+' => s.plus = true,
                    b' ' => s.space = true,
                    b'0' => s.zero = true,
                    b'#' => s.alt = true,
                    b'\'' => {}
                    _ => break,
                }
                i += 1;
            }
            let num = |i: &mut usize| -> Result<usize, String> {
                let mut v: usize = 0;
                while *i < b.len() && b[*i].is_ascii_digit() {
                    v = v
                        .checked_mul(10)
                        .and_then(|v| v.checked_add((b[*i] - b'0') as usize))
                        .filter(|v| *v <= 100_000)
                        .ok_or_else(|| format!("width or precision too large in '{}'", &fmt[pct..]))?;
                    *i += 1;
                }
                Ok(v)
            };
            if i < b.len() && b[i] == b'*' {
                return Err(format!("'*' width is not supported in format '{fmt}'"));
            }
            s.width = num(&mut i)?;
            if i < b.len() && b[i] == b'.' {
                i += 1;
                if i < b.len() && b[i] == b'*' {
                    return Err(format!("'*' precision is not supported in format '{fmt}'"));
                }
                s.precision = Some(num(&mut i)?);
            }
            while i < b.len() {
                match b[i] {
                    b'h' => {}
                    b'l' => s.long = s.long.saturating_add(1),
                    b'L' | b'q' | b'j' | b'z' | b't' => s.long = 2,
                    _ => break,
                }
                i += 1;
            }
            if i >= b.len() {
                return Err(format!("incomplete conversion '{}' at the end of format '{fmt}'", &fmt[pct..]));
            }
            match b[i] {
                b'd' | b'i' | b'u' | b'x' | b'X' | b'o' | b'c' | b'e' | b'E' | b'f' | b'F' | b'g' | b'G' | b's' => s.conv = b[i],
                _ => {
                    let end = fmt[i..].chars().next().map_or(i + 1, |c| i + c.len_utf8());
                    return Err(format!("unknown conversion '{}' in format '{fmt}'", &fmt[pct..end]));
                }
            }
            i += 1;
            if !lit.is_empty() {
                pieces.push(Piece::Lit(std::mem::take(&mut lit)));
            }
            pieces.push(Piece::Conv(s));
        }
        if !lit.is_empty() {
            pieces.push(Piece::Lit(lit));
        }
        Ok(CFormat { pieces })
    }

    /// The kinds of arguments the conversions consume, in order.
    pub fn arg_kinds(&self) -> Vec<ArgKind> {
        self.pieces
            .iter()
            .filter_map(|p| match p {
                Piece::Conv(s) => Some(match s.conv {
                    b'e' | b'E' | b'f' | b'F' | b'g' | b'G' => ArgKind::Float,
                    b's' => ArgKind::Str,
                    _ => ArgKind::Int,
                }),
                Piece::Lit(_) => None,
            })
            .collect()
    }

    /// Append the formatted text to `out`. Integers are accepted by float
    /// conversions; floats with an integral value by integer conversions.
    /// Missing or mismatched arguments are errors; extra ones are ignored
    /// (as in C).
    pub fn write(&self, out: &mut String, args: &[CArg]) -> Result<(), String> {
        let mut next = 0;
        for p in &self.pieces {
            match p {
                Piece::Lit(s) => out.push_str(s),
                Piece::Conv(s) => {
                    let a = args.get(next).ok_or_else(|| format!("format needs more than {} argument(s)", args.len()))?;
                    next += 1;
                    write_conv(out, s, a)?;
                }
            }
        }
        Ok(())
    }

    /// Format into a new string.
    pub fn format(&self, args: &[CArg]) -> Result<String, String> {
        let mut s = String::new();
        self.write(&mut s, args)?;
        Ok(s)
    }
}

/// Format like C `sprintf(fmt, args...)`. Errors name what is wrong with `fmt`.
pub fn sprintf(fmt: &str, args: &[CArg]) -> Result<String, String> {
    CFormat::parse(fmt)?.format(args)
}

/// C `%.{precision}g` of one number.
pub fn fmt_g(x: f64, precision: usize) -> String {
    let mut out = String::new();
    let s = Spec { left: false, plus: false, space: false, zero: false, alt: false, width: 0, precision: Some(precision), long: 0, conv: b'g' };
    write_float(&mut out, &s, x);
    out
}

/// C `%g` (6 significant digits), the default float format of dumps.
pub fn fmt_g6(x: f64) -> String {
    fmt_g(x, 6)
}

/// C `%-1.16e` (the box-bound format of LAMMPS dumps and LIGGGHTS data files).
pub fn fmt_e16(x: f64) -> String {
    let mut out = String::new();
    let s = Spec { left: true, plus: false, space: false, zero: false, alt: false, width: 1, precision: Some(16), long: 0, conv: b'e' };
    write_float(&mut out, &s, x);
    out
}

/// Shortest text that reads back to exactly `x`, in the style of the {fmt}
/// library's `{}` (LAMMPS 29 Sep 2021 `write_data`): `0.1`, `2`, `-0`,
/// `1e-05`, `1e+16`, `inf`, `nan`. Exponent form is used when the decimal
/// exponent is below -4 or at least 16.
pub fn fmt_shortest(x: f64) -> String {
    if x.is_nan() {
        return if x.is_sign_negative() { "-nan".into() } else { "nan".into() };
    }
    if x.is_infinite() {
        return if x < 0.0 { "-inf".into() } else { "inf".into() };
    }
    let neg = x.is_sign_negative();
    let e = format!("{:e}", x.abs());
    let (mant, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let digits: String = mant.chars().filter(|c| c.is_ascii_digit()).collect();
    let mut out = String::new();
    if neg {
        out.push('-');
    }
    if !(-4..16).contains(&exp) {
        out.push_str(&digits[..1]);
        if digits.len() > 1 {
            out.push('.');
            out.push_str(&digits[1..]);
        }
        push_exp(&mut out, exp, b'e');
    } else if exp < 0 {
        out.push_str("0.");
        for _ in 0..(-exp - 1) {
            out.push('0');
        }
        out.push_str(&digits);
    } else {
        let int_len = exp as usize + 1;
        if digits.len() <= int_len {
            out.push_str(&digits);
            for _ in digits.len()..int_len {
                out.push('0');
            }
        } else {
            out.push_str(&digits[..int_len]);
            out.push('.');
            out.push_str(&digits[int_len..]);
        }
    }
    out
}

fn push_exp(out: &mut String, exp: i32, e: u8) {
    out.push(e as char);
    out.push(if exp < 0 { '-' } else { '+' });
    let a = exp.unsigned_abs();
    if a < 10 {
        out.push('0');
    }
    let _ = write!(out, "{a}");
}

fn write_conv(out: &mut String, s: &Spec, a: &CArg) -> Result<(), String> {
    match s.conv {
        b'e' | b'E' | b'f' | b'F' | b'g' | b'G' => {
            let x = match *a {
                CArg::Float(x) => x,
                CArg::Int(i) => i as f64,
                CArg::Str(t) => return Err(format!("%{} needs a number, got string '{t}'", s.conv as char)),
            };
            write_float(out, s, x);
        }
        b's' => {
            let owned;
            let t: &str = match *a {
                CArg::Str(t) => t,
                CArg::Int(i) => {
                    owned = i.to_string();
                    &owned
                }
                CArg::Float(x) => {
                    owned = fmt_g(x, 6);
                    &owned
                }
            };
            let t = match s.precision {
                Some(p) => t.char_indices().nth(p).map_or(t, |(i, _)| &t[..i]),
                None => t,
            };
            pad(out, s, "", t, false);
        }
        _ => {
            let v = match *a {
                CArg::Int(i) => i,
                CArg::Float(x) if x.fract() == 0.0 && x.abs() < 9.2e18 => x as i64,
                CArg::Float(x) => return Err(format!("%{} needs an integer, got {}", s.conv as char, fmt_g(x, 6))),
                CArg::Str(t) => return Err(format!("%{} needs an integer, got string '{t}'", s.conv as char)),
            };
            write_int(out, s, v);
        }
    }
    Ok(())
}

/// Write `sign` + `body` padded to the width; `zero_ok` allows '0' padding.
fn pad(out: &mut String, s: &Spec, sign: &str, body: &str, zero_ok: bool) {
    let len = sign.len() + body.chars().count();
    let fill = s.width.saturating_sub(len);
    if s.left {
        out.push_str(sign);
        out.push_str(body);
        out.extend(std::iter::repeat_n(' ', fill));
    } else if s.zero && zero_ok {
        out.push_str(sign);
        out.extend(std::iter::repeat_n('0', fill));
        out.push_str(body);
    } else {
        out.extend(std::iter::repeat_n(' ', fill));
        out.push_str(sign);
        out.push_str(body);
    }
}

fn write_int(out: &mut String, s: &Spec, v: i64) {
    if s.conv == b'c' {
        let c = char::from_u32((v as u32) & 0xff).unwrap_or('?');
        pad(out, s, "", &c.to_string(), false);
        return;
    }
    let signed = matches!(s.conv, b'd' | b'i');
    let (neg, mag): (bool, u64) = if signed {
        if s.long == 0 {
            let v = v as i32;
            (v < 0, (v as i64).unsigned_abs())
        } else {
            (v < 0, v.unsigned_abs())
        }
    } else if s.long == 0 {
        (false, v as u32 as u64)
    } else {
        (false, v as u64)
    };
    let mut digits = match s.conv {
        b'x' => format!("{mag:x}"),
        b'X' => format!("{mag:X}"),
        b'o' => format!("{mag:o}"),
        _ => mag.to_string(),
    };
    if let Some(p) = s.precision {
        if p == 0 && mag == 0 {
            digits.clear();
        }
        while digits.len() < p {
            digits.insert(0, '0');
        }
    }
    let mut sign = String::new();
    if signed {
        if neg {
            sign.push('-');
        } else if s.plus {
            sign.push('+');
        } else if s.space {
            sign.push(' ');
        }
    } else if s.alt {
        match s.conv {
            b'x' if mag != 0 => sign.push_str("0x"),
            b'X' if mag != 0 => sign.push_str("0X"),
            b'o' if !digits.starts_with('0') => digits.insert(0, '0'),
            _ => {}
        }
    }
    pad(out, s, &sign, &digits, s.precision.is_none());
}

fn write_float(out: &mut String, s: &Spec, x: f64) {
    let upper = s.conv.is_ascii_uppercase();
    let neg = x.is_sign_negative();
    let sign = if neg {
        "-"
    } else if s.plus {
        "+"
    } else if s.space {
        " "
    } else {
        ""
    };
    if !x.is_finite() {
        let body = match (x.is_nan(), upper) {
            (true, false) => "nan",
            (true, true) => "NAN",
            (false, false) => "inf",
            (false, true) => "INF",
        };
        pad(out, s, sign, body, false);
        return;
    }
    let a = x.abs();
    let p = s.precision.unwrap_or(6);
    let body = match s.conv.to_ascii_lowercase() {
        b'f' => {
            let mut b = format!("{:.*}", p, a);
            if s.alt && p == 0 {
                b.push('.');
            }
            b
        }
        b'e' => fmt_exp(a, p, s.alt, if upper { b'E' } else { b'e' }),
        _ => {
            let p = if p == 0 { 1 } else { p };
            let probe = format!("{:.*e}", p - 1, a);
            let exp: i32 = probe.rsplit_once('e').and_then(|(_, e)| e.parse().ok()).unwrap_or(0);
            let mut b = if exp < -4 || exp >= p as i32 {
                // glibc quirk: when rounding in the fixed branch carries into
                // a new digit (999999.5 at %#g), the fraction digits of the
                // fixed branch (zero) are kept: "1.e+06".
                let digits = if s.alt && exp == p as i32 && unrounded_exp(a) == exp - 1 { 0 } else { p - 1 };
                fmt_exp(a, digits, s.alt, if upper { b'E' } else { b'e' })
            } else {
                let mut f = format!("{:.*}", (p as i32 - 1 - exp) as usize, a);
                if s.alt && !f.contains('.') {
                    f.push('.');
                }
                f
            };
            if !s.alt {
                strip_zeros(&mut b);
            }
            b
        }
    };
    pad(out, s, sign, &body, true);
}

/// Decimal exponent of `a` before any rounding.
fn unrounded_exp(a: f64) -> i32 {
    let r = format!("{:.40e}", a);
    r.rsplit_once('e').and_then(|(_, e)| e.parse().ok()).unwrap_or(0)
}

/// `d.ddde+XX` with `p` fraction digits.
fn fmt_exp(a: f64, p: usize, alt: bool, e: u8) -> String {
    let r = format!("{:.*e}", p, a);
    let (mant, exp) = r.rsplit_once('e').unwrap_or((&r, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let mut b = String::with_capacity(mant.len() + 5);
    b.push_str(mant);
    if alt && p == 0 {
        b.push('.');
    }
    push_exp(&mut b, exp, e);
    b
}

/// Remove trailing zeros of the fraction (and a bare '.') before any exponent.
fn strip_zeros(b: &mut String) {
    let (num, exp) = match b.find(['e', 'E']) {
        Some(i) => (b[..i].to_string(), b[i..].to_string()),
        None => (b.clone(), String::new()),
    };
    if !num.contains('.') {
        return;
    }
    let t = num.trim_end_matches('0').trim_end_matches('.');
    *b = format!("{t}{exp}");
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(fmt: &str, x: f64) -> String {
        sprintf(fmt, &[CArg::Float(x)]).unwrap()
    }

    #[test]
    fn glibc_cases() {
        // Expected strings from `printf` (bash builtin, glibc) on Debian.
        assert_eq!(f("%g", 0.0), "0");
        assert_eq!(f("%g", -0.0), "-0");
        assert_eq!(f("%g", 1e-300), "1e-300");
        assert_eq!(f("%g", 100000.0), "100000");
        assert_eq!(f("%g", 1000000.0), "1e+06");
        assert_eq!(f("%.3g", 0.0005), "0.0005");
        assert_eq!(f("%.3g", 9.9995), "10");
        assert_eq!(f("%#.3g", 9.9995), "10.0");
        assert_eq!(f("%-1.16e", -2.0), "-2.0000000000000000e+00");
        assert_eq!(f("%08.3f", -3.14259), "-003.143");
        assert_eq!(f("%+.2e", 12345.678), "+1.23e+04");
        assert_eq!(f("%5.1f", f64::INFINITY), "  inf");
        assert_eq!(f("%05G", f64::NAN), "  NAN");
        assert_eq!(
            sprintf("%5d|%-5d|%05d|%+d|% d", &[CArg::Int(42), CArg::Int(-42), CArg::Int(-42), CArg::Int(7), CArg::Int(7)]).unwrap(),
            "   42|-42  |-0042|+7| 7"
        );
        assert_eq!(sprintf("%.0d|%.3d|%u", &[CArg::Int(0), CArg::Int(5), CArg::Int(-1)]).unwrap(), "|005|4294967295");
        assert_eq!(sprintf("%s=%5s%%", &[CArg::Str("a"), CArg::Str("bc")]).unwrap(), "a=   bc%");
    }

    #[test]
    fn bad_formats_are_errors() {
        assert!(sprintf("%q", &[CArg::Int(1)]).is_err());
        assert!(sprintf("%*d", &[CArg::Int(1)]).is_err());
        assert!(sprintf("%d %d", &[CArg::Int(1)]).is_err());
        assert!(sprintf("abc %", &[]).is_err());
        assert!(sprintf("%d", &[CArg::Float(1.5)]).is_err());
    }

    #[test]
    fn shortest_like_fmt_library() {
        assert_eq!(fmt_shortest(0.1), "0.1");
        assert_eq!(fmt_shortest(2.0), "2");
        assert_eq!(fmt_shortest(-0.0), "-0");
        assert_eq!(fmt_shortest(0.029999999999999874), "0.029999999999999874");
        assert_eq!(fmt_shortest(1e-5), "1e-05");
        assert_eq!(fmt_shortest(1e-4), "0.0001");
        assert_eq!(fmt_shortest(1e16), "1e+16");
        assert_eq!(fmt_shortest(1e15), "1000000000000000");
        assert_eq!(fmt_shortest(1.5e300), "1.5e+300");
    }
}
