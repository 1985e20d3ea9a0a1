//! The schemes as a user runs them: the scenario's and the report's names,
//! the CSV's columns, reverse-acting plants, the defaults on everyday plants,
//! the chosen durations, the warnings and the metrics per event.
mod common;
use common::*;
use msp::sim::SetpointStep;
use msp::study::Scenario;

/// `Scenario::FIELDS`, which the CLI and Python are checked against, is the
/// serde form of the scenario exactly (scenario files and reports).
#[test]
fn scenario_fields_are_the_serde_fields() {
    let v = serde_json::to_value(msp::study::Scenario::default()).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    let mut want: Vec<&str> = msp::study::Scenario::FIELDS.to_vec();
    let mut got = keys.clone();
    want.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, want);
}

/// The figures' names (the CSV columns, the text table, Python's sweep
/// arrays) are the keys of the JSON report, each once, with the value
/// serde writes under it.
#[test]
fn figure_names_are_the_report_keys() {
    fn check<S: serde::Serialize>(s: &S, fields: Vec<(&'static str, f64)>) {
        let v = serde_json::to_value(s).unwrap();
        let object = v.as_object().unwrap();
        assert_eq!(object.len(), fields.len(), "{object:?}");
        for (k, x) in fields {
            // JSON has no NaN or infinity: serde writes null
            assert_eq!(object[k].as_f64(), x.is_finite().then_some(x), "{k}");
        }
    }
    let o = scenario("0.2/s*e^-7.4s").run().unwrap();
    check(&o.metrics, o.metrics.fields().collect());
    check(&o.metrics.step, o.metrics.step.fields().to_vec());
    check(&o.metrics.indices, o.metrics.indices.fields().to_vec());
    let m = o.robustness.unwrap();
    check(&m, m.fields().to_vec());
}

/// Every scheme's CSV has unique column names: its internal signals never
/// take the name of a column of the run (`d`, the disturbance, was also the
/// PID's derivative term).
#[test]
fn csv_columns_are_unique_for_every_scheme() {
    use msp::poly::PlantKind;
    for s in msp::registry::SCHEMES {
        let mut sc = msp::study::Scenario {
            controller: Some(s.name.to_string()),
            duration: Some(5.0),
            ..Default::default()
        };
        if s.is_cascade() {
            sc.plant = if s.plants.contains(&PlantKind::Unstable) {
                "e^-4s/(20s-1)"
            } else {
                "e^-4s/(20s+1)"
            }
            .parse()
            .ok();
            sc.inner_plant = Some("2e^-2s/(20s+1)".parse().unwrap());
            sc.ts = Some(0.2);
            sc.set = common::required_settings(s.name).into_iter().collect();
        } else {
            sc.plant = match s.plants.first() {
                Some(PlantKind::Integrating) => "0.2/s*e^-7.4s",
                Some(PlantKind::Unstable) => "5*e^-6s/(100s-1)",
                _ => "5.6*e^-93.9s/(40.2s+1)",
            }
            .parse()
            .ok();
            sc.ts = Some(0.1);
        }
        let out = sc.run().unwrap_or_else(|e| panic!("{}: {e}", s.name));
        let mut csv = Vec::new();
        out.result.write_csv(&mut csv).unwrap();
        let head = String::from_utf8(csv).unwrap();
        let names: Vec<&str> = head.lines().next().unwrap().split(',').collect();
        let mut sorted = names.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), names.len(), "{}: {names:?}", s.name);
    }
}

