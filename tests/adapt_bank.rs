//! The adaptation's benchmark bank, reduced (#48): where the process does
//! not change, the adaptive loop does no harm — set-point moves, input and
//! output load steps, measurement noise and a 10-bit converter, on stable
//! and integrating processes, at a coarse period and at a fine one — and
//! where it changes into a loop the fixed model makes unstable, the
//! adaptive one stays stable.

use msp::sim::SetpointStep;
use msp::study::{AdaptOptions, RunOutput, Scenario};

/// A run of `plant` under the Smith predictor at `ts` for `duration`
/// seconds: the set point steps to 1 at 0 and back to 0 at `back`, the
/// loads are `loads` (`input:0.2@400`, …), the process events `events`.
#[allow(clippy::too_many_arguments)]
fn run(
    plant: &str,
    ts: f64,
    duration: f64,
    back: f64,
    loads: &[&str],
    events: &[&str],
    noise: f64,
    bits: Option<u32>,
    seed: u64,
    adapt: bool,
) -> RunOutput {
    Scenario {
        plant: Some(plant.parse().unwrap()),
        controller: Some("smith".into()),
        ts: Some(ts),
        duration: Some(duration),
        setpoint: vec![
            SetpointStep {
                value: 1.0,
                at: 0.0,
            },
            SetpointStep {
                value: 0.0,
                at: back,
            },
        ],
        disturbance: loads.iter().map(|d| d.parse().unwrap()).collect(),
        noise: (noise > 0.0).then_some(noise),
        quantization: bits.map(|b| 4.0 / f64::from(1u32 << b)),
        seed: Some(seed),
        events: events.iter().map(|e| e.parse().unwrap()).collect(),
        adapt: adapt.then(AdaptOptions::default),
        ..Default::default()
    }
    .run()
    .unwrap()
}

/// The IAE of each event's segment (the report's `events`).
fn event_iae(out: &RunOutput) -> Vec<f64> {
    out.events
        .iter()
        .map(|e| match e {
            msp::study::Event::Setpoint(s) => s.iae,
            msp::study::Event::Disturbance(d) => d.iae,
        })
        .collect()
}

/// No process change: with loads only between two set-point moves (output
/// loads on the stable processes only), under
/// each measurement condition and at a coarse period (twelve samples of
/// dead time) and a fine one (120), the adaptive loop's IAE of every event
/// is within 5 % of the fixed-model loop's, and no model is applied.
#[test]
fn loads_and_noise_do_no_harm() {
    let plants: [(&str, f64, f64, &[&str]); 3] = [
        (
            "1.6e^-6s/(10s+1)",
            6.0,
            1900.0,
            &["input:0.2@400", "output:0.3@800", "input:-0.15@1200"],
        ),
        (
            "2.3e^-8s/(15s+1)",
            8.0,
            1900.0,
            &["output:-0.2@500", "input:0.1@900", "output:0.25@1300"],
        ),
        // (an output load on an integrating process still teaches the
        // estimator a wrong gain at a fine period: not in the bank yet)
        (
            "0.15e^-5s/s",
            5.0,
            1500.0,
            &["input:0.5@300", "input:-0.4@1000"],
        ),
    ];
    let conditions: [(f64, Option<u32>); 4] =
        [(0.0, None), (0.005, None), (0.02, None), (0.0, Some(10))];
    for (plant, theta, duration, loads) in plants {
        for per in [12.0, 120.0] {
            let ts = theta / per;
            for (noise, bits) in conditions {
                for seed in 1..=2u64 {
                    let back = duration - 300.0;
                    let with = |adapt| {
                        run(
                            plant,
                            ts,
                            duration,
                            back,
                            loads,
                            &[],
                            noise,
                            bits,
                            seed,
                            adapt,
                        )
                    };
                    let (fixed, adaptive) = (with(false), with(true));
                    let case = format!("{plant} ts {ts} noise {noise} bits {bits:?} seed {seed}");
                    let applied: Vec<_> = adaptive
                        .report()
                        .adaptation
                        .iter()
                        .filter(|c| {
                            matches!(
                                c.kind,
                                msp::adapt::ChangeKind::Applied
                                    | msp::adapt::ChangeKind::Emergency
                                    | msp::adapt::ChangeKind::Detuned
                            )
                        })
                        .cloned()
                        .collect();
                    assert!(applied.is_empty(), "{case}: {applied:?}");
                    for (a, f) in event_iae(&adaptive).iter().zip(event_iae(&fixed)) {
                        assert!(*a <= 1.05 * f + 1e-9, "{case}: IAE {a} against {f}");
                    }
                }
            }
        }
    }
}

