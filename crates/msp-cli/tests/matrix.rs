//! A matrix plant (`--plant "[g11, g12; g21, g22]"`, #51) in `msp tune`,
//! `run`, `margins` and `compare`: the Wood–Berry column's published BLT
//! tuning, the CSV and reports equal to the library's, the schemes by name,
//! loads and events, and the refusals that name what is wrong.

mod common;

use common::*;

const WB: &str =
    "[12.8e^-1s/(16.7s+1), -18.9e^-3s/(21s+1); 6.6e^-7s/(10.9s+1), -19.4e^-3s/(14.4s+1)]";

/// `msp tune` gives the RGA, the pairing, the Niederlinski index and
/// Luyben's BLT loops for the Wood–Berry column (F = 2.55, Kc = 0.375 and
/// −0.075, τI = 8.29 and 23.6 min), in the text and the JSON; `-c smith`
/// and `-c decoupled` their designs with the sampled loop's verdict; a
/// malformed matrix exits 2 naming the column of the entry's error.
#[test]
fn a_matrix_plant_is_tuned_by_blt_or_a_scheme() {
    prints(
        msp().args(["tune", "--plant", WB]),
        &[
            "rga         [2.0094, -1.0094]",
            "pairing     y1-u1, y2-u2",
            "F = 2.5446",
            "loop 1    kp = 0.37502, ti = 8.2857",
            "loop 2    kp = -0.0754, ti = 23.606",
            "stability   stable",
        ],
    );
    let j = json_out(&["tune", "--plant", WB, "--json"]);
    assert!((j["f"].as_f64().unwrap() - 2.55).abs() < 0.006, "{j}");
    assert!(
        (j["loops"][1]["ti"].as_f64().unwrap() - 23.6).abs() < 0.05,
        "{j}"
    );
    assert_eq!(j["scheme"], "pi");
    let d = json_out(&[
        "tune",
        "--plant",
        WB,
        "-c",
        "decoupled",
        "--json",
        "--ts",
        "1",
    ]);
    assert_eq!(d["decoupler"][0]["realization"]["as"], "exact", "{d}");
    assert_eq!(d["decoupler_stability"]["stable"], true, "{d}");
    assert_eq!(d["stability"]["stable"], true, "{d}");
    let s = json_out(&["tune", "--plant", WB, "-c", "smith", "--json", "--ts", "1"]);
    assert!((s["lcm"].as_f64().unwrap() - 4.0).abs() < 0.01, "{s}");
    fails(
        msp().args(["tune", "--plant", "[1/(s+1), 2/(s+1); 3/(s+1), 4/(q+1)]"]),
        2,
        "column 32",
    );
    fails(
        msp().args(["tune", "--plant", WB, "-c", "karan-dey"]),
        2,
        "one of pi, smith, decoupled",
    );
    prints(
        msp().arg("list"),
        &["controllers of a matrix plant", "  decoupled", "  smith "],
    );
    // SIMC loops alone, then BLT's detuning
    prints(
        msp().args(["tune", "--plant", WB, "--rule", "simc"]),
        &["(SIMC alone: kp = 0.65234, ti = 8)"],
    );
    let simc = json_out(&["tune", "--plant", WB, "--rule", "simc", "--json"]);
    assert_eq!(simc["rule"], "simc");
    assert!(
        (simc["loops"][0]["kp"].as_f64().unwrap() * simc["f"].as_f64().unwrap() - 16.7 / 25.6)
            .abs()
            < 1e-9
    );
    fails(
        msp().args(["tune", "--plant", WB, "--rule", "amigo"]),
        2,
        "rule zn (BLT) or simc",
    );
}

