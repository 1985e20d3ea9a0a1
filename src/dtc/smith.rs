//! The classic Smith predictor.
//!
//! Structure (Kaya (2003) Fig. 1, Bag (2022)
//! Figs. 4.4–4.5, Eq. 4.5): the primary controller `Gc` acts on
//!
//! `e'[k] = r[k] − y_m[k] − (y[k] − y_m[k − d])`,
//!
//! where `y_m = G_m·u` is the output of the delay-free model and
//! `y_m[k − d]` the same output delayed by the model dead time `d` (samples).
//! With a perfect model the feedback signal is the delay-free model output,
//! so the closed loop is `Gc·Gm/(1 + Gc·Gm)·e^{−Lm s}` (Eq. 1 of Kaya (2003)): the
//! delay-free loop, delayed. The model is ZOH-discretized, so for an integer
//! delay this identity holds sample for sample. A fractional delay is read
//! from the model output by linear interpolation (see [`crate::delay`]).

use super::DelayedModel;
use crate::delay::{Delay, DelayStorage};
use crate::{
    controller::CascadeControl, controller::Controller, controller::FrequencyResponse,
    controller::Introspect,
};
use crate::{error::Error, lti::Lti, model::ProcessModel, pid::Pid, pid::PidConfig, real::Real};
use core::ops::{Add, Mul, Sub};

/// Smith predictor around a [`Pid`], with a model of order `≤ N` and its dead
/// time in a delay line over storage `S` (`[T; D]` for firmware, `Vec<T>` on a host).
///
/// The MathWorks example's plant `5.6 e^{−93.9s}/(40.2s + 1)` at `Ts = 1 s`,
/// its PI tuned by Kaya (2003) Eqs. 20–21 (`λ = L`), the dead time in a line
/// of 128 samples; with a perfect model the loop is the delay-free one,
/// delayed (`1 − e^{−(t − L)/λ}` after the dead time):
///
/// ```
/// use msp::{tuning, Controller, Fopdt, Lti, ProcessModel, SmithPredictor};
/// let model = ProcessModel::from(Fopdt::new(5.6, 40.2, 93.9)?);
/// let gains = tuning::kaya(&model, 93.9)?;
/// let mut sp: SmithPredictor<f64, 1, [f64; 128]> =
///     SmithPredictor::from_model(gains.config(1.0), &model, 1.0)?;
/// // the plant: the same model, its dead time in a line of its own
/// let (mut plant, d) = model.discretize::<1>(1.0)?;
/// let mut line: msp::DelayLine<f64, 128> = msp::DelayLine::new(d)?;
/// let mut y = 0.0;
/// for _ in 0..400 {
///     let u = sp.update(1.0, y);
///     y = plant.step(line.process(u));
/// }
/// // 400 s: 306 s after the dead time, e^{−306/93.9} ≈ 3.8 % left
/// assert!((y - (1.0 - (-306.1f64 / 93.9).exp())).abs() < 0.02, "{y}");
/// # Ok::<(), msp::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct SmithPredictor<T, const N: usize, S> {
    pid: Pid<T>,
    model: DelayedModel<T, N, S>,
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> SmithPredictor<T, N, S> {
    /// A predictor from its parts. The model must be strictly proper (no direct
    /// feed-through), or the loop would be algebraic.
    pub fn new(pid: PidConfig<T>, model: Lti<T, N>, delay: Delay<T, S>) -> Result<Self, Error> {
        let model = DelayedModel::new(model, delay)?;
        Ok(SmithPredictor {
            pid: Pid::new(pid)?,
            model,
        })
    }

    /// The primary controller.
    pub fn pid(&self) -> &Pid<T> {
        &self.pid
    }
    /// The primary controller, mutable (manual mode, presets).
    pub fn pid_mut(&mut self) -> &mut Pid<T> {
        &mut self.pid
    }
    /// Output of the delay-free model `y_m[k]` (the prediction of `y[k + d]`).
    pub fn prediction(&self) -> T {
        self.model.prediction()
    }
    /// The delayed model output `y_m[k − d]`.
    pub fn delayed_prediction(&self) -> T {
        self.model.delayed_prediction()
    }
    /// The model error `y[k] − y_m[k − d]` (while the measurement is not
    /// finite, the last finite one).
    pub fn model_error(&self) -> T {
        self.model.error()
    }
}

