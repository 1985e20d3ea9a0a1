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
//! A response opens at a load's onset, where the watch finds one the
//! onset test does not see (`Estimator::levels_watch`: Page's two-sided
//! test on the model in use's residual in levels at rest, which under 5 %
//! noise finds an output load of six times the noise in two samples), or
//! where the input first moves after rest (a set-point change's response,
//! fitted alike: the constant is the level, and the free response the
//! state that the controller's answer to the noise left in flight; at a
//! coarse period under noise the differences are slow to
//! tell a halved gain or a doubled lag, the levels quick: measured on the
//! bank, 41 and 39 of 45 such cases within 10 % of the true model's IAE
//! before, 45 and 45 after), and closes at rest a response's time later.
//!
//! A response counts only when some model explains it (the best leaves
//! the noise's residual to within three of its standard deviations, `χ²`
//! with `n − 2` degrees of freedom, and at most [`EXPLAINED`] of the model
//! in use's residual above the noise; or the model in use leaves no more
//! than the noise): a ramp, a second load inside the response, a
//! change of dead time the hypotheses do not cover, or dynamics no model
//! has leave residuals no hypothesis removes, and teach nothing about the
//! gain and the lag. Nor when the best fit leaves a drift (a ramp load:
//! [`DRIFT`]), when the model in use at another dead time explains it
//! better (`shifted`), or when the measurement hardly moved (a load the
//! controller held it against). A hypothesis is proposed when its sum
//! reached [`LEVEL_EVIDENCE`], it has the most, it explained the last
//! two responses to the noise better than the model in use, and the
//! responses besides its largest gave [`REPLICATED`] of it; the supervisor
//! applies it as the differences' proposal ([`Estimator::proposal`]), with
//! the sum as its evidence.
//!
//! Beside the hypotheses the test weighs the supervisor's challenger
//! (`challenger.rs`): the bank's settled estimate where its prediction in
//! the differences is not yet better than the model in use's by the
//! validation's margin (under 5 % noise at ten samples of dead time a gain
//! 0.6 times the model's, settled within 2 %, never was). Its evidence
//! sums as a hypothesis's, on the same responses and by the same tests
//! (its own fit to the noise and drift), the load's regressors on every
//! response alike. Even a set-point change's from rest starts from a
//! state in flight: the controller's answer to the noise moved the
//! process, and that state's free response, unknown, is the regressor
//! `c1·q`'s to take (Ljung (1999) Sec. 4.3, the initial state a nuisance
//! parameter). Fitted with the constant alone, that free response was
//! evidence of either sign, some 40 in a response under 5 % noise, and a
//! challenger 13 % from the model in use (the bank's estimate, itself
//! that far off) reached [`LEVEL_EVIDENCE`] in three responses (measured:
//! no change, set-point moves, 5 % noise, seeds the bank does not run: 5
//! of 210 cases had a model applied, an event 1.07 times the fixed
//! loop's IAE; with the free response, none of 1 050 under any noise).
//! The bank's changes are learnt as before (`docs/adapt-bank.md`: one
//! family's slowest case later, every case within 10 % of the true
//! model's IAE).
//!
//! And beside them the model in use at other dead times (`dead.rs`), each
//! weighed as a hypothesis on the responses that one of them explains
//! better than every gain and lag, and proposed where the bank's
//! differences do not see the change (under noise, a loop that only loads
//! move: measured on the bank's dead time ×0.7 with loads at the coarse
//! period, 34 of 45 cases within 10 % of the true model's IAE, 28 before).
//!
//! And the gain and the lag between the hypotheses (`between.rs`): the
//! model in use and its gain hypotheses are points on one parabola in the
//! gain, whose lowest point is the response's least-squares gain; its lag
//! hypotheses, near the lowest point, on one in the lag's logarithm.
//! Weighed each by its own sum (one parameter more, a penalty per
//! response), each is proposed as the nearest hypothesis with its own
//! factor, where it explains the responses better than that hypothesis
//! (measured on the bank: a gain ×0.6 with loads within 10 % of the true
//! model's IAE in 134 of 150 cases, 120 before the gain; a lag ×1.6 with
//! loads 81 of 90, 68 before the lag).
//! The test needs plain
//! differences ([`EstimatorConfig::prefilter`] 0, the default): another
//! prefilter colours the noise the evidence is measured against.

