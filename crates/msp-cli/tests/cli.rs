//! End-to-end tests of the real `msp` binary.
mod common;

use common::*;
use predicates::prelude::*;

#[test]
fn run_writes_csv_report_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("out.csv");
    let report = dir.path().join("report.json");
    let plot = dir.path().join("plot.svg");
    msp()
        .args(words("run --plant 0.2/s*e^-7.4s -o"))
        .arg(&csv)
        .arg("--report")
        .arg(&report)
        .arg("--plot")
        .arg(&plot)
        .assert()
        .success()
        .stderr(predicate::str::contains("karan-dey").and(predicate::str::contains("chosen")));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t,r,y,u,d,"), "{}", &text[..40]);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for key in [
        "plant",
        "model",
        "ts",
        "controller",
        "metrics",
        "metrics_delayed_reference",
    ] {
        assert!(j.get(key).is_some(), "report lacks {key}");
    }
    assert_eq!(j["controller"]["name"], "karan-dey");
    for key in [
        "iae",
        "ise",
        "itae",
        "itse",
        "tv",
        "rise_time",
        "settling_time",
        "settling_min",
        "settling_max",
        "overshoot",
        "undershoot",
        "peak",
        "peak_time",
    ] {
        assert!(j["metrics"][key].is_number(), "metrics.{key}");
        assert!(
            j["metrics_delayed_reference"][key].is_number(),
            "metrics_delayed_reference.{key}"
        );
    }
    // the default scenario: the set-point step (whose delayed-reference IAE
    // is the thesis's 0.93, Table 5.4) and then a load
    assert_eq!(j["default_scenario"], true);
    let step = &j["events"][0];
    assert_eq!(step["kind"], "setpoint");
    assert_eq!(j["events"][1]["kind"], "disturbance");
    assert!(j["events"][1]["at"].as_f64().unwrap() > step["settling_time"].as_f64().unwrap());
    assert_eq!(j["float32"], false);
    assert!(std::fs::read_to_string(&plot).unwrap().contains("<svg"));
}

#[test]
fn float32_runs_the_controller_in_f32() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report.json");
    let out = msp()
        .args(words("run -q --plant 0.2/s*e^-7.4s --float32 --report"))
        .arg(&report)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(j["float32"], true);
    // the actuator column (u, the fourth) holds f32 numbers only
    let text = String::from_utf8(out).unwrap();
    for line in text.lines().skip(1) {
        let u: f64 = line.split(',').nth(3).unwrap().parse().unwrap();
        assert_eq!(f64::from(u as f32), u, "{line}");
    }
}

/// In `f32` the chosen period keeps the plant's slowest pole 2⁻¹⁰ from 1
/// (the unstable plant's 100 s: 0.098 s, 61 samples of dead time, where
/// `f64` takes 1000) and says why; a finer `--ts` is warned of.
#[test]
fn float32_chooses_a_period_f32_resolves_and_warns_of_a_finer_one() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("run.csv");
    let said = |extra: &str| {
        let out = msp()
            .args(words(&format!(
                "run --plant 5e^-6s/(100s-1) --float32 {extra} -o"
            )))
            .arg(&csv)
            .assert()
            .success()
            .get_output()
            .clone();
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
    };
    let chosen = said("");
    assert!(
        chosen.contains("(61 samples of dead time, the finest at which f32 keeps the slowest pole 2^-10 from 1)"),
        "{chosen}"
    );
    assert!(!chosen.contains("warning: float32"), "{chosen}");
    let fine = said("--ts 0.006");
    assert!(
        fine.contains("warning: float32: at ts 0.006 s the plant's slowest pole is 6e-5 from 1")
            && fine.contains("--ts 0.09836 keeps it 2^-10 away"),
        "{fine}"
    );
}

#[test]
fn csv_goes_to_stdout_and_set_overrides() {
    let text = stdout_of(msp().args(words(
        "run --plant 5.6*e^-93.9s/(40.2s+1) --controller smith --set kp=0.05 --ts 1 -q",
    )));
    assert!(text.starts_with("t,r,y,u,d,ym,ym_delayed,model_error"));
    // u[0] = kp·(r − y) = 0.05
    let second = text.lines().nth(1).unwrap();
    assert_eq!(second.split(',').nth(3).unwrap(), "0.05");
}

#[test]
fn bad_expressions_exit_2_with_the_column_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("out.csv");
    for (expr, col) in [
        ("(s+1", 1),
        ("0.2/x*e^-7.4s", 5),
        ("s^2/(s+1)", 1),
        ("e^7s/(s+1)", 3),
        ("", 1),
    ] {
        msp()
            .args(["run", "--plant", expr, "-o"])
            .arg(&csv)
            .assert()
            .code(2)
            .stderr(
                predicate::str::contains(format!("column {col}"))
                    .and(predicate::str::contains("panicked").not()),
            );
        assert!(!csv.exists(), "{expr} left a file");
    }
}

/// `msp ARGS…` exits with status 2 and says `says` on standard error.
fn rejects<I, S>(args: I, says: &str)
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    fails(msp().args(args), 2, says);
}

#[test]
fn bad_names_exit_2() {
    rejects(
        ["run", "--plant", "0.2/s*e^-7.4s", "--controller", "nope"],
        "unknown controller 'nope'",
    );
    rejects(
        ["run", "--plant", "0.2/s*e^-7.4s", "--set", "zeta=1"],
        "no parameter 'zeta'",
    );
    rejects(
        ["run", "--plant", "5/(100s-1)*e^-6s", "-c", "smith"],
        "cannot control an unstable plant; use one of: fsp",
    );
    // a scheme prefix names a scheme, or the run stops and lists them
    rejects(
        [
            "run",
            "--plant",
            "0.2/s*e^-7.4s",
            "--set",
            "nosuchscheme.kp=5",
        ],
        "unknown controller 'nosuchscheme'; available: pid, pi, smith",
    );
    rejects(
        [
            "compare",
            "--plant",
            "0.2/s*e^-7.4s",
            "--controllers",
            "karan-dey,smith",
            "--set",
            "smith.zeta=1",
        ],
        "no parameter 'zeta'",
    );
}

