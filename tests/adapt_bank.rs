//! The adaptation's benchmark bank (`msp::study::bank`), reduced: where
//! the process does not change, the adaptive loop does no harm — set-point
//! moves, input and output load steps, measurement noise and a 10-bit
//! converter, on stable and integrating processes, at a coarse period and
//! at msp's chosen one; where it changes (dead time stepping or drifting up
//! and down, gain and lag doubled and halved) the adaptive loop ends near
//! the loop built with the true model and never diverges. The full bank is
//! `scripts/adapt-bank` and its table `docs/adapt-bank.md`.

use msp::sim::SetpointStep;
use msp::study::bank::Period;
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

/// The kinds of the changes a run's adaptation logged, in order.
fn kinds(out: &RunOutput) -> Vec<msp::adapt::ChangeKind> {
    out.report().adaptation.iter().map(|c| c.kind).collect()
}

/// The bank's cases of `family` (seed 1) under `conditions` at `period`.
fn bank_cases(
    family: &str,
    period: Period,
    conditions: &[(f64, Option<u32>)],
) -> Vec<msp::study::bank::BankCase> {
    msp::study::bank::cases(1)
        .into_iter()
        .filter(|c| c.family == family && c.period == period)
        .filter(|c| conditions.contains(&(c.noise, c.bits)))
        .collect()
}

/// Item 1, no harm: where the process does not change — the set point
/// moving, loads stepping at the input and output (on integrating
/// processes the input), or ramping to new levels — under every measurement condition of the bank and at both
/// periods, no model is applied and no event's IAE is more than 5 % above
/// the fixed-model loop's.
fn no_harm(family: &str) {
    for period in [Period::Chosen, Period::Coarse] {
        let cases = bank_cases(family, period, &msp::study::bank::CONDITIONS);
        assert_eq!(cases.len(), 25, "{family}");
        for case in cases {
            let r = case.run().unwrap();
            assert_eq!(r.applied, 0, "{r:?}");
            assert!(r.worst_event_ratio <= 1.05, "{r:?}");
        }
    }
}

#[test]
fn no_change_with_the_set_point_moving_does_no_harm() {
    no_harm("no change, set point");
}

#[test]
fn no_change_with_loads_does_no_harm() {
    no_harm("no change, loads");
}

#[test]
fn no_change_with_ramping_loads_does_no_harm() {
    no_harm("no change, ramps");
}

/// The settling scales (`θ + τ`; `2θ` integrating) after a change within
/// which the adaptive loop's events come within 10 % of the true model's
/// loop's, at 0.5 % noise and 10 bits (the bank's table, three seeds: the
/// worst 76 at msp's chosen period, a dead time drifting up on an
/// integrating process; twenty set-point moves).
const LEARNT_WITHIN: f64 = 80.0;

/// [`LEARNT_WITHIN`] for a gain or a lag between the change detector's
/// hypotheses, which none of them names: the nearest is applied first and
/// the bank's estimate refines it once it held still (the bank's table:
/// at most 108 at 0.5 % noise, three seeds).
const LEARNT_BETWEEN: f64 = 120.0;

/// Items 2 and 3, help and never destabilise: after each change of the
/// bank on every process (0.5 % noise and a 10-bit converter at msp's
/// chosen period, 0.5 % noise at the coarse one) the adaptive loop ends
/// within 10 % of the IAE of the loop built with the true model — so
/// where the fixed model loses 20 % or more it wins back at least half
/// of that — and it never diverges (the fixed one does on every
/// integrating process: a Smith predictor's margin there is thin); every
/// event from [`LEARNT_WITHIN`] settling scales after the change on is
/// within 10 % of the true model's loop's
/// ([`msp::study::bank::BankResult::learnt_after`]).
fn learns(family: &str) {
    learns_within(family, LEARNT_WITHIN);
}

