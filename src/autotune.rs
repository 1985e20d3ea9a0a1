//! Relay autotuning on the process: a sample-by-sample relay experiment and the
//! exact identification of a process model from its limit cycle.
//!
//! The experiment (Kaya (2003) Fig. 4, Sec. 3.1): starting from
//! a steady state `(u0, y0)`, the actuator is switched between `u0 + bias ± h`
//! by a relay with hysteresis `ε` on `e = y0 − y`; the loop settles into a
//! limit cycle whose half-periods and extremes identify the process. The
//! experiment ends when `cycles` consecutive periods agree within `tolerance`
//! (periods and amplitudes), and aborts — actuator back at `u0` — on a
//! timeout or when `y` leaves `y0 ± band`.
//!
//! Identification uses the time-domain limit-cycle relations, exact for
//! plants of the model's form (not the describing-function approximation):
//!
//! - **IPDT** `K e^{−Ls}/s`, symmetric relay: the output ramps at `±K h`, so
//!   the peak is `a = ε + K h L` and the period `P = 4L + 4ε/(K h)`, giving
//!   `K = 4a/(hP)`, `L = (a − ε)P/(4a)`.
//! - **FOPDT** `K e^{−Ls}/(Ts + 1)` with relay levels `u₊ = bias + h`,
//!   `u₋ = bias − h` (Kaya & Atherton 2001, the asymmetric relay gives the
//!   gain): over a period of the limit cycle the mean output is `K` times the
//!   mean input (exact, `K = G(0)`); the maximum `a₊ = K u₊ − (K u₊ − ε) e^{−L/T}`
//!   and the falling half-period `P₋ = L + T ln((a₊ − K u₋)/(−ε − K u₋))` then give
//!   `x = e^{−L/T} = (K u₊ − a₊)/(K u₊ − ε)`, `T = P₋/ln((a₊ − K u₋)/((−ε − K u₋)·x))`,
//!   `L = −T ln x` (all in deviations from `(u0, y0)`). Without a bias the
//!   gain must come from elsewhere (a step test, or [`RelayResult::gain`] of a biased run).
//!
//! - **Unstable FOPDT** `K e^{−Ls}/(Ts − 1)` (`T y' = y + K u(t − L)`: from
//!   `y₀` under a constant `u` the output runs away as `−K u + (y₀ + K u)e^{t/T}`),
//!   with an asymmetric relay (Majhi & Atherton (2000) derive the cycle of
//!   this plant under it; the relations here are derived the same way, for
//!   this relay with hysteresis). With `E = e^{L/T}`, from the switch low at
//!   `+ε` the input is `u₊` for `L` more seconds, the peak, then `u₋`, down
//!   to `−ε`, and likewise up: `a₊ = −K u₊ + (ε + K u₊)E`,
//!   `a₋ = −K u₋ + (K u₋ − ε)E`, `P₋ = L + T ln((K u₋ − ε)/(a₊ + K u₋))`,
//!   `P₊ = L + T ln((K u₊ + ε)/(a₋ + K u₊))`. For a trial `L/T`, `a₊` gives
//!   `K`, `P₊` gives `T` and `P₋` is predicted; `L/T` is the root of that
//!   prediction's error (a scan, then bisection), and `a₋` checks the fit.
//!   A symmetric relay leaves `L/T` undetermined (its cycle gives a swing
//!   and a half period for three parameters): a bias is needed, as for the
//!   FOPDT's gain.
//!
//! The describing function also gives the ultimate gain and period,
//! `Ku = 4h/(π a)`, `Tu = P`, for the ultimate-cycle rules of Tables 3.2/3.3.

use crate::real::{finite, non_negative, positive};
use crate::{error::Error, model::Fopdt, model::Ipdt, model::Ufopdt, real::Real};

