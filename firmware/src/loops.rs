// The two closed loops, written once for f32 (firmware) and f64 (host reference,
// included by build.rs): the controller against an exactly discretized plant
// with its dead time in a delay line.

use msp::dtc::fsp::{design, FilteredSmith};
use msp::dtc::karan_dey::{self, KaranDey};
use msp::ParamList;
use msp::{
    Controller, Delay, DelayLine, Lti, Operated, PidConfig, ProcessModel, Real, SmithPredictor,
};

pub const SAMPLES: usize = 10_000;
pub const CHECKS: usize = 20;
pub const CAP: usize = 128;

/// The plant: the same ZOH block as the model, the dead time in a line.
pub struct Plant<T: Real> {
    block: Lti<T, 1>,
    line: DelayLine<T, CAP>,
}

impl<T: Real> Plant<T> {
    pub fn new(m: &ProcessModel<T>, ts: T) -> Plant<T> {
        let (block, d) = match m.discretize::<1>(ts) {
            Ok(x) => x,
            Err(_) => panic_model(),
        };
        let line = match Delay::new_in(d) {
            Ok(l) => l,
            Err(_) => panic_model(),
        };
        Plant { block, line }
    }
    pub fn output(&self) -> T {
        self.block.free_output()
    }
    /// The process's dead time changes (whole samples).
    pub fn set_dead_time(&mut self, samples: T) {
        if self.line.set_delay(samples).is_err() {
            panic_model()
        }
    }
    pub fn advance(&mut self, u: T) {
        let v = self.line.process(u);
        self.block.step(v);
    }
}

fn panic_model() -> ! {
    panic!("model")
}

pub fn smith<T: Real>() -> (SmithPredictor<T, 1, [T; CAP]>, Plant<T>) {
    // the MathWorks Smith predictor example: 5.6 e^{-93.9 s}/(40.2 s + 1), Kaya's PI, Ts = 0.939 s (100 samples of dead time)
    let ts = T::of(0.939);
    let m: ProcessModel<T> = match msp::Fopdt::new(T::of(5.6), T::of(40.2), T::of(93.9)) {
        Ok(f) => f.into(),
        Err(_) => panic_model(),
    };
    let pi = PidConfig::isa(T::of(40.2 / (5.6 * 93.9)), T::of(40.2), T::zero(), ts);
    match SmithPredictor::from_model(pi, &m, ts) {
        Ok(c) => (c, Plant::new(&m, ts)),
        Err(_) => panic_model(),
    }
}

pub fn karan_dey<T: Real>() -> (KaranDey<T, 1, [T; CAP]>, Plant<T>) {
    // Bag (2022): 0.2 e^{-7.4 s}/s with lambda = L/4, Ts = 0.074 s (100 samples of dead time)
    let ts = T::of(0.074);
    let ipdt = match msp::Ipdt::new(T::of(0.2), T::of(7.4)) {
        Ok(m) => m,
        Err(_) => panic_model(),
    };
    let p = match msp::tuning::karan_dey(&ipdt, ipdt.l / T::of(4.0)) {
        Ok(p) => p,
        Err(_) => panic_model(),
    };
    let m: ProcessModel<T> = ipdt.into();
    match karan_dey::from_model(&p, &m, ts) {
        Ok(c) => (c, Plant::new(&m, ts)),
        Err(_) => panic_model(),
    }
}

pub fn fsp<T: Real>() -> (FilteredSmith<T, [T; CAP]>, Plant<T>) {
    // Bag (2022)'s unstable benchmark 5 e^{-6 s}/(100 s - 1), Ts = 0.06 s (100 samples of
    // dead time); the PI that places a double pole at -1/lambda (lambda = L) and
    // Fr with Tf = L/2, as `msp run` tunes it; Fr and S designed here, in f64
    let (k, t, l, ts) = (5.0, 100.0, 6.0, 0.06);
    let kkc = 1.0 + 2.0 * t / l;
    let (kp, ti) = (kkc / k, kkc * l * l / t);
    let m64: ProcessModel<f64> = match msp::Ufopdt::new(k, t, l) {
        Ok(m) => m.into(),
        Err(_) => panic_model(),
    };
    let gm = match m64.discretize::<1>(ts) {
        Ok((g, _)) => g,
        Err(_) => panic_model(),
    };
    let d = match design::<[f64; CAP], 1>(&gm, 100, ts, l / 2.0) {
        Ok(d) => d,
        Err(_) => panic_model(),
    };
    let pi = PidConfig::isa(T::of(kp), T::of(ti), T::zero(), T::of(ts));
    let c = match FilteredSmith::new(pi, &d, ParamList::default()) {
        Ok(c) => c,
        Err(_) => panic_model(),
    };
    let m: ProcessModel<T> = match msp::Ufopdt::new(T::of(k), T::of(t), T::of(l)) {
        Ok(m) => m.into(),
        Err(_) => panic_model(),
    };
    (c, Plant::new(&m, T::of(ts)))
}

