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
    pub(super) fn still(&self, tol: T, min_learnt: usize) -> Option<Still<T>> {
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
        let spread = [self.hi.k - self.lo.k, self.hi.tau - self.lo.tau];
        (narrow(self.lo.k, self.hi.k, mean.k) && narrow(self.lo.tau, self.hi.tau, mean.tau))
            .then_some(Still { d, mean, spread })
    }
}

/// A block in which the estimate held still ([`Block::still`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Still<T> {
    /// Its one dead time (estimator samples).
    d: usize,
    /// Its mean model.
    mean: Model<T>,
    /// The spread, lowest to highest, of its gain and of its time constant.
    spread: [T; 2],
}

/// The model two still blocks in a row settle on, `prev` then `now`
/// (`None`: they do not agree; see [`crate::adapt::SPREAD`]): one dead
/// time, within half a period (`period`), and the means within half of
/// `tol` (`min_change`: the later one), or within `tol` and within half of
/// either block's spread, the estimate wandering about them (a trend moves
/// a block's mean from the last one's by about the block's own spread):
/// their midpoint, within half of `tol` of each.
pub(super) fn settled<T: Real>(
    prev: Still<T>,
    now: Still<T>,
    tol: T,
    period: T,
) -> Option<Model<T>> {
    let (p, m) = (prev.mean, now.mean);
    if prev.d != now.d || (p.theta - m.theta).abs() > period / T::of(2.0) {
        return None;
    }
    let half = tol / T::of(2.0);
    if near(p.k, m.k, half) && near(p.tau, m.tau, half) {
        return Some(m);
    }
    let wanders = |a: T, b: T, sa: T, sb: T| {
        a == b || (near(a, b, tol) && (a - b).abs() * T::of(2.0) <= at_most(sa, sb))
    };
    let [sk, st] = prev.spread;
    let [nk, nt] = now.spread;
    let mid = |a: T, b: T| (a + b) / T::of(2.0);
    (wanders(p.k, m.k, sk, nk) && wanders(p.tau, m.tau, st, nt)).then(|| Model {
        k: mid(p.k, m.k),
        tau: mid(p.tau, m.tau),
        theta: mid(p.theta, m.theta),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(k: f64, tau: f64, spread: [f64; 2]) -> Still<f64> {
        Still {
            d: 6,
            mean: Model { k, tau, theta: 6.0 },
            spread,
        }
    }

    /// Means within half of `min_change` settle on the later one; within
    /// `min_change` and half of both blocks' spreads (an estimate wandering
    /// about them) on their midpoint; a move as large as a block's spread
    /// (a trend) or beyond `min_change`, or another dead time, not at all.
    #[test]
    fn wandering_means_settle_at_their_midpoint_and_a_trend_does_not() {
        let tol = 0.05;
        let near = settled(
            still(1.0, 4.0, [0.0; 2]),
            still(1.02, 4.0, [0.0; 2]),
            tol,
            1.0,
        );
        assert_eq!(near.map(|m| m.k), Some(1.02));
        let wide = [0.2, 0.8];
        let wander = settled(still(1.0, 4.0, wide), still(1.04, 4.1, wide), tol, 1.0);
        let m = wander.map(|m| (m.k, m.tau));
        assert!(matches!(m, Some((k, t)) if (k - 1.02).abs() < 1e-12 && (t - 4.05).abs() < 1e-12));
        // a trend: each block spread by about the move between their means
        let trend = [0.04, 0.1];
        assert!(settled(still(1.0, 4.0, trend), still(1.04, 4.1, trend), tol, 1.0).is_none());
        assert!(settled(still(1.0, 4.0, wide), still(1.06, 4.0, wide), tol, 1.0).is_none());
        let mut other = still(1.0, 4.0, wide);
        other.d = 7;
        assert!(settled(still(1.0, 4.0, wide), other, tol, 1.0).is_none());
        // an integrating model's time constant is infinite in both
        let inf = f64::INFINITY;
        let integ = settled(still(1.0, inf, wide), still(1.04, inf, wide), tol, 1.0);
        assert_eq!(integ.map(|m| m.tau), Some(inf));
    }
}
