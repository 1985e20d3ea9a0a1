//! End-to-end tests of the real `msp` binary: its files, signals and
//! resources (temporaries, interrupts, pipes, full devices, outputs that
//! would overwrite an input, memory limits, permissions) and the inputs it
//! refuses.
mod common;

use common::*;
use predicates::prelude::*;

/// Files named as msp names its temporaries (`.msp-PID-` and twelve
/// letters or digits, `.tmp`), of a process gone or running, are left
/// alone: a killed run's cannot be told from a look-alike of someone
/// else's, and msp deletes only what this run made.
#[cfg(target_os = "linux")]
#[test]
fn temporaries_of_other_runs_are_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let dead = dir.path().join(".msp-4000000000-abc123def456.tmp");
    let live = dir
        .path()
        .join(format!(".msp-{}-def456abc123.tmp", std::process::id()));
    std::fs::write(&dead, "half a file").unwrap();
    std::fs::write(&live, "being written").unwrap();
    msp()
        .args(words("run --plant e^-2s/(5s+1) --duration 10 -o"))
        .arg(dir.path().join("run.csv"))
        .assert()
        .success();
    assert!(dead.exists() && live.exists());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
}

/// Ctrl-C (SIGINT) stops a long command cleanly: exit status 130 and no
/// output file, whole or partial.
#[cfg(unix)]
#[test]
fn an_interrupt_stops_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let mut child = std::process::Command::new(bin)
        .args(words(
            "sweep --plant 5e^-6s/(100s-1) --gain -20%..20% --delay -20%..20% --grid 40 -o",
        ))
        .arg(dir.path().join("sweep.csv"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(500));
    std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// SIGTERM at any moment of a run that writes three files — before, while
/// and after the temporaries are made and renamed — leaves the outputs
/// whole or absent, never a temporary: 60 signals spread over the run's
/// own duration, measured first.
#[cfg(target_os = "linux")]
#[test]
fn a_signal_at_any_moment_leaves_no_temporary() {
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let run = |dir: &std::path::Path| {
        let mut cmd = std::process::Command::new(&bin);
        cmd.args(words(
            "run --plant e^-2s/(5s+1) --duration 2000 --ts 0.01 -o",
        ))
        .arg(dir.join("run.csv"))
        .arg("--report")
        .arg(dir.join("run.json"))
        .arg("--plot")
        .arg(dir.join("run.svg"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
        cmd
    };
    let dir = tempfile::tempdir().unwrap();
    let started = std::time::Instant::now();
    assert!(run(dir.path()).status().unwrap().success());
    let whole = started.elapsed();
    let sizes: Vec<u64> = ["run.csv", "run.json", "run.svg"]
        .iter()
        .map(|f| std::fs::metadata(dir.path().join(f)).unwrap().len())
        .collect();
    for i in 0..60u32 {
        let dir = tempfile::tempdir().unwrap();
        let mut child = run(dir.path()).spawn().unwrap();
        std::thread::sleep(whole * i / 50);
        let _ = std::process::Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let status = child.wait().unwrap();
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert!(
            names.iter().all(|n| !n.ends_with(".tmp")),
            "try {i} ({status:?}): {names:?}"
        );
        // each output whole, or not there
        for (f, size) in ["run.csv", "run.json", "run.svg"].iter().zip(&sizes) {
            if let Ok(m) = std::fs::metadata(dir.path().join(f)) {
                assert_eq!(m.len(), *size, "try {i}: {f} is not whole");
            }
        }
    }
}

mod loader {
    use msp::study::Scenario;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2000, .. ProptestConfig::default() })]
        #[test]
        fn scenario_files_never_panic(s in "\\PC{0,80}") {
            let _ = toml::from_str::<Scenario>(&s).map_err(|e| e.to_string());
            let _ = serde_json::from_str::<Scenario>(&s).map_err(|e| e.to_string());
        }

        #[test]
        fn plausible_scenario_files_never_panic(
            plant in "[-+*/^()se0-9. ]{0,20}", ts in -1.0f64..1.0, d in -10.0f64..100.0, field in "[a-z]{1,8}",
        ) {
            let toml = format!("plant = \"{plant}\"\nts = {ts}\nduration = {d}\n{field} = 1\n");
            if let Ok(sc) = toml::from_str::<Scenario>(&toml) {
                let _ = sc.run().map_err(|e| e.to_string());
            }
        }
    }
}

