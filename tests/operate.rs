//! Operating every scheme of the registry: bumpless manual→auto and
//! tracking→auto, external reset feedback against a limit outside the
//! controller, and a run-time dead-time change at steady state.
mod common;
use msp::registry::{Build, Scheme, SCHEMES};
use msp::sim::{CascadeStepper, PlantStepper};
use msp::{CascadeControl, Controller, LoopController, Operate, Operated};

/// The closed loop of one scheme with its plant, sample by sample.
struct Loop {
    c: Operated<f64, Box<dyn LoopController<f64>>>,
    single: Option<PlantStepper>,
    cascade: Option<CascadeStepper>,
}

impl Loop {
    fn new(scheme: &'static Scheme) -> Loop {
        let t = common::tuned(scheme, 0.0);
        let c = t.controller::<f64>();
        let (single, cascade) = match &t.p2 {
            Some(p2) => (None, Some(CascadeStepper::new(&t.p1, p2, t.ts).unwrap())),
            None => (Some(PlantStepper::new(&t.p1, t.ts).unwrap()), None),
        };
        Loop {
            c: Operated::new(c),
            single,
            cascade,
        }
    }

    /// One sample at set point `r`; the plant gets `u + d`. Returns `u`.
    fn step(&mut self, r: f64, d: f64) -> f64 {
        if let Some(s) = &mut self.cascade {
            let (y, y2) = s.outputs();
            let u = self.c.update_cascade(r, y, y2);
            s.advance(u + d);
            u
        } else if let Some(s) = &mut self.single {
            let u = msp::Controller::update(&mut self.c, r, s.output());
            s.advance(u + d);
            u
        } else {
            unreachable!()
        }
    }
}

/// Auto to a steady state, then for 1500 samples the output held by hand
/// at the steady output + 0.2 (or tracking a ramp to it), then auto again:
/// the output's change at the switch, and the largest change per sample of
/// the five automatic samples after it (what the control law itself does in
/// one sample, the measure of a bumpless switch).
fn switch(scheme: &'static Scheme, tracking: bool) -> (f64, f64) {
    let mut l = Loop::new(scheme);
    let mut u = 0.0;
    for _ in 0..4000 {
        u = l.step(1.0, 0.0);
    }
    let mut forced = u;
    for k in 0..1500 {
        if tracking {
            forced = u + 0.2 * (f64::from(k) / 1000.0).min(1.0);
            l.c.track(forced).unwrap();
        } else {
            forced = u + 0.2;
            l.c.manual(forced).unwrap();
        }
        assert_eq!(l.step(1.0, 0.0), forced);
    }
    l.c.auto();
    let mut last = l.step(1.0, 0.0);
    let jump = (last - forced).abs();
    let mut law = 0.0f64;
    for _ in 0..5 {
        let next = l.step(1.0, 0.0);
        law = law.max((next - last).abs());
        last = next;
    }
    (jump, law)
}

#[test]
fn every_scheme_returns_to_auto_without_a_bump() {
    for scheme in SCHEMES {
        for tracking in [false, true] {
            let (jump, law) = switch(scheme, tracking);
            println!(
                "{} (tracking {tracking}): jump {jump:e}, then per sample {law:e}",
                scheme.name
            );
            assert!(
                jump <= 1.5 * law + 1e-9,
                "{} (tracking {tracking}): the output jumps by {jump} at the switch, the law then moves it by {law} per sample",
                scheme.name
            );
        }
    }
}

/// The plant's rational part stepped exactly, its dead time a line of whole
/// samples that can change length.
struct Plant {
    block: PlantStepper,
    line: std::collections::VecDeque<f64>,
}

impl Plant {
    fn new(p: &msp::poly::TransferFunction, ts: f64, samples: usize) -> Plant {
        let mut free = p.clone();
        free.delay = 0.0;
        Plant {
            block: PlantStepper::new(&free, ts).unwrap(),
            line: vec![0.0; samples].into(),
        }
    }
    fn output(&self) -> f64 {
        self.block.output()
    }
    fn advance(&mut self, u: f64) {
        self.line.push_back(u);
        let v = self.line.pop_front().unwrap();
        self.block.advance(v);
    }
    /// A new length, the line holding its oldest value where it grows (at a
    /// steady state every value is the same).
    fn set_samples(&mut self, n: usize) {
        while self.line.len() > n {
            self.line.pop_front();
        }
        while self.line.len() < n {
            let oldest = *self.line.front().unwrap();
            self.line.push_front(oldest);
        }
    }
}

