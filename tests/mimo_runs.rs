//! The sampled multivariable loop's runs (#51): the firmware's decoupler is
//! the host's, a loop's events are the single loop's, diagonal plants run as
//! single loops, manual and automatic per loop, actuator limits and noise,
//! the Smith detuning, and a channel's dead-time change.

use msp::analysis::mimo::TransferMatrix;
use msp::poly::TransferFunction;
use msp::sim::{simulate_mimo, SetpointStep};
use msp::study::mimo::{analyse, controller, design};
use msp::PidConfig;

mod mimo_common;
use mimo_common::*;

/// The firmware's decoupled compensator — `fopdt_element`'s closed form of
/// each element over arrays, Smith predictors from `from_model` — is the
/// host's (`msp::study::mimo::controller` of the design, whose elements
/// are the ratios of the exact sampled channels): on the Wood–Berry column
/// and on random first-order channels with fractions of a sample, the same
/// inputs sample for sample (f64, to rounding).
#[test]
fn the_firmware_decoupler_is_the_hosts() {
    use msp::mimo::{fopdt_element, Decoupled, InvertedDecoupler};
    use msp::{Fopdt, ProcessModel, SmithPredictor};
    type Sp = SmithPredictor<f64, 1, [f64; 64]>;
    let mut rng = Rng(0x00f1_2e55_5eed_0001);
    let wb = [
        (12.8, 16.7, 1.0),
        (-18.9, 21.0, 3.0),
        (6.6, 10.9, 7.0),
        (-19.4, 14.4, 3.0),
    ];
    for case in 0..6 {
        let ts = if case == 0 { 1.0 } else { 0.5 };
        let ch: Vec<(f64, f64, f64)> = if case == 0 {
            wb.to_vec()
        } else {
            let th = [1.0 + 2.0 * rng.uni(), 1.0 + 2.0 * rng.uni()];
            (0..4)
                .map(|idx| {
                    let (i, j) = (idx / 2, idx % 2);
                    // diagonal: whole samples and a fraction below 0.4
                    let l = if i == j {
                        (th[i] / ts).round() * ts + 0.4 * ts * rng.uni()
                    } else {
                        th[i] + 2.0 * rng.uni()
                    };
                    let k = if i == j {
                        1.0 + rng.uni()
                    } else {
                        rng.uni() - 0.5
                    };
                    (k, 2.0 + 8.0 * rng.uni(), l)
                })
                .collect()
        };
        let rows: Vec<Vec<TransferFunction>> = (0..2)
            .map(|i| {
                (0..2)
                    .map(|j| {
                        let (k, t, l) = ch[i * 2 + j];
                        TransferFunction::new(&[k], &[t, 1.0], l).unwrap()
                    })
                    .collect()
            })
            .collect();
        let m = TransferMatrix::new(rows).unwrap();
        let d = design(&m, "decoupled", None, ts).unwrap();
        let f = |idx: usize| Fopdt::new(ch[idx].0, ch[idx].1, ch[idx].2).unwrap();
        let el = |i: usize, j: usize| {
            Some(fopdt_element(&f(i * 2 + j), &f(i * 3), ts, [0.0; 64]).unwrap())
        };
        let dec = InvertedDecoupler::new([[None, el(0, 1)], [el(1, 0), None]]).unwrap();
        let sp = |i: usize| -> Sp {
            let p = &d.loops[i];
            let cfg = PidConfig::isa(p.get("kp").unwrap(), p.get("ti").unwrap(), 0.0, ts);
            SmithPredictor::from_model(cfg, &ProcessModel::from(f(i * 3)), ts).unwrap()
        };
        let mut fw = Decoupled::new([sp(0), sp(1)], dec);
        let mut host = controller(&m, &d).unwrap();
        let sps = steps(&[(1.0, 0.0), (-0.5, 20.0)]);
        let a = simulate_mimo(&m, &mut fw, &sps, &Default::default(), ts, 80.0).unwrap();
        let b = simulate_mimo(&m, &mut *host, &sps, &Default::default(), ts, 80.0).unwrap();
        for i in 0..2 {
            for (k, (x, y)) in a.u[i].iter().zip(&b.u[i]).enumerate() {
                assert!(
                    (x - y).abs() < 1e-9 * (1.0 + y.abs()),
                    "{m}: u{i} at {k}: {x} vs {y}"
                );
            }
        }
    }
}