use super::hypotheses::gain_factors;
use super::*;
use crate::real::arg_min;
use between::{betweens, Proposed, Quadratic, Response, Weigh, KINDS};
use challenger::Challenger;
use dead::{shifted, Dead, DeadResponse};
use fit::Fit;
pub use noise::DRIFT;
use noise::{top, Noise};
pub use ramps::PARTIAL;
pub use watch::{WATCH_DRIFT, WATCH_LIMIT};

/// The other dead times the level test fits the model in use at
/// ([`shifted`]).
const DEAD: usize = 4;

/// The models the level test fits: the model in use, each hypothesis, the
/// model in use at the other dead times of [`shifted`], and the
/// supervisor's challenger ([`Estimator::challenge`]).
const FITS: usize = HYPOTHESES + DEAD + 2;

/// Page's sum of a hypothesis's evidence over the responses at which the
/// level test proposes it. Against the model in use when nothing changed,
/// a hypothesis's evidence per response is negative in the mean and as
/// large as its spread; measured on the bank (`docs/adapt-bank.md`): a
/// halved gain shows about 150 per output load at the coarse period under
/// 2 % noise and about 30 under 5 %.
pub const LEVEL_EVIDENCE: f64 = 60.0;

/// The evidence a hypothesis's sum must hold beyond its largest single
/// response's: a change of the process shows in every response that
/// excites it, a load of a shape the load's regressors do not cover in
/// one now and then. A ramp load that levels off within a response is
/// fitted by a smaller gain or a longer lag to the noise, with an evidence
/// a step's response of a changed process would give (measured: the model
/// in use's drift share as large as the hypothesis's evidence alike), and
/// the next response does not repeat it (measured on the bank's no-change
/// ramps at the coarse period under 2 % noise, seeds it does not run: a
/// doubled lag proposed on one response's 59 and the next's 2, the
/// following load's event 1.8 times the fixed loop's IAE). A quarter of
/// [`LEVEL_EVIDENCE`]: the responses besides the largest must carry a
/// quarter of the threshold themselves (measured on the bank: a gain ×0.6
/// with loads on an integrating process, whose second step of 0.86 shows
/// little in each response, was learnt in one case of 30 fewer).
pub const REPLICATED: f64 = 15.0;

/// The level test's state: a fit per model over the response under way,
/// and the evidence over the responses so far.
#[derive(Debug, Clone, Copy)]
pub(super) struct Levels<T> {
    fits: [Fit<T>; FITS],
    /// Samples of the response under way (`None`: none).
    open: Option<usize>,
    /// A response ended, of this many samples, not compared yet.
    due: Option<usize>,
    /// The watch at rest: the model in use's residual in levels (an
    /// integrating model's: its first sum too), its mean, Page's sums of
    /// its departures up and down; whether it runs (else it starts again
    /// at the next sample at rest).
    watch: [T; 5],
    watched: bool,
    /// The drift's regressor `p[k]` (`k`, integrating `k²`: a ramp load's
    /// response beside a step's) over the response: `k`, `Σp`, `Σp²`.
    p: [T; 3],
    /// The measured output's level from the response's start (an
    /// integrating process's: its difference first), its sum and its sum
    /// of squares over the response.
    y: [T; 4],
    /// Page's sum of each hypothesis's evidence over the responses.
    sums: [T; HYPOTHESES],
    /// The largest evidence of a single response in each sum since it was
    /// last at zero.
    peaks: [T; HYPOTHESES],
    /// The hypothesis with the most evidence, and the responses in a row
    /// that it explained better than the model in use.
    streak: (usize, u8),
    /// The measurement's quantum: the smallest difference between its raw
    /// samples a block apart that was not zero (a converter's step), and
    /// the last block's last raw sample. Not the block means': undithered,
    /// a slow block's samples round alike, a whole step's error (measured:
    /// read as 1/25 of a step at msp's chosen period, an integrating
    /// loop's moves within one step gave a halved gain the evidence of 85).
    quantum: T,
    raw: T,
    /// The nonzero raw differences in a row that were whole multiples of
    /// the quantum (a converter's; a continuous noise's smallest
    /// difference is no grid the next ones fall on).
    on_grid: u16,
    /// The hypothesis proposed, with its evidence over the last response
    /// and its relative error there (as [`Mismatch`]'s).
    proposal: Option<(usize, Mismatch<T>)>,
    /// Responses compared, and those of them taken as evidence
    /// ([`Estimator::level_responses`]; kept through a reset).
    responses: (u32, u32),
    /// Since the model in use was set: the steps' responses (a set-point
    /// change's, a load's taken as evidence) and the ramps'
    /// ([`Levels::ramping`]); the ramps' in all
    /// ([`Estimator::level_ramps`]; kept through a reset).
    since: (u32, u32),
    ramps: u32,
    /// The response under way is a load's (else a set-point change's).
    load: bool,
    /// The challenger ([`Estimator::challenge`]).
    challenger: Option<Challenger<T>>,
    /// The gain and the lag between the hypotheses (`between.rs`), each:
    /// Page's sum of its evidence with its largest response ([`page`]),
    /// the responses in a row it explained better than the model in use,
    /// the responses' parabolas since the sum was last at zero (each over
    /// the noise's variance), and the factor proposed: the nearest
    /// hypothesis, the factor from its to the one proposed, and the
    /// mismatch (of the two, `Levels::between_choice` takes the one with
    /// the more evidence).
    between: [((T, T), u8); KINDS],
    quads: [Quadratic<T>; KINDS],
    between_proposed: [Option<Proposed<T>>; KINDS],
    /// The last response's factors between, weighed in the next call (the
    /// Cortex-M4F's longest call is a response's comparison, #48 item 7):
    /// meanwhile the level test proposes nothing.
    weigh: Option<Weigh<T>>,
    /// The dead-time hypotheses (`dead.rs`).
    dead: Dead<T>,
}

