//! The industrial PID controller: P, PI, PD and PID are configurations of one type.
//!
//! Continuous law (ISA / standard form, Bag (2022) ch. 3, Eq. 3.3
//! family; Åström & Hägglund's two-degree-of-freedom form):
//!
//! `u = Kp·[ (b·r − y) + 1/(Ti·s)·(r − y) + Td·s/(1 + Tf·s)·(c·r − y) ]`, `Tf = Td/N`,
//!
//! held internally in parallel gains `kp = Kp`, `ki = Kp/Ti`, `kd = Kp·Td`.
//! Sampled every `Ts = h`, the difference equations are (sample `k`):
//!
//! ```text
//! P[k]   = kp·(b·r[k] − y[k])
//! D[k]   = Tf/(Tf+h)·D[k−1] + kd/(Tf+h)·(e_d[k] − e_d[k−1]),   e_d = c·r − y   (backward Euler)
//! v[k]   = P[k] + I[k] + D[k]
//! u[k]   = sat(ratelimit(v[k]))                                            (limits, rate limit)
//! I[k+1] = I[k] + ki·h·(r[k] − y[k]) + h/Tt·(u[k] − v[k])                  (forward Euler,
//!                                                                            back-calculation)
//! ```
//!
//! With conditional integration instead of back-calculation, `I` is frozen while
//! the output is saturated and the error would drive it further into the limit.
//! A tracking input replaces `u[k]` by the actuator's real value in the
//! back-calculation term. In manual mode the output is the manual value and
//! the integrator tracks `I = u_manual − P − D`, so both transfers are bumpless.
//! A non-finite set point or measurement (or a difference of the two beyond
//! the float range) never reaches the state: the output is held and
//! [`Pid::fault`] is raised until valid data returns.

use crate::real::{finite, non_negative, positive};
use crate::{error::Error, real::Real};

mod config;
mod gains;
pub use config::PidConfig;
pub(crate) use gains::pid_params;
pub use gains::PidGains;

/// How the integrator is kept from winding up while the output is limited.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AntiWindup<T> {
    /// No protection (for comparison only).
    None,
    /// Back-calculation with tracking time constant `tt` (seconds).
    BackCalculation {
        /// Tracking time constant `Tt`; Åström–Hägglund suggest `√(Ti·Td)`, or `Ti` for PI.
        tt: T,
    },
    /// Conditional integration (clamping).
    Conditional,
}

/// The terms of the last update, for logging.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PidTerms<T> {
    /// Proportional term `P[k]`.
    pub p: T,
    /// Integral term `I[k]`.
    pub i: T,
    /// Derivative term `D[k]`.
    pub d: T,
    /// Output after limits.
    pub output: T,
}

/// Auto or manual operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Mode {
    /// The controller computes the output.
    #[default]
    Auto,
    /// The output is set by the operator; the integrator tracks it.
    Manual,
}

/// A PID controller (see the module documentation for the equations).
///
/// A PI in ISA form with output limits, one `update(setpoint, measurement)`
/// per sample, as pid-rs and idsp are used:
///
/// ```
/// use msp::{Controller, Pid, PidConfig};
/// let mut pi = Pid::new(PidConfig::isa(2.0f32, 10.0, 0.0, 0.1).with_limits(-5.0, 5.0))?;
/// let u = pi.update(1.0, 0.25); // the first sample: Kp·e (the integral, forward Euler, is 0)
/// assert_eq!(u, 2.0 * 0.75);
/// let u = pi.update(1.0, 0.25); // then I = Kp·Ts/Ti·e
/// assert!((u - (2.0 * 0.75 + 2.0 * 0.1 / 10.0 * 0.75)).abs() < 1e-6);
/// assert_eq!(pi.update(10.0, 0.0), 5.0); // at its limit
/// # Ok::<(), msp::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pid<T> {
    cfg: PidConfig<T>,
    /// Derivative filter coefficients `Tf/(Tf+h)` and `kd/(Tf+h)`.
    ad: T,
    bd: T,
    /// Integral increment per unit error `ki·h` and tracking gain `h/Tt`.
    bi: T,
    ar: T,
    /// Largest change per sample.
    du: T,
    /// Derivative action present (`kd > 0`), rate limit finite.
    has_d: bool,
    has_rate: bool,
    has_limits: bool,
    /// Auto mode, started, no fault, and nothing but P and I to compute: the
    /// short path of [`Pid::update`].
    lean: bool,
    integral: T,
    deriv: T,
    ed_prev: T,
    started: bool,
    mode: Mode,
    manual: T,
    terms: PidTerms<T>,
    fault: bool,
    failsafe: Option<T>,
}

