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
