//! The Karan–Dey three-controller modified Smith predictor (MSP) for
//! integrating processes with long dead time (`000_3f0725a46e29ef08.txt` Sec. 4.5).
//!
//! Controllers (Eqs. 4.22–4.24):
//! `Gc1 = Kp(1 + 1/(Ti s))` (set-point, IMC-PI), `Gc2 = β·Kp` (stabilizing, P),
//! `Gc3 = γ·Kp(1 + Td s/(1 + (Td/N) s))` (disturbance rejection, PD with a
//! derivative filter; the thesis leaves `Gc3` unfiltered, which is not
//! realizable — `N = 10` by default, the same ratio as Kaya–Atherton's
//! `Gc3 = kb(Td s + 1)/(0.1 Td s + 1)` in Sec. 4.4.3).
//!
//! The thesis's block diagram (Fig. 4.11) is missing from the source. This
//! realization reproduces its set-point response (Eq. 4.20) and its
//! disturbance response (Eq. 4.21 with the term `Gc1·Gc3·e^{−θs}` read as
//! `Gm·Gc1·e^{−θs}`, see the seeds' README):
//!
//! ```text
//! u1 = Gc1·(r − ym − ε) − Gc2·ym      ym = Gm·u1  (delay-free model)
//! ε  = y − e^{−θm s}·ym               u  = u1 − Gc3·ε
//! ```
//!
//! Derivation: with `y = e^{−θs}G(u + d)` and a perfect model,
//! `ε = e^{−θs}G(d − Gc3 ε)`, so `ε = e^{−θs}G d/(1 + Gc3 G e^{−θs})` (the
//! characteristic equation 4.41) and `ε = 0` without a load: then
//! `y = e^{−θs}·ym = e^{−θs}·Gm Gc1/(1 + Gm(Gc1 + Gc2))·r`, Eq. 4.20. With the
//! tuning of [`crate::tuning::karan_dey`] this is exactly `e^{−θs}/(1 + θs/8)`.
//! Under a constant input load `d`, `ε → d/(γKp)`, the integral of `Gc1`
//! drives `ym → r − ε`, so `y → r` (zero steady-state error) and `u → −d`.

use crate::delay::{Delay, DelayStorage};
use crate::dtc::Controller;
use crate::real::{finite, non_negative, positive};
use crate::{Error, Lti, Pid, PidConfig, ProcessModel, Real};

/// Tuned parameters of the Karan–Dey MSP (names as in reports and `--set`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct KaranDeyParams<T> {
    /// Proportional gain `Kp` shared by the three controllers.
    pub kp: T,
    /// Integral time `Ti` of `Gc1` (s).
    pub ti: T,
    /// Weight `β` of `Gc2 = β·Kp`.
    pub beta: T,
    /// Weight `γ` of `Gc3 = γ·Kp(1 + Td s)`.
    pub gamma: T,
    /// Derivative time `Td` of `Gc3` (s).
    pub td: T,
    /// Derivative filter ratio `N` of `Gc3` (`Tf = Td/N`).
    pub n: T,
}

impl<T: Real> KaranDeyParams<T> {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.kp, "kp")?;
        positive(self.ti, "ti")?;
        non_negative(self.beta, "beta")?;
        non_negative(self.gamma, "gamma")?;
        non_negative(self.td, "td")?;
        positive(self.n, "n")?;
        Ok(())
    }
}

/// The Karan–Dey MSP with a model of order `≤ N` and delay storage `S`.
#[derive(Debug, Clone)]
pub struct KaranDey<T, const N: usize, S> {
    params: KaranDeyParams<T>,
    gc1: Pid<T>,
    gc2: T,
    gc3: Pid<T>,
    model: Lti<T, N>,
    delay: Delay<T, S>,
    u_min: T,
    u_max: T,
    ym: T,
    eps: T,
    u1: T,
    u3: T,
    u: T,
    fault: bool,
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> KaranDey<T, N, S> {
    /// An MSP from its parts: the delay-free model `Gm` (strictly proper), its
    /// dead time, and the sample period. Output limits default to none.
    pub fn new(
        params: KaranDeyParams<T>,
        model: Lti<T, N>,
        delay: Delay<T, S>,
        ts: T,
    ) -> Result<Self, Error> {
        params.validate()?;
        if model.output(T::one()) != model.free_output() {
            return Err(Error::Improper("model"));
        }
        let gc1 = Pid::new(PidConfig::isa(params.kp, params.ti, T::zero(), ts))?;
        let gk = params.gamma * params.kp;
        let gc3 = Pid::new(
            PidConfig::parallel(gk, T::zero(), gk * params.td, ts)
                .with_filter_time(params.td / params.n),
        )?;
        Ok(KaranDey {
            params,
            gc1,
            gc2: params.beta * params.kp,
            gc3,
            model,
            delay,
            u_min: T::neg_infinity(),
            u_max: T::infinity(),
            ym: T::zero(),
            eps: T::zero(),
            u1: T::zero(),
            u3: T::zero(),
            u: T::zero(),
            fault: false,
        })
    }

    /// Actuator limits applied to `u`.
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
        Ok(self)
    }

    /// The parameters.
    pub fn params(&self) -> &KaranDeyParams<T> {
        &self.params
    }
}

impl<T: Real, const N: usize, S: DelayStorage<T>> KaranDey<T, N, S> {
    /// An MSP whose model is `model` ZOH-discretized at `ts`.
    pub fn from_model(
        params: KaranDeyParams<T>,
        model: &ProcessModel<T>,
        ts: T,
    ) -> Result<Self, Error> {
        let (block, d) = model.discretize::<N>(finite(ts, "ts")?)?;
        Self::new(params, block, Delay::new_in(d)?, ts)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Controller<T> for KaranDey<T, N, S> {
    #[inline]
    fn update(&mut self, r: T, y: T) -> T {
        if !(r.is_finite() && y.is_finite()) {
            self.fault = true;
            self.ym = self.model.step(self.u1);
            self.delay.process(self.ym);
            return self.u;
        }
        self.fault = false;
        let ym = self.model.free_output();
        let eps = y - self.delay.process(ym);
        let u1 = self.gc1.update(r, ym + eps) - self.gc2 * ym;
        let u3 = self.gc3.update(eps, T::zero());
        let u = (u1 - u3).max(self.u_min).min(self.u_max);
        self.model.step(u1);
        self.ym = ym;
        self.eps = eps;
        self.u1 = u1;
        self.u3 = u3;
        self.u = u;
        u
    }

    fn reset(&mut self) {
        self.gc1.reset();
        self.gc3.reset();
        self.model.reset();
        self.delay.reset();
        self.ym = T::zero();
        self.eps = T::zero();
        self.u1 = T::zero();
        self.u3 = T::zero();
        self.u = T::zero();
        self.fault = false;
    }

    fn signal_names(&self) -> &'static [&'static str] {
        &["ym", "epsilon", "u1", "u3"]
    }

    fn signal(&self, i: usize) -> T {
        match i {
            0 => self.ym,
            1 => self.eps,
            2 => self.u1,
            3 => self.u3,
            _ => T::nan(),
        }
    }

    fn param_names(&self) -> &'static [&'static str] {
        &["kp", "ti", "beta", "gamma", "td", "n"]
    }

    fn param(&self, i: usize) -> T {
        let p = &self.params;
        match i {
            0 => p.kp,
            1 => p.ti,
            2 => p.beta,
            3 => p.gamma,
            4 => p.td,
            5 => p.n,
            _ => T::nan(),
        }
    }

    fn fault(&self) -> bool {
        self.fault
    }
}
