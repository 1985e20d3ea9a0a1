//! ZOH discretization against closed-form step responses at the sample instants.
mod common;
use common::assert_close;
use msp::{Discretization, Lti};

fn step(mut b: Lti<f64, 4>, n: usize) -> Vec<f64> {
    (0..n).map(|_| b.step(1.0)).collect()
}

#[test]
fn first_order() {
    let (k, tau, h) = (2.5, 3.0, 0.1);
    let y = step(Lti::first_order(k, tau, h).unwrap(), 500);
    for (i, yi) in y.iter().enumerate() {
        assert_close(*yi, k * (1.0 - (-(i as f64) * h / tau).exp()), 1e-12, 1e-13);
    }
}

#[test]
fn unstable_first_order() {
    // 1/(2s − 1): y = e^{t/2} − 1
    let h = 0.05;
    let b = Lti::from_tf(&[1.0], &[2.0, -1.0], h, Discretization::Zoh).unwrap();
    for (i, yi) in step(b, 200).iter().enumerate() {
        let t = i as f64 * h;
        assert_close(*yi, (t / 2.0).exp() - 1.0, 1e-11, 1e-12);
    }
}

#[test]
fn integrator() {
    let b = Lti::integrator(0.2, 0.074).unwrap();
    for (i, yi) in step(b, 300).iter().enumerate() {
        assert_close(*yi, 0.2 * i as f64 * 0.074, 1e-12, 1e-14);
    }
}

#[test]
fn second_order_underdamped() {
    let (wn, z, h) = (2.0, 0.3, 0.02);
    let wd = wn * (1.0f64 - z * z).sqrt();
    let phi = z.acos();
    let b = Lti::second_order(1.0, wn, z, h).unwrap();
    for (i, yi) in step(b, 1000).iter().enumerate() {
        let t = i as f64 * h;
        let e = 1.0 - (-z * wn * t).exp() * (wd * t + phi).sin() / (1.0 - z * z).sqrt();
        assert_close(*yi, e, 1e-10, 1e-11);
    }
}

#[test]
fn sopdt_two_real_poles() {
    // 1/((17s+1)(6s+1)): y = 1 − (17 e^{−t/17} − 6 e^{−t/6})/11
    let h = 0.5;
    let b = Lti::from_tf(&[1.0], &[102.0, 23.0, 1.0], h, Discretization::Zoh).unwrap();
    for (i, yi) in step(b, 400).iter().enumerate() {
        let t = i as f64 * h;
        let e = 1.0 - (17.0 * (-t / 17.0).exp() - 6.0 * (-t / 6.0).exp()) / 11.0;
        assert_close(*yi, e, 1e-11, 1e-12);
    }
}

#[test]
fn tustin_and_matched_keep_dc_gain() {
    for m in [Discretization::Tustin, Discretization::Matched] {
        let b: Lti<f64, 4> = Lti::from_tf(&[3.0, 1.0], &[2.0, 3.0, 1.0], 0.1, m).unwrap();
        assert_close(b.dc_gain().unwrap(), 1.0, 1e-9, 0.0);
    }
    // matched: pole 1/(τs+1) → z = e^{−h/τ}
    let b: Lti<f64, 1> = Lti::from_tf(&[1.0], &[4.0, 1.0], 0.2, Discretization::Matched).unwrap();
    let z = Lti::<f64, 1>::first_order(1.0, 4.0, 0.2).unwrap();
    let (mut a, mut c) = (b, z);
    for _ in 0..50 {
        assert_close(a.step(1.0), c.step(1.0), 1e-12, 1e-12);
    }
}

