//! End-to-end tests of the real `msp` binary.
use assert_cmd::Command;
use predicates::prelude::*;

fn msp() -> Command {
    Command::cargo_bin("msp").unwrap()
}

#[test]
fn run_writes_csv_report_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("out.csv");
    let report = dir.path().join("report.json");
    let plot = dir.path().join("plot.svg");
    msp()
        .args(["run", "--plant", "0.2/s*e^-7.4s", "-o"])
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
    let iae = j["metrics_delayed_reference"]["iae"].as_f64().unwrap();
    assert!((iae - 0.93).abs() < 0.015, "{iae}");
    assert!(std::fs::read_to_string(&plot).unwrap().contains("<svg"));
}

#[test]
fn csv_goes_to_stdout_and_set_overrides() {
    let out = msp()
        .args([
            "run",
            "--plant",
            "5.6*e^-93.9s/(40.2s+1)",
            "--controller",
            "smith",
            "--set",
            "kp=0.05",
            "--ts",
            "1",
            "-q",
        ])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let text = String::from_utf8(out).unwrap();
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
    msp()
        .args(["run", "--plant", "0.2/s*e^-7.4s", "--controller", "nope"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("unknown controller 'nope'"));
    msp()
        .args(["run", "--plant", "0.2/s*e^-7.4s", "--set", "zeta=1"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("no parameter 'zeta'"));
    msp()
        .args(["run", "--plant", "5/(100s-1)*e^-6s"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("unstable"));
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
        .args(["run", "-q", "--scenario"])
        .arg(&good)
        .assert()
        .success();
    let bad = dir.path().join("b.toml");
    std::fs::write(&bad, "plant = \"0.2/s*e^-7.4s\"\nsetpiont = 1\n").unwrap();
    msp()
        .args(["run", "--scenario"])
        .arg(&bad)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("setpiont"));
}

#[test]
fn tune_prints_kaya_settings() {
    msp()
        .args([
            "tune",
            "--plant",
            "e^-10s/(s+1)^2",
            "--set",
            "alpha=0.5",
            "--json",
        ])
        .assert()
        .success()
        .stdout(
            predicate::str::contains("\"kp\": 0.4").and(predicate::str::contains("\"td\": 0.5")),
        );
}
