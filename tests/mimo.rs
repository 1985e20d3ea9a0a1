//! Multivariable analysis (#51): the Wood–Berry column's published
//! relative gain (Bristol's λ11 = 2.01) and BLT tuning (Luyben (1986):
//! F = 2.55, Kc = 0.375 and −0.075, τI = 8.29 and 23.6 min), and the
//! identities the measures obey on random plants.
use msp::analysis::mimo::{
    biggest_log_modulus, blt, det, inverse, niederlinski, pairing, rga, rga_at, PiLoop,
    TransferMatrix,
};
use msp::complex::Complex;
use msp::poly::TransferFunction;

fn tf(s: &str) -> TransferFunction {
    s.parse().unwrap()
}

/// A channel without coupling.
fn zero() -> TransferFunction {
    TransferFunction::new(&[0.0], &[1.0], 0.0).unwrap()
}

/// Wood & Berry (1973), time in minutes.
fn wood_berry() -> TransferMatrix {
    TransferMatrix::new(vec![
        vec![tf("12.8e^-1s/(16.7s+1)"), tf("-18.9e^-3s/(21s+1)")],
        vec![tf("6.6e^-7s/(10.9s+1)"), tf("-19.4e^-3s/(14.4s+1)")],
    ])
    .unwrap()
}

/// The steady-state RGA: `λ11 = 1/(1 − g12·g21/(g11·g22))` = 2.01 (the
/// 2×2 closed form), rows and columns summing to 1; the pairing is the
/// diagonal; the Niederlinski index of a 2×2 is `1/λ11`.
#[test]
fn wood_berrys_rga_and_niederlinski_index() {
    let m = wood_berry();
    let l = rga(&m).unwrap();
    let closed = 1.0 / (1.0 - (-18.9 * 6.6) / (12.8 * -19.4));
    assert!((l[0] - closed).abs() < 1e-12, "{l:?}");
    assert_eq!((l[0] * 100.0).round() / 100.0, 2.01);
    assert!((l[0] + l[1] - 1.0).abs() < 1e-12 && (l[0] + l[2] - 1.0).abs() < 1e-12);
    assert_eq!(pairing(&l, 2), Some(vec![0, 1]));
    let ni = niederlinski(&m).unwrap();
    assert!((ni - 1.0 / closed).abs() < 1e-12, "{ni}");
}

/// Luyben's (1986) Wood–Berry BLT: the ZN settings of each loop alone and
/// the detuning factor that brings the biggest log modulus to 4 dB, to the
/// digits published. The printed F = 2.55 is the one figure that is not
/// the others' rounding: the printed τI1 = 8.29 over loop 1's ZN τI
/// (3.2562) pins F to [2.5444, 2.5474], which the printed Kc1 = 0.375
/// confirms ([2.541, 2.548]); F = 2.55 itself would print τI1 = 8.30 and
/// Kc1 = 0.374. msp's F lies in that interval, within 0.006 of 2.55.
#[test]
fn luybens_blt_tuning_of_wood_berry() {
    let b = blt(&wood_berry(), None).unwrap();
    let r = |x: f64, d: i32| (x * 10f64.powi(d)).round() / 10f64.powi(d);
    let zn_ti = b.alone[0].ti;
    assert!(b.f >= 8.285 / zn_ti && b.f < 8.295 / zn_ti, "{b:?}");
    assert!((b.f - 2.55).abs() < 0.006, "{b:?}");
    assert_eq!(
        (r(b.loops[0].kp, 3), r(b.loops[1].kp, 3)),
        (0.375, -0.075),
        "{b:?}"
    );
    assert_eq!(
        (r(b.loops[0].ti, 2), r(b.loops[1].ti, 1)),
        (8.29, 23.6),
        "{b:?}"
    );
    assert!((b.lcm - 4.0).abs() < 1e-6, "{b:?}");
}