#[test]
fn every_scheme_controls_a_reverse_acting_plant_as_its_mirror() {
    // A plant of negative gain (a cooling process) under the controller tuned
    // for it is the mirror of the positive plant's loop: the controller's
    // gains change sign, so y is the same and u changes sign.
    for s in msp::registry::SCHEMES {
        let (p1, p2, ts) = common::plant_for(s);
        let negated = format!("-({p1})");
        let base = |plant: &str| {
            let mut sc = Scenario {
                inner_plant: p2.clone(),
                controller: Some(s.name.into()),
                ts: Some(ts),
                ..scenario(plant)
            };
            // Uma et al.'s Gcd is set by hand: mirrored with the plant
            let sign = if plant == negated { -1.0 } else { 1.0 };
            sc.set = common::required_settings(s.name)
                .into_iter()
                .map(|(k, v)| (k, sign * v))
                .collect();
            sc
        };
        let pos = base(&p1.to_string()).run();
        let neg = base(&negated).run();
        let (pos, neg) = match (pos, neg) {
            (Ok(a), Ok(b)) => (a, b),
            (a, b) => panic!(
                "{}: {:?} / {:?}",
                s.name,
                a.err(),
                b.err().map(|e| e.to_string())
            ),
        };
        let scale = pos.result.y.iter().fold(1.0f64, |m, y| m.max(y.abs()));
        for (k, (a, b)) in pos.result.y.iter().zip(&neg.result.y).enumerate() {
            assert!(
                (a - b).abs() <= 1e-9 * scale,
                "{}: y[{k}] {a} vs {b}",
                s.name
            );
        }
        let uscale = pos.result.u.iter().fold(1.0f64, |m, u| m.max(u.abs()));
        for (k, (a, b)) in pos.result.u.iter().zip(&neg.result.u).enumerate() {
            assert!(
                (a + b).abs() <= 1e-9 * uscale,
                "{}: u[{k}] {a} vs {b}",
                s.name
            );
        }
    }
}

#[test]
fn pi_is_a_pi_tuned_by_simc_on_the_first_order_model() {
    // Skogestad (2003): K e^{-θs}/(τ1 s + 1) → kp = τ1/(K(τc + θ)), ti = min(τ1, 4(τc + θ)),
    // τc = θ by default; a second lag τ2 goes half to τ1, half to θ; K/s → τ1 → ∞.
    let scheme = msp::registry::find("pi").unwrap();
    let cases = [
        ("5.6*e^-93.9s/(40.2s+1)", 5.6, 40.2, 93.9),
        ("e^-10s/(s+1)^2", 1.0, 1.5, 10.5),
        ("2*e^-1s/((10s+1)*(2s+1))", 2.0, 11.0, 2.0),
    ];
    for (plant, k, t1, theta) in cases {
        let tf: msp::poly::TransferFunction = plant.parse().unwrap();
        let p = scheme.tune_with(&tf, None, &[]).unwrap();
        let tc = theta;
        assert_close(p.get("kp").unwrap(), t1 / (k * (tc + theta)), 1e-12, 0.0);
        assert_close(p.get("ti").unwrap(), t1.min(4.0 * (tc + theta)), 1e-12, 0.0);
        assert_eq!(p.get("td"), Some(0.0), "{plant}");
        // pid on the same plant keeps its derivative where the model has a second lag
        let pid = msp::registry::find("pid").unwrap();
        let q = pid.tune_with(&tf, None, &[]).unwrap();
        if plant.contains("(2s+1)") || plant.contains("^2") {
            assert!(q.get("td").unwrap() > 0.0, "{plant}");
        }
    }
    // integrating: kp = 1/(K(τc + θ)), ti = 4(τc + θ)
    let p = scheme
        .tune_with(&"0.2/s*e^-7.4s".parse().unwrap(), None, &[])
        .unwrap();
    assert_close(p.get("kp").unwrap(), 1.0 / (0.2 * 14.8), 1e-12, 0.0);
    assert_close(p.get("ti").unwrap(), 4.0 * 14.8, 1e-12, 0.0);
    // a PID rule is refused by name, not silently stripped
    let zn = scheme.tune_rule(&"e^-10s/(s+1)^2".parse().unwrap(), None, Some("zn"), &[]);
    assert!(zn.is_err());
    assert!(scheme
        .tune_rule(&"e^-10s/(s+1)^2".parse().unwrap(), None, Some("zn-pi"), &[])
        .is_ok());
}