#[test]
fn scenario_file_and_unknown_fields() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("s.toml");
    std::fs::write(
        &good,
        "plant = \"0.2/s*e^-7.4s\"\nduration = 100\n[[disturbance]]\nlocation = \"input\"\nvalue = -0.1\nat = 50\n",
    )
    .unwrap();
    msp()
        .args(words("run -q --scenario"))
        .arg(&good)
        .assert()
        .success();
    // JSON too, even behind a byte-order mark (as some editors write it)
    let json = dir.path().join("s.json");
    std::fs::write(
        &json,
        "\u{feff}{\"plant\": \"0.2/s*e^-7.4s\", \"duration\": 20}",
    )
    .unwrap();
    msp()
        .args(words("run -q --scenario"))
        .arg(&json)
        .arg("-o")
        .arg(dir.path().join("o.csv"))
        .assert()
        .success();
    let bad = dir.path().join("b.toml");
    std::fs::write(&bad, "plant = \"0.2/s*e^-7.4s\"\nsetpiont = 1\n").unwrap();
    rejects(
        [
            std::ffi::OsStr::new("run"),
            "--scenario".as_ref(),
            bad.as_os_str(),
        ],
        "setpiont",
    );
    // a plant expression in a file is read by the same parser as --plant:
    // the error names the field, the problem and the column
    let typo = dir.path().join("t.toml");
    std::fs::write(&typo, "plant = \"0.2/x*e^-7.4s\"\n").unwrap();
    let err = stderr_of(["run", "--scenario", typo.to_str().unwrap()], 2);
    assert!(err.contains("plant") && err.contains("column 5"), "{err}");
    // a file without a plant, and no --plant: said so, by name
    let none = dir.path().join("n.toml");
    std::fs::write(&none, "duration = 10\n").unwrap();
    let err = stderr_of(["run", "--scenario", none.to_str().unwrap()], 2);
    assert!(err.contains("has no plant"), "{err}");
    // --plant given with the file supplies it
    msp()
        .args(words("run -q --plant 0.2/s*e^-7.4s --scenario"))
        .arg(&none)
        .assert()
        .success();
}

#[test]
fn tune_prints_kaya_settings() {
    prints(
        msp().args(words("tune --plant e^-10s/(s+1)^2 --set alpha=0.5 --json")),
        &["\"kp\": 0.4", "\"td\": 0.5"],
    );
}

fn read_csv(path: &std::path::Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn sweep_of_10000_runs_and_its_worst_case_by_a_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("runs.csv");
    let common = [
        "--plant",
        "0.2/s*e^-7.4s",
        "-c",
        "karan-dey",
        "--ts",
        "0.074",
        "--duration",
        "100",
    ];
    msp()
        .arg("sweep")
        .args(common)
        .args(words("--gain=-20%..+20% --delay=-10%..+10% --grid 100 -o"))
        .arg(&csv)
        .assert()
        .success()
        .stderr(predicate::str::contains("10000 runs"));
    let rows = read_csv(&csv);
    assert_eq!(rows.len(), 10_001);
    let col = |name: &str| rows[0].iter().position(|h| h == name).unwrap();
    let (iae, gain, delay) = (col("iae"), col("gain"), col("delay"));
    let worst = rows[1..]
        .iter()
        .max_by(|a, b| {
            a[iae]
                .parse::<f64>()
                .unwrap()
                .total_cmp(&b[iae].parse::<f64>().unwrap())
        })
        .unwrap();
    let (g, d): (f64, f64) = (worst[gain].parse().unwrap(), worst[delay].parse().unwrap());
    // the same loop as one msp run: the perturbed plant, the nominal model
    let report = dir.path().join("worst.json");
    msp()
        .args([
            "run",
            "-q",
            "--plant",
            &format!("{}/s*e^-{}s", 0.2 * (1.0 + g), 7.4 * (1.0 + d)),
            "--model",
            "0.2/s*e^-7.4s",
        ])
        .args(words("-c karan-dey --ts 0.074 --duration 100 -o"))
        .arg(dir.path().join("worst.csv"))
        .arg("--report")
        .arg(&report)
        .assert()
        .success();
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let single = j["metrics"]["iae"].as_f64().unwrap();
    let swept: f64 = worst[iae].parse().unwrap();
    assert!(
        (single - swept).abs() <= 1e-9 * swept.abs(),
        "{single} vs {swept}"
    );
}

#[test]
fn sweep_shards_merge_into_the_whole() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--plant",
        "0.2/s*e^-7.4s",
        "--ts",
        "0.074",
        "--duration",
        "60",
        "--gain=-10%..+10%",
        "--samples",
        "30",
    ];
    let whole = dir.path().join("whole.csv");
    msp()
        .arg("sweep")
        .args(args)
        .arg("-q")
        .arg("-o")
        .arg(&whole)
        .assert()
        .success();
    let mut parts = Vec::new();
    for i in 0..3 {
        let p = dir.path().join(format!("part{i}.csv"));
        msp()
            .arg("sweep")
            .args(args)
            .args(["-q", "--shard", &format!("{i}/3"), "-o"])
            .arg(&p)
            .assert()
            .success();
        parts.push(p);
    }
    let merged = dir.path().join("merged.csv");
    msp()
        .args(["sweep", "--merge"])
        .args(&parts)
        .arg("-o")
        .arg(&merged)
        .assert()
        .success();
    assert_eq!(
        std::fs::read_to_string(&whole).unwrap(),
        std::fs::read_to_string(&merged).unwrap()
    );
}

