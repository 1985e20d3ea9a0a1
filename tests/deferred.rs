//! A run whose figures are computed later (`Scenario::run_unmeasured`, then
//! `RunOutput::measure` and `RunOutput::analyse`: what Python's `msp.run`
//! does when the figures are read) is the run of `Scenario::run`, report for
//! report: the default protocol, a given duration, a load, an unstable
//! plant, a cascade.
use msp::sim::{Disturbance, Location, SetpointStep, Shape};
use msp::study::Scenario;

fn scenarios() -> Vec<Scenario> {
    let plant = |p: &str| Some(p.parse().unwrap());
    vec![
        Scenario {
            plant: plant("0.2/s*e^-7.4s"),
            ..Scenario::default()
        },
        Scenario {
            plant: plant("5.6*e^-93.9s/(40.2s+1)"),
            controller: Some("pi".into()),
            ts: Some(0.1),
            duration: Some(3000.0),
            setpoint: vec![SetpointStep {
                value: 1.0,
                at: 0.0,
            }],
            disturbance: vec![Disturbance {
                location: Location::Input,
                shape: Shape::Step,
                value: -0.1,
                at: 1500.0,
                freq: 0.0,
            }],
            ..Scenario::default()
        },
        Scenario {
            plant: plant("5*e^-6s/(100s-1)"),
            duration: Some(60.0),
            ..Scenario::default()
        },
        Scenario {
            plant: plant("e^-4s/(20s-1)"),
            inner_plant: plant("2e^-2s/(20s+1)"),
            ts: Some(0.2),
            duration: Some(300.0),
            ..Scenario::default()
        },
    ]
}

#[test]
fn a_deferred_run_is_the_run() {
    for sc in scenarios() {
        let eager = sc.run().unwrap();
        let mut late = sc.run_unmeasured().unwrap();
        if sc.duration.is_some() {
            // nothing measured or analysed yet
            assert!(late.events.is_empty() && late.metrics.indices.iae.is_nan());
            assert!(late.stable().is_none() && late.robustness.is_none());
        }
        late.measure().unwrap();
        late.analyse().unwrap();
        // analysing an unmeasured run measures it first: the same run
        let mut unmeasured = sc.run_unmeasured().unwrap();
        unmeasured.analyse().unwrap();
        assert_eq!(
            serde_json::to_value(unmeasured.report()).unwrap(),
            serde_json::to_value(eager.report()).unwrap()
        );
        let (a, b) = (
            serde_json::to_value(eager.report()).unwrap(),
            serde_json::to_value(late.report()).unwrap(),
        );
        assert_eq!(a, b, "{:?}", sc.plant);
        assert_eq!(eager.result, late.result);
    }
}