/// `msp run --plant EXPR` with nothing else, for plants a process engineer
/// meets every day: integrating plants with lags or zeros, and plants without
/// dead time. A dead-time-dominant integrating plant gets the Matausek–Micić
/// predictor, a lag-dominant or delay-free one the SIMC PID (the predictor
/// tuned on `θ + T` destabilises the delay-free `2/(s(2s + 1)^2)`). The default loop settles on the set point and rejects an input
/// load with zero steady error (a sampled loop with integral action on an
/// integrating plant: the error of the final samples is at rounding level).
#[test]
fn the_defaults_control_everyday_plants() {
    for (plant, scheme) in [
        ("e^-1.5s/(s*(s+1))", "matausek-micic"),
        ("2/(s*(10s+1))*e^-1s", "pid"),
        ("e^-1.5s*(2s+1)/(s*(s+1)*(0.5s+1))", "matausek-micic"),
        ("0.5/(s*(2s+1)^2)*e^-3s", "matausek-micic"),
        ("2/(s*(2s+1)^2)*e^-1s", "pid"),
        ("1/(s*(s+1))", "pid"),
        ("2/(s*(2s+1)^2)", "pid"),
        ("1/s", "pid"),
        ("0.2/s*e^-7.4s", "karan-dey"),
        // delay-free stable plants: the PID the Smith predictor would run anyway
        ("1/(s+1)^2", "pid"),
        ("2/(5s+1)", "pid"),
        ("2*e^-1s/(5s+1)", "smith"),
    ] {
        let sc = Scenario {
            duration: Some(900.0),
            disturbance: vec![load(-0.1, 450.0)],
            ..scenario(plant)
        };
        let o = sc.run().unwrap_or_else(|e| panic!("{plant}: {e}"));
        assert_eq!(o.controller, scheme, "{plant}");
        let y = &o.result.y;
        let settled = |to: usize| y[to - 50..to].iter().all(|v| (v - 1.0).abs() < 1e-6);
        let before_load = (450.0 / o.ts) as usize;
        assert!(
            settled(before_load),
            "{plant}: y = {} before the load",
            y[before_load]
        );
        assert!(
            settled(y.len()),
            "{plant}: y = {} at the end",
            y[y.len() - 1]
        );
    }
    // a delay-free plant needs no --lambda: λ is half the largest time constant
    let o = run("1/(s+1)^2", "pid", |_| {});
    assert_eq!(o.params.lambda(), Some(0.5));
}

/// The Karan–Dey MSP is designed for an IPDT model: on an integrating plant
/// with a lag it says so and names the scheme that takes the whole model.
#[test]
fn karan_dey_names_the_scheme_for_an_integrating_plant_with_lags() {
    let sc = Scenario {
        controller: Some("karan-dey".into()),
        ..scenario("2/(s*(3s+1))*e^-1s")
    };
    let e = sc.run().unwrap_err().to_string();
    assert!(e.contains("IPDT") && e.contains("matausek-micic"), "{e}");
}

/// `pi` is a PI on every plant: on an integrator with a lag SIMC's rule gives
/// a PID (`td = T`), so the PI is tuned on the IPDT with the lag in the delay.
#[test]
fn pi_has_no_derivative_on_an_integrator_with_a_lag() {
    let o = run("2/(s*(3s+1))*e^-1s", "pi", |sc| {
        sc.duration = Some(1000.0);
    });
    assert_eq!(o.params.get("td"), Some(0.0));
    let pid = run("2/(s*(3s+1))*e^-1s", "pid", |sc| {
        sc.duration = Some(300.0);
    });
    assert!(pid.params.get("td").unwrap() > 0.0);
    assert!((o.result.y.last().unwrap() - 1.0).abs() < 1e-6);
}

/// The automatic duration covers settling for a chain of lags, whose slowest
/// single time constant (10 s) is a quarter of what it takes (their sum, 40 s).
#[test]
fn the_chosen_duration_covers_a_chain_of_lags() {
    let sc = scenario("2*e^-5s/(10s+1)^4");
    let o = sc.run().unwrap();
    assert!(o.duration_chosen);
    let settle = o.metrics.step.settling_time;
    assert!(
        settle.is_finite() && settle < 0.5 * o.duration,
        "settling {settle} in {} s",
        o.duration
    );
}