/// `msp margins --plant EXPR` alone is the bare plant (MATLAB's `margin(G)`),
/// `--continuous` drops the hold (gm = 2 for `1/(s³ + 2s² + 3s + 4)`, as
/// MATLAB), and the JSON says which view it is.
#[test]
fn margins_of_the_bare_plant() {
    let j = json_of(msp().args(words(
        "margins --plant 1/(s^3+2s^2+3s+4) --continuous --json",
    )));
    assert_eq!(j["controller"]["name"], "none");
    assert_eq!(j["view"], "continuous");
    assert!((j["gm"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    prints(
        msp().args(words(
            "margins --plant 1/(s^3+2s^2+3s+4) -c none --set kp=0.5",
        )),
        &["L = 0.5·G", "behind a hold"],
    );
    msp()
        .args(words("margins --plant 1/(s+1) --continuous --discrete"))
        .assert()
        .code(2);
}

/// A P-only loop settles at `k/(1 + k)`, off the set point, and is stable.
/// `msp step`: the plant's own step response, no controller; its JSON has
/// MATLAB's `stepinfo` figures (FOPDT: rise `τ ln 9`), the CSV `t,y`, the
/// plot is written, and `msp --help` lists it.
#[test]
fn step_prints_the_open_loop_response() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, svg) = (dir.path().join("s.csv"), dir.path().join("s.svg"));
    let j = json_of(
        msp()
            .args(words("step --plant 2*e^-1.3s/(5s+1) --json -o"))
            .arg(&csv)
            .arg("--plot")
            .arg(&svg),
    );
    assert_eq!(j["dc_gain"], 2.0);
    let rise = j["rise_time"].as_f64().unwrap();
    assert!((rise - 5.0 * 9f64.ln()).abs() < 1e-3, "{rise}");
    let text = std::fs::read_to_string(&csv).unwrap();
    // the rest state one sample before the step, then the response from 0
    let rows: Vec<&str> = text.lines().take(3).collect();
    assert_eq!(rows[0], "t,u,y");
    assert!(
        rows[1].starts_with('-') && rows[1].ends_with(",0,0"),
        "{rows:?}"
    );
    assert_eq!(rows[2], "0,1,0");
    assert!(std::fs::read_to_string(&svg)
        .unwrap()
        .contains("final value 2"));
    prints(msp().args(words("step --plant 1/s")), &["does not settle"]);
    prints(msp().arg("--help"), &["step "]);
}

/// `msp tune` prints the loop's margins beside the tuning and warns of a
/// fragile one (the default Karan–Dey loop: Ms 2.5, dm 16 % of θ).
#[test]
fn tune_prints_robustness_and_warns() {
    prints(
        msp().args(words("tune --plant 0.2/s*e^-7.4s")),
        &[
            "robustness  gm 1.6893",
            "warning: robustness: the sensitivity peak Ms = 2.52",
        ],
    );
    let j = json_of(msp().args(words("tune --plant e^-2s/(5s+1) --json")));
    assert!(j["robustness"]["ms"].as_f64().unwrap() < 2.0);
    assert_eq!(j["warnings"], serde_json::json!([]));
}

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

/// On a terminal, `msp run` without `-o` prints the summary, not thousands of
/// CSV rows, and says how to get them; piped, it writes the CSV. The
/// terminal is a pseudo-terminal from util-linux's `script`.
#[cfg(target_os = "linux")]
#[test]
fn a_terminal_gets_the_summary_not_the_csv() {
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let cmd = format!("{} run --plant '0.2/s*e^-7.4s'", bin.display());
    let out = std::process::Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .expect("util-linux's script runs the pseudo-terminal test");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("controller  karan-dey") && text.contains("CSV rows go to a file"),
        "{text}"
    );
    assert!(!text.contains("t,r,y,u"), "{text}");
    let piped = msp()
        .args(words("run --plant 0.2/s*e^-7.4s -q"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&piped.stdout).starts_with("t,r,y,u"));
}

/// A run report carries the scenario as given and the msp version, and
/// `msp run --scenario report.json` runs it again: the same CSV and the same
/// report, byte for byte (a scenario with noise, limits, set points, a load
/// and sub-steps, and the default scenario).
#[test]
fn a_report_reruns_as_itself() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let cases: [&[&str]; 2] = [
        &["--plant", "0.2/s*e^-7.4s"],
        &[
            "--plant",
            "e^-1s/(s^2+3s+2)",
            "-c",
            "pid",
            "--set",
            "ti=2.5",
            "--noise",
            "0.01",
            "--seed",
            "7",
            "--setpoint",
            "1@0",
            "--setpoint",
            "0.5@30",
            "--disturbance",
            "input:-0.2@15",
            "--umax",
            "3",
            "--substeps",
            "3",
        ],
    ];
    for args in cases {
        msp()
            .arg("run")
            .args(args)
            .args(["-q", "-o"])
            .arg(p("a.csv"))
            .arg("--report")
            .arg(p("a.json"))
            .assert()
            .success();
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p("a.json")).unwrap()).unwrap();
        assert_eq!(j["msp_version"], env!("CARGO_PKG_VERSION"));
        assert!(j["scenario"]["plant"].is_string());
        msp()
            .args(words("run -q --scenario"))
            .arg(p("a.json"))
            .arg("-o")
            .arg(p("b.csv"))
            .arg("--report")
            .arg(p("b.json"))
            .assert()
            .success();
        for (a, b) in [("a.csv", "b.csv"), ("a.json", "b.json")] {
            assert!(
                std::fs::read(p(a)).unwrap() == std::fs::read(p(b)).unwrap(),
                "{args:?}: {a} and {b} differ"
            );
        }
    }
}

/// The report of `msp run --scenario FILE`, printed to standard output.
fn report_of_scenario(file: &std::path::Path) -> serde_json::Value {
    let out = msp()
        .args(words("run -q -o /dev/null --report - --scenario"))
        .arg(file)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    serde_json::from_slice(&out).unwrap()
}

/// A scenario file is the user's own scenario: with a plant alone it is the
/// unit set-point step, not the default scenario with its load.
#[test]
fn a_scenario_file_is_the_users_own_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("p.toml");
    std::fs::write(&file, "plant = \"0.2/s*e^-7.4s\"\n").unwrap();
    let j = report_of_scenario(&file);
    assert_eq!(j["default_scenario"], false);
    assert_eq!(j["events"].as_array().unwrap().len(), 1);
}