/// Settings of a relay experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RelayConfig<T> {
    /// Relay amplitude `h` (actuator units); negative for a reverse-acting
    /// process (its output falls as its input rises): the relay then lowers
    /// the input while the output is below its reference, and the identified
    /// gains come out negative.
    pub amplitude: T,
    /// Hysteresis `ε` on the error (output units).
    pub hysteresis: T,
    /// Bias added to both relay levels (asymmetric relay, for the static gain).
    pub bias: T,
    /// Actuator value at the starting steady state.
    pub u0: T,
    /// Output at the starting steady state (the relay's reference).
    pub y0: T,
    /// Actuator limits.
    pub u_min: T,
    /// Actuator limits.
    pub u_max: T,
    /// Abort when `|y − y0|` exceeds this.
    pub band: T,
    /// Abort after this many samples.
    pub max_samples: u32,
    /// Consecutive agreeing periods needed.
    pub cycles: u8,
    /// Relative agreement of consecutive periods and amplitudes.
    pub tolerance: T,
    /// Sample period (s).
    pub ts: T,
}

impl<T: Real> RelayConfig<T> {
    /// A symmetric relay of amplitude `h` around the steady state `(u0, y0)`,
    /// no hysteresis, no bias, band ±∞, 3 agreeing cycles within 1 %, at most
    /// 10⁶ samples.
    pub fn new(amplitude: T, ts: T) -> Self {
        RelayConfig {
            amplitude,
            hysteresis: T::zero(),
            bias: T::zero(),
            u0: T::zero(),
            y0: T::zero(),
            u_min: T::neg_infinity(),
            u_max: T::infinity(),
            band: T::infinity(),
            max_samples: 1_000_000,
            cycles: 3,
            tolerance: T::of(0.01),
            ts,
        }
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<(), Error> {
        // a negative amplitude is a reverse-acting relay (for a process whose
        // output falls as its input rises): the high state lowers the input
        if finite(self.amplitude, "amplitude")? == T::zero() {
            return Err(Error::OutOfRange("amplitude"));
        }
        non_negative(self.hysteresis, "hysteresis")?;
        finite(self.bias, "bias")?;
        if self.bias.abs() >= self.amplitude.abs() {
            return Err(Error::OutOfRange("bias"));
        }
        finite(self.u0, "u0")?;
        finite(self.y0, "y0")?;
        if self.u_min.is_nan() || self.u_max.is_nan() {
            return Err(Error::NonFinite("u_min"));
        }
        if self.u_min > self.u_max {
            return Err(Error::InvalidLimits("u_min"));
        }
        if !(self.band > T::zero()) {
            return Err(Error::NotPositive("band"));
        }
        if self.cycles == 0 {
            return Err(Error::OutOfRange("cycles"));
        }
        positive(self.tolerance, "tolerance")?;
        positive(self.ts, "ts")?;
        Ok(())
    }
}

/// What a settled limit cycle measured (deviations from `(u0, y0)`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RelayResult<T> {
    /// Relay amplitude `h`.
    pub amplitude: T,
    /// Hysteresis `ε`.
    pub hysteresis: T,
    /// Bias.
    pub bias: T,
    /// Half-period with the relay high (s).
    pub t_up: T,
    /// Half-period with the relay low (s).
    pub t_down: T,
    /// Period `P = t_up + t_down` (s).
    pub period: T,
    /// Largest output deviation over the last period.
    pub a_max: T,
    /// Smallest output deviation over the last period.
    pub a_min: T,
    /// Mean actuator deviation over the last period.
    pub mean_u: T,
    /// Mean output deviation over the last period.
    pub mean_y: T,
    /// Periods run.
    pub cycles: u32,
}

impl<T: Real> RelayResult<T> {
    /// The static gain `mean(y)/mean(u)` over a period (needs a bias).
    pub fn gain(&self) -> Option<T> {
        if self.bias == T::zero() || self.mean_u.abs() < T::epsilon() {
            None
        } else {
            Some(self.mean_y / self.mean_u)
        }
    }

    /// Describing-function ultimate gain `Ku = 4h/(πa)` and period `Tu = P`.
    pub fn ultimate(&self) -> (T, T) {
        let a = T::half() * (self.a_max - self.a_min);
        (T::of(4.0) * self.amplitude / (T::PI() * a), self.period)
    }
}

/// Why an experiment stopped without a result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum RelayAbort {
    /// No settled limit cycle within the sample budget.
    Timeout,
    /// The output left the safety band.
    OutOfBand,
    /// A non-finite measurement.
    BadMeasurement,
}

