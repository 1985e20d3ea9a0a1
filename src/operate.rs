//! Operating a controller as process plants do: automatic, manual and
//! tracking modes with bumpless transfer, the value the actuator really
//! applied fed back (external reset), the model's dead time changed at run
//! time, and a rate limit on the set point.
//!
//! Every scheme implements [`Operate`]: it amends its last update as if its
//! output had been another value (the operator's, a tracked one, or what a
//! limit downstream let through). Its integrators and its predictor's model
//! then follow what the plant really received, so that the prediction stays
//! right and the return to automatic is bumpless. [`Operated`] adds the modes,
//! the external reset and the set-point ramp around any such controller.
//!
//! The amendment is exact for linear blocks: a block stepped with `u` and
//! amended by `du` has the state it would have had stepped with `u + du`
//! ([`crate::Lti::amend_input`]); integrators are set as the PID's manual
//! mode sets them (Åström & Hägglund (2006), Sec. 3.5, tracking and
//! bumpless transfer).

use crate::{controller::Controller, error::Error, real::Real};

/// How an amended output reaches the integrators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tracking {
    /// The integrators are set so that the output would have been the
    /// applied value (manual and tracking modes).
    Full,
    /// External reset feedback: the integrators move by the back-calculation
    /// gain times the difference (anti-windup against a limit outside the
    /// controller).
    Reset,
}

/// A gain of the primary PID that can be changed while the loop runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Gain {
    /// The proportional gain `Kp`.
    Kp,
    /// The integral time `Ti` (s).
    Ti,
    /// The derivative time `Td` (s).
    Td,
}

impl Gain {
    /// The gain's name in reports and `--set`.
    pub fn name(self) -> &'static str {
        match self {
            Gain::Kp => "kp",
            Gain::Ti => "ti",
            Gain::Td => "td",
        }
    }
}

/// Operation of a scheme beyond `update`: every scheme implements it.
pub trait Operate<T: Real>: Controller<T> {
    /// Amends the last update as if the controller's output had been
    /// `applied`: the integrators (as `how` says), the predictor's model and
    /// every internal controller follow it. A no-op before the first update.
    fn apply(&mut self, applied: T, how: Tracking);

    /// The model's dead time, in samples (`None`: the scheme has none that
    /// can change at run time).
    fn dead_time(&self) -> Option<T> {
        None
    }

