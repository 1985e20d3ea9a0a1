//! The settings of an [`super::Adaptive`] controller.

use crate::adapt::EstimatorConfig;
use crate::{error::Error, real::Real};

/// Settings of an [`crate::adapt::Adaptive`] controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveConfig<T> {
    /// The estimator's.
    pub estimator: EstimatorConfig<T>,
    /// The relative change of the gain or the time constant that is applied
    /// (default 0.05).
    pub min_change: T,
    /// Estimator samples an estimate must hold before it is applied
    /// (default 300; every count here is of the estimator's samples, of
    /// [`EstimatorConfig::period`]).
    pub settle: u32,
    /// Estimator samples between two changes at least (default 1000).
    pub min_interval: u32,
    /// The evidence for the chosen dead time over the next candidate, at
    /// least ([`crate::adapt::Estimate::evidence`]; default 20).
    pub min_evidence: T,
    /// A change moves the gain and the time constant by at most this factor
    /// (default 2).
    pub max_step: T,
    /// The oscillation detector's band on the control error: a half-cycle
    /// of the error (between sign changes) counts when its peak exceeds
    /// this and four times the noise the estimator measures, it is shorter
    /// than four of the longest candidate dead times, and its peak is at
    /// least half the previous half-cycle's (default 0: the measured
    /// noise's band alone).
    pub band: T,
    /// Consecutive counted half-cycles after a change that restore the
    /// last validated model (default 6; the commissioned one until a change
    /// was validated).
    pub crossings: u32,
    /// Estimator samples watched after a change (default 2000); a change
    /// watched to the end without an oscillation, whose model predicts as
    /// well as the estimate or is within `min_change` of it, is validated:
    /// the model a later oscillation restores.
    pub watch: u32,
    /// The estimates' gain and time constant stay within this factor of
    /// the commissioned model's (default 4): beyond it an estimate is
    /// refused with a warning ([`crate::adapt::ChangeKind::Edge`]), as one at the end of
    /// the dead-time range is.
    pub bound: T,
    /// Half-cycles of a growing oscillation of the control error (each
    /// reaching the band, each peak above the one before by the band) that set off
    /// the emergency path (default 4: two periods): the primary's gain is
    /// halved ([`crate::adapt::ChangeKind::Detuned`]); when the oscillation
    /// goes on, a clear estimate is applied
    /// ([`crate::adapt::ChangeKind::Emergency`]), or the gain halved again.
    pub emergency: u32,
    /// The evidence by which the estimate must predict the data since the
    /// model in use was set better than it before it is applied
    /// ([`crate::adapt::Mismatch::evidence`], default 16). For Gaussian
    /// errors the evidence is twice the log-likelihood ratio of the
    /// estimate over the model in use; where the model in use is right,
    /// the estimate's three coefficients fitted to the same data gain
    /// about a χ² of three degrees of freedom from the noise alone, which
    /// passes 16 with a probability of 0.1 % (Ljung (1999) Sec. 16.4) — a
    /// single load's response under noise moves the estimate by several
    /// percent, and does not pass. Never below 0: no model is applied that
    /// predicts the recent data worse than the one in use.
    pub validate: T,
    /// Whether settled estimates are applied (default true); false: a
    /// model-error monitor only — the estimator learns, the alarm is
    /// raised and cleared, the model in use stays.
    pub apply: bool,
    /// The model error ([`crate::adapt::Mismatch::error`]) that raises the
    /// alarm when it holds for `settle` samples with the evidence of
    /// `min_evidence` (default 0.1); it clears below half of it; infinite:
    /// no alarm.
    pub alarm: T,
    /// Whether a scheme rebuilt for a model ([`crate::adapt::Redesign::rebuild`])
    /// is built by [`crate::adapt::Adaptive::design`], called outside the
    /// control loop's sample, rather than in the update that applies the
    /// model (default false): a device's update then stays within its
    /// budget whatever the design costs.
    pub background_design: bool,
}

impl<T: Real> AdaptiveConfig<T> {
    /// Checks every setting (the estimator's included).
    pub fn validate(&self) -> Result<(), Error> {
        self.estimator.validate()?;
        crate::real::positive(self.min_change, "min_change")?;
        if !(self.max_step > T::one()) {
            return Err(Error::OutOfRange("max_step: above 1"));
        }
        if !(self.alarm > T::zero()) {
            return Err(Error::NotPositive("alarm"));
        }
        if !(self.bound > T::one()) {
            return Err(Error::OutOfRange("bound: above 1"));
        }
        crate::real::non_negative(self.band, "band")?;
        crate::real::non_negative(self.validate, "validate")?;
        Ok(())
    }

    /// Defaults around the estimator's settings.
    pub fn new(estimator: EstimatorConfig<T>) -> Self {
        AdaptiveConfig {
            estimator,
            min_change: T::of(0.05),
            settle: 300,
            min_interval: 1000,
            min_evidence: T::of(20.0),
            max_step: T::of(2.0),
            band: T::zero(),
            crossings: 6,
            watch: 2000,
            apply: true,
            alarm: T::of(0.1),
            bound: T::of(4.0),
            emergency: 4,
            validate: T::of(16.0),
            background_design: false,
        }
    }
}