/// The example scenario file documents every field and runs; its events are
/// in the flags' own syntax and in the structured form.
#[test]
fn the_example_scenario_file_runs() {
    let file =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenario.toml");
    let j = report_of_scenario(&file);
    let kinds: Vec<&str> = j["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["kind"].as_str().unwrap())
        .collect();
    assert_eq!(
        kinds,
        ["setpoint", "setpoint", "disturbance", "disturbance"]
    );
    assert_eq!(j["events"][3]["location"], "output");
    assert_eq!(j["controller"]["params"]["kp"], 0.08);
}

/// `msp tune` and the report show what the paper prints beside the gains:
/// FSPCC's `Fr` for García et al. (2010) Example 1 at Ts = 0.2 (lead 3 s,
/// lag 0.144 s, Tf = 36 s) has kf = 14.9524 and ρ2 = 0.9957, and cancels the
/// unstable pole e^{0.2/20} and z = 1.
#[test]
fn tune_prints_the_designed_filter() {
    let args = [
        "--plant",
        "e^-4s/(20s-1)",
        "--inner-plant",
        "2e^-2s/(20s+1)",
        "--ts",
        "0.2",
        "--set",
        "tf=36",
        "--set",
        "lead=3",
        "--set",
        "lag=0.144",
    ];
    let j = json_of(msp().arg("tune").args(args).arg("--json"));
    let d = &j["design"];
    assert!(
        (d["kf"].as_f64().unwrap() - 14.9524).abs() < 5e-3 * 14.9524,
        "{d}"
    );
    assert!((d["rho2"].as_f64().unwrap() - 0.9957).abs() < 5e-4, "{d}");
    let cancels = d["cancels"].as_array().unwrap();
    assert!(
        (cancels[1].as_f64().unwrap() - (0.2f64 / 20.0).exp()).abs() < 1e-9,
        "{d}"
    );
    prints(
        msp().arg("tune").args(args),
        &["design\n  fr", "kf          = 14.952"],
    );
    let g = json_of(
        msp()
            .arg("tune")
            .args(&args[..6])
            .args(words("-c gpcc --json")),
    );
    assert_eq!(g["design"]["f1_taps"], 30.0);
    assert!(g["design"]["gamma"]["num"].is_array());
}

/// The plots carry what a report needs: the time plot names its axes with
/// units, draws the set point (dashed) and the load with legends and titles
/// the controller with its key parameters and the plant; the margins plot
/// marks gm and pm, draws the phase unwrapped (as MATLAB's `bode`, no
/// wrap's jump), and its Nyquist panel (alone with `--nyquist`) has the unit
/// and Ms circles.
#[test]
fn plots_carry_what_a_report_needs() {
    let dir = tempfile::tempdir().unwrap();
    let (run, bode, nyq) = (
        dir.path().join("r.svg"),
        dir.path().join("b.svg"),
        dir.path().join("n.svg"),
    );
    msp()
        .args(words("run --plant 0.2/s*e^-7.4s -q -o /dev/null --plot"))
        .arg(&run)
        .assert()
        .success();
    msp()
        .args(words("margins --plant 0.2/s*e^-7.4s -c karan-dey --plot"))
        .arg(&bode)
        .arg("--nyquist")
        .arg(&nyq)
        .assert()
        .success();
    let shows = [
        (&run, "time t (s)"),
        (&run, "r (set point)"),
        (&run, "d (input load)"),
        (&run, "u (control)"),
        (&run, "karan-dey (kp = 5.4054"),
        (&bode, "gm 4.554 dB"),
        (&bode, "pm 33.11°"),
        (&bode, "arg L (deg)"),
        (&bode, "Ms circle"),
    ];
    for (file, text) in shows {
        let svg = std::fs::read_to_string(file).unwrap();
        assert!(svg.contains(text), "{}: {text}", file.display());
    }
    let svg = std::fs::read_to_string(&nyq).unwrap();
    assert!(svg.contains("unit circle") && svg.contains("Ms circle (radius 1/Ms = 0.39725)"));
}

/// A run that takes more than a second shows a spinner on a terminal (a
/// pseudo-terminal from util-linux's `script`); piped, nothing is drawn.
#[cfg(target_os = "linux")]
#[test]
fn a_long_run_shows_it_is_running() {
    let bin = assert_cmd::cargo::cargo_bin("msp");
    let cmd = format!(
        "{} run --plant '5e^-6s/(100s-1)' --duration 20000 -o /dev/null",
        bin.display()
    );
    let out = std::process::Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .expect("util-linux's script runs the pseudo-terminal test");
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("simulating"));
    let piped = msp()
        .args(words("run --plant 0.2/s*e^-7.4s -q -o /dev/null"))
        .output()
        .unwrap();
    assert!(!String::from_utf8_lossy(&piped.stderr).contains("simulating"));
}

/// `-o -` is standard output, as for most Unix tools, and no file named `-`
/// appears; two outputs cannot both be `-`.
#[test]
fn a_dash_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = msp()
        .current_dir(dir.path())
        .args(words("run --plant e^-2s/(5s+1) --duration 10 -o -"))
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    assert!(String::from_utf8(out).unwrap().starts_with("t,r,y,u,"));
    assert!(!dir.path().join("-").exists());
    fails(
        msp()
            .current_dir(dir.path())
            .args(words("run --plant e^-2s/(5s+1) -o - --report -")),
        2,
        "both name standard output",
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// A delay-free plant runs with λ chosen from its time constants, and both
/// the summary and the report say so; a given λ is not "chosen".
#[test]
fn run_says_what_it_chose() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report.json");
    msp()
        .current_dir(dir.path())
        .args(words("run --plant 1/(s+1)^2 -o - --report"))
        .arg(&report)
        .assert()
        .success()
        .stderr(predicate::str::contains("lambda chosen from the plant"));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(j["chosen"], serde_json::json!(["ts", "duration", "lambda"]));
    assert_eq!(j["controller"]["params"]["lambda"], 0.5);
    msp()
        .args(words(
            "run --plant 1/(s+1)^2 --lambda 1 --ts 0.1 -o - --report",
        ))
        .arg(&report)
        .assert()
        .success()
        .stderr(predicate::str::contains("chosen from the plant; --lambda").not());
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(j["chosen"], serde_json::json!(["duration"]));
}

#[test]
fn margins_call_a_p_only_loop_stable() {
    msp()
        .args(words(
            "margins --plant 1/(s+1) -c pid --set kp=1 --set ti=inf --set td=0",
        ))
        .assert()
        .success()
        .stdout(predicates::str::contains("nominal loop  stable"));
}

#[test]
fn margins_json_has_the_matlab_keys() {
    let j = json_of(msp().args(words("margins --plant 5.6*e^-93.9s/(40.2s+1) -c pid --set kp=0.0501 --set ti=47.3 --set td=0 --json")));
    for k in ["gm", "gm_db", "pm", "wcg", "wcp", "dm", "ms", "mt"] {
        assert!(j[k].is_number(), "{k}");
    }
    assert_eq!(j["stable"], true);
    // the loop response the plots draw: L(jω) and its unwrapped phase, whose
    // wrapped value is L's argument and whose steps between neighbours are
    // under half a turn once the dead time's exact −ωθ is taken out
    let (w, l, phase) = (
        j["w"].as_array().unwrap(),
        j["l"].as_array().unwrap(),
        j["phase_unwrapped"].as_array().unwrap(),
    );
    assert!(w.len() > 100 && l.len() == w.len() && phase.len() == w.len());
    let mut prev: Option<f64> = None;
    for ((w, l), p) in w.iter().zip(l).zip(phase) {
        let (w, p) = (w.as_f64().unwrap(), p.as_f64().unwrap());
        let (re, im) = (l[0].as_f64().unwrap(), l[1].as_f64().unwrap());
        let turns = (p - im.atan2(re).to_degrees()) / 360.0;
        assert!((turns - turns.round()).abs() < 1e-9, "{p} vs {re} {im}");
        let rest = p + (w * 93.9).to_degrees();
        if let Some(q) = prev {
            assert!((rest - q).abs() < 180.0, "{q} → {rest} at {w}");
        }
        prev = Some(rest);
    }
}