    /// Changes the model's dead time to `samples` at once, within the
    /// capacity fixed at construction ([`Error::DelayTooLong`] beyond it;
    /// [`Error::Unsupported`] for a scheme whose design contains the dead
    /// time). At a steady state, when the delay line holds the same value
    /// throughout, the change causes no transient.
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        let _ = samples;
        Err(Error::Unsupported(
            "this scheme has no model dead time that can change at run time (none, or one its design contains): rebuild it for another",
        ))
    }

    /// Moves the model's dead time towards `samples` by at most `per_sample`
    /// samples each sample (a delay that drifts: the line's read position
    /// slides, never jumps), within the same capacity as
    /// [`Operate::set_dead_time`].
    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        let _ = per_sample;
        self.set_dead_time(samples)
    }

    /// The model's delay-free part becomes `K/(τs + 1)` (`tau` infinite:
    /// the integrating `K/s`), ZOH-discretized at the scheme's period, its
    /// output continuing from the old model's times the ratio of the gains,
    /// and its dead-time line's stored outputs alike (the Smith predictor:
    /// for a change of gain, the new model's response to the past inputs,
    /// so the predictor's correction `y_m − y_m[k − d]` does not jump; an
    /// integrating model's output only continues, unscaled);
    /// the dead time is [`Operate::set_dead_time`]'s. [`Error::Unsupported`]
    /// for a scheme whose other blocks are designed from the model (rebuild
    /// it) or that has none.
    fn set_model(&mut self, gain: T, tau: T) -> Result<(), Error> {
        let _ = (gain, tau);
        Err(Error::Unsupported(
            "this scheme's blocks are designed from its model (or it has none): rebuild it for another model",
        ))
    }

    /// Freezes (`false`) or resumes (`true`) the adaptation of an adaptive
    /// controller ([`crate::adapt::Adaptive`]): frozen, it learns and
    /// applies nothing. [`Error::Unsupported`] for one that does not adapt.
    fn set_adapting(&mut self, on: bool) -> Result<(), Error> {
        let _ = on;
        Err(Error::Unsupported(
            "this controller does not adapt (run it with adaptation: --adapt)",
        ))
    }

    /// Calls `f` with each change an adaptive controller logged, oldest
    /// first ([`crate::adapt::Adaptive::log`]); nothing for one that does
    /// not adapt.
    fn visit_log(&self, f: &mut dyn FnMut(Change<T>)) {
        let _ = f;
    }

    /// What an adaptive controller knows now ([`AdaptiveState`],
    /// [`crate::adapt::Adaptive::state`]); `None` for one that does not
    /// adapt.
    fn adaptive_state(&self) -> Option<AdaptiveState<T>> {
        None
    }

    /// The work an adaptive controller leaves for outside the sample with
    /// [`crate::adapt::AdaptiveConfig::background_design`]: the scheme a
    /// new model needs, designed ([`crate::adapt::Adaptive::design`]);
    /// whether one was. `false` for a controller with none.
    fn design(&mut self) -> bool {
        false
    }

    /// Changes a gain of the primary PID while the loop runs, bumpless: the
    /// integrator absorbs the change of the proportional and derivative
    /// terms, so that the output at the change is the one the old gains gave
    /// ([`crate::Pid::retune`]). [`Error::Unsupported`] for a scheme whose
    /// other controllers share the gain or that has no PID.
    fn retune(&mut self, gain: Gain, value: T) -> Result<(), Error> {
        let _ = (gain, value);
        Err(Error::Unsupported(
            "this scheme's gains are not a PID's alone: rebuild it with the new parameters",
        ))
    }
}

/// The operating mode of an [`Operated`] controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode<T> {
    /// The controller computes the output.
    Auto,
    /// The operator sets the output.
    Manual(T),
    /// The output follows an external value (a selector, an override).
    Track(T),
}

/// A controller with modes, external reset feedback and a set-point ramp.
///
/// In manual and tracking modes the controller keeps computing (its model
/// and filters see every measurement) and is amended to the given output
/// every sample, so that switching back to automatic is bumpless: the first
/// automatic output differs from the last applied one by what one sample of
/// the control law adds.
///
/// ```
/// use msp::{tuning, Controller, Fopdt, Operated, ProcessModel, SmithPredictor};
/// let model = ProcessModel::from(Fopdt::new(5.6, 40.2, 93.9)?);
/// let sp: SmithPredictor<f64, 1, [f64; 128]> =
///     SmithPredictor::from_model(tuning::kaya(&model, 93.9)?.config(1.0), &model, 1.0)?;
/// let mut c = Operated::new(sp);
/// c.manual(0.3)?; // the operator sets the output; the model follows it
/// assert_eq!(c.update(1.0, 0.0), 0.3);
/// c.auto(); // bumpless: the next output continues from 0.3
/// let u = c.update(1.0, 0.0);
/// assert!((u - 0.3).abs() < 0.1, "{u}");
/// c.set_dead_time(100.0)?; // samples: the model's dead time drifted
/// # Ok::<(), msp::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Operated<T, C> {
    inner: C,
    mode: Mode<T>,
    /// Largest set-point change per sample (∞: no ramp).
    ramp: T,
    r: T,
    started: bool,
}

impl<T: Real, C: Operate<T>> Operated<T, C> {
    /// `inner` in automatic mode, no set-point ramp.
    pub fn new(inner: C) -> Self {
        Operated {
            inner,
            mode: Mode::Auto,
            ramp: T::infinity(),
            r: T::zero(),
            started: false,
        }
    }

