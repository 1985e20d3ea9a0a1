//! The continuous view (`msp margins --continuous`) of a plant alone or
//! behind a gain: its margins against python-control's own margin tests
//! (`control/tests/margin_test.py`, the cases and numbers of its fixtures,
//! tolerance 1.5e-3 as there), and its stability verdict — the continuous
//! characteristic equation with the exact delay — against truths computed
//! here: the roots of `D(s) + k·N(s)` for a loop without delay, and the
//! critical gains of loops with one, from their phase equations.
//!
//! Conventions where msp differs: python-control's `gm` of a loop that
//! is stable only above a gain (type 3) is msp's `gm_lower` (msp's `gm` is
//! the upper limit, infinite there); its `sm`, the least `|1 + L|`, is
//! msp's `1/ms`; a phase margin past 180° is reported as python-control
//! does, wrapped to (−180°, 180°] (2s/(s+1): −120°).

use msp::analysis::{Analysis, View};
use msp::study::Scenario;
use nalgebra::DMatrix;

fn analyze(plant: &str, k: f64) -> Analysis {
    let mut sc = Scenario {
        plant: Some(plant.parse().unwrap()),
        ..Default::default()
    };
    sc.set.insert("kp".into(), k);
    msp::study::analyze(&sc, View::Continuous, None).unwrap()
}

/// The largest real part of the roots of `p` (descending powers).
fn abscissa(p: &[f64]) -> f64 {
    let p: Vec<f64> = p.iter().copied().skip_while(|c| *c == 0.0).collect();
    let n = p.len() - 1;
    let m = DMatrix::from_fn(n, n, |i, j| {
        if i == 0 {
            -p[j + 1] / p[0]
        } else if i == j + 1 {
            1.0
        } else {
            0.0
        }
    });
    m.complex_eigenvalues()
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// `a + k·b`, aligned at the constant term.
fn plus(a: &[f64], b: &[f64], k: f64) -> Vec<f64> {
    let n = a.len().max(b.len());
    (0..n)
        .map(|i| {
            let at = |p: &[f64]| {
                (i + p.len())
                    .checked_sub(n)
                    .and_then(|j| p.get(j))
                    .copied()
                    .unwrap_or(0.0)
            };
            at(a) + k * at(b)
        })
        .collect()
}

/// `a·b`.
fn times(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a.is_infinite() && b.is_infinite() && a.signum() == b.signum()) || (a - b).abs() <= tol
}