#[test]
fn compare_prints_the_frequency_rows() {
    prints(
        msp().args(words(
            "compare --plant 0.2/s*e^-7.4s -c karan-dey,smith --duration 60",
        )),
        &["Gm (dB)", "Wpm (rad/s)", "IAE"],
    );
}

#[test]
fn autotune_reports_the_identified_and_the_true_model() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("at.json");
    prints(
        msp()
            .args(words(
                "autotune --plant 0.2/s*e^-7.4s --hysteresis 0.05 --report",
            ))
            .arg(&report),
        &["identified"],
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(j["identified"]["model"], "ipdt");
    assert!((j["identified"]["k"].as_f64().unwrap() - 0.2).abs() < 0.002);
    assert!((j["identified"]["l"].as_f64().unwrap() - 7.4).abs() < 0.074);
    assert_eq!(j["true"]["model"], "ipdt");
    assert!(j["relay"]["period"].is_number() && j["metrics"]["iae"].is_number());
    assert_eq!(j["controller"]["name"], "karan-dey");
    fails(
        msp().args(words("autotune --plant 0.2/s*e^-7.4s --band 0.5")),
        1,
        "aborted",
    );
}

/// `msp autotune` of unstable processes (the unstable FOPDT from the biased
/// relay's cycle, its dead time rounded to whole samples and said so, the
/// filtered Smith predictor on it): the model in the report within 0.2 % of
/// the process, a stable loop; a symmetric relay is refused by name.
#[test]
fn autotune_identifies_unstable_processes() {
    let dir = tempfile::tempdir().unwrap();
    for (plant, k, t, l) in [
        ("2e^-1s/(3s-1)", 2.0, 3.0, 1.0),
        ("1e^-1.5s/(5s-1)", 1.0, 5.0, 1.5),
    ] {
        let report = dir.path().join("u.json");
        let out = msp()
            .args(["autotune", "--plant", plant, "--report"])
            .arg(&report)
            .assert()
            .success()
            .get_output()
            .clone();
        let text = String::from_utf8_lossy(&out.stdout);
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        assert_eq!(j["identified"]["model"], "ufopdt", "{plant}");
        for (key, want) in [("k", k), ("t", t), ("l", l)] {
            let got = j["identified"][key].as_f64().unwrap();
            assert!((got - want).abs() < 2e-3 * want, "{plant} {key}: {got}");
        }
        assert_eq!(j["stable"], true, "{plant}");
        let samples = j["identified"]["l"].as_f64().unwrap() / j["ts"].as_f64().unwrap();
        let rounded = (samples - samples.round()).abs() > 1e-9;
        let said = j["warnings"]
            .to_string()
            .contains("a whole number of samples");
        assert_eq!(rounded, said, "{plant}: {}", j["warnings"]);
        assert_eq!(
            said,
            text.contains("a whole number of samples"),
            "{plant}: {text}"
        );
    }
    fails(
        msp().args(["autotune", "--plant", "2e^-1s/(3s-1)", "--bias", "0"]),
        1,
        "asymmetric relay: give it a bias",
    );
}

/// A step test of `2e^{−4s}/(5s + 1)`: a unit step at 5 s, 1200 rows every
/// 0.05 s, under the header `head`.
fn step_test_csv(head: &str) -> String {
    let mut text = format!("{head}\n");
    for k in 0..1200 {
        let t = k as f64 * 0.05;
        let u = if t >= 5.0 { 1.0 } else { 0.0 };
        let y = if t > 9.0 {
            2.0 * (1.0 - (-(t - 9.0) / 5.0).exp())
        } else {
            0.0
        };
        text.push_str(&format!("{t},{u},{y}\n"));
    }
    text
}

#[test]
fn identify_reads_a_step_test() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("step.csv");
    std::fs::write(&data, step_test_csv("t,u,y")).unwrap();
    let j = json_of(msp().args(words("identify --json --data")).arg(&data));
    assert!(
        (j["k"].as_f64().unwrap() - 2.0).abs() < 0.02
            && (j["t"].as_f64().unwrap() - 5.0).abs() < 0.1
    );
    std::fs::write(&data, "t,u\n0,1\n").unwrap();
    rejects(
        [
            std::ffi::OsStr::new("identify"),
            "--data".as_ref(),
            data.as_os_str(),
        ],
        "no column 'y'",
    );
}

/// Column names are the user's (`--time`, `--input`, `--output`; `time` is
/// found without a flag), and closed-loop data — a PI loop's run, whose
/// input moves at every sample — is refused in those words instead of
/// giving a wrong gain.
#[test]
fn identify_takes_named_columns_and_refuses_closed_loop_data() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("step.csv");
    std::fs::write(&data, step_test_csv("time,valve,level")).unwrap();
    let j = json_of(
        msp()
            .args(words("identify --json --input valve --output level --data"))
            .arg(&data),
    );
    assert!((j["k"].as_f64().unwrap() - 2.0).abs() < 0.02, "{j}");
    fails(
        msp().args(["identify", "--data"]).arg(&data),
        2,
        "no column 'u' (--input names it; the columns are: time, valve, level)",
    );
    let closed = dir.path().join("closed.csv");
    msp()
        .args(words(
            "run --plant 5.6*e^-93.9s/(40.2s+1) -c pi --noise 0.01 -o",
        ))
        .arg(&closed)
        .assert()
        .success();
    fails(
        msp().args(["identify", "--data"]).arg(&closed),
        2,
        "closed-loop data",
    );
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
fn an_unstable_loop_ends_with_a_warning_and_keeps_its_data() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, report) = (dir.path().join("u.csv"), dir.path().join("u.json"));
    // the plain PI far too aggressive for this dead time
    msp()
        .args(words(
            "run --plant 5.6*e^-93.9s/(40.2s+1) -c pid --set kp=2 --ts 1 --duration 5000 -o",
        ))
        .arg(&csv)
        .arg("--report")
        .arg(&report)
        .assert()
        .success()
        .stderr(predicate::str::contains(
            "warning: the closed loop with pid is unstable",
        ));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(j["stable"], false);
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
    assert!(rows > 100 && rows < 5000, "{rows}");
    assert!(!std::fs::read_to_string(&csv).unwrap().contains("inf"));
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