    /// The controller inside.
    pub fn inner(&self) -> &C {
        &self.inner
    }

    /// The controller inside, mutable.
    pub fn inner_mut(&mut self) -> &mut C {
        &mut self.inner
    }

    /// The mode.
    pub fn mode(&self) -> Mode<T> {
        self.mode
    }

    /// Manual mode with the output `u` (finite).
    pub fn manual(&mut self, u: T) -> Result<(), Error> {
        self.mode = Mode::Manual(crate::real::finite(u, "u")?);
        Ok(())
    }

    /// Tracking mode: the output follows `u` (finite) until [`Operated::auto`].
    pub fn track(&mut self, u: T) -> Result<(), Error> {
        self.mode = Mode::Track(crate::real::finite(u, "u")?);
        Ok(())
    }

    /// Automatic mode (bumpless from manual or tracking).
    pub fn auto(&mut self) {
        self.mode = Mode::Auto;
    }

    /// Limits the set point's change to `per_second` (`∞` turns the ramp off),
    /// for the sample period `ts`.
    pub fn set_setpoint_ramp(&mut self, per_second: T, ts: T) -> Result<(), Error> {
        if per_second.is_nan() || per_second <= T::zero() {
            return Err(Error::NotPositive("setpoint_ramp"));
        }
        self.ramp = per_second * crate::real::positive(ts, "ts")?;
        Ok(())
    }

    /// Changes the model's dead time (see [`Operate::set_dead_time`]).
    pub fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.inner.set_dead_time(samples)
    }

    /// Feeds back the value the actuator really applied for the last output
    /// (`None`: nothing to feed back) before the next update (see
    /// [`Operated::update_applied`]).
    pub fn feed_back(&mut self, applied: Option<T>) {
        if self.started {
            feed_back(&mut self.inner, self.mode, applied);
        }
    }

    /// One sample with the value the actuator really applied for the last
    /// output (`None`: what this controller gave): the controller is amended
    /// to it before computing (external reset feedback).
    pub fn update_applied(&mut self, r: T, y: T, applied: Option<T>) -> T {
        self.feed_back(applied);
        self.step(r, y)
    }

    fn step(&mut self, r: T, y: T) -> T {
        self.step_with(r, |c, r| c.update(r, y))
    }

    /// The sample around `update` (the set point ramped, the mode applied).
    fn step_with(&mut self, r: T, update: impl FnOnce(&mut C, T) -> T) -> T {
        let r = if self.ramp.is_finite() && self.started && r.is_finite() {
            crate::real::clamp(r, self.r - self.ramp, self.r + self.ramp)
        } else {
            r
        };
        self.r = r;
        self.started = true;
        let u = update(&mut self.inner, r);
        in_mode(&mut self.inner, self.mode, u)
    }
}

/// The output of a controller `c` that computed `u` in `mode`: `u` in
/// automatic; otherwise the mode's value, which `c` is amended to.
pub(crate) fn in_mode<T: Real, C: Operate<T> + ?Sized>(c: &mut C, mode: Mode<T>, u: T) -> T {
    match mode {
        Mode::Auto => u,
        Mode::Manual(v) | Mode::Track(v) => {
            c.apply(v, Tracking::Full);
            v
        }
    }
}

/// External reset feedback: in automatic, `c` is amended to the value the
/// actuator applied for its last output.
pub(crate) fn feed_back<T: Real, C: Operate<T> + ?Sized>(
    c: &mut C,
    mode: Mode<T>,
    applied: Option<T>,
) {
    if let (Some(a), Mode::Auto) = (applied, mode) {
        // an actuator value too large to compute with is not taken in
        if a.usable() {
            c.apply(a, Tracking::Reset);
        }
    }
}