#[test]
fn bad_flags_exit_2_without_a_panic_trace() {
    for args in [
        vec!["run", "--plant", "1/(s+1)", "--ts", "0"],
        vec!["run", "--plant", "1/(s+1)", "--ts", "nan"],
        vec!["run", "--plant", "1/(s+1)", "--umin", "2", "--umax", "1"],
        vec!["run", "--plant", "1/(s+1)", "--duration", "-3"],
        vec!["run", "--plant", "1/(s+1)", "--setpoint", "x@2"],
        vec!["run", "--plant", "1/(s+1)", "--disturbance", "input:1@-2"],
        vec!["sweep", "--plant", "1/(s+1)", "--gain", "20%..10%"],
        vec!["sweep", "--plant", "1/(s+1)", "--shard", "3/2"],
        vec!["margins", "--plant", "1/(s+1)", "-c", "karan-dey"],
        vec!["autotune", "--plant", "1/(s+1)", "--relay-amplitude", "0"],
    ] {
        msp()
            .args(&args)
            .assert()
            .code(2)
            .stderr(predicate::str::contains("panicked").not());
    }
}

/// The path of the `msp` binary built for these tests.
fn msp_path() -> std::path::PathBuf {
    assert_cmd::cargo::cargo_bin("msp")
}

#[test]
fn a_closed_pipe_ends_quietly() {
    // the reader takes one line and closes the pipe; msp must neither panic nor complain
    for _ in 0..5 {
        let mut child = std::process::Command::new(msp_path())
            .arg("list")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = [0u8; 1];
        use std::io::Read;
        child.stdout.take().unwrap().read_exact(&mut first).unwrap();
        // stdout dropped: the pipe is closed
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "status {:?}: {err}", out.status);
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_device_is_an_error_not_a_panic() {
    for args in [
        vec!["list"],
        vec!["tune", "--plant", "5.6*e^-93.9s/(40.2s+1)"],
        vec!["margins", "--plant", "5.6*e^-93.9s/(40.2s+1)"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = std::process::Command::new(msp_path())
            .args(&args)
            .stdout(full)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("standard output") && !err.contains("panicked"),
            "{err}"
        );
    }
    // a full standard error does not stop a run that writes its file
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("run.csv");
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = std::process::Command::new(msp_path())
        .args(words("run --plant 0.2/s*e^-7.4s -o"))
        .arg(&csv)
        .stderr(full)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(csv.exists());
}

#[test]
fn outputs_are_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let keep = dir.path().join("keep.csv");
    std::fs::write(&keep, "old").unwrap();
    // the report's directory is missing, or two outputs on one path:
    // nothing is written, keep.csv stays
    for (report, says) in [
        (dir.path().join("missing_dir/r.json"), "does not exist"),
        (keep.clone(), "name the same file"),
    ] {
        fails(
            msp()
                .args(words("run --plant 0.2/s*e^-7.4s -o"))
                .arg(&keep)
                .arg("--report")
                .arg(&report),
            2,
            says,
        );
        assert_eq!(std::fs::read_to_string(&keep).unwrap(), "old");
    }
    // a run that succeeds leaves its files and no temporary beside them
    msp()
        .args(words("run -q --plant 0.2/s*e^-7.4s -o"))
        .arg(&keep)
        .arg("--report")
        .arg(dir.path().join("r.json"))
        .arg("--plot")
        .arg(dir.path().join("p.svg"))
        .assert()
        .success();
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["keep.csv", "p.svg", "r.json"]);
    assert!(std::fs::read_to_string(&keep)
        .unwrap()
        .starts_with("t,r,y,u"));
}

/// An output that names a file the command reads is refused before
/// anything runs, naming both, by any spelling (a link to it too), and the
/// input is left as it was; a device such as /dev/null takes any number of
/// outputs.
#[test]
fn no_output_writes_over_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    std::fs::write(&input, "t,r\n0,1\n0.1,1\n0.2,1\n").unwrap();
    let scenario = dir.path().join("s.toml");
    std::fs::write(&scenario, "plant = \"e^-1s/(s+1)\"\nduration = 5\n").unwrap();
    let link = dir.path().join("link.toml");
    std::os::unix::fs::symlink(&scenario, &link).unwrap();
    let cases: Vec<(Vec<std::ffi::OsString>, &str)> = vec![
        (
            vec![
                "run".into(),
                "-p".into(),
                "e^-1s/(s+1)".into(),
                "--ts".into(),
                "0.1".into(),
                "--input".into(),
                input.clone().into(),
                "-o".into(),
                input.clone().into(),
            ],
            "--output",
        ),
        (
            vec![
                "run".into(),
                "--scenario".into(),
                scenario.clone().into(),
                "-o".into(),
                "/dev/null".into(),
                "--report".into(),
                scenario.clone().into(),
            ],
            "--report",
        ),
        (
            vec![
                "compare".into(),
                "-c".into(),
                "smith,pid".into(),
                "--scenario".into(),
                scenario.clone().into(),
                "--plot".into(),
                link.clone().into(),
            ],
            "--plot",
        ),
        (
            vec![
                "margins".into(),
                "--scenario".into(),
                scenario.clone().into(),
                "--plot".into(),
                scenario.clone().into(),
            ],
            "--plot",
        ),
    ];
    for (args, flag) in cases {
        msp()
            .args(&args)
            .assert()
            .code(2)
            .stderr(predicate::str::contains(flag).and(predicate::str::contains("reads")));
    }
    assert_eq!(
        std::fs::read_to_string(&input).unwrap(),
        "t,r\n0,1\n0.1,1\n0.2,1\n"
    );
    assert!(std::fs::read_to_string(&scenario)
        .unwrap()
        .starts_with("plant"));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    msp()
        .args(["run", "-q", "--scenario"])
        .arg(&scenario)
        .args([
            "-o",
            "/dev/null",
            "--report",
            "/dev/null",
            "--plot",
            "/dev/null",
        ])
        .assert()
        .success();
}

