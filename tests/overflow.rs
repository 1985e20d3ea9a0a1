//! A finite input too large to compute with is a fault, as NaN is: every
//! scheme of the registry, in `f32` and `f64`, holds its output (finite)
//! and raises its fault while the set point or a measurement puts the
//! control error beyond `Real::USABLE` of its precision, and clears it,
//! with every internal signal finite and the loop back at its set point,
//! once the inputs are sane again: no state is poisoned, nothing latches.
//! The largest usable values are computed with, and nothing overflows.
mod common;

use msp::registry::{Precision, SCHEMES};
use msp::sim::{CascadeStepper, PlantStepper};
use msp::Real;

/// Runs `scheme`'s loop in precision `T`; samples `BAD` carry `big` in
/// place of the measurement (`which` 0), the set point (1) or a cascade's
/// secondary measurement (2).
fn survives<T: Precision + Real>(t: &common::Tuned, big: T, which: usize) {
    let gated = !big.usable();
    const BAD: core::ops::Range<usize> = 2000..2003;
    let name = t.scheme.name;
    let big_f = big.to_f64().unwrap_or(f64::NAN);
    let mut c = t.controller::<T>();
    let n = 6000;
    let mut y_end = f64::NAN;
    let mut step = |k: usize, y: f64, y2: f64| -> f64 {
        let (mut r, mut y, mut y2) = (T::one(), T::of(y), T::of(y2));
        let bad = BAD.contains(&k);
        if bad {
            match which {
                0 => y = big,
                1 => r = big,
                _ => y2 = big,
            }
        }
        let u = if t.p2.is_some() {
            c.update_cascade(r, y, y2)
        } else {
            c.update(r, y)
        };
        let u = u.to_f64().unwrap_or(f64::NAN);
        assert!(u.is_finite(), "{name} ({which}, {big_f:e}): u {u} at {k}");
        if bad && which < 2 && gated {
            assert!(c.fault(), "{name} ({which}, {big_f:e}): no fault at {k}");
        }
        // a spike the controller computed with may keep a predictor's
        // signal beyond the usable range for a while (its primary holds)
        let settled = if gated { BAD.end + 5 } else { n - 100 };
        if k >= settled {
            assert!(
                !c.fault(),
                "{name} ({which}, {big_f:e}): fault latched at {k}"
            );
        }
        // nothing overflows, at any sample
        for (i, s) in c.signal_names().iter().enumerate() {
            let v = c.signal(i).to_f64().unwrap_or(f64::NAN);
            assert!(
                v.is_finite(),
                "{name} ({which}, {big_f:e}): {s} = {v} at {k}"
            );
        }
        u
    };
    match &t.p2 {
        Some(p2) => {
            let mut sim = CascadeStepper::new(&t.p1, p2, t.ts).unwrap();
            for k in 0..n {
                let (y, y2) = sim.outputs();
                y_end = y;
                sim.advance(step(k, y, y2));
            }
        }
        None => {
            let mut sim = PlantStepper::new(&t.p1, t.ts).unwrap();
            for k in 0..n {
                let y = sim.output();
                y_end = y;
                sim.advance(step(k, y, f64::NAN));
            }
        }
    }
    // (a usable spike is computed with: its transient may outlast the run)
    assert!(
        !gated || (y_end - 1.0).abs() < 0.05,
        "{name} ({which}, {big_f:e}): the loop ends at {y_end}"
    );
}

#[test]
fn an_input_too_large_to_compute_with_is_a_held_fault_that_clears() {
    for scheme in SCHEMES {
        let t = common::tuned(scheme, 0.0);
        let inputs = if t.p2.is_some() { 3 } else { 2 };
        for which in 0..inputs {
            for sign in [1.0f32, -1.0] {
                survives::<f32>(&t, sign * 1e38, which);
                survives::<f32>(&t, sign * 5e9, which);
                survives::<f64>(&t, f64::from(sign) * 1e308, which);
                survives::<f64>(&t, f64::from(sign) * 2e77, which);
                // the largest usable numbers: computed with, nothing overflows
                // (every output and signal finite, no fault kept)
                survives::<f32>(&t, sign * f32::USABLE, which);
                survives::<f64>(&t, f64::from(sign) * f64::USABLE, which);
            }
        }
    }
}

/// The adaptive Smith predictor in `f32` (the firmware's): measurements of
/// 10³⁸ and 5·10⁹ now and then are faults, held, and not learnt from: the
/// estimate after set-point moves is the process's, as without them.
#[test]
fn an_adaptive_loop_learns_nothing_from_an_unusable_measurement() {
    use msp::adapt::{Adaptive, AdaptiveConfig, EstimatorConfig};
    use msp::{tuning, Controller, Fopdt, ProcessModel, SmithPredictor};
    let run = |spikes: bool| {
        let ts = 0.1f32;
        // commissioned with the gain 30 % low: the estimate must move to 1
        let model = ProcessModel::from(Fopdt::new(0.7f32, 4.0, 1.0).unwrap());
        let sp: SmithPredictor<f32, 1, [f32; 64]> =
            SmithPredictor::from_model(tuning::kaya(&model, 2.0).unwrap().config(ts), &model, ts)
                .unwrap();
        let mut c: Adaptive<f32, _, _, 16, 32> = Adaptive::new(
            sp,
            (0.7, 4.0, 1.0),
            AdaptiveConfig::new(EstimatorConfig::new(ts, 0)),
            (),
        )
        .unwrap();
        let a = (-0.1f64 / 4.0).exp();
        let (mut y, mut line) = (0.0f64, [0.0f64; 10]);
        for k in 0..20_000usize {
            let r = if (k / 400) % 2 == 0 { 0.0 } else { 1.0 };
            let y_meas = match k % 997 {
                13 if spikes => 1e38,
                14 if spikes => -5e9,
                _ => y as f32,
            };
            let u = c.update(r, y_meas);
            assert!(u.is_finite(), "{k}: {u}");
            assert_eq!(c.fault(), !y_meas.usable(), "{k}");
            let late = line[k % 10];
            line[k % 10] = f64::from(u);
            y = a * y + (1.0 - a) * late;
        }
        c.estimate().unwrap()
    };
    let (clean, spiked) = (run(false), run(true));
    assert!((clean.k - 1.0).abs() < 0.05, "{clean:?}");
    assert!(
        (spiked.k - clean.k).abs() < 0.01 * clean.k,
        "{spiked:?} vs {clean:?}"
    );
    assert_eq!(spiked.d, clean.d);
}
