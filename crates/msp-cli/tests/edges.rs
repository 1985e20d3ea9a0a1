//! Hostile inputs and outputs at the edges: allocations sized by input
//! (under a `ulimit -v`, so that an abort fails the test), special files that
//! could hang, and output paths that must not be replaced.
#![cfg(target_os = "linux")]

mod common;

use common::*;
use std::time::{Duration, Instant};

/// `msp step --plant 1/(s+1) -o PATH`: a small CSV written to `path`.
fn step_to(path: impl AsRef<std::ffi::OsStr>) -> assert_cmd::Command {
    let mut cmd = msp();
    cmd.args(["step", "--plant", "1/(s+1)", "-o"]).arg(path);
    cmd
}

/// Runs `msp ARGS` under a 4 GiB address-space limit; the exit status
/// (never a signal: an abort or a kill fails the test) and stderr.
fn limited(args: &[&str]) -> (i32, String) {
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let mut line = format!("ulimit -v 4194304; exec '{}'", bin.display());
    for a in args {
        line.push_str(&format!(" '{a}'"));
    }
    let out = std::process::Command::new("bash")
        .args(["-c", &line])
        .output()
        .unwrap();
    let code = out
        .status
        .code()
        .unwrap_or_else(|| panic!("{args:?} ended by a signal: {:?}", out.status));
    (code, String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A run-time dead time far beyond memory is refused by the budget before
/// the robustness and stability rebuilds allocate it, naming the event;
/// raised past the machine, the budget still ends in an error.
#[test]
fn dead_time_events_beyond_memory_are_refused() {
    const SMITH: &str = "--plant 2*e^-3s/(4s+1) -c smith";
    for d in ["1e7", "1e9", "1e12"] {
        let event = format!("20:dead-time={d}");
        let (code, err) = limited(&line(&format!("margins {SMITH} --event {event}")));
        assert_eq!(code, 2, "margins {event}: {err}");
        let (code, err) = limited(&line(&format!("run {SMITH} --event {event} -o /dev/null")));
        assert_eq!(code, 2);
        assert!(err.contains("the event at 20 s"), "{err}");
    }
    let (code, err) = limited(&line(&format!(
        "run {SMITH} --event 20:dead-time=1e9 --max-memory 100000T -o /dev/null"
    )));
    assert_eq!(code, 2, "{err}");
}

/// Files that never end, never come or are not text: a clean error, fast.
#[test]
fn special_inputs_end_in_errors() {
    let dir = tempfile::tempdir().unwrap();
    let sparse = dir.path().join("sparse.csv");
    std::fs::File::create(&sparse)
        .unwrap()
        .set_len(2 << 30)
        .unwrap();
    let sparse = sparse.to_str().unwrap().to_string();
    for args in [
        vec!["identify", "--data", "/dev/zero"],
        vec!["identify", "--data", sparse.as_str()],
        vec!["run", "--scenario", "/dev/zero"],
        vec!["sweep", "--merge", "/dev/zero", "-o", "-"],
    ] {
        let (code, err) = limited(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("binary data") || err.contains("more than"),
            "{args:?}: {err}"
        );
    }
    // a FIFO nobody writes to: an error after the read's timeout, not a hang
    let fifo = dir.path().join("fifo");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let started = Instant::now();
    fails(
        msp()
            .args(["identify", "--data"])
            .arg(&fifo)
            .timeout(Duration::from_secs(60)),
        2,
        "no data came",
    );
    assert!(started.elapsed() < Duration::from_secs(30));
    // and nobody reads from: an error at once
    fails(
        step_to(&fifo).timeout(Duration::from_secs(60)),
        1,
        "nobody reads",
    );
}

/// `-o` through a link to standard output writes to standard output: the
/// link stays a link, the redirection gets the CSV. A link to a file
/// replaces the file, not the link.
#[test]
fn links_are_followed_not_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("out.csv");
    std::os::unix::fs::symlink("/proc/self/fd/1", &link).unwrap();
    let out = step_to(&link)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    assert!(String::from_utf8_lossy(&out).starts_with("t,u,y\n"));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let target = dir.path().join("target.csv");
    std::fs::write(&target, "old").unwrap();
    let to_file = dir.path().join("to_file.csv");
    std::os::unix::fs::symlink(&target, &to_file).unwrap();
    step_to(&to_file).assert().success();
    assert!(std::fs::symlink_metadata(&to_file)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read_to_string(&target)
        .unwrap()
        .starts_with("t,u,y"));
    // a closed pipe on -o /dev/stdout ends quietly, as on -o -
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let o = std::process::Command::new("bash")
        .args(["-c", &format!("'{}' run --plant '1/(s+1)' -o /dev/stdout | head -c 10 >/dev/null; echo ${{PIPESTATUS[0]}}", bin.display())])
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).trim(),
        "0",
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("error"));
    // one file by two spellings
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let x = dir.path().join("x.csv");
    let y = dir.path().join("sub/../x.csv");
    fails(
        msp()
            .args(["run", "--plant", "1/(s+1)", "-o"])
            .arg(&x)
            .arg("--report")
            .arg(&y),
        2,
        "name the same file",
    );
}