/// On random 2×2 to 4×4 matrices: the determinant and the inverse agree
/// (`G·G⁻¹ = I`, `det G⁻¹ = 1/det G`, det of a triangular matrix the
/// product of its diagonal), every row and column of the RGA sums to 1, a
/// diagonal plant's RGA is the identity, and the biggest log modulus of
/// decentralized loops on a diagonal plant is that of the worst loop alone
/// (`W = Π(1 + gᵢcᵢ) − 1`: computed here in the test).
#[test]
fn identities_on_random_matrices() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut uni = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for n in 2..=4 {
        for _ in 0..50 {
            let a: Vec<Complex<f64>> = (0..n * n).map(|_| Complex::new(uni(), uni())).collect();
            let inv = inverse(&a, n).unwrap();
            for i in 0..n {
                for j in 0..n {
                    let s =
                        (0..n).fold(Complex::real(0.0), |s, k| s + a[i * n + k] * inv[k * n + j]);
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((s - Complex::real(want)).abs() < 1e-9, "{n} {i} {j}");
                }
            }
            let (d, di) = (det(&a, n), det(&inv, n));
            assert!((d * di - Complex::real(1.0)).abs() < 1e-9);
            let l = msp::analysis::mimo::rga_of(&a, n).unwrap();
            for i in 0..n {
                let row = (0..n).fold(Complex::real(0.0), |s, j| s + l[i * n + j]);
                let col = (0..n).fold(Complex::real(0.0), |s, j| s + l[j * n + i]);
                assert!((row - Complex::real(1.0)).abs() < 1e-9);
                assert!((col - Complex::real(1.0)).abs() < 1e-9);
            }
            let mut tri = a.clone();
            for i in 0..n {
                for j in 0..i {
                    tri[i * n + j] = Complex::real(0.0);
                }
            }
            let prod = (0..n).fold(Complex::real(1.0), |p, i| p * tri[i * n + i]);
            assert!((det(&tri, n) - prod).abs() < 1e-12 * (1.0 + prod.abs()));
        }
    }
    // a diagonal plant
    let diag = TransferMatrix::new(vec![
        vec![tf("2e^-1s/(4s+1)"), zero()],
        vec![zero(), tf("-1.5e^-2s/(6s+1)")],
    ])
    .unwrap();
    let l = rga_at(&diag, 0.3).unwrap();
    assert!((l[0] - Complex::real(1.0)).abs() < 1e-12 && l[1].abs() < 1e-12);
    let loops = [PiLoop { kp: 0.8, ti: 4.0 }, PiLoop { kp: -0.5, ti: 6.0 }];
    let by_hand = |w: f64| {
        let one = |g: &TransferFunction, l: &PiLoop| {
            let (re, im) = g.freq(w);
            let c = Complex::new(l.kp, -l.kp / (l.ti * w));
            Complex::real(1.0) + Complex::new(re, im) * c
        };
        let w_ = one(diag.get(0, 0).unwrap(), &loops[0]) * one(diag.get(1, 1).unwrap(), &loops[1])
            - Complex::real(1.0);
        20.0 * (w_ / (w_ + Complex::real(1.0))).abs().log10()
    };
    let peak = (0..20000)
        .map(|k| by_hand(1e-3 * 1.0005f64.powi(k)))
        .fold(f64::NEG_INFINITY, f64::max);
    let ours = biggest_log_modulus(&diag, &loops);
    assert!(ours >= peak - 1e-6 && ours - peak < 1e-3, "{ours} {peak}");
}