impl<T: Real, const N: usize, S: DelayStorage<T>> SmithPredictor<T, N, S> {
    /// A predictor whose model is `model` ZOH-discretized at the controller's period.
    pub fn from_model(pid: PidConfig<T>, model: &ProcessModel<T>, ts: T) -> Result<Self, Error> {
        let (block, d) = model.discretize::<N>(ts)?;
        Self::new(PidConfig { ts, ..pid }, block, Delay::new_in(d)?)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Controller<T>
    for SmithPredictor<T, N, S>
{
    // always inlined: a caller that wraps it (an operated predictor beside
    // the plain one) would otherwise pay a call on the per-sample path
    #[inline(always)]
    fn update(&mut self, r: T, y: T) -> T {
        let (ym, err) = self.model.predict(y);
        // a non-finite set point or measurement reaches the PID as such (NaN
        // propagates through `ym + err`): it holds its output (or gives its
        // fail-safe value), and the model keeps running on what the actuator
        // receives, so it still tracks the plant
        let u = self.pid.update(r, ym + err);
        self.model.advance(u);
        u
    }

    fn reset(&mut self) {
        self.pid.reset();
        self.model.reset();
    }

    fn reset_to_rest(&mut self) {
        self.pid.reset_to_rest();
        self.model.reset();
    }

    /// The PID's: a non-finite set point or measurement.
    fn fault(&self) -> bool {
        self.pid.fault()
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> crate::operate::Operate<T>
    for SmithPredictor<T, N, S>
{
    /// The model is amended to the applied input (it predicts what the plant
    /// really receives) and the PID tracks it.
    fn apply(&mut self, applied: T, how: crate::operate::Tracking) {
        let u = self.pid.output();
        if !(applied.usable() && u.is_finite()) {
            return;
        }
        self.model.amend_input(applied - u);
        self.pid.apply(applied, how);
    }

    fn dead_time(&self) -> Option<T> {
        Some(self.model.line().delay())
    }

    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.model.line_mut().set_delay(samples)
    }

    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        let line = self.model.line_mut();
        line.set_slew(per_sample)?;
        line.ramp_delay(samples)
    }

    fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), Error> {
        self.pid.retune(gain, value)
    }

    fn set_model(&mut self, gain: T, tau: T) -> Result<(), Error> {
        let model: crate::model::ProcessModel<T> = if tau.is_infinite() && tau > T::zero() {
            crate::model::Ipdt::new(gain, T::zero())?.into()
        } else {
            crate::model::Fopdt::new(gain, tau, T::zero())?.into()
        };
        let (block, _) = model.discretize::<N>(self.pid.config().ts)?;
        let g = gain_ratio(self.model.block(), &block);
        self.model.set_model(block)?;
        // the prediction and its delayed copy become the new model's
        // response to the past inputs where the models differ by their gain
        // (exact then): a predictor whose old model had settled keeps its
        // correction `y_m − y_m[k − d]`; kept from the old model's outputs
        // alone, the prediction would move to the new model's level over
        // the lag while its delayed copy waits a dead time, and the
        // controller would answer the difference (measured: a gain halved
        // at the end of a load's response, 0.8e^{-10s}/(4s + 1), kicked the
        // input by 1.5 and the output 31 % above its set point)
        if let Some(g) = g {
            self.model.rescale(g);
        }
        Ok(())
    }
}

/// The ratio of `new`'s DC gain to `old`'s; `None` where it is not a finite
/// positive number, and for integrating blocks: under a steady load an
/// integrating model's prediction ramps and its correction
/// `y_m − y_m[k − d] = K·u·θ` never settles, so rescaling it would step it
/// (kept continuous, it moves to the new gain's over one dead time).
fn gain_ratio<T: Real, const N: usize>(old: &Lti<T, N>, new: &Lti<T, N>) -> Option<T> {
    let g = new.dc_gain().ok()? / old.dc_gain().ok()?;
    (g.is_finite() && g > T::zero()).then_some(g)
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> CascadeControl<T>
    for SmithPredictor<T, N, S>
{
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Introspect<T>
    for SmithPredictor<T, N, S>
{
    fn signal_names(&self) -> &'static [&'static str] {
        &["ym", "ym_delayed", "model_error"]
    }

    fn signal(&self, i: usize) -> T {
        self.model.signals().get(i).copied().unwrap_or_else(T::nan)
    }

    fn write_signals(&self, out: &mut [T]) {
        for (o, v) in out.iter_mut().zip(self.model.signals()) {
            *o = v;
        }
    }

    fn param_names(&self) -> &'static [&'static str] {
        self.pid.param_names()
    }

    fn param(&self, i: usize) -> T {
        Introspect::param(&self.pid, i)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> SmithPredictor<T, N, S> {
    /// `(Cr, Cy)` at any [`Point`](crate::lti::zdomain::Point) (see
    /// [`FrequencyResponse::response`]).
    fn response_at<P: crate::lti::zdomain::Point<T>>(&self, at: &P) -> (P::V, P::V) {
        use crate::lti::zdomain::Algebra;
        let (g1r, g1y) = self.pid.response_at(at);
        let (gm, d) = self.model.response_at(at);
        let one = P::V::one();
        let den = one.clone() + g1y.clone() * gm * (one - d);
        (g1r / den.clone(), g1y / den)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> FrequencyResponse<T>
    for SmithPredictor<T, N, S>
{
    /// `u = G1r/(1 + G1y·Gm(1 − z^{−d}))·r − G1y/(1 + G1y·Gm(1 − z^{−d}))·y`.
    fn response(
        &self,
        theta: T,
    ) -> Option<(crate::complex::Complex<T>, crate::complex::Complex<T>)> {
        Some(self.response_at(&crate::lti::zdomain::Frequency::new(theta)))
    }

    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(crate::lti::zdomain::Rational, crate::lti::zdomain::Rational)> {
        Some(self.response_at(&crate::lti::zdomain::Symbolic))
    }

    fn inner_response(&self, theta: T) -> Option<crate::complex::Complex<T>> {
        Some(self.pid.response(theta).1.mul(self.model.response(theta).0))
    }

    /// `Nc = G1y`, `Dc = 1 + G1y·Gm(1 − z^{−d})`: the predictor's own loop.
    fn feedback_parts(
        &self,
        theta: T,
    ) -> Option<(crate::complex::Complex<T>, crate::complex::Complex<T>)> {
        use crate::complex::Complex;
        let at = crate::lti::zdomain::Frequency::new(theta);
        let (_, g1y) = self.pid.response_at(&at);
        let (gm, d) = self.model.response_at(&at);
        let one = Complex::real(T::one());
        Some((g1y, one.add(g1y.mul(gm).mul(one.sub(d)))))
    }

    fn unstable_poles(&self) -> usize {
        self.model.unstable_poles()
    }
}
