//! Bad input, faults and long runs: never a panic, never a silent NaN.
mod common;
use msp::poly::TransferFunction;
use msp::registry::{Build, SCHEMES};
use msp::syntax::parse_plant;
use msp::{AntiWindup, Delay, Lti, Pid, PidConfig, SmithPredictor};
use msp::{Controller, Introspect};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, .. ProptestConfig::default() })]

    #[test]
    fn the_parser_never_panics(s in "\\\\PC{0,40}") {
        match parse_plant(&s) {
            Ok(tf) => prop_assert!(tf.num.iter().chain(&tf.den).all(|c| c.is_finite()) && tf.delay >= 0.0),
            Err(e) => {
                prop_assert!(!e.message.is_empty());
                prop_assert!(e.column >= 1 && e.column <= s.chars().count() + 1, "{e}");
            }
        }
    }

    #[test]
    fn the_parser_never_panics_on_plausible_input(s in "[-+*/^()se0-9. xp]{0,30}") {
        let _ = parse_plant(&s).map_err(|e| e.to_string());
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, .. ProptestConfig::default() })]

    #[test]
    fn pid_output_stays_within_its_limits_and_its_integrator_bounded(
        kp in 0.01f64..10.0, ti in 0.1f64..100.0, td in 0.0f64..5.0, lo in -5.0f64..0.0, span in 0.1f64..10.0,
        ys in prop::collection::vec(-100.0f64..100.0, 50..300), cond in any::<bool>(),
    ) {
        let hi = lo + span;
        let aw = if cond { AntiWindup::Conditional } else { AntiWindup::BackCalculation { tt: ti } };
        let mut c = Pid::new(PidConfig::isa(kp, ti, td, 0.1).with_limits(lo, hi).with_anti_windup(aw)).unwrap();
        for y in ys {
            let u = c.update(1.0, y);
            prop_assert!(u >= lo && u <= hi);
            // back-calculation and clamping keep I within the reach of the limits plus one step
            prop_assert!(c.terms().i.abs() <= 100.0 * kp + hi.abs() + lo.abs() + kp * 200.0 * 0.1 / ti * 100.0);
        }
    }

    #[test]
    fn smith_identity_for_random_models(k in 0.1f64..5.0, t1 in 0.5f64..20.0, t2 in 0.1f64..5.0, d in 1usize..60, kind in 0u8..3) {
        let ts = 0.1;
        let (num, den): (Vec<f64>, Vec<f64>) = match kind {
            0 => (vec![k], vec![t1, 1.0]),
            1 => (vec![k], vec![t1 * t2, t1 + t2, 1.0]),
            _ => (vec![k], vec![1.0, 0.0]),
        };
        let plant: Lti<f64, 2> = Lti::from_tf(&num, &den, ts, msp::Discretization::Zoh).unwrap();
        let pid = if kind == 2 { PidConfig::isa(0.5 / (k * d as f64 * ts), 8.0 * d as f64 * ts, 0.0, ts) } else { PidConfig::isa(t1 / (k * d as f64 * ts), t1, 0.0, ts) };
        let (mut p0, mut c0) = (plant, Pid::new(pid).unwrap());
        let free: Vec<f64> = (0..600).map(|_| { let y = p0.free_output(); p0.step(c0.update(1.0, y)); y }).collect();
        // the Smith loop on the delayed plant: its output is the free one, d samples later
        let mut p2 = plant;
        let mut line2: Delay<f64, Vec<f64>> = Delay::new_in(d as f64).unwrap();
        let mut sp2: SmithPredictor<f64, 2, Vec<f64>> = SmithPredictor::new(pid, plant, Delay::new_in(d as f64).unwrap()).unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..600 {
            let y = p2.free_output();
            if i >= d { worst = worst.max((y - free[i - d]).abs()); }
            let u = sp2.update(1.0, y);
            p2.step(line2.process(u));
        }
        prop_assert!(worst < 1e-9 * (1.0 + free.iter().fold(0.0f64, |m, v| m.max(v.abs()))), "{worst}");
    }
}

