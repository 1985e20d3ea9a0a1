//! PID: anti-windup, bumpless transfer, no derivative kick.
use msp::{AntiWindup, Lti, Pid, PidConfig};

/// PI on a first-order plant with a saturating actuator; returns (peak y, max |I|).
fn saturated_run(aw: AntiWindup<f64>) -> (f64, f64) {
    run(aw, 1.2)
}

fn run(aw: AntiWindup<f64>, limit: f64) -> (f64, f64) {
    let h = 0.1;
    let cfg = PidConfig::isa(2.0, 5.0, 0.0, h)
        .with_limits(-limit, limit)
        .with_anti_windup(aw);
    let mut c = Pid::new(cfg).unwrap();
    let mut p: Lti<f64, 1> = Lti::first_order(1.0, 10.0, h).unwrap();
    let (mut peak, mut imax) = (f64::MIN, 0.0f64);
    for _ in 0..3000 {
        let y = p.free_output();
        let u = c.update(1.0, y);
        imax = imax.max(c.terms().i.abs());
        peak = peak.max(y);
        p.step(u);
    }
    (peak, imax)
}

#[test]
fn anti_windup_bounds_the_integrator_and_removes_the_overshoot() {
    let (peak_none, i_none) = saturated_run(AntiWindup::None);
    let (peak_linear, _) = run(AntiWindup::None, f64::INFINITY);
    for aw in [
        AntiWindup::BackCalculation { tt: 5.0 },
        AntiWindup::Conditional,
    ] {
        let (peak, i) = saturated_run(aw);
        assert!(i < 1.5, "{aw:?}: integrator reached {i}");
        assert!(
            peak < peak_linear + 0.01,
            "{aw:?}: overshoot to {peak}, linear loop {peak_linear}"
        );
        assert!(peak < peak_none - 0.02, "no improvement over {peak_none}");
        assert!(i < i_none);
    }
}

#[test]
fn bumpless_manual_auto_transfers() {
    let cfg = PidConfig::isa(1.5, 4.0, 0.5, 0.1);
    let mut c = Pid::new(cfg).unwrap();
    let mut last: f64 = 0.0;
    for k in 0..50 {
        last = c.update(1.0, 0.02 * k as f64);
    }
    c.set_manual();
    let m = c.update(1.0, 1.0);
    assert_eq!(m, last, "auto→manual holds the last output");
    c.set_manual_output(0.7).unwrap();
    for _ in 0..20 {
        assert_eq!(c.update(1.0, 0.9), 0.7);
    }
    c.set_auto();
    let a = c.update(1.0, 0.9);
    assert!((a - 0.7).abs() < 0.02, "manual→auto jumped from 0.7 to {a}");
}

#[test]
fn no_derivative_kick_with_c_zero() {
    let cfg = PidConfig::isa(1.0, f64::INFINITY, 2.0, 0.1).with_weights(1.0, 0.0);
    let mut c = Pid::new(cfg).unwrap();
    c.update(0.0, 0.0);
    c.update(1.0, 0.0);
    assert_eq!(c.terms().d, 0.0);
    let cfg = PidConfig::isa(1.0, f64::INFINITY, 2.0, 0.1);
    let mut kick = Pid::new(cfg).unwrap();
    kick.update(0.0, 0.0);
    kick.update(1.0, 0.0);
    assert!(
        kick.terms().d > 1.0,
        "with c = 1 the step kicks the derivative"
    );
}