#[test]
fn wrong_inputs_that_were_accepted() {
    // juxtaposed numbers are not a product
    rejects(
        ["run", "--plant", "2 3*e^-1s/(s+1)"],
        "a number after another factor",
    );
    // a sweep of the headline loop with `extra` flags
    let sweep = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v = vec!["sweep", "--plant", "0.2/s*e^-7.4s", "-c", "karan-dey"];
        v.extend_from_slice(extra);
        v
    };
    // a range is LOW..HIGH exactly
    rejects(sweep(&["--gain=-20%...20%"]), "write it as LOW..HIGH");
    // an empty uncertainty list is not a robustness verdict
    rejects(
        [
            "margins",
            "--plant",
            "5.6*e^-93.9s/(40.2s+1)",
            "--uncertainty",
            "",
        ],
        "an empty list",
    );
    // counts are checked before anything is allocated
    let huge = "18446744073709551615";
    rejects(
        sweep(&["--gain", "-20%..20%", "--grid", huge]),
        "the limit is 10000000",
    );
    rejects(sweep(&["--grid", "0"]), "at least one point per axis");
    rejects(sweep(&["--samples", huge]), "the limit is");
    // the output path is checked before the sweep runs
    rejects(
        sweep(&["--grid", "5", "-o", "/nonexistent-dir/runs.csv"]),
        "does not exist",
    );
}

#[test]
fn merging_a_shard_twice_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    msp()
        .args(words("sweep -q --plant 0.2/s*e^-7.4s -c karan-dey --gain -10%..10% --grid 3 --duration 30 --shard 0/2 -o"))
        .arg(&a)
        .assert()
        .success();
    fails(
        msp().args(["sweep", "--merge"]).arg(&a).arg(&a),
        2,
        "is a shard given twice",
    );
}

/// Runs `msp` under a 4 GiB address-space limit: an allocation the budget
/// check missed would abort the process instead of exiting 2.
#[cfg(target_os = "linux")]
fn limited(args: &[&str]) -> std::process::Output {
    let mut cmd = String::from("ulimit -v 4194304; exec \"$0\"");
    for (i, _) in args.iter().enumerate() {
        // braces: `$10` would be `$1` followed by a 0
        cmd.push_str(&format!(" \"${{{}}}\"", i + 1));
    }
    std::process::Command::new("sh")
        .arg("-c")
        .arg(cmd)
        .arg(msp_path())
        .args(args)
        .output()
        .unwrap()
}

