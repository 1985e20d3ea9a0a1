//! Cascade control of dead-time processes (García et al. (2010) Fig. 1):
//! a secondary process `P2 e^{−L2 s}` whose output `y2` is measured and feeds
//! the primary process `P1 e^{−L1 s}`; disturbances `d2` at the plant input,
//! `d0` at the secondary output (it enters `y2` and `P1`) and `d1` at the
//! primary output.
//!
//! Every cascade scheme of the paper has the same inner loop, an IMC
//! controller on the secondary measurement,
//!
//! `u = Q(z)·(r2 − (y2 − P2m(z)·z^{−d2}·u))`, `Q = Mimc/P2` (Sec. 3.1),
//!
//! with `Q(s) = P2⁻¹(s)/(λ2 s + 1)^r` (`r` the relative degree of `P2`, so
//! `Mimc = e^{−L2 s}/(λ2 s + 1)^r`; the paper's inner controllers are exactly
//! this: `0.5(20s+1)/(2s+1)` for `2/(20s+1)`, λ2 = 2 s) pole-zero matched at
//! the sample period. The schemes differ in the outer (primary) controller,
//! designed for the overall model `Pm = Mimc·P1 = Gm(s)·e^{−(L1+L2)s}`
//! (Eqs. 5–9): FSPCC is the filtered Smith predictor
//! ([`crate::dtc::fsp`]) on `Gm`, GPCC the generalized predictor
//! ([`crate::dtc::gpcc`]), and the competitors of Sec. 2 — Uma et al. 2009 and
//! Kaya et al. 2008 — are configurations of [`crate::dtc::Compensator`].
//! [`Cascade`] joins any such outer controller to the inner IMC loop.

#[cfg(feature = "alloc")]
use alloc::vec::Vec;

use super::DelayedModel;
use crate::delay::Delay;
#[cfg(feature = "alloc")]
use crate::delay::DelayStorage;
#[cfg(feature = "alloc")]
use crate::lti::Discretization;
#[cfg(feature = "alloc")]
use crate::poly::{mul, trim, TransferFunction};
use crate::{
    complex::Complex, error::Error, lti::Lti, pid::AntiWindup, pid::PidConfig, real::Real,
};
use crate::{
    controller::CascadeControl, controller::Controller, controller::FrequencyResponse,
    controller::Introspect,
};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

mod design;
pub use design::*;

crate::params::base_struct! { $ cascade_params;
    /// What every cascade scheme of García et al. (2010) shares: the primary
    /// series PID `(kp + ki/s + kd s)/(τ s + 1)` with set-point weight `ε`,
    /// and the inner IMC filter time constant `λ2`; `cascade_params!`
    /// declares a cascade scheme's (these first).
    pub struct CascadePrimary {
        /// Proportional gain of the primary PID.
        kp: Finite,
        /// Integral gain of the primary PID (1/s).
        ki: Finite,
        /// Derivative gain of the primary PID (s).
        kd: Finite,
        /// Filter time constant `τ` of the primary PID (s).
        tau: NonNegative,
        /// Set-point weight `ε` of the proportional term.
        epsilon: Finite,
        /// Inner IMC filter time constant `λ2` (s).
        lambda2: Positive,
    }
}

cascade_params! {
    /// Parameters of FSPCC (García et al. (2010) Sec. 3.1): [`CascadePrimary`]
    /// and the robustness filter `Fr` (`tf`, an optional lead-lag `lead`/`lag`).
    pub struct FspccParams {
        /// Robustness filter time constant `Tf` (s).
        tf: Positive,
        /// Lead time constant of `Fr`'s lead-lag (s); 0: none.
        lead: NonNegative,
        /// Lag time constant of `Fr`'s lead-lag (s); 0: none.
        lag: NonNegative,
    }
}

cascade_params! {
    /// Parameters of GPCC (García et al. (2010) Sec. 3.2): [`CascadePrimary`]
    /// and the time constant of the predictor's filter `Fk`.
    pub struct GpccParams {
        /// Time constant of `Fk` (s); 0: `Fk = 1`.
        tk: NonNegative,
    }
}

