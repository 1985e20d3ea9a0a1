//! A scheme rebuilt for each model, designed between samples
//! (`background_design`: as a device's background task would) against the
//! same scheme designed in the update that applies the model, over a
//! family: stable and integrating processes, the filtered Smith and the
//! Karan–Dey predictors, a change of dead time, gain or lag, a fine and a
//! coarse period, with and without measurement noise.

use msp::adapt::ChangeKind;
use msp::sim::SetpointStep;
use msp::study::{AdaptOptions, AdaptationReport, RunOutput, Scenario};

/// `plant` under `controller` at `ts` (s), its set point alternating every
/// `half` seconds, the process changed by `event`, adapted (designed in the
/// background with `background`), `noise` (fixed seed).
fn run(
    (plant, controller, event, half): (&str, &str, &str, f64),
    ts: f64,
    noise: f64,
    background: bool,
) -> RunOutput {
    let duration = 60.0 * half;
    Scenario {
        plant: Some(plant.parse().unwrap()),
        controller: Some(controller.into()),
        ts: Some(ts),
        duration: Some(duration),
        setpoint: (0..60)
            .map(|i| SetpointStep {
                value: (i % 2) as f64,
                at: i as f64 * half,
            })
            .collect(),
        noise: (noise > 0.0).then_some(noise),
        seed: Some(3),
        events: vec![event.parse().unwrap()],
        adapt: Some(AdaptOptions {
            background_design: background.then_some(true),
            ..AdaptOptions::default()
        }),
        ..Default::default()
    }
    .run()
    .unwrap()
}

fn applied(out: &RunOutput) -> Vec<AdaptationReport> {
    out.report()
        .adaptation
        .into_iter()
        .filter(|c| c.kind == ChangeKind::Applied)
        .collect()
}

/// Until the first rebuilt scheme takes over the two loops are the same
/// sample for sample (the one warming up does not act on the plant, and
/// the design waits for nothing the loop computes); the first change is
/// the same model, taken exactly one sample later in the background; both
/// loops end with the process's model within 10 % of each other's.
#[test]
fn the_background_design_takes_the_same_model_a_sample_later() {
    let family = [
        ("e^-1s/(4s+1)", "fsp", "150:plant-lag=8", 30.0),
        ("2.3e^-8s/(15s+1)", "fsp", "900:plant-gain=1.15", 92.0),
        ("1.6e^-6s/(10s+1)", "fsp", "700:plant-dead-time=8.4", 64.0),
        ("0.5e^-1s/s", "karan-dey", "150:plant-gain=0.6", 30.0),
        ("0.15e^-5s/s", "karan-dey", "600:plant-gain=0.1", 40.0),
    ];
    let mut cases = 0;
    for case in family {
        let theta: f64 = case
            .0
            .split("e^-")
            .nth(1)
            .unwrap()
            .split('s')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        for ts in [theta / 10.0, theta / 40.0] {
            for noise in [0.0, 0.01] {
                let (inline, later) = (run(case, ts, noise, false), run(case, ts, noise, true));
                let (a, b) = (applied(&inline), applied(&later));
                let what = format!("{case:?} ts {ts} noise {noise}: {a:?} {b:?}");
                assert!(!a.is_empty() && !b.is_empty(), "{what}");
                let (first, next) = (&a[0], &b[0]);
                assert!((next.at - first.at - ts).abs() < 1e-9 * first.at, "{what}");
                assert_eq!(
                    (first.k, first.tau, first.theta),
                    (next.k, next.tau, next.theta),
                    "{what}"
                );
                // the same loop until the inline scheme took over
                let until = inline
                    .result
                    .t
                    .iter()
                    .take_while(|t| **t < first.at)
                    .count();
                assert_eq!(inline.result.y[..until], later.result.y[..until], "{what}");
                let (p, q) = (
                    inline.report().adaptive.unwrap(),
                    later.report().adaptive.unwrap(),
                );
                assert!(
                    (p.k_model - q.k_model).abs() <= 0.1 * p.k_model.abs(),
                    "{what} {p:?} {q:?}"
                );
                assert!(
                    (p.theta_model - q.theta_model).abs() <= 0.1 * p.theta_model,
                    "{what} {p:?} {q:?}"
                );
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 20);
}