impl<T: Real> Levels<T> {
    pub(super) fn new() -> Self {
        Levels {
            fits: [Fit::zero(); FITS],
            open: None,
            due: None,
            watch: [T::zero(); 5],
            watched: false,
            p: [T::zero(); 3],
            y: [T::zero(); 4],
            sums: [T::zero(); HYPOTHESES],
            peaks: [T::zero(); HYPOTHESES],
            streak: (0, 0),
            quantum: T::infinity(),
            raw: T::zero(),
            on_grid: 0,
            proposal: None,
            responses: (0, 0),
            since: (0, 0),
            ramps: 0,
            load: false,
            challenger: None,
            between: [((T::zero(), T::zero()), 0); KINDS],
            quads: [[T::zero(); 3]; KINDS],
            between_proposed: [None; KINDS],
            weigh: None,
            dead: Dead::new(),
        }
    }
}

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// A response starts (an onset's last sample): every fit from zero;
    /// `load`, a load's (an onset, the watch), else the input's first move
    /// after rest (a set-point change's).
    pub(super) fn levels_open(&mut self, load: bool) {
        if self.cfg.prefilter != T::zero() {
            return;
        }
        // (a response due is compared now: its fits start again here)
        if let Some(n) = self.levels.due.take() {
            self.levels_compare(n);
        }
        let lv = &mut self.levels;
        lv.fits = [Fit::zero(); FITS];
        lv.y = [T::zero(); 4];
        lv.p = [T::zero(); 3];
        lv.open = Some(0);
        lv.load = load;
        lv.watched = false;
        if let Some(c) = lv.challenger.as_mut() {
            c.whole = true;
        }
    }

    /// The raw measurement `y` at a block's end (`ok`: the block is the
    /// process's own response), for the quantum.
    pub(super) fn levels_quantum(&mut self, y: T, ok: bool) {
        let d = (y - self.levels.raw).abs();
        self.levels.raw = y;
        if !ok || self.samples < 1 {
            return;
        }
        let lv = &mut self.levels;
        if d > T::zero() && d < lv.quantum {
            lv.quantum = d;
            lv.on_grid = 1;
        } else if d > T::zero() {
            let r = d / lv.quantum;
            let whole = (r - r.round()).abs() < T::of(1e-3);
            lv.on_grid = if whole {
                lv.on_grid.saturating_add(1)
            } else {
                0
            };
        }
    }

    /// A response is under way.
    pub(super) fn levels_open_now(&self) -> bool {
        self.levels.open.is_some()
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
        lv.peaks = [T::zero(); HYPOTHESES];
        lv.streak = (0, 0);
        lv.proposal = None;
        lv.challenger = None;
        lv.between = [((T::zero(), T::zero()), 0); KINDS];
        lv.quads = [[T::zero(); 3]; KINDS];
        lv.between_proposed = [None; KINDS];
        lv.weigh = None;
        lv.dead = Dead::new();
        lv.since = (0, 0);
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
        let d = r.d;
        let dead = shifted(d, H.saturating_sub(2));
        let [k, sp, spp] = self.levels.p;
        let k = k + T::one();
        let p = if integrating { k * k } else { k };
        self.levels.p = [k, sp + p, spp + p * p];
        let challenger = self.levels.challenger.map(|c| (c.coef, c.d));
        let hist = &self.hist;
        // (the fits in runs of their own: the model in use, the hypotheses,
        // the other dead times, the challenger)
        let fit = |f: &mut Fit<T>, coef: [T; 3], u: (T, T)| {
            f.step(coef, u, target, p, integrating);
        };
        let u = hist.pair(d);
        let (model, rest) = self.levels.fits.split_at_mut(1);
        let (hyps, rest) = rest.split_at_mut(HYPOTHESES.min(rest.len()));
        let (deads, rest) = rest.split_at_mut(dead.len().min(rest.len()));
        for f in model {
            fit(f, r.theta, u);
        }
        for (f, h) in hyps.iter_mut().zip(&self.hyp) {
            fit(f, h.coef, u);
        }
        for (f, &d) in deads.iter_mut().zip(&dead) {
            fit(f, r.theta, hist.pair(d));
        }
        for (f, (coef, d)) in rest.iter_mut().zip(challenger) {
            fit(f, coef, hist.pair(d));
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
        let ended =
            (self.hist.quiet > self.rest_after && n > response) || n >= response.saturating_mul(4);
        if ended {
            // compared by the next `levels_finish`
            self.levels.open = None;
            self.levels.due = Some(n);
        }
    }

    /// Whether a response that ended waits for its comparison, or its
    /// factors between the hypotheses for their weighing.
    #[inline]
    pub(super) fn levels_due(&self) -> bool {
        self.levels.due.is_some() || self.levels.weigh.is_some()
    }

    /// A response that ended in `levels_step` compared, or its factors
    /// between the hypotheses weighed (each in a call of its own: between
    /// the estimator's passes, `Estimator::advance`).
    pub(super) fn levels_finish(&mut self) {
        if let Some(w) = self.levels.weigh.take() {
            self.levels.weigh_betweens(w);
        } else if let Some(n) = self.levels.due.take() {
            self.levels_compare(n);
        }
    }

    /// The response's end: the fits compared (see the module
    /// documentation), Page's sums moved on, the proposal renewed.
    fn levels_compare(&mut self, n: usize) {
        // (the last response's weighing first, where it still waits)
        if let Some(w) = self.levels.weigh.take() {
            self.levels.weigh_betweens(w);
        }
        self.levels.open = None;
        let (compared, used) = self.levels.responses;
        self.levels.responses = (compared.saturating_add(1), used);
        let tested = self.hypotheses().len();
        let nt = T::of(n as f64);
        let (noise_dev, rounding) = self.level_noises();
        // the noise is the rounding's (a measured noise within half a
        // quantum, `q/2 = √3·rounding`, is the rounding's own trace, and
        // does not dither it): see `independent` below
        let rounded = noise_dev < T::of(1.732_050_807_568_877_2) * rounding;
        let deviation = at_least(noise_dev, rounding);
        let measured = deviation * deviation;
        let factors = gain_factors(self.fine).map(T::of);
        let dead_ds = self.dead_candidates();
        let lv = &mut self.levels;
        let [reference, rest @ ..] = &lv.fits;
        let (hyps, rest) = rest.split_at(HYPOTHESES);
        let (dead, challenger) = rest.split_at(rest.len().saturating_sub(1));
        let [_, sp, spp] = lv.p;
        let fit_ref = reference.rss(nt, [sp, spp]);
        let (v_ref, _) = fit_ref;
        let v_challenger = challenger.first().map(|f| f.rss(nt, [sp, spp]));
        let mut dead_fits = [(T::infinity(), T::zero()); DEAD];
        for (v, f) in dead_fits.iter_mut().zip(dead) {
            *v = f.rss(nt, [sp, spp]);
        }
        let v_dead = dead_fits.iter().fold(T::infinity(), |m, f| at_most(m, f.0));
        let mut rss = [T::zero(); HYPOTHESES];
        let mut drifts = [T::zero(); HYPOTHESES];
        for ((v, d), f) in rss.iter_mut().zip(&mut drifts).zip(hyps).take(tested) {
            (*v, *d) = f.rss(nt, [sp, spp]);
        }
        let rss = rss.get(..tested).unwrap_or_default();
        let Some((best, v_best)) = arg_min(rss.iter().copied()) else {
            return;
        };
        let drift = drifts.get(best).copied().unwrap_or_default();
        // the gain and the lag between the hypotheses (`between.rs`)
        let betweens = betweens(
            factors,
            rss,
            drifts.get(..tested).unwrap_or_default(),
            fit_ref,
        );
        // the noise's variance in levels (`level_deviation`), at least half the
        // best fit's residual per degree of freedom and [`FLOOR`] of the
        // response's energy per sample (`noise.rs`)
        let [_, _, sy, syy] = lv.y;
        let energy = at_least(syy - sy * sy / nt, T::zero());
        let noise = Noise::new(nt, T::of(2.0), measured, v_best, energy).undithered(rounded);
        let sigma2 = noise.sigma2;
        // the best fits to the noise, and leaves at most EXPLAINED of the
        // model in use's excess
        let explains = noise.explains(v_best, v_ref);
        let fits_ref = noise.fits(v_ref);
        let seen = noise.seen(energy);
        // and the best fit leaves no drift: a ramp load, which a model with
        // the wrong gain follows in part (the controller's answer carries
        // it), is no step's response (the drift's share of the residual
        // within [`DRIFT`] times the noise's variance, `χ²` with one degree
        // of freedom: an F-test of the drift's regressor)
        let steady = noise.steady(drift);
        // a ramp's response? (every fit: a changed process's is no ramp's)
        let fits = dead_fits
            .iter()
            .copied()
            .chain(betweens.iter().flatten().map(|b| (b.rss, b.drift)));
        lv.weigh_ramp(&noise, v_ref, fits.chain([(v_best, drift)]));
        // and no other dead time explains it better (see [`shifted`])
        let own = v_best < v_dead || fits_ref;
        // and, where the rounding is the noise, a misfit beyond it: without
        // a noise that dithers it (a standard deviation of half a quantum
        // or more), the rounding is a function of the signal, not the
        // independent uniform noise of Widrow, Kollár & Liu (1996), the same
        // in each of the loads' alike responses, and its misfits do not add
        // up to evidence as independent noise's do (measured on the bank:
        // noise-free integrating loops behind a 10-bit converter, each
        // load's response fitted by the model in use to the rounding, had a
        // gain 1.4 times their own proposed after twenty of them)
        let independent = !(rounded && fits_ref);
        if let (Some(c), Some((v, drift))) = (lv.challenger.as_mut(), v_challenger) {
            // the challenger on the same response, by the same tests but
            // its own: it explains the response to the noise and leaves no
            // drift (not the hypotheses' `own`: its dead time is its own)
            let counts = c.whole
                && (noise.fits(v) || fits_ref)
                && seen
                && noise.steady(drift)
                && independent
                && sigma2 > T::zero();
            if counts {
                c.sum = at_least(c.sum + (v_ref - v) / sigma2, T::zero());
                let better = noise.better(v, v_ref);
                c.streak = if better {
                    c.streak.saturating_add(1)
                } else {
                    0
                };
            }
        }
        // the gain and the lag between the hypotheses, each by its own sum
        // (`between.rs`)
        let response = Response {
            n: nt,
            measured,
            energy,
            v_ref,
            v_dead,
            rounded,
        };
        lv.weigh = Some(Weigh {
            betweens,
            response,
            factors,
        });
        // the dead-time hypotheses, by their own sums (`dead.rs`)
        lv.dead.weigh(DeadResponse {
            d: dead_ds,
            v: dead_fits.map(|f| f.0),
            drift: dead_fits.map(|f| f.1),
            v_ref,
            v_hyp: v_best,
            noise,
            energy,
            counts: seen && independent,
        });
        if !(explains || fits_ref)
            || !seen
            || !steady
            || !own
            || !independent
            || !(sigma2 > T::zero())
        {
            return;
        }
        lv.responses.1 = used.saturating_add(1);
        lv.since.0 = lv.since.0.saturating_add(u32::from(lv.load));
        let inv = T::one() / sigma2;
        for ((s, peak), &v) in lv.sums.iter_mut().zip(&mut lv.peaks).zip(rss) {
            (*s, *peak) = page((*s, *peak), (v_ref - v) * inv);
        }
        // the hypothesis with the most evidence, proposed while it has
        // enough and explains the last two responses to the noise better
        // than the model in use (under 5 % noise a single response's
        // evidence is within the noise's spread: only the sum tells; and a
        // response during which the process changed, half the one and half
        // the other, is explained by neither, and by a lag or a gain
        // between them in part: measured on the bank, a dead time that rose
        // inside a load's response had a doubled lag proposed by it)
        let sums = lv.sums.get(..tested).unwrap_or_default();
        let (i, sum) = top(sums.iter().copied());
        let v_top = rss.get(i).copied().unwrap_or(v_ref);
        let better = noise.better(v_top, v_ref);
        lv.streak = streak(lv.streak, i, better);
        let peak = lv.peaks.get(i).copied().unwrap_or_default();
        let proposed = enough((sum, peak)) && lv.streak.1 >= 2;
        lv.proposal = proposed.then(|| {
            (
                i,
                Mismatch {
                    error: (at_least(v_ref - v_top, T::zero()) / energy).sqrt(),
                    evidence: sum,
                },
            )
        });
    }

    /// The responses (a load's, or a set-point change's from rest) the
    /// level test compared so far, and how many of them it took as
    /// evidence: the others it held back (within the noise or the
    /// rounding, a measurement that hardly moved, a drift, a response
    /// another dead time explains better; see the module documentation).
    /// Many responses and none taken: what moves this loop cannot teach it
    /// a gain or a lag.
    pub fn level_responses(&self) -> (u32, u32) {
        self.levels.responses
    }

    /// Of the responses the level test compared, those that were a ramp
    /// load's ([`PARTIAL`]): while, since the model in use was set, they
    /// outnumber the ones taken as evidence, the level test proposes
    /// nothing (it cannot tell a ramp's end from a change of the process).
    pub fn level_ramps(&self) -> u32 {
        self.levels.ramps
    }

    /// The hypothesis the level test proposes (see the module
    /// documentation) and how far the model in use is from the last
    /// response against it.
    pub(super) fn level_proposal(&self) -> Option<(usize, Mismatch<T>)> {
        if self.levels.ramping() || self.levels.weigh.is_some() {
            return None;
        }
        match self.level_between() {
            Some(p) => Some((p.i, p.mismatch)),
            None => self.levels.proposal,
        }
    }

    /// Where the level test proposes the gain or the lag between its
    /// hypotheses (`between.rs`; where a hypothesis is proposed too, as
    /// `Levels::between_choice` chooses): the nearest hypothesis ([`Estimator::level_proposal`]'s), the factor
    /// from its gain or lag to the one proposed, and the mismatch.
    pub(super) fn level_between(&self) -> Option<Proposed<T>> {
        if self.levels.ramping() || self.levels.weigh.is_some() {
            return None;
        }
        self.levels.between_choice()
    }
}