/// The set point (steps) and an input load at two thirds of the run.
pub fn inputs<T: Real>(k: usize) -> (T, T) {
    let r = if k < SAMPLES / 2 {
        T::one()
    } else {
        T::of(0.5)
    };
    let d = if k >= 2 * SAMPLES / 3 {
        T::of(-0.05)
    } else {
        T::zero()
    };
    (r, d)
}

/// Runs the loop, calling `tick` around each update; returns `y` at CHECKS evenly spaced samples.
#[allow(dead_code)] // build.rs runs it for the host reference
pub fn run<T: Real, C: Controller<T>>(
    c: &mut C,
    p: &mut Plant<T>,
    tick: impl FnMut(bool),
) -> [T; CHECKS] {
    run_with(c, p, tick, |c, r, y| c.update(r, y))
}

/// [`run`] with the update call given (the firmware passes a non-inlined function).
pub fn run_with<T: Real, C>(
    c: &mut C,
    p: &mut Plant<T>,
    mut tick: impl FnMut(bool),
    mut update: impl FnMut(&mut C, T, T) -> T,
) -> [T; CHECKS] {
    let mut out = [T::zero(); CHECKS];
    for k in 0..SAMPLES {
        let (r, d) = inputs::<T>(k);
        let y = p.output();
        tick(true);
        let u = update(c, r, y);
        tick(false);
        p.advance(u + d);
        if (k + 1) % (SAMPLES / CHECKS) == 0 {
            if let Some(slot) = out.get_mut((k + 1) / (SAMPLES / CHECKS) - 1) {
                *slot = y;
            }
        }
    }
    out
}

/// The Smith predictor operated as in a plant (`msp::Operated`).
pub type OperatedSmith<T> = Operated<T, SmithPredictor<T, 1, [T; CAP]>>;

/// The Smith predictor's loop with an operator: manual at the output it had
/// from sample `SAMPLES / 4` (the set point still steps under it), back to
/// automatic 500 samples later (bumpless), and the process's and the model's
/// dead time from 100 to 110 samples together at `SAMPLES * 3 / 5`.
pub fn smith_operated<T: Real>() -> (OperatedSmith<T>, Plant<T>) {
    let (c, p) = smith::<T>();
    (Operated::new(c), p)
}

/// [`run_with`] with the operator's actions of [`smith_operated`].
#[allow(dead_code)] // build.rs runs it for the host reference
pub fn run_operated<T: Real>(
    c: &mut OperatedSmith<T>,
    p: &mut Plant<T>,
    mut tick: impl FnMut(bool),
    mut update: impl FnMut(&mut OperatedSmith<T>, T, T) -> T,
) -> [T; CHECKS] {
    let mut out = [T::zero(); CHECKS];
    let mut u = T::zero();
    for k in 0..SAMPLES {
        if k == SAMPLES / 4 && c.manual(u).is_err() {
            panic_model()
        }
        if k == SAMPLES / 4 + 500 {
            c.auto();
        }
        if k == SAMPLES * 3 / 5 {
            p.set_dead_time(T::of(110.0));
            if c.set_dead_time(T::of(110.0)).is_err() {
                panic_model()
            }
        }
        let (r, d) = inputs::<T>(k);
        let y = p.output();
        tick(true);
        u = update(c, r, y);
        tick(false);
        p.advance(u + d);
        if (k + 1) % (SAMPLES / CHECKS) == 0 {
            if let Some(slot) = out.get_mut((k + 1) / (SAMPLES / CHECKS) - 1) {
                *slot = y;
            }
        }
    }
    out
}

/// The Smith predictor kept right by on-line identification: a bank of 16
/// candidate dead times (5 … 20 estimator samples of 10 controller samples
/// each: half to twice the model's 100 samples) in f32,
/// no retuning; the loop's process does not drift, so the model it starts
/// with stays (the estimator learns from the set-point steps and the load).
pub type AdaptiveSmith<T> = msp::adapt::Adaptive<T, SmithPredictor<T, 1, [T; CAP]>, (), 16, 112>;

pub fn smith_adaptive<T: Real>() -> (AdaptiveSmith<T>, Plant<T>) {
    let (c, p) = smith::<T>();
    let ts = T::of(0.939);
    // the estimator at the process's time scale: a tenth of the dead time
    // per sample (10 controller samples), candidates from half the
    // model's dead time to twice it (5 … 20 of its samples)
    let mut est = msp::adapt::EstimatorConfig::new(ts, 5);
    est.decimation = 10;
    let cfg = msp::adapt::AdaptiveConfig::new(est);
    match msp::adapt::Adaptive::new(c, (T::of(5.6), T::of(40.2), T::of(93.9)), cfg, ()) {
        Ok(a) => (a, p),
        Err(_) => panic_model(),
    }
}
