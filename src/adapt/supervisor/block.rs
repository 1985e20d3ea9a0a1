//! The estimates of a block of estimator samples, and when they held still.

use super::*;

/// The estimates of a block of samples.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Block<T> {
    pub(super) count: u32,
    /// Samples without a plausible estimate.
    missing: u32,
    d: Option<usize>,
    /// Whether every estimate of the block had the dead time `d`.
    one_d: bool,
    sum: Model<T>,
    lo: Model<T>,
    hi: Model<T>,
    /// The estimator's learnt samples ([`crate::adapt::Estimator::learnt`])
    /// at the block's first sample and at its last.
    learnt: Option<(u32, u32)>,
}

impl<T: Real> Block<T> {
    pub(super) fn add(&mut self, e: Option<Estimate<T>>, learnt: u32) {
        self.count = self.count.saturating_add(1);
        self.learnt = Some((self.learnt.map_or(learnt, |(first, _)| first), learnt));
        let Some(e) = e else {
            self.missing = self.missing.saturating_add(1);
            return;
        };
        match self.d {
            None => {
                self.d = Some(e.d);
                self.one_d = true;
                self.lo = Model {
                    k: e.k,
                    tau: e.tau,
                    theta: e.theta,
                };
                self.hi = self.lo;
            }
            Some(d) => {
                self.one_d &= d == e.d;
                self.lo.k = at_most(e.k, self.lo.k);
                self.hi.k = at_least(e.k, self.hi.k);
                self.lo.tau = at_most(e.tau, self.lo.tau);
                self.hi.tau = at_least(e.tau, self.hi.tau);
            }
        }
        self.sum.k = self.sum.k + e.k;
        self.sum.tau = self.sum.tau + e.tau;
        self.sum.theta = self.sum.theta + e.theta;
    }

    /// The block's dead time and mean model when the estimate held still in
    /// it: every sample plausible, one dead time, the gain and the time
    /// constant within `tol` of their mean from lowest to highest, and the
    /// estimator learnt from `min_learnt` samples in it at least (an
    /// estimate that nothing moved is still without having settled on
    /// anything: measured, a loop oscillating beyond what the excitation
    /// gate takes as moves froze the estimate of its onset, k 0.50 for 1,
    /// and two blocks of it were applied; the bank's ramp loads, where the
    /// bank learns only at a ramp's start and end, applied a gain likewise:
    /// `tests/adapt_bank.rs` fails without it).
    pub(super) fn still(&self, tol: T, min_learnt: usize) -> Option<(usize, Model<T>)> {
        let d = self.d?;
        let learnt = self
            .learnt
            .map_or(0, |(first, last)| last.wrapping_sub(first));
        if self.missing > 0 || !self.one_d || self.count == 0 || (learnt as usize) < min_learnt {
            return None;
        }
        let n = T::of(f64::from(self.count));
        let mean = Model {
            k: self.sum.k / n,
            tau: self.sum.tau / n,
            theta: self.sum.theta / n,
        };
        let narrow = |lo: T, hi: T, m: T| m.is_infinite() || hi - lo <= tol * m.abs();
        (narrow(self.lo.k, self.hi.k, mean.k) && narrow(self.lo.tau, self.hi.tau, mean.tau))
            .then_some((d, mean))
    }
}

/// `b` within the fraction `rel` of `a` (both infinite: equal).
pub(super) fn near<T: Real>(a: T, b: T, rel: T) -> bool {
    if a.is_infinite() || b.is_infinite() {
        return a == b;
    }
    (a - b).abs() <= rel * a.abs()
}
