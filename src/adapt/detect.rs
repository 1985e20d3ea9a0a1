//! The dead-time change detector of an [`Estimator`]: the chosen
//! model from a response or two ago simulated at every candidate dead
//! time, and Page's cumulative sum of the evidence for each.

use super::*;

/// One sample of the change detector ([`Estimator::detect_begin`]): what
/// each candidate's step reads, and the dead time it found.
#[derive(Debug, Clone, Copy)]
pub(super) struct Scan<T> {
    /// The snapshot's coefficients (`a` = 0 for an integrating model).
    coef: [T; 3],
    target: T,
    /// The chosen dead time's squared error now and over the last response.
    e2: T,
    recent_chosen: T,
    /// The noise's variance and its reciprocal ([`inverse`]), and its
    /// share of a recent error.
    scale: T,
    inv_scale: T,
    floor: T,
    /// The recent errors' discount per excited sample.
    short: T,
    excited: bool,
    chosen: usize,
    /// [`EstimatorConfig::switch_evidence`].
    evidence: T,
    /// The dead time whose evidence counts, the most of them, and its sum.
    best: Option<(usize, T)>,
    /// The least recent error of all dead times.
    least: T,
}

impl<T: Real> Scan<T> {
    /// Candidate `i`'s simulation at its dead time (`u0 = Δu[k−d]`,
    /// `u1 = Δu[k−d−1]`), its recent error and its cumulative sum.
    #[inline(always)]
    pub(super) fn step(&mut self, i: usize, c: &mut Candidate<T>, u0: T, u1: T) {
        let [a, b0, b1] = self.coef;
        let pred = a * c.scan + b0 * u0 + b1 * u1;
        let e = self.target - pred;
        let e2 = e * e;
        let recent = if self.excited {
            self.short * c.recent + e2
        } else {
            c.recent
        };
        let mut sum = c.cusum;
        if self.excited && i.abs_diff(self.chosen) >= 2 {
            sum = page(sum, self.e2 - e2, self.inv_scale);
            // significant, and of the chosen one's recent error above the
            // noise most explained: a model wrong in its gain or lag is
            // beaten by some other dead time now and then, not by this much
            if sum >= self.evidence
                && self.recent_chosen > self.floor
                && recent - self.floor <= T::of(EXPLAINED) * (self.recent_chosen - self.floor)
                && self.best.map_or(true, |(_, s)| sum > s)
            {
                self.best = Some((i, sum));
            }
        }
        c.scan = pred;
        c.cusum = sum;
        c.recent = recent;
        self.least = at_most(self.least, recent);
    }
}

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// The change detector (at rest only the chosen dead time's simulation
    /// runs: `rest.rs`): the chosen candidate's coefficients as they
    /// were a response or two ago (from before a change: a snapshot per
    /// `window` excited samples, the older of two used) simulated at every
    /// candidate dead time (`Δŷ_d[k+1] = â·Δŷ_d[k] + b̂0·Δu[k−d] +
    /// b̂1·Δu[k−d−1]`), and for each dead time not the chosen one's
    /// neighbour Page's cumulative sum of the evidence for it,
    /// `S_d = max(0, S_d + (e_chosen² − e_d²)/σ̂²)` over the excited samples
    /// (for Gaussian errors twice the log-likelihood ratio since the dead
    /// time changed: Page (1954), Basseville & Nikiforov (1993) Sec. 2.2;
    /// `σ̂²` the noise, from the median of the chosen simulation's error
    /// differences: white noise doubles its variance there, a slow misfit
    /// hardly shows, a sharp one at a move is rare).
    ///
    /// Only the dead time differs between the simulations, so after a step
    /// of the process's dead time the right one is better from the first
    /// response on, where the candidates' own estimators would first have
    /// to unlearn the data from before the step. A sum that reaches
    /// [`EstimatorConfig::switch_evidence`] counts when, over the last
    /// response (`window` excited samples of memory), the chosen
    /// simulation's squared error is above the noise's share and the other
    /// dead time leaves at most a quarter of that excess ([`EXPLAINED`]: a
    /// model wrong in its gain or lag is beaten by some other dead time now
    /// and then, not by this much). Then the bank restarts from the
    /// snapshot, the model that was right but for its dead time: every
    /// candidate at its coefficients (the chosen one's covariance), the
    /// costs cleared (their evidence is from before the change), the
    /// choice left to the bank's comparison as before; the detector rests
    /// for four responses.
    pub(super) fn detect(&mut self, target: T, excited: bool, e_ref: T) {
        let Some(mut scan) = self.detect_begin(target, excited) else {
            return;
        };
        // consecutive dead times share an input, as in the bank
        let inputs = self.hist.from(self.cfg.d_min);
        let pairs = inputs.iter().zip(inputs.get(1..).unwrap_or_default());
        let bank = self.bank.get_mut(..self.n).unwrap_or_default();
        for ((i, c), (&u0, &u1)) in bank.iter_mut().enumerate().zip(pairs) {
            scan.step(i, c, u0, u1);
        }
        self.recent_least = scan.least;
        // the model in use with other gains and lags
        self.test_hypotheses(target, e_ref, excited, scan.scale);
        self.detect_end(scan);
    }

    /// The detector before its pass over the candidates ([`Scan::step`]):
    /// the chosen dead time's error, the noise.
    pub(super) fn detect_begin(&mut self, target: T, excited: bool) -> Option<Scan<T>> {
        let cfg = self.cfg;
        let chosen = self.chosen;
        let c = self.bank.get(chosen)?;
        let [snap, _] = self.snap;
        let [a, b0, b1] = snap;
        let a = if cfg.integrating { T::zero() } else { a };
        let e_chosen = target
            - predict(
                snap,
                c.scan,
                self.hist.pair(cfg.d_min + chosen),
                cfg.integrating,
            );
        let e2 = e_chosen * e_chosen;
        let short = self.short;
        let recent_chosen = if excited {
            short * c.recent + e2
        } else {
            c.recent
        };
        // the noise: from the median of the error's differences (white
        // noise of variance σ² gives differences of variance 2σ², whose
        // absolute values have the median 0.6745·√2·σ; a slow misfit of
        // the model hardly shows in them, a sharp one at a move is rare)
        let de = e_chosen - self.last_e;
        self.last_e = e_chosen;
        let med = self.noise.push(de.abs());
        let scale = med * med * T::of(1.0 / (2.0 * 0.6745 * 0.6745));
        if excited {
            self.recent_weight = short * self.recent_weight + T::one();
        }
        Some(Scan {
            coef: [a, b0, b1],
            target,
            e2,
            recent_chosen,
            scale,
            inv_scale: inverse(scale),
            // the noise's share of a recent error
            floor: self.recent_weight * scale,
            short,
            excited,
            chosen,
            evidence: cfg.switch_evidence,
            best: None,
            least: T::infinity(),
        })
    }

    /// The detector after the pass: a restart from the snapshot when a
    /// dead time had the evidence (and the detector is not resting), else
    /// the snapshots move on.
    fn detect_end(&mut self, scan: Scan<T>) {
        let chosen = self.chosen;
        let Some(p) = self.bank.get(chosen).map(|c| c.p) else {
            return;
        };
        let [snap, _] = self.snap;
        let excited = scan.excited;
        self.pause = self.pause.saturating_sub(usize::from(excited));
        if scan.best.is_some() && self.pause == 0 {
            // the bank from the model before the change, each candidate's
            // simulation continuing from the detector's
            for c in &mut self.bank {
                c.theta = snap;
                c.p = p;
                c.yhat = c.scan;
                c.psi = [T::zero(); 3];
                c.cost = T::zero();
                c.cusum = T::zero();
            }
            self.snap = [snap; 2];
            self.snap_count = 0;
            self.weight = T::zero();
            self.challenger_for = 0;
            self.pause = self.window.saturating_mul(4);
            self.restarts = self.restarts.saturating_add(1);
            self.refresh_model();
        } else if excited {
            // a snapshot per response's worth of excited samples: the
            // detector's model is from between one and two of them ago
            self.snap_count = self.snap_count.saturating_add(1);
            if self.snap_count >= self.window {
                let now = self.bank.get(chosen).map_or(snap, |c| c.theta);
                self.snap = [self.snap[1], now];
                self.snap_count = 0;
            }
        }
    }

    /// The detector starts again from the chosen candidate's coefficients
    /// (its dead time changed: the simulations are relative to it).
    pub(super) fn rebase(&mut self) {
        let now = self.bank.get(self.chosen).map(|c| c.theta);
        if let Some(now) = now {
            self.snap = [now; 2];
        }
        self.snap_count = 0;
        for c in &mut self.bank {
            c.cusum = T::zero();
        }
    }
}

/// Page's cumulative sum `max(0, S + gain/σ̂²)` for a sample's evidence
/// `gain` (a squared error less another) and the reciprocal `inv` of the
/// noise's variance ([`inverse`]: infinite without noise, where a gain is
/// infinite evidence).
#[inline(always)]
pub(super) fn page<T: Real>(sum: T, gain: T, inv: T) -> T {
    if inv.is_finite() {
        at_least(sum + gain * inv, T::zero())
    } else if gain > T::zero() {
        T::infinity()
    } else {
        T::zero()
    }
}

/// `1/x` for a variance `x > 0`, infinite for 0 (once a sample: the sums
/// multiply by it).
#[inline(always)]
pub(super) fn inverse<T: Real>(x: T) -> T {
    if x > T::zero() {
        T::one() / x
    } else {
        T::infinity()
    }
}