/// The decentralized closed loop (`msp::sim::simulate_mimo` of
/// `msp::mimo::Decentralized`; on diagonal plants it is the single loops'
/// runs, `tests/mimo_loops.rs`): on a
/// coupled 2×2 of first-order lags with whole-sample dead times, the same
/// samples as the difference equations written here (`y ← a·y + K(1 − a)·u`
/// per channel, the PI `u = kp·e + I`, `I ← I + kp·Ts/Ti·e`), and the
/// interaction of a step in loop 1 shows in output 2.
#[test]
fn the_decentralized_loop_is_the_difference_equations() {
    use msp::mimo::Decentralized;
    use msp::sim::{simulate_mimo, MimoRun, SetpointStep};
    use msp::{Pid, PidConfig};
    let ts = 0.1;
    // the PI loops `gains` on `plant`, sampled every `ts`
    let closed = |plant: &TransferMatrix,
                  gains: &[(f64, f64)],
                  sps: &[Vec<SetpointStep>],
                  t: f64|
     -> MimoRun {
        let pids: Vec<Pid<f64>> = gains
            .iter()
            .map(|(kp, ti)| Pid::new(PidConfig::isa(*kp, *ti, 0.0, ts)).unwrap())
            .collect();
        simulate_mimo(
            plant,
            &mut Decentralized::new(pids),
            sps,
            &Default::default(),
            ts,
            t,
        )
        .unwrap()
    };
    let step = |at: f64, value: f64| vec![SetpointStep { value, at }];
    // coupled, whole-sample delays: the difference equations
    let coupled = TransferMatrix::new(vec![
        vec![tf("1.2e^-0.3s/(2s+1)"), tf("0.4e^-0.6s/(3s+1)")],
        vec![tf("-0.5e^-0.5s/(1.5s+1)"), tf("0.9e^-0.2s/(2.5s+1)")],
    ])
    .unwrap();
    let (k, tau, d) = (
        [1.2, 0.4, -0.5, 0.9],
        [2.0, 3.0, 1.5, 2.5],
        [3usize, 6, 5, 2],
    );
    let gains = [(0.9, 2.0), (1.1, 2.5)];
    let sps = [step(0.5, 1.0), Vec::new()];
    let run = closed(&coupled, &gains, &sps, 30.0);
    let mut x = [0.0f64; 4];
    let mut hist: Vec<[f64; 2]> = vec![[0.0; 2]; 10];
    let mut integral = [0.0f64; 2];
    for s in 0..300 {
        let t = s as f64 * ts;
        let y = [x[0] + x[1], x[2] + x[3]];
        let r = [if t >= 0.5 - 1e-9 { 1.0 } else { 0.0 }, 0.0];
        let mut u = [0.0; 2];
        for i in 0..2 {
            let e = r[i] - y[i];
            u[i] = gains[i].0 * e + integral[i];
            integral[i] += gains[i].0 * ts / gains[i].1 * e;
            assert!((run.y[i][s] - y[i]).abs() < 1e-12, "output {i} sample {s}");
            assert!((run.u[i][s] - u[i]).abs() < 1e-12, "input {i} sample {s}");
        }
        hist.insert(0, u);
        hist.truncate(10);
        for c in 0..4 {
            let a = (-ts / tau[c]).exp();
            let late = hist.get(d[c]).map_or(0.0, |h| h[c % 2]);
            x[c] = a * x[c] + k[c] * (1.0 - a) * late;
        }
    }
    let inter = run.interaction(0.5, 40.0);
    assert!(inter[1] > 0.05, "{inter:?}");
}

/// The pairing and BLT on families, not one column: on random 2×2 to 4×4
/// plants of first-order lags with dead times, whose strong channels are a
/// random permutation of the inputs, the pairing found is that permutation;
/// on random 2×2 plants paired on the diagonal, the BLT loops reach a
/// biggest log modulus of 4 dB by the 2×2 closed form `W = (1 + g11c1)(1 +
/// g22c2) − g12g21c1c2 − 1` evaluated here on a dense grid.
#[test]
fn pairing_and_blt_on_random_plants() {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut uni = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let lag =
        |k: f64, tau: f64, theta: f64| TransferFunction::new(&[k], &[tau, 1.0], theta).unwrap();
    for n in 2..=4 {
        for _ in 0..10 {
            // a random permutation (Fisher–Yates)
            let mut perm: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                let j = (uni() * (i + 1) as f64) as usize;
                perm.swap(i, j.min(i));
            }
            let rows: Vec<Vec<TransferFunction>> = (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            let k = if perm[i] == j {
                                2.0 + 3.0 * uni()
                            } else {
                                0.3 * (uni() - 0.5)
                            };
                            lag(k, 1.0 + 9.0 * uni(), 0.5 + 3.0 * uni())
                        })
                        .collect()
                })
                .collect();
            let m = TransferMatrix::new(rows).unwrap();
            assert_eq!(pairing(&rga(&m).unwrap(), n), Some(perm.clone()), "{m}");
        }
    }
    for _ in 0..8 {
        let g = [
            lag(1.0 + 4.0 * uni(), 2.0 + 10.0 * uni(), 0.5 + 2.0 * uni()),
            lag(2.0 * (uni() - 0.5), 2.0 + 10.0 * uni(), 1.0 + 4.0 * uni()),
            lag(2.0 * (uni() - 0.5), 2.0 + 10.0 * uni(), 1.0 + 4.0 * uni()),
            lag(-(1.0 + 4.0 * uni()), 2.0 + 10.0 * uni(), 0.5 + 2.0 * uni()),
        ];
        let m = TransferMatrix::new(vec![
            vec![g[0].clone(), g[1].clone()],
            vec![g[2].clone(), g[3].clone()],
        ])
        .unwrap();
        let b = blt(&m, None).unwrap();
        assert!(b.f >= 1.0 && b.loops[1].kp < 0.0, "{b:?}");
        let lc = |w: f64| {
            let c = |l: &PiLoop| Complex::new(l.kp, -l.kp / (l.ti * w));
            let r = |t: &TransferFunction| {
                let (re, im) = t.freq(w);
                Complex::new(re, im)
            };
            let (c1, c2) = (c(&b.loops[0]), c(&b.loops[1]));
            let one = Complex::real(1.0);
            let w_ =
                (one + r(&g[0]) * c1) * (one + r(&g[3]) * c2) - r(&g[1]) * r(&g[2]) * c1 * c2 - one;
            20.0 * (w_ / (w_ + one)).abs().log10()
        };
        let peak = (0..40000)
            .map(|k| lc(1e-4 * 1.0004f64.powi(k)))
            .fold(f64::NEG_INFINITY, f64::max);
        if b.f > 1.0 {
            assert!((peak - 4.0).abs() < 0.01, "{peak} {b:?}");
        } else {
            assert!(peak <= 4.0 + 0.01, "{peak} {b:?}");
        }
    }
}

