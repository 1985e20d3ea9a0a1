//! Design targets (`--target`, MATLAB `pidtune`'s options): the λ solved
//! for each figure, checked by the loop's own analysis on a fine grid (not
//! the solver's coarse one), and the refusals of targets out of reach.
use msp::analysis::{margins, View};
use msp::study::{Scenario, Target};

fn scenario(plant: &str, controller: &str, target: &str) -> Scenario {
    Scenario {
        plant: Some(plant.parse().unwrap()),
        controller: Some(controller.into()),
        target: Some(target.parse().unwrap()),
        ..Default::default()
    }
}

/// The tuned loop's figures from the full analysis (6000 frequencies), on
/// the model as the plant, at the period the tuning chose.
fn figures(sc: &Scenario) -> (msp::analysis::Margins, f64) {
    let plant = sc.plant.clone().unwrap();
    let b = sc.build_controller(&plant).unwrap();
    let m = margins(b.controller.as_ref(), &plant, b.ts, View::Sampled).unwrap();
    let lambda = b.params.lambda().unwrap();
    (m, lambda)
}

#[test]
fn every_figure_is_met_on_the_loop() {
    let fopdt = "2*e^-3s/(4s+1)";
    let cases = [
        ("pi", "ms=1.4"),
        ("pid", "ms=1.6"),
        ("smith", "ms=1.3"),
        ("pi", "pm=60"),
        ("smith", "pm=70"),
        ("pi", "gm=3"),
        ("pid", "gm=9.5dB"),
        ("smith", "dm=0.5θ"),
        ("pi", "dm=2"),
        ("pi", "wc=0.15"),
    ];
    for (controller, target) in cases {
        let sc = scenario(fopdt, controller, target);
        let report = sc.tune_report(None).unwrap();
        let t = report.controller.target.clone().expect("target report");
        let want: Target = target.parse().unwrap();
        let value = want.resolved(3.0);
        let (m, lambda) = figures(&sc);
        let got = t.figure.of(&m);
        // the bisection stops at a relative width of 1e-6 in λ; the fine
        // grid's crossovers are refined to f64 precision: within 1e-3
        assert!(
            (got - value).abs() <= 1e-3 * value,
            "{controller} {target}: the loop has {got}, asked {value}"
        );
        assert!(
            (t.lambda.unwrap() - lambda).abs() <= 1e-12 * lambda,
            "{t:?} vs {lambda}"
        );
        assert!((t.achieved - value).abs() <= 1e-3 * value, "{t:?}");
        assert_eq!(report.stable, Some(true));
    }
}

#[test]
fn a_target_out_of_reach_names_the_range_and_who_reaches_it() {
    // the Karan–Dey MSP's structure keeps its Ms above 2 on 0.2e^{-7.4s}/s
    let sc = scenario("0.2/s*e^-7.4s", "karan-dey", "ms=1.4");
    let e = sc.tune_report(None).unwrap_err().to_string();
    assert!(
        e.contains("out of reach") && e.contains("karan-dey reaches ms from"),
        "{e}"
    );
    assert!(e.contains("reached by:") && e.contains("smith"), "{e}");
    // and the scheme it names does reach it
    let ok = scenario("0.2/s*e^-7.4s", "smith", "ms=1.4");
    let t = ok.tune_report(None).unwrap().controller.target.unwrap();
    assert!((t.achieved - 1.4).abs() < 1.4e-3, "{t:?}");
}

#[test]
fn targets_are_refused_where_they_cannot_apply() {
    for bad in [
        "ms=0.9", "pm=200", "gm=1", "dm=-1", "wc=0", "xx=1", "ms", "pm=5θ", "ms=3dB",
    ] {
        assert!(bad.parse::<Target>().is_err(), "{bad}");
    }
    // with a λ given, or a rule without one
    let mut sc = scenario("2*e^-3s/(4s+1)", "pi", "ms=1.4");
    sc.lambda = Some(2.0);
    assert!(sc
        .tune_report(None)
        .unwrap_err()
        .to_string()
        .contains("one or the other"));
    let mut sc = scenario("2*e^-3s/(4s+1)", "pid", "ms=1.4");
    sc.rule = Some("zn".into());
    assert!(sc.tune_report(None).is_err());
}

/// `compare --target`: every scheme solved for the same target (instead of
/// the default equal robustness), each run's λ the one its tuning reports.
#[test]
fn compare_takes_a_common_target() {
    let base = Scenario {
        plant: Some("2*e^-3s/(4s+1)".parse().unwrap()),
        target: Some("ms=1.5".parse().unwrap()),
        ..Default::default()
    };
    let runs =
        msp::study::compare(&base, &["pi".into(), "smith".into()], Default::default()).unwrap();
    for r in &runs {
        let t = r.target.as_ref().expect("solved");
        assert!((t.achieved - 1.5).abs() < 1.5e-3, "{t:?}");
        assert_eq!(r.params.lambda(), t.lambda);
    }
}