/// The first update: built new or `reset`, the first sample is the
/// derivative's reference (no kick: a controller started on a running
/// process); `reset_to_rest`, it differences against zero, the transfer
/// function's initial condition. Backward Euler through the filter
/// `Tf = Td/N`: `D = Kp·Td/(Tf + h)·Δ(c·r − y)` from zero.
#[test]
fn first_update_from_a_running_process_and_from_rest() {
    let (kp, ti, td, h, n) = (0.5f64, 4.0, 2.0, 0.1, 10.0);
    let cfg = PidConfig::isa(kp, ti, td, h);
    let mut c = Pid::new(cfg).unwrap();
    assert_eq!(c.update(1.0, 0.25), kp * 0.75, "no kick on a new PID");
    c.update(1.0, 0.5);
    c.reset();
    assert_eq!(c.update(1.0, 0.25), kp * 0.75, "none after reset");
    let kick = kp * td / (td / n + h);
    for y in [0.0, 0.25, -3.0] {
        c.reset_to_rest();
        let u = c.update(1.0, y);
        let want = kp * (1.0 - y) + kick * (1.0 - y);
        assert!((u - want).abs() <= 1e-15 * want.abs(), "{u} vs {want}");
        assert_eq!(c.terms().i, 0.0);
    }
    // through the trait and a scheme that holds a PID: the same kick
    let m: msp::ProcessModel<f64> = msp::Fopdt::new(1.0, 5.0, 1.0).unwrap().into();
    let mut sp = msp::SmithPredictor::<f64, 1, [f64; 16]>::from_model(cfg, &m, h).unwrap();
    msp::Controller::reset_to_rest(&mut sp);
    let u = msp::Controller::update(&mut sp, 1.0, 0.0);
    assert!((u - (kp + kick)).abs() <= 1e-15 * u, "{u}");
    msp::Controller::reset(&mut sp);
    assert_eq!(msp::Controller::update(&mut sp, 1.0, 0.0), kp);
}

#[test]
fn tracking_input_and_rate_limit() {
    let cfg = PidConfig::isa(1.0, 1.0, 0.0, 0.1).with_rate_limit(1.0);
    let mut c = Pid::new(cfg).unwrap();
    let u0: f64 = c.update(1.0, 0.0);
    let u1 = c.update(1.0, 0.0);
    assert!((u1 - u0).abs() <= 0.1 + 1e-12);
    let mut t = Pid::new(PidConfig::isa(1.0, 1.0, 0.0, 0.1)).unwrap();
    for _ in 0..200 {
        t.update_tracking(1.0, 0.0, 0.3);
    }
    assert!(
        t.terms().i < 0.3,
        "integrator follows the actuator's real value"
    );
}

#[test]
fn nan_measurement_holds_the_output() {
    let mut c = Pid::new(PidConfig::isa(1.0, 2.0, 0.0, 0.1)).unwrap();
    let u = c.update(1.0, 0.5);
    assert_eq!(c.update(1.0, f64::NAN), u);
    assert!(c.fault());
    assert!(c.update(1.0, 0.5).is_finite());
    assert!(!c.fault());
}

/// An unlimited PI runs a short path; the same PI with limits it never reaches
/// runs the general one. Both must give the same outputs and terms, through a
/// sensor fault, a manual period and their recoveries.
#[test]
fn the_short_pi_path_equals_the_general_path() {
    let cfg = PidConfig::isa(1.7, 4.0, 0.0, 0.1).with_weights(0.6, 1.0);
    let mut short = Pid::new(cfg).unwrap();
    let mut general = Pid::new(cfg.with_limits(-1e300, 1e300)).unwrap();
    let mut p: Lti<f64, 1> = Lti::first_order(2.0, 7.0, 0.1).unwrap();
    for k in 0..600 {
        let y = p.free_output();
        let y_meas = if (200..210).contains(&k) { f64::NAN } else { y };
        let r = if k < 300 { 1.0 } else { -0.5 };
        if k == 400 {
            short.set_manual();
            general.set_manual();
        }
        if k == 450 {
            short.set_auto();
            general.set_auto();
        }
        let (a, b) = (short.update(r, y_meas), general.update(r, y_meas));
        assert_eq!(a, b, "sample {k}");
        assert_eq!(short.terms(), general.terms(), "sample {k}");
        assert_eq!(short.fault(), general.fault(), "sample {k}");
        p.step(a);
    }
}

