//! An [`Estimator`] at rest: the input has not moved by the excitation
//! gate's amount for a response's time (the excitation's window, or the
//! longest dead time and four of the chosen model's time constants where
//! that is longer: `Estimator::refresh_model`; only with a prior model,
//! [`Estimator::start_from`], as the adaptive controller's), so no sample
//! teaches anything about the process (Ljung (1999) Sec. 13.4: closed-loop
//! data that only the noise excites identify the controller as much as the
//! process).
//! Only what the rest of the time reads runs: the chosen candidate's
//! simulation (the onset test's and the dead zone's), the model in use's
//! comparison and the noise's measure; the other candidates and the
//! hypotheses wait, and take up the chosen one's state when the input
//! moves again ([`Estimator::wake`]).
//!
//! At rest every candidate predicts the same output to within the input's
//! jitter through its gain (the response to the last move has passed: the
//! rest begins a longest dead time and four lags after it), so every
//! candidate's error is the chosen one's and its cost follows
//! `V ← μ·V + e²` with the same `e`: `V_i` after `R` samples at rest is
//! `μ^R·V_i + Σ_j μ^{R−1−j}·e_j²`, one discount and one sum for the whole
//! bank, applied when it wakes. Differences of cost fade at rest as they
//! did before, and nothing that only the noise excites is learnt: the
//! comparison's evidence is the excited samples'.

