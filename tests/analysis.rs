//! Margins against independent closed forms, and the limits against simulation.
mod common;
use common::assert_close;
use msp::analysis::{margins, View};
use msp::poly::TransferFunction;
use msp::registry::{self, Build};
use msp::study::Scenario;

/// Independent margins of a continuous loop function by scanning and bisection.
fn margins_of(l: &dyn Fn(f64) -> (f64, f64)) -> (f64, f64, f64, f64) {
    let (mut gm, mut wcg, mut pm, mut wcp) = (f64::INFINITY, f64::NAN, f64::INFINITY, f64::NAN);
    let ws: Vec<f64> = (0..200_000)
        .map(|i| 1e-5 * 10f64.powf(i as f64 * 5.0 / 200_000.0))
        .collect();
    for pair in ws.windows(2) {
        let (a, b) = (l(pair[0]), l(pair[1]));
        if (a.1 > 0.0) != (b.1 > 0.0) && a.0 < 0.0 {
            let k = 1.0 / a.0.hypot(a.1);
            if k < gm {
                gm = k;
                wcg = pair[0];
            }
        }
        let (ma, mb) = (a.0.hypot(a.1), b.0.hypot(b.1));
        if (ma > 1.0) != (mb > 1.0) && wcp.is_nan() {
            wcp = pair[0];
            pm = 180.0 + a.1.atan2(a.0).to_degrees();
        }
    }
    (gm, wcg, pm, wcp)
}

