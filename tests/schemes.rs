//! The dead-time compensators of the sources: each one's defining property.
mod common;
use common::*;
use msp::sim::{Disturbance, SetpointStep, Shape};
use msp::study::{RunOutput, Scenario};

#[test]
fn every_modified_scheme_removes_the_load_offset_of_the_smith_predictor() {
    // Draganović et al. (2001) introduction: the classic SP leaves an offset K·L·d under a constant
    // input load on an integrating plant; every modification removes it.
    let with_load = |sc: &mut Scenario| {
        sc.duration = Some(400.0);
        sc.ts = Some(0.037);
        sc.disturbance = vec![load(-0.1, 100.0)];
    };
    let smith = run(IPDT, "smith", with_load);
    let last = |o: &RunOutput| *o.result.y.last().unwrap();
    assert_close(last(&smith) - 1.0, -0.2 * 7.4 * 0.1, 1e-3, 0.0);
    for c in [
        "watanabe-ito",
        "astrom-hang-lim",
        "matausek-micic",
        "kaya-atherton",
        "karan-dey",
        "disturbance-estimator",
    ] {
        let o = run(IPDT, c, with_load);
        assert!(o.result.diverged_at.is_none(), "{c} diverged");
        assert!((last(&o) - 1.0).abs() < 2e-3, "{c}: y = {}", last(&o));
        let max = o.result.y.iter().fold(0.0f64, |m, y| m.max(y.abs()));
        assert!(max < 2.0, "{c}: peak {max}");
    }
}

#[test]
fn astrom_hang_lim_set_point_is_first_order_and_independent_of_m() {
    // Eq. 4.14: y/r = k/(s + k)·e^{-Ls}, whatever M(s)
    let a = run(IPDT, "astrom-hang-lim", |sc| sc.duration = Some(40.0));
    let b = run(IPDT, "astrom-hang-lim", |sc| {
        sc.duration = Some(40.0);
        set(sc, &[("a", 0.5)]);
    });
    assert_eq!(a.result.y, b.result.y);
    assert_ne!(a.params.get("k2"), b.params.get("k2"));
    let k = a.params.get("k").unwrap();
    for (t, y) in a.result.t.iter().zip(&a.result.y) {
        let e = if *t <= 7.4 {
            0.0
        } else {
            1.0 - (-k * (t - 7.4)).exp()
        };
        // the sampled P loop has the pole 1 - k·Ts instead of e^{-k·Ts}
        assert!((y - e).abs() < 0.01, "t {t}: {y} vs {e}");
    }
}

#[test]
fn matausek_micic_set_point_is_first_order_with_time_constant_tr() {
    let o = run(IPDT, "matausek-micic", |sc| {
        sc.duration = Some(40.0);
        set(sc, &[("tr", 2.0)]);
    });
    assert_close(o.params.get("kr").unwrap(), 1.0 / (0.2 * 2.0), 1e-12, 0.0);
    assert_close(o.metrics.step.rise_time, 2.0 * 9f64.ln(), 0.01, 0.0);
    assert!(o.metrics.step.overshoot < 1e-9);
}

#[test]
fn disturbance_estimator_cases_reject_their_disturbances() {
    // Draganović et al. (2001) Sec. 4: plant e^{-5s}/(s(0.9s+1)(0.5s+1)(0.3s+1)(0.1s+1)), model e^{-6.8s}/s, Kr = 0.5
    let plant = "e^-5s/(s(0.9s+1)(0.5s+1)(0.3s+1)(0.1s+1))";
    let step = load(-0.1, 70.0);
    let ramp = Disturbance {
        shape: Shape::Ramp,
        value: -0.01,
        ..step
    };
    let w0 = 0.05;
    let sine = Disturbance {
        shape: Shape::Sine,
        value: 0.1,
        at: 37.0,
        freq: w0 / std::f64::consts::TAU,
        ..step
    };
    let cases: [(f64, Disturbance, f64); 6] = [
        (1.0, step, 0.074),
        (2.0, step, 0.136),
        (3.0, step, 0.089),
        (4.0, ramp, 0.065),
        (5.0, ramp, 0.077),
        (6.0, sine, f64::NAN),
    ];
    for (case, d, ka) in cases {
        let o = run(plant, "disturbance-estimator", |sc| {
            sc.model = Some("e^-6.8s/s".parse().unwrap());
            sc.ts = Some(0.02);
            sc.duration = Some(if case == 6.0 {
                37.0 + 2.0 * std::f64::consts::TAU / w0
            } else {
                500.0
            });
            sc.disturbance = vec![d];
            set(sc, &[("case", case), ("td", 2.0)]);
            if case == 3.0 {
                set(sc, &[("tde", 0.55 * 6.8)]);
            }
            if case == 5.0 {
                set(sc, &[("alpha", 0.7)]);
            }
        });
        assert_close(o.params.get("kr").unwrap(), 0.5, 1e-12, 0.0);
        if ka.is_finite() {
            assert!(
                (o.params.get("ka").unwrap() - ka).abs() < 6e-4,
                "case {case}: ka {}",
                o.params.get("ka").unwrap()
            );
        }
        // zero mean steady-state error over the last stretch (for the sine:
        // the second period after it starts, i.e. absorbed within about one period)
        let from = o.result.t.last().unwrap()
            - if case == 6.0 {
                std::f64::consts::TAU / w0
            } else {
                100.0
            };
        let tail: Vec<f64> = o
            .result
            .t
            .iter()
            .zip(&o.result.y)
            .filter(|(t, _)| **t >= from)
            .map(|(_, y)| y - 1.0)
            .collect();
        let mean = tail.iter().sum::<f64>() / tail.len() as f64;
        let worst = tail.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        assert!(
            mean.abs() < 1e-3 && worst < 0.02,
            "case {case}: mean {mean}, worst {worst}"
        );
    }
}