#[cfg(target_os = "linux")]
#[test]
fn runs_that_ask_for_too_much_memory_are_refused_before_allocating() {
    let plant = "0.2/s*e^-7.4s";
    for args in [
        vec!["run", "--plant", plant, "--ts", "1e-12"],
        // (a chosen period gives at most 1e5 samples of dead time: these
        // periods are the user's)
        vec!["run", "--plant", "e^-1e9s/(s+1)", "--ts", "0.1"],
        vec!["run", "--plant", "e^-1e6s/(s+1)", "--ts", "0.1"],
        vec!["run", "--plant", "e^-1s/(1e-9*s+1)", "--ts", "1e-10"],
        vec![
            "run",
            "--plant",
            "e^-1s/(s+1)",
            "--model",
            "e^-1e9s/(s+1)",
            "--ts",
            "0.1",
        ],
        vec![
            "run",
            "--plant",
            plant,
            "--substeps",
            "1000",
            "--duration",
            "7400",
        ],
        vec!["margins", "--plant", plant, "--ts", "1e-12"],
        vec![
            "compare",
            "--plant",
            plant,
            "--controllers",
            "karan-dey,smith",
            "--ts",
            "1e-12",
        ],
        vec![
            "sweep",
            "--plant",
            plant,
            "-c",
            "karan-dey",
            "--ts",
            "1e-12",
        ],
        vec!["autotune", "--plant", "2*e^-4s/(5s+1)", "--ts", "1e-12"],
    ] {
        let out = limited(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("the limit is") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    // a period msp chooses keeps the dead time within 1e5 samples: such a
    // plant runs (it asked for 1e10 samples of 1e9 s before)
    let out = limited(&["run", "--plant", "e^-1e9s/(s+1)", "-o", "/dev/null"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("100000 samples of dead time, the most a chosen period gives"),
        "{err}"
    );
    // the flag moves the limit both ways
    let out = limited(&["run", "--plant", plant, "--max-memory", "1K"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("the limit is 1 KiB"));
    let out = limited(&[
        "run",
        "-q",
        "--plant",
        plant,
        "--duration",
        "10",
        "--max-memory",
        "2G",
        "-o",
        "/dev/null",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The CSV of a run streams from the recorded columns into its output: a
/// run whose CSV (726 MB) is larger than the whole address space allowed
/// (640 MiB, the binary's own mappings and the columns within it) writes it
/// completely, which it could not if the text were held in memory beside
/// the columns (6·10⁶ rows × 10 columns = 480 MB).
#[cfg(target_os = "linux")]
#[test]
fn a_csv_larger_than_the_memory_limit_streams_out() {
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 655360; \"$0\" run -q --plant '0.2/s*e^-7.4s' --ts 0.001 --duration 6000 --max-memory 2G | wc -c")
        .arg(msp_path())
        .output()
        .unwrap();
    let bytes: u64 = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
    assert!(
        bytes > 655_360 * 1024,
        "{bytes} bytes: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[cfg(unix)]
#[test]
fn output_to_a_device_writes_into_it_and_leaves_it_a_device() {
    use std::os::unix::fs::FileTypeExt;
    // an atomic write renames a temporary over its target: over /dev/null
    // that would replace the device by a regular file (as root)
    msp()
        .args(words("run -q --plant 0.2/s*e^-7.4s --duration 10"))
        .args(["-o", "/dev/null"])
        .assert()
        .success();
    let t = std::fs::metadata("/dev/null").unwrap().file_type();
    assert!(t.is_char_device(), "/dev/null is no longer a device");
}

/// Files written atomically get the mode a plain `File::create` gives (0666
/// less the umask), as any other tool's output, not a temporary's 0600; a
/// file that is replaced keeps its mode.
#[cfg(unix)]
#[test]
fn outputs_have_the_usual_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("reference");
    std::fs::File::create(&reference).unwrap();
    let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    let csv = dir.path().join("run.csv");
    let report = dir.path().join("report.json");
    let run = || {
        msp()
            .args(words("run -q --plant 0.2/s*e^-7.4s --duration 10"))
            .arg("-o")
            .arg(&csv)
            .arg("--report")
            .arg(&report)
            .assert()
            .success();
    };
    run();
    assert_eq!(mode(&csv), mode(&reference));
    assert_eq!(mode(&report), mode(&reference));
    std::fs::set_permissions(&csv, std::fs::Permissions::from_mode(0o640)).unwrap();
    run();
    assert_eq!(mode(&csv), 0o640);
}

#[test]
fn bad_events_and_actuators_are_named() {
    for (args, needle) in [
        (vec!["--event", "60:beta=3"], "unknown action 'beta'"),
        (vec!["--event", "manual=3"], "TIME:ACTION"),
        (vec!["--event", "60:manual"], "'manual' needs a value"),
        (vec!["--event", "-5:auto"], "must not be negative"),
        (vec!["--event", "60:dead-time=-1"], "must not be negative"),
        (vec!["--actuator", "1..0"], "MIN must be below MAX"),
        (vec!["--actuator", "0...1"], "MIN..MAX"),
    ] {
        msp()
            .args(words("run --plant 0.2/s*e^-7.4s"))
            .args(&args)
            .assert()
            .code(2)
            .stderr(predicates::str::contains(needle));
    }
    // a dead time the scheme cannot take is refused by the run, with the reason
    for (plant, extra, needle) in [
        ("2*e^-3s/(4s+1)", ["-c", "pid"], "no model dead time"),
        ("5*e^-6s/(100s-1)", ["--ts", "0.06"], "whole samples"),
    ] {
        msp()
            .args(["run", "--plant", plant])
            .args(extra)
            .args(["--event", "10:dead-time=7.01"])
            .assert()
            .code(2)
            .stderr(predicates::str::contains(needle));
    }
}
