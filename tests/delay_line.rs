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

/// One operation on a line during a test of its rescale.
#[derive(Debug, Clone)]
enum Op {
    Process(f64),
    SetDelay(f64),
    RampDelay(f64),
    Push(f64),
    AmendNewest(f64),
    Scale(f64),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        8 => (-5.0f64..5.0).prop_map(Op::Process),
        1 => (0.0f64..1.0).prop_map(Op::SetDelay),
        1 => (0.0f64..1.0).prop_map(Op::RampDelay),
        1 => (-5.0f64..5.0).prop_map(Op::Push),
        1 => (-1.0f64..1.0).prop_map(Op::AmendNewest),
        1 => (0.25f64..4.0).prop_map(Op::Scale),
    ]
}

proptest! {
    /// Delay::scale spreads its work over the following samples; whatever
    /// happens meanwhile, the line reads as the line that always had `g`
    /// times its input (exactly: the same products, in the same places).
    #[test]
    fn a_rescaled_line_is_the_line_that_always_had_that_input(
        cap in 1usize..90,
        d in 0.0f64..1.0,
        xs in prop::collection::vec(-5.0f64..5.0, 0..200),
        g in 0.25f64..4.0,
        ops in prop::collection::vec(op(), 0..150),
    ) {
        let frac = |x: f64| (x * cap as f64 * 4.0).round() / 4.0;
        let mut a: Delay<f64, Vec<f64>> = Delay::with_storage(vec![0.0; cap], frac(d)).unwrap();
        let mut b = a.clone();
        for x in &xs {
            a.process(*x);
            b.process(g * x);
        }
        a.scale(g);
        // a line of 33 samples or more at an integer delay is still rescaling
        prop_assert_eq!(a.is_rescaling() || cap <= 32 || xs.is_empty(), true);
        for op in ops {
            prop_assert_eq!(a.last(), b.last());
            for j in 0..=cap {
                prop_assert_eq!(a.peek_back(0.5, j), b.peek_back(0.5, j), "peek_back {}", j);
            }
            prop_assert_eq!(a.peek(0.5), b.peek(0.5));
            match op {
                Op::Process(x) => prop_assert_eq!(a.process(x), b.process(x)),
                Op::SetDelay(d) => {
                    a.set_delay(frac(d)).unwrap();
                    b.set_delay(frac(d)).unwrap();
                }
                Op::RampDelay(d) => {
                    a.ramp_delay(frac(d)).unwrap();
                    b.ramp_delay(frac(d)).unwrap();
                }
                Op::Push(x) => {
                    a.push(x);
                    b.push(x);
                }
                Op::AmendNewest(x) => {
                    a.amend_newest(x);
                    b.amend_newest(x);
                }
                Op::Scale(h) => {
                    // both rescaled: b at once
                    a.scale(h);
                    b.scale(h);
                    b.settle();
                }
            }
        }
    }
}

#[test]
fn a_rescale_ends_within_its_samples_and_costs_its_call_a_constant() {
    let mut line: Delay<f64, Vec<f64>> = Delay::with_storage(vec![0.0; 1000], 900.0).unwrap();
    for i in 0..1500 {
        line.process(i as f64);
    }
    line.scale(0.5);
    // 32 samples a sample: the 901 the line reads first, then the 99 it
    // has not overwritten (fewer each sample)
    let mut samples = 0;
    while line.is_rescaling() {
        line.process(0.0);
        samples += 1;
        assert!(samples <= 1000 / 32 + 1, "{samples}");
    }
    assert!(samples >= 1000 / 33, "{samples}");
}