/// A fixture: plant, gain, numerator, denominator, and python-control's
/// gm (msp's upper one), msp's gm_lower, pm, wcg, wcp.
type Case = (&'static str, f64, Vec<f64>, Vec<f64>, [f64; 5]);

/// python-control's margin fixtures without delay: msp's margins match its
/// numbers, and the verdict matches the closed-loop roots.
#[test]
fn python_controls_margin_cases() {
    let (inf, nan) = (f64::INFINITY, f64::NAN);
    let sys4_num = times(&[35.0, 3.5, 8.75], &[1.0]);
    let sys4_den = times(
        &times(&[100.0, 1.0], &[1.0, 0.22, 1.0]),
        &[0.01, 0.008, 1.0],
    );
    // (plant, gain, numerator, denominator, [gm, gm_lower, pm, wcg, wcp])
    #[rustfmt::skip]
    let cases: Vec<Case> = vec![
        ("(s+2)/(s^2+2s+3)", 1.0, vec![1.0, 2.0], vec![1.0, 2.0, 3.0], [inf, 0.0, inf, nan, nan]),
        ("1/(s^3+2s^2+3s+4)", 1.0, vec![1.0], vec![1.0, 2.0, 3.0, 4.0], [2.0, 0.0, inf, 1.7321, nan]),
        ("8.75(4s^2+0.4s+1)/((100s+1)(s^2+0.22s+1)(0.01s^2+0.008s+1))", 1.0, sys4_num, sys4_den, [2.2716, 0.0, 97.5941, 10.0053, 0.0850]),
        ("1/(1+s)", 1.0, vec![1.0], vec![1.0, 1.0], [inf, 0.0, inf, nan, nan]),
        ("3(10+s)/(2+s)", 1.0, vec![3.0, 30.0], vec![1.0, 2.0], [inf, 0.0, inf, nan, nan]),
        ("0.01(10-s)/((2+s)(1+s))", 1.0, vec![-0.01, 0.1], vec![1.0, 3.0, 2.0], [300.0, 0.0, inf, 5.6569, nan]),
        ("s/(s+1)", 2.0, vec![1.0, 0.0], vec![1.0, 1.0], [inf, 0.0, -120.0007, nan, 0.5774]),
        ("1/(s+1)^3", 0.8, vec![1.0], vec![1.0, 3.0, 3.0, 1.0], [10.0014, 0.0, inf, 1.7322, nan]),
        ("1/(s+1)^3", 2.0, vec![1.0], vec![1.0, 3.0, 3.0, 1.0], [4.0, 0.0, 67.6058, 1.7322, 0.7663]),
        ("(s+0.1)/(s(s+1))", 1.0, vec![1.0, 0.1], vec![1.0, 1.0, 0.0], [inf, 0.0, 144.9032, nan, 0.3162]),
        ("(s+0.1)/(s^2(s+1))", 1.0, vec![1.0, 0.1], vec![1.0, 1.0, 0.0, 0.0], [inf, 0.0, 44.4594, nan, 0.7907]),
        ("(s+0.1)^2/(s^3(s+1))", 1.0, vec![1.0, 0.2, 0.01], vec![1.0, 1.0, 0.0, 0.0, 0.0], [inf, 0.0626, 37.1748, 0.1119, 0.7951]),
    ];
    for (plant, k, num, den, [gm, gm_lower, pm, wcg, wcp]) in cases {
        let an = analyze(plant, k);
        let truth = abscissa(&plus(&den, &num, k)) < 0.0;
        assert_eq!(an.stable, Some(truth), "{plant} k {k}: {:?}", an.stability);
        assert!(
            an.stability.reason.contains("continuous"),
            "{}",
            an.stability.reason
        );
        let m = an.margins;
        // python-control's tolerance, relative where the number is large
        let tol = |x: f64| 1.5e-3 * x.abs().max(1.0);
        assert!(close(m.gm, gm, tol(gm)), "{plant}: gm {} for {gm}", m.gm);
        assert!(
            close(m.gm_lower, gm_lower, tol(gm_lower)),
            "{plant}: gm_lower {}",
            m.gm_lower
        );
        let pm_msp = if m.pm.is_finite() && m.pm > 180.0 {
            m.pm - 360.0
        } else {
            m.pm
        };
        assert!(close(pm_msp, pm, tol(pm)), "{plant}: pm {} for {pm}", m.pm);
        // the crossover of the limit python-control reports (type 3: the lower one)
        if wcg.is_finite() && gm.is_finite() {
            assert!(
                close(m.wcg, wcg, tol(wcg)),
                "{plant}: wcg {} for {wcg}",
                m.wcg
            );
        }
        if wcp.is_finite() {
            assert!(
                close(m.wcp, wcp, tol(wcp)),
                "{plant}: wcp {} for {wcp}",
                m.wcp
            );
        }
    }
    // 1/(s^3 + 2s^2 + 3s + 4): python-control's sm 0.4170 is msp's 1/ms
    let an = analyze("1/(s^3+2s^2+3s+4)", 1.0);
    assert!(
        (1.0 / an.margins.ms - 0.4170).abs() < 1.5e-3,
        "{}",
        an.margins.ms
    );
    // its state-space case, (s − 18)/(s² − 3s − 10): one closed-loop pole
    // at 1 + √29 in the right half plane (python-control still prints
    // margins for it; msp says unstable, with none)
    let an = analyze("(s-18)/(s^2-3s-10)", 1.0);
    assert_eq!(an.stable, Some(false), "{:?}", an.stability);
    assert_eq!(an.stability.unstable_poles, Some(1));
    assert_eq!(an.stability.open_loop_unstable_poles, Some(1));
}

/// Bavafi-Toosi's example 21 (python-control's tricky case, an unstable
/// open-loop pole at 0.0005): the verdict at gains 1, 1000 and 5000 against
/// the closed-loop roots.
#[test]
fn a_loop_with_a_slow_unstable_pole() {
    let num = times(
        &times(&[0.002, 0.002 * 0.02], &[1.0, 0.05]),
        &times(&[1.0, 5.0], &[1.0, 10.0]),
    );
    let den = times(
        &times(
            &times(&[1.0, -0.0005], &[1.0, 0.0001]),
            &times(&[1.0, 0.01], &[1.0, 0.2]),
        ),
        &times(&[1.0, 1.0], &times(&[1.0, 100.0], &[1.0, 100.0])),
    );
    let plant =
        "0.002(s+0.02)(s+0.05)(s+5)(s+10)/((s-0.0005)(s+0.0001)(s+0.01)(s+0.2)(s+1)(s+100)^2)";
    for k in [1.0, 1000.0, 5000.0] {
        let an = analyze(plant, k);
        let truth = abscissa(&plus(&den, &num, k)) < 0.0;
        assert_eq!(an.stable, Some(truth), "k {k}: {:?}", an.stability);
        assert_eq!(an.stability.open_loop_unstable_poles, Some(1));
    }
}

/// The gain at which a loop `k·|G(jω)|·e^{j·phase(ω)}` first meets −1 from
/// the phase equation `phase(ω) = −π` (bisection on `ω` in `lo..hi`) and
/// `k = 1/|G(jω)|`.
fn critical(
    phase: &dyn Fn(f64) -> f64,
    gain: &dyn Fn(f64) -> f64,
    mut lo: f64,
    mut hi: f64,
) -> f64 {
    let pi = std::f64::consts::PI;
    assert!((phase(lo) + pi) * (phase(hi) + pi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (phase(lo) + pi) * (phase(mid) + pi) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    1.0 / gain(0.5 * (lo + hi))
}

/// Loops with the exact delay: stable exactly below the critical gain from
/// the phase equation (15 % either side), and for an unstable lag between
/// its lower limit 1 and the upper one.
#[test]
fn loops_with_a_delay_against_their_phase_equations() {
    let factors = [0.85, 0.95, 0.99, 1.01, 1.05, 1.15];
    // e^{−s}/(s + 1): −ω − atan ω = −π
    let kc = critical(
        &|w: f64| -w - w.atan(),
        &|w: f64| 1.0 / (1.0 + w * w).sqrt(),
        0.5,
        3.0,
    );
    assert!((kc - 2.2618).abs() < 1e-3, "{kc}");
    for f in factors {
        let an = analyze("e^-1s/(s+1)", f * kc);
        assert_eq!(an.stable, Some(f < 1.0), "{f}·kc: {:?}", an.stability);
    }
    // 0.2 e^{−7.4 s}/s: −π/2 − 7.4ω = −π
    let kc = critical(
        &|w: f64| -std::f64::consts::FRAC_PI_2 - 7.4 * w,
        &|w: f64| 0.2 / w,
        0.01,
        1.0,
    );
    for f in factors {
        let an = analyze("0.2e^-7.4s/s", f * kc);
        assert_eq!(an.stable, Some(f < 1.0), "{f}·kc: {:?}", an.stability);
    }
    // e^{−0.5 s}/(s − 1): stable from k = 1 (|L(0)| = k) to the k where
    // −π + atan ω − 0.5ω = −π again
    let kmax = critical(
        &|w: f64| -std::f64::consts::PI + w.atan() - 0.5 * w,
        &|w: f64| 1.0 / (1.0 + w * w).sqrt(),
        0.5,
        10.0,
    );
    for f in factors {
        assert_eq!(
            analyze("e^-0.5s/(s-1)", f * kmax).stable,
            Some(f < 1.0),
            "{f}·kmax"
        );
        let an = analyze("e^-0.5s/(s-1)", f);
        assert_eq!(an.stable, Some(f > 1.0), "k {f}: {:?}", an.stability);
        assert_eq!(an.stability.open_loop_unstable_poles, Some(1));
    }
}

/// A direct feedthrough behind a delay: `|k·D| > 1` is a neutral system,
/// unstable whatever the rest (infinitely many roots in the right half
/// plane); without a delay the feedthrough is part of an ordinary loop and
/// the continuous verdict holds no computational delay (the sampled views
/// say they apply it a sample late).
#[test]
fn direct_feedthrough_in_the_continuous_and_the_sampled_views() {
    let an = analyze("e^-1s*(s+1)/(s+2)", 3.0);
    assert_eq!(an.stable, Some(false));
    assert!(
        an.stability.reason.contains("neutral"),
        "{}",
        an.stability.reason
    );
    let an = analyze("2s/(s+1)", 1.0);
    assert_eq!(an.stable, Some(true), "{:?}", an.stability);
    assert!(!an
        .stability
        .reason
        .contains("sample late in the sampled loop"));
    let sampled = {
        let sc = Scenario {
            plant: Some("2s/(s+1)".parse().unwrap()),
            ..Default::default()
        };
        msp::study::analyze(&sc, View::Sampled, None).unwrap()
    };
    assert!(
        sampled.stability.reason.contains("a sample late"),
        "{}",
        sampled.stability.reason
    );
}
