//! One estimator sample's learning, in parts: its start (the onset), the
//! RLS step of a range of candidates, the comparison with the model in use
//! and the change detector, and the choice. [`Estimator::update`] runs the parts in
//! one call, or with a block of means over the controller samples after
//! the block's end (`Estimator::advance`).

use super::*;

/// A block's learning under way (see `Estimator::advance`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Pass<T> {
    pub(super) target: T,
    excited: bool,
    /// The bank learns (the input departed from its drift).
    informative: bool,
    /// The dead zone, squared.
    zone2: T,
    chosen: usize,
    /// The chosen candidate's error, the lowest cost so far and whose.
    chosen_e: T,
    /// The chosen candidate learnt (its model is to be refreshed).
    chosen_learnt: bool,
    best: usize,
    lowest: T,
    /// The next candidate to update.
    pub(super) next: usize,
    /// The comparison and the change detector are done.
    pub(super) compared: bool,
    /// The level test's sample is done (`levels.rs`).
    pub(super) levelled: bool,
    /// The block's input, for the history once the pass has read it.
    pub(super) u: T,
    /// A sample at rest: only the level test's part (`Pass::rest`).
    pub(super) rest: bool,
}

impl<T: Real> Pass<T> {
    /// A sample at rest whose level test's step waits for a call of its
    /// own (the bank's `n` candidates passed over, the comparison's part
    /// empty: the rest's own step ran).
    fn rest(target: T, u: T, n: usize) -> Self {
        Pass {
            target,
            excited: false,
            informative: false,
            zone2: T::zero(),
            chosen: 0,
            chosen_e: T::zero(),
            chosen_learnt: false,
            best: 0,
            lowest: T::infinity(),
            next: n,
            compared: false,
            levelled: false,
            u,
            rest: true,
        }
    }
}

