//! The level test: a load's response compared in levels, the load a
//! nuisance parameter of the regression.
//!
//! In the differences the estimator learns from, a load's response is a
//! short, small signal under the noise: a response of amplitude `A` over
//! `n` samples carries `A²/2n` of energy there against `2σ²` of noise per
//! sample, in levels `A²·n/2` against `σ²` (for ten samples of dead time
//! and a lag of seventeen, a factor of some 300 in the evidence per
//! response). In levels, though, the load itself stands in the data. So each
//! response from a load's onset ([`Estimator::onset`]) to rest is fitted,
//! for the model in use and for each of its gain and lag hypotheses
//! ([`GAINS`], [`LAGS`]), as the model's own simulation from the onset (state
//! 0, driven by the input's moves) plus the load's part, which a step at the
//! output or the input and any initial state of a first-order model share:
//! a constant and the model's free response, `c0 + c1·q[k]` with
//! `q[k] = (1 − a^k)/(1 − a)` (`a` the model's pole; `k` for an integrating
//! one: its free response is a ramp). The load's two coefficients are
//! estimated by least squares for each model (the disturbance modelled in
//! the regression: Ljung (1999) Sec. 4.3, a step disturbance as an initial
//! state and an offset; Söderström & Stoica (1989) Ch. 4, the residual
//! sum of squares of a linear regression). The residual sums of
//! squares `V` then compare the models on the same data with the same
//! number of parameters: `(V_ref − V_h)/σ²` is the evidence for hypothesis
//! `h` over the model in use (twice the log-likelihood ratio for Gaussian
//! noise of variance `σ²`), summed over the responses by Page's test (Page
//! (1954)).
//!
//! A response counts only when some model explains it (the best leaves
//! the noise's residual to within three of its standard deviations, `χ²`
//! with `n − 2` degrees of freedom, and at most [`EXPLAINED`] of the model
//! in use's residual above the noise; or the model in use leaves no more
//! than the noise): a ramp, a second load inside the response, a
//! change of dead time the hypotheses do not cover, or dynamics no model
//! has leave residuals no hypothesis removes, and teach nothing about the
//! gain and the lag. A hypothesis is proposed when its sum reached
//! [`LEVEL_EVIDENCE`], it has the most, and on the last response, which
//! stood out of the noise, it explained what the model in use did not; the
//! supervisor applies it as the differences' proposal
//! ([`Estimator::proposal`]). The test needs plain
//! differences ([`EstimatorConfig::prefilter`] 0, the default): another
//! prefilter colours the noise the evidence is measured against.

use super::*;

/// The models the level test fits: the model in use, then each hypothesis.
const FITS: usize = HYPOTHESES + 1;

/// Page's sum of a hypothesis's evidence over the responses at which the
/// level test proposes it. Against the model in use when nothing changed,
/// a hypothesis's evidence per response is negative in the mean and as
/// large as its spread; measured on the bank (`docs/adapt-bank.md`): a
/// halved gain shows about 150 per output load at the coarse period under
/// 2 % noise and about 30 under 5 %.
pub const LEVEL_EVIDENCE: f64 = 60.0;

/// The level test's noise is at least this fraction of the response's
/// energy per sample (its level's variance about its mean over the
/// response): a misfit of 1 % of the response in RMS is as much as it
/// tells apart where the noise measure reads less (noise-free data, a
/// converter's steps; measured on the bank: a 10-bit converter at rest
/// reads no noise, and the model's own 0.01 % of misfit was evidence).
const FLOOR: f64 = 1e-4;

/// One model's fit over a response: its simulation, the residual's level,
/// the load's regressor and the sums of the least-squares problem.
#[derive(Debug, Clone, Copy)]
struct Fit<T> {
    /// The model's simulated difference `Δŷ[k]` from the response's start.
    x: T,
    /// The residual's first sum (an integrating model's target is the
    /// second difference).
    v: T,
    /// The residual in levels.
    r: T,
    /// The load's regressor `q[k]`.
    q: T,
    /// `Σr, Σr², Σr·q, Σq, Σq²`.
    s: [T; 5],
}

impl<T: Real> Fit<T> {
    fn zero() -> Self {
        Fit {
            x: T::zero(),
            v: T::zero(),
            r: T::zero(),
            q: T::zero(),
            s: [T::zero(); 5],
        }
    }

    /// The residual sum of squares after the least-squares fit of
    /// `c0 + c1·q` over `n` samples (of `c0` alone where `q` is nearly
    /// constant over them).
    fn rss(&self, n: T) -> T {
        let [sr, srr, srq, sq, sqq] = self.s;
        let det = n * sqq - sq * sq;
        let explained = if det > T::epsilon() * n * sqq {
            (sqq * sr * sr - T::of(2.0) * sq * sr * srq + n * srq * srq) / det
        } else {
            sr * sr / n
        };
        at_least(srr - explained, T::zero())
    }
}