use super::*;
use crate::real::normal;

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// At rest: the input has not moved by the excitation gate's amount
    /// within a response's time, and nothing is learnt (see the module
    /// documentation).
    pub fn is_resting(&self) -> bool {
        self.resting
    }

    /// One estimator sample at rest (`target` the prefiltered output's
    /// difference, no onset in it): the chosen candidate's simulation and
    /// gradient, the shared cost's discount and sum, the comparison with
    /// the model in use and the noise's measure. Returns the model in use's
    /// error.
    pub(super) fn rest_step(&mut self, target: T) -> T {
        let cfg = self.cfg;
        let chosen = self.chosen;
        let (u0, u1) = self.hist.pair(cfg.d_min.saturating_add(chosen));
        let Some(c) = self.bank.get_mut(chosen) else {
            return T::zero();
        };
        let f0 = if cfg.integrating { T::zero() } else { c.yhat };
        let [t0, t1, t2] = c.theta;
        // (the states decay without input: kept normal numbers)
        let pred = normal(t0 * f0 + t1 * u0 + t2 * u1);
        let e = target - pred;
        c.yhat = pred;
        c.psi = if cfg.integrating {
            [f0, u0, u1]
        } else {
            let [p0, p1, p2] = c.psi;
            [f0 + t0 * p0, u0 + t0 * p1, u1 + t0 * p2].map(normal)
        };
        let (g, sum) = if self.resting {
            self.rest
        } else {
            (T::one(), T::zero())
        };
        self.rest = (
            normal(cfg.cost_memory * g),
            normal(cfg.cost_memory * sum + e * e),
        );
        self.resting = true;
        let e_ref = self.compare_reference(target, false, e);
        self.weight = cfg.cost_memory * self.weight + T::one();
        // the change detector: the noise from the chosen dead time's
        // simulation, which alone runs
        let Some(scan) = self.detect_begin(target, false) else {
            return e_ref;
        };
        // (the chosen dead time's inputs, read above)
        if let Some(c) = self.bank.get_mut(chosen) {
            let mut scan = scan;
            scan.step(chosen, c, u0, u1);
            c.scan = normal(c.scan);
        }
        e_ref
    }

    /// The bank from rest: every candidate's cost with the shared discount
    /// and sum (see the module documentation), the chosen candidate's
    /// simulation, gradient and detector state for every other's, the
    /// model in use's simulation for every hypothesis's.
    pub(super) fn wake(&mut self) {
        if !self.resting {
            return;
        }
        self.resting = false;
        let (g, sum) = self.rest;
        let Some(&from) = self.bank.get(self.chosen) else {
            return;
        };
        for c in self.bank.get_mut(..self.n).unwrap_or_default() {
            c.cost = g * c.cost + sum;
            c.yhat = from.yhat;
            c.psi = from.psi;
            c.scan = from.scan;
        }
        if let Some(r) = self.reference.as_ref() {
            for h in &mut self.hyp {
                h.yhat = r.yhat;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{drive_dead_time_step, uniform};
    use super::*;
    use crate::test_util::ExpectOk;

    /// A first-order process `e^{−0.5s}/(4s + 1)` at 0.1 s driven by `u(j)`,
    /// measured with uniform noise of width `noise` (seed fixed), into `est`;
    /// `each` sees the sample's index and the estimator after each update.
    fn drive(
        est: &mut Estimator<f64, 16, 40>,
        n: usize,
        noise: f64,
        u: impl Fn(usize) -> f64,
        mut each: impl FnMut(usize, &Estimator<f64, 16, 40>),
    ) {
        let a = (-0.1f64 / 4.0).exp();
        let (mut y, mut seed, mut line) = (0.0f64, 5u64, [0.0f64; 5]);
        for j in 0..n {
            let uj = u(j);
            est.update(y + noise * (uniform(&mut seed) - 0.5), uj, true);
            each(j, est);
            y = a * y + (1.0 - a) * line[j % 5];
            line[j % 5] = uj;
        }
    }

    /// At rest (the input still for a response's time) nothing is learnt and
    /// every candidate pays the chosen one's error: over the rest the costs'
    /// differences are discounted by `μ` a sample and nothing else, and each
    /// cost gains the same sum (`rest.rs`: one discount and one sum for the
    /// whole bank, applied when it wakes); the coefficients do not move. A
    /// move wakes the bank, and the costs go on from the ones the rest gave.
    #[test]
    fn at_rest_every_candidate_pays_the_chosen_ones_error() {
        let mut est: Estimator<f64, 16, 40> =
            Estimator::new(EstimatorConfig::new(0.1, 1)).expect_ok();
        est.start_from(1.0, 4.0, 0.5).expect_ok();
        let (n, rest_from) = (3000, 1500);
        let u = |j: usize| {
            if j < rest_from {
                ((j / 60) % 2) as f64
            } else {
                0.0
            }
        };
        let mut at_rest: Vec<(usize, Vec<f64>, [f64; 3])> = Vec::new();
        drive(
            &mut est,
            n,
            0.01,
            |j| if j < 2900 { u(j) } else { 1.0 },
            |j, e| {
                if e.is_resting() {
                    at_rest.push((j, e.costs().collect(), e.bank[e.chosen].theta));
                }
            },
        );
        // the rest after the square wave (the estimator rests at the start too,
        // before the first move reached it): the last run of samples at rest
        let start = at_rest
            .windows(2)
            .rposition(|w| w[1].0 != w[0].0 + 1)
            .map_or(0, |i| i + 1);
        // (never at rest: the test fails here)
        let (first, last) = (at_rest.get(start).expect_ok(), at_rest.last().expect_ok());
        assert!(
            first.0 < rest_from + 400 && last.0 >= 2899,
            "{} {}",
            first.0,
            last.0
        );
        assert_eq!(first.2, last.2, "learnt at rest");
        let mu = est.cfg.cost_memory;
        let discount = mu.powi((last.0 - first.0) as i32);
        let gained: Vec<f64> = (first.1.iter().zip(&last.1))
            .map(|(a, b)| b - discount * a)
            .collect();
        let scale = last.1.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        for g in &gained {
            assert!((g - gained[0]).abs() <= 1e-12 * scale, "{gained:?}");
        }
        assert!(gained[0] > 0.0, "the noise costs something");
        assert!(!est.is_resting(), "a move wakes the bank");
    }

    /// A long rest without noise keeps every state a normal number: what
    /// decays without input (the simulations, the costs, the medians) is
    /// flushed to zero rather than passing through the subnormal numbers,
    /// whose arithmetic costs a host a hundred times more.
    #[test]
    fn a_long_rest_leaves_no_subnormal_numbers() {
        let mut est: Estimator<f64, 16, 40> =
            Estimator::new(EstimatorConfig::new(0.1, 1)).expect_ok();
        est.start_from(1.0, 4.0, 0.5).expect_ok();
        drive(
            &mut est,
            200_000,
            0.0,
            |j| if j < 300 { 1.0 } else { 0.0 },
            |_, _| {},
        );
        assert!(est.is_resting());
        let normal = |x: f64| x == 0.0 || x.abs() >= f64::MIN_POSITIVE;
        let c = est.bank[est.chosen];
        let r = est.reference.expect_ok();
        let states = [
            c.yhat, c.scan, c.psi[0], c.psi[1], c.psi[2], r.yhat, r.cost, r.energy,
        ]
        .into_iter()
        .chain([est.rest.0, est.rest.1, est.noise.get(), est.noise_level()])
        .chain(est.costs());
        for x in states {
            assert!(normal(x), "{x:e}");
        }
    }

    /// The calls [`Estimator::calm_calls`] counts are those of
    /// [`Estimator::update`] that only add their sample to the block: an
    /// estimator fed through [`Estimator::add`] in them (as the adaptive
    /// controller's calm calls do) and one fed through `update` in every call
    /// hold the same estimate, costs, noise and restarts bit for bit after
    /// every sample, with a prior model and without, through a dead-time step,
    /// under noise and with samples a controller would not compute with.
    #[test]
    fn calm_calls_are_the_updates_that_only_add() {
        for prior in [None, Some((1.5, 4.0, 1.2))] {
            let ts = 0.01;
            let mut cfg = EstimatorConfig::new(ts, 2);
            cfg.decimation = 10;
            let mut all: Estimator<f64, 16, 40> = Estimator::new(cfg).expect_ok();
            let mut calm: Estimator<f64, 16, 40> = Estimator::new(cfg).expect_ok();
            if let Some((k, tau, theta)) = prior {
                all.start_from(k, tau, theta).expect_ok();
                calm.start_from(k, tau, theta).expect_ok();
            }
            let (mut left, mut added) = (0usize, 0usize);
            drive_dead_time_step(11, |j, ym, u| {
                let ym = if j % 997 == 0 { f64::NAN } else { ym };
                let ended = all.update(ym, u, true);
                if left > 0 {
                    left -= 1;
                    added += 1;
                    calm.add(ym, u, true);
                    assert!(!ended, "sample {j}: a calm call ended a pass");
                } else {
                    assert_eq!(calm.update(ym, u, true), ended, "sample {j}");
                    left = calm.calm_calls();
                }
                let bits = |e: &Estimator<f64, 16, 40>| {
                    e.estimate()
                        .map(|m| [m.k, m.tau, m.theta, m.evidence].map(f64::to_bits))
                };
                assert_eq!(bits(&calm), bits(&all), "sample {j}");
                assert!(calm.costs().eq(all.costs()), "sample {j}");
                assert_eq!(calm.noise_level().to_bits(), all.noise_level().to_bits());
                assert_eq!(calm.restarts(), all.restarts());
            });
            // half the calls are calm ones here (nine in ten at rest, fewer
            // while a pass spreads over the calls after its block: the input
            // moves every 700 samples)
            assert!(added > 15_000, "{added}");
            assert!(all.restarts() >= 1, "the detector's restart is in the run");
        }
    }
}