/// The companion-matrix roots against polynomials built from known roots:
/// simple roots to rounding, a triple root to the `ε^{1/3}` a perturbation
/// of a triple root allows, and degrees on both sides of the size switch (4/16).
#[test]
fn polynomial_roots_are_the_companion_eigenvalues() {
    use msp::poly::{mul, poly_roots};
    fn from_roots(rs: &[(f64, f64)]) -> Vec<f64> {
        let mut p = vec![1.0];
        for &(re, im) in rs {
            if im == 0.0 {
                p = mul(&p, &[1.0, -re]);
            } else if im > 0.0 {
                // the conjugate pair as one real quadratic
                p = mul(&p, &[1.0, -2.0 * re, re * re + im * im]);
            }
        }
        p
    }
    let check = |rs: &[(f64, f64)], tol: f64| {
        let p = from_roots(rs);
        let found = poly_roots(&p).unwrap();
        assert_eq!(found.len(), rs.len(), "{rs:?}");
        for r in rs {
            let nearest = found
                .iter()
                .map(|f| (f.0 - r.0).hypot(f.1 - r.1))
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < tol * (1.0 + r.0.hypot(r.1)), "{r:?} in {found:?}");
        }
    };
    check(
        &[(-1.0, 0.0), (-2.0, 0.0), (-1.0, 2.0), (-1.0, -2.0)],
        1e-12,
    );
    check(&[(0.0, 0.0), (-1.0 / 40.2, 0.0)], 1e-12);
    check(&[(0.5, 0.0), (-3.0, 0.0), (-0.1, 0.0)], 1e-12);
    check(&[(-1.0, 0.0); 3], 1e-4);
    let ten: Vec<(f64, f64)> = (1..=10).map(|k| (-f64::from(k) / 4.0, 0.0)).collect();
    check(&ten, 1e-6);
    // a constant has none; beyond degree 16 the companion matrix is on the heap
    assert!(poly_roots(&[3.0]).unwrap().is_empty());
    // the poles of an 18th-order Butterworth filter (well conditioned)
    let butterworth: Vec<(f64, f64)> = (0..18)
        .map(|k| {
            let phi = std::f64::consts::PI * (2.0 * f64::from(k) + 19.0) / 36.0;
            (phi.cos(), phi.sin())
        })
        .collect();
    // its coefficients reach ~1e4, so rounding them moves the roots by ~1e-9
    check(&butterworth, 1e-7);
    assert_eq!(
        "e^-2s/(s+1)^17"
            .parse::<msp::poly::TransferFunction>()
            .unwrap()
            .kind(),
        msp::poly::PlantKind::Stable
    );
}

