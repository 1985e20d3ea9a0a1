//! End-to-end tests of the real `msp` binary: the design and analysis
//! commands (`tune`, `sweep`, `margins`, `step`, `compare`, `tradeoff`,
//! `stepinfo`, `autotune`, `identify`, `list`).
mod common;

use common::*;
use predicates::prelude::*;

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
