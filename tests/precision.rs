//! Every scheme of the registry built in `f32` computes what the `f64` build
//! computes, to `f32` rounding: the same closed loop (the plant simulated in
//! `f64`) run with each, sample for sample.
mod common;

use msp::registry::{Scheme, SCHEMES};
use msp::sim::{CascadeStepper, PlantStepper};

/// The largest difference of the plant outputs of the f32 and f64 loops,
/// relative to the largest output of the f64 loop.
fn worst(scheme: &'static Scheme) -> f64 {
    let t = common::tuned(scheme, 0.0);
    let (p1, p2, ts) = (&t.p1, &t.p2, t.ts);
    let mut c64 = t.controller::<f64>();
    let mut c32 = t.controller::<f32>();
    let n = 4000;
    let run = |update: &mut dyn FnMut(f64, f64, f64) -> f64| -> Vec<f64> {
        let mut ys = Vec::with_capacity(n);
        match &p2 {
            Some(p2) => {
                let mut sim = CascadeStepper::new(p1, p2, ts).unwrap();
                for k in 0..n {
                    let (y, y2) = sim.outputs();
                    ys.push(y);
                    let d = if k >= n / 2 { 0.1 } else { 0.0 };
                    sim.advance(update(1.0, y, y2) + d);
                }
            }
            None => {
                let mut sim = PlantStepper::new(p1, ts).unwrap();
                for k in 0..n {
                    let y = sim.output();
                    ys.push(y);
                    let d = if k >= n / 2 { 0.1 } else { 0.0 };
                    sim.advance(update(1.0, y, f64::NAN) + d);
                }
            }
        }
        ys
    };
    let cascade = p2.is_some();
    let y64 = run(&mut |r, y, y2| {
        if cascade {
            c64.update_cascade(r, y, y2)
        } else {
            c64.update(r, y)
        }
    });
    let y32 = run(&mut |r, y, y2| {
        let u = if cascade {
            c32.update_cascade(r as f32, y as f32, y2 as f32)
        } else {
            c32.update(r as f32, y as f32)
        };
        f64::from(u)
    });
    let scale = y64.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.5, "{}: the loop does not respond", scheme.name);
    y64.iter()
        .zip(&y32)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
        / scale
}

#[test]
fn every_scheme_in_f32_follows_its_f64_build() {
    for scheme in SCHEMES {
        let w = worst(scheme);
        // f32 carries 24 bits (6e-8); the loops accumulate a few hundred
        // roundings, the filtered Smith predictor more: its S sums the dead
        // time's h = 100 past inputs every sample
        let tol = if scheme.name == "fsp" { 1e-3 } else { 1e-4 };
        println!("{}: {w:e}", scheme.name);
        assert!(w < tol, "{}: f32 differs by {w:e} (relative)", scheme.name);
    }
}

/// `Scenario::float32` runs the controller in f32 (every actuator value is
/// an f32 number) against the exact f64 plant, close to the f64 run. The
/// unstable plant's FSP at h = 100 samples of dead time, as in the firmware:
/// at the default h = 1000 its S, a sum over the dead time's inputs, drifts
/// in f32 (README, "Performance").
#[test]
fn a_float32_scenario_runs_the_controller_in_f32() {
    for (plant, ts) in [
        ("0.2/s*e^-7.4s", None),
        ("5.6*e^-93.9s/(40.2s+1)", None),
        ("5*e^-6s/(100s-1)", Some(0.06)),
    ] {
        let sc = msp::study::Scenario {
            plant: Some(plant.parse().unwrap()),
            ts,
            ..Default::default()
        };
        let wide = sc.run().unwrap();
        let narrow = msp::study::Scenario {
            float32: true,
            ..sc.clone()
        }
        .run()
        .unwrap();
        assert!(narrow.float32 && !wide.float32);
        assert!(
            narrow.result.u.iter().all(|u| f64::from(*u as f32) == *u),
            "{plant}: an actuator value that is not an f32"
        );
        assert!(
            wide.result.u.iter().any(|u| f64::from(*u as f32) != *u),
            "{plant}: the f64 run should not look like f32"
        );
        let scale = wide.result.y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = wide
            .result
            .y
            .iter()
            .zip(&narrow.result.y)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(worst < 1e-3 * scale, "{plant}: {worst:e}");
    }
}