/// The IMC-PID of `K/(s(Ts + 1))` is the IMC-PI of `K/s` in series with the
/// lead `Ts + 1`: its ISA form has the same frequency response as that series
/// product at every frequency, and with the lag it gives the IMC-PI's loop.
#[test]
fn imc_pid_for_an_integrator_with_a_lag_is_the_series_form() {
    let m = msp::Foipdt::new(2.0, 3.0, 1.0).unwrap();
    let lambda = 0.25;
    let g = msp::tuning::imc_pid_integrating_lag(&m, lambda).unwrap();
    // the IMC-PI of K/s: Kp = 2/(Kλ), Ti = 2λ (Bag (2022) Eqs. 4.30-4.31)
    let (kc, ti): (f64, f64) = (2.0 / (m.k * lambda), 2.0 * lambda);
    for w in [0.01f64, 0.1, 1.0, 10.0] {
        // ISA: Kp(1 + 1/(jω Ti) + jω Td)
        let isa = (g.kp, g.kp * (w * g.td - 1.0 / (w * g.ti)));
        // series: Kc(1 + 1/(jω Ti))(1 + jω T)
        let (a, b) = (1.0, -1.0 / (w * ti));
        let (c, d) = (1.0, w * m.t);
        let series = (kc * (a * c - b * d), kc * (a * d + b * c));
        assert!(
            (isa.0 - series.0).abs() < 1e-12 * series.0.abs().max(1.0),
            "{w}"
        );
        assert!(
            (isa.1 - series.1).abs() < 1e-12 * series.1.abs().max(1.0),
            "{w}"
        );
    }
}

/// Retuning `Td` keeps the derivative filter's `N = Td/Tf`: an unfiltered
/// derivative (`N = ∞`, `Tf = 0`) stays unfiltered, a filtered one keeps its
/// ratio, and a derivative switched on from none takes the default `N = 10`.
#[test]
fn retune_keeps_the_derivative_filter_ratio() {
    use msp::operate::Gain;
    let unfiltered = PidConfig::<f64>::isa(2.0, 5.0, 1.0, 0.1).with_filter(f64::INFINITY);
    let mut c = Pid::new(unfiltered).unwrap();
    c.retune(Gain::Td, 0.4).unwrap();
    assert_eq!(c.config().tf, 0.0);
    let mut c = Pid::<f64>::new(PidConfig::isa(2.0, 5.0, 1.0, 0.1).with_filter(4.0)).unwrap();
    c.retune(Gain::Td, 2.0).unwrap();
    assert!((c.config().tf - 0.5).abs() < 1e-15, "{}", c.config().tf);
    let mut c = Pid::<f64>::new(PidConfig::isa(2.0, 5.0, 0.0, 0.1)).unwrap();
    c.retune(Gain::Td, 2.0).unwrap();
    assert!((c.config().tf - 0.2).abs() < 1e-15, "{}", c.config().tf);
}

/// A manual output given and then auto mode: the next output continues from
/// the manual value (for an unchanged error, the proportional term moves it
/// by nothing more), as the operator left it; pid-rs and simple-pid users
/// expect `set_auto_mode` to start from the last output.
#[test]
fn auto_mode_continues_from_the_manual_output() {
    let mut c = Pid::new(PidConfig::isa(2.0, 10.0, 0.0, 0.1)).unwrap();
    c.set_manual();
    c.set_manual_output(25.0).unwrap();
    c.set_auto();
    // zero error: no proportional or integral change, the output is 25
    let u = c.update(3.0, 3.0);
    assert_eq!(u, 25.0);
}

/// Finite measurements whose terms leave the float range are a fault: the
/// output is held, the fault raised, and the next normal samples give finite
/// outputs again (no state latches ±∞ or NaN) — with and without limits.
#[test]
fn finite_inputs_never_latch_non_finite_states() {
    for limits in [false, true] {
        let mut cfg = PidConfig::isa(3.0, 5.0, 0.5, 0.1);
        if limits {
            cfg = cfg.with_limits(-10.0, 10.0);
        }
        let mut c = Pid::new(cfg).unwrap();
        let before = c.update(1.0, 0.5);
        let u = c.update(0.0, f64::MAX);
        assert!(u.is_finite(), "limits {limits}: {u}");
        assert!(c.fault(), "limits {limits}: the sample is a fault");
        let mut last = f64::NAN;
        for _ in 0..50 {
            last = c.update(1.0, 0.5);
            assert!(last.is_finite(), "limits {limits}: {last}");
        }
        assert!(!c.fault());
        assert!(before.is_finite() && last.is_finite());
        let mut c = Pid::new(cfg).unwrap();
        let u = c.update(0.0, 1.7e308);
        assert!(
            u.is_finite() && c.update(0.0, 0.0).is_finite(),
            "limits {limits}"
        );
    }
}

