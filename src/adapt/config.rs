//! The settings of an [`super::Estimator`].

use crate::real::positive;
use crate::{error::Error, real::Real};

/// Settings of an [`super::Estimator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig<T> {
    /// The sample period (s).
    pub ts: T,
    /// The smallest candidate dead time (whole samples).
    pub d_min: usize,
    /// The longest candidate dead time (whole samples, at least `d_min`;
    /// `None`: `d_min + N − 1`, the whole bank). The bank's candidates
    /// beyond it are not run and never chosen.
    pub d_max: Option<usize>,
    /// Forgetting factor `λ` (0.98–0.9999): memory `1/(1 − λ)` samples.
    pub forgetting: T,
    /// Bound on the covariance's trace (no "bursting" when nothing moves).
    pub max_trace: T,
    /// Dead zone: prediction errors below this (the noise level) do not update.
    pub dead_zone: T,
    /// Dead zone from the measured noise level: no update while the
    /// prediction error is within this many times the chosen candidate's
    /// RMS error (`√(V/W)`: the noise, once the model is right; default 0:
    /// off). Errors the noise makes do not move the estimates; a model
    /// that is wrong makes larger ones (Åström & Wittenmark (1995)
    /// Sec. 11.2: dead zones against bounded disturbances).
    pub dead_zone_ratio: T,
    /// Excitation gate relative to the input's own jitter: no update unless
    /// `|Δu|` reached this many times its running median (what the noise
    /// through the controller moves it by) within the gate's window
    /// (default 10; 0: off). Closed-loop data in which only the noise moves
    /// the input identify the controller's inverse as much as the process
    /// (Ljung (1999) Sec. 13.4): the gate keeps the estimator to the
    /// moves that are the set point's and the loads'.
    pub excitation_ratio: T,
    /// Excitation gate: no update unless `|Δu|` reached this within the
    /// history the candidates read (and, whatever this is, a hundredth of
    /// the largest move of late: a smaller one adds under 10⁻⁴ of its
    /// information).
    pub min_excitation: T,
    /// Discount of the candidates' costs (the decision's memory).
    pub cost_memory: T,
    /// A new dead time must have at least this much evidence over the
    /// current one (see [`super::Estimate::evidence`])…
    pub switch_evidence: T,
    /// …for this many consecutive samples.
    pub switch_hold: u32,
    /// The process integrates (`a = 1`, not estimated).
    pub integrating: bool,
    /// Controller samples per estimator sample (at least 1): the estimator
    /// learns from the means of `y` over blocks of this many samples, at
    /// its period `ts·decimation` (the process's own time scale: a fine
    /// controller period gives it no more information per sample, only
    /// more noise and more work), and from the input as those means see it
    /// (a triangle over the block and the one before, a block older:
    /// [`EstimatorConfig::lag`], `Estimator::update`). The
    /// dead times `d_min`, `d_max` and every other count of samples here
    /// are the estimator's. The block means obey an integrating process's
    /// model exactly, a lag's up to the block's own aliasing (small once
    /// the block is a fraction of the lag); the measurement noise falls by
    /// `√decimation`.
    pub decimation: usize,
    /// The pole `c` of the prefilter `L(z) = (1 − z⁻¹)/(1 − c·z⁻¹)` both
    /// the input and the output pass before the estimator sees them
    /// (`0 ≤ c < 1`; 0: plain differences). The model is linear, so the
    /// filtered signals obey it too; like differencing, `L` removes
    /// offsets and constant loads (its zero at `z = 1`), and with `c` near
    /// 1 it passes the process's band while attenuating the measurement
    /// noise differencing would amplify (Ljung (1999) Sec. 14.1, prefiltering).
    pub prefilter: T,
}

impl<T: Real> EstimatorConfig<T> {
    /// The prefilter's pole from its time constant `t` (s): `c = e^{−Ts/t}`
    /// at the estimator's period `Ts` ([`EstimatorConfig::period`])
    /// (0: plain differences).
    pub fn set_prefilter_time(&mut self, t: T) -> Result<(), Error> {
        if !(t >= T::zero() && t.is_finite()) {
            return Err(Error::OutOfRange(
                "prefilter: a time constant (s), 0 or positive",
            ));
        }
        self.prefilter = if t > T::zero() {
            (-self.period() / t).exp()
        } else {
            T::zero()
        };
        Ok(())
    }