#[test]
fn identify_names_a_time_that_does_not_increase() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("step.csv");
    let mut text = String::from("t,u,y\n");
    for i in 0..50 {
        let t = if i == 20 { 9.5 } else { i as f64 * 0.5 };
        let u = if i >= 10 { 1.0 } else { 0.0 };
        let y = 2.0 * (1.0 - (-(t - 7.0f64).max(0.0) / 10.0).exp());
        text.push_str(&format!("{t},{u},{y}\n"));
    }
    std::fs::write(&f, text).unwrap();
    fails(
        msp().args(["identify", "--data"]).arg(&f),
        2,
        "`time` must increase: data row 21",
    );
}

#[test]
fn a_reverse_acting_plant_is_tuned_with_negative_gains() {
    // a plant of negative gain, written as a user types it (the leading minus
    // is the plant's, not an option)
    for cmd in [["run", "-q"], ["tune", "--json"]] {
        let text = stdout_of(msp().args(cmd).args(["--plant", "-2*e^-3s/(5s+1)"]));
        if cmd[0] == "tune" {
            let j: serde_json::Value = serde_json::from_str(&text).unwrap();
            let kp = j["controller"]["params"]["kp"].as_f64().unwrap();
            assert!(kp < 0.0, "kp = {kp}");
        } else {
            // the output is back at the set point (within the 2 % band the
            // default scenario's load recovery is measured by) at the end
            let last = text.lines().last().unwrap();
            let y: f64 = last.split(',').nth(2).unwrap().parse().unwrap();
            assert!((y - 1.0).abs() < 0.02, "y = {y}");
        }
    }
}

#[test]
fn ti_inf_switches_the_integral_off() {
    // P-only on e^{-s}/(s+1) with kp = 1: y settles at K·kp/(1 + K·kp) = 1/2
    let text = stdout_of(msp().args(words(
        "run -q --plant e^-1s/(s+1) --controller pi --set kp=1 --set ti=inf --duration 40",
    )));
    let y: f64 = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    assert!((y - 0.5).abs() < 1e-9, "y = {y}");
    // a gain of inf is still refused, by name
    fails(
        msp().args(words("run --plant e^-1s/(s+1) --set kp=inf")),
        2,
        "kp",
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

/// `msp list` names each scheme's design keys (the fields of its typed
/// design inputs), which `--set` accepts before tuning.
#[test]
fn list_names_the_design_keys() {
    let text = stdout_of(msp().arg("list"));
    for s in msp::registry::SCHEMES {
        let line = format!("design (--set before tuning): {};", s.design.join(", "));
        assert!(text.contains(&line), "{}: {line}", s.name);
    }
}

#[test]
fn operator_events_and_an_outside_actuator_reach_the_csv_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, rep) = (dir.path().join("r.csv"), dir.path().join("r.json"));
    msp()
        .args(words("run -q --plant 0.2/s*e^-7.4s --setpoint 1 --duration 200 --event 60:manual=0.3 --event 120:auto --actuator -1..1 --reset-feedback -o"))
        .arg(&csv)
        .arg("--report")
        .arg(&rep)
        .assert()
        .success();
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t,r,y,u,u_applied,d"), "{}", &text[..40]);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rep).unwrap()).unwrap();
    let ev = report["operator_events"].as_array().unwrap();
    assert_eq!(ev.len(), 2);
    assert_eq!(ev[0]["action"]["manual"], 0.3);
    assert_eq!(ev[1]["action"], "auto");
    // the scenario runs again from its report, events included
    msp()
        .args(words("run -q --scenario"))
        .arg(&rep)
        .arg("-o")
        .arg(dir.path().join("again.csv"))
        .assert()
        .success();
    assert_eq!(
        std::fs::read_to_string(dir.path().join("again.csv")).unwrap(),
        text
    );
}

/// A cascade process whose primary's transport delay grows at a steady
/// state, the controller told at the same instant (García et al. (2010)
/// Example 2, GPCC): the report shows the events and neither moves the
/// output; the set-point step after them shows whether the controller was told.
#[test]
fn a_cascade_takes_dead_time_events() {
    let run = |model_dead_time: &str| -> serde_json::Value {
        let out = msp()
            .args(words("run -q --plant 2e^-2s/s --inner-plant 4e^-2s/(s+1) -c gpcc --ts 0.1 --setpoint 1@0 --setpoint 2@250 --duration 350 --event 200:plant-dead-time=5 --event"))
            .arg(format!("200:dead-time={model_dead_time}"))
            .args(words("-o /dev/null --report -"))
            .assert()
            .success();
        serde_json::from_slice(&out.get_output().stdout).unwrap()
    };
    let told = run("5");
    let ev = told["operator_events"].as_array().unwrap();
    assert_eq!(ev.len(), 2);
    assert_eq!(ev[0]["action"]["plant-dead-time"], 5.0);
    let change = |r: &serde_json::Value| {
        r["operator_events"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["output_change"].as_f64().unwrap())
            .fold(0.0f64, f64::max)
    };
    assert!(change(&told) < 1e-9, "{}", change(&told));
    // the model left at 4 s: at the steady state nothing shows it (the
    // output's change above is as small), the set-point step at 250 s does
    let untold = run("4");
    let iae = |r: &serde_json::Value| r["metrics"]["iae"].as_f64().unwrap();
    // (the loop built for 5 s from the start is the told one: tests/operate.rs)
    let (a, b) = (iae(&told), iae(&untold));
    assert!((a - b).abs() > 1e-3, "{a} vs {b}");
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

/// `msp stepinfo` reads `msp step -o`'s own CSV (the rest row before the
/// step at t = 0 included) and gives the figures `msp step` prints for the
/// same response; its errors name the file and the column.
#[test]
fn stepinfo_of_step_data_is_steps_own() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("st.csv");
    let plant = "(8s^2+18s+32)/(s^3+6s^2+14s+24)";
    let step = json_of(
        msp()
            .args([
                "step",
                "--plant",
                plant,
                "--ts",
                "1e-3",
                "--duration",
                "10",
                "--json",
                "-o",
            ])
            .arg(&csv),
    );
    let info = json_of(
        msp()
            .args([
                "stepinfo",
                "--yfinal",
                "1.3333333333333333",
                "--json",
                "--data",
            ])
            .arg(&csv),
    );
    for key in [
        "rise_time",
        "settling_time",
        "overshoot",
        "peak",
        "peak_time",
    ] {
        let (a, b) = (info[key].as_f64().unwrap(), step[key].as_f64().unwrap());
        assert!(
            (a - b).abs() <= 1e-9 * b.abs().max(1.0),
            "{key}: {a} vs {b}"
        );
    }
    fails(
        msp()
            .args(["stepinfo", "--output", "q", "--data"])
            .arg(&csv),
        2,
        "no column 'q'",
    );
    fails(
        msp()
            .args(["stepinfo", "--rise-limits", "0.9,0.1", "--data"])
            .arg(&csv),
        2,
        "rise_limits",
    );
}

