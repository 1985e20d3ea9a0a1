//! The general modified Smith predictor that the multi-loop schemes configure.
//!
//! All the modified Smith predictors of the sources share one skeleton — a
//! delay-free model `Gm` with its dead time, a primary controller `Gc1`
//! acting on a predicted output, and extra paths around it. With
//! `ym = Gm·u1` (delay-free model output), `ε = y − e^{−θm s}·ym` (model error):
//!
//! ```text
//! u1 = Gc1·(r − ym − F·ε + Mc·u1) − Gc2·ym      primary and inner (stabilizing) controller
//! u  = sat(u1 − Gd·ε)                          disturbance controller at the plant input
//! ```
//!
//! - `F` — how the model error enters the primary loop: `1` (classic Smith
//!   predictor, Karan–Dey, Draganović), `0` (Åström–Hang–Lim: set point and
//!   load responses decoupled), a filter (the filtered Smith predictor of
//!   the MathWorks Smith predictor example) or Huang's `(1+B)/(1+B e^{−θs})`;
//! - `Gc2` — P or PD feedback of the model output (Karan–Dey `β·Kp`,
//!   Kaya–Atherton's PD);
//! - `Gd` — disturbance controller on the model error (Karan–Dey's `Gc3`,
//!   Draganović's disturbance estimator `A(s)/C(s)`, Matausek–Micic's `K0`,
//!   Åström–Hang–Lim's `M(s)`);
//! - `Mc` — Watanabe–Ito's correction of the predictor, `m(s)`.
//!
//! With a perfect model and no load, `ε = 0` and the set-point response is
//! that of the delay-free loop `Gc1·Gm/(1 + Gm(Gc1 + Gc2))`, delayed
//! (Bag (2022) Eq. 4.20); the load response is shaped by `Gd`
//! and `F` alone. Each scheme's module documents its configuration and tuning.

use super::DelayedModel;
use crate::delay::Delay;
use crate::lti::zdomain::{Algebra, Frequency, Point};
use crate::metrics::Sum;
use crate::params::{ParamList, ParamSet};
use crate::real::finite;
use crate::{complex::Complex, error::Error, lti::Lti, pid::Pid, real::Real};
use crate::{
    controller::CascadeControl, controller::Controller, controller::FrequencyResponse,
    controller::Introspect,
};
use core::ops::{Add, Mul, Sub};

mod traits;

/// Order capacity of the auxiliary blocks (filters and disturbance controllers).
pub const AUX: usize = 4;

/// How the model error enters the primary controller's feedback.
#[derive(Debug, Clone)]
// a plain tag byte: the per-sample dispatch is one load and compare
#[repr(u8)]
pub enum ErrorPath<T, S> {
    /// `F = 1`: the classic Smith predictor.
    Direct,
    /// `F = 0`: the primary sees only the delay-free model.
    Blocked,
    /// `F` any proper filter (first order, lead-lag, …).
    Filter(Lti<T, AUX>),
    /// Huang's approximate inverse of dead time `F = (1 + B)/(1 + B e^{−θs})`
    /// realized as `f = x + B·(x − e^{−θs} f)`; `B` strictly proper.
    Huang {
        /// The low-pass `B(s)`.
        b: Lti<T, AUX>,
        /// `e^{−θs}` applied to `f`.
        line: Delay<T, S>,
    },
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> ErrorPath<T, S> {
    /// `F·ε` for one sample.
    #[inline(always)]
    fn step(&mut self, eps: T) -> T {
        match self {
            ErrorPath::Direct => eps,
            ErrorPath::Blocked => T::zero(),
            ErrorPath::Filter(f) => f.step(eps),
            ErrorPath::Huang { b, line } => {
                let f_delayed = line.peek(T::zero());
                let f = eps + b.free_output();
                b.step(eps - f_delayed);
                line.process(f);
                f
            }
        }
    }
}

/// The inner (stabilizing) feedback `Gc2` of the model output.
#[derive(Debug, Clone)]
// a plain tag byte: the per-sample dispatch is one load and compare
#[repr(u8)]
pub enum InnerPath<T> {
    /// None.
    Off,
    /// A proportional gain (Karan–Dey's `β·Kp`): one multiplication per sample.
    Gain(T),
    /// A PID acting on `ym` as its set point (Kaya–Atherton's PD).
    Pid(Pid<T>),
}

impl<T: Real> InnerPath<T> {
    /// `Gc2·ym`.
    #[inline(always)]
    fn update(&mut self, ym: T) -> T {
        match self {
            InnerPath::Off => T::zero(),
            InnerPath::Gain(k) => *k * ym,
            InnerPath::Pid(g) => g.update(ym, T::zero()),
        }
    }

