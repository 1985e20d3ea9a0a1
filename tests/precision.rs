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
/// in f32 (the guide's "Performance" chapter).
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

/// A period msp chooses for an `f32` controller keeps the plant's slowest
/// pole at least 2⁻¹⁰ from 1 once sampled (`choose_ts_as`), and there the
/// `f32` loop follows the `f64` loop at the same period — where at the
/// `f64` choice (1000 samples of dead time) the filtered Smith predictor
/// of the unstable plant drifts by percents.
#[test]
fn a_chosen_f32_period_keeps_the_f32_loop_on_the_f64_one() {
    let run = |plant: &str, ts: Option<f64>, float32: bool| {
        msp::study::Scenario {
            plant: Some(plant.parse().unwrap()),
            ts,
            duration: Some(400.0),
            float32,
            ..Default::default()
        }
        .run()
        .unwrap()
    };
    let gap = |a: &msp::study::RunOutput, b: &msp::study::RunOutput| {
        let scale = a.result.y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.result
            .y
            .iter()
            .zip(&b.result.y)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    };
    for (plant, slowest) in [
        ("5*e^-6s/(100s-1)", 100.0),
        ("2*e^-1s/(30s-1)", 30.0),
        ("5.6*e^-93.9s/(40.2s+1)", 40.2),
        ("e^-5s/(60s+1)", 60.0),
        ("e^-2s/((50s+1)(3s+1))", 50.0),
        ("0.2/s*e^-7.4s", 0.0),
    ] {
        let narrow = run(plant, None, true);
        assert!(narrow.ts_chosen && narrow.ts >= slowest / 1024.0 * (1.0 - 1e-12));
        let wide = run(plant, Some(narrow.ts), false);
        let g = gap(&wide, &narrow);
        println!("{plant}: ts {} gap {g:e}", narrow.ts);
        assert!(g < 1e-3, "{plant} at {}: f32 off by {g:e}", narrow.ts);
    }
    // the f64 choice for the unstable plant, in f32: the drift the floor avoids
    let fine = run("5*e^-6s/(100s-1)", None, false);
    let drift = gap(&fine, &run("5*e^-6s/(100s-1)", Some(fine.ts), true));
    assert!(fine.ts < 100.0 / 1024.0 && drift > 1e-2, "{drift:e}");
}