/// pid-rs's tests (braincore/pid-rs, `src/lib.rs`: `pid`, `derivative`,
/// `output_limit`) on msp's Pid: per-sample gains are the parallel form at
/// `Ts = 1`, pid-rs's derivative on the measurement is `c = 0` unfiltered.
/// The proportional and derivative terms are pid-rs's at every sample; the
/// integral differs by msp's convention (forward Euler: the error of sample
/// `k` enters at `k + 1`), so msp's `i` at `k` is pid-rs's at `k − 1`.
#[test]
fn pid_rs_combined_operation() {
    let cfg = PidConfig::<f64>::parallel(1.0, 0.1, 1.0, 1.0)
        .with_filter_time(0.0)
        .with_weights(1.0, 0.0);
    let mut c = Pid::new(cfg).unwrap();
    // pid-rs: (y, p, i, d) with its i including the present error
    let pid_rs: [(f64, f64, f64, f64); 4] = [
        (0.0, 10.0, 1.0, 0.0),
        (5.0, 5.0, 1.5, -5.0),
        (11.0, -1.0, 1.4, -6.0),
        (10.0, 0.0, 1.4, 1.0),
    ];
    let mut i_before = 0.0f64;
    for (y, p, i, d) in pid_rs {
        let u = c.update(10.0, y);
        let t = c.terms();
        assert!((t.p - p).abs() < 1e-12, "p at y = {y}: {} vs {p}", t.p);
        assert!((t.d - d).abs() < 1e-12, "d at y = {y}: {} vs {d}", t.d);
        assert!(
            (t.i - i_before).abs() < 1e-12,
            "i at y = {y}: {} vs {i_before}",
            t.i
        );
        assert!((u - (p + i_before + d)).abs() < 1e-12);
        i_before = i;
    }
    // output limits clamp the sum (pid-rs `output_limit`)
    let mut c = Pid::new(PidConfig::parallel(1.0, 0.0, 0.0, 1.0).with_limits(-1.0, 1.0)).unwrap();
    assert_eq!(c.update(10.0, 0.0), 1.0);
    assert_eq!(c.terms().p, 10.0);
    assert_eq!(c.update(10.0, 20.0), -1.0);
    assert_eq!(c.terms().p, -10.0);
    // derivative alone: none on the first measurement, then −kd·Δy (pid-rs `derivative`)
    let cfg = PidConfig::parallel(0.0, 0.0, 2.0, 1.0)
        .with_filter_time(0.0)
        .with_weights(1.0, 0.0);
    let mut c = Pid::new(cfg).unwrap();
    assert_eq!(c.update(10.0, 0.0), 0.0);
    assert_eq!(c.update(10.0, 5.0), -10.0);
}

/// A P controller made PI by an operator (`retune(Ti, 5)` of one built with
/// `Ti = ∞`) gets the anti-windup a PI built with `Ti = 5` has: held at its
/// limit by a large error and then given a set point it can reach, it
/// leaves the limit on the same sample as that PI, and computes the same
/// outputs to rounding (it had no anti-windup, and wound up for tens of
/// seconds).
#[test]
fn an_integral_turned_on_by_a_retune_does_not_wind_up() {
    use msp::operate::Gain;
    let ts = 0.1;
    let build =
        |ti: f64| Pid::new(PidConfig::isa(2.0, ti, 0.0, ts).with_limits(-1.0, 1.0)).unwrap();
    let mut retuned = build(f64::INFINITY);
    retuned.retune(Gain::Ti, 5.0).unwrap();
    let mut built = build(5.0);
    // each on its own plant y+ = 0.9·y + 0.1·u (a gain of one), the set
    // point out of reach for 100 s (u held at its limit 1, y at 1), then 0.2
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let (mut ya, mut yb) = (0.0, 0.0);
    for k in 0..2000 {
        let r = if k < 1000 { 50.0 } else { 0.2 };
        let (ua, ub) = (retuned.update(r, ya), built.update(r, yb));
        (ya, yb) = (0.9 * ya + 0.1 * ua, 0.9 * yb + 0.1 * ub);
        a.push(ua);
        b.push(ub);
    }
    let left = |u: &[f64]| u.iter().skip(1000).position(|v| *v < 1.0).unwrap();
    assert_eq!(left(&a), left(&b));
    assert!(left(&a) <= 1, "{}", left(&a));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-12, "{x} {y}");
    }
}
