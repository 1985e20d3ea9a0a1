//! A model-error monitor: does the controller's model still explain the
//! process? Usable without adapting — the alarm a plant operator wants.
//!
//! The model `y[k+1] = a·y[k] + b0·u[k−d] + b1·u[k−d−1]` (the estimator's,
//! [`super::Estimator`]) predicts each differenced output one sample ahead
//! from the measured one (equation-error form):
//!
//! `r[k+1] = Δy[k+1] − a·Δy[k] − b0·Δu[k−d] − b1·Δu[k−d−1]`.
//!
//! With the right model, `r` is the noise `(1 − a·z⁻¹)(1 − z⁻¹)·n` — its
//! variance `(1 + (1 + a)² + a²)·σ²` for white measurement noise of
//! standard deviation `σ` — plus a single-sample pulse at a load step (a
//! step load at the input or the output is a pulse in the differenced
//! equation error, not a lasting one). A wrong gain, lag or dead time
//! leaves a residual every time the input moves. The monitor's statistic is
//! the residual's mean square over an exponential window; it raises the
//! alarm when the statistic exceeds `ratio²` times the noise's for `hold`
//! consecutive samples, and clears it when the statistic falls below the
//! noise's level times `ratio` (hysteresis). A residual test of this kind
//! is Åström & Wittenmark (1995) Sec. 11.2 (supervision) on Ljung (1999)
//! Sec. 16.6 (model validation by the residuals).

use super::History;
use crate::{Error, Real};

/// Settings of a [`Monitor`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonitorConfig<T> {
    /// The model: `a = e^{−Ts/τ}` (1 for an integrating process).
    pub a: T,
    /// `b0`, the input's coefficient `d` samples back.
    pub b0: T,
    /// `b1`, the input's coefficient `d + 1` samples back.
    pub b1: T,
    /// The model's whole dead time (samples).
    pub d: usize,
    /// Standard deviation of the measurement noise (the same unit as `y`).
    pub noise: T,
    /// The alarm at `ratio²` times the noise's mean square (default 3).
    pub ratio: T,
    /// The window's memory in samples (default 200).
    pub memory: T,
    /// Samples the statistic must stay above the limit (default 50).
    pub hold: u32,
}

impl<T: Real> MonitorConfig<T> {
    /// The model `K e^{−θs}/(τs + 1)` sampled every `ts` (`tau` infinite:
    /// `K e^{−θs}/s`), its dead time's fraction in `b0`, `b1` (exact ZOH),
    /// for noise of standard deviation `noise`.
    pub fn for_model(k: T, tau: T, theta: T, ts: T, noise: T) -> Result<Self, Error> {
        let ts = crate::real::positive(ts, "ts")?;
        crate::real::non_negative(theta, "theta")?;
        crate::real::non_negative(noise, "noise")?;
        crate::real::finite(k, "k")?;
        let samples = theta / ts;
        let d = samples.floor();
        let f = samples - d;
        let d = d
            .to_usize()
            .ok_or(Error::DelayTooLong("monitor dead time"))?;
        let (a, b0, b1) = if tau.is_infinite() && tau > T::zero() {
            (T::one(), k * ts * (T::one() - f), k * ts * f)
        } else {
            let tau = crate::real::positive(tau, "tau")?;
            let a = (-ts / tau).exp();
            let af = a.powf(T::one() - f);
            (a, k * (T::one() - af), k * (af - a))
        };
        Ok(MonitorConfig {
            a,
            b0,
            b1,
            d,
            noise,
            ratio: T::of(3.0),
            memory: T::of(200.0),
            hold: 50,
        })
    }
}

/// The model-error monitor over a history of `H` input differences
/// (`H ≥ d + 2`).
#[derive(Debug, Clone)]
pub struct Monitor<T, const H: usize> {
    cfg: MonitorConfig<T>,
    hist: History<T, H>,
    last_y: T,
    last_dy: T,
    samples: u32,
    /// The residual's exponentially weighted mean square.
    ms: T,
    above: u32,
    alarm: bool,
}

impl<T: Real, const H: usize> Monitor<T, H> {
    /// A monitor of the model in `cfg`.
    pub fn new(cfg: MonitorConfig<T>) -> Result<Self, Error> {
        if H < cfg.d.saturating_add(2) {
            return Err(Error::OutOfRange(
                "monitor: the history must hold the dead time + 2 inputs",
            ));
        }
        if !(cfg.memory >= T::one()) {
            return Err(Error::OutOfRange("monitor memory: at least one sample"));
        }
        crate::real::positive(cfg.ratio, "monitor ratio")?;
        Ok(Monitor {
            cfg,
            hist: History::new(),
            last_y: T::zero(),
            last_dy: T::zero(),
            samples: 0,
            ms: T::zero(),
            above: 0,
            alarm: false,
        })
    }

    /// The noise's share of the residual's mean square:
    /// `(1 + (1 + a)² + a²)·σ²`.
    pub fn noise_level(&self) -> T {
        let a = self.cfg.a;
        let s = self.cfg.noise;
        (T::one() + (T::one() + a) * (T::one() + a) + a * a) * s * s
    }

    /// One sample: `y` measured now, `u_applied` the input the plant
    /// received over the period that just ended; `ok` false for a sample
    /// that is not the process's own response (saturated, manual, a
    /// fault), which the statistic skips. Returns the alarm.
    pub fn update(&mut self, y: T, u_applied: T, ok: bool) -> bool {
        if !(y.is_finite() && u_applied.is_finite()) {
            return self.alarm;
        }
        let dy = y - self.last_y;
        if ok && self.samples >= 2 {
            let c = self.cfg;
            let r = dy
                - c.a * self.last_dy
                - c.b0 * self.hist.back(c.d)
                - c.b1 * self.hist.back(c.d + 1);
            let w = T::one() / c.memory;
            self.ms = self.ms + w * (r * r - self.ms);
            let level = self.noise_level();
            let limit = c.ratio * c.ratio * level;
            if self.ms > limit {
                self.above = self.above.saturating_add(1);
                if self.above >= c.hold {
                    self.alarm = true;
                }
            } else {
                self.above = 0;
                if self.ms < c.ratio * level {
                    self.alarm = false;
                }
            }
        }
        self.hist.push(u_applied);
        self.last_y = y;
        self.last_dy = dy;
        self.samples = self.samples.saturating_add(1);
        self.alarm
    }

    /// The alarm: the model no longer explains the process.
    pub fn alarm(&self) -> bool {
        self.alarm
    }

    /// The residual's mean square over the noise's (1 for a right model
    /// under white noise; the alarm is at `ratio²`).
    pub fn mismatch(&self) -> T {
        let level = self.noise_level();
        if level > T::zero() {
            self.ms / level
        } else if self.ms > T::zero() {
            T::infinity()
        } else {
            T::zero()
        }
    }
}
