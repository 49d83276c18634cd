//! C printf-style number formatting, as LAMMPS and LIGGGHTS use for dumps,
//! thermo output and `$(expr:%fmt)` (stub: to be completed).

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

/// Format like C `sprintf(fmt, args...)`. Errors name what is wrong with `fmt`.
pub fn sprintf(fmt: &str, args: &[CArg]) -> Result<String, String> {
    let _ = (fmt, args);
    Err("printf formatting is not implemented yet".into())
}

/// C `%.{precision}g` of one number.
pub fn fmt_g(x: f64, precision: usize) -> String {
    let _ = precision;
    format!("{x}")
}
