//! The sampled multivariable loop (#51): its stability verdict against the
//! closed-loop poles computed here independently, and the decoupled
//! compensator's decoupling, realizability and runs.
//!
//! The poles: the state matrix of the sampled loop written out from its
//! parts — each channel `gᵢⱼ = Kᵢⱼe^{−dᵢⱼTs·s}/(τᵢⱼs + 1)` (whole-sample
//! dead times) as `xᵢⱼ ← aᵢⱼxᵢⱼ + Kᵢⱼ(1 − aᵢⱼ)uⱼ[k − dᵢⱼ]`, `yᵢ = Σⱼ xᵢⱼ`,
//! each input's past values as a shift register, msp's PI as
//! `uⱼ = kpⱼ·eⱼ + Iⱼ`, `Iⱼ ← Iⱼ + kpⱼTs/Tiⱼ·eⱼ` — and its eigenvalues
//! (nalgebra). The verdict (the generalized Nyquist criterion on
//! `det(diag(Dc) + diag(Nc)·G)`) must agree with the spectral radius at
//! gains 15 % below and above each loop's critical scaling.

use msp::analysis::mimo::{Realization, SampledLoop, TransferMatrix};
use msp::mimo::{Decentralized, MultiController};
use msp::poly::TransferFunction;
use msp::sim::{simulate_mimo, SetpointStep};
use msp::study::mimo::{analyse, controller, design};
use msp::{LoopController, Pid, PidConfig};
use nalgebra::DMatrix;

fn tf(s: &str) -> TransferFunction {
    s.parse().unwrap()
}

/// Wood & Berry (1973), time in minutes.
fn wood_berry() -> TransferMatrix {
    TransferMatrix::new(vec![
        vec![tf("12.8e^-1s/(16.7s+1)"), tf("-18.9e^-3s/(21s+1)")],
        vec![tf("6.6e^-7s/(10.9s+1)"), tf("-19.4e^-3s/(14.4s+1)")],
    ])
    .unwrap()
}

/// One set-point step per loop: `(value, at)` each.
fn steps(each: &[(f64, f64)]) -> Vec<Vec<SetpointStep>> {
    each.iter()
        .map(|&(value, at)| vec![SetpointStep { value, at }])
        .collect()
}

struct Rng(u64);
impl Rng {
    fn uni(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A channel `k e^{−d·ts·s}/(τs + 1)`.
#[derive(Clone, Copy, Debug)]
struct Channel {
    k: f64,
    tau: f64,
    d: usize,
}

/// The spectral radius of the sampled loop of PI loops `(kp, ti)` on
/// `channels` (row-major, `n×n`) at `ts`.
fn radius(channels: &[Channel], n: usize, pis: &[(f64, f64)], ts: f64) -> f64 {
    let dmax: Vec<usize> = (0..n)
        .map(|j| (0..n).map(|i| channels[i * n + j].d).max().unwrap())
        .collect();
    // states: x (n²), then each input's register (dmax[j]), then I (n)
    let nx = n * n;
    let reg0: Vec<usize> = (0..n)
        .scan(nx, |at, j| {
            let s = *at;
            *at += dmax[j];
            Some(s)
        })
        .collect();
    let i0 = nx + dmax.iter().sum::<usize>();
    let size = i0 + n;
    // u_j as a row over the states: −kp_j·y_j + I_j
    let u_row = |j: usize| {
        let mut r = vec![0.0; size];
        for m in 0..n {
            r[j * n + m] -= pis[j].0;
        }
        r[i0 + j] = 1.0;
        r
    };
    let mut a = DMatrix::<f64>::zeros(size, size);
    for i in 0..n {
        for j in 0..n {
            let c = channels[i * n + j];
            let ad = (-ts / c.tau).exp();
            let b = c.k * (1.0 - ad);
            let row = i * n + j;
            a[(row, row)] += ad;
            if c.d == 0 {
                for (s, v) in u_row(j).iter().enumerate() {
                    a[(row, s)] += b * v;
                }
            } else {
                a[(row, reg0[j] + c.d - 1)] += b;
            }
        }
    }
    for j in 0..n {
        if dmax[j] > 0 {
            for (s, v) in u_row(j).iter().enumerate() {
                a[(reg0[j], s)] += v;
            }
            for m in 1..dmax[j] {
                a[(reg0[j] + m, reg0[j] + m - 1)] = 1.0;
            }
        }
        // I_j ← I_j + kp·ts/ti·(−y_j)
        a[(i0 + j, i0 + j)] = 1.0;
        for m in 0..n {
            a[(i0 + j, j * n + m)] -= pis[j].0 * ts / pis[j].1;
        }
    }
    a.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

fn matrix(channels: &[Channel], n: usize, ts: f64) -> TransferMatrix {
    TransferMatrix::new(
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let c = channels[i * n + j];
                        TransferFunction::new(&[c.k], &[c.tau, 1.0], c.d as f64 * ts).unwrap()
                    })
                    .collect()
            })
            .collect(),
    )
    .unwrap()
}