/// `msp run` on a matrix plant: CSV columns `t, r1, y1, u1, r2, y2, u2`
/// whose samples are the library's run (`msp::study::MimoScenario`), the
/// report its `MimoOutput`; a loop that does not exist and a single-loop
/// flag are refused by name.
#[test]
fn a_matrix_plant_runs_as_the_library_does() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, json, svg) = (
        dir.path().join("wb.csv"),
        dir.path().join("wb.json"),
        dir.path().join("wb.svg"),
    );
    msp()
        .args([
            "run",
            "--plant",
            WB,
            "--ts",
            "0.1",
            "--duration",
            "120",
            "-q",
        ])
        .args([
            "--loop-setpoint",
            "2:1@10",
            "--loop-disturbance",
            "1:input:0.1@60",
        ])
        .args(["-c", "smith", "-o"])
        .arg(&csv)
        .arg("--report")
        .arg(&json)
        .arg("--plot")
        .arg(&svg)
        .assert()
        .success();
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,r1,y1,u1,r2,y2,u2"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let m: msp::poly::TransferMatrix = WB.parse().unwrap();
    let lib = msp::study::MimoScenario {
        plant: m,
        controller: Some("smith".into()),
        rule: None,
        ts: Some(0.1),
        duration: Some(120.0),
        setpoints: vec![
            vec![],
            vec![msp::sim::SetpointStep {
                value: 1.0,
                at: 10.0,
            }],
        ],
        events: msp::sim::MimoEvents {
            loads: vec![msp::sim::LoopLoad {
                loop_index: 0,
                location: msp::sim::Location::Input,
                value: 0.1,
                at: 60.0,
            }],
            ..Default::default()
        },
    }
    .run()
    .unwrap();
    assert_eq!(rows.len(), lib.run.t.len());
    for (k, row) in rows.iter().enumerate() {
        for i in 0..2 {
            assert_eq!(row[2 + 3 * i], lib.run.y[i][k], "y{} at {k}", i + 1);
            assert_eq!(row[3 + 3 * i], lib.run.u[i][k], "u{} at {k}", i + 1);
        }
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(
        (report["iae"][1].as_f64().unwrap() - lib.iae[1]).abs() < 1e-12,
        "{report}"
    );
    assert_eq!(report["loads"][0]["loop"], 0, "{report}");
    assert_eq!(report["scheme"], "smith", "{report}");
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(
        plot.starts_with("<svg") && plot.contains("input u2"),
        "{}",
        &plot[..200]
    );
    fails(
        msp().args(["run", "--plant", WB, "--loop-setpoint", "3:1@10"]),
        2,
        "the plant has 2 loops",
    );
    fails(
        msp().args(["run", "--plant", WB, "--umin", "0", "--setpoint", "1"]),
        2,
        "does not take --setpoint, --umin",
    );
    // no flag is dropped silently
    fails(
        msp().args(["run", "--plant", WB, "--substeps", "4", "--reset-feedback"]),
        2,
        "does not take --substeps, --reset-feedback",
    );
    fails(
        msp().args([
            "run",
            "--plant",
            "1/(s+1)",
            "--loop-disturbance",
            "1:input:1@0",
        ]),
        2,
        "--loop-disturbance is for a matrix plant",
    );
}

