//! End-to-end tests of the real `msp` binary: adaptation and monitoring
//! (`--adapt`, `--monitor`).
mod common;

use common::*;

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
    // the same in the report (the adaptive controller's state at the end,
    // under the CSV's names: its last row) and the summary
    let state = &r["adaptive"];
    assert_eq!(state["learnt"].as_u64(), Some(learnt));
    // the counts alike in the CSV and the JSON (the level test's responses
    // compared, those taken as evidence among them)
    for name in [
        "onsets",
        "restarts",
        "responses",
        "responses_used",
        "responses_ramps",
    ] {
        let csv: u64 = last(name).parse().unwrap();
        assert_eq!(state[name].as_u64(), Some(csv), "{name}");
    }
    assert!(state["responses_used"].as_u64() <= state["responses"].as_u64());
    for name in [
        "k_model",
        "tau_model",
        "theta_model",
        "k_hat",
        "theta_hat",
        "mismatch",
    ] {
        let csv: f64 = last(name).parse().unwrap();
        let json = state[name].as_f64().unwrap();
        assert!(
            (csv - json).abs() <= 1e-12 * json.abs().max(1.0),
            "{name}: {csv} {json}"
        );
    }
    assert_eq!(state["model_alarm"], true);
    assert_eq!(state["frozen"], false);
    assert!(
        text.contains(&format!("estimator   learnt from {learnt} samples")),
        "{text}"
    );
    assert!(
        text.contains(&format!(
            "{} responses compared in levels ({} taken as evidence, {} a ramp load's)",
            state["responses"], state["responses_used"], state["responses_ramps"]
        )),
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
    assert_eq!(short["adaptive"]["learnt"].as_u64(), Some(0));
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

/// The command line `line` with the set point alternating between 0 and
/// 1 every 30 s (20 half periods).
fn square_wave(line: &str) -> Vec<String> {
    let mut args: Vec<String> = words(line).map(String::from).collect();
    for i in 0..20 {
        args.push("--setpoint".into());
        args.push(format!("{}@{}", i % 2, 30 * i));
    }
    args
}

/// `msp run` of the Smith predictor on `e^{−1s}/(4s+1)` at 0.1 s for 600 s,
/// the set point alternating every 30 s, with the flags `extra`: its
/// summary (standard error), its report, and the CSV's last row by column.
fn square_wave_run(extra: &str) -> (String, serde_json::Value, impl Fn(&str) -> String) {
    let dir = tempfile::tempdir().unwrap();
    let (csv, report) = (dir.path().join("m.csv"), dir.path().join("m.json"));
    let args = square_wave(&format!(
        "run --plant e^-1s/(4s+1) -c smith --lambda 2 --ts 0.1 --duration 600 {extra}"
    ));
    let (text, r) = reported_run(&args, &csv, &report);
    let data = std::fs::read_to_string(&csv).unwrap();
    let cells = |line: Option<&str>| -> Vec<String> {
        line.unwrap().split(',').map(String::from).collect()
    };
    let (header, row) = (cells(data.lines().next()), cells(data.lines().last()));
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

/// `--adapt-background`: the filtered Smith predictor, rebuilt for each
/// model, designed between samples (as a device's background task would)
/// takes the same model one sample later than when designed in the update
/// that applies it; the report's scenario keeps the option (a rerun from
/// it designs alike). Without `--adapt` it is refused by name.
#[test]
fn a_design_in_the_background_takes_over_a_sample_later() {
    let run = |extra: &str| {
        let dir = tempfile::tempdir().unwrap();
        let args = square_wave(&format!(
            "run --plant e^-1s/(4s+1) -c fsp --ts 0.1 --duration 600 --event 150:plant-lag=8 --adapt {extra}"
        ));
        reported_run(&args, &dir.path().join("b.csv"), &dir.path().join("b.json")).1
    };
    let (inline, background) = (run(""), run("--adapt-background"));
    let applied = |r: &serde_json::Value| -> Vec<(f64, f64)> {
        r["adaptation"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["kind"] == "applied")
            .map(|c| (c["at"].as_f64().unwrap(), c["tau"].as_f64().unwrap()))
            .collect()
    };
    let (a, b) = (applied(&inline), applied(&background));
    assert!(!a.is_empty() && a.len() == b.len(), "{a:?} {b:?}");
    for ((t1, tau1), (t2, tau2)) in a.iter().zip(&b) {
        assert!(((t2 - t1) - 0.1).abs() < 1e-9, "{a:?} {b:?}");
        assert!((tau1 - tau2).abs() < 1e-6 * tau1, "{a:?} {b:?}");
    }
    assert_eq!(background["scenario"]["adapt"]["background_design"], true);
    // here the option acts: nothing said of it; on the Smith predictor, whose
    // model changes in place, it has nothing to act on: said so
    let said = |r: &serde_json::Value| r["warnings"].to_string().contains("--adapt-background");
    assert!(!said(&background), "{}", background["warnings"]);
    let dir = tempfile::tempdir().unwrap();
    let smith: Vec<String> = words(
        "run --plant e^-1s/(4s+1) -c smith --ts 0.1 --duration 60 --adapt --adapt-background",
    )
    .map(String::from)
    .collect();
    let (summary, smith) = reported_run(
        &smith,
        &dir.path().join("s.csv"),
        &dir.path().join("s.json"),
    );
    assert!(said(&smith), "{}", smith["warnings"]);
    assert!(
        summary.contains("warning: --adapt-background") && summary.contains("has no effect"),
        "{summary}"
    );
    assert_eq!(
        inline["scenario"]["adapt"]["background_design"],
        serde_json::Value::Null
    );
    let refused = msp()
        .args(words(
            "run --plant e^-1s/(4s+1) -c fsp --adapt-background -o /dev/null",
        ))
        .assert()
        .failure()
        .get_output()
        .clone();
    let text = String::from_utf8(refused.stderr).unwrap();
    assert!(text.contains("--adapt-background"), "{text}");
}