/// Page's sum and its largest single response since it was last at zero,
/// `(sum, peak)`, moved on by a response's evidence `e`: `max(0, sum + e)`
/// (Page (1954)).
fn page<T: Real>((sum, peak): (T, T), e: T) -> (T, T) {
    let sum = at_least(sum + e, T::zero());
    let peak = if sum > T::zero() {
        peak.max(e)
    } else {
        T::zero()
    };
    (sum, peak)
}

/// The responses in a row `(i, count)` that the model `top` explained
/// better than the model in use, after a response it did (`better`) or
/// not: a new model's run starts at one.
fn streak((was, count): (usize, u8), top: usize, better: bool) -> (usize, u8) {
    match (better, was == top) {
        (true, true) => (top, count.saturating_add(1)),
        (true, false) => (top, 1),
        (false, _) => (top, 0),
    }
}

/// A sum `(sum, peak)` of [`page`] is evidence enough: it reached
/// [`LEVEL_EVIDENCE`], and not on one response alone ([`REPLICATED`]).
fn enough<T: Real>((sum, peak): (T, T)) -> bool {
    sum >= T::of(LEVEL_EVIDENCE) && sum - peak >= T::of(REPLICATED)
}

mod between;
mod challenger;
mod dead;
mod fit;
mod noise;
mod ramps;
#[cfg(test)]
mod tests;
mod watch;
