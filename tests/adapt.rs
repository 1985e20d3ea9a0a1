//! Adaptive dead-time compensation end to end: a Smith predictor whose
//! process drifts (dead time, gain, lag), run by the scenario as `msp run
//! --adapt` runs it, against the same loop with the fixed model and against
//! a loop built with the true model from the start.

use msp::sim::SetpointStep;
use msp::study::{AdaptOptions, RunOutput, Scenario};

const TS: f64 = 0.1;

/// A set point alternating between 0 and 1 every 30 s (the excitation a
/// loop in normal operation gets from its set-point changes).
fn square(duration: f64) -> Vec<SetpointStep> {
    (0..(duration / 30.0) as usize)
        .map(|i| SetpointStep {
            value: (i % 2) as f64,
            at: i as f64 * 30.0,
        })
        .collect()
}

fn scenario(plant: &str, events: &[&str], noise: f64, seed: u64, adapt: bool) -> Scenario {
    Scenario {
        plant: Some(plant.parse().unwrap()),
        controller: Some("smith".into()),
        lambda: Some(2.0),
        ts: Some(TS),
        duration: Some(900.0),
        setpoint: square(900.0),
        noise: (noise > 0.0).then_some(noise),
        seed: Some(seed),
        events: events.iter().map(|e| e.parse().unwrap()).collect(),
        adapt: adapt.then(AdaptOptions::default),
        ..Default::default()
    }
}

/// IAE of the set-point error from `from` seconds on.
fn iae_after(out: &RunOutput, from: f64) -> f64 {
    let r = &out.result;
    r.t.iter()
        .zip(r.y.iter().zip(&r.r))
        .filter(|(t, _)| **t >= from)
        .map(|(_, (y, r))| (r - y).abs() * TS)
        .sum()
}

/// The times at which signal `name` changed.
fn changes(out: &RunOutput, name: &str) -> Vec<(f64, f64)> {
    let (_, s) = out.result.signals.iter().find(|(n, _)| n == name).unwrap();
    let mut v = Vec::new();
    for (i, w) in s.windows(2).enumerate() {
        if w[1] != w[0] {
            v.push((out.result.t[i + 1], w[1]));
        }
    }
    v
}

fn last(out: &RunOutput, name: &str) -> f64 {
    let (_, s) = out
        .result
        .signals
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no signal {name}"));
    *s.last().unwrap()
}

/// The process drifts (its dead time 10 → 14 samples, its gain +30 %, its
/// lag doubled), noise-free: the adaptive predictor's model becomes the
/// process's (the dead time to a sample, the gain within 5 %, the lag
/// within 10 %), and from then on its loop is the loop built with the true
/// model (set-point IAE within 20 %), which a fixed model's loop is not.
#[test]
fn the_model_follows_the_process() {
    let cases: [(&str, &str, (f64, f64, f64)); 3] = [
        (
            "150:plant-dead-time=1.4",
            "1*e^-1.4s/(4s+1)",
            (1.0, 4.0, 1.4),
        ),
        ("150:plant-gain=1.3", "1.3*e^-1s/(4s+1)", (1.3, 4.0, 1.0)),
        ("150:plant-lag=8", "1*e^-1s/(8s+1)", (1.0, 8.0, 1.0)),
    ];
    for (drift, after, (k, tau, theta)) in cases {
        let plant = "1*e^-1s/(4s+1)";
        let adaptive = scenario(plant, &[drift], 0.0, 7, true).run().unwrap();
        let fixed = scenario(plant, &[drift], 0.0, 7, false).run().unwrap();
        let truth = scenario(after, &[], 0.0, 7, false).run().unwrap();
        let applied = changes(&adaptive, "theta_model");
        let (ka, ta, tha) = (
            last(&adaptive, "k_model"),
            last(&adaptive, "tau_model"),
            last(&adaptive, "theta_model"),
        );
        let (ia, ifx, it) = (
            iae_after(&adaptive, 600.0),
            iae_after(&fixed, 600.0),
            iae_after(&truth, 600.0),
        );
        println!("{drift}: model {ka} {ta} {tha} (changes {applied:?}); IAE adaptive {ia}, fixed {ifx}, true {it}");
        assert!((tha - theta).abs() < TS, "{drift}: theta {tha}");
        assert!((ka - k).abs() < 0.05 * k, "{drift}: k {ka}");
        assert!((ta - tau).abs() < 0.1 * tau, "{drift}: tau {ta}");
        assert!((ia - it).abs() < 0.2 * it, "{drift}: IAE {ia} against {it}");
        // the report's log: each change when the model in use changed, the
        // last one the model at the end
        let log = adaptive.report().adaptation;
        let last_change = log.last().expect("a change is logged");
        assert!(log
            .iter()
            .all(|c| c.kind == msp::adapt::ChangeKind::Applied));
        assert_eq!(
            (last_change.k, last_change.tau, last_change.theta),
            (ka, ta, tha)
        );
        let when = changes(&adaptive, "k_model").last().map(|c| c.0);
        assert_eq!(when, Some(last_change.at), "{drift}");
        assert!(fixed.report().adaptation.is_empty());
    }
}