    /// The estimator's period, `ts·decimation` (s).
    pub fn period(&self) -> T {
        self.ts * T::of(self.decimation as f64)
    }

    /// The dead time `theta` (s) in the estimator's samples, whole and
    /// fraction, never below zero (a billionth added: a dead time of whole
    /// samples in decimals, as 0.3 s at 0.1 s, is not a sample short). The
    /// block means obey the process's model at its own dead time: each
    /// block's input is the one they see (`Estimator::update`).
    pub(crate) fn dead_samples(&self, theta: T) -> T {
        (theta - self.lag()).max(T::zero()) / self.period() + T::of(1e-9)
    }

    /// How much older the block's input is than its output mean (s): a
    /// block (the triangle over the block and the one before,
    /// `Estimator::update`), none without decimation.
    pub fn lag(&self) -> T {
        if self.decimation > 1 {
            self.period()
        } else {
            T::zero()
        }
    }

    /// The decimation for a model dead time of `dead` controller samples:
    /// about a tenth of it (the estimator at the process's time scale), and
    /// where the dead time is a whole number of samples with a divisor
    /// giving 8 to 10 blocks, that divisor (the smallest), so that the
    /// model's dead time is a whole number of blocks, which the block means
    /// obey exactly (a fraction is interpolated: [`crate::adapt::Estimator::update`]);
    /// else `⌈dead/10⌉`, and 1 below ten samples.
    pub fn decimation_for(dead: T) -> usize {
        if !(dead >= T::zero() && dead.is_finite()) {
            return 1;
        }
        let tenth = num_traits::ToPrimitive::to_usize(&(dead / T::of(10.0)).ceil())
            .unwrap_or(1)
            .clamp(1, 1 << 20);
        let whole = dead.round();
        let n = num_traits::ToPrimitive::to_usize(&whole).filter(|n| *n < 1 << 30);
        let Some(n) = n.filter(|_| (dead - whole).abs() <= T::of(1e-6)) else {
            return tenth;
        };
        (tenth..=(n / 8).max(tenth))
            .find(|m| n.checked_rem(*m) == Some(0))
            .unwrap_or(tenth)
    }

    /// Checks every setting (the history's room is the estimator's).
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.ts, "ts")?;
        if self.decimation == 0 {
            return Err(Error::OutOfRange("decimation: at least 1"));
        }
        let unit = |v: T, name| {
            if v > T::zero() && v <= T::one() {
                Ok(())
            } else {
                Err(Error::OutOfRange(name))
            }
        };
        unit(self.forgetting, "forgetting in (0, 1]")?;
        unit(self.cost_memory, "cost_memory in (0, 1]")?;
        if !(self.prefilter >= T::zero() && self.prefilter < T::one()) {
            return Err(Error::OutOfRange("prefilter pole in [0, 1)"));
        }
        positive(self.max_trace, "max_trace")?;
        if self.d_max.is_some_and(|d| d < self.d_min) {
            return Err(Error::OutOfRange("estimator: d_max at least d_min"));
        }
        for (v, name) in [
            (self.dead_zone, "dead_zone"),
            (self.dead_zone_ratio, "dead_zone_ratio"),
            (self.min_excitation, "min_excitation"),
            (self.excitation_ratio, "excitation_ratio"),
            (self.switch_evidence, "switch_evidence"),
        ] {
            crate::real::non_negative(v, name)?;
        }
        Ok(())
    }

    /// Defaults for period `ts` and candidates from `d_min` samples:
    /// forgetting 0.999, trace ≤ 1e4, no dead zone, excitation 1e-6, cost
    /// memory 0.9995 (2000 samples), a switch of dead time at an evidence
    /// of 20 held 50 samples.
    pub fn new(ts: T, d_min: usize) -> Self {
        EstimatorConfig {
            ts,
            d_min,
            d_max: None,
            forgetting: T::of(0.999),
            max_trace: T::of(1e4),
            dead_zone: T::zero(),
            dead_zone_ratio: T::zero(),
            min_excitation: T::of(1e-6),
            excitation_ratio: T::of(10.0),
            cost_memory: T::of(0.9995),
            switch_evidence: T::of(20.0),
            switch_hold: 50,
            integrating: false,
            decimation: 1,
            prefilter: T::zero(),
        }
    }
}