cascade_params! {
    /// Parameters of Uma et al.'s scheme (García et al. (2010) Sec. 2.3):
    /// [`CascadePrimary`] as `Gcs`, the disturbance controller
    /// `Gcd = (kpd + kid/s + kdd s)(lead s + 1)/(lag s + 1)` and the filter
    /// `Gf = 1/(tf s + 1)`. The sources give no rule for `Gcd`: its gains are
    /// NaN until set.
    pub struct UmaParams {
        /// Proportional gain of `Gcd`.
        kpd: Any,
        /// Integral gain of `Gcd` (1/s).
        kid: Any,
        /// Derivative gain of `Gcd` (s).
        kdd: Any,
        /// Lead time constant of `Gcd` (s).
        lead: NonNegative,
        /// Lag time constant of `Gcd` (s).
        lag: NonNegative,
        /// Time constant of `Gf` (s); 0: no filter.
        tf: NonNegative,
    }
}

crate::dtc::kaya_atherton::kaya_atherton_params! {
    /// Parameters of Kaya et al.'s cascade (García et al. (2010) Sec. 2.2): the
    /// PI-PD Smith predictor's ([`crate::dtc::kaya_atherton::KayaAthertonParams`])
    /// outside the inner IMC loop with filter `λ2`.
    pub struct KayaCascadeParams {
        /// Inner IMC filter time constant `λ2` (s).
        lambda2: Positive,
    }
}