/// msp's verdict for the PI loops `pis` on `m`.
fn verdict(m: &TransferMatrix, pis: &[(f64, f64)], ts: f64) -> Option<bool> {
    let loops: Vec<Pid<f64>> = pis
        .iter()
        .map(|(kp, ti)| Pid::new(PidConfig::isa(*kp, *ti, 0.0, ts)).unwrap())
        .collect();
    let refs: Vec<&dyn LoopController<f64>> = loops.iter().map(|p| p as _).collect();
    SampledLoop::new(m, ts, &refs, None)
        .unwrap()
        .verdict()
        .stable
}

#[test]
fn the_verdict_agrees_with_the_closed_loop_poles_on_random_plants() {
    let mut rng = Rng(0x5151_5151_0bad_cafe);
    let ts = 1.0;
    let (mut checked, mut cases) = (0, 0);
    for n in [2, 2, 2, 3, 3] {
        for _ in 0..6 {
            cases += 1;
            let channels: Vec<Channel> = (0..n * n)
                .map(|idx| {
                    let diag = idx / n == idx % n;
                    let sign = if rng.uni() < 0.5 { -1.0 } else { 1.0 };
                    Channel {
                        k: sign
                            * if diag {
                                1.0 + 3.0 * rng.uni()
                            } else {
                                0.8 * rng.uni()
                            },
                        tau: 2.0 + 15.0 * rng.uni(),
                        d: (rng.uni() * 7.0) as usize,
                    }
                })
                .collect();
            let m = matrix(&channels, n, ts);
            let base: Vec<(f64, f64)> = (0..n)
                .map(|i| {
                    let c = channels[i * n + i];
                    (0.5 / c.k, c.tau)
                })
                .collect();
            let scaled = |s: f64| base.iter().map(|(k, t)| (k * s, *t)).collect::<Vec<_>>();
            let rho = |s: f64| radius(&channels, n, &scaled(s), ts);
            // every case: the verdict at the nominal gains
            assert_eq!(
                verdict(&m, &scaled(1.0), ts),
                Some(rho(1.0) < 1.0),
                "{m} ρ = {}",
                rho(1.0)
            );
            // the critical scaling, where one exists in (0.01, 100)
            let (mut lo, mut hi) = (0.01f64, 100.0f64);
            if !(rho(lo) < 1.0 && rho(hi) > 1.0) {
                continue;
            }
            for _ in 0..60 {
                let mid = (lo * hi).sqrt();
                if rho(mid) < 1.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            // a non-monotone stability region: check only where both sides agree
            if rho(0.85 * lo) >= 1.0 || rho(1.15 * hi) <= 1.0 {
                continue;
            }
            assert_eq!(
                verdict(&m, &scaled(0.85 * lo), ts),
                Some(true),
                "{m} at {lo}"
            );
            assert_eq!(
                verdict(&m, &scaled(1.15 * hi), ts),
                Some(false),
                "{m} at {hi}"
            );
            checked += 1;
        }
    }
    assert!(
        checked >= cases / 2,
        "{checked} of {cases} cases had a critical gain"
    );
}

/// The inverted decoupler on random plants whose elements are all
/// realizable (each off-diagonal dead time at least its row's diagonal
/// one; fractions of a sample included): each output answers its own set
/// point only — a step in one loop moves no other output (to rounding) —
/// and each loop is the single-loop Smith predictor on its diagonal
/// channel, sample for sample.
#[test]
fn the_decoupled_loops_are_independent_on_realizable_plants() {
    let mut rng = Rng(0xdec0_0b1e_d00d_f00d);
    let ts = 0.5;
    for n in [2, 2, 3, 3, 4] {
        let theta_ii: Vec<f64> = (0..n).map(|_| 0.5 + 3.0 * rng.uni()).collect();
        let rows: Vec<Vec<TransferFunction>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let (k, tau) = if i == j {
                            (1.0 + 2.0 * rng.uni(), 2.0 + 10.0 * rng.uni())
                        } else {
                            (0.6 * (rng.uni() - 0.5), 2.0 + 10.0 * rng.uni())
                        };
                        // whole samples or a fraction below one half (a
                        // fraction above it puts a zero of g_ii(z) outside)
                        let theta = if i == j {
                            (theta_ii[i] / ts).round() * ts + 0.4 * ts * rng.uni()
                        } else {
                            theta_ii[i] + 4.0 * rng.uni()
                        };
                        TransferFunction::new(&[k], &[tau, 1.0], theta).unwrap()
                    })
                    .collect()
            })
            .collect();
        let m = TransferMatrix::new(rows).unwrap();
        let d = design(&m, "decoupled", None, ts).unwrap();
        for e in &d.decoupler {
            assert_eq!(e.realization, Realization::Exact, "{m}: {}", e.describe());
        }
        let (v, dv, _) = analyse(&m, &d).unwrap();
        assert_eq!(v.stable, Some(true), "{m}: {}", v.reason);
        assert_eq!(dv.unwrap().stable, Some(true), "{m}");
        let duration = 120.0;
        for step in 0..n {
            let mut sps = vec![Vec::new(); n];
            sps[step] = vec![SetpointStep {
                value: 1.0,
                at: 0.0,
            }];
            let mut c = controller(&m, &d).unwrap();
            let run = simulate_mimo(&m, &mut *c, &sps, &Default::default(), ts, duration).unwrap();
            for i in (0..n).filter(|i| *i != step) {
                let worst = run.y[i].iter().fold(0.0f64, |a, v| a.max(v.abs()));
                assert!(
                    worst < 1e-9,
                    "{m}: output {i} moved by {worst} for a step in {step}"
                );
            }
            // loop `step` alone: the registry's Smith predictor on its channel
            let g = m.get(step, step).unwrap().clone();
            let single = msp::study::Scenario {
                plant: Some(g),
                controller: Some("smith".into()),
                set: d.loops[step]
                    .iter()
                    .map(|(k, v)| (k.to_string(), v))
                    .collect(),
                setpoint: sps[step].clone(),
                ts: Some(ts),
                duration: Some(duration),
                ..Default::default()
            }
            .run()
            .unwrap()
            .result;
            let k = run.y[step].len().min(single.y.len());
            for t in 0..k {
                assert!(
                    (run.y[step][t] - single.y[t]).abs() < 1e-9,
                    "{m}: loop {step} at sample {t}: {} vs {}",
                    run.y[step][t],
                    single.y[t]
                );
            }
        }
    }
}