/// Integrating processes whose dead time grows by 40 % (0.15 e^{−5s}/s to
/// 7 s, 0.05 e^{−6s}/s to 8.4 s), at 20 and at 120 samples of dead time:
/// the fixed model's loop diverges after the next set-point move; the
/// adaptive one takes the emergency path (its log says so), ends with the
/// process's dead time and stays bounded.
#[test]
fn integrating_loops_going_unstable_are_caught() {
    for (plant, theta, grown) in [("0.15e^-5s/s", 5.0, 7.0), ("0.05e^-6s/s", 6.0, 8.4)] {
        for per in [20.0, 120.0] {
            let event = format!("1200:plant-dead-time={grown}");
            let with = |adapt| {
                run(
                    plant,
                    theta / per,
                    1500.0,
                    1230.0,
                    &[],
                    &[event.as_str()],
                    0.0,
                    None,
                    1,
                    adapt,
                )
            };
            let (fixed, adaptive) = (with(false), with(true));
            let case = format!("{plant} at {per} samples of dead time");
            // the largest |y| after the set point's return (a diverged
            // run's columns end where it diverged)
            let worst = |out: &RunOutput| {
                out.result
                    .y
                    .iter()
                    .zip(&out.result.t)
                    .filter(|(_, t)| **t > 1400.0)
                    .map(|(y, _)| y.abs())
                    .fold(0.0f64, f64::max)
            };
            let ended = |out: &RunOutput| out.result.t.last().copied().unwrap_or(0.0);
            assert!(
                worst(&fixed) > 10.0 || ended(&fixed) < 1499.0,
                "{case}: the fixed loop {} until {}",
                worst(&fixed),
                ended(&fixed)
            );
            assert!(ended(&adaptive) >= 1499.0, "{case}: {}", ended(&adaptive));
            assert!(worst(&adaptive) < 0.1, "{case}: {}", worst(&adaptive));
            let kinds: Vec<_> = adaptive
                .report()
                .adaptation
                .iter()
                .map(|c| c.kind)
                .collect();
            assert!(
                kinds.contains(&msp::adapt::ChangeKind::Emergency),
                "{case}: {kinds:?}"
            );
            let theta_model = adaptive
                .result
                .signals
                .iter()
                .find(|(n, _)| n == "theta_model")
                .and_then(|(_, s)| s.last().copied())
                .unwrap();
            assert!(
                (theta_model - grown).abs() < 0.05 * grown,
                "{case}: {theta_model}"
            );
        }
    }
}

/// The process changes at a fine period (125 samples of dead time, the
/// estimator decimating by 13) on `2.3 e^{−8s}/(15s + 1)` under 1 % noise,
/// the set point moving every 80 s: the gain doubled and halved, the lag
/// doubled and halved, the dead time +60 % and −40 % are each learnt; over
/// the last 1000 s of an hour the adaptive loop's IAE is within 10 % of
/// the loop built with the true model from the start, and where the fixed
/// model's is 20 % worse than that, it wins back three quarters of the
/// difference.
#[test]
fn process_changes_are_learnt_at_a_fine_period() {
    let ts = 0.064;
    let (k, tau, theta) = (2.3, 15.0, 8.0);
    let cases = [
        ("plant-gain=4.6", (4.6, tau, theta)),
        ("plant-gain=1.15", (1.15, tau, theta)),
        ("plant-lag=30", (k, 30.0, theta)),
        ("plant-lag=7.5", (k, 7.5, theta)),
        ("plant-dead-time=12.8", (k, tau, 12.8)),
        ("plant-dead-time=4.8", (k, tau, 4.8)),
    ];
    let square: Vec<SetpointStep> = (0..50)
        .map(|i| SetpointStep {
            value: f64::from(i % 2),
            at: 80.0 * f64::from(i),
        })
        .collect();
    // the loop tuned for the plant as it is at the start
    let run = |plant: &str, event: Option<&str>, adapt: bool| {
        Scenario {
            plant: Some(plant.parse().unwrap()),
            controller: Some("smith".into()),
            lambda: Some(8.0),
            ts: Some(ts),
            duration: Some(4000.0),
            setpoint: square.clone(),
            noise: Some(0.01),
            seed: Some(2),
            events: event.map(|e| e.parse().unwrap()).into_iter().collect(),
            adapt: adapt.then(AdaptOptions::default),
            ..Default::default()
        }
        .run()
        .unwrap()
    };
    let iae_late = |out: &RunOutput| -> f64 {
        let r = &out.result;
        r.t.iter()
            .zip(r.y.iter().zip(&r.r))
            .filter(|(t, _)| **t >= 3000.0)
            .map(|(_, (y, r))| (r - y).abs() * ts)
            .sum()
    };
    let plant = format!("{k}e^-{theta}s/({tau}s+1)");
    for (event, (k1, tau1, theta1)) in cases {
        let at = format!("400:{event}");
        let adaptive = run(&plant, Some(&at), true);
        let fixed = run(&plant, Some(&at), false);
        // the true model's loop: the changed process, tuned for itself
        let changed = format!("{k1}e^-{theta1}s/({tau1}s+1)");
        let truth = run(&changed, None, false);
        let (ia, ifx, it) = (iae_late(&adaptive), iae_late(&fixed), iae_late(&truth));
        let model: Vec<f64> = ["k_model", "tau_model", "theta_model"]
            .iter()
            .map(|n| {
                adaptive
                    .result
                    .signals
                    .iter()
                    .find(|(m, _)| m == n)
                    .and_then(|(_, s)| s.last().copied())
                    .unwrap()
            })
            .collect();
        let case =
            format!("{event}: model {model:?}, IAE adaptive {ia:.3}, fixed {ifx:.3}, true {it:.3}");
        assert!((model[0] / k1 - 1.0).abs() < 0.08, "{case}");
        assert!((model[1] / tau1 - 1.0).abs() < 0.1, "{case}");
        assert!((model[2] / theta1 - 1.0).abs() < 0.03, "{case}");
        assert!(ia <= 1.1 * it, "{case}");
        // where the fixed model loses 20 % or more, the adaptive loop wins
        // back at least three quarters of it (20 % better than the fixed
        // loop asks more than the true model gives where it loses just
        // 20 %)
        if ifx >= 1.2 * it {
            assert!(ia <= it + 0.25 * (ifx - it), "{case}");
        }
    }
}