/// [`learns`] with every event within 10 % of the true model's loop from
/// `within` settling scales after the change on.
fn learns_within(family: &str, within: f64) {
    let mut n = 0;
    for (period, conditions) in [
        (Period::Chosen, &[(0.005, None), (0.0, Some(10))][..]),
        (Period::Coarse, &[(0.005, None)][..]),
    ] {
        for case in bank_cases(family, period, conditions) {
            let r = case.run().unwrap();
            assert!(r.iae_adaptive.is_finite(), "{r:?}");
            assert!(r.within_true(), "{r:?}");
            assert!(r.learnt_after.is_some_and(|a| a <= within), "{r:?}");
            if r.iae_fixed.is_finite() && r.iae_fixed >= 1.2 * r.iae_true {
                assert!(
                    r.iae_adaptive <= r.iae_fixed - 0.5 * (r.iae_fixed - r.iae_true),
                    "{r:?}"
                );
            }
            n += 1;
        }
    }
    // three conditions on every process (three stable ones for a lag)
    assert!(n >= 9, "{family}: {n} cases");
}

#[test]
fn a_dead_time_step_up_is_learnt() {
    learns("dead time ×1.6");
}

#[test]
fn a_dead_time_step_down_is_learnt() {
    learns("dead time ×0.6");
}

#[test]
fn a_dead_time_drifting_up_is_learnt() {
    learns("dead time drifts ×1.5");
}

#[test]
fn a_dead_time_drifting_down_is_learnt() {
    learns("dead time drifts ×0.7");
}

#[test]
fn a_gain_doubling_is_learnt() {
    learns("gain ×2");
}

#[test]
fn a_gain_halving_is_learnt() {
    learns("gain ×0.5");
}

#[test]
fn a_lag_doubling_is_learnt() {
    learns("lag ×2");
}

#[test]
fn a_lag_halving_is_learnt() {
    learns("lag ×0.5");
}

/// A gain and a lag between the change detector's hypotheses (none names
/// 0.6 times the gain or 1.6 times the lag exactly).
#[test]
fn a_gain_between_the_hypotheses_is_learnt() {
    learns_within("gain ×0.6", LEARNT_BETWEEN);
}

#[test]
fn a_lag_between_the_hypotheses_is_learnt() {
    learns_within("lag ×1.6", LEARNT_BETWEEN);
}