/// Each loop's events of a multivariable run are the single loop's
/// measures: under the decoupler, loop 1's set-point step on Wood–Berry has
/// the step information and IAE of the single-loop run of its Smith
/// predictor on `g11` (the same samples, the same measure).
#[test]
fn a_loops_events_are_the_single_loops() {
    use msp::study::{Event, MimoScenario, Scenario};
    let m = wood_berry();
    let step = SetpointStep {
        value: 1.0,
        at: 0.0,
    };
    let out = MimoScenario {
        plant: m.clone(),
        controller: Some("decoupled".into()),
        rule: None,
        ts: Some(0.5),
        duration: Some(100.0),
        setpoints: vec![vec![step], vec![]],
        events: Default::default(),
    }
    .run()
    .unwrap();
    let single = Scenario {
        plant: Some(m.get(0, 0).unwrap().clone()),
        controller: Some("smith".into()),
        set: out.report.design.loops[0]
            .iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        ts: Some(0.5),
        duration: Some(100.0),
        setpoint: vec![step],
        ..Default::default()
    }
    .run()
    .unwrap();
    let (Event::Setpoint(a), Some(Event::Setpoint(b))) = (&out.events[0][0], single.events.first())
    else {
        panic!("{:?}", out.events)
    };
    for (x, y) in [
        (a.iae, b.iae),
        (a.step.rise_time, b.step.rise_time),
        (a.step.settling_time, b.step.settling_time),
        (a.step.overshoot, b.step.overshoot),
    ] {
        assert!((x - y).abs() < 1e-9 * (1.0 + y.abs()), "{x} vs {y}");
    }
    assert!(out.events[1].is_empty());
}

/// The diagonal plants of a family (stable and integrating channels, two
/// sample periods), each loop a PI: the multivariable run under `events`
/// is, loop by loop and sample for sample, the single loop's run of its
/// channel with the same PI and `single(loop, scenario)`'s additions.
fn diagonal_runs_are_single_loops(
    events: &msp::sim::MimoEvents,
    single: &dyn Fn(usize, msp::study::Scenario) -> msp::study::Scenario,
) {
    use msp::mimo::Decentralized;
    use msp::{Pid, PidConfig};
    let family = [
        (
            "2e^-1.05s/(4s+1)",
            "-1.5e^-2s/(6s+1)",
            [(0.8, 4.0), (-0.9, 6.0)],
        ),
        (
            "0.5e^-1s/s",
            "3e^-0.5s/((2s+1)(s+1))",
            [(0.6, 8.0), (0.3, 3.0)],
        ),
        ("e^-2s/(10s+1)", "-0.2e^-1s/s", [(2.0, 10.0), (-1.5, 12.0)]),
    ];
    let zero = TransferFunction::new(&[0.0], &[1.0], 0.0).unwrap();
    for (a, b, gains) in family {
        for ts in [0.1, 0.05] {
            let g = [tf(a), tf(b)];
            let diag = TransferMatrix::new(vec![
                vec![g[0].clone(), zero.clone()],
                vec![zero.clone(), g[1].clone()],
            ])
            .unwrap();
            let sps = steps(&[(1.0, 1.0), (-0.5, 3.0)]);
            let pids: Vec<Pid<f64>> = gains
                .iter()
                .map(|(kp, ti)| Pid::new(PidConfig::isa(*kp, *ti, 0.0, ts)).unwrap())
                .collect();
            let run = simulate_mimo(&diag, &mut Decentralized::new(pids), &sps, events, ts, 60.0)
                .unwrap();
            for i in 0..2 {
                let sc = msp::study::Scenario {
                    plant: Some(g[i].clone()),
                    controller: Some("pi".into()),
                    set: [
                        ("kp".to_string(), gains[i].0),
                        ("ti".to_string(), gains[i].1),
                    ]
                    .into_iter()
                    .collect(),
                    ts: Some(ts),
                    duration: Some(60.0),
                    setpoint: sps[i].clone(),
                    ..Default::default()
                };
                let one = single(i, sc).run().unwrap().result;
                // what the plant received (the controller's output where nothing changed it)
                let u = if one.u_applied.is_empty() {
                    &one.u
                } else {
                    &one.u_applied
                };
                assert_eq!(run.t.len(), one.y.len(), "{a}, {b} at {ts}");
                for (k, ((y, ym), (v, vm))) in one
                    .y
                    .iter()
                    .zip(&run.y[i])
                    .zip(u.iter().zip(&run.u[i]))
                    .enumerate()
                {
                    assert!(
                        (y - ym).abs() < 1e-12 && (v - vm).abs() < 1e-12,
                        "{a}, {b} at {ts}: loop {i} at {k}: y {y} vs {ym}, u {v} vs {vm}"
                    );
                }
            }
        }
    }
}

