//! Operating every scheme of the registry: bumpless manual→auto and
//! tracking→auto, external reset feedback against a limit outside the
//! controller, and a run-time dead-time change at steady state.
mod common;
use common::{plant_for, required_settings};
use msp::registry::{Build, Scheme, SCHEMES};
use msp::sim::{CascadeStepper, PlantStepper};
use msp::{CascadeControl, LoopController, Operated};

/// The closed loop of one scheme with its plant, sample by sample.
struct Loop {
    c: Operated<f64, Box<dyn LoopController<f64>>>,
    single: Option<PlantStepper>,
    cascade: Option<CascadeStepper>,
}

impl Loop {
    fn new(scheme: &'static Scheme) -> Loop {
        let (p1, p2, ts) = plant_for(scheme);
        let set = required_settings(scheme.name);
        let p = scheme
            .tune_process(&p1, p2.as_ref(), None, None, &set)
            .unwrap();
        let b = Build {
            ts,
            u_min: -10.0,
            u_max: 10.0,
        };
        let c = scheme.build_process(&p, &p1, p2.as_ref(), &b).unwrap();
        let (single, cascade) = match &p2 {
            Some(p2) => (None, Some(CascadeStepper::new(&p1, p2, ts).unwrap())),
            None => (Some(PlantStepper::new(&p1, ts).unwrap()), None),
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
