//! The [`Estimator`]'s bank: construction, the prior model, the recursive
//! prediction-error step of every candidate, the choice of dead time and
//! the estimate.

use super::*;

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// A bank with every candidate at `a = e^{−Ts/τ0}`, `b0 = b1 = 0` and a
    /// large covariance (little is known yet).
    pub fn new(cfg: EstimatorConfig<T>) -> Result<Self, Error> {
        cfg.validate()?;
        if N == 0 || H < cfg.d_min.saturating_add(N).saturating_add(1) {
            return Err(Error::OutOfRange(
                "estimator: the history must hold d_min + N + 1 inputs",
            ));
        }
        let n = cfg
            .d_max
            .map_or(N, |d| d.saturating_sub(cfg.d_min).saturating_add(1))
            .min(N);
        let p0 = cfg.max_trace / T::of(3.0);
        let mut p = [[T::zero(); 3]; 3];
        for (i, row) in p.iter_mut().enumerate() {
            if let Some(x) = row.get_mut(i) {
                // an integrating model's `a` is 1, not estimated
                *x = if cfg.integrating && i == 0 {
                    T::zero()
                } else {
                    p0
                };
            }
        }
        let a0 = if cfg.integrating {
            T::one()
        } else {
            T::of(0.9)
        };
        Ok(Estimator {
            cfg,
            bank: [Candidate {
                theta: [a0, T::zero(), T::zero()],
                p,
                cost: T::zero(),
                yhat: T::zero(),
                psi: [T::zero(); 3],
                scan: T::zero(),
                cusum: T::zero(),
                recent: T::zero(),
            }; N],
            n,
            hist: History::new(
                cfg.prefilter,
                cfg.min_excitation,
                cfg.excitation_ratio,
                // the drift's time: the window (the longest dead time), so a
                // move's response is counted whole and a ramp's steady part
                // not (measured on the bank: twice as long let ramps at the
                // coarse period teach a load-biased gain; see `History`)
                T::one() / T::of(cfg.d_min.saturating_add(n).max(1) as f64),
            ),
            last_y: T::zero(),
            last_dy: T::zero(),
            samples: 0,
            weight: T::zero(),
            chosen: 0,
            challenger_for: 0,
            model: None,
            a_range: (T::of(1e-6), T::one() - T::of(1e-9)),
            sign: T::zero(),
            window: cfg.d_min.saturating_add(n),
            rest_after: usize::MAX,
            short: memory(cfg.d_min.saturating_add(n)),
            reference: None,
            noise: Median::new(),
            snap: [[a0, T::zero(), T::zero()]; 2],
            snap_count: 0,
            last_e: T::zero(),
            recent_weight: T::zero(),
            recent_least: T::zero(),
            restarts: 0,
            pause: 0,
            block: (T::zero(), T::zero(), 0, true),
            partial: T::zero(),
            before: None,
            skip: 0,
            settled: (0, 0),
            onsets: 0,
            onset_error: T::zero(),
            pending: None,
            current: None,
            resting: false,
            rest: (T::one(), T::zero()),
            hyp: [Hypothesis {
                coef: [a0, T::zero(), T::zero()],
                yhat: T::zero(),
                cusum: T::zero(),
                recent: T::zero(),
            }; HYPOTHESES],
            fine: false,
            proposal: None,
            proposal_for: 0,
            explaining: None,
            energy: T::zero(),
            fits: false,
            turn: 0,
            learnt: 0,
            levels: Levels::new(),
        })
    }

    /// Starts from a model `K e^{−θs}/(τs + 1)` (`tau` infinite:
    /// `K e^{−θs}/s`), e.g. the one a controller was designed for: the
    /// choice is its whole dead time `d` (a switch away needs the evidence
    /// of [`EstimatorConfig::switch_evidence`]), and every candidate's
    /// coefficients are the model's ZOH `a`, `b0 = K(1 − a^{1−f})`,
    /// `b1 = K(a^{1−f} − a)` (integrating: `K·Ts·(1 − f)`, `K·Ts·f`), its
    /// fractional part `f` (so the candidate at the model's dead time
    /// predicts from the first sample, and the others pay for being wrong
    /// rather than for having started from nothing).
    pub fn start_from(&mut self, k: T, tau: T, theta: T) -> Result<(), Error> {
        let (d, coef) = self.coefficients(k, tau, theta)?;
        self.wake();
        let i = d
            .checked_sub(self.cfg.d_min)
            .filter(|i| *i < self.n)
            .ok_or(Error::OutOfRange(
                "estimator: a dead time among the candidates",
            ))?;
        let ts = self.cfg.period();
        // the prior's weight: a covariance of one per coefficient (the
        // equivalent of a sample of unit regressors), not the cold start's
        // large one, whose first noisy updates could throw `a` to the edge
        // of stability, where the output-error model's simulation runs away
        let mut p = [[T::zero(); 3]; 3];
        if !self.cfg.integrating {
            let a_of = |t: T| (-ts / t).exp();
            let span = T::of(SPAN);
            self.a_range = (a_of(tau / span), a_of(tau * span));
            p[0][0] = T::one();
            let settle = num_traits::ToPrimitive::to_usize(&(T::of(4.0) * tau / ts).ceil())
                .unwrap_or(0)
                .min(1 << 20);
            self.window = self.cfg.d_min.saturating_add(self.n).saturating_add(settle);
            self.short = memory(self.window);
        }
        p[1][1] = T::one();
        p[2][2] = T::one();
        self.sign = if k > T::zero() { T::one() } else { -T::one() };
        for c in &mut self.bank {
            c.theta = coef;
            c.p = p;
        }
        self.chosen = i;
        self.challenger_for = 0;
        self.rebase();
        self.refresh_model();
        self.current = self.estimate_now();
        self.set_reference(k, tau, theta)
    }

    /// The whole dead time `d` and the ZOH coefficients `(a, b0, b1)` of
    /// `K e^{−θs}/(τs + 1)` (`tau` infinite: `K e^{−θs}/s`; see the module
    /// documentation).
    pub(super) fn coefficients(&self, k: T, tau: T, theta: T) -> Result<(usize, [T; 3]), Error> {
        crate::real::finite(k, "k")?;
        if k == T::zero() {
            return Err(Error::OutOfRange("k: not zero"));
        }
        crate::real::non_negative(theta, "theta")?;
        if !(tau > T::zero()) {
            return Err(Error::OutOfRange("tau: positive (infinite: integrating)"));
        }
        if self.cfg.integrating != tau.is_infinite() {
            return Err(Error::OutOfRange(
                "tau: infinite exactly for an integrating estimator",
            ));
        }
        let ts = self.cfg.period();
        let samples = self.cfg.dead_samples(theta);
        let whole = samples.floor();
        let f = (samples - whole - T::of(1e-9)).max(T::zero()).min(T::one());
        let d = num_traits::ToPrimitive::to_usize(&whole)
            .filter(|d| d.saturating_add(2) < H)
            .ok_or(Error::DelayTooLong(
                "estimator: the history holds the dead time",
            ))?;
        let coef = if self.cfg.integrating {
            [T::one(), k * ts * (T::one() - f), k * ts * f]
        } else {
            // a^{1−f} as its own exponential (a power costs more)
            let x = -ts / tau;
            let (a, af) = (x.exp(), (x * (T::one() - f)).exp());
            [a, k * (T::one() - af), k * (af - a)]
        };
        Ok((d, coef))
    }

    /// The model in use, whose error [`Estimator::mismatch`] weighs: it
    /// predicts the same prefiltered data as the candidates, without
    /// learning ([`Estimator::start_from`] sets it too).
    pub fn set_reference(&mut self, k: T, tau: T, theta: T) -> Result<(), Error> {
        let (d, theta) = self.coefficients(k, tau, theta)?;
        self.reference = Some(Reference {
            theta,
            d,
            cost: T::zero(),
            energy: T::zero(),
            yhat: T::zero(),
            seen: 0,
            rival: T::zero(),
            weight: T::zero(),
            recent: [T::zero(); 4],
            growth: growth::Growth::default(),
        });
        self.reset_hypotheses(theta);
        Ok(())
    }

    /// The last window's peak of the model in use's simulation error where
    /// the windows' peaks grew several times in a row: the loop is going
    /// unstable (`growth.rs`; `None` otherwise).
    pub(crate) fn grown(&self) -> Option<T> {
        self.reference.as_ref().and_then(|r| r.growth.grown())
    }

    /// The growth's windows start again (the emergency path acted).
    pub(crate) fn growth_clear(&mut self) {
        if let Some(r) = self.reference.as_mut() {
            r.growth = growth::Growth::default();
        }
    }

    /// The estimator samples the chosen candidate has learnt from so far
    /// (its RLS steps; wrapping at `u32::MAX`): the supervisor counts the
    /// samples behind an estimate that held still.
    pub fn learnt(&self) -> u32 {
        self.learnt
    }

    /// The estimator samples of a response: the longest candidate dead
    /// time, and with a prior model four of its time constants more.
    pub fn window(&self) -> usize {
        self.window
    }

    /// How far the model in use ([`Estimator::set_reference`]) is from the
    /// process, from the costs of the two on the same data (`None` without
    /// a reference, or before it was compared over a whole response's
    /// excited samples): see [`Mismatch`].
    pub fn mismatch(&self) -> Option<Mismatch<T>> {
        self.costs_since().map(Costs::mismatch)
    }

    /// The costs [`Estimator::mismatch`] is computed from.
    pub(crate) fn costs_since(&self) -> Option<Costs<T>> {
        let r = self.reference.as_ref().filter(|r| r.seen >= self.window)?;
        self.model?;
        Some(Costs {
            cost: r.cost,
            energy: r.energy,
            best: r.rival,
            weight: r.weight,
        })
    }

    /// [`Estimator::mismatch`] over the last response's excited samples
    /// only (the change detector's memory, `1 − 1/window` a sample), the
    /// model in use against the best of the chosen candidate and the
    /// change detector's simulations (the model of a response or two ago
    /// at every dead time, and at the chosen dead time with other gains
    /// and lags, [`GAINS`], [`LAGS`]: a new dead time, gain or lag shows
    /// there before the bank has learnt it): a change shows within a
    /// response or two, where the costs' long memory takes many. The
    /// model-error alarm reads it.
    pub fn recent_mismatch(&self) -> Option<Mismatch<T>> {
        self.recent_costs().map(Costs::mismatch)
    }

    /// The costs [`Estimator::recent_mismatch`] is computed from.
    pub(crate) fn recent_costs(&self) -> Option<Costs<T>> {
        let r = self.reference.as_ref().filter(|r| r.seen >= self.window)?;
        self.model?;
        let [cost, energy, rival, weight] = r.recent;
        let best = at_most(rival, self.recent_least);
        // a gain or a lag: the hypothesis that explains the recent data
        // (not one that explains a part of a load's response better)
        let best = self
            .explaining
            .and_then(|i| self.hyp.get(i))
            .map_or(best, |h| at_most(best, h.recent));
        Some(Costs {
            cost,
            energy,
            best,
            weight,
        })
    }

    /// One controller sample: `y` measured now and `u` the input the plant
    /// received in the last period (`u_applied`); `ok` false for a sample
    /// that is not the process's own response (saturated, manual,
    /// tracking, faulted): the history moves on, nothing is learnt from
    /// its block. Returns whether an estimator sample's learning ended
    /// here: with [`EstimatorConfig::decimation`] `M` the estimator takes
    /// one sample of its own per block of `M` (the block's means), and with
    /// `M ≥ 4` learns from it over four calls (half the candidates at the
    /// block's end, the other half at the next call, the comparison and the
    /// change detector at the one after, the choice at the fourth: the same
    /// arithmetic as in one call, a fraction of its longest run), so the
    /// estimate is the block's from the call that returns true.
    ///
    /// A block's sample is its mean output `ȳ_k` and the input as that
    /// mean sees it: for the process `y_j = y_{j−1} + K·ts·u_{j−1−D}` at
    /// the controller's period, the means of `M` samples obey
    /// `ȳ_k − ȳ_{k−1} = K·ts·M·x_{k−d}` exactly where `D = (d + 1)·M`, with
    /// `x_k = (Σ_p (p + 1)·u_{(k−1)M+p} + Σ_p (M − 1 − p)·u_{kM+p})/M²` — the
    /// moving average of `M` samples (which commutes with the process)
    /// applied twice, a triangle over blocks `k − 1` and `k`, a block older
    /// than `ȳ_k` ([`EstimatorConfig::lag`]). The block means of the input
    /// are that only while it holds still over each block: a set point's
    /// kick within a block, measured, gave an integrating process's gain
    /// 11 to 27 % high, the block's phase deciding (0.3 % with the kick at
    /// a block's start; exact with the triangle); a lag's weights `a^p`
    /// within a block are nearly the triangle's (gain and lag within 1 %
    /// without noise at a block of half the lag). `x` is the sums'
    /// `Σ (p + 1)·u_p = M·Σu − Σ_p Σ_{i<p} u_i` of the block before and
    /// `Σ_p Σ_{i<p} u_i` of this one: two additions a sample. The first
    /// block, without one before, is not learnt from; without decimation
    /// the sample is the controller's.
    pub fn update(&mut self, y: T, u_applied: T, ok: bool) -> bool {
        // a sample a controller would not compute with (`Real::usable_with`)
        // is not one to learn from, nor to take into a block's mean
        if !y.usable_with(u_applied) {
            return false;
        }
        // a block's learning under way goes on, a part a sample
        let mut done = self.advance();
        let (sy, su, n, all) = self.block;
        let n = n + 1;
        if n < self.cfg.decimation {
            self.join(y, u_applied, ok);
            return done;
        }
        // (with a block shorter than the parts, the last one ends first)
        while self.pending.is_some() {
            done |= self.advance();
        }
        // the block's input as the block means of the output see it: the
        // triangle `Σ (p + 1)·u_p` of the block before and `Σ (N − 1 − p)·u_p`
        // of this one, over N² (see `Estimator::update_block`)
        let falling = self.partial + su;
        let (s0, ok) = (su + u_applied, all && ok);
        self.block = (T::zero(), T::zero(), 0, true);
        self.partial = T::zero();
        self.levels_quantum(y, ok);
        let size = T::of(n as f64);
        let inv = T::one() / size;
        let rising = size * s0 - falling;
        let y_mean = (sy + y) * inv;
        if n == 1 {
            return self.sample(y_mean, s0, ok) || done;
        }
        let (rising_before, ok_before) =
            self.before.replace((rising, ok)).unwrap_or((rising, false));
        let u = (rising_before + falling) * inv * inv;
        self.sample(y_mean, u, ok_before && ok) || done
    }

    /// How many calls from now on have nothing to do but add their sample
    /// to the block ([`Estimator::add`]): with no learning under way and no
    /// response to compare, those before the block's end.
    pub(super) fn calm_calls(&self) -> usize {
        if self.pending.is_some() || self.levels_due() {
            return 0;
        }
        let (_, _, in_block, _) = self.block;
        self.cfg
            .decimation
            .saturating_sub(in_block.saturating_add(1))
    }

    /// [`Estimator::update`] in a call [`Estimator::calm_calls`] counted:
    /// the sample joins the block (none that a controller would not
    /// compute with).
    #[inline(always)]
    pub(super) fn add(&mut self, y: T, u_applied: T, ok: bool) {
        if y.usable_with(u_applied) {
            self.join(y, u_applied, ok);
        }
    }

    /// The sample joins the block's sums and count.
    #[inline(always)]
    fn join(&mut self, y: T, u_applied: T, ok: bool) {
        let (sy, su, n, all) = self.block;
        self.partial = self.partial + su;
        self.block = (sy + y, su + u_applied, n + 1, all && ok);
    }

    /// The next call has nothing to do but add its sample to the block:
    /// no learning under way, no response to compare, not a block's end.
    pub(super) fn idle(&self) -> bool {
        self.calm_calls() > 0
    }

    /// One estimator sample: the block's mean measurement and input.
    /// Returns whether its learning is done (else it goes on over the next
    /// controller samples: [`Estimator::advance`]).
    fn sample(&mut self, y: T, u_applied: T, ok: bool) -> bool {
        let dy = self.cfg.prefilter * self.last_dy + (y - self.last_y);
        let learn = ok && self.samples >= 2;
        if !ok {
            self.levels_drop();
        }
        let pass = if learn {
            self.learn_begin(dy, u_applied)
        } else {
            None
        };
        self.last_y = y;
        self.last_dy = dy;
        match pass {
            None => {
                self.close(u_applied);
                true
            }
            Some(p) => {
                self.pending = Some(p);
                if self.cfg.decimation >= PARTS {
                    // the first part now, the others with the next samples
                    self.advance()
                } else {
                    while !self.advance() {}
                    true
                }
            }
        }
    }

    /// The input of the period that just ended joins the history, once
    /// the estimator sample's learning read it.
    fn close(&mut self, u_applied: T) {
        self.hist.push(u_applied);
        self.samples = self.samples.saturating_add(1);
    }

    /// One part of the learning under way: half the candidates, the
    /// comparison with the model in use and the change detector, or the
    /// choice (the pass's end). Returns whether the pass ended here. The
    /// parts are the same arithmetic in the same order as one call: spread,
    /// a controller sample carries at most half of the bank's updates (the
    /// Cortex-M4F's longest call, #48 item 7).
    #[inline]
    fn advance(&mut self) -> bool {
        // (most calls have nothing to do: decided here, without a call)
        if self.pending.is_none() && !self.levels_due() {
            return false;
        }
        self.advance_work()
    }

    /// [`Estimator::advance`] where there is work.
    #[inline(never)]
    fn advance_work(&mut self) -> bool {
        // (a response the level test closed is compared in a call without
        // a pass under way, the Cortex-M4F's longest call, #48 item 7)
        if self.pending.is_none() {
            self.levels_finish();
            return false;
        }
        let Some(mut p) = self.pending.take() else {
            return false;
        };
        if p.next < self.n {
            let to = p.next.saturating_add(self.n.div_ceil(2)).min(self.n);
            self.learn_bank(&mut p, to);
            self.pending = Some(p);
            false
        } else if !p.compared {
            if !p.rest {
                self.learn_compare(&p);
            }
            p.compared = true;
            self.pending = Some(p);
            false
        } else if !p.levelled {
            self.levels_step(p.target);
            p.levelled = true;
            self.pending = Some(p);
            false
        } else {
            if !p.rest {
                self.learn_choose(&p);
            }
            self.close(p.u);
            true
        }
    }

    /// The evidence for a candidate of cost `chosen` over one of cost
    /// `other`: `(other − chosen)/(chosen/W)`, the chosen one's mean squared
    /// error per sample `chosen/W` (early on, `W` counts fewer samples than
    /// the memory holds).
    fn evidence(&self, chosen: T, other: T) -> T {
        evidence(chosen, other, self.weight)
    }

    /// The chosen dead time moves to the best candidate `best` (of the
    /// lowest cost) only when the evidence for it over the current one
    /// reaches `switch_evidence` for `switch_hold` samples in a row.
    pub(super) fn decide(&mut self, best: usize) {
        let cur = self.bank.get(self.chosen).map_or(T::infinity(), |c| c.cost);
        let new = self.bank.get(best).map_or(T::infinity(), |c| c.cost);
        // a neighbour shares an end of the current one's dead times: a step
        // to it is a small one, taken on a quarter of the evidence
        let need = if best.abs_diff(self.chosen) == 1 {
            self.cfg.switch_evidence / T::of(4.0)
        } else {
            self.cfg.switch_evidence
        };
        if best != self.chosen && self.evidence(new, cur) >= need {
            self.challenger_for = self.challenger_for.saturating_add(1);
            if self.challenger_for >= self.cfg.switch_hold {
                self.chosen = best;
                self.challenger_for = 0;
            }
        } else {
            self.challenger_for = 0;
        }
    }

    /// The measurement noise's standard deviation as the estimator sees
    /// it, `σ̂` (the prefiltered output's, about the raw one's for a
    /// prefilter pole near 1): from the running median of the chosen dead
    /// time's simulation error differences, `median|Δe|/(0.6745·√2)` (see
    /// [`Estimator::update`]'s detector; 0 before any data).
    pub fn noise_level(&self) -> T {
        self.noise.get() / T::of(0.6745 * core::f64::consts::SQRT_2)
    }

    /// The model of the chosen candidate (`None` before it means anything:
    /// `b0 + b1` of the wrong sign or zero), as of the end of the last
    /// estimator sample's learning (between the parts of a pass spread over
    /// controller samples, the one before it).
    pub fn estimate(&self) -> Option<Estimate<T>> {
        self.current
    }

    /// The evidence ([`Estimate::evidence`]) for the chosen dead time over
    /// the candidate at the reference's ([`Estimator::set_reference`]), from
    /// the candidates' costs as they are (0: the same candidate, none, or
    /// the reference's beyond the bank: not weighed). Computed when asked:
    /// the supervisor asks only while the chosen dead time is another.
    pub(crate) fn over_reference(&self) -> T {
        let (Some(r), Some(c)) = (self.reference.as_ref(), self.bank.get(self.chosen)) else {
            return T::zero();
        };
        let other =
            r.d.checked_sub(self.cfg.d_min)
                .filter(|&i| i < self.n)
                .and_then(|i| self.bank.get(i))
                .map_or(c.cost, |o| o.cost);
        self.evidence(c.cost, other).max(T::zero())
    }

    /// [`Estimator::estimate`] from the bank as it is (a pass's end keeps it).
    pub(super) fn estimate_now(&self) -> Option<Estimate<T>> {
        let c = self.bank.get(self.chosen)?;
        let (k, tau, frac) = self.model?;
        // a neighbour's interval of dead times shares an end with the
        // chosen one's (`d` with `f = 1` is `d + 1` with `f = 0`): the
        // evidence is against the candidates that cannot be the same, those
        // below `chosen − 1` and above `chosen + 1`
        let lowest = |cs: &[Candidate<T>]| {
            cs.iter()
                .fold(T::infinity(), |m, c| if c.cost < m { c.cost } else { m })
        };
        let bank = self.bank.get(..self.n).unwrap_or_default();
        let (below, above) = bank.split_at(self.chosen.min(bank.len()));
        let second = at_most(
            lowest(below.get(..below.len().saturating_sub(1)).unwrap_or(&[])),
            lowest(above.get(2..).unwrap_or(&[])),
        );
        let d = self.cfg.d_min + self.chosen;
        Some(Estimate {
            k,
            tau,
            theta: (T::of(d as f64) + frac) * self.cfg.period() + self.cfg.lag(),
            d,
            evidence: self.evidence(c.cost, second),
        })
    }

    /// The chosen candidate's model anew ([`Estimator::model_of`]), and the
    /// samples without a move after which the estimator rests: the window,
    /// or the longest dead time and four of the model's time constants
    /// where that is longer (a process whose lag grew, or one learnt
    /// without a prior model, responds for longer than the window); without
    /// a prior model it never rests.
    pub(super) fn refresh_model(&mut self) {
        self.model = self.model_of();
        let period = self.cfg.period();
        // without a prior model (its gain's sign unknown) no response's
        // time is known: it never rests (the cold estimates' lags are no
        // measure, and a move the gate did not see, as the first one from
        // rest, may still be answered)
        let prior = self.sign != T::zero();
        let Some((_, tau, _)) = self.model.filter(|_| prior) else {
            self.rest_after = usize::MAX;
            return;
        };
        let settle = Some(T::of(4.0) * tau / period)
            .filter(|s| s.is_finite())
            .and_then(|s| num_traits::ToPrimitive::to_usize(&s.ceil()))
            .unwrap_or(0)
            .min(1 << 20);
        let longest = self.cfg.d_min.saturating_add(self.n);
        self.rest_after = self.window.max(longest.saturating_add(settle));
    }

    /// `(K, τ, f)` of the chosen candidate's coefficients (`None`: `b0 + b1`
    /// zero), in closed form (see the module documentation).
    pub(super) fn model_of(&self) -> Option<(T, T, T)> {
        let c = self.bank.get(self.chosen)?;
        model_from(c.theta, self.cfg.period(), self.cfg.integrating)
    }

    /// Each candidate's discounted squared prediction error, from the
    /// shortest dead time `d_min` on: the curve the choice minimises.
    pub fn costs(&self) -> impl Iterator<Item = T> + '_ {
        let (g, sum) = if self.resting {
            self.rest
        } else {
            (T::one(), T::zero())
        };
        self.bank.iter().take(self.n).map(move |c| g * c.cost + sum)
    }

    /// The chosen dead time is the first or the last candidate: the process's
    /// may lie beyond the range searched.
    pub fn at_edge(&self) -> bool {
        self.chosen == 0 || self.chosen + 1 >= self.n
    }

    /// How many times the change detector moved the dead time (and
    /// restarted the bank from the chosen model; see the module
    /// documentation).
    pub fn restarts(&self) -> u32 {
        self.restarts
    }

    /// The covariance's trace of the chosen candidate.
    pub fn trace(&self) -> T {
        self.bank.get(self.chosen).map_or(T::zero(), |c| {
            c.p.iter().enumerate().fold(T::zero(), |s, (i, row)| {
                s + row.get(i).copied().unwrap_or(T::zero())
            })
        })
    }
}