/// Where an element cannot be realized, the design says so and what it
/// does: an off-diagonal channel that answers sooner than the diagonal one
/// loses its advance; a diagonal channel with a right-half-plane zero
/// leaves its row's elements static; a plant whose `det G` has a zero in
/// the right half-plane makes the decoupler's own loop unstable, and the
/// scheme is refused with the reason.
#[test]
fn an_unrealizable_decoupler_says_why_and_what_is_done() {
    let ts = 1.0;
    let early = TransferMatrix::new(vec![
        vec![tf("2e^-4s/(5s+1)"), tf("0.5e^-1s/(4s+1)")],
        vec![tf("0.3e^-5s/(6s+1)"), tf("1.5e^-2s/(3s+1)")],
    ])
    .unwrap();
    let d = design(&early, "decoupled", None, ts).unwrap();
    assert_eq!(
        d.decoupler[0].realization,
        Realization::WithoutAdvance { samples: 3 }
    );
    assert!(
        d.decoupler[0].describe().contains("θ12 < θ11"),
        "{}",
        d.decoupler[0].describe()
    );
    assert_eq!(d.decoupler[1].realization, Realization::Exact);
    // a step in loop 2 disturbs output 1 only for the advance's samples
    // and then the residual those samples left
    let (v, _, _) = analyse(&early, &d).unwrap();
    assert_eq!(v.stable, Some(true), "{}", v.reason);

    let rhp = TransferMatrix::new(vec![
        vec![tf("2(1-3s)e^-1s/((5s+1)(2s+1))"), tf("0.5e^-2s/(4s+1)")],
        vec![tf("0.3e^-3s/(6s+1)"), tf("1.5e^-1s/(3s+1)")],
    ])
    .unwrap();
    let d = design(&rhp, "decoupled", None, ts).unwrap();
    match &d.decoupler[0].realization {
        Realization::Static { reason } => assert!(reason.contains("outside the unit circle")),
        r => panic!("{r:?}"),
    }
    assert!((d.decoupler[0].num[0] - 0.5 / 2.0).abs() < 1e-12);

    // det G(0) = 1 − 4 < 0 while det G(s) > 0 for large real s: a real
    // transmission zero in the right half-plane
    let zero = TransferMatrix::new(vec![
        vec![tf("1e^-1s/(s+1)"), tf("2e^-1s/(3s+1)")],
        vec![tf("2e^-1s/(3s+1)"), tf("1e^-1s/(s+1)")],
    ])
    .unwrap();
    let e = design(&zero, "decoupled", None, ts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("decoupler's own loop is unstable"), "{e}");
}

/// The trait's slices: a `Decentralized` of `[Pid; 2]` (firmware's form)
/// and of a `Vec` give the same inputs.
#[test]
fn decentralized_over_an_array_and_a_vec_agree() {
    let cfg = |kp: f64| PidConfig::isa(kp, 5.0, 0.0, 0.5);
    let mut a = Decentralized::new([Pid::new(cfg(1.0)).unwrap(), Pid::new(cfg(-0.5)).unwrap()]);
    let mut v = Decentralized::new(vec![
        Pid::new(cfg(1.0)).unwrap(),
        Pid::new(cfg(-0.5)).unwrap(),
    ]);
    let (mut ua, mut uv) = ([0.0; 2], [0.0; 2]);
    for k in 0..50 {
        let y = [0.01 * k as f64, -0.02 * k as f64];
        a.update(&[1.0, 2.0], &y, &mut ua);
        v.update(&[1.0, 2.0], &y, &mut uv);
        assert_eq!(ua, uv);
    }
    assert_eq!(MultiController::<f64>::loops(&a), 2);
}

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