impl<T: Real> Pid<T> {
    /// A controller with zero initial state.
    pub fn new(cfg: PidConfig<T>) -> Result<Self, Error> {
        cfg.validate()?;
        let h = cfg.ts;
        let denom = cfg.tf + h;
        let ar = match cfg.anti_windup {
            AntiWindup::BackCalculation { tt } => h / tt,
            AntiWindup::None | AntiWindup::Conditional => T::zero(),
        };
        let mut pid = Pid {
            cfg,
            ad: cfg.tf / denom,
            bd: cfg.kd / denom,
            bi: cfg.ki * h,
            ar,
            du: cfg.rate_limit * h,
            has_d: cfg.kd != T::zero(),
            has_rate: cfg.rate_limit.is_finite(),
            has_limits: cfg.u_min.is_finite() || cfg.u_max.is_finite(),
            lean: false,
            integral: T::zero(),
            deriv: T::zero(),
            ed_prev: T::zero(),
            started: false,
            mode: Mode::Auto,
            manual: T::zero(),
            terms: PidTerms::default(),
            fault: false,
            failsafe: None,
        };
        pid.refresh();
        Ok(pid)
    }

    /// Recomputes whether the next update may take the short path.
    fn refresh(&mut self) {
        self.lean = self.mode == Mode::Auto
            && self.started
            && !self.fault
            && !self.has_d
            && !self.has_rate
            && !self.has_limits;
    }

    /// The configuration.
    pub fn config(&self) -> &PidConfig<T> {
        &self.cfg
    }

    /// The terms of the last update.
    #[inline]
    pub fn terms(&self) -> PidTerms<T> {
        self.terms
    }

    /// The last output.
    #[inline]
    pub fn output(&self) -> T {
        self.terms.output
    }

    /// True while the last set point or measurement was not finite (output held).
    #[inline]
    pub fn fault(&self) -> bool {
        self.fault
    }

    /// The output to give while the set point or measurement is not finite
    /// (`None`: hold the last output). When valid data returns, the integrator
    /// is set so that the output continues from this value (bumpless).
    pub fn set_failsafe(&mut self, value: Option<T>) -> Result<(), Error> {
        if let Some(v) = value {
            finite(v, "failsafe")?;
            if v < self.cfg.u_min || v > self.cfg.u_max {
                return Err(Error::OutOfRange("failsafe"));
            }
        }
        self.failsafe = value;
        Ok(())
    }

    /// Zeroes the state and returns to auto mode.
    pub fn reset(&mut self) {
        self.integral = T::zero();
        self.deriv = T::zero();
        self.ed_prev = T::zero();
        self.started = false;
        self.mode = Mode::Auto;
        self.terms = PidTerms::default();
        self.fault = false;
        self.refresh();
    }

    /// Returns every state to zero, as [`Pid::reset`], with the loop at
    /// rest before the next sample (every signal zero, the transfer
    /// function's initial condition): the first update's derivative
    /// differences `c·r − y` against zero, `D = bd·(c·r − y)`, where after
    /// `reset` it takes the first sample as its reference (no kick; see
    /// [`crate::Controller::reset_to_rest`]). The last output, the rate
    /// limit's reference, is zero too.
    pub fn reset_to_rest(&mut self) {
        self.reset();
        self.started = true;
        self.refresh();
    }