/// The level test's state: a fit per model over the response under way,
/// and the evidence over the responses so far.
#[derive(Debug, Clone, Copy)]
pub(super) struct Levels<T> {
    fits: [Fit<T>; FITS],
    /// Samples of the response under way (`None`: none).
    open: Option<usize>,
    /// A response ended, of this many samples, not compared yet.
    due: Option<usize>,
    /// The measured output's level from the response's start (an
    /// integrating process's: its difference first), its sum and its sum
    /// of squares over the response.
    y: [T; 4],
    /// Page's sum of each hypothesis's evidence over the responses.
    sums: [T; HYPOTHESES],
    /// The hypothesis proposed, with its evidence over the last response
    /// and its relative error there (as [`Mismatch`]'s).
    proposal: Option<(usize, Mismatch<T>)>,
}

impl<T: Real> Levels<T> {
    pub(super) fn new() -> Self {
        Levels {
            fits: [Fit::zero(); FITS],
            open: None,
            due: None,
            y: [T::zero(); 4],
            sums: [T::zero(); HYPOTHESES],
            proposal: None,
        }
    }
}

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// A response starts (an onset's last sample): every fit from zero.
    pub(super) fn levels_open(&mut self) {
        if self.cfg.prefilter != T::zero() {
            return;
        }
        self.levels_finish();
        self.levels.fits = [Fit::zero(); FITS];
        self.levels.y = [T::zero(); 4];
        self.levels.open = Some(0);
    }

    /// The response under way is not the process's own (a sample the
    /// caller flagged): dropped.
    pub(super) fn levels_drop(&mut self) {
        self.levels.open = None;
    }

    /// A new onset: the response under way compared when it lasted a
    /// response's time, else dropped (a load inside it).
    pub(super) fn levels_end(&mut self) {
        match self.levels.open {
            Some(n) if n > self.response() => self.levels_compare(n),
            _ => self.levels_drop(),
        }
    }

    /// A response's time in estimator samples: the rest's.
    fn response(&self) -> usize {
        self.rest_after.max(self.window)
    }

    /// The model in use changed: the evidence and the proposal were
    /// against the one before.
    pub(super) fn levels_reset(&mut self) {
        // (in place: the fits start again when a response opens; a whole
        // new state is some 500 instructions on a Cortex-M4F, in the call
        // that applies a model)
        let lv = &mut self.levels;
        lv.open = None;
        lv.due = None;
        lv.sums = [T::zero(); HYPOTHESES];
        lv.proposal = None;
    }

    /// One sample of the response under way, `target` the estimator's
    /// (`Δy[k+1]`, integrating `Δ²y[k+1]`): each model's simulation, its
    /// residual's level, the load's regressor and the sums; at rest after a
    /// response's time, or after four, the response is compared.
    pub(super) fn levels_step(&mut self, target: T) {
        let Some(n) = self.levels.open else {
            return;
        };
        let Some(r) = self.reference.as_ref() else {
            return;
        };
        let integrating = self.cfg.integrating;
        let (u0, u1) = self.hist.pair(r.d);
        let models = core::iter::once(r.theta).chain(self.hyp.iter().map(|h| h.coef));
        for (f, coef) in self.levels.fits.iter_mut().zip(models) {
            f.x = predict(coef, f.x, (u0, u1), integrating);
            let e = target - f.x;
            if integrating {
                f.v = f.v + e;
                f.r = f.r + f.v;
            } else {
                f.r = f.r + e;
            }
            let pole = if integrating { T::one() } else { coef[0] };
            f.q = pole * f.q + T::one();
            let [sr, srr, srq, sq, sqq] = f.s;
            f.s = [
                sr + f.r,
                srr + f.r * f.r,
                srq + f.r * f.q,
                sq + f.q,
                sqq + f.q * f.q,
            ];
        }
        let [dy, y, sy, syy] = self.levels.y;
        let (dy, y) = if integrating {
            (dy + target, y + dy + target)
        } else {
            (dy, y + target)
        };
        self.levels.y = [dy, y, sy + y, syy + y * y];
        let n = n.saturating_add(1);
        self.levels.open = Some(n);
        let response = self.response();
        if (self.hist.quiet > self.rest_after && n > response) || n >= response.saturating_mul(4) {
            // compared by the next `levels_finish`
            self.levels.open = None;
            self.levels.due = Some(n);
        }
    }

    /// A response that ended in `levels_step` compared (in a call of its
    /// own: between the estimator's passes, `Estimator::advance`).
    pub(super) fn levels_finish(&mut self) {
        if let Some(n) = self.levels.due.take() {
            self.levels_compare(n);
        }
    }

    /// The response's end: the fits compared (see the module
    /// documentation), Page's sums moved on, the proposal renewed.
    fn levels_compare(&mut self, n: usize) {
        self.levels.open = None;
        let tested = self.hypotheses().len();
        let nt = T::of(n as f64);
        let level = self.noise_level();
        let lv = &mut self.levels;
        let [reference, hyps @ ..] = &lv.fits;
        let v_ref = reference.rss(nt);
        let mut rss = [T::zero(); HYPOTHESES];
        for (v, f) in rss.iter_mut().zip(hyps).take(tested) {
            *v = f.rss(nt);
        }
        let rss = rss.get(..tested).unwrap_or_default();
        let Some((best, &v_best)) = rss
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.partial_cmp(b.1).unwrap_or(core::cmp::Ordering::Equal))
        else {
            return;
        };
        // the noise's variance in levels: the target's noise is the first
        // (integrating: second) difference of white noise, whose own
        // differences the measure reads (variance 3σ², 10σ²); at least
        // half the best fit's residual per degree of freedom and [`FLOOR`]
        // of the response's energy per sample (a measure that a
        // converter's steps hold at zero)
        let dof = at_least(nt - T::of(2.0), T::one());
        let share = if self.cfg.integrating { 10.0 } else { 3.0 };
        let [_, _, sy, syy] = lv.y;
        let energy = at_least(syy - sy * sy / nt, T::zero());
        let sigma2 = at_least(level * level / T::of(share), v_best / (T::of(2.0) * dof));
        let sigma2 = at_least(sigma2, T::of(FLOOR) * energy / nt);
        let noise = dof * sigma2;
        // the spread of a residual sum of squares of pure noise (χ² with
        // `dof` degrees of freedom: `σ²·√(2·dof)`), three times
        let spread = T::of(3.0) * sigma2 * (T::of(2.0) * dof).sqrt();
        let excess_ref = v_ref - noise;
        // the best fits to the noise, and leaves at most EXPLAINED of the
        // model in use's excess
        let explains = v_best - noise <= spread && v_best - noise <= T::of(EXPLAINED) * excess_ref;
        let fits_ref = excess_ref <= spread;
        if !(explains || fits_ref) || !(sigma2 > T::zero()) {
            return;
        }
        let inv = T::one() / sigma2;
        for (s, &v) in lv.sums.iter_mut().zip(rss) {
            *s = at_least(*s + (v_ref - v) * inv, T::zero());
        }
        let sums = lv.sums.get(..tested).unwrap_or_default();
        let most = sums
            .iter()
            .all(|s| *s <= sums.get(best).copied().unwrap_or_default());
        let sum = sums.get(best).copied().unwrap_or_default();
        // the response stands out of the noise (its variance at least
        // twice the noise's: a response within a converter's step, which
        // the input's moves do not show in the measurement, tells nothing;
        // not the differences' [`MATERIAL`] test: a doubled lag changes
        // less than 1 % of a load's response in levels)
        let seen = energy >= T::of(2.0) * noise;
        let proposed = explains && !fits_ref && most && seen;
        lv.proposal = (proposed && sum >= T::of(LEVEL_EVIDENCE)).then(|| {
            (
                best,
                Mismatch {
                    error: (at_least(v_ref - v_best, T::zero()) / energy).sqrt(),
                    evidence: (v_ref - v_best) * inv,
                },
            )
        });
    }

    /// The hypothesis the level test proposes (see the module
    /// documentation) and how far the model in use is from the last
    /// response against it.
    pub(super) fn level_proposal(&self) -> Option<(usize, Mismatch<T>)> {
        self.levels.proposal
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::uniform;
    use super::*;
    use crate::test_util::ExpectOk;

    /// `Fit::rss` is the residual of the least-squares fit of `c0 + c1·q`:
    /// against the residual computed directly (`q` made orthogonal to the
    /// constant, both projections taken off `r`), on random data, on data
    /// the two regressors explain exactly, and with `q` constant.
    #[test]
    fn rss_is_the_least_squares_residual() {
        let mut seed = 3u64;
        for case in 0..40 {
            let n = 5 + case * 7;
            let a = 0.5 + 0.5 * uniform(&mut seed);
            let (c0, c1, noise) = (uniform(&mut seed) - 0.5, 2.0 * uniform(&mut seed), case % 3);
            let mut f = Fit::<f64>::zero();
            let (mut rs, mut qs) = (Vec::new(), Vec::new());
            for _ in 0..n {
                f.q = if case % 5 == 4 { 1.0 } else { a * f.q + 1.0 };
                let r = c0 + c1 * f.q + noise as f64 * (uniform(&mut seed) - 0.5);
                let [sr, srr, srq, sq, sqq] = f.s;
                f.s = [
                    sr + r,
                    srr + r * r,
                    srq + r * f.q,
                    sq + f.q,
                    sqq + f.q * f.q,
                ];
                rs.push(r);
                qs.push(f.q);
            }
            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
            let (mr, mq) = (mean(&rs), mean(&qs));
            let qc: Vec<f64> = qs.iter().map(|q| q - mq).collect();
            let qq: f64 = qc.iter().map(|q| q * q).sum();
            let slope = if qq > 1e-12 {
                rs.iter().zip(&qc).map(|(r, q)| (r - mr) * q).sum::<f64>() / qq
            } else {
                0.0
            };
            let direct: f64 = rs
                .iter()
                .zip(&qc)
                .map(|(r, q)| (r - mr - slope * q).powi(2))
                .sum();
            let got = f.rss(n as f64);
            let scale = rs.iter().map(|r| r * r).sum::<f64>();
            assert!(
                (got - direct).abs() <= 1e-9 * scale,
                "{case}: {got} {direct}"
            );
            if noise == 0 {
                assert!(got <= 1e-9 * scale, "{case}: {got}");
            }
        }
    }

    /// A PI loop that only loads move (output steps ±0.3 and input steps
    /// ±0.2/K, one every 400 samples), its process `k_true e^{−θs}/(τ_true s
    /// + 1)` against the model `K e^{−θs}/(τs + 1)` the estimator starts
    /// from, measured with noise `noise` (standard deviation): the level
    /// test's proposal after each load, from `loads` loads.
    fn loads_only(
        model: (f64, f64, usize),
        truth: (f64, f64),
        noise: f64,
        seed: u64,
        loads: usize,
    ) -> Vec<Option<usize>> {
        let (k, tau, d) = model;
        let ts = 0.5;
        let mut est: Estimator<f64, 16, 40> =
            Estimator::new(EstimatorConfig::new(ts, 2)).expect_ok();
        est.start_from(k, tau, d as f64 * ts).expect_ok();
        est.set_reference(k, tau, d as f64 * ts).expect_ok();
        let (kt, taut) = truth;
        let a = (-ts / taut).exp();
        // (tuned for the model, as the loop was commissioned)
        let (kp, ki) = (0.4 / k, 0.4 / k * ts / tau);
        let (mut y, mut integral, mut seed) = (0.0f64, 0.0f64, seed);
        let mut line = std::vec![0.0f64; d];
        let (mut d_in, mut d_out) = (0.0, 0.0);
        let mut out = Vec::new();
        let width = noise * 12f64.sqrt();
        for j in 0..(loads + 1) * 400 {
            if j % 400 == 0 && j > 0 {
                out.push(est.level_proposal().map(|(i, _)| i));
                let i = j / 400;
                let sign = if i % 4 < 2 { 1.0 } else { -1.0 };
                if i % 2 == 0 {
                    d_out += 0.3 * sign;
                } else {
                    d_in += 0.2 * sign / k;
                }
            }
            let meas = y + d_out + width * (uniform(&mut seed) - 0.5);
            let e = 1.0 - meas;
            integral += ki * e;
            let u = kp * e + integral;
            est.update(meas, u, true);
            let late = line[j % d];
            line[j % d] = u + d_in;
            y = a * y + kt * (1.0 - a) * late;
        }
        out
    }

    /// Loads alone name a halved gain or a doubled lag by the level test
    /// within six loads (three at the output) under 0.5 to 5 % noise, on
    /// three processes and three seeds, and never propose anything where
    /// the process is the model (twenty loads each).
    #[test]
    fn loads_alone_name_a_changed_gain_or_lag() {
        let halved = GAINS.iter().position(|g| *g == 0.5).expect_ok();
        let doubled = GAINS.len() + LAGS.iter().position(|l| *l == 2.0).expect_ok();
        for model in [(1.6, 10.0, 12usize), (2.3, 15.0, 16), (0.8, 4.0, 14)] {
            let (k, tau, _) = model;
            for noise in [0.005, 0.02] {
                for seed in [1u64, 2, 3] {
                    let case = (model, noise, seed);
                    let same = loads_only(model, (k, tau), noise, seed, 20);
                    assert!(same.iter().all(|p| p.is_none()), "{case:?}: {same:?}");
                    // (a doubled lag changes the loop's answer to a load
                    // less: under 2 % noise this loop's responses leave
                    // its evidence under the test's in twelve loads)
                    let lag = (noise < 0.01).then_some(((k, 2.0 * tau), doubled, 12));
                    for (truth, want, loads) in [((k / 2.0, tau), halved, 6)].into_iter().chain(lag)
                    {
                        let got = loads_only(model, truth, noise, seed, loads);
                        assert_eq!(got.last(), Some(&Some(want)), "{case:?} {truth:?}: {got:?}");
                    }
                }
            }
        }
    }
}