/// Declares a cascade scheme's design inputs: `lambda`, `alpha` (of the
/// primary loop: default `λ = 0.8·L`), the inner filter's `lambda2` and the
/// set-point weight `epsilon`, then the scheme's own.
macro_rules! cascade_tuning {
    ($(#[$meta:meta])* pub struct $name:ident { $($rest:tt)* }) => {
        crate::params::design_struct! {
            $(#[$meta])*
            pub struct $name {
                /// Inner IMC filter time constant `λ2` (s); default the
                /// secondary dead time `L2`.
                lambda2,
                /// Set-point weight `ε`; default 0.3 (the paper's examples).
                epsilon,
                $($rest)*
            }
        }
    };
}

cascade_tuning! {
    /// The design inputs every cascade scheme of García et al. (2010) shares
    /// (read by each one's primary design).
    pub struct CascadePrimaryTuning {}
}

cascade_tuning! {
    /// Design inputs of FSPCC.
    pub struct FspccTuning {
        /// Robustness filter time constant `Tf` (s); default half the primary model's dead time.
        tf,
        /// Lead of `Fr` (s); default none.
        lead,
        /// Lag of `Fr` (s); default none.
        lag,
    }
}

cascade_tuning! {
    /// Design inputs of GPCC.
    pub struct GpccTuning {
        /// Time constant of `Fk` (s); default 0 (`Fk = 1`).
        tk,
    }
}

cascade_tuning! {
    /// Design inputs of Uma et al.'s scheme.
    pub struct UmaTuning {
        /// Lead of `Gcd` (s); default none.
        lead,
        /// Lag of `Gcd` (s); default none.
        lag,
        /// Time constant of `Gf` (s); default none.
        tf,
    }
}

crate::params::design_struct! {
    /// Design inputs of Kaya et al.'s cascade (the primary's `λ` as for
    /// Kaya–Atherton's predictor).
    pub struct KayaCascadeTuning {
        /// Inner IMC filter time constant `λ2` (s); default the secondary dead time `L2`.
        lambda2,
    }
}

/// Order capacity of the inner IMC controller `Q`.
pub const Q_ORDER: usize = 4;
/// Order capacity of the inner model `P2m`.
pub const P2_ORDER: usize = 4;

/// The inner IMC loop `u = Q·(r2 − (y2 − P2m z^{−d2} u))`, its dead-time line
/// over storage `S` (`[T; D]` on a device, `Vec<T>` on a host).
#[derive(Debug, Clone)]
pub struct Imc<T, S> {
    q: Lti<T, Q_ORDER>,
    model: DelayedModel<T, P2_ORDER, S>,
    u_min: T,
    u_max: T,
    r2: T,
    u: T,
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> Imc<T, S> {
    /// The loop from its controller `q`, the delay-free secondary model
    /// (strictly proper) and its dead-time line.
    pub fn new(
        q: Lti<T, Q_ORDER>,
        model: Lti<T, P2_ORDER>,
        line: Delay<T, S>,
    ) -> Result<Self, Error> {
        let model = DelayedModel::new(model, line).map_err(|_| Error::Improper("inner model"))?;
        Ok(Imc {
            q,
            model,
            u_min: T::neg_infinity(),
            u_max: T::infinity(),
            r2: T::zero(),
            u: T::zero(),
        })
    }

    /// Actuator limits (the model sees the limited value: IMC needs no anti-windup).
    pub fn with_limits(mut self, u_min: T, u_max: T) -> Result<Self, Error> {
        if u_min > u_max || u_min.is_nan() || u_max.is_nan() {
            return Err(Error::InvalidLimits("u_min"));
        }
        self.u_min = u_min;
        self.u_max = u_max;
        Ok(self)
    }

    /// One sample: inner set point `r2`, secondary measurement `y2` (`None`: the
    /// model error is taken as zero).
    pub fn update(&mut self, r2: T, y2: Option<T>) -> T {
        // without the secondary measurement the model is taken as exact
        let error = match y2 {
            Some(y) => self.model.predict(y).1,
            None => {
                self.model.predict_exact();
                T::zero()
            }
        };
        let u = self.q.step(r2 - error).max(self.u_min).min(self.u_max);
        self.model.advance(u);
        self.r2 = r2;
        self.u = u;
        u
    }

    /// Amends the last update as if the loop's output had been `applied`:
    /// the model follows it, and `Q`'s last input moves by
    /// `(applied − u)/Q(∞)` so that `Q`'s output was `applied` too (`Q` is
    /// biproper): the inner set point `r2` that gives it.
    pub fn apply(&mut self, applied: T) {
        if !(applied.usable() && self.u.is_finite()) {
            return;
        }
        self.model.amend_input(applied - self.u);
        let d = self.q.feedthrough();
        if d != T::zero() {
            let dv = (applied - self.u) / d;
            self.q.amend_input(dv);
            self.r2 = self.r2 + dv;
        }
        self.u = applied;
    }

    /// The inner set point `r2` of the last sample.
    pub fn setpoint(&self) -> T {
        self.r2
    }

    /// The model error `y2 − P2m z^{−d2} u` of the last sample.
    pub fn error(&self) -> T {
        self.model.error()
    }

    /// `Q(e^{jθ})`.
    pub fn q_response(&self, theta: T) -> Complex<T> {
        self.q.response(theta)
    }

    /// Zeroes every state.
    pub fn reset(&mut self) {
        self.q.reset();
        self.model.reset();
        self.r2 = T::zero();
        self.u = T::zero();
    }
}

#[cfg(feature = "alloc")]
impl<T: Real, S: DelayStorage<T>> Imc<T, S> {
    /// The IMC loop for the secondary plant `p2` with the filter time constant
    /// `lambda2`, sampled at `ts`.
    pub fn design(p2: &TransferFunction, lambda2: f64, ts: f64) -> Result<Self, Error> {
        let (qn, qd) = imc_q(p2, lambda2)?;
        let q = Lti::from_tf_of(&qn, &qd, ts, Discretization::Matched)?;
        let model = Lti::from_tf_of(&p2.num, &p2.den, ts, Discretization::Zoh)?;
        Imc::new(q, model, Delay::new_in(T::of(p2.delay_samples(ts)?))?)
    }
}

/// Any single-loop outer controller (its "actuator" is the inner set point
/// `r2`) joined to the inner IMC loop.
///
/// Built by hand from its parts, or through the registry, which designs
/// FSPCC, GPCC and Uma et al.'s scheme for a pair of processes:
///
/// ```
/// use msp::poly::TransferFunction;
/// use msp::registry::{self, Build};
/// // García et al. (2010) Example 1: P1 = e^{-4s}/(20s - 1), P2 = 2e^{-2s}/(20s + 1)
/// let p1: TransferFunction = "e^-4s/(20s-1)".parse()?;
/// let p2: TransferFunction = "2e^-2s/(20s+1)".parse()?;
/// let gpcc = registry::find("gpcc")?;
/// let params = gpcc.tune_process(&p1, Some(&p2), None, None, &[])?;
/// let build = Build { ts: 0.2, u_min: f64::NEG_INFINITY, u_max: f64::INFINITY, max_dead_time: 0.0 };
/// let mut c = gpcc.build_process(&params, &p1, Some(&p2), &build)?;
/// // the set point, the primary and the secondary measurements
/// let u = c.update_cascade(1.0, 0.0, 0.0);
/// assert!(u.is_finite() && c.is_cascade(), "{u}");
/// let later = (0..10).map(|_| c.update_cascade(1.0, 0.0, 0.0)).last();
/// assert!(later > Some(0.0), "{later:?}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Cascade<T, O, S> {
    outer: O,
    inner: Imc<T, S>,
    names: &'static [&'static str],
    fault: bool,
}

/// Names of the cascade's own signals, before the outer controller's.
pub const SIGNALS: &[&str] = &["r2", "inner_error"];

impl<T: Real, O, S> Cascade<T, O, S> {
    /// `outer` around `inner`; `names` lists [`SIGNALS`] followed by the outer
    /// controller's signal names.
    pub fn new(outer: O, inner: Imc<T, S>, names: &'static [&'static str]) -> Self {
        Cascade {
            outer,
            inner,
            names,
            fault: false,
        }
    }
    /// The outer controller.
    pub fn outer(&self) -> &O {
        &self.outer
    }
    /// The inner loop.
    pub fn inner(&self) -> &Imc<T, S> {
        &self.inner
    }
}