    /// Sets the integral term so that the next output is `u` for zero error
    /// (bumpless start from a steady state with actuator value `u`).
    pub fn preset(&mut self, u: T) -> Result<(), Error> {
        self.integral = finite(u, "u")?;
        self.terms.output = u;
        Ok(())
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Switches to manual mode holding the last output (bumpless auto→manual).
    pub fn set_manual(&mut self) {
        self.manual = self.terms.output;
        self.mode = Mode::Manual;
        self.refresh();
    }

    /// Sets the manual output (limited to `[u_min, u_max]`).
    pub fn set_manual_output(&mut self, u: T) -> Result<(), Error> {
        self.manual = finite(u, "u")?.max(self.cfg.u_min).min(self.cfg.u_max);
        Ok(())
    }

    /// Switches to auto mode continuing from the manual output (bumpless
    /// manual→auto): the integrator tracks the manual output at every update
    /// in manual, and is set to it here too, so that a manual output given
    /// just before (with no update since) is where auto mode starts.
    pub fn set_auto(&mut self) {
        if self.mode == Mode::Manual {
            let t = self.terms;
            self.integral = self.manual - t.p - t.d;
            self.terms.output = self.manual;
        }
        self.mode = Mode::Auto;
        self.refresh();
    }

    /// Amends the last update as if its output had been `applied` (the value
    /// the actuator really took, or an operator's): with
    /// [`Tracking::Full`](crate::Tracking) the integrator is set so that the
    /// output would have been `applied` (as in manual mode: the next output
    /// continues from it); with [`Tracking::Reset`](crate::Tracking) it moves
    /// by the back-calculation gain `h/Tt`·(applied − output) (external reset
    /// feedback: no windup against a limit the controller does not own; full
    /// tracking when the controller has no back-calculation).
    pub fn apply(&mut self, applied: T, how: crate::operate::Tracking) {
        if !applied.usable() || !self.started {
            return;
        }
        let t = self.terms;
        self.integral = match how {
            crate::operate::Tracking::Reset if self.ar > T::zero() => {
                self.integral + self.ar * (applied - t.output)
            }
            _ => applied - t.p - t.d,
        };
        self.terms.output = applied;
    }

    /// Changes one ISA gain while the loop runs (`Ti = ∞` turns the integral
    /// off), bumpless: the proportional and derivative terms of the last
    /// update are rescaled to the new gains and the integrator takes up their
    /// change, so that the next output equals the last one for unchanged
    /// inputs; the derivative filter keeps its ratio `N = Td/Tf`. A
    /// proportional gain of zero cannot be left (its term says nothing of
    /// the error).
    pub fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), Error> {
        use crate::operate::Gain;
        let c = self.cfg;
        let (mut kp, mut ti, mut td) = (c.kp, c.ti(), c.td());
        match gain {
            Gain::Kp => kp = finite(value, "kp")?,
            Gain::Ti => {
                if value.is_nan() || !(value > T::zero()) {
                    return Err(Error::NotPositive("ti"));
                }
                ti = value;
            }
            Gain::Td => td = non_negative(value, "td")?,
        }
        if c.kp == T::zero() && kp != T::zero() {
            return Err(Error::Unsupported(
                "a PID with kp = 0 cannot be retuned online: rebuild it",
            ));
        }
        let isa = PidConfig::try_isa(kp, ti, td, c.ts)?;
        // N = Td/Tf as it was: an unfiltered derivative (Tf = 0, N = ∞) stays
        // unfiltered; a derivative turned on from none gets the default N = 10
        let ratio = if c.td() > T::zero() {
            if c.tf > T::zero() {
                c.td() / c.tf
            } else {
                T::infinity()
            }
        } else {
            T::of(10.0)
        };
        // an integral turned on in a controller that had none gets the
        // anti-windup the ISA form gives one (back-calculation): `None` was
        // there only for want of an integral, and would let it wind up
        // against the limits; a chosen scheme stays
        let anti_windup = if c.ki == T::zero() && matches!(c.anti_windup, AntiWindup::None) {
            isa.anti_windup
        } else {
            c.anti_windup
        };
        let cfg = PidConfig {
            kp: isa.kp,
            ki: isa.ki,
            kd: isa.kd,
            tf: td / ratio,
            anti_windup,
            ..c
        };
        let mut next = Pid::new(cfg)?;
        // the terms of the last update with the new gains
        let scale = |new: T, old: T, term: T| {
            if old != T::zero() {
                term * new / old
            } else {
                T::zero()
            }
        };
        let t = self.terms;
        let (p, d) = (scale(cfg.kp, c.kp, t.p), scale(cfg.kd, c.kd, t.d));
        next.integral = self.integral + (t.p - p) + (t.d - d);
        next.deriv = scale(cfg.kd, c.kd, self.deriv);
        next.ed_prev = self.ed_prev;
        next.started = self.started;
        next.mode = self.mode;
        next.manual = self.manual;
        next.terms = PidTerms { p, d, ..t };
        next.fault = self.fault;
        next.failsafe = self.failsafe;
        next.refresh();
        *self = next;
        Ok(())
    }