/// `analysis::step_response` samples the continuous step response exactly
/// (ZOH of a step is the step): FOPDT and an underdamped pair with dead
/// time against their closed forms at every sample, and MATLAB's `stepinfo`
/// figures against theirs — FOPDT rise `τ ln 9`, settling `θ + τ ln 50`;
/// the pair's overshoot `exp(−πζ/√(1−ζ²))` and peak time `θ + π/ωd` (to a
/// sample: the peak is taken at the samples).
#[test]
fn open_loop_step_is_the_closed_form() {
    let (k, tau, theta) = (2.0, 5.0, 1.3);
    let s = msp::analysis::step_response(&"2*e^-1.3s/(5s+1)".parse().unwrap(), None, None).unwrap();
    assert_eq!(s.dc_gain, Some(k));
    assert_eq!(s.chosen, ["ts", "duration"]);
    for (t, y) in s.t.iter().zip(&s.y) {
        let exact = if *t <= theta {
            0.0
        } else {
            k * (1.0 - (-(t - theta) / tau).exp())
        };
        assert!((y - exact).abs() < 1e-12, "t = {t}: {y} vs {exact}");
    }
    // linear interpolation between samples: error below ts²/(8τ²) of the step
    let tol = (s.ts / tau).powi(2);
    assert!((s.info.rise_time - tau * 9f64.ln()).abs() < tau * tol + 1e-9);
    assert!((s.info.settling_time - theta - tau * 50f64.ln()).abs() < s.ts);
    assert!(s.info.overshoot.abs() < 1e-9);

    let (zeta, wn, theta) = (0.2f64, 1.0f64, 2.0);
    let s =
        msp::analysis::step_response(&"e^-2s/(s^2+0.4s+1)".parse().unwrap(), None, None).unwrap();
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    for (t, y) in s.t.iter().zip(&s.y) {
        let tt = t - theta;
        let exact = if tt <= 0.0 {
            0.0
        } else {
            1.0 - (-zeta * wn * tt).exp() * ((wd * tt).cos() + zeta * wn / wd * (wd * tt).sin())
        };
        assert!((y - exact).abs() < 1e-11, "t = {t}: {y} vs {exact}");
    }
    let os = 100.0 * (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    assert!(
        (s.info.overshoot - os).abs() < 1e-3 * os,
        "{}",
        s.info.overshoot
    );
    assert!((s.info.peak_time - theta - std::f64::consts::PI / wd).abs() <= s.ts);
    // the duration covers the ringing: settled within 2 % well before the end
    assert!(s.info.settling_time < 0.8 * s.duration);
    // an integrator has no final value and no step information
    let s =
        msp::analysis::step_response(&"0.2/s*e^-7.4s".parse().unwrap(), None, Some(20.0)).unwrap();
    assert_eq!(s.dc_gain, None);
    assert!(s.info.rise_time.is_nan());
    assert!((s.y.last().unwrap() - 0.2 * (20.0 - 7.4)).abs() < 1e-9);
}

/// The simulator's plant with a dead time of a fraction of a sample
/// (13.7 samples) against the closed form of its step response
/// `K(1 − e^{−(t − θ)/τ})` for `t ≥ θ`, and a held staircase input against
/// the superposition of such steps: the sampled loop sees the fraction exactly.
#[test]
fn a_fractional_dead_time_is_exact() {
    let (k, tau, theta, ts) = (2.0f64, 5.0, 1.37, 0.1);
    let plant: msp::poly::TransferFunction = "2*e^-1.37s/(5s+1)".parse().unwrap();
    let step = |t: f64| {
        if t >= theta {
            k * (1.0 - (-(t - theta) / tau).exp())
        } else {
            0.0
        }
    };
    let u: Vec<f64> = (0..400).map(|i| if i < 150 { 1.0 } else { -0.5 }).collect();
    let y = msp::sim::open_loop(&plant, ts, &u).unwrap();
    for (i, yi) in y.iter().enumerate() {
        let t = i as f64 * ts;
        // 1 from 0 s, then −1.5 more from 15 s
        let want = step(t) - 1.5 * step(t - 15.0);
        assert!((yi - want).abs() < 1e-12, "t = {t}: {yi} vs {want}");
    }
}

/// The closed forms of `Lti::first_order` and `Lti::integrator` are the
/// matrix exponential's block (`from_tf`, the same realization), coefficient
/// by coefficient, over lags from a hundredth of the period to 10⁵ periods,
/// either sign; and in `f32` the block `from_tf_of` rounds from `f64`.
#[test]
fn closed_forms_are_the_matrix_exponentials_block() {
    let coeffs = |b: &Lti<f64, 2>| (b.phi_entry(0, 0), b.input_vector()[0], b.output_vector()[0]);
    for &h in &[0.001, 0.05, 1.0] {
        for &r in &[0.01, 0.3, 1.0, 7.0, 1e3, 1e5] {
            for &(k, sign) in &[(2.5, 1.0), (-0.4, 1.0), (1.0, -1.0)] {
                let tau = sign * r * h;
                let closed = Lti::<f64, 2>::first_order(k, tau, h).unwrap();
                let expm =
                    Lti::<f64, 2>::from_tf(&[k], &[tau, 1.0], h, Discretization::Zoh).unwrap();
                let (a, b) = (coeffs(&closed), coeffs(&expm));
                // scaling and squaring's rounding grows with |A|·h = 1/r
                let tol = 1e-15 * (1.0 + 1.0 / r);
                assert_close(a.0, b.0, tol, 0.0);
                assert_close(a.1, b.1, tol, 0.0);
                assert_close(a.2, b.2, 1e-15, 0.0);
                assert_eq!(closed.order(), expm.order());
                let narrow = Lti::<f32, 2>::first_order(k as f32, tau as f32, h as f32);
                let rounded = Lti::<f32, 2>::from_tf_of(&[k], &[tau, 1.0], h, Discretization::Zoh);
                // e^{100} is beyond f32: both refuse it
                assert_eq!(narrow.is_ok(), rounded.is_ok(), "{tau} {h}");
                let (Ok(narrow), Ok(rounded)) = (narrow, rounded) else {
                    continue;
                };
                for (x, y) in [
                    (narrow.phi_entry(0, 0), rounded.phi_entry(0, 0)),
                    (narrow.input_vector()[0], rounded.input_vector()[0]),
                    (narrow.output_vector()[0], rounded.output_vector()[0]),
                ] {
                    assert_close(
                        f64::from(x),
                        f64::from(y),
                        4.0 * f64::from(f32::EPSILON),
                        0.0,
                    );
                }
            }
        }
        let closed = Lti::<f64, 2>::integrator(0.2, h).unwrap();
        let expm = Lti::<f64, 2>::from_tf(&[0.2], &[1.0, 0.0], h, Discretization::Zoh).unwrap();
        assert_eq!(coeffs(&closed), coeffs(&expm));
    }
    // their equilibrium in their own precision: the gain k (1/(1 − φ)·γ·k/τ),
    // none for an integrator
    for &(k, tau, h) in &[(2.5, 3.0, 0.1), (-0.4, 1e3, 0.01), (1.0, 0.02, 1.0)] {
        let wide = Lti::<f64, 2>::first_order(k, tau, h).unwrap();
        assert_close(wide.dc_gain().unwrap(), k, 1e-12, 0.0);
        let narrow = Lti::<f32, 2>::first_order(k as f32, tau as f32, h as f32).unwrap();
        // f32's φ near 1 is off by up to an ulp (ε/2): 1 − φ, and the gain,
        // by ε/2 over 1 − φ ≈ Ts/τ
        let tol = f64::from(f32::EPSILON) * (1.0 + tau.abs() / h);
        assert_close(f64::from(narrow.dc_gain().unwrap()), k, tol, 0.0);
    }
    assert!(Lti::<f64, 2>::integrator(0.2, 0.1)
        .unwrap()
        .dc_gain()
        .is_err());
    assert!(Lti::<f64, 0>::first_order(1.0, 1.0, 0.1).is_err());
    assert!(Lti::<f64, 1>::first_order(1.0, 0.0, 0.1).is_err());
    assert!(Lti::<f64, 1>::integrator(1.0, 0.0).is_err());
}

/// The lead-lag `k(as + 1)/(bs + 1)` in closed form is the block the
/// matrix exponential gives for the same transfer function, coefficient by
/// coefficient and its feedthrough, for a lead, a lag, a zero in the right
/// half-plane and a zero on the pole (a gain), in f64 and f32; and the same
/// frequency response.
#[test]
fn lead_lag_in_closed_form_is_the_matrix_exponentials_block() {
    let coeffs = |b: &Lti<f64, 2>| {
        (
            b.phi_entry(0, 0),
            b.input_vector()[0],
            b.output_vector()[0],
            b.feedthrough(),
        )
    };
    for &h in &[0.001, 0.05, 1.0] {
        for &r in &[0.01, 0.3, 1.0, 7.0, 1e3, 1e5] {
            let b = r * h;
            for &(k, ratio) in &[
                (2.5, 11.0),
                (-0.4, 0.1),
                (1.0, -3.0),
                (0.7, 1.0),
                (1.3, 0.0),
            ] {
                let a = ratio * b;
                let closed = Lti::<f64, 2>::lead_lag(k, a, b, h).unwrap();
                let expm =
                    Lti::<f64, 2>::from_tf(&[k * a, k], &[b, 1.0], h, Discretization::Zoh).unwrap();
                let (x, y) = (coeffs(&closed), coeffs(&expm));
                // scaling and squaring's rounding grows with |A|·h = 1/r;
                // C = k(b − a)/b²: from the transfer function, k/b − (ka/b)/b,
                // to a few roundings of its terms (the closed form has none of
                // their cancellation: 0 where a = b)
                let tol = 1e-15 * (1.0 + 1.0 / r);
                let scale = k.abs() * (b + a.abs()) / (b * b);
                assert_close(x.0, y.0, tol, 0.0);
                assert_close(x.1, y.1, tol, 0.0);
                assert!(
                    (x.2 - y.2).abs() <= 4e-16 * scale,
                    "{k} {a} {b} {h}: {x:?} {y:?}"
                );
                assert_close(x.3, y.3, 1e-15, 0.0);
                // the same transfer function on the unit circle
                for w in [0.1, 1.0, 3.0] {
                    let (p, q) = (closed.response(w), expm.response(w));
                    assert!((p - q).abs() <= 1e-12 * (1.0 + q.abs()), "{w}: {p:?} {q:?}");
                }
                let narrow = Lti::<f32, 2>::lead_lag(k as f32, a as f32, b as f32, h as f32);
                let rounded =
                    Lti::<f32, 2>::from_tf_of(&[k * a, k], &[b, 1.0], h, Discretization::Zoh);
                assert_eq!(narrow.is_ok(), rounded.is_ok(), "{a} {b} {h}");
                let (Ok(narrow), Ok(rounded)) = (narrow, rounded) else {
                    continue;
                };
                let eps = 4.0 * f64::from(f32::EPSILON);
                assert_close(
                    f64::from(narrow.phi_entry(0, 0)),
                    f64::from(rounded.phi_entry(0, 0)),
                    eps,
                    0.0,
                );
                assert_close(
                    f64::from(narrow.input_vector()[0]),
                    f64::from(rounded.input_vector()[0]),
                    eps,
                    0.0,
                );
                assert!(
                    (f64::from(narrow.output_vector()[0]) - f64::from(rounded.output_vector()[0]))
                        .abs()
                        <= eps * scale
                );
                assert_close(
                    f64::from(narrow.feedthrough()),
                    f64::from(rounded.feedthrough()),
                    eps,
                    0.0,
                );
            }
        }
    }
    assert!(Lti::<f64, 1>::lead_lag(1.0, 1.0, 0.0, 0.1).is_err());
    assert!(Lti::<f64, 1>::lead_lag(1.0, 1.0, 1.0, 0.0).is_err());
    assert!(Lti::<f64, 1>::lead_lag(f64::NAN, 1.0, 1.0, 0.1).is_err());
    assert_eq!(
        Lti::<f64, 1>::lead_lag(3.0, 0.0, 0.0, 0.1)
            .unwrap()
            .feedthrough(),
        3.0
    );
}