/// `msp compare` runs the schemes on one scenario: the decoupled
/// compensator's interaction is zero to rounding where BLT's is tens of
/// percent; `msp margins` prints the verdict and Lcm; Wood–Berry's feed
/// disturbance enters through its own channels.
#[test]
fn compare_and_margins_take_a_matrix_plant() {
    let out = msp()
        .args(["compare", "--plant", WB, "-c", "pi,decoupled", "--ts", "1"])
        .args([
            "--duration",
            "240",
            "--loop-setpoint",
            "1:1@0",
            "--loop-setpoint",
            "2:1@120",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let row = |name: &str| -> Vec<String> {
        text.lines()
            .find(|l| l.starts_with(name))
            .unwrap()
            .split_whitespace()
            .map(str::to_string)
            .collect()
    };
    let inter = |name: &str| row(name).last().unwrap().parse::<f64>().unwrap();
    assert!(inter("pi") > 0.3, "{text}");
    assert!(inter("decoupled") < 1e-5, "{text}");
    prints(
        msp().args(["margins", "--plant", WB, "-c", "decoupled", "--ts", "1"]),
        &["stability   stable", "decoupler   stable", "Lcm "],
    );
    let j = json_out(&[
        "run",
        "--plant",
        WB,
        "--ts",
        "1",
        "--duration",
        "200",
        "--disturbance-plant",
        "[3.8e^-8.1s/(14.9s+1); 4.9e^-3.4s/(13.2s+1)]",
        "--disturbance-step",
        "0.1@10",
        "--report",
        "-",
        "-q",
        "-o",
        "/dev/null",
    ]);
    // the feed moves both outputs and the loops bring them back
    assert!(j["iae"][0].as_f64().unwrap() > 0.1, "{j}");
    fails(
        msp().args(["run", "--plant", WB, "--disturbance-plant", "[1/(s+1)]"]),
        2,
        "one channel per output",
    );
}

/// A matrix plant's scenario file (TOML or JSON, the flags' names and text
/// forms) runs as its flags do, the flags adding to it; an unknown field
/// and a loop the plant lacks are refused by name.
#[test]
fn a_matrix_scenario_file_is_its_flags() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("wb.toml");
    std::fs::write(
        &file,
        format!(
            "plant = \"{WB}\"\ncontroller = \"decoupled\"\nts = 1.0\nduration = 200.0\nloop_setpoint = [\"1:1@0\"]\nloop_event = [\"2:50:manual=0.1\", \"2:90:auto\"]\n"
        ),
    )
    .unwrap();
    let json = dir.path().join("wb.json");
    std::fs::write(
        &json,
        serde_json::json!({
            "plant": WB, "controller": "decoupled", "ts": 1.0, "duration": 200.0,
            "loop_setpoint": ["1:1@0"], "loop_event": ["2:50:manual=0.1", "2:90:auto"],
        })
        .to_string(),
    )
    .unwrap();
    let csv = |args: &[&str]| stdout_of(msp().args(args).args(["-q", "-o", "-"]));
    let flags = csv(&[
        "run",
        "--plant",
        WB,
        "-c",
        "decoupled",
        "--ts",
        "1",
        "--duration",
        "200",
        "--loop-setpoint",
        "1:1@0",
        "--loop-setpoint",
        "2:1@100",
        "--loop-event",
        "2:50:manual=0.1",
        "--loop-event",
        "2:90:auto",
    ]);
    for f in [&file, &json] {
        let path = f.to_str().unwrap();
        assert_eq!(
            csv(&["run", "--scenario", path, "--loop-setpoint", "2:1@100"]),
            flags
        );
    }
    std::fs::write(&file, format!("plant = \"{WB}\"\numin = 0.1\n")).unwrap();
    fails(
        msp().args(["run", "--scenario", file.to_str().unwrap()]),
        2,
        "unknown field `umin`",
    );
    std::fs::write(
        &file,
        format!("plant = \"{WB}\"\nloop_setpoint = [\"3:1\"]\n"),
    )
    .unwrap();
    fails(
        msp().args(["run", "--scenario", file.to_str().unwrap()]),
        2,
        "the plant has 2 loops",
    );
}

/// Plants at the edges: an integrating channel has no steady-state RGA (the
/// report says so and gives the RGA over frequency) but every scheme runs;
/// a dead time of more samples than a run holds is refused with the
/// channel and the remedy; a static diagonal names what it lacks.
#[test]
fn matrix_plants_at_the_edges() {
    const LEVEL: &str = "[e^-s/s, 0.2e^-2s/s; 0.1e^-2s/(s+1), e^-s/(2s+1)]";
    for c in ["pi", "smith", "decoupled"] {
        let j = json_out(&["tune", "--plant", LEVEL, "-c", c, "--json"]);
        assert!(j["rga"].is_null() && j["niederlinski"].is_null(), "{j}");
        assert_eq!(j["rga_over_frequency"].as_array().unwrap().len(), 12);
        assert_eq!(j["stability"]["stable"], true, "{c}: {j}");
    }
    fails(
        msp().args(["run", "--plant", "[e^-1000000s/(s+1), 0; 0, e^-s/(s+1)]"]),
        2,
        "g11's dead time is 1.000e9 samples",
    );
    fails(
        msp().args(["tune", "--plant", "[1, 0; 0, 1]", "-c", "smith"]),
        2,
        "a plant without dynamics",
    );
}