impl<T: Real, C: Operate<T>> Controller<T> for Operated<T, C> {
    fn update(&mut self, r: T, y: T) -> T {
        self.step(r, y)
    }
    fn reset(&mut self) {
        self.inner.reset();
        self.started = false;
        self.r = T::zero();
    }
    fn reset_to_rest(&mut self) {
        self.reset();
        self.inner.reset_to_rest();
    }
    fn fault(&self) -> bool {
        self.inner.fault()
    }
}

impl<T: Real, C: Operate<T> + crate::controller::CascadeControl<T>>
    crate::controller::CascadeControl<T> for Operated<T, C>
{
    fn update_cascade(&mut self, r: T, y: T, y2: T) -> T {
        self.step_with(r, |c, r| c.update_cascade(r, y, y2))
    }
    fn is_cascade(&self) -> bool {
        self.inner.is_cascade()
    }
}

impl<T: Real, C: Operate<T>> Operate<T> for Operated<T, C> {
    fn apply(&mut self, applied: T, how: Tracking) {
        self.inner.apply(applied, how);
    }
    fn retune(&mut self, gain: Gain, value: T) -> Result<(), Error> {
        self.inner.retune(gain, value)
    }
    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        self.inner.ramp_dead_time(samples, per_sample)
    }
    fn dead_time(&self) -> Option<T> {
        self.inner.dead_time()
    }
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.inner.set_dead_time(samples)
    }
    fn set_model(&mut self, gain: T, tau: T) -> Result<(), Error> {
        self.inner.set_model(gain, tau)
    }
    fn set_adapting(&mut self, on: bool) -> Result<(), Error> {
        self.inner.set_adapting(on)
    }
    fn visit_log(&self, f: &mut dyn FnMut(Change<T>)) {
        self.inner.visit_log(f);
    }
    fn adaptive_state(&self) -> Option<AdaptiveState<T>> {
        self.inner.adaptive_state()
    }
    fn design(&mut self) -> bool {
        self.inner.design()
    }
}

/// What an adaptive controller knows now, under the names of its recorded
/// signals ([`crate::adapt::SIGNALS`]), which a run's CSV records every
/// sample and Python (`Controller.state`) and C (`msp_adaptive_read`) give
/// alike ([`Operate::adaptive_state`]): the
/// estimate (`k_hat`, `tau_hat`, `theta_hat`, NaN before it means
/// anything) and the `evidence` for its dead time, the model in use
/// (`k_model`, `tau_model`, `theta_model`; `tau` infinite: integrating),
/// the changes logged (`adapt_changes`) and the last one's kind
/// (`adapt_kind`, [`ChangeKind::code`]; 0 none), its error against the
/// process (`mismatch`, [`crate::adapt::Mismatch::error`]; NaN before it
/// means anything), the alarm (`model_alarm`), the estimator's counts
/// (`onsets`, `restarts`, `learnt`: 0, nothing moved the loop enough to
/// identify the process; `responses`, the responses the level test
/// compared, `responses_used`, those it took as evidence, and
/// `responses_ramps`, those it found a ramp load's) and whether adaptation
/// is `frozen`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AdaptiveState<T> {
    /// The estimate's gain (NaN before it means anything).
    pub k_hat: T,
    /// The estimate's time constant (s; infinite: integrating).
    pub tau_hat: T,
    /// The estimate's dead time (s).
    pub theta_hat: T,
    /// The evidence for the estimate's dead time ([`crate::adapt::Estimate::evidence`]).
    pub evidence: T,
    /// The model in use's gain.
    pub k_model: T,
    /// The model in use's time constant (s; infinite: integrating).
    pub tau_model: T,
    /// The model in use's dead time (s).
    pub theta_model: T,
    /// The changes logged so far.
    pub adapt_changes: u64,
    /// The last change's kind ([`ChangeKind::code`]; 0: none).
    pub adapt_kind: u8,
    /// The model in use's error against the process (0.3: 30 %; NaN before it means anything).
    pub mismatch: T,
    /// The model-error alarm.
    pub model_alarm: bool,
    /// Load onsets the estimator found and did not learn from.
    pub onsets: u32,
    /// Restarts of the estimator's change detector.
    pub restarts: u32,
    /// Estimator samples the chosen dead time learnt from.
    pub learnt: u32,
    /// Responses (a load's, a set-point change's) the level test compared ([`crate::adapt::Estimator::level_responses`]).
    pub responses: u32,
    /// Of those, the ones it took as evidence (the others held back).
    pub responses_used: u32,
    /// Of those, the ones it found a ramp load's
    /// ([`crate::adapt::Estimator::level_ramps`]: while they outnumber the
    /// ones taken since the model in use was set, the level test holds
    /// back).
    pub responses_ramps: u32,
    /// Adaptation is frozen.
    pub frozen: bool,
}