/// The Smith predictor on an integrator with a lag: its PID (kp 28, ti 3.5,
/// td 0.4286, N 10) cancels the lag, so the loop settles as the delay-free
/// continuous one, `C·G/(1 + C·G)` with `G = 2/(s(3s + 1))`, whose step
/// overshoots 18.5 % (python-control's `step_response`; 9.2 % with the
/// derivative on the measurement alone: the set point's kick is part of
/// it); tuned for the half-rule IPDT instead (the lag folded into the
/// delay the predictor removes) it diverged.
#[test]
fn smith_cancels_the_lag_of_an_integrating_plant() {
    let o = run("2/(s*(3s+1))*e^-1s", "smith", |sc| sc.duration = Some(40.0));
    let over = o.metrics.step.overshoot;
    // sampled (ZOH, the filter by backward Euler): within a percent of it
    assert!((over - 18.5).abs() < 1.0, "overshoot {over} %");
    assert!((o.result.y.last().unwrap() - 1.0).abs() < 1e-4);
}

/// A plant no scheme can control gets a message that says so in those words
/// and names what would work, never a field the user did not set.
#[test]
fn uncontrollable_plants_are_named_as_such() {
    for (plant, controller, words) in [
        ("1/s^2", None, "more than one integrator"),
        ("e^-2s/(s^2*(s+1))", None, "inner loop"),
        ("s/(s+1)", None, "zero at the origin"),
        ("s^2/(s+1)^2", Some("pid"), "no static gain"),
        ("1/s", Some("karan-dey"), "use pid"),
        ("1/s", Some("matausek-micic"), "use pid"),
        ("1/(s^2+1)", None, "imaginary axis"),
        ("1/(s*(s-1))", None, "an integrator and an unstable pole"),
        ("1/(s-1)^2", None, "more than one unstable pole"),
        ("e^-1s", None, "without dynamics"),
        ("2", Some("pid"), "static gain or a pure dead time"),
    ] {
        let sc = Scenario {
            controller: controller.map(Into::into),
            ..scenario(plant)
        };
        let e = sc.run().unwrap_err().to_string();
        assert!(e.contains(words), "{plant}: {e}");
        for field in ["`k`", "`ki`", "`l`", "`lambda`", "`t`"] {
            assert!(!e.contains(field), "{plant}: {e}");
        }
    }
}

/// A loop that diverges before the model's dead time has passed leaves no
/// sample for the delayed-reference metrics: they are NaN (null in the
/// report), never 0; the integral indices of the whole run are NaN too (they
/// grow without bound), and the warning says where the data and metrics stop.
#[test]
fn a_diverging_loop_never_reads_as_perfect() {
    let sc = Scenario {
        controller: Some("pid".into()),
        set: [("kp".to_string(), 1e308)].into_iter().collect(),
        ..scenario("0.2/s*e^-7.4s")
    };
    let o = sc.run().unwrap();
    assert!(o.result.diverged_at.is_some());
    let d = o.metrics_delayed_reference;
    for (k, v) in d.fields() {
        assert!(v.is_nan(), "{k} = {v}");
    }
    // the integrals of a diverged run are unbounded: no number, not a partial sum
    for (k, v) in o.metrics.indices.fields() {
        assert!(v.is_nan(), "{k} = {v}");
    }
    assert_eq!(o.stable(), Some(false));
    assert!(o.warnings()[0].contains("metrics stop there"));
}