#[test]
fn filtered_smith_and_huang_keep_the_smith_set_point_response() {
    // the MathWorks Smith predictor example: with a perfect model the filter only acts on loads; with the same PI
    // the set-point response is the Smith predictor's
    let plant = "5.6*e^-93.9s/(40.2s+1)";
    let same_pi = |sc: &mut Scenario| {
        sc.ts = Some(0.939); // the dead time is 100 samples: the model error is exactly zero
        sc.duration = Some(1200.0);
        set(sc, &[("kp", 0.574), ("ti", 40.2)]);
        sc.disturbance = vec![load(-0.1, 600.0)];
    };
    let sp = run(plant, "smith", same_pi);
    for c in ["filtered-smith", "huang"] {
        let o = run(plant, c, same_pi);
        let split = o.result.t.iter().position(|t| *t > 600.0 + 93.9).unwrap();
        for i in 0..split {
            assert!(
                (o.result.y[i] - sp.result.y[i]).abs() < 1e-12,
                "{c} differs at t = {}",
                o.result.t[i]
            );
        }
        let differs =
            (split..o.result.y.len()).any(|i| (o.result.y[i] - sp.result.y[i]).abs() > 1e-3);
        assert!(differs, "{c} does not change the load response");
        assert!((o.result.y.last().unwrap() - 1.0).abs() < 1e-3);
    }
    // and the loops stay stable for the example's perturbed plants P1, P2
    for perturbed in ["5*e^-90s/(38s+1)", "6*e^-100s/(42s+1)"] {
        for c in ["smith", "filtered-smith", "huang"] {
            let o = run(perturbed, c, |sc| {
                sc.model = Some(plant.parse().unwrap());
                sc.ts = Some(1.0);
                sc.duration = Some(3000.0);
                sc.disturbance = vec![load(-0.1, 1500.0)];
            });
            assert!(o.result.diverged_at.is_none());
            assert!(
                (o.result.y.last().unwrap() - 1.0).abs() < 1e-3,
                "{c} on {perturbed}"
            );
        }
    }
}

#[test]
fn filtered_smith_default_reproduces_the_matlab_pi() {
    let plant: msp::poly::TransferFunction = "5.6*e^-93.9s/(40.2s+1)".parse().unwrap();
    let p = msp::registry::find("filtered-smith")
        .unwrap()
        .tune_with(&plant, None, &[])
        .unwrap();
    assert_close(p.get("kp").unwrap(), 0.574, 0.002, 0.0);
    assert_close(p.get("ti").unwrap(), 40.2, 1e-12, 0.0);
}

#[test]
fn pid_rules_from_the_ultimate_point() {
    // K e^{-Ls}/s: ωu = π/(2L), Ku = ωu/K, Tu = 4L
    let plant: msp::poly::TransferFunction = "0.2/s*e^-7.4s".parse().unwrap();
    let (ku, tu) = plant.ultimate().unwrap();
    assert_close(tu, 4.0 * 7.4, 1e-9, 0.0);
    assert_close(ku, std::f64::consts::PI / (2.0 * 7.4) / 0.2, 1e-9, 0.0);
    let zn = msp::registry::find("pid")
        .unwrap()
        .tune_rule(&plant, None, Some("zn"), &[])
        .unwrap();
    assert_close(zn.get("kp").unwrap(), 0.6 * ku, 1e-12, 0.0);
    assert_close(zn.get("ti").unwrap(), 0.5 * tu, 1e-12, 0.0);
    assert_close(zn.get("td").unwrap(), 0.125 * tu, 1e-12, 0.0);
    // IMC-PID of Eqs. 3.25-3.27 is the default for FOPDT plants
    let f: msp::poly::TransferFunction = "5.6*e^-93.9s/(40.2s+1)".parse().unwrap();
    let p = msp::registry::find("pid")
        .unwrap()
        .tune_with(&f, None, &[])
        .unwrap();
    assert_close(p.get("ti").unwrap(), 40.2 + 93.9 / 2.0, 1e-12, 0.0);
    // every rule of the tables gives a stable loop on the FOPDT plant? not required;
    // but each one must at least tune
    for r in msp::tuning::PI_RULES.iter().chain(msp::tuning::PID_RULES) {
        let p = msp::registry::find("pid")
            .unwrap()
            .tune_rule(&f, None, Some(r.name), &[])
            .unwrap();
        assert!(p.get("kp").unwrap() > 0.0, "{}", r.name);
    }
}