/// On diagonal plants, each loop of the decentralized closed loop is the
/// single loop's run of its channel with the same PI (the study's `pi`
/// with `kp`, `ti` set), sample for sample.
#[test]
fn diagonal_loops_are_single_loops() {
    diagonal_runs_are_single_loops(&Default::default(), &|_, sc| sc);
}

/// An operator's manual and auto per loop: on diagonal plants, loop 2 in
/// manual at 0.3 from 20 s and back to automatic at 35 s is, sample for
/// sample, the single loop's run with `20:manual=0.3` and `35:auto`
/// (bumpless, its PI tracking the held value), and loop 1 the single
/// loop's without them; under the decoupled predictors on Wood–Berry, the
/// return to automatic moves the input by a small step, not a jump.
#[test]
fn manual_and_auto_per_loop() {
    use msp::sim::{LoopMode, MimoEvents};
    let events = MimoEvents {
        modes: vec![
            LoopMode {
                loop_index: 1,
                at: 20.0,
                manual: Some(0.3),
            },
            LoopMode {
                loop_index: 1,
                at: 35.0,
                manual: None,
            },
        ],
        ..Default::default()
    };
    diagonal_runs_are_single_loops(&events, &|i, mut sc| {
        if i == 1 {
            sc.events = vec!["20:manual=0.3".parse().unwrap(), "35:auto".parse().unwrap()];
        }
        sc
    });
    // the decoupled predictors: loop 2 held at its own output, then back
    let m = wood_berry();
    let d = design(&m, "decoupled", None, 1.0).unwrap();
    let mut c = controller(&m, &d).unwrap();
    let sps = steps(&[(1.0, 0.0), (1.0, 0.0)]);
    let free = simulate_mimo(&m, &mut *c, &sps, &Default::default(), 1.0, 150.0).unwrap();
    let held_at = free.u[1][60];
    let events = MimoEvents {
        modes: vec![
            LoopMode {
                loop_index: 1,
                at: 60.0,
                manual: Some(held_at),
            },
            LoopMode {
                loop_index: 1,
                at: 90.0,
                manual: None,
            },
        ],
        // a load while loop 2 is held: its output drifts, its controller waits
        loads: vec![msp::sim::LoopLoad {
            loop_index: 1,
            location: msp::sim::Location::Output,
            value: 0.1,
            at: 65.0,
        }],
        ..Default::default()
    };
    let mut c = controller(&m, &d).unwrap();
    let run = simulate_mimo(&m, &mut *c, &sps, &events, 1.0, 150.0).unwrap();
    assert!((60..90).all(|k| run.u[1][k] == held_at));
    let jump = (run.u[1][90] - held_at).abs();
    assert!(
        jump < 0.05 * held_at.abs().max(0.01),
        "{jump} from {held_at}"
    );
    // and the loop comes back to its set point
    assert!((run.y[1][149] - 1.0).abs() < 0.01, "{}", run.y[1][149]);
}

