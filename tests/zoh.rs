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
