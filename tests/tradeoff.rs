//! The trade-off sweep against closed forms and the loop's own figures.
use msp::study::{tradeoff, Scenario};

/// A Smith predictor with a perfect model and Kaya's tuning makes the
/// set-point response `1 − e^{−(t − L)/λ}` after the dead time (Kaya (2003)
/// Eqs. 20–21), so the IAE of a unit step is `L + λ` at every point of the
/// sweep; the sampled run's trapezoids differ by the dead time's jump
/// (`ts/2`) and the sampling of the exponential (`O(ts²/λ)`).
#[test]
fn smith_set_point_iae_is_dead_time_plus_lambda() {
    let (l, ts) = (3.0, 0.01);
    let base = Scenario {
        plant: Some("2*e^-3s/(4s+1)".parse().unwrap()),
        ts: Some(ts),
        ..Default::default()
    };
    let t = tradeoff(&base, &["smith".into()], &|_, _| {}).unwrap();
    assert_eq!(t.points.len(), msp::study::tradeoff_factors().len());
    let own = t.points.iter().find(|p| p.default).unwrap();
    assert_eq!(own.lambda, l, "Kaya's λ = L is the scheme's own");
    for p in &t.points {
        assert_eq!(p.stable, Some(true), "{p:?}");
        let want = l + p.lambda;
        assert!(
            (p.iae_setpoint - want).abs() <= ts,
            "λ {}: IAE {} vs L + λ = {want}",
            p.lambda,
            p.iae_setpoint
        );
        assert_eq!(p.load_rejected, Some(true));
    }
    // more robust as λ grows: Ms falls, the load's IAE rises
    for w in t.points.windows(2).skip(6) {
        assert!(w[1].ms < w[0].ms && w[1].iae_load > w[0].iae_load, "{w:?}");
    }
}

/// Each point's Ms is the tuned loop's own analysis (`tune_report` at that
/// λ); a load a scheme cannot reject (the Smith predictor on an integrator,
/// Bag (2022) Sec. 4.3) has an infinite IAE, and the MSP rejects it.
#[test]
fn points_are_the_loops_and_offsets_are_infinite() {
    let base = Scenario {
        plant: Some("0.2/s*e^-7.4s".parse().unwrap()),
        ..Default::default()
    };
    let t = tradeoff(&base, &["smith".into(), "karan-dey".into()], &|_, _| {}).unwrap();
    for p in t
        .points
        .iter()
        .filter(|p| p.stable == Some(true))
        .step_by(3)
    {
        let one = Scenario {
            controller: Some(p.scheme.into()),
            lambda: Some(p.lambda),
            ts: Some(t.ts),
            ..base.clone()
        };
        let ms = one.tune_report(None).unwrap().robustness.unwrap().ms;
        assert!((ms - p.ms).abs() <= 1e-9 * ms, "{p:?}: {ms}");
        match p.scheme {
            "smith" => assert!(p.iae_load.is_infinite() && p.load_rejected == Some(false)),
            _ => assert!(p.iae_load.is_finite() && p.load_rejected == Some(true)),
        }
    }
    // the default list: every single-loop scheme for an integrating plant tuned by λ
    let all = tradeoff(&base, &[], &|_, _| {}).unwrap();
    assert!(all.points.iter().any(|p| p.scheme == "karan-dey"));
    assert!(all
        .points
        .iter()
        .all(|p| { msp::registry::find(p.scheme).is_ok_and(|s| !s.is_cascade()) }));
}