/// The loop of `scheme` tuned for `p1` whose dead time moves from 100 to 120
/// samples at steady state (plant and model together), then a set-point
/// step; and the same controller parameters built for the 120 samples from
/// the start. The largest difference of their outputs after the step (None:
/// the scheme's dead time is part of its design and cannot change).
fn dead_time_change(scheme: &'static Scheme) -> Option<f64> {
    let (h0, h1) = (100usize, 120usize);
    let common::Tuned {
        p1,
        ts,
        params,
        build: b,
        ..
    } = common::tuned(scheme, 0.0);
    assert!((p1.delay / ts - h0 as f64).abs() < 1e-9);
    let mut p_new = p1.clone();
    p_new.delay = h1 as f64 * ts;
    let b = Build {
        max_dead_time: h1 as f64 * ts,
        ..b
    };
    let build = |model: &msp::poly::TransferFunction| {
        scheme.build_process(&params, model, None, &b).unwrap()
    };
    let (mut a, mut b) = (build(&p1), build(&p_new));
    let (mut pa, mut pb) = (Plant::new(&p1, ts, h0), Plant::new(&p1, ts, h1));
    let (change, settle, after) = (9000, 12000, 3000);
    let mut worst = 0.0f64;
    for k in 0..settle + after {
        if k == change {
            match a.set_dead_time(h1 as f64) {
                Ok(()) => pa.set_samples(h1),
                Err(msp::Error::Unsupported(_)) => return None,
                Err(e) => panic!("{}: {e}", scheme.name),
            }
        }
        let r = if k < settle { 1.0 } else { 2.0 };
        // from the change on: a change at steady state moves nothing
        if k >= change {
            worst = worst.max((pa.output() - pb.output()).abs());
        }
        let ua = a.update(r, pa.output());
        let ub = b.update(r, pb.output());
        pa.advance(ua);
        pb.advance(ub);
    }
    Some(worst)
}

#[test]
fn a_dead_time_change_at_steady_state_is_a_loop_built_for_it() {
    let mut changed = Vec::new();
    for scheme in SCHEMES.iter().filter(|s| !s.is_cascade()) {
        match dead_time_change(scheme) {
            Some(d) => {
                println!("{}: largest difference {d:e}", scheme.name);
                assert!(d < 1e-9, "{}: the runs differ by {d:e}", scheme.name);
                changed.push(scheme.name);
            }
            None => println!("{}: no dead time to change at run time", scheme.name),
        }
    }
    // the Smith predictor and the compensators of the modified schemes
    for name in [
        "smith",
        "filtered-smith",
        "huang",
        "astrom-hang-lim",
        "watanabe-ito",
        "fsp",
        "karan-dey",
        "matausek-micic",
    ] {
        assert!(
            changed.contains(&name),
            "{name} should take a new dead time"
        );
    }
}

fn scenario(plant: &str, controller: &str) -> msp::study::Scenario {
    msp::study::Scenario {
        plant: Some(plant.parse().unwrap()),
        controller: Some(controller.into()),
        setpoint: vec![msp::sim::SetpointStep {
            value: 1.0,
            at: 0.0,
        }],
        duration: Some(100.0),
        ..Default::default()
    }
}

/// An actuator limit outside the controller: with the applied value fed
/// back the response is the one the same limit gives as the controller's own
/// (overshoot within 1 % point); without it the integrators wind up.
#[test]
fn reset_feedback_keeps_an_outside_limit_from_winding_up() {
    for c in ["pi", "smith", "filtered-smith", "fsp"] {
        let own = msp::study::Scenario {
            umin: Some(0.0),
            umax: Some(0.55),
            ..scenario("2*e^-3s/(4s+1)", c)
        };
        let outside = msp::study::Scenario {
            actuator: Some((0.0, 0.55)),
            ..scenario("2*e^-3s/(4s+1)", c)
        };
        let fed = msp::study::Scenario {
            reset_feedback: true,
            ..outside.clone()
        };
        let os = |sc: &msp::study::Scenario| sc.run().unwrap().metrics.step.overshoot;
        let (a, b, w) = (os(&own), os(&fed), os(&outside));
        println!("{c}: own limit {a}, outside + feedback {b}, outside alone {w}");
        assert!((a - b).abs() <= 1.0, "{c}: {a} vs {b}");
        assert!(w > b + 0.5, "{c}: without feedback {w}, with {b}");
        // the plant got the limited value, the controller's output went beyond
        let r = outside.run().unwrap().result;
        assert!(r.u_applied.iter().all(|u| (0.0..=0.55).contains(u)));
        assert!(r.u.iter().any(|u| *u > 0.55));
    }
}

