//! The delay line against a plain reference implementation.
use msp::{Delay, DelayLine, Error};
use proptest::prelude::*;

/// y[n] = x[n − d] with linear interpolation, from the whole history.
fn reference(history: &[f64], d: f64) -> f64 {
    let n = history.len() as f64 - 1.0;
    let pos = n - d;
    let at = |i: f64| {
        if i < 0.0 {
            0.0
        } else {
            history.get(i as usize).copied().unwrap_or(0.0)
        }
    };
    let lo = pos.floor();
    let f = pos - lo;
    // pos = n - k - f'  → interpolate between floor and ceil
    at(lo) * (1.0 - f) + at(lo + 1.0) * f
}

proptest! {
    #[test]
    fn matches_reference(d in 0.0f64..60.0, xs in prop::collection::vec(-10.0f64..10.0, 1..200)) {
        let mut line: DelayLine<f64, 64> = DelayLine::new(d).unwrap();
        let mut hist = Vec::new();
        for x in xs {
            hist.push(x);
            let y = line.process(x);
            let e = reference(&hist, d);
            prop_assert!((y - e).abs() < 1e-9, "d={} y={} e={}", d, y, e);
        }
    }

    #[test]
    fn runtime_change(d1 in 0u32..30, d2 in 0u32..30, xs in prop::collection::vec(-1.0f64..1.0, 40..120)) {
        let mut line: Delay<f64, Vec<f64>> = Delay::new_in(40.0).unwrap();
        line.set_delay(d1 as f64).unwrap();
        let mut hist = Vec::new();
        let half = xs.len() / 2;
        for (i, x) in xs.into_iter().enumerate() {
            if i == half {
                line.set_delay(d2 as f64).unwrap();
            }
            hist.push(x);
            let d = if i >= half { d2 } else { d1 } as f64;
            let y = line.process(x);
            prop_assert!((y - reference(&hist, d)).abs() < 1e-12);
        }
    }
}

#[test]
fn ramped_delay_change_moves_at_most_one_sample_per_sample() {
    let mut line: DelayLine<f64, 100> = DelayLine::new(10.0).unwrap();
    for i in 0..200 {
        line.process(i as f64);
    }
    line.ramp_delay(50.0).unwrap();
    let mut prev = line.process(200.0);
    for i in 201..300 {
        let y = line.process(i as f64);
        // a ramp x[n] = n read with a delay growing by one per sample stands still
        // at worst; it never jumps backward by more than one sample's step
        assert!(
            y >= prev - 1e-12 && y <= prev + 1.0 + 1e-12,
            "{prev} -> {y}"
        );
        prev = y;
    }
    assert_eq!(line.delay(), 50.0);
}

#[test]
fn capacity_errors_instead_of_panics() {
    assert_eq!(
        DelayLine::<f64, 8>::new(8.5).unwrap_err(),
        Error::DelayTooLong("delay")
    );
    let mut line: DelayLine<f64, 8> = DelayLine::new(2.0).unwrap();
    assert_eq!(
        line.set_delay(9.0).unwrap_err(),
        Error::DelayTooLong("delay")
    );
    assert_eq!(
        line.set_delay(f64::INFINITY).unwrap_err(),
        Error::NonFinite("delay")
    );
    let mut buf = [0.0f32; 3];
    assert!(msp::DelayLineRef::with_storage(&mut buf[..], 4.0).is_err());
}