    /// The linear (unsaturated) frequency response at `z = e^{jθ}` as the pair
    /// `(Cr, Cy)` of `u = Cr·r − Cy·y`: `Cr = kp·b + ki·h/(z − 1) + D(z)·c`,
    /// `Cy = kp + ki·h/(z − 1) + D(z)`, `D(z) = kd/(Tf + h)·(1 − z⁻¹)/(1 − Tf/(Tf + h)·z⁻¹)`.
    pub fn response(&self, theta: T) -> (crate::complex::Complex<T>, crate::complex::Complex<T>) {
        self.response_at(&crate::lti::zdomain::Frequency::new(theta))
    }

    /// [`Pid::response`] at any [`Point`](crate::lti::zdomain::Point), with
    /// `w = z^{−1}`: `ki·h/(z − 1) = ki·h·w/(1 − w)`, `D = kd/(Tf + h)·(1 − w)/(1 − Tf/(Tf + h)·w)`.
    pub fn response_at<P: crate::lti::zdomain::Point<T>>(&self, at: &P) -> (P::V, P::V) {
        use crate::lti::zdomain::Algebra;
        let k = <P::V as Algebra<T>>::constant;
        let w = at.backward();
        let one = k(T::one());
        let integ = k(self.bi) * w.clone() / (one.clone() - w.clone());
        let kp = self.cfg.kp;
        if self.has_d {
            let deriv = k(self.bd) * (one.clone() - w.clone()) / (one - k(self.ad) * w);
            let cr = k(kp * self.cfg.b) + integ.clone() + k(self.cfg.c) * deriv.clone();
            (cr, k(kp) + integ + deriv)
        } else {
            (k(kp * self.cfg.b) + integ.clone(), k(kp) + integ)
        }
    }

    /// One sample: set point `r`, measurement `y`; returns the output.
    #[inline]
    pub fn update(&mut self, r: T, y: T) -> T {
        if self.lean {
            self.step_pi(r, y)
        } else {
            self.step(r, y, None)
        }
    }

    /// [`Pid::step`] for a P or PI controller in auto mode with nothing to limit
    /// (no derivative, output limits or rate limit, no fault to recover from):
    /// `u = kp·(b·r − y) + I`, `I ← I + ki·h·(r − y)`. The same arithmetic as the
    /// general path with `D = 0`, in the fewest operations.
    #[inline(always)]
    fn step_pi(&mut self, r: T, y: T) -> T {
        let e = r - y;
        let p = self.cfg.kp * (self.cfg.b * r - y);
        let i = self.integral;
        let u = p + i;
        let next = i + self.bi * e;
        // one test before any state is written: a control error too large
        // to compute with (`Real::usable`; NaN and ±∞ among them), or terms
        // that leave the float range (`u` or `next` ±∞ or NaN) — a fault
        // either way, never a state that latches ±∞ or NaN (one comparison:
        // `(u + next)·0` is NaN exactly when u + next is not finite, and
        // NaN fails it)
        if !((u + next) * T::zero() + e).usable() {
            return self.hold();
        }
        self.integral = next;
        // `started` is already set and `terms.d` is zero (no derivative)
        self.terms.p = p;
        self.terms.i = i;
        self.terms.output = u;
        u
    }

    /// One sample with a tracking input: `u_actual` is the actuator's real value
    /// (after external limits or overrides); the integrator tracks it.
    #[inline]
    pub fn update_tracking(&mut self, r: T, y: T, u_actual: T) -> T {
        self.step(r, y, Some(u_actual))
    }

    /// The output during a fault: held, or the fail-safe value.
    #[cold]
    #[inline(never)]
    fn hold(&mut self) -> T {
        self.fault = true;
        self.lean = false;
        let held = self.failsafe.unwrap_or(self.terms.output);
        self.terms.output = held;
        held
    }