/// The command line: the process's and the model's dead time move
/// from 7.4 s to 9 s at 60 s, then the set point steps at 100 s; the run is
/// the one of a loop with 9 s from the start and the same parameters.
#[test]
fn dead_time_events_of_a_scenario() {
    let events: Vec<msp::sim::Operation> = ["60:plant-dead-time=9", "60:dead-time=9"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let base = msp::study::Scenario {
        ts: Some(0.01),
        duration: Some(200.0),
        setpoint: vec!["1@0".parse().unwrap(), "2@100".parse().unwrap()],
        ..scenario("0.2/s*e^-7.4s", "smith")
    };
    let moved = msp::study::Scenario {
        events,
        ..base.clone()
    }
    .run()
    .unwrap();
    let params = moved.params.clone();
    let mut fresh = msp::study::Scenario {
        plant: Some("0.2/s*e^-9s".parse().unwrap()),
        ..base
    };
    for (k, v) in params.iter().filter(|(k, _)| *k != "lambda") {
        fresh.set.insert(k.to_string(), v);
    }
    let fresh = fresh.run().unwrap();
    let k0 = (100.0f64 / 0.01).round() as usize;
    let worst = moved.result.y[k0..]
        .iter()
        .zip(&fresh.result.y[k0..])
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst < 1e-9, "{worst}");
    let rep = moved.report();
    assert_eq!(rep.operator_events.len(), 2);
    assert!(rep.operator_events.iter().all(|e| e.output_change < 1e-9));
}

/// The cascade schemes: the primary's transport delay moves from 2 s to
/// 3 s (the dead time from the plant input to `y`, `L1 + L2`, from 4 s to
/// 5 s) at a steady state held against a load, the controller told at the
/// same instant; after a set-point step the run is the one of a loop built
/// for 3 s from the start with the same parameters. The integrating primary
/// of García et al. (2010) Example 2, and a stable one whose output load
/// makes the generalized predictor's `ȳ` depend on the dead time (its line
/// and `Fk` are moved with the redesign). Without telling the controller the
/// runs differ (the test can fail).
#[test]
fn a_cascade_dead_time_change_is_a_loop_built_for_it() {
    let at = |v: [&str; 2]| -> Vec<msp::sim::Operation> {
        v.iter().map(|s| s.parse().unwrap()).collect()
    };
    let processes = [
        (common::EXAMPLE2.0, "2e^-3s/s", "inner:0.1@50"),
        ("e^-2s/(10s+1)", "e^-3s/(10s+1)", "output:0.3@50"),
    ];
    for (before, after, load) in processes {
        for scheme in SCHEMES.iter().filter(|s| s.is_cascade()) {
            let base = msp::study::Scenario {
                inner_plant: Some(common::EXAMPLE2.1.parse().unwrap()),
                ts: Some(0.1),
                duration: Some(700.0),
                setpoint: vec!["1@0".parse().unwrap(), "2@500".parse().unwrap()],
                disturbance: vec![load.parse().unwrap()],
                // GPCC with a prediction-error filter Fk of its own
                set: common::required_settings(scheme.name)
                    .into_iter()
                    .chain((scheme.name == "gpcc").then(|| ("tk".to_string(), 2.0)))
                    .collect(),
                ..scenario(before, scheme.name)
            };
            let run = |events| {
                msp::study::Scenario {
                    events,
                    ..base.clone()
                }
                .run()
                .unwrap()
            };
            let moved = run(at(["350:plant-dead-time=5", "350:dead-time=5"]));
            let unaware = run(at(["350:plant-dead-time=5", "350:dead-time=4"]));
            let mut fresh = msp::study::Scenario {
                plant: Some(after.parse().unwrap()),
                ..base.clone()
            };
            for (k, v) in moved.params.iter().filter(|(k, _)| *k != "lambda") {
                fresh.set.insert(k.to_string(), v);
            }
            let fresh = fresh.run().unwrap();
            // from the change on: a change at steady state moves nothing
            let k0 = 3500;
            let differ = |a: &msp::study::RunOutput| {
                a.result.y[k0..]
                    .iter()
                    .zip(&fresh.result.y[k0..])
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            };
            let (worst, off) = (differ(&moved), differ(&unaware));
            println!("{before}, {}: {worst:e} (not told: {off:e})", scheme.name);
            assert!(worst < 1e-9, "{before}, {}: {worst:e}", scheme.name);
            assert!(off > 1e-3, "{before}, {}: {off:e}", scheme.name);
        }
    }
}

