//! The sampled multivariable loop (#51): its stability verdict against the
//! closed-loop poles computed here independently, and the decoupled
//! compensator's decoupling and realizability (the runs: `mimo_runs.rs`).
//!
//! The poles: the state matrix of the sampled loop written out from its
//! parts — each channel `gᵢⱼ = Kᵢⱼe^{−dᵢⱼTs·s}/(τᵢⱼs + 1)` (whole-sample
//! dead times) as `xᵢⱼ ← aᵢⱼxᵢⱼ + Kᵢⱼ(1 − aᵢⱼ)uⱼ[k − dᵢⱼ]`, `yᵢ = Σⱼ xᵢⱼ`,
//! each input's past values as a shift register, msp's PI as
//! `uⱼ = kpⱼ·eⱼ + Iⱼ`, `Iⱼ ← Iⱼ + kpⱼTs/Tiⱼ·eⱼ` — and its eigenvalues
//! (nalgebra). The verdict (the generalized Nyquist criterion on
//! `det(diag(Dc) + diag(Nc)·G)`) must agree with the spectral radius at
//! gains 15 % below and above each loop's critical scaling.

use msp::analysis::mimo::{Realization, TransferMatrix};
use msp::mimo::{Decentralized, MultiController};
use msp::poly::TransferFunction;
use msp::sim::{simulate_mimo, SetpointStep};
use msp::study::mimo::{analyse, controller, design};
use msp::{Pid, PidConfig};
use nalgebra::DMatrix;

mod mimo_common;
use mimo_common::*;

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