/// The lag doubles under measurement noise (0.5 % and 2 % of the set-point
/// step, three seeds each): the estimate (through the prefilter that keeps
/// the noise out of the differenced data) is the process's — the dead time
/// to a sample, the gain within 5 %, the lag within 10 %. (The supervisor
/// does not apply them yet: its settling test holds back an estimate that
/// wanders by more than 5 % within a block of 300 samples; what it does
/// apply is right.)
#[test]
fn estimates_under_noise() {
    for noise in [0.005, 0.02] {
        for seed in [1u64, 2, 3] {
            let a = scenario("1*e^-1s/(4s+1)", &["150:plant-lag=8"], noise, seed, true)
                .run()
                .unwrap();
            let (k, tau, theta) = (
                last(&a, "k_hat"),
                last(&a, "tau_hat"),
                last(&a, "theta_hat"),
            );
            println!(
                "noise {noise} seed {seed}: {k} {tau} {theta}; model {} {} {}",
                last(&a, "k_model"),
                last(&a, "tau_model"),
                last(&a, "theta_model")
            );
            assert!((k - 1.0).abs() < 0.05, "noise {noise} seed {seed}: k {k}");
            assert!(
                (tau - 8.0).abs() < 0.8,
                "noise {noise} seed {seed}: tau {tau}"
            );
            assert!(
                (theta - 1.0).abs() < TS,
                "noise {noise} seed {seed}: theta {theta}"
            );
            // the supervisor, holding back while the estimate wanders, never
            // applies a wrong model: the one in use is the first or the process's
            let model = (
                last(&a, "k_model"),
                last(&a, "tau_model"),
                last(&a, "theta_model"),
            );
            let first = model == (1.0, 4.0, 1.0);
            let right = (model.0 - 1.0).abs() < 0.05
                && (model.1 - 8.0).abs() < 0.8
                && (model.2 - 1.0).abs() < TS;
            assert!(first || right, "noise {noise} seed {seed}: model {model:?}");
        }
    }
}

/// Adaptation frozen before the lag doubles learns and applies nothing;
/// resumed, it adapts; a controller that does not adapt refuses the event
/// with the reason.
#[test]
fn freeze_and_resume() {
    let plant = "1*e^-1s/(4s+1)";
    let frozen = scenario(
        plant,
        &["140:adapt-freeze", "150:plant-lag=8"],
        0.0,
        7,
        true,
    )
    .run()
    .unwrap();
    assert!(frozen.report().adaptation.is_empty());
    assert_eq!(last(&frozen, "tau_model"), 4.0);
    let resumed = scenario(
        plant,
        &["140:adapt-freeze", "150:plant-lag=8", "450:adapt-resume"],
        0.0,
        7,
        true,
    )
    .run()
    .unwrap();
    let log = resumed.report().adaptation;
    assert!(
        !log.is_empty() && log.iter().all(|c| c.at > 450.0),
        "{log:?}"
    );
    assert!((last(&resumed, "tau_model") - 8.0).abs() < 0.8);
    let plain = scenario(plant, &["140:adapt-freeze"], 0.0, 7, false).run();
    let msg = match plain {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a controller that does not adapt refuses adapt-freeze"),
    };
    assert!(msg.contains("does not adapt"), "{msg}");
}