/// An actuator that limits every input: on diagonal plants each loop is
/// the single loop's run with `actuator` and `reset_feedback` (the limited
/// value as external reset feedback, no windup), sample for sample; with
/// measurement noise, the recorded outputs are the plant's and the inputs
/// stay within the limits.
#[test]
fn actuator_limits_and_noise() {
    use msp::mimo::Decentralized;
    use msp::sim::MimoEvents;
    use msp::{Pid, PidConfig};
    let events = MimoEvents {
        actuator: Some((-0.2, 0.6)),
        ..Default::default()
    };
    diagonal_runs_are_single_loops(&events, &|_, mut sc| {
        sc.actuator = Some((-0.2, 0.6));
        sc.reset_feedback = true;
        sc
    });
    let ts = 0.1;
    let zero = TransferFunction::new(&[0.0], &[1.0], 0.0).unwrap();
    let diag = TransferMatrix::new(vec![
        vec![tf("2e^-1.05s/(4s+1)"), zero.clone()],
        vec![zero, tf("1.5e^-2s/(6s+1)")],
    ])
    .unwrap();
    let sps = steps(&[(1.0, 1.0), (0.5, 3.0)]);
    let gains = [(0.8, 4.0), (0.9, 6.0)];
    let pids = || -> Vec<Pid<f64>> {
        gains
            .iter()
            .map(|(kp, ti)| Pid::new(PidConfig::isa(*kp, *ti, 0.0, ts)).unwrap())
            .collect()
    };
    let run = simulate_mimo(
        &diag,
        &mut Decentralized::new(pids()),
        &sps,
        &events,
        ts,
        40.0,
    )
    .unwrap();
    assert!(run.u[0].contains(&0.6), "the limit is reached");
    let noisy = MimoEvents {
        noise: 0.05,
        seed: 7,
        ..events
    };
    let n = simulate_mimo(
        &diag,
        &mut Decentralized::new(pids()),
        &sps,
        &noisy,
        ts,
        40.0,
    )
    .unwrap();
    assert!(n.u.iter().flatten().all(|u| (-0.2..=0.6).contains(u)));
    // the plant's output is smooth (a first-order response), the noise only measured
    let jumps = n.y[0]
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0f64, f64::max);
    assert!(jumps < 0.05, "{jumps}");
    assert_ne!(n.u[0], run.u[0]);
}

/// The decentralized Smith predictors' common detuning on a family of
/// random 2×2 and 3×3 plants (diagonal-dominant first-order channels with
/// dead times, two periods): the designed loop is stable by the sampled
/// verdict, its biggest log modulus is `2n` dB where `F > 1` raised it
/// there and at most that where the loops alone already met it, and each
/// loop's λ is its own channel's times `F`.
#[test]
fn smith_detuning_reaches_2n_db_on_a_family() {
    let mut rng = Rng(0x1234_5678_9abc_def0);
    for (n, ts) in [(2, 0.5), (2, 0.1), (3, 0.5), (2, 1.0), (3, 0.2)] {
        let rows: Vec<Vec<TransferFunction>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let k = if i == j {
                            1.0 + 2.0 * rng.uni()
                        } else {
                            0.8 * (rng.uni() - 0.5)
                        };
                        let (tau, l) = (2.0 + 10.0 * rng.uni(), 0.5 + 3.0 * rng.uni());
                        TransferFunction::new(&[k], &[tau, 1.0], l).unwrap()
                    })
                    .collect()
            })
            .collect();
        let m = TransferMatrix::new(rows).unwrap();
        let d = design(&m, "smith", None, ts).unwrap();
        let (v, _, lcm) = analyse(&m, &d).unwrap();
        assert_eq!(v.stable, Some(true), "{m}: {}", v.reason);
        let target = 2.0 * n as f64;
        if d.f > 1.0 {
            assert!((lcm - target).abs() < 0.05, "{m}: F {} Lcm {lcm}", d.f);
        } else {
            assert!(lcm <= target + 1e-9, "{m}: Lcm {lcm}");
        }
        let alone = design(&m, "decoupled", None, ts).unwrap();
        for (a, b) in d.loops.iter().zip(&alone.loops) {
            let (la, lb) = (a.lambda().unwrap(), b.lambda().unwrap());
            assert!(
                (la - lb * d.f).abs() < 1e-9 * la,
                "{m}: λ {la} vs {lb}·{}",
                d.f
            );
        }
    }
}