impl core::fmt::Display for RelayAbort {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            RelayAbort::Timeout => "the limit cycle did not settle in time",
            RelayAbort::OutOfBand => "the output left its safety band",
            RelayAbort::BadMeasurement => "a measurement was not a finite number",
        })
    }
}

/// The state of the experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum RelayState<T> {
    /// Still oscillating.
    Running,
    /// A settled limit cycle: the actuator is back at `u0`.
    Done(RelayResult<T>),
    /// Stopped: the actuator is back at `u0`.
    Aborted(RelayAbort),
}

/// The relay experiment, one sample at a time (no_std, no allocation).
///
/// On the thesis's benchmark `0.2 e^{−7.4s}/s` (Bag (2022) Eq. 5.1), sampled
/// every 0.1 s: the relay's limit cycle identifies the plant exactly.
///
/// ```
/// use msp::autotune::{identify_ipdt, RelayConfig, RelayState, RelayTest};
/// let ts = 0.1;
/// let mut test = RelayTest::new(RelayConfig { hysteresis: 0.05, ..RelayConfig::new(1.0, ts) })?;
/// // the plant: an integrator behind 74 samples of dead time
/// let (mut y, mut line) = (0.0f64, [0.0f64; 74]);
/// for k in 0.. {
///     let u = test.update(y);
///     let slot = &mut line[k % 74];
///     y += 0.2 * ts * *slot; // the input of 74 samples ago
///     *slot = u;
///     if test.state() != RelayState::Running {
///         break;
///     }
/// }
/// let RelayState::Done(cycle) = test.state() else { panic!("{:?}", test.state()) };
/// let m = identify_ipdt(&cycle)?;
/// assert!((m.k - 0.2).abs() < 0.01 && (m.l - 7.4).abs() < 0.15, "{m:?}");
/// # Ok::<(), msp::Error>(())
/// ```
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RelayTest<T> {
    cfg: RelayConfig<T>,
    high: bool,
    k: u32,
    /// Time of the last switch to high and to low (s, interpolated).
    t_high: T,
    t_low: T,
    has_high: bool,
    has_low: bool,
    /// Running extremes and integrals since the last switch to high.
    ymax: T,
    ymin: T,
    int_u: T,
    int_y: T,
    prev_e: T,
    prev_y: T,
    prev_u: T,
    last: Option<RelayResult<T>>,
    agree: u8,
    cycles: u32,
    state: RelayState<T>,
}

impl<T: Real> RelayTest<T> {
    /// A new experiment; the first output is the high level.
    pub fn new(cfg: RelayConfig<T>) -> Result<Self, Error> {
        cfg.validate()?;
        Ok(RelayTest {
            cfg,
            high: true,
            k: 0,
            t_high: T::zero(),
            t_low: T::zero(),
            has_high: false,
            has_low: false,
            ymax: T::neg_infinity(),
            ymin: T::infinity(),
            int_u: T::zero(),
            int_y: T::zero(),
            prev_e: T::zero(),
            prev_y: T::zero(),
            prev_u: T::zero(),
            last: None,
            agree: 0,
            cycles: 0,
            state: RelayState::Running,
        })
    }

    /// The state.
    pub fn state(&self) -> RelayState<T> {
        self.state
    }

    fn level(&self) -> T {
        let c = &self.cfg;
        let d = if self.high { c.amplitude } else { -c.amplitude };
        (c.u0 + c.bias + d).max(c.u_min).min(c.u_max)
    }

    fn stop(&mut self, s: RelayState<T>) -> T {
        self.state = s;
        self.cfg.u0
    }