#[test]
fn ten_million_samples_stay_finite() {
    let plant: TransferFunction = "0.2/s*e^-7.4s".parse().unwrap();
    let s = msp::registry::find("karan-dey").unwrap();
    let p = s.tune_with(&plant, None, &[]).unwrap();
    let mut c = s
        .build_with(
            &p,
            &plant,
            &Build {
                ts: 0.074,
                u_min: -10.0,
                u_max: 10.0,
                max_dead_time: 0.0,
            },
        )
        .unwrap();
    let mut y = 0.0f64;
    let mut line: Delay<f64, Vec<f64>> = Delay::new_in(100.0).unwrap();
    let mut noise = msp::sim::Noise::new(7);
    for k in 0..10_000_000u64 {
        let r = if (k / 20_000) % 2 == 0 { 1.0 } else { -1.0 };
        let u = c.update(r, y + 0.01 * noise.gaussian());
        y += 0.2 * 0.074 * line.process(u);
        assert!(u.is_finite() && y.is_finite(), "sample {k}");
    }
    assert!(y.abs() < 2.0);
}

#[test]
fn f32_runs_do_not_drift() {
    // the same Smith loop in f32 and f64 for 10^6 samples
    fn run<T: msp::Real>() -> (T, Vec<(f64, f64)>) {
        let ts = T::of(0.1);
        let model: Lti<T, 1> = Lti::first_order(T::of(5.6), T::of(40.2), ts).unwrap();
        let mut sp: SmithPredictor<T, 1, Vec<T>> = SmithPredictor::new(
            PidConfig::isa(T::of(0.0764), T::of(40.2), T::zero(), ts),
            model,
            Delay::new_in(T::of(939.0)).unwrap(),
        )
        .unwrap();
        let mut plant = model;
        let mut line: Delay<T, Vec<T>> = Delay::new_in(T::of(939.0)).unwrap();
        let mut y = T::zero();
        let mut eu = Vec::with_capacity(1_000_000);
        for k in 0..1_000_000u32 {
            let r = if (k / 50_000) % 2 == 0 {
                T::one()
            } else {
                T::zero()
            };
            let u = sp.update(r, y);
            y = plant.step(line.process(u));
            eu.push(((r - y).f64(), u.f64()));
        }
        (y, eu)
    }
    let (y32, _) = run::<f32>();
    let (y64, eu) = run::<f64>();
    assert!((f64::from(y32) - y64).abs() < 1e-3, "{y32} vs {y64}");
    // the integral indices accumulate 10^6 terms (time up to 10^5 s in ITAE): the f32
    // sums stay within the f32 rounding of their inputs
    let mut i32 = msp::IntegralIndices::<f32>::new(0.1).unwrap();
    let mut i64 = msp::IntegralIndices::<f64>::new(0.1).unwrap();
    for (e, u) in &eu {
        i32.push(*e as f32, *u as f32);
        i64.push(*e, *u);
    }
    let (a, b) = (i32.value(), i64.value());
    for (x, y) in [
        (a.iae, b.iae),
        (a.ise, b.ise),
        (a.itae, b.itae),
        (a.itse, b.itse),
        (a.tv, b.tv),
    ] {
        assert!((f64::from(x) - y).abs() <= 1e-5 * y.abs(), "{x} vs {y}");
    }
}

/// Every internal signal of the controller of `scheme` is finite.
fn signals_are_finite<C: Introspect<f64> + ?Sized>(c: &C, scheme: &str) {
    for (i, name) in c.signal_names().iter().enumerate() {
        assert!(
            c.signal(i).is_finite(),
            "{scheme}: signal {name} is not finite"
        );
    }
}