/// A replaced file keeps its permission bits but not a set-user-ID bit; a
/// temporary-looking file of a user's is left alone, and nothing is cleaned
/// when the command fails.
#[test]
fn replacing_files_keeps_what_is_not_ours() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("su.csv");
    std::fs::write(&f, "x").unwrap();
    std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o4755)).unwrap();
    step_to(&f).assert().success();
    assert_eq!(
        std::fs::metadata(&f).unwrap().permissions().mode() & 0o7777,
        0o755
    );
    let users = dir.path().join(".msp-99999999-x.tmp");
    std::fs::write(&users, "mine").unwrap();
    step_to(dir.path().join("a.csv")).assert().success();
    assert!(users.exists(), "a user's file was deleted");
    // nor one named as msp names its temporaries, of a process gone
    let look_alike = dir.path().join(".msp-99999999-abcdefghijkl.tmp");
    std::fs::write(&look_alike, "").unwrap();
    step_to(dir.path().join("b.csv")).assert().success();
    assert!(look_alike.exists(), "a file msp did not make was deleted");
}

/// A file that belongs to another user is not replaced, directly or
/// through a link (msp would make it this user's; root too): exit 2 naming
/// the owner, the file and the link as they were. As root the file is
/// given to `nobody`; otherwise the link leads to `/etc/passwd` (root's).
#[test]
fn a_file_of_another_user_is_not_replaced() {
    use std::os::unix::fs::MetadataExt;
    let dir = tempfile::tempdir().unwrap();
    let root = std::fs::metadata("/proc/self").unwrap().uid() == 0;
    let theirs = if root {
        let f = dir.path().join("theirs.csv");
        std::fs::write(&f, "keep").unwrap();
        std::os::unix::fs::chown(&f, Some(65534), Some(65534)).unwrap();
        f
    } else {
        std::path::PathBuf::from("/etc/passwd")
    };
    let before = std::fs::read(&theirs).unwrap();
    let owner = std::fs::metadata(&theirs).unwrap().uid();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&theirs, &link).unwrap();
    let mut targets = vec![link.clone()];
    if root {
        targets.push(theirs.clone());
    }
    for target in targets {
        fails(&mut step_to(&target), 2, "belongs to another user");
    }
    assert_eq!(std::fs::read(&theirs).unwrap(), before);
    assert_eq!(std::fs::metadata(&theirs).unwrap().uid(), owner);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
}

/// An existing file the user may not write is not replaced, even in a
/// directory anyone may write to (as `cp` refuses). As root, the command
/// runs as `nobody` for this (setpriv); otherwise the file is made read-only.
#[test]
fn a_file_the_user_may_not_write_is_not_replaced() {
    use std::os::unix::fs::PermissionsExt;
    // under /tmp, which anyone may enter (so `nobody` reaches the copy below)
    let dir = tempfile::Builder::new().tempdir_in("/tmp").unwrap();
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
    let f = dir.path().join("theirs.csv");
    std::fs::write(&f, "keep").unwrap();
    let root = std::fs::read_to_string("/proc/self/status")
        .unwrap()
        .lines()
        .any(|l| l.starts_with("Uid:") && l.split_whitespace().nth(2) == Some("0"));
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let out = if root {
        std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o644)).unwrap();
        // the binary must be reachable for nobody
        let copy = dir.path().join("msp");
        std::fs::copy(&bin, &copy).unwrap();
        std::fs::set_permissions(&copy, std::fs::Permissions::from_mode(0o755)).unwrap();
        std::process::Command::new("setpriv")
            .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
            .arg(&copy)
            .args(["step", "--plant", "1/(s+1)", "-o"])
            .arg(&f)
            .output()
            .expect("setpriv (util-linux) runs the command as nobody")
    } else {
        std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o444)).unwrap();
        std::process::Command::new(&bin)
            .args(["step", "--plant", "1/(s+1)", "-o"])
            .arg(&f)
            .output()
            .unwrap()
    };
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("permission denied"));
    assert_eq!(std::fs::read_to_string(&f).unwrap(), "keep");
}

