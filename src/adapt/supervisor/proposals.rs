//! What the supervisor may apply besides the bank's settled estimate: the
//! change detector's hypothesis, the model in use at the bank's new dead
//! time, the level test's challenger; and which estimates count at all,
//! and when one differs from the model in use or confirms it.

use super::*;

/// What the hypothesis in use moved: the gain, the lag or the dead time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Moved {
    Gain,
    Lag,
    DeadTime,
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Adaptive<T, C, R, N, H, L>
{
    /// The change detector's gain or lag hypothesis
    /// ([`Estimator::proposal`]) applied when it differs from the model in
    /// use by `min_change`, lies within the bounds, and predicts the last
    /// response's data better than the model in use with the evidence of
    /// `validate` (as the bank's estimate must: the same rule, on the
    /// detector's memory of a response rather than on the data since the
    /// model in use was set). A loop that only loads move learns this way
    /// in responses where the bank takes tens of them. Returns whether it
    /// was applied.
    ///
    /// While a lag hypothesis is the model in use (`provisional`), a gain
    /// `g` moves the lag again, to the `K/τ` it names: the lag `τ/g`. A
    /// load's response, `K·d·(1 − e^{−t/τ})
    /// ≈ (K/τ)·d·t` while `t ≪ τ`, tells `K/τ` more than `K` and `τ` apart,
    /// and a change between two of the hypotheses' factors is named by the
    /// nearer one and then, along `K/τ`, by one of the other kind
    /// (measured on the bank's lag ×1.6 with loads: the lag's ×2, then the
    /// gain's ×1.4 under evidence 99, the loop 11.5 % worse than the fixed
    /// model's; a process changes one thing at a time far more often than
    /// two; with the lag moved on, the loop ends at most 0.8 % above the
    /// fixed model's at msp's chosen period, and within 10 % of the true
    /// model's in 37 of 45 cases, 36 before: `tests/adapt_between.rs`). A
    /// lag after a gain hypothesis is applied as it is named: no case of
    /// the bank proposes one, so nothing measures the other direction.
    pub(super) fn propose(&mut self) -> bool {
        if self.since < self.cfg.min_interval {
            return false;
        }
        let Some(m) = self.est.proposal().and_then(|m| self.plausible(m)) else {
            return false;
        };
        let cur = self.model;
        let m = Model::from(m);
        let tol = self.cfg.min_change;
        let (gain, lag) = (!near(cur.k, m.k, tol), !near(cur.tau, m.tau, tol));
        let differs = gain || lag;
        // (and the bank's own model predicts the last response worse:
        // where it learns, its estimate is the one to apply)
        let validated = self
            .est
            .proposal_mismatch()
            .is_some_and(|(mm, bank_better)| mm.evidence >= self.cfg.validate && !bank_better);
        if !differs || !validated || !self.within_bounds(m) {
            return false;
        }
        // (a hypothesis moves one of them)
        let moved = if lag { Moved::Lag } else { Moved::Gain };
        let (m, moved) = match (self.provisional, moved) {
            (Some(Moved::Lag), Moved::Gain) => (
                Model {
                    k: cur.k,
                    tau: cur.tau * cur.k / m.k,
                    ..m
                },
                Moved::Lag,
            ),
            _ => (m, moved),
        };
        // (the parameter moved on stays within the bounds too)
        if !self.within_bounds(m) {
            return false;
        }
        self.apply(m);
        self.provisional = Some(moved);
        true
    }

    /// The bank's estimate where it is the model in use at another dead
    /// time (its gain and time constant within [`SPREAD`] times
    /// `min_change` of the model's — the bank's, which loads bias, by
    /// 8 % on the bank's `2.3 e^{−8s}/(15s + 1)` at ten samples of dead
    /// time under 0.5 % noise, need not be the model's; the model's are
    /// kept —, its dead time two estimator samples or more from it and
    /// chosen with the evidence [`Adaptive::plausible`] asks for),
    /// predicting the data since the model in use was set better with the
    /// evidence of `validate`: the model in use with that dead time,
    /// applied at once. After a step of the process's dead time the change
    /// detector restarts the bank from the model it had
    /// (`Estimator::detect`), and the candidate at the new dead time is
    /// then that model there; a loop that only loads move would next teach
    /// the bank a load-biased gain before two blocks of it held still
    /// (measured on the bank's dead time ×0.7 with loads: the right dead
    /// time, gain and lag with evidence above 10⁶ for some 100 s, then a
    /// gain 10 % low, applied 3 000 s later).
    pub(super) fn moved_dead_time(&mut self) -> bool {
        // (not in the swings of an oscillation, whose data any model with
        // its response at their frequency fits: the emergency path's; nor
        // at the end of the dead-time range)
        if self.since < self.cfg.min_interval
            || self.crossed > 0
            || self.growing > 0
            || self.est.at_edge()
        {
            return false;
        }
        let Some(e) = self.est.estimate() else {
            return false;
        };
        // (the dead time first: at rest it is the model's, and the rest
        // is not asked)
        let cur = self.model;
        let period = self.cfg.estimator.period();
        if (cur.theta - e.theta).abs() < T::of(1.5) * period {
            return false;
        }
        let Some(m) = self.plausible(e).filter(|m| m.theta == e.theta) else {
            return false;
        };
        let tol = self.cfg.min_change * T::of(SPREAD);
        let moved = Model {
            theta: m.theta,
            ..cur
        };
        if !near(cur.k, m.k, tol)
            || !near(cur.tau, m.tau, tol)
            || !(self.beats_model() || self.beats_model_recently())
        {
            return false;
        }
        self.apply(moved);
        self.provisional = Some(Moved::DeadTime);
        true
    }

    /// The level test's dead time (`levels/dead.rs`): the model in use at
    /// the dead time whose responses in levels it explains with the
    /// evidence a gain or a lag needs, where the bank's differences do not
    /// see the change (a loop that only loads move, under noise), applied
    /// at once as the bank's ([`Adaptive::moved_dead_time`]). Only where
    /// the bank learnt from a response's samples since the model in use was
    /// set: a loop that only ramps move teaches the bank nothing (its
    /// excitation gate takes a ramp's steady input for no move), and a ramp
    /// that ends inside a response is fitted better by another dead time
    /// too (measured: ramps alone at msp's chosen period under 0.5 % noise,
    /// seeds the bank does not run, 9 of 90 cases had a dead time applied,
    /// an event 2.8 times the fixed loop's IAE; none with this rule). A move
    /// back towards the dead time the last one left is taken halfway: the
    /// process's lies between them, and the shifts of 20 and 40 % step over
    /// it (measured: a drift to 0.7 times, 4.8, 3.6 and 4.8 s applied in
    /// turn for a process's 4.2). Not in the swings of an oscillation (the
    /// emergency path's).
    pub(super) fn level_dead_time(&mut self) -> bool {
        if self.since < self.cfg.min_interval || self.crossed > 0 || self.growing > 0 {
            return false;
        }
        let Some((shift, mm)) = self.est.level_dead_time() else {
            return false;
        };
        let cur = self.model;
        let mut theta = cur.theta + shift;
        // back towards the dead time the last move left: the process's lies
        // between the two, halfway taken
        if let Some((before, after)) = self.dead_moved {
            if after == cur.theta && (theta - cur.theta) * (before - cur.theta) > T::zero() {
                theta = (cur.theta + before) / T::of(2.0);
            }
        }
        let excited =
            (self.est.learnt().wrapping_sub(self.learnt_from) as usize) >= self.est.window();
        if mm.evidence < self.cfg.validate || !(theta > T::zero()) || !excited {
            return false;
        }
        self.apply(Model { theta, ..cur });
        self.provisional = Some(Moved::DeadTime);
        self.dead_moved = Some((cur.theta, theta));
        true
    }

    /// The settled estimate the differences could not validate, applied
    /// once the level test has the evidence for it over the model in use
    /// ([`Estimator::challenger`]: what it asks of a hypothesis). Returns
    /// whether it was applied.
    pub(super) fn challenged(&mut self) -> bool {
        if self.since < self.cfg.min_interval {
            return false;
        }
        let Some((k, tau, theta)) = self.est.challenger() else {
            return false;
        };
        let m = Model { k, tau, theta };
        if !self.differs(m, self.cfg.min_change) || !self.within_bounds(m) {
            return false;
        }
        self.apply(m);
        self.provisional = None;
        true
    }

    /// An estimate worth applying: the gain of the model's sign, a finite
    /// positive time constant (or an integrating model for an integrating
    /// one); its dead time where it was chosen without ambiguity, or where
    /// it is no neighbour of the model's and clearly better than the
    /// model's own (`min_evidence` over that candidate,
    /// [`Estimator::over_reference`]: the data need not yet tell it from a
    /// candidate two samples away to tell it from the model's), the
    /// model's where not (a switch of dead time waits for evidence; the
    /// gain and the lag do not). Measured on the bank at the coarse period
    /// under 5 % noise: the evidence over the nearest rival two samples
    /// away stayed between 5 and 20 for some 1 000 s after a dead time's
    /// step to 0.6 times, or hovered about 20 after a drift to 0.7 times,
    /// each sample below it broke its block's stillness, and the model's
    /// dead time stood until the evaluated window (3 of 108 cases more
    /// than 10 % from the true model's loop; none with this rule).
    /// The change is still applied only when the estimate predicts the
    /// data better than the model in use (`validate`).
    pub(super) fn plausible(&self, m: Estimate<T>) -> Option<Estimate<T>> {
        let integrating = self.cfg.estimator.integrating;
        let ok = (m.k > T::zero()) == (self.model.k > T::zero())
            && m.k.is_finite()
            && (integrating || (m.tau.is_finite() && m.tau > T::zero()));
        if !ok {
            return None;
        }
        let d = self.model_d;
        // a neighbour's dead times share an end with the model's: only
        // the evidence over the others counts for it
        let far = d.is_some_and(|d| d.abs_diff(m.d) > 1);
        if m.evidence >= self.cfg.min_evidence
            || d == Some(m.d)
            || (far && self.est.over_reference() >= self.cfg.min_evidence)
        {
            return Some(m);
        }
        Some(Estimate {
            theta: self.model.theta,
            d: d.unwrap_or(m.d),
            ..m
        })
    }

    /// The estimator's estimate, predicting better than the model in use,
    /// is that model within `min_change` (its dead time within half an
    /// estimator sample): the data confirm the model (measured: under a
    /// 10-bit converter an integrating process's model applied by the
    /// emergency path, 3 % from the process, was never validated — the
    /// bank's estimate beat it with the evidence of hundreds of thousands
    /// on a quantization's noise — and a later restore went back to the
    /// commissioned model, whose dead time the process had left).
    pub(super) fn confirmed(&self) -> bool {
        self.est
            .estimate()
            .and_then(|m| self.plausible(m))
            .is_some_and(|m| !self.differs(m.into(), self.cfg.min_change))
    }

    /// `m` differs from the model in use: its gain or its time constant
    /// by `tol` (relative), or its dead time by half an estimator sample.
    pub(super) fn differs(&self, m: Model<T>, tol: T) -> bool {
        let cur = self.model;
        let period = self.cfg.estimator.period();
        !near(cur.k, m.k, tol)
            || !near(cur.tau, m.tau, tol)
            || (cur.theta - m.theta).abs() > period / T::of(2.0)
    }
}

/// The dead time `theta` in the estimator's whole samples, as it counts
/// them ([`crate::adapt::EstimatorConfig::dead_samples`] truncated; `None`
/// beyond a `usize`): the model in use's, kept beside it
/// (`Adaptive::use_model`) for [`Adaptive::plausible`], which asks it at
/// every block.
pub(super) fn whole_samples<T: Real>(
    est: &crate::adapt::EstimatorConfig<T>,
    theta: T,
) -> Option<usize> {
    num_traits::ToPrimitive::to_usize(&est.dead_samples(theta))
}