/// `msp run --input FILE.csv` (columns t, r, d, d_out) writes the CSV that
/// the equivalent `--setpoint`/`--disturbance` steps write, byte for byte;
/// non-uniform times are refused naming the sample.
#[test]
fn run_input_is_the_run_with_the_equivalent_steps() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    let mut text = String::from("t,r,d,d_out\n");
    for k in 0..=200 {
        let t = k as f64 * 0.5;
        let d = if t >= 50.0 { -0.1 } else { 0.0 };
        let d_out = if t >= 80.0 { 0.05 } else { 0.0 };
        text.push_str(&format!("{t},1,{d},{d_out}\n"));
    }
    std::fs::write(&input, &text).unwrap();
    let a = stdout_of(
        msp()
            .args(words("run --plant 2e^-3s/(4s+1) -c pi -q -o - --input"))
            .arg(&input),
    );
    let b = stdout_of(msp().args(words(
        "run --plant 2e^-3s/(4s+1) -c pi -q -o - --setpoint 1@0 --disturbance input:-0.1@50 --disturbance output:0.05@80 --ts 0.5 --duration 100",
    )));
    assert_eq!(a, b);
    std::fs::write(&input, "t,r\n0,1\n0.5,1\n1.2,1\n1.5,1\n").unwrap();
    fails(
        msp()
            .args(words("run --plant 2e^-3s/(4s+1) -q -o - --input"))
            .arg(&input),
        2,
        "sample 3",
    );
}

/// `msp tradeoff`: the table (text, CSV, JSON) and the picture, a curve and
/// a ringed own tuning per scheme.
#[test]
fn tradeoff_writes_the_table_and_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, svg) = (dir.path().join("t.csv"), dir.path().join("t.svg"));
    let j = json_of(
        msp()
            .args(words(
                "tradeoff --plant 2*e^-3s/(4s+1) -c smith,pi -q --json -o",
            ))
            .arg(&csv)
            .arg("--plot")
            .arg(&svg),
    );
    let points = j["points"].as_array().unwrap();
    assert_eq!(points.len(), 26);
    assert_eq!(points.iter().filter(|p| p["default"] == true).count(), 2);
    let table = std::fs::read_to_string(&csv).unwrap();
    assert!(table.starts_with("scheme,lambda,default,stable,ms,dm,iae_setpoint,iae_load,tv\n"));
    assert_eq!(table.lines().count(), 27);
    let pic = std::fs::read_to_string(&svg).unwrap();
    // two panels, each with a ring (r = 6) per scheme's own tuning
    assert_eq!(pic.matches("r=\"6\"").count(), 4, "rings");
    assert!(pic.contains("smith") && pic.contains("IAE, unit input load"));
    // a scheme named is swept or refused by name
    let err = stderr_of(
        ["tradeoff", "--plant", "2*e^-3s/(4s+1)", "-c", "nonesuch"],
        2,
    );
    assert!(err.contains("unknown controller 'nonesuch'"), "{err}");
}

/// The time plot marks every scheduled thing on the time axis (set-point
/// steps, input and output loads, operator events), shades the manual
/// period, draws the output load with the control, and its legend shows the
/// set point dashed as it is drawn.
#[test]
fn the_time_plot_marks_what_was_scheduled() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("r.svg");
    msp()
        .args(words(
            "run --plant 2e^-3s/(4s+1) -c smith --ts 0.1 --setpoint 1@0 --setpoint 0.5@40 --disturbance output:0.1@80 --disturbance input:-0.05@100 --event 120:manual=0.3 --event 150:auto --event 170:plant-dead-time=4 --duration 220 -q -o /dev/null --plot",
        ))
        .arg(&svg)
        .assert()
        .success();
    let pic = std::fs::read_to_string(&svg).unwrap();
    for text in [
        "r → 0.5",
        "output load 0.1",
        "input load -0.05",
        "manual 0.3",
        "auto",
        "plant θ = 4 s",
        "d_out (output load)",
        "d (input load)",
    ] {
        assert!(pic.contains(text), "{text}");
    }
    // the manual period shaded on both panels (a filled rectangle each)
    assert!(pic.matches("opacity=\"0.25\"").count() >= 2, "shading");
}

