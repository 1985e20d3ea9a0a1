//! What the supervisor watches: the control error's oscillation (the
//! restore after a change, the emergency path), the estimate at the edge
//! of what may be applied, and the model-error alarm.

use super::*;

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Adaptive<T, C, R, N, H, L>
{
    /// The control error's half-cycles (between sign changes, at the
    /// estimator's period): after a change, `crossings` sustained ones
    /// restore the last validated model; at any time, `emergency` growing
    /// ones set off the emergency path. Returns whether it acted.
    pub(super) fn oscillation(&mut self, e: T) -> bool {
        // a set-point move starts the count again: the error's swing from
        // one set point to the next is the move's, not an oscillation's
        if core::mem::take(&mut self.r_moved) {
            (self.side, self.half, self.crossed, self.growing) = (0, 0, 0, 0);
            (self.peak, self.last_peak) = (T::zero(), T::zero());
            self.swing.count(false);
        }
        // an error that held its sign for longer than a half-cycle lasts:
        // the loop settled away from the set point (a load's offset), and
        // its swings about its level count from then on, until the set
        // point moves or the emergency path acts (`swing.rs`; also where
        // the error then crosses zero: a growing oscillation about the
        // offset soon does, its half-cycles about zero too jagged, sampled
        // two to four times each, for four in a row to grow — measured:
        // counted afresh at each crossing, the case of `swing.rs` under
        // 0.5 % noise diverged)
        let need = self.cfg.emergency.max(1);
        let max_half = self.max_half();
        if !self.swing.counting() && self.half > max_half {
            self.swing.count(true);
        }
        // (the band asked at a half-cycle's end only)
        let (given, est, r) = (self.cfg.band, &self.est, self.r_last);
        let swinging = self
            .swing
            .grows(e, (|| band(given, est, r), max_half), need);
        self.half = self.half.saturating_add(1);
        if e.abs() > self.peak {
            self.peak = e.abs();
        }
        let side = if e > T::zero() {
            1
        } else if e < T::zero() {
            -1
        } else {
            0
        };
        if side != 0 && side != self.side {
            // a half-cycle ended: one of an oscillation when it reached
            // the band, was short and kept at least half the previous
            // one's peak (decaying slower than the quarter amplitude per
            // cycle a loop is tuned for: Ziegler & Nichols (1942)); a long
            // one (the loop settled, a set-point step) or one dying out (a
            // transient the change met) starts the count again; one
            // larger than the one before is growing (one as large is not:
            // a 10-bit converter's quantized peaks repeat, and a stable
            // loop's slow ring, lag doubled with loads only, set off the
            // emergency path as a limit cycle: a model applied, then the
            // primary detuned twice; nor is one larger by less than the
            // band: the responses to loads of one size peak alike, by
            // 10⁻⁵ more or less — measured, four of them in a row on
            // 0.8 e^{−10s}/(4s + 1) without noise, the primary detuned,
            // 1.37 times the fixed loop's IAE)
            if self.side != 0 {
                let band = self.band();
                let counts = self.peak > band && self.half <= max_half;
                let sustained = counts && self.peak >= self.last_peak / T::of(2.0);
                let growing =
                    counts && self.last_peak > T::zero() && self.peak > self.last_peak + band;
                self.crossed = if sustained { self.crossed + 1 } else { 0 };
                self.growing = if growing { self.growing + 1 } else { 0 };
                self.last_peak = self.peak;
            }
            self.side = side;
            self.half = 0;
            self.peak = T::zero();
        }
        if self.watching > 0 && self.crossed >= self.cfg.crossings {
            self.watching = 0;
            // (a model the data confirm, predicting the last response to
            // half the alarm's error, rings as the loop built for the
            // process does: its own tuning's, no model error's — measured,
            // the bank's 0.8 e^{−10s}/(4s + 1) at ten samples of dead time
            // without noise, the dead time ×0.7 applied exactly, a load's
            // response counted as an oscillation and the commissioned
            // model restored, 1.43 times the true model's IAE)
            if !(self.confirmed() && self.predicts_recent_data()) {
                self.restore();
                return true;
            }
        }
        // growing half-cycles (about zero, or about the error's level
        // where it holds an offset), or (once detuned) ones that go on
        let detuned_still = self.detune < T::one() && self.crossed >= self.cfg.crossings;
        // or the model in use's simulation error growing window by window
        // (`growth.rs`: irregular half-cycles, a set point that moves)
        let grown = self.est.grown().is_some_and(|p| p > self.band());
        if (self.growing >= need || swinging || detuned_still || grown) && !self.frozen {
            self.growing = 0;
            self.crossed = 0;
            self.swing.count(false);
            self.est.growth_clear();
            self.emergency();
            return true;
        }
        false
    }

    /// The model in use misses at most half of [`AdaptiveConfig::alarm`]
    /// of the last response's movement ([`Estimator::recent_mismatch`]).
    fn predicts_recent_data(&self) -> bool {
        self.est
            .recent_costs()
            .is_some_and(|c| !c.error_reaches(self.cfg.alarm / T::of(2.0)))
    }

    /// Back to the last validated model and its tuning; adaptation rests
    /// for `4·min_interval`.
    pub(super) fn restore(&mut self) {
        let back = self.validated;
        self.shadow = None;
        self.detune = T::one();
        self.take(back, ChangeKind::Restored);
        self.rest_until = self
            .blocks
            .saturating_add(4 * u64::from(self.cfg.min_interval));
    }

    /// The loop is going unstable: first the primary's gain is halved (a
    /// dead-time loop detuned is stable for a larger model error: its
    /// robustness bound `|ΔG/G| < |1 + C G₀|/|C G₀|` grows as the gain
    /// falls, Bag (2022) Eqs. 4.52–4.58 for the integrating case); if the
    /// oscillation goes on, a clear estimate (its dead time chosen with
    /// the evidence of `min_evidence` and not at the end of the range,
    /// predicting the recent data better than the model in use with as
    /// much, within the bounds) is applied, else the gain is halved again;
    /// each logged (a scheme its rule cannot detune has the estimate at
    /// once). Detuning comes first because it is safe whatever the
    /// process, and an estimate is not, at the start of an oscillation:
    /// data of a growing oscillation excite its frequency alone, which any
    /// model with the same response there fits (measured: an integrating
    /// process's dead time ×1.6 under 5 % noise, an estimate with half the
    /// dead time, fitted over a few samples, applied at once and the output
    /// 120 times the step away before the loop recovered; detuned first,
    /// the estimator had the process's dead time a period later).
    pub(super) fn emergency(&mut self) {
        // (a scheme the rule cannot detune goes to the estimate at once)
        if self.detune >= T::one() && self.halve_gain() {
            return;
        }
        let clear = self
            .est
            .estimate()
            .and_then(|m| self.plausible(m))
            .filter(|m| m.evidence >= self.cfg.min_evidence)
            // (an estimate at the end of the dead-time range is not clear:
            // the process may lie beyond it; measured, one at the range's
            // end applied in an emergency left the loop diverging)
            .filter(|_| !self.est.at_edge())
            .filter(|_| self.beats_model())
            .map(Model::from)
            .filter(|m| self.within_bounds(*m));
        if let (Some(m), true) = (clear, self.cfg.apply) {
            self.shadow = None;
            self.detune = T::one();
            self.take(m, ChangeKind::Emergency);
            return;
        }
        if self.halve_gain() {
            return;
        }
        // nothing this scheme can do by itself: said, once per episode
        if !self.alarm {
            self.alarm = true;
            self.record_model(ChangeKind::Alarm, self.model);
        }
    }

    /// The primary's gain halved from its detuned value by the rule's own
    /// (logged as detuned); `false` where the rule or the scheme cannot.
    fn halve_gain(&mut self) -> bool {
        let m = self.model;
        let detuned = self.detune / T::of(2.0);
        let Some([kp, _, _]) = self.retune.gains(m.k, m.tau, m.theta) else {
            return false;
        };
        if self.inner.retune(Gain::Kp, kp * detuned).is_err() {
            return false;
        }
        self.detune = detuned;
        self.record(ChangeKind::Detuned);
        self.since = 0;
        true
    }

    /// The estimate as it stands lies at the end of the dead-time range or
    /// beyond the bounds, and predicts the data better than the model in
    /// use (the process has left what the search may find): a warning,
    /// logged once while it lasts ([`ChangeKind::Edge`], with the estimate),
    /// and nothing applied. Returns whether it is so.
    pub(super) fn edge(&mut self) -> bool {
        let Some(e) = self.est.estimate() else {
            return false;
        };
        let m = Model {
            k: e.k,
            tau: e.tau,
            theta: e.theta,
        };
        let outside = self.est.at_edge() || !self.within_bounds(m);
        if !(outside && self.beats_model()) {
            self.edge_warned = false;
            return false;
        }
        if !self.edge_warned {
            self.edge_warned = true;
            self.record_model(ChangeKind::Edge, m);
        }
        true
    }

    /// The estimator's chosen model predicts the data since the model in
    /// use was set better than it, with the evidence of `validate`
    /// ([`super::Mismatch::evidence`]): no model is applied that does not.
    pub(super) fn beats_model(&self) -> bool {
        self.est
            .mismatch()
            .is_some_and(|mm| mm.evidence >= self.cfg.validate)
    }

    /// The model in use predicts the last response worse than the best of
    /// the bank's chosen model and the change detector's simulations
    /// ([`Estimator::recent_mismatch`]) with the evidence of `validate`.
    pub(super) fn beats_model_recently(&self) -> bool {
        self.est
            .recent_mismatch()
            .is_some_and(|mm| mm.evidence >= self.cfg.validate)
    }

    /// `m`'s gain and time constant within [`AdaptiveConfig::bound`] of the
    /// commissioned model's.
    pub(super) fn within_bounds(&self, m: Model<T>) -> bool {
        let c = self.commissioned;
        let (b, inv_b) = (self.cfg.bound, self.inv_bound);
        let inside = |x: T, x0: T| {
            if x0.is_infinite() || x.is_infinite() {
                x0.is_infinite() == x.is_infinite()
            } else {
                let r = x / x0;
                r >= inv_b && r <= b
            }
        };
        inside(m.k, c.k) && inside(m.tau, c.tau)
    }

    /// The model-error alarm: raised when the error over the last response
    /// ([`crate::adapt::Estimator::recent_mismatch`]) reached `alarm` with
    /// the evidence of `min_evidence` for a quarter of a response's
    /// samples, or the error since the model was set did for `settle`
    /// samples; cleared when both stayed below half of it for `settle`;
    /// each logged.
    pub(super) fn watch_model(&mut self) {
        if !self.cfg.alarm.is_finite() {
            return;
        }
        // two comparisons of the model in use with the process: over the
        // last response (a change shows within a response or two, when
        // the data are clear enough for the evidence over so few samples)
        // and since the model was set (slower, surer under noise)
        // (as costs: the tests without a square root or a division)
        let (Some(fast), Some(slow)) = (self.est.recent_costs(), self.est.costs_since()) else {
            return;
        };
        let (alarm, evidence) = (self.cfg.alarm, self.cfg.min_evidence);
        // a model error is another model that predicts the data better:
        // the estimate away from the model in use (its gain or its lag by
        // the alarm's fraction: less cannot miss that much of the output's
        // movement; or half an estimator sample of dead time), or, over the
        // last response, a gain or a lag hypothesis that explains its
        // error; a model nearer than that fits the block means' departure
        // from every model (an integrating process's response at a fine
        // period), not a change
        let estimated = self.est.estimate().is_some_and(|e| {
            self.differs(
                Model {
                    k: e.k,
                    tau: e.tau,
                    theta: e.theta,
                },
                alarm,
            )
        });
        let raise = |m: &crate::adapt::Costs<T>, distinct: bool| {
            distinct && m.error_reaches(alarm) && m.evidence_reaches(evidence)
        };
        let (against, hold) = if self.alarm {
            let half = alarm / T::of(2.0);
            let quiet = !slow.error_reaches(half) && !fast.error_reaches(half);
            (quiet, self.cfg.settle)
        } else if raise(&fast, estimated || self.est.explains()) {
            // held for a quarter of a response's excited samples (the
            // recent comparison's memory is one response)
            let quarter = u32::try_from(self.est.window() / 4).unwrap_or(u32::MAX);
            (true, quarter.clamp(1, self.cfg.settle.max(1)))
        } else {
            (raise(&slow, estimated), self.cfg.settle)
        };
        self.alarm_for = if against {
            self.alarm_for.saturating_add(1)
        } else {
            0
        };
        if self.alarm_for >= hold {
            self.alarm = !self.alarm;
            self.alarm_for = 0;
            if self.alarm {
                let e = self.est.estimate();
                let m = e.map_or(self.model, |e| Model {
                    k: e.k,
                    tau: e.tau,
                    theta: e.theta,
                });
                self.record_model(ChangeKind::Alarm, m);
            } else {
                self.record(ChangeKind::Cleared);
            }
        }
    }

    /// The model-error alarm is raised (see [`AdaptiveConfig::alarm`]).
    pub fn alarm(&self) -> bool {
        self.alarm
    }

    /// The model in use against the process now.
    pub fn mismatch(&self) -> Option<crate::adapt::Mismatch<T>> {
        self.est.mismatch()
    }

    /// The oscillation detector's band: the one given, and at least four
    /// times the measurement noise the estimator measures (a half-cycle of
    /// the noise alone does not reach it: a device need not know its
    /// noise), and a thousandth of the set point's size (`1 + |r|`: without
    /// noise the error's last ripples as a load's response settles are
    /// half-cycles of a ten-thousandth that may grow four in a row —
    /// measured: 0.8 e^{−10s}/(4s + 1) without noise, a stable loop detuned
    /// as an emergency after an output load, 1.37 times the fixed loop's
    /// IAE; the level watch's floor likewise, `levels.rs`).
    pub(super) fn band(&self) -> T {
        band(self.cfg.band, &self.est, self.r_last)
    }

    /// The longest half-cycle of an oscillation: four times the longest
    /// candidate dead time (a detuned dead-time loop oscillates with a
    /// period of about two to four dead times).
    pub(super) fn max_half(&self) -> u32 {
        longest_half(self.cfg.estimator.d_min, N)
    }
}

/// [`Adaptive::band`] from the band given, the estimator and the set point.
fn band<T: Real, const N: usize, const H: usize>(given: T, est: &Estimator<T, N, H>, r: T) -> T {
    let floor = T::of(1e-3) * (T::one() + r.abs());
    given.max(T::of(4.0) * est.noise_level()).max(floor)
}

/// [`Adaptive::max_half`] for the shortest candidate dead time `d_min` and
/// `n` candidates.
pub(super) fn longest_half(d_min: usize, n: usize) -> u32 {
    let d = d_min.saturating_add(n);
    u32::try_from(d.saturating_mul(4)).unwrap_or(u32::MAX)
}
