//! Everything `msp` writes: files atomically, standard output without
//! panicking, and one module per format.

use std::io::Write;
use std::path::{Path, PathBuf};

use msp::poly::fmt_num;
use serde_json::Value;

use crate::error::CliError;

pub(crate) mod csv;
pub(crate) mod json;
pub(crate) mod svg;
pub(crate) mod text;

/// Writes `bytes` to `path` through a temporary file in the same directory and
/// a rename, so a failure never leaves a truncated file behind.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let fail = |e: std::io::Error| {
        let _ = std::fs::remove_file(&tmp);
        CliError::Runtime(format!("cannot write {}: {e}", path.display()))
    };
    let mut f = std::fs::File::create(&tmp).map_err(fail)?;
    f.write_all(bytes).map_err(fail)?;
    f.sync_all().map_err(fail)?;
    drop(f);
    std::fs::rename(&tmp, path).map_err(fail)
}

/// Writes `bytes` to the file `path` (atomically) or to standard output.
pub(crate) fn write_or_print(path: Option<&PathBuf>, bytes: &[u8]) -> Result<(), CliError> {
    match path {
        Some(p) => write_atomic(p, bytes),
        None => print(bytes),
    }
}

/// Writes `bytes` to standard output and flushes: a closed pipe becomes
/// [`CliError::BrokenPipe`], any other failure (`> /dev/full`) a runtime error.
pub(crate) fn print(bytes: &[u8]) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(|e| CliError::stdout(&e))
}

/// One line of text to standard output, as [`print`].
pub(crate) fn print_line(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    print(format!("{args}\n").as_bytes())
}

/// A message for the user on standard error. A failure to write it (a closed
/// or full standard error) is ignored: the exit status still tells.
pub(crate) fn note(args: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "{args}");
}

/// `println!` that returns a [`CliError`] instead of panicking.
macro_rules! outln {
    ($($t:tt)*) => {
        $crate::export::print_line(format_args!($($t)*))
    };
}
pub(crate) use outln;

/// `eprintln!` that never panics.
macro_rules! noteln {
    ($($t:tt)*) => {
        $crate::export::note(format_args!($($t)*))
    };
}
pub(crate) use noteln;

/// Shortest round-trip formatting of a float.
pub(crate) fn fmt_f(v: f64) -> String {
    format!("{v}")
}

/// A JSON number, or null for NaN/infinity.
pub(crate) fn num(v: f64) -> Value {
    serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
}

/// `kp=0.0764 ti=40.2 …` for summaries.
pub(crate) fn params_line(p: &msp::registry::Params) -> String {
    p.0.iter()
        .map(|(k, v)| format!("{k}={}", fmt_sig(*v)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A relative change as a signed percentage: `+10`, `-5`, `0`.
pub(crate) fn pct(x: f64) -> String {
    let v = fmt_sig(100.0 * x);
    if x > 0.0 {
        format!("+{v}")
    } else {
        v
    }
}

/// Four significant digits.
pub(crate) fn fmt_sig(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let s = format!("{v:.4e}");
    let x: f64 = s.parse().unwrap_or(v);
    fmt_num(x)
}