/// The parts of a pass: two halves of the bank, the comparison with the
/// change detector, the level test's sample, the choice. A block of fewer
/// controller samples learns in one call.
pub(super) const PARTS: usize = 5;

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// The start of the RLS step of every candidate for the new difference
    /// `dy` (`Δy[k+1]`, with the history holding `Δu[k] … `): the target,
    /// a load's onset (`None`: this sample teaches nothing), the dead zone.
    pub(super) fn learn_begin(&mut self, dy: T, u: T) -> Option<Pass<T>> {
        let cfg = self.cfg;
        // the input moved by the gate's amount within the history the
        // candidates read (`Δu[k] … Δu[k−d_max−1]`)
        let excited = self.hist.quiet <= self.window;
        // and departed from its drift (a ramp load's steady answer does
        // not teach the bank: `History::steady`)
        let informative = self.hist.steady <= self.window;
        // integrating: `Δy[k+1] − Δy[k] = b0·Δu[k−d] + b1·Δu[k−d−1]` (a = 1
        // taken to the left: the regressors are inputs only)
        let target = if cfg.integrating {
            dy - self.last_dy
        } else {
            dy
        };
        if self.onset(target) {
            return None;
        }
        // at rest: no move within the response's time (by the chosen
        // model's lag too: without a prior model, or with a lag grown
        // longer than its, the response outlasts the excitation's window)
        if self.hist.quiet > self.rest_after {
            // the level test's sample in a call of its own where a block
            // has the calls (a Cortex-M4F's longest call, #48 item 7)
            let later = self.levels_open_now() && self.cfg.decimation >= PARTS;
            if !later {
                self.levels_step(target);
            }
            let e_ref = self.rest_step(target);
            self.levels_watch(e_ref);
            return later.then(|| Pass::rest(target, u, self.n));
        }
        // the input's first move after rest opens a response for the level
        // test (a set-point change's: see `levels.rs`)
        if self.resting && !self.levels_open_now() {
            self.levels_open(false);
        }
        self.levels_wake();
        self.wake();
        let chosen = self.chosen;
        // the dead zone, squared: the given one, or the measured noise's
        // multiple (`|e| ≤ zone` as `e² ≤ zone²`: no square root)
        let zone2 = cfg.dead_zone * cfg.dead_zone;
        let zone2 = if cfg.dead_zone_ratio > T::zero() && self.weight > T::zero() {
            let v = self.bank.get(chosen).map_or(T::zero(), |c| c.cost) / self.weight;
            at_least(cfg.dead_zone_ratio * cfg.dead_zone_ratio * v, zone2)
        } else {
            zone2
        };
        Some(Pass {
            target,
            excited,
            informative,
            zone2,
            chosen,
            chosen_e: T::zero(),
            chosen_learnt: false,
            best: 0,
            lowest: T::infinity(),
            next: 0,
            compared: false,
            levelled: false,
            u,
            rest: false,
        })
    }

    /// The RLS step of candidates `pass.next .. to`, in two sweeps: every
    /// candidate's prediction, cost and gradient (the same few operations
    /// for each, no branch), then the RLS step of those that learn (an error
    /// beyond the dead zone; while the model in use fits, the far ones in
    /// turn: [`TURNS`]). The first sweep
    /// keeps each candidate's error and regressor `Δŷ[k]` for the second.
    pub(super) fn learn_bank(&mut self, pass: &mut Pass<T>, to: usize) {
        let cfg = self.cfg;
        let Pass {
            target,
            informative,
            zone2,
            chosen,
            ..
        } = *pass;
        let from = pass.next;
        let to = to.min(self.n);
        // consecutive candidates share an input: candidate `d`'s
        // `Δu[k−d−1]` is candidate `d + 1`'s `Δu[k−d−1]`
        let inputs = self.hist.from(cfg.d_min).get(from..).unwrap_or_default();
        let pairs = inputs.iter().zip(inputs.get(1..).unwrap_or_default());
        let bank = self.bank.get_mut(from..to).unwrap_or_default();
        let mut errors = [(T::zero(), T::zero()); N];
        for ((c, (&f1, &f2)), slot) in bank.iter_mut().zip(pairs.clone()).zip(&mut errors) {
            // φ = (Δŷ[k], Δu[k−d], Δu[k−d−1]): the model's own past output
            // in the regressor, not the measurement's — the output-error
            // form (Landau's pseudo-linear regression), which noise on y
            // does not bias as it does the equation-error (ARX) form; an
            // integrating model has no `a` (its regressor and covariance
            // row stay zero)
            let f0 = if cfg.integrating { T::zero() } else { c.yhat };
            let [t0, t1, t2] = c.theta;
            let pred = t0 * f0 + t1 * f1 + t2 * f2;
            let e = target - pred;
            c.cost = cfg.cost_memory * c.cost + e * e;
            c.yhat = pred;
            // the gradient of the prediction, ψ[k+1] = φ[k] + â·ψ[k] (the
            // output error's Gauss–Newton direction: the recursive
            // prediction-error method, Ljung (1999) Sec. 11.3; an
            // integrating model's prediction is linear in its inputs, ψ = φ)
            c.psi = if cfg.integrating {
                [f0, f1, f2]
            } else {
                let [p0, p1, p2] = c.psi;
                [f0 + t0 * p0, f1 + t0 * p1, f2 + t0 * p2]
            };
            *slot = (e, f0);
        }
        // the lowest cost (the first of them) and the chosen one's error
        let (mut best, mut lowest) = (pass.best, pass.lowest);
        for (j, c) in bank.iter().enumerate() {
            let lower = c.cost < lowest;
            best = if lower { from + j } else { best };
            lowest = if lower { c.cost } else { lowest };
        }
        if let Some(&(e, _)) = chosen.checked_sub(from).and_then(|j| errors.get(j)) {
            if chosen < to {
                pass.chosen_e = e;
            }
        }
        pass.best = best;
        pass.lowest = lowest;
        pass.next = to;
        if !informative {
            return;
        }
        let step = Step {
            inv_lam: T::one() / cfg.forgetting,
            a_range: self.a_range,
            sign: self.sign,
            cfg,
        };
        let (fits, turn) = (self.fits, self.turn);
        let learns = |i: usize| !fits || i.abs_diff(chosen) <= 1 || (i + turn) % TURNS == 0;
        let learning = bank.iter_mut().zip(pairs).zip(&errors).enumerate();
        for (j, ((c, (&f1, &f2)), &(e, f0))) in learning {
            if e * e > zone2 && learns(from + j) {
                step.rls(c, e, [f0, f1, f2]);
                pass.chosen_learnt |= from + j == chosen;
            }
        }
    }

    /// The pass's third part: the model in use's prediction, the chosen
    /// candidate against it, the costs' weight, the change detector.
    pub(super) fn learn_compare(&mut self, pass: &Pass<T>) {
        let Pass {
            target,
            excited,
            chosen_e,
            ..
        } = *pass;
        let e_ref = self.compare_reference(target, excited, chosen_e);
        self.weight = self.cfg.cost_memory * self.weight + T::one();
        self.detect(target, excited, e_ref);
    }

    /// The model in use on the sample whose target is `target` (here, where
    /// the rest of the comparison is: between the parts of a pass it stays
    /// whole): its cost and its prediction's energy, the chosen candidate's
    /// cost (its error `chosen_e`) over the same samples, and over the last
    /// response's when `excited`. Returns the model in use's error.
    pub(super) fn compare_reference(&mut self, target: T, excited: bool, chosen_e: T) -> T {
        let cfg = self.cfg;
        let short = self.short;
        // (ten times the noise: its differences' peaks stay below)
        let band = T::of(10.0) * self.noise_level();
        let hist = &self.hist;
        let Some(r) = self.reference.as_mut() else {
            return T::zero();
        };
        // (what decays without input kept a normal number: this runs at rest)
        let normal = crate::real::normal;
        let pred = normal(predict(r.theta, r.yhat, hist.pair(r.d), cfg.integrating));
        let e = target - pred;
        let m = cfg.cost_memory;
        r.cost = normal(m * r.cost + e * e);
        r.energy = normal(m * r.energy + pred * pred);
        r.yhat = pred;
        // (windows of twice the model's dead time, at least four samples)
        let len = u32::try_from(r.d.saturating_mul(2))
            .unwrap_or(u32::MAX)
            .max(4);
        r.growth.add(e, len, band);
        r.rival = normal(m * r.rival + chosen_e * chosen_e);
        r.weight = m * r.weight + T::one();
        if excited {
            // (the recent comparison's memory is the change detector's)
            let [c, en, rival, w] = r.recent;
            r.recent = [
                short * c + e * e,
                short * en + pred * pred,
                short * rival + chosen_e * chosen_e,
                short * w + T::one(),
            ];
            r.seen = r.seen.saturating_add(1);
        }
        e
    }

    /// The pass's end: the choice of dead time and the model it gives.
    pub(super) fn learn_choose(&mut self, pass: &Pass<T>) {
        let before = self.chosen;
        self.turn = self.turn.wrapping_add(1);
        self.decide(pass.best);
        if self.chosen != before {
            self.rebase();
        }
        // (its logarithms are a good part of a pass: only for new
        // coefficients)
        if pass.chosen_learnt || self.chosen != before {
            self.refresh_model();
        }
        self.learnt = self.learnt.wrapping_add(u32::from(pass.chosen_learnt));
        self.current = self.estimate_now();
    }
}