impl<T: Copy> AdaptiveState<T> {
    /// The state in another precision (`f` converts each number).
    pub fn map<U>(&self, f: impl Fn(T) -> U) -> AdaptiveState<U> {
        AdaptiveState {
            k_hat: f(self.k_hat),
            tau_hat: f(self.tau_hat),
            theta_hat: f(self.theta_hat),
            evidence: f(self.evidence),
            k_model: f(self.k_model),
            tau_model: f(self.tau_model),
            theta_model: f(self.theta_model),
            adapt_changes: self.adapt_changes,
            adapt_kind: self.adapt_kind,
            mismatch: f(self.mismatch),
            model_alarm: self.model_alarm,
            onsets: self.onsets,
            restarts: self.restarts,
            learnt: self.learnt,
            responses: self.responses,
            responses_used: self.responses_used,
            responses_ramps: self.responses_ramps,
            frozen: self.frozen,
        }
    }
}

/// What a logged change of a controller's model did (an adaptive
/// controller's log, [`Operate::visit_log`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ChangeKind {
    /// A settled estimate became the model.
    Applied,
    /// The loop oscillated after a change: the last good model came back.
    Restored,
    /// A scheme's operation refused the model: adaptation froze.
    Refused,
    /// The model in use no longer matches the process (the entry's model
    /// is the estimate's).
    Alarm,
    /// The model in use matches again.
    Cleared,
    /// The loop was going unstable and the estimate was clear: applied at
    /// once (the entry's model).
    Emergency,
    /// The loop was going unstable without a clear estimate: the
    /// primary's gain halved (the entry's model is the one in use).
    Detuned,
    /// An estimate at the end of the dead-time range, or beyond the gain's
    /// or the time constant's bound: not applied (the entry's model is the
    /// estimate's).
    Edge,
}

impl ChangeKind {
    /// The number the `adapt_kind` signal gives it (1 … 8).
    pub fn code(self) -> u8 {
        match self {
            ChangeKind::Applied => 1,
            ChangeKind::Restored => 2,
            ChangeKind::Refused => 3,
            ChangeKind::Alarm => 4,
            ChangeKind::Cleared => 5,
            ChangeKind::Emergency => 6,
            ChangeKind::Detuned => 7,
            ChangeKind::Edge => 8,
        }
    }

    /// The kind of a code of [`ChangeKind::code`].
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            1 => Some(ChangeKind::Applied),
            2 => Some(ChangeKind::Restored),
            3 => Some(ChangeKind::Refused),
            4 => Some(ChangeKind::Alarm),
            5 => Some(ChangeKind::Cleared),
            6 => Some(ChangeKind::Emergency),
            7 => Some(ChangeKind::Detuned),
            8 => Some(ChangeKind::Edge),
            _ => None,
        }
    }
}

/// One entry of the adaptation log: the model in use from `sample` on.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Change<T> {
    /// The sample at which it happened (counted from the first update).
    pub sample: u64,
    /// What happened.
    pub kind: ChangeKind,
    /// The model's gain `K`.
    pub k: T,
    /// The model's time constant `τ` (s; infinite: integrating).
    pub tau: T,
    /// The model's dead time `θ` (s).
    pub theta: T,
}