/// Online retuning at a steady state with a non-zero steady output: the
/// output does not move at the change (below 1e-9), and the new gain acts
/// on the next set-point step.
#[test]
fn retuning_at_steady_state_is_bumpless() {
    for c in ["pid", "smith", "filtered-smith", "fsp"] {
        let base = msp::study::Scenario {
            setpoint: vec!["1@0".parse().unwrap(), "1.5@100".parse().unwrap()],
            duration: Some(160.0),
            ..scenario("2*e^-3s/(4s+1)", c)
        };
        let plain = base.run().unwrap();
        let kp = plain.params.get("kp").unwrap();
        for (event, what) in [
            (format!("60:kp={}", 1.5 * kp), "kp"),
            ("60:ti=20".into(), "ti"),
        ] {
            let retuned = msp::study::Scenario {
                events: vec![event.parse().unwrap()],
                ..base.clone()
            }
            .run()
            .unwrap();
            let jump = retuned.report().operator_events[0].output_change;
            println!("{c} {what}: output change at the retune {jump:e}");
            assert!(jump < 1e-9, "{c} {what}: {jump}");
            let k = (60.0 / retuned.ts).round() as usize;
            assert_eq!(&retuned.result.u[..k], &plain.result.u[..k]);
            let after = retuned.result.u.iter().zip(&plain.result.u).skip(k + 1);
            assert!(
                after.clone().any(|(a, b)| (a - b).abs() > 1e-3),
                "{c} {what}: no effect"
            );
        }
    }
    // Karan-Dey's three controllers share kp: refused, with the reason
    let kd = msp::study::Scenario {
        events: vec!["60:kp=3".parse().unwrap()],
        ..scenario("0.2/s*e^-7.4s", "karan-dey")
    };
    let e = kd.run().unwrap_err().to_string();
    assert!(e.contains("shared"), "{e}");
}

/// A drifting delay: the model's dead time slides to its new value at the
/// given rate, and a set-point ramp limits the set point the controller sees.
#[test]
fn dead_time_slews_and_the_set_point_ramps() {
    // the Smith predictor's line slides; the predictors (fsp, and gpcc on
    // its cascade) are redesigned one whole sample at a time, at the rate
    for (name, h0, whole) in [
        ("smith", 100.0, false),
        ("fsp", 100.0, true),
        ("gpcc", 40.0, true),
    ] {
        let s = msp::registry::find(name).unwrap();
        let mut l = Loop::new(s);
        // room for 30 samples more: rebuilt with it
        let t = common::tuned(s, 0.0);
        let b = Build {
            max_dead_time: (h0 + 30.0) * t.ts,
            ..t.build
        };
        let c = s.build_process(&t.params, &t.p1, t.p2.as_ref(), &b);
        l.c = Operated::new(c.unwrap());
        assert!((l.c.inner().dead_time().unwrap() - h0).abs() < 1e-9);
        l.c.inner_mut().ramp_dead_time(h0 + 20.0, 0.1).unwrap();
        for k in 1..=250 {
            l.step(1.0, 0.0);
            let moved = 0.1 * f64::from(k);
            let moved = if whole { (moved + 1e-9).floor() } else { moved };
            let want = (h0 + moved).min(h0 + 20.0);
            let got = l.c.inner().dead_time().unwrap();
            assert!(
                (got - want).abs() < 1e-9,
                "{name}, sample {k}: {got} vs {want}"
            );
        }
        // beyond the room
        assert!(l.c.inner_mut().ramp_dead_time(h0 + 40.0, 0.1).is_err());
    }
    // a correction redesigned for its dead time, a window of whole samples:
    // they take a new dead time at once, not a slide
    for name in ["watanabe-ito", "astrom-hang-lim"] {
        let s = msp::registry::find(name).unwrap();
        let t = common::tuned(s, 0.0);
        let b = Build {
            max_dead_time: 2.0 * t.p1.delay,
            ..t.build
        };
        let mut c = s.build_process(&t.params, &t.p1, None, &b).unwrap();
        let h = c.dead_time().unwrap();
        assert!(
            matches!(
                c.ramp_dead_time(h + 10.0, 0.1),
                Err(msp::Error::Unsupported(_))
            ),
            "{name}"
        );
        c.set_dead_time(h + 10.0).unwrap();
        assert_eq!(c.dead_time(), Some(h + 10.0), "{name}");
    }
    // the set-point ramp: the step reaches the controller over 10 s
    let run = |ramp: Option<f64>| {
        msp::study::Scenario {
            setpoint_ramp: ramp,
            ..scenario("2*e^-3s/(4s+1)", "smith")
        }
        .run()
        .unwrap()
    };
    let (step, ramped) = (run(None), run(Some(0.1)));
    assert!(ramped.result.u[0] < 0.2 * step.result.u[0]);
    let (a, b) = (ramped.metrics.step.rise_time, step.metrics.step.rise_time);
    assert!(a > b + 1.0, "rise {a} with the ramp, {b} without");
    assert_eq!(ramped.result.r, step.result.r); // the schedule is recorded as given
    assert!(msp::study::Scenario {
        setpoint_ramp: Some(0.0),
        ..scenario("2*e^-3s/(4s+1)", "smith")
    }
    .run()
    .is_err());
}