/// A chosen duration is extended until the output has come to rest: the
/// P-only loop on `e^-s/(s+1)` with kp = 2 (a slowly decaying oscillation,
/// near the ultimate gain 2.26) needs several doublings of what the plant
/// alone suggests (its gains given in full, no λ stretches it); at kp = 2.25
/// it never settles within the cap of 16×, and the run says so. A given
/// duration is never changed.
#[test]
fn the_chosen_duration_is_extended_until_the_loop_settles() {
    let run = |kp: f64, duration: Option<f64>| {
        Scenario {
            controller: Some("pid".into()),
            set: [("kp", kp), ("ti", f64::INFINITY), ("td", 0.0)]
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            duration,
            ..scenario("e^-1s/(s+1)")
        }
        .run()
        .unwrap()
    };
    let o = run(2.0, None);
    assert!(o.duration > 20.0 && o.duration_chosen && o.has_settled());
    assert!(
        o.warnings().iter().all(|w| !w.contains("settled")),
        "{:?}",
        o.warnings()
    );
    let o = run(2.25, None);
    let plant: msp::poly::TransferFunction = "e^-1s/(s+1)".parse().unwrap();
    assert_eq!(o.duration, 16.0 * msp::study::choose_duration(&plant, o.ts));
    assert!(o.warnings()[0].contains("had not settled"));
    let o = run(2.25, Some(30.0));
    assert_eq!(o.duration, 30.0);
    assert!(o.warnings().iter().all(|w| !w.contains("settled")));
}

/// Every run carries its loop's margins and warns when the tuning is
/// fragile: the default Karan–Dey loop of the headline plant has pm ≈ 33°,
/// Ms ≈ 2.5 and a delay margin of 1.2 s (16 % of θ), and no λ of its rule
/// does better, so the warning names a scheme that does; the filtered Smith
/// predictor on `5e^-6s/(100s − 1)` has Ms ≈ 2.9 and the λ the warning names
/// gives, by `msp margins`' own analysis, Ms ≤ 2 with dm ≥ 0.2θ.
#[test]
fn runs_warn_of_fragile_tunings_and_name_a_better_one() {
    let sc = scenario("0.2/s*e^-7.4s");
    let o = sc.run().unwrap();
    let m = o.robustness.unwrap();
    assert!(
        (m.pm - 33.1).abs() < 0.1 && (m.ms - 2.52).abs() < 0.01,
        "{m:?}"
    );
    assert!((m.dm - 1.2).abs() < 0.01, "{m:?}");
    let w = o.warnings().join("\n");
    assert!(
        w.contains("16 % of the dead time") && w.contains("--controller"),
        "{w}"
    );

    let sc = Scenario {
        ts: Some(0.06),
        ..scenario("5e^-6s/(100s-1)")
    };
    let o = sc.run().unwrap();
    assert!(o.robustness.unwrap().ms > 2.0);
    let w = o.warnings().join("\n");
    let lambda: f64 = w
        .split("--lambda ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{w}"));
    let better = Scenario {
        lambda: Some(lambda),
        controller: Some(o.controller.into()),
        ..sc
    };
    let an = msp::study::analyze(&better, msp::analysis::View::Sampled, None).unwrap();
    assert!(
        an.margins.ms <= 2.0 && an.margins.dm >= 0.2 * 6.0,
        "{:?}",
        an.margins
    );
    assert_eq!(an.stable, Some(true));
}