impl<T: Real, O: Controller<T>, S: AsRef<[T]> + AsMut<[T]>> Cascade<T, O, S> {
    fn step(&mut self, r: T, y: T, y2: Option<T>) -> T {
        let r2 = self.outer.update(r, y);
        let y2 = y2.filter(|v| v.usable());
        let u = self.inner.update(r2, y2);
        self.fault = self.outer.fault() || y2.is_none();
        u
    }
}

impl<T: Real, O: Controller<T>, S: AsRef<[T]> + AsMut<[T]>> Controller<T> for Cascade<T, O, S> {
    /// Without the secondary measurement the inner model error is taken as zero.
    fn update(&mut self, r: T, y: T) -> T {
        let u = self.step(r, y, None);
        self.fault = self.outer.fault();
        u
    }

    fn reset(&mut self) {
        self.outer.reset();
        self.inner.reset();
        self.fault = false;
    }

    fn reset_to_rest(&mut self) {
        self.reset();
        self.outer.reset_to_rest();
    }

    fn fault(&self) -> bool {
        self.fault
    }
}

impl<T: Real, O: crate::operate::Operate<T>, S: AsRef<[T]> + AsMut<[T]>> crate::operate::Operate<T>
    for Cascade<T, O, S>
{
    /// The inner loop follows `applied` (its model and `Q`), and the outer
    /// controller the inner set point that gives it.
    fn apply(&mut self, applied: T, how: crate::operate::Tracking) {
        self.inner.apply(applied);
        self.outer.apply(self.inner.setpoint(), how);
    }

    /// The outer controller's gains.
    fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), Error> {
        self.outer.retune(gain, value)
    }

    /// The outer model's dead time: the primary's with the secondary's
    /// (`L1 + L2`, all the way from the plant input to `y`); the inner loop's
    /// model keeps `L2`, so a change is one of the primary's transport delay.
    fn dead_time(&self) -> Option<T> {
        self.outer.dead_time()
    }

    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.outer.set_dead_time(samples)
    }

    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        self.outer.ramp_dead_time(samples, per_sample)
    }
}

impl<T: Real, O: Controller<T>, S: AsRef<[T]> + AsMut<[T]>> CascadeControl<T> for Cascade<T, O, S> {
    fn update_cascade(&mut self, r: T, y: T, y2: T) -> T {
        self.step(r, y, Some(y2))
    }

    fn is_cascade(&self) -> bool {
        true
    }
}

impl<T: Real, O: Introspect<T>, S: AsRef<[T]> + AsMut<[T]>> Introspect<T> for Cascade<T, O, S> {
    fn signal_names(&self) -> &'static [&'static str] {
        self.names
    }

    fn signal(&self, i: usize) -> T {
        match i {
            0 => self.inner.setpoint(),
            1 => self.inner.error(),
            _ => self.outer.signal(i.saturating_sub(SIGNALS.len())),
        }
    }

    fn param_names(&self) -> &'static [&'static str] {
        self.outer.param_names()
    }

    fn param(&self, i: usize) -> T {
        self.outer.param(i)
    }
}

impl<T: Real, O: FrequencyResponse<T>, S: AsRef<[T]> + AsMut<[T]>> FrequencyResponse<T>
    for Cascade<T, O, S>
{
    /// The outer controller's `(Cr, Cy)` with the inner set point `r2` as its
    /// actuator: the loop it closes is `Q·P1·P2` (the inner loop closed, nominal).
    fn response(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        self.outer.response(theta)
    }

    fn inner_response(&self, theta: T) -> Option<Complex<T>> {
        self.outer.inner_response(theta)
    }

    fn feedback_parts(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        self.outer.feedback_parts(theta)
    }

    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(crate::lti::zdomain::Rational, crate::lti::zdomain::Rational)> {
        self.outer.transfer()
    }

    fn unstable_poles(&self) -> usize {
        self.outer.unstable_poles()
    }
}

#[cfg(all(test, feature = "alloc"))]
mod tests;