    /// One sample: the measurement in, the actuator value out.
    pub fn update(&mut self, y: T) -> T {
        if self.state != RelayState::Running {
            return self.cfg.u0;
        }
        if !y.is_finite() {
            return self.stop(RelayState::Aborted(RelayAbort::BadMeasurement));
        }
        let c = self.cfg;
        let dy = y - c.y0;
        if dy.abs() > c.band {
            return self.stop(RelayState::Aborted(RelayAbort::OutOfBand));
        }
        if self.k >= c.max_samples {
            return self.stop(RelayState::Aborted(RelayAbort::Timeout));
        }
        let h = c.ts;
        let t = T::from(self.k).unwrap_or(T::zero()) * h;
        let e = -dy;
        // integrals of the deviations (trapezoid) and extremes over the current period
        if self.k > 0 {
            self.int_u = self.int_u + T::half() * h * (self.prev_u + (self.level() - c.u0));
            self.int_y = self.int_y + T::half() * h * (self.prev_y + dy);
        }
        self.ymax = self.ymax.max(dy);
        self.ymin = self.ymin.min(dy);
        // switching with hysteresis; the crossing instant interpolated in the sample
        let cross = |level: T, prev: T, now: T| {
            if now == prev {
                t
            } else {
                t - h + h * (level - prev) / (now - prev)
            }
        };
        if self.high && e < -c.hysteresis {
            // output above y0 + ε: switch low
            let tc = cross(-c.hysteresis, self.prev_e, e);
            self.high = false;
            self.t_low = tc;
            self.has_low = true;
        } else if !self.high && e > c.hysteresis {
            let tc = cross(c.hysteresis, self.prev_e, e);
            if self.has_high && self.has_low {
                self.period_done(tc);
            }
            self.high = true;
            self.t_high = tc;
            self.has_high = true;
            self.ymax = dy;
            self.ymin = dy;
            self.int_u = T::zero();
            self.int_y = T::zero();
        }
        self.prev_e = e;
        self.prev_y = dy;
        let u = self.level();
        self.prev_u = u - c.u0;
        self.k = self.k.saturating_add(1);
        if let RelayState::Done(_) = self.state {
            return c.u0;
        }
        u
    }

    fn period_done(&mut self, t_now: T) {
        let c = self.cfg;
        let period = t_now - self.t_high;
        if !(period > T::zero()) {
            return;
        }
        self.cycles = self.cycles.saturating_add(1);
        let r = RelayResult {
            amplitude: c.amplitude,
            hysteresis: c.hysteresis,
            bias: c.bias,
            t_up: self.t_low - self.t_high,
            t_down: t_now - self.t_low,
            period,
            a_max: self.ymax,
            a_min: self.ymin,
            mean_u: self.int_u / period,
            mean_y: self.int_y / period,
            cycles: self.cycles,
        };
        let close = |a: T, b: T| (a - b).abs() <= c.tolerance * a.abs().max(b.abs());
        let agrees = self.last.is_some_and(|l| {
            close(l.period, r.period)
                && close(l.a_max - l.a_min, r.a_max - r.a_min)
                && close(l.t_up, r.t_up)
        });
        self.agree = if agrees {
            self.agree.saturating_add(1)
        } else {
            0
        };
        self.last = Some(r);
        // the first periods carry the start-up transient: need `cycles` agreeing pairs
        if self.agree >= c.cycles {
            self.state = RelayState::Done(r);
        }
    }
}

/// IPDT `K e^{−Ls}/s` from a symmetric limit cycle: `K = 4a/(hP)`, `L = (a − ε)P/(4a)`,
/// with `a` the half peak-to-peak amplitude.
pub fn identify_ipdt<T: Real>(r: &RelayResult<T>) -> Result<Ipdt<T>, Error> {
    let a = T::half() * (r.a_max - r.a_min);
    let p = positive(r.period, "period")?;
    let k = T::of(4.0) * a / (r.amplitude * p);
    let l = (a - r.hysteresis) * p / (T::of(4.0) * a);
    Ipdt::new(k, l)
}

/// FOPDT `K e^{−Ls}/(Ts + 1)` from a limit cycle with the static gain `k`
/// (from a biased relay, [`RelayResult::gain`], or known otherwise); exact
/// for FOPDT plants (see the module documentation).
pub fn identify_fopdt<T: Real>(r: &RelayResult<T>, k: T) -> Result<Fopdt<T>, Error> {
    let k = finite(k, "k")?;
    let (up, dn) = (r.bias + r.amplitude, r.bias - r.amplitude);
    let (kup, kdn) = (k * up, k * dn);
    let eps = r.hysteresis;
    let x = (kup - r.a_max) / (kup - eps);
    let ratio = (r.a_max - kdn) / ((-eps - kdn) * x);
    if !(x > T::zero() && x < T::one() && ratio > T::one()) {
        return Err(Error::Numerical(
            "FOPDT identification (the limit cycle is not that of an FOPDT plant)",
        ));
    }
    let t = r.t_down / ratio.ln();
    let l = -t * x.ln();
    Fopdt::new(k, t, l)
}