/// Metrics per event: on `1/(s+1)` the PI with `kp = 1, ti = 1` makes the
/// loop `L = 1/s`, so each set-point step responds as `1/(s+1)` (rise
/// `ln 9`, settling `ln 50`, no overshoot — a second step is not "100 %
/// overshoot" of the first) and an input load `d` gives `y − r = d·t·e^{−t}`:
/// peak `d/e` at 1 s, back within 2 % of r = 2 when `t·e^{−t} = 0.04`, IAE
/// `|d|`. Sampled at 1 ms, the loop is the continuous one to `O(ts)`.
#[test]
fn metrics_per_event_are_the_closed_forms() {
    use msp::study::Event;
    let sc = Scenario {
        controller: Some("pid".into()),
        set: [("kp", 1.0), ("ti", 1.0), ("td", 0.0)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        ts: Some(0.001),
        duration: Some(80.0),
        setpoint: vec![
            SetpointStep {
                value: 1.0,
                at: 0.0,
            },
            SetpointStep {
                value: 2.0,
                at: 20.0,
            },
        ],
        disturbance: vec![load(-1.0, 40.0)],
        ..scenario("1/(s+1)")
    };
    let o = sc.run().unwrap();
    let tol = 5e-3;
    // the report's first-step figures are the first step's alone
    assert!(
        (o.metrics.step.overshoot).abs() < 0.1,
        "{:?}",
        o.metrics.step
    );
    assert!((o.metrics.step.settling_time - 50f64.ln()).abs() < tol);
    assert_eq!(o.events.len(), 3);
    for (i, e) in o.events.iter().take(2).enumerate() {
        let Event::Setpoint(s) = e else {
            panic!("{e:?}")
        };
        assert_eq!(s.at, 20.0 * i as f64);
        assert!((s.step.rise_time - 9f64.ln()).abs() < tol, "{s:?}");
        assert!((s.step.settling_time - 50f64.ln()).abs() < tol, "{s:?}");
        assert!(s.step.overshoot.abs() < 0.1, "{s:?}");
    }
    let Event::Disturbance(d) = o.events[2] else {
        panic!()
    };
    assert!((d.peak_deviation + (-1f64).exp()).abs() < tol, "{d:?}");
    assert!((d.peak_time - 1.0).abs() < 0.01, "{d:?}");
    // t·e^{−t} = 0.04 beyond the peak, by bisection
    let (mut a, mut b) = (1.0f64, 20.0f64);
    for _ in 0..100 {
        let m = 0.5 * (a + b);
        if m * (-m).exp() > 0.04 {
            a = m
        } else {
            b = m
        }
    }
    assert!((d.recovery_time - a).abs() < 0.01, "{d:?} vs {a}");
    assert!((d.iae - 1.0).abs() < tol, "{d:?}");
}

/// The Karan–Dey design names its three controllers (Bag (2022) Eqs.
/// 4.22–4.24) and the Routh range of γ (Eq. 4.49, `0 < γ < 1/(θm·K·Kp)`);
/// the default tuning takes its middle (Eq. 4.50).
#[test]
fn karan_dey_design_names_its_controllers_and_the_routh_range() {
    use msp::registry::DesignValue;
    let scheme = msp::registry::find("karan-dey").unwrap();
    let model: msp::poly::TransferFunction = "0.2/s*e^-7.4s".parse().unwrap();
    let p = scheme.tune_with(&model, None, &[]).unwrap();
    let d = scheme.design_report(&p, &model, None, 0.0074).unwrap();
    let get = |k: &str| {
        d.iter()
            .find(|(n, _)| *n == k)
            .map(|(_, v)| v.clone())
            .unwrap()
    };
    let kp = p.get("kp").unwrap();
    assert_eq!(get("gc1_kp"), DesignValue::Scalar(kp));
    let DesignValue::StableRange { param, low, high } = get("gamma_range") else {
        panic!()
    };
    assert_eq!((param, low), ("gamma", 0.0));
    assert_close(high, 1.0 / (7.4 * 0.2 * kp), 1e-12, 0.0);
    assert_close(p.get("gamma").unwrap(), high / 2.0, 1e-12, 0.0);
    // a γ beyond the range is warned of, naming the range and its source
    let warnings = |gamma: f64| {
        Scenario {
            plant: Some(model.clone()),
            set: [("gamma".to_string(), gamma)].into_iter().collect(),
            ..Default::default()
        }
        .tune_report(None)
        .unwrap()
        .warnings
        .join("\n")
    };
    assert!(warnings(0.2).contains("gamma = 0.2 is outside its stability range (0, 0.125)"));
    assert!(!warnings(0.1).contains("stability range"));
}

/// The fields a tuning takes are those of `Scenario::FIELDS` from the inner
/// plant to the period: what shapes the tuned controller, nothing of the
/// run (no model, no duration, no set point).
#[test]
fn tune_fields_are_the_tuning_inputs() {
    let tune = msp::study::Scenario::TUNE_FIELDS;
    assert_eq!(tune.len(), 7);
    assert_eq!(
        (tune.first(), tune.last()),
        (Some(&"inner_plant"), Some(&"ts"))
    );
    for not in ["plant", "model", "inner_model", "duration", "setpoint"] {
        assert!(!tune.contains(&not), "{not}");
    }
}