    #[inline(always)]
    fn step(&mut self, r: T, y: T, track: Option<T>) -> T {
        let e = r - y;
        // NaN or ±∞ in r or y, or a control error too large to compute
        // with (`Real::usable`): the output held, the fault raised
        if !e.usable() {
            return self.hold();
        }
        let recovering = self.fault;
        let first = !self.started;
        self.fault = false;
        let cfg = &self.cfg;
        let p = cfg.kp * (cfg.b * r - y);
        let ed = cfg.c * r - y;
        let d = if self.has_d && self.started && !recovering {
            self.ad * self.deriv + self.bd * (ed - self.ed_prev)
        } else {
            T::zero()
        };
        let i = if recovering && self.started {
            // continue from the output given during the fault, as manual→auto does
            self.terms.output - p - d
        } else {
            self.integral
        };
        let v = p + i + d;
        let u = match self.mode {
            Mode::Manual => self.manual,
            Mode::Auto => {
                let mut u = v;
                if self.has_rate && self.started {
                    let last = self.terms.output;
                    u = crate::real::clamp(u, last - self.du, last + self.du);
                }
                if self.has_limits {
                    u = crate::real::clamp(u, cfg.u_min, cfg.u_max);
                }
                u
            }
        };
        let applied = match track {
            Some(t) if t.is_finite() => t,
            _ => u,
        };
        let next = match self.mode {
            Mode::Manual => applied - p - d,
            // nothing limits the output: no windup to guard against
            Mode::Auto if !self.has_limits && !self.has_rate && track.is_none() => i + self.bi * e,
            Mode::Auto => match cfg.anti_windup {
                AntiWindup::Conditional => {
                    let pushing_up = e > T::zero() && v >= cfg.u_max;
                    let pushing_down = e < T::zero() && v <= cfg.u_min;
                    if pushing_up || pushing_down {
                        i
                    } else {
                        i + self.bi * e
                    }
                }
                AntiWindup::BackCalculation { .. } => {
                    // the tracking term only when the output is limited: it keeps
                    // the integrator's dependency chain short otherwise
                    if applied == v {
                        i + self.bi * e
                    } else {
                        i + self.bi * e + self.ar * (applied - v)
                    }
                }
                AntiWindup::None => i + self.bi * e,
            },
        };
        // finite inputs whose terms leave the float range (a measurement near
        // f64::MAX times a gain): a fault, the state untouched, never a state
        // that latches ±∞ or NaN
        if !(v + next).is_finite() {
            return self.hold();
        }
        self.integral = next;
        self.deriv = d;
        self.ed_prev = ed;
        self.started = true;
        self.terms = PidTerms { p, i, d, output: u };
        if recovering || first {
            self.refresh();
        }
        u
    }
}

impl<T: Real> crate::operate::Operate<T> for Pid<T> {
    fn apply(&mut self, applied: T, how: crate::operate::Tracking) {
        Pid::apply(self, applied, how);
    }
    fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), Error> {
        Pid::retune(self, gain, value)
    }
}

/// The plain PID loop is a controller too (the `pid` scheme).
impl<T: Real> crate::controller::Controller<T> for Pid<T> {
    #[inline(always)]
    fn update(&mut self, r: T, y: T) -> T {
        Pid::update(self, r, y)
    }
    fn reset(&mut self) {
        Pid::reset(self)
    }
    fn reset_to_rest(&mut self) {
        Pid::reset_to_rest(self)
    }
    fn fault(&self) -> bool {
        Pid::fault(self)
    }
}

impl<T: Real> crate::controller::CascadeControl<T> for Pid<T> {}

impl<T: Real> crate::controller::Introspect<T> for Pid<T> {
    fn signal_names(&self) -> &'static [&'static str] {
        &["p_term", "i_term", "d_term"]
    }
    fn signal(&self, i: usize) -> T {
        let t = self.terms();
        [t.p, t.i, t.d].get(i).copied().unwrap_or_else(T::nan)
    }
    #[inline]
    fn write_signals(&self, out: &mut [T]) {
        // the simulator records the terms every sample: written at once
        let t = &self.terms;
        for (o, v) in out.iter_mut().zip([t.p, t.i, t.d]) {
            *o = v;
        }
    }
    fn param_names(&self) -> &'static [&'static str] {
        &["kp", "ti", "td"]
    }
    fn param(&self, i: usize) -> T {
        let c = self.config();
        [c.kp, c.ti(), c.td()]
            .get(i)
            .copied()
            .unwrap_or_else(T::nan)
    }
}

impl<T: Real> crate::controller::FrequencyResponse<T> for Pid<T> {
    fn response(
        &self,
        theta: T,
    ) -> Option<(crate::complex::Complex<T>, crate::complex::Complex<T>)> {
        Some(Pid::response(self, theta))
    }
    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(crate::lti::zdomain::Rational, crate::lti::zdomain::Rational)> {
        Some(self.response_at(&crate::lti::zdomain::Symbolic))
    }
}

#[cfg(test)]
mod tests;