/// Inputs that were accepted and gave something wrong: each a clear error
/// now, exit 2, naming the field the user gave.
#[test]
fn wrong_inputs_that_were_accepted_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let toml = dir.path().join("a.toml");
    std::fs::write(&toml, "plant = \"1/(s+1)\"\nactuator = [1, 2, 3]\n").unwrap();
    let json = dir.path().join("a.json");
    std::fs::write(&json, r#"{"plant": "1/(s+1)", "ts": 0.1, "ts": 0.2}"#).unwrap();
    let long = "x".repeat(100_000);
    // a step test whose times are scaled by 1e-300
    let tiny = dir.path().join("tiny.csv");
    let mut text = String::from("t,u,y\n0,0,0\n");
    for k in 1..2000 {
        let t = f64::from(k) * 0.05;
        let y = if t > 4.0 {
            2.0 * (1.0 - (-(t - 4.0) / 5.0).exp())
        } else {
            0.0
        };
        text.push_str(&format!("{:e},1,{y}\n", t * 1e-300));
    }
    std::fs::write(&tiny, text).unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["tune", "--plant", "5e-324*e^-1s/(s+1)"], "kp = inf"),
        (
            vec!["tune", "--plant", "e^-1s/(s+1)", "--lambda", "5e-324"],
            "kp = inf",
        ),
        (vec!["tune", "--plant", "1/(s+1)^56*e^-1s"], "order exceeds"),
        (
            vec![
                "tune",
                "--plant",
                "e^-1s/(s+1)",
                "-c",
                "smith",
                "--rule",
                "zn",
            ],
            "only the pid and pi",
        ),
        (
            vec!["margins", "--plant", "e^-1s/(s+1)", "--duration=-1"],
            "duration",
        ),
        (
            vec![
                "run",
                "--plant",
                "e^-1s/(s+1)",
                "--disturbance",
                "input:1@1~5",
                "-o",
                "-",
            ],
            "sine disturbance only",
        ),
        (
            vec![
                "run",
                "--plant",
                "e^-1s/(s+1)",
                "--set",
                "ti=1e-320",
                "-o",
                "-",
            ],
            "`ti`",
        ),
        (
            vec!["autotune", "--plant", "e^-1s/(s+1)", "--noise", "1e308"],
            "`noise`",
        ),
        (
            vec!["run", "--scenario", toml.to_str().unwrap(), "-o", "-"],
            "two values, not 3",
        ),
        (
            vec!["run", "--scenario", json.to_str().unwrap(), "-o", "-"],
            "'ts' is given twice",
        ),
        (
            vec![
                "run",
                "--plant",
                "e^-1s/(s+1)",
                "--duration",
                "10",
                "--event",
                "1e308:manual=0.5",
                "-o",
                "-",
            ],
            "after the end of the run",
        ),
        (
            vec!["identify", "--data", tiny.to_str().unwrap()],
            "identification",
        ),
    ];
    for (args, words) in cases {
        fails(msp().args(&args), 2, words);
    }
    // a long name is not echoed whole
    let out = msp()
        .args(["run", "--plant", "1/(s+1)", "-c", &long])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        out.stderr.len() < 1000,
        "{} bytes of message",
        out.stderr.len()
    );
}

/// A cascade plant's dead time a rounding below a whole number of samples
/// is that whole number, within the line's room (it was "beyond capacity"
/// while 7.2 worked).
#[test]
fn a_dead_time_a_rounding_short_of_whole_samples_fits() {
    for d in ["7.2", "7.199999999999999"] {
        msp()
            .args([
                "run",
                "--plant",
                "e^-4s/(20s-1)",
                "--inner-plant",
                "2*e^-2s/(20s+1)",
                "-c",
                "gpcc",
                "--event",
                &format!("40:plant-dead-time={d}"),
                "-o",
                "/dev/null",
            ])
            .assert()
            .success();
    }
}

/// Text without end on a pipe is read until what it makes is too much —
/// the numbers kept, not the bytes (a short line makes numbers of eight
/// bytes each): refused with a clear error under a 4 GiB address space,
/// never an abort. A header of 200 000 columns gives a message of a few
/// hundred bytes, and a column named twice is refused, naming both.
#[test]
fn endless_wide_and_ambiguous_csv() {
    let bin = assert_cmd::cargo::cargo_bin("msp");
    for cmd in ["identify --data /dev/stdin", "stepinfo --data /dev/stdin"] {
        let line = format!(
            "ulimit -v 4194304; (echo t,u,y; yes 1,1,1) | '{}' {cmd}",
            bin.display()
        );
        let out = std::process::Command::new("bash")
            .args(["-c", &line])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {:?} {err}", out.status);
        assert!(err.contains("numbers in the columns read"), "{cmd}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    let wide = dir.path().join("wide.csv");
    let head: Vec<String> = (0..200_000).map(|i| format!("c{i}")).collect();
    std::fs::write(&wide, format!("{}\n", head.join(","))).unwrap();
    let out = msp()
        .args(["stepinfo", "--data"])
        .arg(&wide)
        .assert()
        .code(2)
        .get_output()
        .clone();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.len() < 1000 && err.contains("and 199980 more"),
        "{} bytes",
        err.len()
    );
    let twice = dir.path().join("twice.csv");
    std::fs::write(&twice, "t,y,u,y\n0,0,1,5\n1,1,1,6\n2,1,1,6\n").unwrap();
    fails(
        msp().args(["stepinfo", "--data"]).arg(&twice),
        2,
        "two columns are named 'y' (columns 2 and 4)",
    );
}

/// A budget raised past what the process may have (`--max-memory 100G`
/// under a 4 GiB address-space limit, a run of about 12 GiB) is refused
/// before anything is allocated, saying what the process can have: the
/// check reads the process's own limits, not the machine's memory alone.
#[test]
fn a_budget_beyond_the_process_limit_is_refused_cleanly() {
    let (code, err) = limited(&[
        "run",
        "-p",
        "e^-5s/(10s+1)",
        "--ts",
        "1e-5",
        "--duration",
        "1000",
        "--max-memory",
        "100G",
        "-o",
        "/dev/null",
        "-q",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("this process can have"), "{err}");
}
