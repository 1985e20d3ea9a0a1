//! The stability verdict against the closed-loop roots, computed here
//! independently: the characteristic polynomial of the sampled loop written
//! out from the blocks' discrete transfer functions (the plant's ZOH
//! equivalent, its dead time as whole samples, the PI of `msp::Pid`:
//! `Cy = kp + ki·h/(z − 1)`), its roots as the eigenvalues of the companion
//! matrix (nalgebra). For each loop the critical gain is found on those
//! roots, and the verdict is checked at gains from 15 % below it to 15 %
//! above it.

use msp::analysis::View;
use msp::poly::TransferFunction;
use msp::study::Scenario;
use nalgebra::DMatrix;

type Poly = Vec<f64>;

/// Product of polynomials (descending powers).
fn mul(a: &[f64], b: &[f64]) -> Poly {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// Sum of polynomials (aligned at the constant term).
fn add(a: &[f64], b: &[f64]) -> Poly {
    let n = a.len().max(b.len());
    let mut out = vec![0.0; n];
    for (k, x) in a.iter().rev().enumerate() {
        out[n - 1 - k] += x;
    }
    for (k, x) in b.iter().rev().enumerate() {
        out[n - 1 - k] += x;
    }
    out
}

/// `z^k`.
fn shift(k: usize) -> Poly {
    let mut p = vec![0.0; k + 1];
    p[0] = 1.0;
    p
}

/// The largest root modulus of `p`.
fn spectral_radius(p: &[f64]) -> f64 {
    let p: Vec<f64> = p.iter().copied().skip_while(|c| *c == 0.0).collect();
    let n = p.len() - 1;
    let mut c = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        c[(0, j)] = -p[j + 1] / p[0];
    }
    for i in 1..n {
        c[(i, i - 1)] = 1.0;
    }
    c.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// ZOH of `k/(τs + 1)` at `h`: `b/(z − a)` as (numerator, denominator); an
/// integrator for `τ = ∞` (`k·h/(z − 1)`), an unstable lag for `τ < 0`.
fn zoh_first_order(k: f64, tau: f64, h: f64) -> (Poly, Poly) {
    if tau.is_infinite() {
        return (vec![k * h], vec![1.0, -1.0]);
    }
    let a = (-h / tau).exp();
    (vec![k * (1.0 - a)], vec![1.0, -a])
}

/// A PI `kp + (kp/ti)·h/(z − 1)` (P only for `ti = ∞`).
fn pi(kp: f64, ti: f64, h: f64) -> (Poly, Poly) {
    if ti.is_infinite() {
        return (vec![kp], vec![1.0]);
    }
    (vec![kp, -kp + kp / ti * h], vec![1.0, -1.0])
}

/// The characteristic polynomial of the PI loop around `Np/Dp·z^{−d}`:
/// `Dc·Dp·z^d + Nc·Np`.
fn pi_loop(c: &(Poly, Poly), p: &(Poly, Poly), d: usize) -> Poly {
    add(&mul(&mul(&c.1, &p.1), &shift(d)), &mul(&c.0, &p.0))
}

/// The Smith predictor's characteristic polynomial with a model `Nm/Dm·z^{−dm}`
/// and a plant `Np/Dp·z^{−dp}`: from `1 + C·Gm(1 − z^{−dm}) + C·P` times
/// `Dc·Dm·Dp·z^D`, `D = max(dm, dp)`.
fn smith_loop(c: &(Poly, Poly), m: &(Poly, Poly), dm: usize, p: &(Poly, Poly), dp: usize) -> Poly {
    let big = dm.max(dp);
    let base = mul(&mul(&c.1, &m.1), &p.1);
    let a = mul(&base, &shift(big));
    let model = mul(&mul(&c.0, &m.0), &p.1);
    let b = mul(
        &model,
        &add(
            &shift(big),
            &shift(big - dm).iter().map(|x| -x).collect::<Vec<_>>(),
        ),
    );
    let plant = mul(&mul(&c.0, &m.1), &p.0);
    let e = mul(&plant, &shift(big - dp));
    add(&add(&a, &b), &e)
}

/// msp's verdict on a scenario (discrete view, as the simulator runs it).
fn verdict(
    plant: &str,
    model: Option<&str>,
    controller: &str,
    set: &[(&str, f64)],
    ts: f64,
) -> Option<bool> {
    let mut sc = Scenario {
        plant: Some(plant.parse().unwrap()),
        model: model.map(|m| m.parse().unwrap()),
        controller: Some(controller.into()),
        ts: Some(ts),
        ..Default::default()
    };
    for (k, v) in set {
        sc.set.insert((*k).into(), *v);
    }
    let an = msp::study::analyze(&sc, View::Discrete, None).unwrap();
    assert_eq!(
        an.stability.stable, an.stable,
        "one verdict: {:?}",
        an.stability
    );
    an.stable
}

/// The gain at which `radius(k)` crosses 1, by bisection between a stable
/// `lo` and an unstable `hi`.
fn critical(radius: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(
        radius(lo) < 1.0 && radius(hi) > 1.0,
        "{} {}",
        radius(lo),
        radius(hi)
    );
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if radius(mid) < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

const FACTORS: [f64; 10] = [0.85, 0.9, 0.95, 0.98, 0.995, 1.005, 1.02, 1.05, 1.1, 1.15];

/// Checks msp's verdict against the roots at each factor of the critical
/// gain `kc` (stable below it, or above it for a lower gain limit).
fn check(
    name: &str,
    radius: &dyn Fn(f64) -> f64,
    msp: &dyn Fn(f64) -> Option<bool>,
    kc: f64,
    stable_below: bool,
) {
    for f in FACTORS {
        let k = kc * f;
        let truth = radius(k) < 1.0;
        assert_eq!(
            truth,
            (f < 1.0) == stable_below,
            "{name}: the roots at {f}·kc"
        );
        assert_eq!(
            msp(k),
            Some(truth),
            "{name}: kp = {k} ({f} of the critical {kc})"
        );
    }
}

#[test]
fn p_and_pi_on_a_lag_with_dead_time() {
    let h = 0.1;
    let p = zoh_first_order(1.0, 5.0, h);
    for ti in [f64::INFINITY, 5.0, 2.0] {
        let radius = |kp: f64| spectral_radius(&pi_loop(&pi(kp, ti, h), &p, 10));
        let msp = |kp: f64| {
            verdict(
                "e^-1s/(5s+1)",
                None,
                "pid",
                &[("kp", kp), ("ti", ti), ("td", 0.0)],
                h,
            )
        };
        check(
            &format!("PI ti {ti} on e^-s/(5s+1)"),
            &radius,
            &msp,
            critical(&radius, 0.1, 50.0),
            true,
        );
    }
}

#[test]
fn pi_on_an_integrator_with_dead_time() {
    // the loop has a double pole at z = 1: the indentation's order two
    let h = 0.1;
    let p = zoh_first_order(0.2, f64::INFINITY, h);
    for ti in [f64::INFINITY, 20.0, 8.0] {
        let radius = |kp: f64| spectral_radius(&pi_loop(&pi(kp, ti, h), &p, 20));
        let msp = |kp: f64| {
            verdict(
                "0.2/s*e^-2s",
                None,
                "pid",
                &[("kp", kp), ("ti", ti), ("td", 0.0)],
                h,
            )
        };
        check(
            &format!("PI ti {ti} on 0.2/s e^-2s"),
            &radius,
            &msp,
            critical(&radius, 0.01, 20.0),
            true,
        );
    }
}

/// A pure gain (`-c none --set kp=K`) on python-control's margin cases of type 2 and 3,
/// `(s + 0.1)/(s²(s + 1))` and `(s + 0.1)²/(s³(s + 1))`: the plant's poles
/// at the origin are exact (a double or triple root's eigenvalues would
/// scatter into the right half plane and count as an unstable pole). Their
/// ZOH equivalents here by partial fractions over the least common
/// denominator `(z − 1)^m (z − a)`, `a = e^{−h}`, with the holds of `1/s`,
/// `1/s²`, `1/s³`: `h/(z − 1)`, `h²(z + 1)/(2(z − 1)²)`,
/// `h³(z² + 4z + 1)/(6(z − 1)³)`. The type-3 loop is stable only between a
/// lower and an upper gain limit.
#[test]
fn p_on_a_double_and_a_triple_integrator() {
    let h = 0.1;
    let a = f64::exp(-h);
    let lag = vec![1.0, -a];
    let one = vec![1.0, -1.0];
    let scale = |p: &[f64], k: f64| p.iter().map(|x| x * k).collect::<Vec<_>>();
    // (s + 0.1)/(s²(s + 1)) = 0.1/s² + 0.9/s − 0.9/(s + 1)
    let num2 = add(
        &add(
            &mul(&scale(&[1.0, 1.0], 0.1 * h * h / 2.0), &lag),
            &mul(&scale(&one, 0.9 * h), &lag),
        ),
        &scale(&mul(&one, &one), -0.9 * (1.0 - a)),
    );
    let den2 = mul(&mul(&one, &one), &lag);
    // (s + 0.1)²/(s³(s + 1)) = 0.01/s³ + 0.19/s² + 0.81/s − 0.81/(s + 1)
    let one2 = mul(&one, &one);
    let num3 = add(
        &add(
            &mul(&scale(&[1.0, 4.0, 1.0], 0.01 * h * h * h / 6.0), &lag),
            &mul(&mul(&scale(&[1.0, 1.0], 0.19 * h * h / 2.0), &one), &lag),
        ),
        &add(
            &mul(&mul(&scale(&one, 0.81 * h), &one), &lag),
            &scale(&mul(&one2, &one), -0.81 * (1.0 - a)),
        ),
    );
    let den3 = mul(&mul(&one2, &one), &lag);
    let p_only =
        |plant: &'static str| move |kp: f64| verdict(plant, None, "none", &[("kp", kp)], h);
    let radius2 = |k: f64| spectral_radius(&add(&den2, &scale(&num2, k)));
    let plant2 = "(s+0.1)/(s^2(s+1))";
    check(
        plant2,
        &radius2,
        &p_only(plant2),
        critical(&radius2, 1.0, 100.0),
        true,
    );
    let radius3 = |k: f64| spectral_radius(&add(&den3, &scale(&num3, k)));
    let plant3 = "(s+0.1)^2/(s^3(s+1))";
    check(
        plant3,
        &radius3,
        &p_only(plant3),
        critical(&radius3, 1.0, 100.0),
        true,
    );
    // the lower limit: unstable below, stable above
    let lower = critical(&|k| 1.0 / radius3(k).max(1e-300), 0.01, 1.0);
    check(plant3, &radius3, &p_only(plant3), lower, false);
    let v = msp::study::analyze(
        &Scenario {
            plant: Some(plant2.parse().unwrap()),
            ts: Some(h),
            ..Default::default()
        },
        View::Discrete,
        None,
    )
    .unwrap();
    assert_eq!(
        v.stability.open_loop_unstable_poles,
        Some(0),
        "{:?}",
        v.stability
    );
}

#[test]
fn pi_on_an_unstable_lag_with_dead_time() {
    // one open-loop pole outside the unit circle: stable only between two gains
    let h = 0.05;
    let p = zoh_first_order(-1.0, -5.0, h); // 1/(5s − 1) = −1/(−5s + 1)
    let ti = 4.0;
    let radius = |kp: f64| spectral_radius(&pi_loop(&pi(kp, ti, h), &p, 10));
    let msp = |kp: f64| {
        verdict(
            "e^-0.5s/(5s-1)",
            None,
            "pid",
            &[("kp", kp), ("ti", ti), ("td", 0.0)],
            h,
        )
    };
    let upper = critical(&radius, 2.0, 40.0);
    check(
        "PI on e^-0.5s/(5s-1), upper limit",
        &radius,
        &msp,
        upper,
        true,
    );
    let lower = critical(&radius, 2.0, 0.1);
    check(
        "PI on e^-0.5s/(5s-1), lower limit",
        &radius,
        &msp,
        lower,
        false,
    );
}

#[test]
fn smith_predictor_with_a_delay_mismatch() {
    // the model's dead time 1 s, the plant's 1.5 s: a gain limit the perfect
    // model would not have
    let h = 0.1;
    let p = zoh_first_order(1.0, 5.0, h);
    let ti = 5.0;
    let radius = |kp: f64| spectral_radius(&smith_loop(&pi(kp, ti, h), &p, 10, &p, 15));
    let msp = |kp: f64| {
        verdict(
            "e^-1.5s/(5s+1)",
            Some("e^-1s/(5s+1)"),
            "smith",
            &[("kp", kp), ("ti", ti), ("td", 0.0)],
            h,
        )
    };
    check(
        "Smith PI, model delay 1 s, plant 1.5 s",
        &radius,
        &msp,
        critical(&radius, 0.5, 60.0),
        true,
    );
}

/// The Smith predictor on an unstable plant is internally unstable for every
/// gain (the plant's unstable mode cancels in `Cy` but not in the loop): the
/// roots say so, and so does the verdict, though with a perfect model
/// `1 + Cy·P = 1 + C·Gm` is the return difference of a stable loop.
#[test]
fn smith_predictor_on_an_unstable_plant_is_unstable() {
    use msp::{Delay, Discretization, Lti, PidConfig, SmithPredictor};
    let h = 0.05;
    let p = zoh_first_order(-1.0, -5.0, h);
    let plant: TransferFunction = "e^-0.5s/(5s-1)".parse().unwrap();
    for kp in [2.0, 5.0, 10.0] {
        let ti = 4.0;
        let r = spectral_radius(&smith_loop(&pi(kp, ti, h), &p, 10, &p, 10));
        assert!(r > 1.0, "{r}");
        let model = Lti::<f64, 2>::from_tf(&[1.0], &[5.0, -1.0], h, Discretization::Zoh).unwrap();
        let sp: SmithPredictor<f64, 2, Vec<f64>> = SmithPredictor::new(
            PidConfig::isa(kp, ti, 0.0, h),
            model,
            Delay::new_in(10.0).unwrap(),
        )
        .unwrap();
        let v = msp::analysis::loop_stability(&sp, &plant, None, h);
        assert_eq!(v.stable, Some(false), "kp {kp}: {v:?}");
        assert_eq!(v.open_loop_unstable_poles, Some(2), "{v:?}");
        // the return difference alone: 1 + C·Gm winds once, as for a stable loop
        assert_eq!(v.unstable_poles, Some(1), "{v:?}");
    }
}

/// Where the count cannot be made the verdict says so: a plant with
/// undamped poles (on the imaginary axis away from the origin) samples onto
/// the unit circle, beyond the indentation at z = 1 — `stable` is unknown,
/// with the reason, never a guess.
#[test]
fn an_undecidable_loop_is_unknown_with_its_reason() {
    let plant: TransferFunction = "e^-0.5s/(s^2+1)".parse().unwrap();
    let c = msp::Pid::new(msp::PidConfig::isa(0.1, f64::INFINITY, 0.0, 0.05)).unwrap();
    let v = msp::analysis::loop_stability(&c, &plant, None, 0.05);
    assert_eq!(v.stable, None, "{v:?}");
    assert!(v.reason.contains("undamped"), "{}", v.reason);
    assert_eq!(v.summary(), "unknown");
}

/// The cross-check's words: agreement, disagreement (the equation decides,
/// and the reason says what the simulation showed) and a verdict from the
/// simulation alone, which is said to prove nothing.
#[test]
fn the_simulation_cross_check_is_said_in_words() {
    use msp::analysis::Stability;
    let proven = |stable| Stability {
        stable: Some(stable),
        reason: "from the equation".into(),
        ..Stability::default()
    };
    let agree = proven(true).with_simulation(true, 12.0);
    assert_eq!((agree.stable, agree.simulation), (Some(true), Some(true)));
    assert!(
        agree.reason.ends_with("the simulation over 12 s agrees"),
        "{}",
        agree.reason
    );
    let disagree = proven(false).with_simulation(true, 12.0);
    assert_eq!(disagree.stable, Some(false), "the equation decides");
    assert!(disagree.reason.contains("disagrees"), "{}", disagree.reason);
    let alone = Stability::unknown("undecided").with_simulation(true, 12.0);
    assert_eq!(alone.stable, None);
    assert!(alone.reason.contains("not a proof"), "{}", alone.reason);
}