#[test]
fn compare_runs_every_controller_on_the_perturbed_plant_with_the_nominal_model() {
    let base = Scenario {
        duration: Some(60.0),
        ..scenario(IPDT)
    };
    let p = msp::study::Perturbation {
        delay: 0.1,
        ..Default::default()
    };
    let runs = msp::study::compare(&base, &["karan-dey".into(), "smith".into()], p).unwrap();
    assert_eq!(runs.len(), 2);
    for r in &runs {
        assert_close(r.plant.delay, 8.14, 1e-12, 0.0);
        assert_close(r.model.delay, 7.4, 1e-12, 0.0);
        assert_eq!(r.ts, runs[0].ts);
    }
    let _ = SetpointStep {
        value: 1.0,
        at: 0.0,
    };
}

#[test]
fn kaya_example_3_settings() {
    // Kaya (2003) Example 3, α = 0.5: FOPDT e^{-23.28s}/(3.67s+1) → Kc = 0.315, Ti = 3.670;
    // SOPDT e^{-21.01s}/(2.77s+1)² → Kc = 0.527, Ti = 5.540, Td = 1.385
    let smith = msp::registry::find("smith").unwrap();
    let a = [("alpha".to_string(), 0.5)];
    let f: msp::poly::TransferFunction = "e^-23.28s/(3.67s+1)".parse().unwrap();
    let p = smith.tune_with(&f, None, &a).unwrap();
    assert!(
        (p.get("kp").unwrap() - 0.315).abs() < 5e-4 && (p.get("ti").unwrap() - 3.67).abs() < 1e-12
    );
    let s: msp::poly::TransferFunction = "e^-21.01s/(2.77s+1)^2".parse().unwrap();
    let p = smith.tune_with(&s, None, &a).unwrap();
    assert!((p.get("kp").unwrap() - 0.527).abs() < 5e-4, "{:?}", p);
    assert!(
        (p.get("ti").unwrap() - 5.54).abs() < 1e-9 && (p.get("td").unwrap() - 1.385).abs() < 1e-9
    );
}

#[test]
fn fsp_controls_unstable_and_integrating_plants_and_rejects_loads() {
    // the thesis's unstable benchmark is the default case for `msp run`
    for (plant, controller) in [
        ("5/(100s-1)*e^-6s", None),
        ("1/((10s-1)(2s+1))*e^-1s", Some("fsp")),
        ("0.2/s*e^-7.4s", Some("fsp")),
    ] {
        let mut sc = Scenario {
            controller: controller.map(Into::into),
            ..scenario(plant)
        };
        sc.duration = Some(300.0);
        sc.disturbance = vec![load(-0.1, 150.0)];
        let o = sc.run().unwrap();
        assert_eq!(o.controller, "fsp", "{plant}");
        assert!(o.result.diverged_at.is_none(), "{plant}");
        let at = |t: f64| o.result.y[o.result.t.iter().position(|x| *x >= t).unwrap()];
        assert!(
            (at(149.0) - 1.0).abs() < 1e-3,
            "{plant}: settles, y = {}",
            at(149.0)
        );
        assert!(
            (o.result.y.last().unwrap() - 1.0).abs() < 1e-3,
            "{plant}: rejects the load"
        );
        // internally stable: the actuator stays bounded
        assert!(o.result.u.iter().all(|u| u.abs() < 20.0), "{plant}");
    }
}

/// A biproper model (García et al.'s Example 3 primary, with a zero): sampled
/// as the simulator samples the plant (the direct term acts on the input in
/// effect just before the instant, `TransferFunction::to_model_lti`), the model
/// is strictly proper and nothing is algebraic. With a perfect model the
/// prediction is the plant output one dead time ahead (the Smith principle),
/// sample for sample, and loads are rejected.
#[test]
fn fsp_handles_a_biproper_model() {
    let sc = Scenario {
        ts: Some(0.01),
        duration: Some(40.0),
        disturbance: vec![load(0.1, 20.0)],
        ..scenario("(0.1251s+1)*e^-0.8s/(2.828s-1)")
    };
    let o = sc.run().unwrap();
    assert_eq!(o.controller, "fsp");
    assert!(o.result.diverged_at.is_none());
    let pred = &o
        .result
        .signals
        .iter()
        .find(|(n, _)| n == "prediction")
        .unwrap()
        .1;
    let h = 80;
    let load_at = 2000;
    for (k, (p, y)) in pred
        .iter()
        .zip(&o.result.y[h..])
        .take(load_at - h)
        .enumerate()
    {
        assert!((y - p).abs() < 1e-9, "sample {k}: {y} vs {p}");
    }
    assert!((o.result.y.last().unwrap() - 1.0).abs() < 1e-3);
}
