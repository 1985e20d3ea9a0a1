//! The level test's dead-time hypotheses: the model in use at the other
//! dead times of `shifted`, weighed over the responses as the gain and lag
//! hypotheses are, and proposed where the bank does not see the change.
//!
//! A loop that only loads move shows a change of its dead time in the
//! differences only where a load's step stands out of the noise there
//! (under 2 % noise at ten samples of dead time it does not: the bank's
//! dead time ×0.7 with loads was never learnt). In levels a response is
//! the model's simulation at a dead time plus the load's part (`levels.rs`),
//! and the model in use at a shorter or longer dead time is one more model
//! fitted on the same response with the same regressors: `(V_ref − V_d)/σ²`
//! its evidence, summed by Page's test (Page (1954)) and proposed on the
//! evidence a gain or a lag needs (`enough`, two responses in a row
//! explained better). Each response is evidence for the dead times or for
//! the gains and lags, never both: the dead times where one of them
//! explains it better than every gain and lag (the hypotheses' `own`,
//! turned round). The supervisor applies a proposed dead time where the
//! bank learnt since the model in use was set, and a move back halfway
//! (`Adaptive::level_dead_time`).

use super::*;
use crate::real::arg_min;

/// The dead-time hypotheses' state: Page's sum and largest response of
/// each, the responses in a row the best explained better than the model
/// in use, and the dead time proposed (estimator samples) with the
/// mismatch.
#[derive(Debug, Clone, Copy)]
pub(super) struct Dead<T> {
    sums: [(T, T); DEAD],
    streak: (usize, u8),
    pub(super) proposed: Option<(usize, Mismatch<T>)>,
}

impl<T: Real> Dead<T> {
    pub(super) fn new() -> Self {
        Dead {
            sums: [(T::zero(), T::zero()); DEAD],
            streak: (0, 0),
            proposed: None,
        }
    }
}

/// What the level test measured on a response, for its dead times: each
/// dead time (estimator samples; `None`: outside the bank's range, not
/// proposed), its fit's residual and drift; the model in use's residual,
/// the best gain or lag's; the noise (`noise.rs`); the measurement's energy; the tests
/// every response passes (it stands out of the noise, a misfit beyond the
/// rounding).
pub(super) struct DeadResponse<T> {
    pub(super) d: [Option<usize>; DEAD],
    pub(super) v: [T; DEAD],
    pub(super) drift: [T; DEAD],
    pub(super) v_ref: T,
    pub(super) v_hyp: T,
    pub(super) noise: Noise<T>,
    pub(super) energy: T,
    pub(super) counts: bool,
}

impl<T: Real> Dead<T> {
    /// One response weighed: where the best dead time explains it (to the
    /// noise, at most [`EXPLAINED`] of the model in use's excess, no drift)
    /// or the model in use does, and no gain or lag explains it better,
    /// each dead time's evidence joins its sum; the best sum proposed with
    /// the evidence a hypothesis needs.
    pub(super) fn weigh(&mut self, r: DeadResponse<T>) {
        let allowed = |j: usize| r.d.get(j).copied().flatten().is_some();
        let Some((best, v_best)) =
            arg_min(
                r.v.iter()
                    .enumerate()
                    .map(|(j, &v)| if allowed(j) { v } else { T::nan() }),
            )
        else {
            return;
        };
        let drift = r.drift.get(best).copied().unwrap_or_default();
        let n = r.noise;
        let fits_ref = n.fits(r.v_ref);
        let counts = r.counts
            && (n.explains(v_best, r.v_ref) || fits_ref)
            && n.steady(drift)
            && (v_best < r.v_hyp || fits_ref)
            && n.sigma2 > T::zero();
        if !counts {
            return;
        }
        let inv = T::one() / n.sigma2;
        for (j, (s, &v)) in self.sums.iter_mut().zip(&r.v).enumerate() {
            *s = if allowed(j) {
                page(*s, (r.v_ref - v) * inv)
            } else {
                (T::zero(), T::zero())
            };
        }
        let (top, _) = top(self.sums.iter().map(|s| s.0));
        let sum = self.sums.get(top).copied().unwrap_or_default();
        let v_top = r.v.get(top).copied().unwrap_or(r.v_ref);
        let better = n.better(v_top, r.v_ref);
        self.streak = streak(self.streak, top, better);
        let d = r.d.get(top).copied().flatten();
        self.proposed = d.filter(|_| enough(sum) && self.streak.1 >= 2).map(|d| {
            let error = (at_least(r.v_ref - v_top, T::zero()) / r.energy).sqrt();
            (
                d,
                Mismatch {
                    error,
                    evidence: sum.0,
                },
            )
        });
    }
}

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// The dead times of [`shifted`] the level test may propose (estimator
    /// samples): inside the bank's range and off its ends (an estimate at
    /// an end is warned of, never applied), not the model in use's. None
    /// for an integrating process: its loads' ramps show in the
    /// differences, and the bank learns its dead time from them (measured:
    /// every integrating case of the bank's families with loads within
    /// 10 % of the true model's IAE without the level test's), while in a
    /// loop that a longer dead time sets swinging the level test named a
    /// shorter one (`tests/adapt_emergency.rs`: 4 s applied for a
    /// process's 7).
    pub(super) fn dead_candidates(&self) -> [Option<usize>; DEAD] {
        let d = self.reference.as_ref().map(|r| r.d);
        let Some(d) = d.filter(|_| !self.cfg.integrating) else {
            return [None; DEAD];
        };
        let lo = self.cfg.d_min.saturating_add(1);
        let hi = self.cfg.d_min.saturating_add(self.n).saturating_sub(2);
        shifted(d, H.saturating_sub(2)).map(|x| (x != d && x >= lo && x <= hi).then_some(x))
    }

    /// The dead time the level test proposes, as a change of the model in
    /// use's (s), and how far the model in use is from the last response
    /// against it.
    pub(crate) fn level_dead_time(&self) -> Option<(T, Mismatch<T>)> {
        if self.levels.ramping() {
            return None;
        }
        let (d, m) = self.levels.dead.proposed?;
        let from = self.reference.as_ref()?.d;
        let shift = T::of(d as f64) - T::of(from as f64);
        Some((shift * self.cfg.period(), m))
    }
}