/// Per-loop SIMC settings with BLT's detuning (#51 item 3): each loop alone
/// is `msp::tuning::simc` of its diagonal channel with `τc = θ`; the common
/// factor brings the biggest log modulus to `2n` dB (or is 1 where the
/// loops alone are already there), and the loops are those settings over
/// `F` (`Kc/F`, `τI·F`).
#[test]
fn simc_loops_detuned_together() {
    use msp::analysis::mimo::{detune, loops_alone, LoopRule};
    use msp::{tuning, Fopdt, ProcessModel};
    let m = wood_berry();
    let alone = loops_alone(&m, LoopRule::Simc).unwrap();
    for (i, (k, tau, theta)) in [(12.8, 16.7, 1.0), (-19.4, 14.4, 3.0)]
        .into_iter()
        .enumerate()
    {
        let g = tuning::simc(
            &ProcessModel::from(Fopdt::new(k, tau, theta).unwrap()),
            theta,
        )
        .unwrap();
        assert!((alone[i].kp - g.kp).abs() < 1e-12 && (alone[i].ti - g.ti).abs() < 1e-12);
    }
    let b = detune(&m, alone.clone(), None).unwrap();
    assert!(b.f > 1.0, "{}", b.f);
    assert!((b.lcm - 4.0).abs() < 1e-6, "{}", b.lcm);
    for (l, a) in b.loops.iter().zip(&alone) {
        assert!((l.kp * b.f - a.kp).abs() < 1e-12 && (l.ti / b.f - a.ti).abs() < 1e-9);
    }
    // looser target: the loops alone already meet it, F = 1
    let loose = detune(&m, alone.clone(), Some(40.0)).unwrap();
    assert_eq!(loose.f, 1.0);
    assert!(LoopRule::from_name("amigo").is_err());
}

/// The RGA over frequency: at each point the rows and columns of `Λ(jω)`
/// sum to 1 (complex), its magnitudes are those of `rga_at`, and at the
/// lowest frequency it is the steady-state RGA to within 1 %.
#[test]
fn the_rga_over_frequency() {
    use msp::analysis::mimo::rga_over;
    let m = wood_berry();
    let pts = rga_over(&m, 12).unwrap();
    assert_eq!(pts.len(), 12);
    let ss = rga(&m).unwrap();
    assert!((pts[0].magnitude[0][0] - ss[0]).abs() < 0.01 * ss[0]);
    for p in &pts {
        let l = rga_at(&m, p.w).unwrap();
        for i in 0..2 {
            let row = l[2 * i] + l[2 * i + 1];
            let col = l[i] + l[2 + i];
            assert!(
                (row - Complex::real(1.0)).abs() < 1e-12
                    && (col - Complex::real(1.0)).abs() < 1e-12
            );
            for j in 0..2 {
                assert!((p.magnitude[i][j] - l[2 * i + j].abs()).abs() < 1e-15);
            }
        }
    }
    assert!(pts.windows(2).all(|w| w[1].w > w[0].w));
}