    fn reset(&mut self) {
        if let InnerPath::Pid(g) = self {
            g.reset();
        }
    }

    fn reset_to_rest(&mut self) {
        if let InnerPath::Pid(g) = self {
            g.reset_to_rest();
        }
    }

    /// `Gc2(e^{jθ})`.
    fn response(&self, theta: T) -> Complex<T> {
        self.response_at(&Frequency::new(theta))
    }

    /// `Gc2` at any [`Point`].
    fn response_at<P: Point<T>>(&self, at: &P) -> P::V {
        match self {
            InnerPath::Off => P::V::zero(),
            InnerPath::Gain(k) => P::V::constant(*k),
            InnerPath::Pid(g) => g.response_at(at).0,
        }
    }
}

/// The disturbance controller on the model error, subtracted at the plant input.
#[derive(Debug, Clone)]
// a plain tag byte: the per-sample dispatch is one load and compare
#[repr(u8)]
pub enum DisturbancePath<T, S> {
    /// None.
    Off,
    /// A rational controller (P, PD, lead-lag, PI, resonant …).
    Block(Lti<T, AUX>),
    /// Åström–Hang–Lim's `M(s)`, which contains the dead time.
    AstromHangLim(AhlFilter<T, S>),
}

/// Åström, Hang & Lim's disturbance compensator (Bag (2022)
/// Eqs. 4.16–4.17, for the model `Kv e^{−Ls}/s`):
///
/// `M(s) = (1/Kv)·(k4 + k3/s) / (1 + k1 + k2/s + k3/s² − (k4/s + k3/s²)·e^{−Ls})`,
/// `k4 = k2 + k3·L`.
///
/// With this `M` the load loop `1 + M·(Kv/s)·e^{−Ls}` has the delay-free
/// characteristic polynomial `(1 + k1)s² + k2 s + k3`. The two poles of the
/// denominator at `s = 0` cancel by the choice of `k4`; the filter is realized
/// without them as
///
/// `m = (Kv⁻¹·k4·ε + I)/(1 + k1)`, `İ = Kv⁻¹·k3·ε − k2·m + k4·m(t − L) − k3·W`,
/// `W = ∫_{t−L}^{t} m`,
///
/// one integrator (the integral action that removes load offsets) and a
/// moving window of `m` — no unstable or marginal mode. `k4` is derived from
/// the window length actually used (`L` rounded to whole samples), so the
/// cancellation at DC is exact in discrete time too.
#[derive(Debug, Clone)]
pub struct AhlFilter<T, S> {
    k1: T,
    k2: T,
    k3: T,
    k4: T,
    inv_kv: T,
    h: T,
    integral: T,
    window: Sum<T>,
    line: Delay<T, S>,
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> AhlFilter<T, S> {
    /// `M(s)` for velocity gain `kv`, sample period `ts` and a line of whole
    /// samples `line` holding the dead time.
    pub fn new(k1: T, k2: T, k3: T, kv: T, ts: T, line: Delay<T, S>) -> Result<Self, Error> {
        let (k1, k2, k3) = (finite(k1, "k1")?, finite(k2, "k2")?, finite(k3, "k3")?);
        if kv == T::zero() || !kv.is_finite() {
            return Err(Error::OutOfRange("k"));
        }
        if !(T::one() + k1 > T::zero()) {
            return Err(Error::OutOfRange("k1"));
        }
        let h = crate::real::positive(ts, "ts")?;
        let window_len = line.delay().floor() * h;
        Ok(AhlFilter {
            k1,
            k2,
            k3,
            k4: k2 + k3 * window_len,
            inv_kv: T::one() / kv,
            h,
            integral: T::zero(),
            window: Sum::default(),
            line,
        })
    }

    #[inline]
    fn step(&mut self, eps: T) -> T {
        let m = (self.k4 * self.inv_kv * eps + self.integral) / (T::one() + self.k1);
        let m_old = self.line.process(m);
        self.window.add(self.h * (m - m_old));
        let w = self.window.value();
        self.integral = self.integral
            + self.h * (self.k3 * self.inv_kv * eps - self.k2 * m + self.k4 * m_old - self.k3 * w);
        m
    }

    fn reset(&mut self) {
        self.integral = T::zero();
        self.window = Sum::default();
        self.line.reset();
    }

    /// A new dead time of `samples` (whole samples): `k4 = k2 + k3·L` for the
    /// new window and the window's integral `W` over the last `L` outputs,
    /// which the line still holds. At a steady state (`m` constant, `ε = 0`)
    /// the integrator's balance `−k2·m + k4·m − k3·W = 0` holds for any `L`,
    /// so the filter is the one built for the new dead time.
    fn set_delay(&mut self, samples: T) -> Result<(), Error> {
        let n = crate::delay::whole_samples(
            samples,
            self.line.capacity(),
            "Åström–Hang–Lim's M takes a dead time of whole samples",
        )?;
        let whole = crate::delay::samples_of(n)?;
        let mut w = Sum::default();
        for j in 1..=n {
            w.add(self.h * self.line.peek_back(T::zero(), j));
        }
        self.line.set_delay(whole)?;
        self.window = w;
        self.k4 = self.k2 + self.k3 * whole * self.h;
        Ok(())
    }

    /// `M(z) = num/den` of the sampled filter: with `q = h/(z − 1)` and
    /// `D = z^{−d}`, `num = (k4 + q·k3)/Kv`,
    /// `den = (1 + k1) + q(k2 − k4·D) + q·k3·h·z(1 − D)/(z − 1)`, the
    /// determinant of the filter's own loop (its integrator and window).
    /// At any [`Point`], with `w = z^{−1}`:
    /// `q = h·w/(1 − w)`, `z(1 − D)/(z − 1) = (1 − D)/(1 − w)`.
    fn parts_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V) {
        let k = P::V::constant;
        let one = P::V::one();
        let w = at.backward();
        let q = k(self.h) * w.clone() / (one.clone() - w.clone());
        let d = at.delay(self.line.delay());
        let num = (k(self.k4) + q.clone() * k(self.k3)) * k(self.inv_kv);
        let win = (one.clone() - d.clone()) / (one - w) * k(self.h * self.k3);
        let den = k(T::one() + self.k1) + q.clone() * (k(self.k2) - d * k(self.k4)) + q * win;
        (num, den)
    }
}

/// The general modified Smith predictor (see the module documentation).
#[derive(Debug, Clone)]
pub struct Compensator<T, const N: usize, S> {
    gc1: Pid<T>,
    gc2: InnerPath<T>,
    err: ErrorPath<T, S>,
    dist: DisturbancePath<T, S>,
    corr: Option<Lti<T, AUX>>,
    /// The correction is Watanabe–Ito's `m(s) = Kv·L/(1 + sL)`, which a new
    /// dead time `L` redesigns (`Kv` from its static gain `Kv·L`, the period
    /// from the PID's). A flag, not the values: it fits in the padding
    /// beside the other flags, and the per-sample fields keep the offsets
    /// a Cortex-M's loads reach without an address computation.
    corr_integrating: bool,
    model: DelayedModel<T, N, S>,
    u_min: T,
    u_max: T,
    /// A finite actuator limit: the output is clamped.
    limited: bool,
    params: ParamList<T>,
    u1: T,
    u3: T,
    u: T,
    fault: bool,
    failsafe: Option<T>,
}

/// The controllers a scheme of this family sets around its model: `Gc1` on
/// the set-point error, an inner `Gc2` on the model output, and a block on
/// the model error — the structure of the Karan–Dey MSP (Bag (2022)
/// Fig. 4.11, Eqs. 4.22–4.24), which also holds Kaya–Atherton's PI-PD
/// predictor (Fig. 4.10, Eq. 4.18), Matausek–Micić's (Sec. 4.4.3) and the
/// disturbance estimator of Draganović, Stojić & Matijević (`Gc2` absent).
#[derive(Debug, Clone)]
pub struct Controllers<T> {
    /// `Gc1`.
    pub gc1: Pid<T>,
    /// `Gc2` (`None`: no inner feedback).
    pub gc2: Option<Pid<T>>,
    /// The block on the model error (`None`: no disturbance path).
    pub gc3: Option<Lti<T, AUX>>,
}

/// A scheme's parameters that design its [`Controllers`].
pub trait CompensatorParams<T: Real>: ParamSet<T> {
    /// The controllers, sampled every `ts`.
    fn controllers(&self, ts: T) -> Result<Controllers<T>, Error>;
}

/// The compensator of the scheme `p` around the delay-free model `model`
/// (strictly proper) and its dead-time line, sampled every `ts`.
pub fn build<T: Real, P: CompensatorParams<T>, const N: usize, S: AsRef<[T]> + AsMut<[T]>>(
    p: &P,
    ts: T,
    model: Lti<T, N>,
    delay: Delay<T, S>,
) -> Result<Compensator<T, N, S>, Error> {
    let c = p.controllers(ts)?;
    let mut out = Compensator::new(c.gc1, model, delay, ParamList::of(p))?;
    if let Some(gc2) = c.gc2 {
        out = out.with_inner(gc2);
    }
    if let Some(gc3) = c.gc3 {
        out = out.with_disturbance(DisturbancePath::Block(gc3));
    }
    Ok(out)
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Compensator<T, N, S> {
    /// A compensator with primary controller `gc1` around the model `model`
    /// (strictly proper) and its dead time `delay`; the other paths start
    /// absent (a classic Smith predictor) and are added with the `with_*` methods.
    pub fn new(
        gc1: Pid<T>,
        model: Lti<T, N>,
        delay: Delay<T, S>,
        params: ParamList<T>,
    ) -> Result<Self, Error> {
        let model = DelayedModel::new(model, delay)?;
        Ok(Compensator {
            gc1,
            gc2: InnerPath::Off,
            err: ErrorPath::Direct,
            dist: DisturbancePath::Off,
            corr: None,
            corr_integrating: false,
            model,
            u_min: T::neg_infinity(),
            u_max: T::infinity(),
            limited: false,
            params,
            u1: T::zero(),
            u3: T::zero(),
            u: T::zero(),
            fault: false,
            failsafe: None,
        })
    }

    /// The output to give while the set point or measurement is not finite
    /// (`None`: hold the last output).
    pub fn with_failsafe(mut self, value: Option<T>) -> Result<Self, Error> {
        if let Some(v) = value {
            finite(v, "failsafe")?;
        }
        self.failsafe = value;
        Ok(self)
    }

    /// Inner feedback `Gc2` of the model output (P or PD). A proportional
    /// controller without limits is kept as its gain `kp·b` (the same output,
    /// `kp·(b·ym − 0)`, in one multiplication).
    pub fn with_inner(mut self, gc2: Pid<T>) -> Self {
        let c = gc2.config();
        let plain_p = c.ki == T::zero()
            && c.kd == T::zero()
            && !c.u_min.is_finite()
            && !c.u_max.is_finite()
            && !c.rate_limit.is_finite();
        self.gc2 = if plain_p {
            InnerPath::Gain(c.kp * c.b)
        } else {
            InnerPath::Pid(gc2)
        };
        self
    }

    /// How the model error enters the primary loop.
    pub fn with_error_path(mut self, path: ErrorPath<T, S>) -> Result<Self, Error> {
        match &path {
            ErrorPath::Filter(f) if f.order() > AUX => return Err(Error::OrderTooHigh("filter")),
            ErrorPath::Huang { b, line } => {
                if b.output(T::one()) != b.free_output() {
                    return Err(Error::Improper("b"));
                }
                if line.delay() < T::one() {
                    return Err(Error::OutOfRange("delay"));
                }
            }
            _ => {}
        }
        self.err = path;
        Ok(self)
    }

    /// The disturbance controller on the model error.
    pub fn with_disturbance(mut self, path: DisturbancePath<T, S>) -> Self {
        self.dist = path;
        self
    }

    /// Watanabe–Ito's predictor correction `m(s)` (strictly proper), driven by `u1`.
    pub fn with_correction(mut self, m: Lti<T, AUX>) -> Result<Self, Error> {
        if m.output(T::one()) != m.free_output() {
            return Err(Error::Improper("m"));
        }
        self.corr = Some(m);
        Ok(self)
    }

    /// Watanabe–Ito's correction `m(s) = Kv·L/(1 + sL)` for the velocity
    /// gain `kv` and the dead time `l` (s) at the period `ts`; it is
    /// redesigned when the dead time changes at run time.
    pub fn with_integrating_correction(self, kv: T, l: T, ts: T) -> Result<Self, Error> {
        if ts != self.gc1.config().ts {
            return Err(Error::Unsupported(
                "the correction's period is the controller's",
            ));
        }
        let m = Self::integrating_correction(kv, l, ts)?;
        let mut c = self.with_correction(m)?;
        c.corr_integrating = true;
        Ok(c)
    }

    fn integrating_correction(kv: T, l: T, ts: T) -> Result<Lti<T, AUX>, Error> {
        let l = crate::real::positive(l, "l")?;
        Lti::from_tf(
            &[finite(kv, "k")? * l],
            &[l, T::one()],
            ts,
            crate::lti::Discretization::Zoh,
        )
    }

    /// Actuator limits on `u`.
    pub fn with_limits(mut self, u_min: T, u_max: T) -> Result<Self, Error> {
        if u_min.is_nan() {
            return Err(Error::NonFinite("u_min"));
        }
        if u_max.is_nan() {
            return Err(Error::NonFinite("u_max"));
        }
        if u_min > u_max {
            return Err(Error::InvalidLimits("u_min"));
        }
        self.u_min = u_min;
        self.u_max = u_max;
        self.limited = u_min.is_finite() || u_max.is_finite();
        Ok(self)
    }

    /// Reports `params` instead of the parameters given at construction (a
    /// scheme that builds this compensator as part of a larger one).
    pub fn with_params(mut self, params: ParamList<T>) -> Self {
        self.params = params;
        self
    }

    /// The primary controller.
    pub fn primary(&self) -> &Pid<T> {
        &self.gc1
    }

    /// A sample with a non-finite input: the output is held (or the fail-safe
    /// value given); the model keeps following what the plant receives.
    #[cold]
    #[inline(never)]
    fn on_fault(&mut self, y: T) -> T {
        self.fault = true;
        if let Some(f) = self.failsafe {
            self.u = f;
        }
        let drive = if self.drives_model_with_u1() {
            self.u1
        } else {
            self.u
        };
        self.model.predict(y);
        self.model.advance(drive);
        self.u
    }

    fn drives_model_with_u1(&self) -> bool {
        !matches!(self.dist, DisturbancePath::Off)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Controller<T> for Compensator<T, N, S> {
    #[inline]
    fn update(&mut self, r: T, y: T) -> T {
        // NaN or ±∞ in r or y, or a control error too large to compute
        // with (`Real::usable`): the output held, the fault raised
        if !(r - y).usable() {
            return self.on_fault(y);
        }
        self.fault = false;
        // y is finite
        let (ym, eps) = self.model.predict_finite(y);
        let fed = if let ErrorPath::Direct = self.err {
            eps
        } else {
            self.err.step(eps)
        };
        let feedback = match &self.corr {
            None => ym + fed,
            Some(c) => ym + fed - c.free_output(),
        };
        let inner = self.gc2.update(ym);
        let u1 = self.gc1.update(r, feedback) - inner;
        self.u1 = u1;
        let (u3, drive_u1) = match &mut self.dist {
            DisturbancePath::Off => (T::zero(), false),
            DisturbancePath::Block(b) => (b.step(eps), true),
            DisturbancePath::AstromHangLim(m) => (m.step(eps), true),
        };
        self.u3 = u3;
        let u = if self.limited {
            crate::real::clamp(u1 - u3, self.u_min, self.u_max)
        } else {
            u1 - u3
        };
        self.u = u;
        let drive = if drive_u1 { u1 } else { u };
        self.model.advance(drive);
        if let Some(c) = &mut self.corr {
            c.advance(drive);
        }
        u
    }

    fn reset(&mut self) {
        self.gc1.reset();
        self.gc2.reset();
        match &mut self.err {
            ErrorPath::Filter(f) => f.reset(),
            ErrorPath::Huang { b, line } => {
                b.reset();
                line.reset();
            }
            ErrorPath::Direct | ErrorPath::Blocked => {}
        }
        match &mut self.dist {
            DisturbancePath::Block(b) => b.reset(),
            DisturbancePath::AstromHangLim(m) => m.reset(),
            DisturbancePath::Off => {}
        }
        if let Some(c) = &mut self.corr {
            c.reset();
        }
        self.model.reset();
        self.u1 = T::zero();
        self.u3 = T::zero();
        self.u = T::zero();
        self.fault = false;
    }

    fn reset_to_rest(&mut self) {
        self.reset();
        // the PIDs are the blocks with a first sample of their own
        self.gc1.reset_to_rest();
        self.gc2.reset_to_rest();
    }

    fn fault(&self) -> bool {
        self.fault
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> CascadeControl<T>
    for Compensator<T, N, S>
{
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Compensator<T, N, S> {
    /// `(Cr, Cy)` at any [`Point`] (see [`FrequencyResponse::response`]).
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V) {
        let one = P::V::one();
        let (g1r, g1y) = self.gc1.response_at(at);
        let g2 = self.gc2.response_at(at);
        let (gm, d) = self.model.response_at(at);
        let f = match &self.err {
            ErrorPath::Direct => one.clone(),
            ErrorPath::Blocked => P::V::zero(),
            ErrorPath::Filter(f) => at.lti(f),
            ErrorPath::Huang { b, line } => {
                let bb = at.lti(b);
                let dl = at.delay(line.delay());
                (one.clone() + bb.clone()) / (one.clone() + bb * dl)
            }
        };
        let gd = match &self.dist {
            DisturbancePath::Off => P::V::zero(),
            DisturbancePath::Block(b) => at.lti(b),
            DisturbancePath::AstromHangLim(m) => {
                let (num, den) = m.parts_at(at);
                num / den
            }
        };
        let mc = self.corr.as_ref().map_or(P::V::zero(), |c| at.lti(c));
        let den = one.clone()
            + g1y.clone() * (gm.clone() - f.clone() * d.clone() * gm.clone() - mc)
            + g2 * gm.clone();
        let through = one + gd.clone() * d * gm;
        (
            g1r * through.clone() / den.clone(),
            g1y * f * through / den + gd,
        )
    }
}