/// The dead times the level test sets beside the hypotheses: the model in
/// use's `d` samples 40 and 20 % shorter, 30 and 60 % longer (at least a
/// sample apart, at most `longest`), the range of changes the adaptation
/// is to follow in steps of a fifth to a third. A response that one of
/// them explains better than every gain and lag points to a change of the
/// dead time (the bank's to find), and its misfit, which a longer lag or a
/// smaller gain follows in part, is no evidence for them (measured on the
/// bank: a dead time 60 % longer with loads at the coarse period had a
/// doubled lag applied under 5 % noise; with the dead times 30 % either
/// side only, still), but evidence for that dead time (this module).
pub(super) fn shifted(d: usize, longest: usize) -> [usize; DEAD] {
    let part = |tenths: usize| (d.saturating_mul(tenths).saturating_add(5) / 10).max(1);
    [
        d.saturating_sub(part(4)),
        d.saturating_sub(part(2)),
        d.saturating_add(part(3)).min(longest),
        d.saturating_add(part(6)).min(longest),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::ExpectOk;

    /// A response of 100 samples under noise of variance 1 on which the
    /// dead time at index `best` leaves the noise alone and the model in use
    /// `excess` more; the others and the best gain or lag leave `other`.
    fn response(best: usize, excess: f64, other: f64) -> DeadResponse<f64> {
        let noise = 98.0;
        let mut v = [noise + other; DEAD];
        v[best] = noise;
        DeadResponse {
            d: [Some(6), Some(8), Some(13), None],
            v,
            drift: [0.0; DEAD],
            v_ref: noise + excess,
            v_hyp: noise + other,
            noise: Noise::new(100.0, 2.0, 1.0, noise, 1.0),
            energy: 1e4,
            counts: true,
        }
    }

    /// A dead time is proposed once its sum has the evidence a hypothesis
    /// needs and two responses in a row: not on one response however
    /// large, not where a gain or a lag explains the responses better, a
    /// drift is left, or the response does not count, and never one outside
    /// the bank's range.
    #[test]
    fn a_dead_time_is_proposed_on_the_evidence_a_hypothesis_needs() {
        let mut dead = Dead::new();
        dead.weigh(response(1, 200.0, 80.0));
        assert!(dead.proposed.is_none(), "one response is not enough");
        dead.weigh(response(1, 200.0, 80.0));
        let (d, m) = dead.proposed.expect_ok();
        assert_eq!(d, 8);
        assert_eq!(m.evidence, 400.0);
        // a gain or a lag explains it better: no evidence for a dead time
        let mut gained = Dead::new();
        for _ in 0..4 {
            let mut r = response(1, 200.0, 80.0);
            r.v_hyp = r.noise.noise - 1.0;
            gained.weigh(r);
        }
        assert!(gained.proposed.is_none());
        // the best fit leaves a drift, or the response does not count
        let mut drifting = Dead::new();
        for _ in 0..4 {
            let mut r = response(1, 200.0, 80.0);
            r.drift[1] = DRIFT + 1.0;
            drifting.weigh(r);
            drifting.weigh(DeadResponse {
                counts: false,
                ..response(0, 200.0, 80.0)
            });
        }
        assert!(drifting.proposed.is_none());
        // the best outside the bank's range, the allowed ones 80 above the
        // noise (beyond its spread): none explains the responses
        let mut outside = Dead::new();
        for _ in 0..4 {
            outside.weigh(response(3, 200.0, 80.0));
        }
        assert!(outside.proposed.is_none());
        // within the range, the same responses propose it
        let mut inside = Dead::new();
        for _ in 0..2 {
            inside.weigh(response(2, 200.0, 80.0));
        }
        assert_eq!(inside.proposed.map(|(d, _)| d), Some(13));
    }
}
