//! A Smith predictor with a perfect model equals, sample for sample, the
//! delay-free closed loop delayed by the dead time (Kaya (2003) Eq. 1).
mod common;

use msp::{Controller, Delay, Lti, Pid, PidConfig, SmithPredictor};

/// Runs both loops for `n` samples and returns the largest difference between
/// the Smith loop's output and the delay-free loop's output `k` samples earlier.
fn max_mismatch(num: &[f64], den: &[f64], k: usize, pid: PidConfig<f64>, ts: f64, n: usize) -> f64 {
    let plant: Lti<f64, 4> = Lti::from_tf(num, den, ts, msp::Discretization::Zoh).unwrap();
    // delay-free reference loop
    let mut p0 = plant;
    let mut c0 = Pid::new(pid).unwrap();
    let mut y_free = Vec::with_capacity(n);
    for i in 0..n {
        let r = if i >= 10 { 1.0 } else { 0.0 };
        let y = p0.free_output();
        y_free.push(y);
        let u = c0.update(r, y);
        p0.step(u);
    }
    // Smith predictor on the delayed plant; the set point is delayed too so that
    // the whole response is the delay-free one, shifted by k samples.
    let mut sp: SmithPredictor<f64, 4, Vec<f64>> =
        SmithPredictor::new(pid, plant, Delay::new_in(k as f64).unwrap()).unwrap();
    let mut p1 = plant;
    let mut u_line: Delay<f64, Vec<f64>> = Delay::new_in(k as f64).unwrap();
    let mut worst: f64 = 0.0;
    let mut last_u = 0.0;
    for i in 0..n + k {
        let r = if i >= 10 { 1.0 } else { 0.0 };
        let y = p1.free_output();
        if i >= k {
            worst = worst.max((y - y_free[i - k]).abs());
        }
        let u = sp.update(r, y);
        last_u = u;
        p1.step(u_line.process(u));
    }
    assert!(last_u.is_finite());
    worst
}

/// The identity for Kaya's FOPDT plant with its PI, an SOPDT with a PID and
/// the IPDT of Bag (2022): numerator, denominator, dead time in samples, the
/// controller and its period.
#[test]
fn fopdt_sopdt_and_ipdt_models() {
    let cases = [
        (
            "fopdt",
            &[5.6][..],
            &[40.2, 1.0][..],
            94,
            [0.0764, 40.2, 0.0],
            1.0,
        ),
        ("sopdt", &[1.0], &[1.0, 2.0, 1.0], 100, [0.4, 2.0, 0.5], 0.1),
        ("ipdt", &[0.2], &[1.0, 0.0], 100, [5.4, 3.7, 0.0], 0.074),
    ];
    for (name, num, den, k, [kp, ti, td], ts) in cases {
        let e = max_mismatch(num, den, k, PidConfig::isa(kp, ti, td, ts), ts, 10_000);
        assert!(e < 1e-12, "{name}: {e}");
    }
}

#[test]
fn identity_is_not_trivially_true() {
    // with a wrong model delay the loops differ: the test above can fail
    let pid = PidConfig::isa(0.0764, 40.2, 0.0, 1.0);
    let plant: Lti<f64, 4> =
        Lti::from_tf(&[5.6], &[40.2, 1.0], 1.0, msp::Discretization::Zoh).unwrap();
    let mut sp: SmithPredictor<f64, 4, Vec<f64>> =
        SmithPredictor::new(pid, plant, Delay::new_in(80.0).unwrap()).unwrap();
    let mut p = plant;
    let mut line: Delay<f64, Vec<f64>> = Delay::new_in(94.0).unwrap();
    let mut ys = vec![];
    for _ in 0..400 {
        let y = p.free_output();
        ys.push(y);
        let u = sp.update(1.0, y);
        p.step(line.process(u));
    }
    assert!(sp.model_error().abs() > 1e-3 || ys.iter().any(|y| *y > 1.01));
}