/// A channel's dead time changing in a run: the report's verdict is the
/// loop's as built, said so, and cross-checked up to the change; after it,
/// the run follows the verdict of the changed plant (`SampledLoop` on the
/// matrix with the new dead time): it settles where that loop is stable
/// and its error grows where it is not. Wood–Berry under BLT's PI loops,
/// `g₁₁`'s dead time from 1 to each of a range.
#[test]
fn after_a_channels_dead_time_change_the_run_follows_the_changed_loops_verdict() {
    use msp::sim::{ChannelDeadTime, MimoEvents};
    use msp::study::MimoScenario;
    let m = wood_berry();
    let ts = 0.5;
    let (at, duration) = (100.0, 3000.0);
    let (mut stable, mut unstable) = (0, 0);
    for new in [1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0] {
        let out = MimoScenario {
            plant: m.clone(),
            controller: Some("pi".into()),
            rule: None,
            ts: Some(ts),
            duration: Some(duration),
            setpoints: steps(&[(1.0, 0.0), (0.0, 0.0)]),
            events: MimoEvents {
                dead_times: vec![ChannelDeadTime {
                    row: 0,
                    col: 0,
                    dead_time: new,
                    at,
                }],
                ..Default::default()
            },
        }
        .run()
        .unwrap();
        let st = &out.report.stability;
        assert_eq!(st.as_built_until, Some(at));
        assert_eq!(st.stable, Some(true), "BLT's loop as built");
        assert!(st.reason.contains("the loop as built"), "{}", st.reason);
        // the changed loop's verdict, independently of the run
        let pis: Vec<(f64, f64)> = out
            .report
            .design
            .loops
            .iter()
            .map(|p| (p.get("kp").unwrap(), p.get("ti").unwrap()))
            .collect();
        let g11 = TransferFunction::new(&[12.8], &[16.7, 1.0], new).unwrap();
        let changed = TransferMatrix::new(vec![
            vec![g11, m.get(0, 1).unwrap().clone()],
            vec![m.get(1, 0).unwrap().clone(), m.get(1, 1).unwrap().clone()],
        ])
        .unwrap();
        let verdict = verdict(&changed, &pis, ts).expect("a verdict");
        // the error of loop 1 over the last two tenths of the run and the two before
        let n = out.run.t.len();
        let worst = |from: usize, to: usize| {
            (from..to)
                .map(|k| (out.run.r[0][k] - out.run.y[0][k]).abs())
                .fold(0.0, f64::max)
        };
        let (late, before) = (worst(n * 8 / 10, n), worst(n * 6 / 10, n * 8 / 10));
        if verdict {
            stable += 1;
            assert!(
                late < 1e-3,
                "dead time {new}: stable, but the error is {late} late in the run"
            );
        } else {
            unstable += 1;
            assert!(
                late > 1.5 * before || !late.is_finite(),
                "dead time {new}: unstable, but the error goes {before} → {late}"
            );
        }
    }
    assert!(
        stable > 0 && unstable > 0,
        "{stable} stable, {unstable} unstable"
    );
}