/// What a candidate's RLS step reads besides its own state.
struct Step<T> {
    inv_lam: T,
    a_range: (T, T),
    sign: T,
    cfg: EstimatorConfig<T>,
}

impl<T: Real> Step<T> {
    /// Candidate `c`'s RLS step for its error `e` with the regressor
    /// `φ = (Δŷ[k], Δu[k−d], Δu[k−d−1])` along its gradient `c.psi`, then
    /// its a-posteriori output.
    #[inline(always)]
    fn rls(&self, c: &mut Candidate<T>, e: T, [f0, f1, f2]: [T; 3]) {
        let Step {
            inv_lam,
            a_range: (lo, hi),
            sign,
            cfg,
        } = *self;
        let [t0, t1, t2] = c.theta;
        let [s0, s1, s2] = c.psi;
        // RLS with forgetting along ψ (P symmetric: six entries):
        // g = Pψ/(λ + ψᵀPψ), θ += g·e, P = (P − g·(Pψ)ᵀ)/λ
        let [[p00, p01, p02], [_, p11, p12], [_, _, p22]] = c.p;
        let q0 = p00 * s0 + p01 * s1 + p02 * s2;
        let q1 = p01 * s0 + p11 * s1 + p12 * s2;
        let q2 = p02 * s0 + p12 * s1 + p22 * s2;
        let denom = cfg.forgetting + s0 * q0 + s1 * q1 + s2 * q2;
        if !(denom > T::zero()) {
            return;
        }
        let inv = T::one() / denom;
        let (g0, g1, g2) = (q0 * inv, q1 * inv, q2 * inv);
        let mut next = [t0 + g0 * e, t1 + g1 * e, t2 + g2 * e];
        let n00 = (p00 - g0 * q0) * inv_lam;
        let n01 = (p01 - g0 * q1) * inv_lam;
        let n02 = (p02 - g0 * q2) * inv_lam;
        let n11 = (p11 - g1 * q1) * inv_lam;
        let n12 = (p12 - g1 * q2) * inv_lam;
        let n22 = (p22 - g2 * q2) * inv_lam;
        // the trace bounded: no "bursting" when nothing moves (rare: a
        // branch, so that its division is not paid on every step)
        let trace = n00 + n11 + n22;
        let mut p = [[n00, n01, n02], [n01, n11, n12], [n02, n12, n22]];
        if trace > cfg.max_trace {
            let k = cfg.max_trace / trace;
            p = p.map(|row| row.map(|x| x * k));
        }
        c.p = p;
        let [[_, n01, n02], [_, n11, n12], [_, _, n22]] = p;
        if sign != T::zero() {
            // projection: with the gain's sign known, both input
            // coefficients carry it (a fraction `f` in [0, 1]); a
            // coefficient of the wrong sign goes to zero along the
            // covariance's direction (the projection in the metric of
            // P⁻¹: the correlated coefficients move with it; Goodwin &
            // Sin (1984) Sec. 3.7): b0 along P's second column, b1
            // along its third. The second can carry b0 back across
            // zero, and a coefficient without a direction stays: what
            // is left of the wrong sign is cut to zero. (Branches: a
            // converged model rarely needs them, and their divisions are
            // a good part of a step.)
            let [mut t0, mut t1, mut t2] = next;
            if sign * t1 < T::zero() && n11 > T::zero() {
                let along = t1 / n11;
                t0 = t0 - n01 * along;
                t1 = T::zero();
                t2 = t2 - n12 * along;
            }
            if sign * t2 < T::zero() && n22 > T::zero() {
                let along = t2 / n22;
                t0 = t0 - n02 * along;
                t1 = t1 - n12 * along;
                t2 = T::zero();
            }
            let t1 = if sign * t1 < T::zero() { T::zero() } else { t1 };
            let t2 = if sign * t2 < T::zero() { T::zero() } else { t2 };
            next = [t0, t1, t2];
        }
        let [mut a, b0, b1] = next;
        if !cfg.integrating {
            // projection onto plausible models: `a` in its range
            a = at_most(at_least(a, lo), hi);
        }
        c.theta = [a, b0, b1];
        // the a-posteriori output
        c.yhat = a * f0 + b0 * f1 + b1 * f2;
    }
}