/// The unstable FOPDT `K e^{−Ls}/(Ts − 1)` of a limit cycle (see the module
/// documentation): exact for plants of that form, from a relay with a bias
/// (a symmetric cycle does not determine it: an error). An error where no ratio
/// `L/T` in `(10⁻³, 3)` reproduces the cycle within 2 % of its swing.
pub fn identify_ufopdt<T: Real>(r: &RelayResult<T>) -> Result<Ufopdt<T>, Error> {
    // a symmetric cycle gives two figures (its swing and half period) for
    // three parameters: every `L/T` fits
    if !(r.bias.abs() > T::of(1e-6) * r.amplitude.abs()) {
        return Err(Error::Unsupported(
            "unstable FOPDT identification needs an asymmetric relay: give it a bias",
        ));
    }
    let (up, dn) = (r.bias + r.amplitude, r.bias - r.amplitude);
    let (eps, a_max, a_min) = (r.hysteresis, r.a_max, r.a_min);
    let swing = a_max - a_min;
    // for a trial g = L/T: (K, T, the error of the predicted P₋, of a₋)
    let trial = |g: T| -> Option<(T, T, T, T)> {
        let e = g.exp();
        let k = (a_max - eps * e) / (up * (e - T::one()));
        let r1 = (k * dn - eps) / (a_max + k * dn);
        let r2 = (k * up + eps) / (a_min + k * up);
        let (l1, l2) = ((e * r1).ln(), (e * r2).ln());
        if !(r1 > T::zero() && r2 > T::zero() && l1 > T::zero() && l2 > T::zero()) {
            return None;
        }
        let t = r.t_up / l2;
        let a_min_model = k * dn * (e - T::one()) - eps * e;
        Some((k, t, t * l1 - r.t_down, (a_min_model - a_min) / swing))
    };
    let (lo, hi) = (T::of(1e-3), T::of(3.0));
    let grid = 400usize;
    let at = |i: usize| lo * (hi / lo).powf(T::of(i as f64) / T::of((grid - 1) as f64));
    let mut best: Option<(T, T, T, T)> = None;
    let mut prev: Option<(T, T)> = None;
    for i in 0..grid {
        let g = at(i);
        let f = trial(g).map(|(_, _, f, _)| f);
        if let (Some((g0, f0)), Some(f1)) = (prev, f) {
            if f0 * f1 <= T::zero() {
                // bisection on the bracket [g0, g]
                let (mut a, mut b, mut fa) = (g0, g, f0);
                for _ in 0..80 {
                    let m = T::half() * (a + b);
                    let Some((_, _, fm, _)) = trial(m) else {
                        break;
                    };
                    if fa * fm <= T::zero() {
                        b = m;
                    } else {
                        (a, fa) = (m, fm);
                    }
                }
                let g = T::half() * (a + b);
                if let Some((k, t, _, miss)) = trial(g) {
                    if best.map_or(true, |(_, _, _, m)| miss.abs() < m.abs()) {
                        best = Some((k, t, g, miss));
                    }
                }
            }
        }
        prev = f.map(|f| (g, f));
    }
    match best {
        Some((k, t, g, miss)) if miss.abs() <= T::of(0.02) => Ufopdt::new(k, t, g * t),
        _ => Err(Error::Numerical(
            "unstable FOPDT identification (the limit cycle is not that of an unstable FOPDT plant)",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::ExpectOk;

    /// Runs the relay on an exactly discretized plant `x' = Φx + Γ u(t − L)`.
    fn run(num: &[f64], den: &[f64], delay: f64, cfg: RelayConfig<f64>) -> RelayState<f64> {
        let plant: crate::lti::Lti<f64, 4> =
            crate::lti::Lti::from_tf(num, den, cfg.ts, crate::lti::Discretization::Zoh).expect_ok();
        let mut p = plant;
        let d = (delay / cfg.ts).round() as usize;
        let mut line = vec![cfg.u0; d + 1];
        let mut test = RelayTest::new(cfg).expect_ok();
        for k in 0..cfg.max_samples as usize + 1 {
            let y = p.free_output();
            let u = test.update(y);
            line[k % (d + 1)] = u;
            p.step(line[(k + 1) % (d + 1)]);
            if test.state() != RelayState::Running {
                break;
            }
        }
        test.state()
    }

    /// The limit cycle of a relay test that finished.
    fn cycle(
        num: &[f64],
        den: &[f64],
        delay: f64,
        cfg: RelayConfig<f64>,
    ) -> Result<RelayResult<f64>, String> {
        match run(num, den, delay, cfg) {
            RelayState::Done(r) => Ok(r),
            other => Err(std::format!("the relay test did not finish: {other:?}")),
        }
    }

    #[test]
    fn ipdt_exact() -> Result<(), Box<dyn std::error::Error>> {
        let cfg = RelayConfig {
            hysteresis: 0.1,
            ..RelayConfig::new(1.0, 0.0074)
        };
        let m = identify_ipdt(&cycle(&[0.2], &[1.0, 0.0], 7.4, cfg)?)?;
        assert!(
            (m.k - 0.2).abs() < 0.002 && (m.l - 7.4).abs() < 0.074,
            "{m:?}"
        );
        Ok(())
    }

    #[test]
    fn fopdt_exact_with_bias() -> Result<(), Box<dyn std::error::Error>> {
        let cfg = RelayConfig {
            bias: 0.3,
            hysteresis: 0.05,
            ..RelayConfig::new(1.0, 0.004)
        };
        let r = cycle(&[2.0], &[5.0, 1.0], 4.0, cfg)?;
        let k = r.gain().ok_or("no gain from a biased relay")?;
        assert!((k - 2.0).abs() < 0.01, "{k}");
        let m = identify_fopdt(&r, k)?;
        assert!(
            (m.t - 5.0).abs() < 0.05 && (m.l - 4.0).abs() < 0.04,
            "{m:?}"
        );
        Ok(())
    }

    /// Unstable FOPDT plants with `L/T` from 0.1 to 0.4 (a cycle exists
    /// below ln 2), gains from 0.5 to 4, with and without
    /// hysteresis: `K`, `T`, `L` from the cycle of the exactly sampled plant.
    #[test]
    fn ufopdt_exact_with_bias() -> Result<(), Box<dyn std::error::Error>> {
        for (k, t, l, eps) in [
            (2.0, 3.0, 1.0, 0.0),
            (1.0, 5.0, 1.5, 0.0),
            (0.5, 10.0, 1.0, 0.02),
            (4.0, 2.0, 0.8, 0.05),
        ] {
            let cfg = RelayConfig {
                bias: 0.2,
                hysteresis: eps,
                ..RelayConfig::new(1.0, 0.0002)
            };
            let r = cycle(&[k], &[t, -1.0], l, cfg)?;
            let m = identify_ufopdt(&r)?;
            // the relations are exact in continuous time; the sampled relay
            // switches at the sample after a crossing, an error of order
            // Ts/L (10⁻⁴ here) that a hysteresis of a quarter of the swing
            // makes a few times larger
            let rel = |a: f64, b: f64| (a - b).abs() / b;
            assert!(
                rel(m.k, k) < 2e-3 && rel(m.t, t) < 2e-3 && rel(m.l, l) < 2e-3,
                "{k} {t} {l}: {m:?}"
            );
        }
        // a symmetric relay: L/T is not determined
        let cfg = RelayConfig::new(1.0, 0.001);
        let r = cycle(&[2.0], &[3.0, -1.0], 1.0, cfg)?;
        assert!(identify_ufopdt(&r).is_err());
        Ok(())
    }

    #[test]
    fn aborts_out_of_band() -> Result<(), Box<dyn std::error::Error>> {
        let cfg = RelayConfig {
            band: 0.5,
            u0: 0.25,
            ..RelayConfig::new(1.0, 0.01)
        };
        assert_eq!(
            run(&[0.2], &[1.0, 0.0], 7.4, cfg),
            RelayState::Aborted(RelayAbort::OutOfBand)
        );
        Ok(())
    }
}