/// Process drift events on an open loop (manual output 1 from the start):
/// `2e^{−s}/(5s + 1)` answers `2(1 − e^{−(t−1)/5})`; at 50 s its gain becomes
/// 4 (an input gain: the output does not jump, it heads for 4 with the same
/// time constant), at 100 s its time constant 2 s (same gain, no jump);
/// every sample against the piecewise closed form. A plant without one lag
/// refuses `plant-lag`, with the reason.
#[test]
fn plant_gain_and_lag_events_follow_the_closed_form() {
    let events: Vec<msp::sim::Operation> = ["0:manual=1", "50:plant-gain=4", "100:plant-lag=2"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let ts = 0.1;
    let run = msp::study::Scenario {
        ts: Some(ts),
        duration: Some(150.0),
        setpoint: vec!["1@0".parse().unwrap()],
        events,
        ..scenario("2*e^-1s/(5s+1)", "pi")
    }
    .run()
    .unwrap();
    let y50 = 2.0 * (1.0 - (-(50.0f64 - 1.0) / 5.0).exp());
    let y100 = 4.0 + (y50 - 4.0) * (-(50.0f64) / 5.0).exp();
    let exact = |t: f64| {
        if t <= 1.0 {
            0.0
        } else if t <= 50.0 {
            2.0 * (1.0 - (-(t - 1.0) / 5.0).exp())
        } else if t <= 100.0 {
            4.0 + (y50 - 4.0) * (-(t - 50.0) / 5.0).exp()
        } else {
            4.0 + (y100 - 4.0) * (-(t - 100.0) / 2.0).exp()
        }
    };
    let worst = run
        .result
        .t
        .iter()
        .zip(&run.result.y)
        .fold(0.0f64, |m, (t, y)| m.max((y - exact(*t)).abs()));
    // rounding of a few thousand ZOH steps of a first-order block
    assert!(worst < 1e-11, "{worst:e}");
    let bad = msp::study::Scenario {
        ts: Some(ts),
        duration: Some(20.0),
        events: vec!["5:plant-lag=3".parse().unwrap()],
        ..scenario("1/(s+1)^2*e^-1s", "pi")
    }
    .run();
    let msg = match bad {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a two-lag plant refuses plant-lag"),
    };
    assert!(msg.contains("one lag"), "{msg}");
    for bad in ["5:plant-gain=0", "5:plant-lag=-1", "5:plant-lag"] {
        assert!(bad.parse::<msp::sim::Operation>().is_err(), "{bad}");
    }
}

/// A run of `plant` with `pi` and the events, sampled every 0.1 s.
fn drift_run(plant: &str, events: &[&str], duration: f64) -> msp::sim::SimResult {
    msp::study::Scenario {
        ts: Some(0.1),
        duration: Some(duration),
        events: events.iter().map(|s| s.parse().unwrap()).collect(),
        ..scenario(plant, "pi")
    }
    .run()
    .unwrap()
    .result
}

/// A drifting gain and lag, every sample against the ZOH recursion with the
/// parameter of that sample: in manual (u = 1 from 0) an integrating
/// process `K/s` with its gain drifting 0.5 → 1 at 0.01 per s from 50 s adds
/// `ts·K[n]` a sample once the dead time has passed, `K[n]` moving 0.001 a
/// sample from the sample after the event; a lag `2/(τs + 1)` drifting
/// 5 → 2 s at 0.02 s per s steps `y ← 2 + (y − 2)·e^{−ts/τ[n]}`.
#[test]
fn plant_drifts_follow_the_sampled_recursion() {
    let ts = 0.1f64;
    let r = drift_run(
        "0.5*e^-1s/s",
        &["0:manual=1", "50:plant-gain=1~0.01"],
        150.0,
    );
    let (mut y, mut worst) = (0.0f64, 0.0f64);
    for n in 0..r.y.len() {
        worst = worst.max((r.y[n] - y).abs());
        let k = (0.5 + 0.001 * (n as f64 - 500.0).max(0.0)).min(1.0);
        if n >= 10 {
            y += ts * k;
        }
    }
    // rounding of 1500 sums of about 10
    assert!(worst < 1e-10, "gain drift: {worst:e}");
    assert!(
        (r.y[1500] - r.y[1499] - ts).abs() < 1e-12,
        "arrived at K = 1"
    );

    let r = drift_run(
        "2*e^-1s/(5s+1)",
        &["0:manual=1", "50:plant-lag=2~0.02"],
        300.0,
    );
    let (mut y, mut worst) = (0.0f64, 0.0f64);
    for n in 0..r.y.len() {
        worst = worst.max((r.y[n] - y).abs());
        let tau = (5.0 - 0.002 * (n as f64 - 500.0).max(0.0)).max(2.0);
        if n >= 10 {
            y = 2.0 + (y - 2.0) * (-ts / tau).exp();
        }
    }
    assert!(worst < 1e-10, "lag drift: {worst:e}");

    for bad in [
        "5:plant-gain=2~0",
        "5:plant-lag=3~-1",
        "5:plant-dead-time=-1~0.1",
        "5:plant-gain=~1",
    ] {
        assert!(bad.parse::<msp::sim::Operation>().is_err(), "{bad}");
    }
    // the drift ends on the plant's fraction of a sample, or is refused with the reason
    let off = msp::study::Scenario {
        ts: Some(ts),
        duration: Some(20.0),
        events: vec!["5:plant-dead-time=2.05~0.1".parse().unwrap()],
        ..scenario("e^-1s/(s+1)", "pi")
    }
    .run();
    let msg = off.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(msg.contains("whole samples"), "{msg}");
}

/// A drifting dead time is the process whose dead time takes the nearest
/// whole sample of `θ0 + RATE·(t − t0)` each sample: the same run as the
/// step events at the samples where that nearest sample changes (found here
/// from the formula, not from the simulator), bit for bit, under a PI that
/// keeps the input moving (set-point steps every 40 s). Down as well as up.
#[test]
fn a_drifting_dead_time_steps_by_whole_samples() {
    let ts = 0.1f64;
    for (theta0, to, rate) in [(1.0f64, 3.0f64, 0.013f64), (3.0, 1.2, 0.0071)] {
        let plant = format!("e^-{theta0}s/(4s+1)");
        let drift = format!("20:plant-dead-time={to}~{rate}");
        let mut steps = Vec::new();
        let mut last = (theta0 / ts).round();
        for j in 1..100_000 {
            let now = theta0 / ts + (to - theta0).signum() * rate * f64::from(j);
            let now = if (to - theta0) > 0.0 {
                now.min(to / ts)
            } else {
                now.max(to / ts)
            };
            let nearest = now.round();
            if nearest != last {
                let t = 20.0 + ts * f64::from(j);
                steps.push(format!("{t:.1}:plant-dead-time={:.1}", nearest * ts));
                last = nearest;
            }
            if now == to / ts {
                break;
            }
        }
        assert!(steps.len() >= 18, "{steps:?}");
        let events = |extra: Vec<String>| {
            let mut e: Vec<String> = (1..12).map(|k| format!("{}:auto", 40 * k)).collect();
            e.extend(extra);
            e
        };
        let run = |ev: Vec<String>| {
            let ev: Vec<&str> = ev.iter().map(String::as_str).collect();
            msp::study::Scenario {
                setpoint: (0..12)
                    .map(|k| format!("{}@{}", k % 2, 40 * k).parse().unwrap())
                    .collect(),
                ..msp::study::Scenario {
                    ts: Some(ts),
                    duration: Some(480.0),
                    events: ev.iter().map(|s| s.parse().unwrap()).collect(),
                    ..scenario(&plant, "pi")
                }
            }
            .run()
            .unwrap()
            .result
        };
        let drifted = run(events(vec![drift]));
        let stepped = run(events(steps.clone()));
        let first = drifted.y.iter().zip(&stepped.y).position(|(a, b)| a != b);
        assert_eq!(first, None, "{theta0} → {to}: {steps:?}");
        assert!(drifted.diverged_at.is_none());
    }
}