/// `msp run --monitor`: the process's gain rises 30 % and the summary says
/// ALARM with the model error, the report logs it (kind "alarm", its
/// mismatch), the CSV has the `mismatch` and `model_alarm` columns, the
/// estimate's `evidence` (the dead time unchanged and identified: past
/// what a switch of dead time needs, 20) and the estimator's counts
/// (`learnt`, `onsets`, `restarts`), the model in use stays; the estimator's options without --adapt or --monitor
/// are refused by name; a bad forgetting factor is refused.
#[test]
fn monitor_raises_the_alarm_in_summary_report_and_csv() {
    let (text, r, last) =
        square_wave_run("--noise 0.01 --quantization 0.0005 --event 150:plant-gain=1.3 --monitor");
    assert!(
        text.contains("ALARM: the model no longer matches") && text.contains("model error"),
        "{text}"
    );
    let log = r["adaptation"].as_array().unwrap();
    assert_eq!(log[0]["kind"], "alarm");
    assert!(log[0]["mismatch"].as_f64().unwrap() >= 0.1);
    assert_eq!(last("model_alarm"), "1");
    assert_eq!(last("k_model"), "1");
    let mismatch: f64 = last("mismatch").parse().unwrap();
    assert!((mismatch - 0.3).abs() < 0.03, "{mismatch}");
    let evidence: f64 = last("evidence").parse().unwrap();
    let theta: f64 = last("theta_hat").parse().unwrap();
    assert!(
        evidence >= 20.0 && (theta - 1.0).abs() < 0.1,
        "{evidence} {theta}"
    );
    // the estimator's counts: it learnt from the set point's moves, whole
    // samples counted
    let learnt: u64 = last("learnt").parse().unwrap();
    assert!(learnt > 100, "{learnt}");
    // the same in the report and the summary
    assert_eq!(r["estimator"]["learnt"].as_u64(), Some(learnt));
    assert!(
        text.contains(&format!("estimator   learnt from {learnt} samples")),
        "{text}"
    );
    // a run too short for the estimator to learn from says so, as its report
    let dir = tempfile::tempdir().unwrap();
    let args: Vec<String> =
        words("run --plant e^-1s/(4s+1) -c smith --ts 0.1 --duration 100 --adapt")
            .map(String::from)
            .collect();
    let (summary, short) =
        reported_run(&args, &dir.path().join("s.csv"), &dir.path().join("s.json"));
    assert_eq!(short["estimator"]["learnt"].as_u64(), Some(0));
    assert!(
        summary.contains(
            "learnt from 0 samples (nothing moved the loop enough to identify the process)"
        ),
        "{summary}"
    );
    assert!(last("onsets").parse::<u64>().is_ok() && last("restarts").parse::<u64>().is_ok());
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --alarm 0.2"),
        "add --adapt or --monitor",
    );
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --adapt --adapt-forgetting 1.5"),
        "forgetting",
    );
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --quantization -1"),
        "quantization",
    );
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --adapt --adapt-dead-zone -1"),
        "dead zone",
    );
    // the dead-time range's parser names what it parses
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --adapt --adapt-delay 2..1"),
        "dead times '2..1': MIN must not be above MAX",
    );
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --adapt --adapt-delay=-1..2"),
        "dead times '-1..2': '-1' is negative",
    );
    // a range without the model's dead time (1 s)
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --ts 0.1 --adapt --adapt-delay 0.5..0.6"),
        "around the model's dead time",
    );
}

/// `msp run --adapt --adapt-bound F`: the process's gain rises 30 %, past a
/// bound of 1.2 on the commissioned gain: the summary warns that the
/// estimate is not applied, the report logs it (kind "edge", with the
/// estimate's gain, near the process's), the model in use stays; a bound
/// not above 1 is refused by name.
#[test]
fn an_estimate_past_the_bound_is_warned_of_not_applied() {
    let (text, r, last) = square_wave_run("--event 150:plant-gain=1.3 --adapt --adapt-bound 1.2");
    assert!(text.contains("WARNING: not applied"), "{text}");
    let log = r["adaptation"].as_array().unwrap();
    assert!(log.iter().all(|c| c["kind"] == "edge"), "{log:?}");
    let k = log[0]["k"].as_f64().unwrap();
    assert!((k - 1.3).abs() < 0.1, "{k}");
    assert_eq!(last("k_model"), "1");
    rejects(
        words("run --plant e^-1s/(4s+1) -c smith --adapt --adapt-bound 1"),
        "bound",
    );
}

/// `msp` with `args`, the CSV to `csv` and the report to `report`: its
/// summary (standard error, where it goes when the CSV goes to a file) and
/// the report.
fn reported_run(
    args: &[String],
    csv: &std::path::Path,
    report: &std::path::Path,
) -> (String, serde_json::Value) {
    let out = msp()
        .args(args)
        .arg("-o")
        .arg(csv)
        .arg("--report")
        .arg(report)
        .assert()
        .success()
        .get_output()
        .clone();
    let r = serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    (String::from_utf8(out.stderr).unwrap(), r)
}

/// `msp run` of the Smith predictor on `e^{−1s}/(4s+1)` at 0.1 s for 600 s,
/// the set point alternating every 30 s, with the flags `extra`: its
/// summary (standard error), its report, and the CSV's last row by column.
fn square_wave_run(extra: &str) -> (String, serde_json::Value, impl Fn(&str) -> String) {
    let dir = tempfile::tempdir().unwrap();
    let (csv, report) = (dir.path().join("m.csv"), dir.path().join("m.json"));
    let mut args: Vec<String> = words(&format!(
        "run --plant e^-1s/(4s+1) -c smith --lambda 2 --ts 0.1 --duration 600 {extra}"
    ))
    .map(String::from)
    .collect();
    for i in 0..20 {
        args.push("--setpoint".into());
        args.push(format!("{}@{}", i % 2, 30 * i));
    }
    let (text, r) = reported_run(&args, &csv, &report);
    let data = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<String> = data
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let row: Vec<String> = data
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let last = move |name: &str| {
        let i = header.iter().position(|h| h == name).unwrap();
        row[i].clone()
    };
    (text, r, last)
}

/// The integrating loop whose dead time grows 5 → 7 s: with the
/// fixed model it diverges (the run says the loop is unstable); with
/// `--adapt` the summary names the emergency path, the primary detuned
/// first and then the estimate it applied, and the report ends stable.
#[test]
fn the_emergency_path_is_said_in_the_summary() {
    let args = "run --plant 0.15e^-5s/s -c smith --ts 0.25 --duration 1500 --setpoint 1@0 --setpoint 0@1230 --event 1200:plant-dead-time=7 -o /dev/null";
    let fixed = msp().args(words(args)).assert().get_output().clone();
    let fixed = String::from_utf8(fixed.stderr).unwrap();
    assert!(fixed.contains("the output diverged at"), "{fixed}");
    let out = msp()
        .args(words(args))
        .arg("--adapt")
        .assert()
        .success()
        .get_output()
        .clone();
    let text = String::from_utf8(out.stderr).unwrap();
    let line = text
        .lines()
        .find(|l| {
            l.contains(
                "EMERGENCY: the loop was going unstable (the primary detuned first where the scheme can be); the clear estimate applied",
            )
        })
        .unwrap_or_else(|| panic!("{text}"));
    // the dead time applied: the process's 7 s
    let theta: f64 = line
        .split("theta = ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((theta - 7.0).abs() < 0.05, "{line}");
    assert!(!text.contains("the output diverged at"), "{text}");
    // detuned first: the halved gain's line comes before the estimate's
    let detuned = text
        .find("EMERGENCY: the loop was going unstable; the primary's gain halved")
        .unwrap_or_else(|| panic!("{text}"));
    assert!(detuned < text.find(line).unwrap_or(0), "{text}");
}