/// Item 2 under heavy noise: at the coarse period with 5 % noise, the
/// estimate of a converged bank wanders from sample to sample more than a
/// change that counts, and the supervisor must still see it settle (the
/// means of its blocks agree, [`msp::adapt::SPREAD`]). Of every change
/// with the set point moving whose factor a hypothesis of the change
/// detector names (seed 1: 36 cases), every one ends within 10 % of the
/// true model's loop (the bank's table, three seeds: 108 of 108; with the
/// blocks' spread held to one `min_change`, 71; before a dead time was
/// taken on its evidence over the model's own, 105); of the gain ×0.6 and
/// the lag ×1.6 between them (8 cases), every one too (the bank's table:
/// 24 of 24; 20 before the level test fitted the lag between its
/// hypotheses, 15 before it weighed the settled estimate the differences
/// could not validate, `tests/adapt_noise.rs`); none diverges.
#[test]
fn most_changes_are_learnt_at_the_coarse_period_under_5_percent_noise() {
    let (mut n, mut within) = ([0; 2], [0; 2]);
    for (family, _, excitation) in msp::study::bank::families() {
        if family.starts_with("no change") || excitation != msp::study::bank::Excitation::Setpoint {
            continue;
        }
        let between = usize::from(family == "gain ×0.6" || family == "lag ×1.6");
        for case in bank_cases(&family, Period::Coarse, &[(0.05, None)]) {
            let r = case.run().unwrap();
            assert!(r.iae_adaptive.is_finite(), "{r:?}");
            n[between] += 1;
            within[between] += usize::from(r.within_true());
        }
    }
    assert_eq!(n, [36, 8]);
    assert_eq!(within, [36, 8]);
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
            let kinds = kinds(&adaptive);
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

/// Item 3 where the loop learns from loads alone: a process change that
/// only load responses show (dead time ×1.6, gain ×0.5, lag ×2) is learnt
/// in part or not at all (the bank's table says how far), but the adaptive
/// loop never diverges, on any process, period or condition of the bank.
#[test]
fn a_change_that_only_loads_show_never_destabilises() {
    for family in ["dead time ×1.6, loads", "gain ×0.5, loads", "lag ×2, loads"] {
        for period in [Period::Chosen, Period::Coarse] {
            for case in bank_cases(family, period, &[(0.02, None), (0.0, Some(10))]) {
                let r = case.run().unwrap();
                assert!(r.iae_adaptive.is_finite(), "{r:?}");
            }
        }
    }
}

/// Item 2 where only loads move the loop: the gain halved on every process
/// of the bank, at the coarse period (no decimation: a load's response is a
/// few samples), without noise, under a 10-bit converter and (stable
/// processes) under 0.5 % noise, is learnt to within 10 % of the true
/// model's IAE (each difference of a load's response is below 0.5 % noise
/// there: the hypothesis's evidence is its sum over the responses) — the
/// change detector's gain hypothesis is proposed even while the bank's own estimate, biased by
/// the loads, sits beyond the bounds (an edge is warned of, not a reason to
/// hold a hypothesis that explains the data: that held `2.3 e^{−8s}/(15s + 1)`
/// at the fixed model's IAE, twice the true one's, for the whole run).
#[test]
fn a_gain_only_loads_show_is_learnt_beside_an_estimate_at_an_edge() {
    let cases = bank_cases(
        "gain ×0.5, loads",
        Period::Coarse,
        &[(0.0, None), (0.0, Some(10)), (0.005, None)],
    );
    // under noise, on the stable processes (on an integrating one the
    // controller's answer to a load is within ten times its jitter: the
    // bank's table)
    for case in cases
        .into_iter()
        .filter(|c| c.noise == 0.0 || c.plant.tau.is_some())
    {
        assert_learnt(&case);
    }
}

/// The bank case's change learnt: its adaptive loop within 10 % of the
/// true model's IAE, with a model applied.
fn assert_learnt(case: &msp::study::bank::BankCase) {
    let r = case.run().unwrap();
    assert!(
        r.within_true() && r.applied > 0,
        "{} {:?} {:?} {:?}: adaptive {} true {} fixed {}",
        case.family,
        case.plant,
        case.bits,
        case.period,
        r.iae_adaptive,
        r.iae_true,
        r.iae_fixed
    );
}

/// Item 2 where only loads move the loop: the lag doubled on every stable
/// process of the bank, at both periods, without noise and under a 10-bit
/// converter, is learnt to within 10 % of the true model's IAE. At rest a
/// wrong model's error finds onset after onset, each re-anchoring the
/// simulations; a load falling among an onset's samples starts them again
/// (taken as the models' state, an output load's pulse was an error
/// decaying over the lag in every simulation, which hid the lag's own: on
/// 1.6 e^{−6s}/(10s + 1) at the chosen period nothing was applied, the
/// loop 44 % worse than the true model's).
#[test]
fn a_lag_only_loads_show_is_learnt_without_noise() {
    for period in [Period::Chosen, Period::Coarse] {
        let cases = bank_cases("lag ×2, loads", period, &[(0.0, None), (0.0, Some(10))]);
        assert_eq!(cases.len(), 6);
        cases.iter().for_each(assert_learnt);
    }
}

/// Item 2 where only loads move the loop, under 5 % noise at msp's chosen
/// period: the gain halved or the lag doubled on the stable processes of
/// the bank, where the fixed model is 20 % worse than the true one, is
/// learnt — within 10 % of the true model's IAE and 20 % better than the
/// fixed one. A load's response there is below the noise in every
/// difference: the hypothesis is proposed on Page's sum over the
/// responses, without asking the model in use's mean error over one to be
/// material above the noise (a mean that is as often below the noise as
/// not: asked, the halved gain and the doubled lag of
/// 2.3 e^{−8s}/(15s + 1) and the doubled lag of 1.6 e^{−6s}/(10s + 1) were
/// held for the whole run, Page's sum past 100).
#[test]
fn a_change_only_loads_show_is_learnt_under_5_percent_noise() {
    let mut n = 0;
    for family in ["gain ×0.5, loads", "lag ×2, loads"] {
        for case in bank_cases(family, Period::Chosen, &[(0.05, None)]) {
            let r = case.run().unwrap();
            if case.plant.tau.is_none() || r.iae_fixed < 1.2 * r.iae_true {
                continue;
            }
            n += 1;
            assert!(
                r.within_true() && r.iae_adaptive <= 0.8 * r.iae_fixed,
                "{family} {:?}: adaptive {} true {} fixed {}",
                case.plant,
                r.iae_adaptive,
                r.iae_true,
                r.iae_fixed
            );
        }
    }
    assert_eq!(n, 5);
}

/// Item 3 under noise: the integrating processes' dead time ×1.6 at the
/// chosen period under 5 % noise, three seeds: the fixed loop diverges, the
/// adaptive one never does. The emergency path detunes first and applies
/// an estimate only if the oscillation goes on (one fitted at its start,
/// half the dead time, applied at once left the output 120 times the step
/// away on seed 3 once the onsets' samples restarted on a load).
#[test]
fn an_emergency_under_noise_detunes_before_it_trusts_an_estimate() {
    let cases: Vec<_> = msp::study::bank::cases(3)
        .into_iter()
        .filter(|c| c.family == "dead time ×1.6" && c.period == Period::Chosen)
        .filter(|c| c.plant.tau.is_none() && c.noise == 0.05)
        .collect();
    assert_eq!(cases.len(), 6);
    for case in cases {
        let r = case.run().unwrap();
        assert!(!r.iae_fixed.is_finite(), "{r:?}");
        assert!(r.iae_adaptive.is_finite(), "{r:?}");
        let out = case.adaptive().unwrap();
        let first = kinds(&out).into_iter().find(|k| {
            matches!(
                k,
                msp::adapt::ChangeKind::Emergency | msp::adapt::ChangeKind::Detuned
            )
        });
        assert_eq!(first, Some(msp::adapt::ChangeKind::Detuned), "{r:?}");
    }
}

/// Item 3's emergency path is for loops going unstable: a stable loop's
/// ring whose quantized half-cycles repeat at the same height (the lag
/// doubled, loads only, ten samples of dead time, a 10-bit converter) is
/// no growing oscillation — no emergency, no detuning, and the adaptive
/// loop no worse than the fixed one by more than 5 % (detuned, it was
/// 29 % worse on 0.8 e^{−10s}/(4s + 1)).
#[test]
fn a_quantized_ring_is_no_emergency() {
    use msp::adapt::ChangeKind;
    let cases = bank_cases("lag ×2, loads", Period::Coarse, &[(0.0, Some(10))]);
    assert_eq!(cases.len(), 3);
    for case in cases {
        let r = case.run().unwrap();
        assert!(r.iae_adaptive <= 1.05 * r.iae_fixed, "{r:?}");
        let kinds = kinds(&case.adaptive().unwrap());
        assert!(
            !kinds.contains(&ChangeKind::Emergency) && !kinds.contains(&ChangeKind::Detuned),
            "{:?}: {kinds:?}",
            case.plant
        );
    }
}

/// Item 5, the monitor (`--monitor`) tells a load from a model error: a
/// change of 30 % either way of the dead time (a set-point move with it)
/// or of the gain or the lag raises the alarm within two of the loop's
/// settling times of the response that shows it; on every process of the bank
/// under 0.5 % noise at both periods. Without a change, loads alone or
/// the set point moving never raise it, under every condition.
#[test]
fn the_monitor_alarms_on_a_30_percent_change_and_never_on_a_load() {
    use msp::sim::PlantParameter;
    use msp::study::bank::{BankCase, Change, Excitation, PLANTS};
    let alarms = |out: &RunOutput| -> Vec<f64> {
        out.report()
            .adaptation
            .iter()
            .filter(|c| c.kind == msp::adapt::ChangeKind::Alarm)
            .map(|c| c.at)
            .collect()
    };
    for plant in PLANTS {
        for period in [Period::Chosen, Period::Coarse] {
            // the bank's case of this process and period, its change and
            // measurement replaced
            let base = msp::study::bank::cases(1)
                .into_iter()
                .find(|c| c.plant == plant && c.period == period)
                .unwrap();
            let case = |change, excitation, noise, bits| BankCase {
                change,
                excitation,
                noise,
                bits,
                ..base.clone()
            };
            for what in [
                PlantParameter::DeadTime,
                PlantParameter::Gain,
                PlantParameter::Lag,
            ] {
                if what == PlantParameter::Lag && plant.tau.is_none() {
                    continue;
                }
                for factor in [1.3, 0.7] {
                    let change = Change {
                        what,
                        factor,
                        drift: None,
                    };
                    let c = case(Some(change), Excitation::Setpoint, 0.005, None);
                    let out = c.monitored().unwrap();
                    let settling = out
                        .events
                        .iter()
                        .find_map(|e| match e {
                            msp::study::Event::Setpoint(s) => Some(s.step.settling_time),
                            msp::study::Event::Disturbance(_) => None,
                        })
                        .unwrap();
                    let first = alarms(&out)
                        .into_iter()
                        .find(|at| *at >= c.change_at())
                        .unwrap_or(f64::INFINITY);
                    // a dead time, a gain or a lag shows in the change
                    // detector's simulations at once: named within two
                    // settling times of the response that shows it (the
                    // first, or on a dead-time-dominant process whose first
                    // response is mostly dead time, the next: a half period
                    // of the square wave, 4 scales, on)
                    let half = plant.half_period();
                    let bound = half + 2.0 * settling;
                    assert!(
                        first.is_finite() && first - c.change_at() <= bound,
                        "{:?} {what:?} ×{factor} {period:?}: alarm {first} s, change at {} s, settling {settling} s",
                        plant, c.change_at()
                    );
                    assert!(
                        alarms(&out).iter().all(|at| *at >= c.change_at()),
                        "{:?}",
                        alarms(&out)
                    );
                }
            }
            // no change, under every measurement condition: loads alone,
            // and the set point moving (the model in use's error is then
            // the block means' departure from every model, which on an
            // integrating process at a fine period a model fitted to them
            // halves: a model that near is not a model error)
            for excitation in [Excitation::Loads, Excitation::Setpoint] {
                for (noise, bits) in msp::study::bank::CONDITIONS {
                    let out = case(None, excitation, noise, bits).monitored().unwrap();
                    assert!(
                        alarms(&out).is_empty(),
                        "{plant:?} {period:?} {excitation:?} noise {noise} {bits:?}: {:?}",
                        alarms(&out)
                    );
                }
            }
        }
    }
}

/// A lag doubled is not taken for a gain halved: in a few load responses'
/// differences the two look alike (the halved gain's simulation may leave
/// the least recent error while the doubled lag has the more evidence), and
/// a hypothesis is proposed only with the most evidence of all. On
/// `2.3 e^{−8s}/(15s + 1)` at the coarse period under 0.5 % noise, seed 4
/// (outside the reduced bank's seed): the gain halved was applied and the
/// loop ended 8.6 % worse than the fixed model's; now no applied model
/// changes the gain, and the adaptive loop is not worse than the fixed one.
#[test]
fn a_doubled_lag_is_not_taken_for_a_halved_gain() {
    let case = msp::study::bank::cases(4)
        .into_iter()
        .find(|c| {
            c.family == "lag ×2, loads"
                && c.period == Period::Coarse
                && c.plant.k == 2.3
                && c.noise == 0.005
                && c.bits.is_none()
                && c.seed == 4
        })
        .unwrap();
    let log = case.adaptive().unwrap().report().adaptation;
    for c in &log {
        if c.kind == msp::adapt::ChangeKind::Applied {
            assert!((c.k - 2.3).abs() < 0.05 * 2.3, "{log:?}");
        }
    }
    let r = case.run().unwrap();
    assert!(
        r.iae_adaptive <= 1.001 * r.iae_fixed,
        "adaptive {} fixed {}",
        r.iae_adaptive,
        r.iae_fixed
    );
}