/// A new model's gain at run time (`Operate::set_model`, what the
/// adaptation applies) does not bump a settled loop: the prediction and its
/// delayed copy both become the new model's response to the past inputs
/// (the old outputs times the ratio of the gains), so their difference —
/// the predictor's correction — stays zero while the input holds still. A
/// loop at rest under an input load (u ≠ 0) whose model's gain is halved
/// keeps its input to rounding for three dead times. (Kept from the old
/// model's output alone, the prediction would fall to the new model's level
/// over the lag while its delayed copy waits a dead time: the input moved
/// by 0.13, 40 % of its value.)
#[test]
fn a_new_gain_does_not_bump_a_settled_loop() {
    use msp::Operate;
    let (k, tau, d, ts) = (5.6, 40.2, 94usize, 1.0);
    let plant: Lti<f64, 4> = Lti::from_tf(&[k], &[tau, 1.0], ts, msp::Discretization::Zoh).unwrap();
    let pid = PidConfig::isa(0.0764, 40.2, 0.0, ts);
    for gain in [k / 2.0, 2.0 * k] {
        let mut sp: SmithPredictor<f64, 4, Vec<f64>> =
            SmithPredictor::new(pid, plant, Delay::new_in(d as f64).unwrap()).unwrap();
        let mut p = plant;
        let mut line: Delay<f64, Vec<f64>> = Delay::new_in(d as f64).unwrap();
        let mut u = 0.0;
        // the set point 1 and an input load of 0.5, settled
        for _ in 0..4000 {
            u = sp.update(1.0, p.free_output());
            p.step(line.process(u) + 0.5);
        }
        let settled = u;
        assert!((settled + 0.5 - 1.0 / k).abs() < 1e-9, "{settled}");
        sp.set_model(gain, tau).unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..3 * d {
            u = sp.update(1.0, p.free_output());
            p.step(line.process(u) + 0.5);
            worst = worst.max((u - settled).abs());
        }
        assert!(worst < 1e-9, "gain {gain}: the input moved by {worst}");
    }
}

/// An integrating model's gain applied under a steady input load `l`: the
/// loop has settled with `u = −l` and the model's prediction ramping, its
/// correction `y_m[k] − y_m[k − d] = K·u·θ`. The new gain `g·K` makes it
/// `g·K·u·θ`; rescaled at once, the feedback would step by
/// `(g − 1)·K·u·θ` and the input by `Kp` times that in one sample. Kept
/// continuous (the new model's prediction goes on from the old one's, its
/// delayed copy reaching the new slope over one dead time), no sample's
/// move of the input is a tenth of that kick.
#[test]
fn an_integrating_models_new_gain_is_taken_over_a_dead_time() {
    use msp::Operate;
    let (k, d, ts, load) = (0.15, 20usize, 0.25, 0.5);
    let theta = d as f64 * ts;
    let plant: Lti<f64, 4> = Lti::from_tf(&[k], &[1.0, 0.0], ts, msp::Discretization::Zoh).unwrap();
    let (kp, ti) = (1.0 / (k * 5.0), 20.0);
    let pid = PidConfig::isa(kp, ti, 0.0, ts);
    for g in [0.5, 2.0] {
        let mut sp: SmithPredictor<f64, 4, Vec<f64>> =
            SmithPredictor::new(pid, plant, Delay::new_in(d as f64).unwrap()).unwrap();
        let mut p = plant;
        let mut line: Delay<f64, Vec<f64>> = Delay::new_in(d as f64).unwrap();
        let mut u = 0.0;
        for _ in 0..8000 {
            u = sp.update(1.0, p.free_output());
            p.step(line.process(u) + load);
        }
        let settled = u;
        assert!((settled + load).abs() < 1e-9, "{settled}");
        sp.set_model(g * k, f64::INFINITY).unwrap();
        let kick = kp * (g - 1.0).abs() * k * load * theta;
        let mut worst: f64 = 0.0;
        for _ in 0..3 * d {
            let next = sp.update(1.0, p.free_output());
            p.step(line.process(next) + load);
            worst = worst.max((next - u).abs());
            u = next;
        }
        assert!(
            worst < 0.1 * kick,
            "gain ×{g}: the input moved by {worst} in a sample (kick {kick})"
        );
    }
}
