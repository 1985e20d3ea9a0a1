//! The forced response (`msp run --input`, `msp.simulate`): sampled set
//! point and loads, the run with the equivalent steps to the bit, for every
//! scheme; the recorded set point is the array; bad arrays are refused.
use msp::study::{SampledInput, Scenario};

fn grid(n: usize, ts: f64) -> Vec<f64> {
    (0..n).map(|k| k as f64 * ts).collect()
}

#[test]
fn arrays_are_the_run_with_the_equivalent_steps_for_every_scheme() {
    let ts = 0.5;
    let t = grid(401, ts);
    let r: Vec<f64> = t
        .iter()
        .map(|x| if *x < 20.0 { 0.0 } else { 1.0 })
        .collect();
    let d: Vec<f64> = t
        .iter()
        .map(|x| if *x < 120.0 { 0.0 } else { -0.1 })
        .collect();
    let d_out: Vec<f64> = t
        .iter()
        .map(|x| if *x < 160.0 { 0.0 } else { 0.05 })
        .collect();
    let cases: Vec<(&str, Option<&str>, &str)> = msp::registry::SCHEMES
        .iter()
        .filter(|s| !s.is_cascade())
        .map(|s| {
            use msp::poly::PlantKind;
            let plant = if s.plants.contains(&PlantKind::Stable) {
                "2e^-3s/(4s+1)"
            } else if s.plants.contains(&PlantKind::Integrating) {
                "0.2/s*e^-4s"
            } else {
                "e^-3s/(10s-1)"
            };
            (plant, None, s.name)
        })
        .chain([("e^-4s/(20s-1)", Some("2e^-2s/(20s+1)"), "fspcc")])
        .collect();
    for (plant, inner, name) in cases {
        let base = Scenario {
            plant: Some(plant.parse().unwrap()),
            inner_plant: inner.map(|p| p.parse().unwrap()),
            controller: Some(name.into()),
            events: vec!["200:manual=0.3".parse().unwrap()],
            ..Default::default()
        };
        let forced = base
            .clone()
            .with_input(SampledInput {
                t: &t,
                r: &r,
                d: &d,
                d_out: &d_out,
            })
            .unwrap();
        let steps = Scenario {
            ts: Some(ts),
            duration: Some(200.0),
            setpoint: vec!["0@0".parse().unwrap(), "1@20".parse().unwrap()],
            disturbance: vec![
                "input:-0.1@120".parse().unwrap(),
                "output:0.05@160".parse().unwrap(),
            ],
            ..base
        };
        let (a, b) = match (forced.run(), steps.run()) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => panic!("{name} on {plant}: {e}"),
        };
        assert_eq!(a.result.y, b.result.y, "{name}");
        assert_eq!(a.result.u, b.result.u, "{name}");
        assert_eq!(a.result.r, r, "{name}: the recorded set point is the array");
    }
}

/// A set point that changes every sample (a ramp) is followed sample by
/// sample: the recorded set point is the array itself.
#[test]
fn a_ramp_set_point_is_held_sample_by_sample() {
    let t = grid(1001, 0.1);
    let r: Vec<f64> = t.iter().map(|x| 0.01 * x).collect();
    let sc = Scenario {
        plant: Some("2e^-1s/(4s+1)".parse().unwrap()),
        controller: Some("pi".into()),
        ..Default::default()
    }
    .with_input(SampledInput {
        t: &t,
        r: &r,
        d: &[],
        d_out: &[],
    })
    .unwrap();
    let out = sc.run().unwrap();
    assert_eq!(out.result.r, r);
    assert_eq!(out.result.t.len(), t.len());
    // a ramp followed by a PI on a lag: the error settles to a constant
    // (type-1 loop): slope/(Kp·K/Ti) … it stays bounded and the output rises
    let n = out.result.y.len();
    assert!(out.result.y[n - 1] > 0.05 && (r[n - 1] - out.result.y[n - 1]).abs() < 0.05);
}

#[test]
fn bad_arrays_are_refused() {
    let base = Scenario {
        plant: Some("2e^-1s/(4s+1)".parse().unwrap()),
        ..Default::default()
    };
    let t = grid(11, 1.0);
    let ok = vec![1.0; 11];
    let try_with = |sc: Scenario, t: &[f64], r: &[f64], d: &[f64]| {
        sc.with_input(SampledInput {
            t,
            r,
            d,
            d_out: &[],
        })
        .map(|_| ())
        .map_err(|e| e.to_string())
    };
    assert!(try_with(base.clone(), &t, &ok[..10], &[])
        .unwrap_err()
        .contains("same length"));
    let mut uneven = t.clone();
    uneven[5] = 5.5;
    assert!(try_with(base.clone(), &uneven, &ok, &[])
        .unwrap_err()
        .contains("sample 6"));
    let late: Vec<f64> = t.iter().map(|x| x + 1.0).collect();
    assert!(try_with(base.clone(), &late, &ok, &[]).is_err());
    let mut nan = ok.clone();
    nan[3] = f64::NAN;
    assert!(try_with(base.clone(), &t, &nan, &[]).is_err());
    let with_ts = Scenario {
        ts: Some(0.5),
        ..base.clone()
    };
    assert!(try_with(with_ts, &t, &ok, &[])
        .unwrap_err()
        .contains("period"));
    let with_steps = Scenario {
        setpoint: vec!["1@0".parse().unwrap()],
        ..base
    };
    assert!(try_with(with_steps, &t, &ok, &[]).is_err());
}