#[test]
fn a_nan_measurement_never_reaches_the_state_and_recovery_is_bumpless() {
    for scheme in SCHEMES {
        if scheme.is_cascade() {
            cascade_nan(scheme);
            continue;
        }
        let integrating = scheme.plants.contains(&msp::poly::PlantKind::Integrating);
        let expr = if integrating {
            "0.2/s*e^-7.4s"
        } else {
            "5.6*e^-93.9s/(40.2s+1)"
        };
        let plant: TransferFunction = expr.parse().unwrap();
        let ts = if integrating { 0.074 } else { 0.939 };
        let p = scheme.tune_with(&plant, None, &[]).unwrap();
        let mut c = scheme.build_with(&p, &plant, &common::limits(ts)).unwrap();
        let mut sim = msp::sim::PlantStepper::new(&plant, ts).unwrap();
        let mut us = Vec::new();
        for k in 0..6000 {
            let y = sim.output();
            // the sensor fails for 40 samples once the loop has settled
            let y_meas = if (5000..5040).contains(&k) {
                f64::NAN
            } else {
                y
            };
            let u = c.update(1.0, y_meas);
            assert!(u.is_finite(), "{}", scheme.name);
            assert_eq!(c.fault(), y_meas.is_nan(), "{}", scheme.name);
            signals_are_finite(&*c, scheme.name);
            us.push(u);
            sim.advance(u);
        }
        // held during the fault, and no jump when the measurement returns
        assert!(
            us[5000..5040].iter().all(|u| *u == us[4999]),
            "{} holds its output",
            scheme.name
        );
        let jump = (us[5040] - us[5039]).abs();
        assert!(
            jump < 1e-6 * (1.0 + us[4999].abs()),
            "{}: jump {jump} on recovery",
            scheme.name
        );
    }
}

#[test]
fn pid_fail_safe_value_and_bumpless_return() {
    let mut c = Pid::new(PidConfig::isa(2.0, 5.0, 0.0, 0.1).with_limits(0.0, 10.0)).unwrap();
    for _ in 0..100 {
        c.update(1.0, 0.5);
    }
    c.set_failsafe(Some(2.5)).unwrap();
    assert_eq!(c.update(1.0, f64::INFINITY), 2.5);
    let back = c.update(1.0, 0.5);
    assert!((back - 2.5).abs() < 0.2, "{back}");
    assert_eq!(
        c.set_failsafe(Some(11.0)).unwrap_err(),
        msp::Error::OutOfRange("failsafe")
    );
}

/// The same for a cascade scheme on García et al.'s Example 2 (integrating
/// primary): the primary sensor fails, then the secondary one.
fn cascade_nan(scheme: &'static msp::registry::Scheme) {
    let p1: TransferFunction = common::EXAMPLE2.0.parse().unwrap();
    let p2: TransferFunction = common::EXAMPLE2.1.parse().unwrap();
    let ts = 0.1;
    let gcd = common::required_settings(scheme.name);
    let p = scheme
        .tune_process(&p1, Some(&p2), None, None, &gcd)
        .unwrap();
    let mut c = scheme
        .build_process(&p, &p1, Some(&p2), &common::limits(ts))
        .unwrap();
    let mut sim = msp::sim::CascadeStepper::new(&p1, &p2, ts).unwrap();
    let mut last = (0.0, 0.0);
    for k in 0..8000 {
        let (y, y2) = sim.outputs();
        let y_meas = if (4000..4040).contains(&k) {
            f64::NAN
        } else {
            y
        };
        let y2_meas = if (6000..6040).contains(&k) {
            f64::NAN
        } else {
            y2
        };
        let u = c.update_cascade(1.0, y_meas, y2_meas);
        assert!(u.is_finite(), "{}", scheme.name);
        assert_eq!(
            c.fault(),
            y_meas.is_nan() || y2_meas.is_nan(),
            "{} at {k}",
            scheme.name
        );
        signals_are_finite(&*c, scheme.name);
        sim.advance(u);
        last = (y, y2);
    }
    // back on the set point after both faults
    assert!(
        (last.0 - 1.0).abs() < 1e-3,
        "{}: y = {}",
        scheme.name,
        last.0
    );
}