/// The discount `1 − 1/window` of a memory of `window` samples.
fn memory<T: Real>(window: usize) -> T {
    T::one() - T::one() / T::of(window.max(1) as f64)
}

/// `(K, τ, f)` of the coefficients `[a, b0, b1]` at the period `ts` (`None`:
/// `b0 + b1` zero), in closed form (see the module documentation).
pub(super) fn model_from<T: Real>(
    [a, b0, b1]: [T; 3],
    ts: T,
    integrating: bool,
) -> Option<(T, T, T)> {
    let b = b0 + b1;
    if !(b.abs() > T::epsilon()) {
        return None;
    }
    Some(if integrating {
        (
            b / ts,
            T::infinity(),
            at_most(at_least(b1 / b, T::zero()), T::one()),
        )
    } else {
        let k = b / (T::one() - a);
        // a^{1−f} = 1 − b0/K
        let r = at_most(at_least(T::one() - b0 / k, a), T::one());
        let ln_a = a.ln();
        // f = 1 − ln r/ln a: r = 1 is a whole sample more (f = 1), r = a none
        let f = if r > T::zero() {
            T::one() - r.ln() / ln_a
        } else {
            T::zero()
        };
        (k, -ts / ln_a, at_most(at_least(f, T::zero()), T::one()))
    })
}
