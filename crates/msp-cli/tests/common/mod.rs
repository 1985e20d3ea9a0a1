//! What the end-to-end tests share: the binary, its output read as text or
//! JSON.
#![allow(dead_code)] // each test file uses its own part

use assert_cmd::Command;

/// The `msp` binary this package builds.
pub fn msp() -> Command {
    Command::cargo_bin("msp").unwrap()
}

/// A command line's words (arguments without spaces).
pub fn words(line: &str) -> std::str::SplitWhitespace<'_> {
    line.split_whitespace()
}

/// What a successful command printed on stdout.
pub fn stdout_of(cmd: &mut Command) -> String {
    String::from_utf8(cmd.assert().success().get_output().stdout.clone()).unwrap()
}

/// Runs a command that must succeed and reads its standard output as JSON.
pub fn json_of(cmd: &mut Command) -> serde_json::Value {
    serde_json::from_str(&stdout_of(cmd)).unwrap()
}

/// Runs `msp ARGS` (which prints JSON) and reads its standard output.
pub fn json_out(args: &[&str]) -> serde_json::Value {
    json_of(msp().args(args))
}

/// A successful command's stdout holds every one of `wanted`.
pub fn prints(cmd: &mut Command, wanted: &[&str]) {
    let out = stdout_of(cmd);
    for w in wanted {
        assert!(out.contains(w), "{w:?} missing from:\n{out}");
    }
}

/// Standard error of `msp ARGS…`, which must exit with `status`.
pub fn stderr_of<const N: usize>(args: [&str; N], status: i32) -> String {
    let out = msp().args(args).assert().code(status).get_output().clone();
    String::from_utf8(out.stderr).unwrap()
}

/// The command exits with `code` and its stderr says `says`.
pub fn fails(cmd: &mut Command, code: i32, says: &str) {
    let out = cmd.assert().code(code).get_output().clone();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(says), "{says:?} missing from:\n{err}");
}

/// A command line's words, collected (arguments without spaces).
pub fn line(text: &str) -> Vec<&str> {
    words(text).collect()
}

/// `msp ARGS…` exits with status 2 and says `says` on standard error.
pub fn rejects<I, S>(args: I, says: &str)
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    fails(msp().args(args), 2, says);
}