fn cmul(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
fn cdiv(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

const PLANT: &str = "5.6*e^-93.9s/(40.2s+1)";

fn controller(
    name: &str,
    plant: &TransferFunction,
    ts: f64,
    set: &[(&str, f64)],
) -> msp::registry::DynController {
    let s = registry::find(name).unwrap();
    let over: Vec<(String, f64)> = set.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    let p = s.tune_with(plant, None, &over).unwrap();
    s.build_with(&p, plant, &Build::unlimited(ts)).unwrap()
}

#[test]
fn pi_and_smith_margins_of_the_matlab_example_agree_with_closed_forms() {
    let plant: TransferFunction = PLANT.parse().unwrap();
    let ts = 0.05;
    let (kp, ti) = (0.0501, 47.3);
    let p = |w: f64| {
        cdiv(
            (5.6 * (-93.9 * w).cos(), -5.6 * (93.9 * w).sin()),
            (1.0, 40.2 * w),
        )
    };
    let c = |w: f64| (kp, -kp / (ti * w));
    // PI loop
    let pi = controller("pid", &plant, ts, &[("kp", kp), ("ti", ti), ("td", 0.0)]);
    let m = margins(pi.as_ref(), &plant, ts, View::Sampled).unwrap();
    let (gm, wcg, pm, wcp) = margins_of(&|w| cmul(c(w), p(w)));
    assert_close(m.gm, gm, 0.01, 0.0);
    assert_close(m.wcg, wcg, 0.01, 0.0);
    assert_close(m.pm, pm, 0.01, 0.0);
    assert_close(m.wcp, wcp, 0.01, 0.0);
    assert_close(m.dm, pm.to_radians() / wcp, 0.01, 0.0);
    // Smith predictor with the example's PI (Kp = 0.574, Ti = 40.2): at the plant input
    // L = C/(1 + C·Gm(1 − e^{-Ls}))·P
    let (kp, ti) = (0.574, 40.2);
    let c = |w: f64| (kp, -kp / (ti * w));
    let gm_ = |w: f64| cdiv((5.6, 0.0), (1.0, 40.2 * w));
    let sp = controller("smith", &plant, ts, &[("kp", kp), ("ti", ti)]);
    let m = margins(sp.as_ref(), &plant, ts, View::Sampled).unwrap();
    let lsp = |w: f64| {
        let one_minus_d = (1.0 - (93.9 * w).cos(), (93.9 * w).sin());
        let den = (1.0, 0.0);
        let inner = cmul(cmul(c(w), gm_(w)), one_minus_d);
        cmul(cdiv(c(w), (den.0 + inner.0, den.1 + inner.1)), p(w))
    };
    let (gm, _, pm, wcp) = margins_of(&lsp);
    assert_close(m.gm, gm, 0.01, 0.0);
    assert_close(m.pm, pm, 0.01, 0.0);
    assert_close(m.wcp, wcp, 0.01, 0.0);
    // the discrete view agrees at these slow frequencies
    let d = margins(sp.as_ref(), &plant, ts, View::Discrete).unwrap();
    assert_close(d.pm, m.pm, 0.01, 0.0);
}

fn settles(plant: &str, model: &str, controller: &str, duration: f64) -> bool {
    let sc = Scenario {
        plant: Some(plant.parse().unwrap()),
        model: Some(model.parse().unwrap()),
        controller: Some(controller.into()),
        ts: Some(0.0939),
        duration: Some(duration),
        ..Default::default()
    };
    let out = sc.run().unwrap();
    let y = &out.result.y;
    if out.result.diverged_at.is_some() {
        return false;
    }
    // the oscillation in the last fifth against the one in the fifth before
    let n = y.len();
    let amp = |a: usize, b: usize| {
        let s = &y[a..b];
        s.iter().fold(f64::MIN, |m, v| m.max(*v)) - s.iter().fold(f64::MAX, |m, v| m.min(*v))
    };
    amp(4 * n / 5, n) < 0.5 * amp(3 * n / 5, 4 * n / 5) + 1e-6
}

#[test]
fn delay_margin_is_where_the_loop_starts_to_oscillate() {
    let plant: TransferFunction = PLANT.parse().unwrap();
    let ts = 0.0939;
    let c = controller("pid", &plant, ts, &[]);
    let m = margins(c.as_ref(), &plant, ts, View::Discrete).unwrap();
    assert_close(m.dm, m.pm.to_radians() / m.wcp, 1e-9, 0.0);
    let with_delay = |extra: f64| format!("5.6*e^-{}s/(40.2s+1)", 93.9 + extra);
    assert!(
        settles(&with_delay(0.9 * m.dm), PLANT, "pid", 20_000.0),
        "90 % of dm should settle"
    );
    assert!(
        !settles(&with_delay(1.05 * m.dm), PLANT, "pid", 20_000.0),
        "dm + 5 % should not settle"
    );
}

#[test]
fn karan_dey_limits_are_confirmed_by_simulation() {
    let ipdt = "0.2/s*e^-7.4s";
    let plant: TransferFunction = ipdt.parse().unwrap();
    let ts = 0.0074;
    let c = controller("karan-dey", &plant, ts, &[]);
    let m = margins(c.as_ref(), &plant, ts, View::Discrete).unwrap();
    assert!(m.gm > 1.0 && m.dm > 0.0, "{m:?}");
    let run = |k: f64, extra: f64| {
        let sc = Scenario {
            plant: Some(
                format!("{}/s*e^-{}s", 0.2 * k, 7.4 + extra)
                    .parse()
                    .unwrap(),
            ),
            model: Some(ipdt.parse().unwrap()),
            controller: Some("karan-dey".into()),
            ts: Some(ts),
            duration: Some(600.0),
            ..Default::default()
        };
        let out = sc.run().unwrap();
        let y = &out.result.y;
        let n = y.len();
        out.result.diverged_at.is_none() && y[9 * n / 10..].iter().all(|v| (v - 1.0).abs() < 0.05)
    };
    assert!(run(0.97 * m.gm, 0.0), "just inside the gain limit {}", m.gm);
    assert!(
        !run(1.03 * m.gm, 0.0),
        "just outside the gain limit {}",
        m.gm
    );
    assert!(
        run(1.0, 0.95 * m.dm),
        "just inside the delay limit {}",
        m.dm
    );
    assert!(
        !run(1.0, 1.05 * m.dm),
        "just outside the delay limit {}",
        m.dm
    );
}

/// The discrete view of a plant is the z-transform of its simulated pulse
/// response — biproper plants and fractional dead times included (the direct
/// term acts on the input in effect just before the sample).
#[test]
fn discrete_plant_is_the_transform_of_the_simulated_pulse_response() {
    use msp::analysis::DiscretePlant;
    let ts = 0.1;
    for expr in [
        "(2s+1)/(s+1)*e^-0.73s",
        "(0.5s+1)/(3s+1)*e^-0.4s",
        "(1-0.5s)/(s^2+1.4s+1)*e^-1.37s",
        "3*e^-0.25s",
    ] {
        let plant: msp::poly::TransferFunction = expr.parse().unwrap();
        let mut u = vec![0.0; 4000];
        u[0] = 1.0;
        let y = msp::sim::open_loop(&plant, ts, &u).unwrap();
        let dp = DiscretePlant::new(&plant, ts).unwrap();
        for theta in [0.01, 0.3, 1.0, 2.5, 3.1] {
            let (mut re, mut im) = (0.0, 0.0);
            for (k, yk) in y.iter().enumerate() {
                re += yk * (theta * k as f64).cos();
                im -= yk * (theta * k as f64).sin();
            }
            let p = dp.response(theta);
            let err = ((p.re - re).powi(2) + (p.im - im).powi(2)).sqrt();
            assert!(
                err < 1e-9 * p.abs().max(1.0),
                "{expr} at {theta}: {p:?} vs ({re}, {im})"
            );
        }
    }
}

/// The verdict on the nominal loop comes from boundedness, not from where the
/// output settles: a P-only loop on `1/(s+1)` settles at `k/(1 + k)` and is
/// stable; with a dead time of one time constant its ultimate gain is
/// `≈ 2.26` (ω tan-free: `ω = −tan ω`, `k_u = √(1 + ω²)`), so `k = 3` is
/// unstable; a probe that cannot run is reported as such, not as unstable.
#[test]
fn stability_verdicts_are_true() {
    let verdict = |plant: &str, kp: &str, max_memory: Option<u64>| {
        let mut sc = Scenario {
            plant: Some(plant.parse().unwrap()),
            controller: Some("pid".into()),
            ..Default::default()
        };
        for (k, v) in [("kp", kp), ("ti", "inf"), ("td", "0")] {
            sc.set.insert(k.into(), v.parse().unwrap());
        }
        sc.max_memory = max_memory;
        let an = msp::study::analyze(&sc, View::Sampled, None).unwrap();
        (an.stable, an.stability)
    };
    for (plant, kp, want) in [
        ("1/(s+1)", "1", true),
        ("e^-1s/(s+1)", "2", true),
        ("e^-1s/(s+1)", "3", false),
    ] {
        let (stable, why) = verdict(plant, kp, None);
        assert_eq!(stable, Some(want), "{plant} kp {kp}: {why:?}");
        // the simulation agrees
        assert_eq!(why.simulation, Some(want), "{why:?}");
        assert!(why.reason.contains("agrees"), "{}", why.reason);
    }
    // the verdict is the characteristic equation's: a simulation that cannot
    // run only loses the cross-check, and says so
    let (stable, why) = verdict("e^-1s/(s+1)", "1", Some(100_000));
    assert_eq!(stable, Some(true));
    assert_eq!(why.simulation, None);
    assert!(why.reason.contains("could not run"), "{}", why.reason);
}

/// Without a controller the loop is the bare plant (MATLAB's `margin(G)`):
/// `G = 1/(s³ + 2s² + 3s + 4)` crosses −180° at `ω = √3` where `|G| = 1/2`,
/// so the continuous view gives `gm = 2` exactly and a gain of 0.5 doubles
/// it; the hold of the sampled view costs phase, so its `gm` is smaller.
/// `ms` is refined to its peak: against `max|1/(1 + G)|` found on a dense
/// grid and golden-section search here.
#[test]
fn bare_plant_margins_are_matlabs() {
    let analyze = |view: View, kp: Option<f64>| {
        let mut sc = Scenario {
            plant: Some("1/(s^3+2s^2+3s+4)".parse().unwrap()),
            ..Default::default()
        };
        if let Some(k) = kp {
            sc.set.insert("kp".into(), k);
        }
        msp::study::analyze(&sc, view, None).unwrap()
    };
    let c = analyze(View::Continuous, None);
    assert_eq!(c.controller, "none");
    assert_close(c.margins.gm, 2.0, 1e-9, 0.0);
    assert_close(c.margins.wcg, 3f64.sqrt(), 1e-9, 0.0);
    assert_close(
        analyze(View::Continuous, Some(0.5)).margins.gm,
        4.0,
        1e-9,
        0.0,
    );
    assert!(analyze(View::Sampled, None).margins.gm < 1.95);
    assert_eq!(c.stable, Some(true));
    // |S(jω)| of the bare loop, independently
    let s_abs = |w: f64| {
        let (re, im) = (4.0 - 2.0 * w * w, 3.0 * w - w * w * w);
        // 1/(1 + 1/D) = D/(D + 1)
        (re.hypot(im)) / (re + 1.0).hypot(im)
    };
    let (mut best, mut at) = (0.0, 0.0);
    for i in 1..200_000 {
        let w = i as f64 * 1e-4;
        if s_abs(w) > best {
            (best, at) = (s_abs(w), w);
        }
    }
    let (mut a, mut b) = (at - 1e-4, at + 1e-4);
    for _ in 0..200 {
        let (c1, c2) = (a + (b - a) / 3.0, b - (b - a) / 3.0);
        if s_abs(c1) > s_abs(c2) {
            b = c2;
        } else {
            a = c1;
        }
    }
    assert_close(c.margins.ms, s_abs((a + b) / 2.0), 1e-12, 0.0);
    // an unknown key for a bare loop names the one that applies
    let mut sc = Scenario {
        plant: Some("1/(s+1)".parse().unwrap()),
        controller: Some("none".into()),
        ..Default::default()
    };
    sc.set.insert("ti".into(), 3.0);
    let e = msp::study::analyze(&sc, View::Sampled, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("kp"), "{e}");
}

/// The step grid resolves the fastest mode that matters: a slow pole
/// cancelled by a zero leaves `y ≈ 1 − e^{−t/τf}`, whose 10–90 % rise is
/// `τf·ln 9` with `τf` the fast pole's time constant — msp picked its grid
/// from the slow pole and reported 17 times that.
#[test]
fn the_step_grid_resolves_the_fast_mode() {
    let plant: TransferFunction = "(1.067e5s + 5.791e4)/(10.67s^2 + 1.067e5s + 5.791e4)"
        .parse()
        .unwrap();
    // the fast pole: the larger root of 10.67 s² + 1.067e5 s + 5.791e4
    let (a, b, c) = (10.67f64, 1.067e5f64, 5.791e4f64);
    let fast = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    let want = -(9f64.ln()) / fast;
    let s = msp::analysis::step_response(&plant, None, None).unwrap();
    assert!(
        (s.info.rise_time - want).abs() < 0.01 * want,
        "{} vs {want}",
        s.info.rise_time
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // a grid the user gives is kept, and a coarse one is said to be coarse
    let s = msp::analysis::step_response(&"1/(s+1)".parse().unwrap(), Some(1.0), None).unwrap();
    assert_eq!(s.ts, 1.0);
    assert!(s.warnings[0].contains("coarse"));
}

/// An integrating or unstable plant's response does not settle: every step
/// figure is NaN (null in JSON), not the window's last peak.
#[test]
fn step_information_of_unsettled_responses_is_nan() {
    for plant in ["0.2/s*e^-7.4s", "e^-1s/(5s-1)"] {
        let s = msp::analysis::step_response(&plant.parse().unwrap(), None, None).unwrap();
        for (k, v) in s.info.fields() {
            assert!(v.is_nan(), "{plant}: {k} = {v}");
        }
    }
}

/// `step_info` of one's own data against MATLAB's documented `stepinfo`
/// example (Control System Toolbox, "Numeric Values of Time-Domain System
/// Characteristics"): `H = tf([8 18 32],[1 6 14 24])`, `stepinfo(H)` gives
/// RiseTime 0.2087, SettlingTime 3.4972, SettlingMin 1.1956, SettlingMax
/// 1.6871, Overshoot 26.5302, Undershoot 0, Peak 1.6871, PeakTime 0.5987,
/// and 4.8896 with a settling threshold of 0.005. The step response is
/// sampled exactly (ZOH of a step) every 10⁻⁴ s; MATLAB's `yfinal` is the
/// DC gain 32/24. The interpolated crossings within half the last printed
/// digit; the peak is a sample of MATLAB's coarser grid (checked on the
/// curve).
#[test]
fn step_info_of_data_is_matlab_s_stepinfo() {
    use msp::metrics::{step_info_of_data, StepInfoOptions};
    let h: TransferFunction = "(8s^2+18s+32)/(s^3+6s^2+14s+24)".parse().unwrap();
    let dt = 1e-4;
    let mut b = h.to_lti::<3>(dt).unwrap();
    let n = 100_001;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let y: Vec<f64> = (0..n).map(|_| b.step(1.0)).collect();
    let yf = Some(32.0 / 24.0);
    let s = step_info_of_data(&t, &y, None, yf, StepInfoOptions::default()).unwrap();
    let close = |got: f64, want: f64, tol: f64| {
        assert!((got - want).abs() <= tol, "{got} vs MATLAB {want} ({s:?})")
    };
    close(s.rise_time, 0.2087, 6e-5);
    close(s.settling_time, 3.4972, 6e-5);
    close(s.settling_min, 1.1956, 6e-5);
    close(s.undershoot, 0.0, 0.0);
    // MATLAB's peak is a sample of its own coarser time grid: the curve
    // passes through (0.5987, 1.6871) and its true maximum, which the fine
    // data find, is a little higher and later
    let at = |x: f64| {
        let k = (x / dt).floor() as usize;
        y[k] + (x / dt - k as f64) * (y[k + 1] - y[k])
    };
    close(at(0.5987), 1.6871, 6e-5);
    assert!(
        s.peak >= 1.6871 && s.peak - 1.6871 < 3e-4 && s.peak_time > 0.5987,
        "{s:?}"
    );
    // the overshoot is the peak's: MATLAB's 26.5302 is 100·(1.6871/(4/3) − 1)
    close(100.0 * (1.6871 * 0.75 - 1.0), 26.5302, 1e-2);
    close(s.overshoot, 100.0 * (s.peak * 0.75 - 1.0), 1e-9);
    close(s.settling_max, s.peak, 0.0);
    let tight = StepInfoOptions {
        settling_threshold: 0.005,
        ..Default::default()
    };
    let s = step_info_of_data(&t, &y, None, yf, tight).unwrap();
    // (MATLAB interpolates on its coarser grid: 2·10⁻⁴ here)
    close(s.settling_time, 4.8896, 2e-4);
    // bad data is refused, not misread
    assert!(step_info_of_data(&t[..3], &y[..2], None, None, Default::default()).is_err());
    assert!(step_info_of_data(&[0.0, 0.0], &[0.0, 1.0], None, None, Default::default()).is_err());
    let wide = StepInfoOptions {
        rise_limits: (0.9, 0.1),
        ..Default::default()
    };
    assert!(step_info_of_data(&t, &y, None, None, wide).is_err());
}

/// The unwrapped phase is the closed form `−atan(ω) − ωθ` of the bare plant
/// `e^{−θs}/(s + 1)` (continuous view), however far the delay turns it —
/// thousands of degrees over the grid, many turns between neighbours.
#[test]
fn unwrapped_phase_is_the_closed_form() {
    let sc = Scenario {
        plant: Some("e^-20s/(s+1)".parse().unwrap()),
        controller: Some("none".into()),
        ..Default::default()
    };
    let an = msp::study::analyze(&sc, View::Continuous, None).unwrap();
    let p = an.response.phase_unwrapped(20.0);
    assert!(p.len() == an.response.w.len() && p.len() > 800);
    for (w, got) in an.response.w.iter().zip(&p) {
        let want = (-w.atan() - 20.0 * w).to_degrees();
        assert!(
            (got - want).abs() < 1e-9 * want.abs().max(1.0),
            "ω {w}: {got} vs {want}"
        );
    }
    assert!(p.last().unwrap() < &-10_000.0);
}
