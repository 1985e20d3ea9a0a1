//! On-line identification of a dead-time process from closed-loop data: a
//! bank of recursive least-squares estimators over candidate dead times
//! (no_std, allocation-free, `f32`/`f64`).
//!
//! The model, for the sampled first-order-plus-dead-time process (its ZOH
//! equivalent with a dead time of `d + f` samples, `0 ≤ f < 1`):
//!
//! `y[k+1] = a·y[k] + b0·u[k−d] + b1·u[k−d−1]`,
//!
//! with `a = e^{−Ts/τ}`, and the fractional part of the dead time shared
//! between `b0` and `b1` (`b1/(b0 + b1)` is `f` to first order in `Ts/τ`;
//! exactly `b0 = K(1 − a^{1−f})`, `b1 = K(a^{1−f} − a)`). So
//! `K = (b0 + b1)/(1 − a)`, `τ = −Ts/ln a`, `θ = (d + f)·Ts` with
//! `a^{1−f} = 1 − b0/K` (Åström & Wittenmark (1997) Sec. 2.3 for the ZOH of
//! a fractional delay). For an integrating process (`a = 1`) `b0 + b1 = K·Ts`
//! and `f = b1/(b0 + b1)`.
//!
//! Each candidate `d ∈ [d_min, d_min + N)` runs its own recursive
//! estimator on the prefiltered data (`L(z) = (1 − z⁻¹)/(1 − c·z⁻¹)` on `u`
//! and `y`: loads and offsets that are constant between samples drop out,
//! the measurement noise is not amplified as by plain differences), in
//! output-error form (the prediction runs on the model's own past output
//! `Δŷ[k]`, so measurement noise does not bias `a`; Landau (1976)) by the
//! recursive prediction-error method: the gain follows the prediction's
//! gradient `ψ[k+1] = φ[k] + â·ψ[k]` (Ljung (1999) Sec. 11.3), which makes
//! the estimate as precise as the data allow where the plain regressor
//! (pseudo-linear regression) loses an order of magnitude for a slow
//! process (`a` near 1); an integrating model regresses `Δy[k+1] − Δy[k]`
//! on the inputs alone. Exponential forgetting, the covariance's trace
//! bounded, and with a prior model ([`Estimator::start_from`]) the
//! estimates projected onto plausible ones: the input coefficients of the
//! gain's sign (a fraction in `[0, 1]`), the time constant within a factor
//! [`SPAN`] of the model's (Åström & Wittenmark (1995), *Adaptive
//! Control*, Secs. 2.2 and 11.2; Goodwin & Sin (1984) Sec. 3.7).
//!
//! Each candidate accumulates its discounted squared prediction error; the
//! candidate with the smallest is the dead time, switched to only when the
//! evidence for it ([`Estimate::evidence`]: the cost difference in units
//! of the noise, twice the log-likelihood ratio for Gaussian errors) reaches
//! [`EstimatorConfig::switch_evidence`] for a number of samples (Ljung
//! (1999) Sec. 16.4, delay by model comparison). The costs remember long
//! (2000 samples) and a candidate's estimator what it was fitted to, so
//! after a step of the process's dead time the comparison would wait for
//! the past to be forgotten; a change detector shortens that: the chosen
//! coefficients simulated at every dead time, Page's cumulative sum of
//! the evidence for each, and when one dead time explains most of the
//! chosen one's error the bank restarts from the chosen model, its costs
//! cleared (see `Estimator::detect`; Page (1954), Basseville & Nikiforov
//! (1993)). An update is skipped when
//! the input has not moved clearly more than its own jitter within the
//! response's time (the excitation gate: in closed loop the noise moves the
//! input too, and data in which only the noise does identify the
//! controller as much as the process, Ljung (1999) Sec. 13.4), when the
//! prediction error is within the dead zone of the noise, or when the
//! caller says the sample is not the process's own response (saturated,
//! manual, tracking, a fault).

use crate::real::{at_least, at_most, positive};
use crate::{Error, Real};

mod supervisor;
pub use supervisor::{Adaptive, AdaptiveConfig, Change, ChangeKind, Rebuild, Redesign, SIGNALS};

/// A running median of a magnitude, followed by multiplicative steps (a
/// quantile tracker: up by 1 % when a value is above it, down when below),
/// robust to the few large values that are the excitation or a misfit.
///
/// The stochastic-approximation quantile estimate (Robbins & Monro (1951);
/// Tierney (1983)) on `ln m`: it rests where the expected step is zero,
/// `ln(1.01)·P(m > v) = −ln(0.99)·P(m < v)`, i.e. at the quantile
/// `P(m < v) = ln 1.01/(ln 1.01 − ln 0.99) ≈ 0.4975` — the median to a
/// quarter of a percent of probability; a step of 1 % lets it follow a
/// change of level in about a hundred samples per factor `e`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Median<T> {
    value: T,
}

impl<T: Real> Median<T> {
    pub(crate) fn new() -> Self {
        Median { value: T::zero() }
    }

    /// The median so far.
    pub(crate) fn get(&self) -> T {
        self.value
    }

    /// Takes `m` (≥ 0) and returns the median so far.
    pub(crate) fn push(&mut self, m: T) -> T {
        self.value = if self.value > T::zero() {
            let step = T::of(0.01);
            self.value
                * if m > self.value {
                    T::one() + step
                } else {
                    T::one() - step
                }
        } else {
            m
        };
        self.value
    }
}

/// The last `H` input differences `Δu`, newest first ([`History::from`]`(0)`).
///
/// A ring stored twice over (each difference written at `at` in both
/// halves), newest-first from `at` on: every run the bank reads,
/// `Δu[k−d_min]`, `Δu[k−d_min−1]`, …, is one contiguous slice, which its
/// loop walks without a wrap to test per candidate.
#[derive(Debug, Clone)]
pub(crate) struct History<T, const H: usize> {
    du: [[T; H]; 2],
    at: usize,
    last_u: T,
    /// The prefilter's pole `c` and its last output (`Δu` through `1/(1 − c·z⁻¹)`).
    pole: T,
    last_f: T,
    /// The excitation gate's threshold, and how many entries ago one
    /// reached it (0: the newest).
    gate: T,
    pub(crate) quiet: usize,
    /// The gate's threshold relative to the input's jitter, and the jitter:
    /// a running median of `|Δu|` (what noise through the controller moves
    /// the input by when nothing else does).
    ratio: T,
    jitter: Median<T>,
}

impl<T: Real, const H: usize> History<T, H> {
    pub(crate) fn new(pole: T, gate: T, ratio: T) -> Self {
        History {
            du: [[T::zero(); H]; 2],
            at: 0,
            last_u: T::zero(),
            pole,
            last_f: T::zero(),
            gate,
            quiet: usize::MAX,
            ratio,
            jitter: Median::new(),
        }
    }

    /// The input `u` of the period that just ended joins as `Δu`.
    pub(crate) fn push(&mut self, u: T) {
        let du = self.pole * self.last_f + (u - self.last_u);
        self.last_f = du;
        // the jitter: the median of |Δu|, robust to the few large moves
        // that are the excitation
        let m = du.abs();
        let jitter = self.jitter.push(m);
        self.quiet = if m >= self.gate && m >= self.ratio * jitter {
            0
        } else {
            self.quiet.saturating_add(1)
        };
        self.at = if self.at == 0 {
            H.saturating_sub(1)
        } else {
            self.at - 1
        };
        for half in &mut self.du {
            if let Some(x) = half.get_mut(self.at) {
                *x = du;
            }
        }
        self.last_u = u;
    }

    /// The differences `j` and `j + 1` entries before the newest
    /// (`Δu[k−d]`, `Δu[k−d−1]` for a dead time `d = j`; 0 beyond the
    /// history).
    pub(crate) fn pair(&self, j: usize) -> (T, T) {
        let u = self.from(j);
        let at = |i: usize| u.get(i).copied().unwrap_or(T::zero());
        (at(0), at(1))
    }

    /// The differences from `j` entries before the newest on, each older
    /// than the one before, to the end of the history (empty from `H` on).
    pub(crate) fn from(&self, j: usize) -> &[T] {
        self.du
            .as_flattened()
            .get(self.at.saturating_add(j)..self.at.saturating_add(H))
            .unwrap_or(&[])
    }
}

/// One candidate dead time's estimator: `θ = (a, b0, b1)` and `P` (3×3).
#[derive(Debug, Clone, Copy)]
struct Candidate<T> {
    theta: [T; 3],
    p: [[T; 3]; 3],
    /// Discounted squared prediction error.
    cost: T,
    /// The model's own output difference `Δŷ[k]` (output-error regressor).
    yhat: T,
    /// The prediction's gradient `ψ[k] = ∂Δŷ[k]/∂(a, b0, b1)`: the
    /// regressor through `1/(1 − â·z⁻¹)`.
    psi: [T; 3],
    /// The chosen candidate's coefficients at this candidate's dead time:
    /// their simulated output `Δŷ[k]` (the change detector's model).
    scan: T,
    /// The change detector's statistic for this dead time against the
    /// chosen one (Page's cumulative sum of the evidence, floored at 0).
    cusum: T,
    /// The simulation's squared error over about the last response
    /// (excited samples, discounted by `1 − 1/window` per sample).
    recent: T,
}

/// One sample of the change detector ([`Estimator::detect_begin`]): what
/// each candidate's step reads, and the dead time it found.
#[derive(Debug, Clone, Copy)]
struct Scan<T> {
    /// The snapshot's coefficients (`a` = 0 for an integrating model).
    coef: [T; 3],
    target: T,
    /// The chosen dead time's squared error now and over the last response.
    e2: T,
    recent_chosen: T,
    /// The noise's variance, and its share of a recent error.
    scale: T,
    floor: T,
    /// The recent errors' discount per excited sample.
    short: T,
    excited: bool,
    chosen: usize,
    /// [`EstimatorConfig::switch_evidence`].
    evidence: T,
    /// The dead time whose evidence counts, the most of them, and its sum.
    best: Option<(usize, T)>,
}

impl<T: Real> Scan<T> {
    /// Candidate `i`'s simulation at its dead time (`u0 = Δu[k−d]`,
    /// `u1 = Δu[k−d−1]`), its recent error and its cumulative sum.
    #[inline(always)]
    fn step(&mut self, i: usize, c: &mut Candidate<T>, u0: T, u1: T) {
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
            let gain = self.e2 - e2;
            sum = if self.scale > T::zero() {
                at_least(sum + gain / self.scale, T::zero())
            } else if gain > T::zero() {
                T::infinity()
            } else {
                T::zero()
            };
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
    }
}

/// Settings of an [`Estimator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig<T> {
    /// The sample period (s).
    pub ts: T,
    /// The smallest candidate dead time (whole samples).
    pub d_min: usize,
    /// The longest candidate dead time (whole samples, at least `d_min`;
    /// `None`: `d_min + N − 1`, the whole bank). The bank's candidates
    /// beyond it are not run and never chosen.
    pub d_max: Option<usize>,
    /// Forgetting factor `λ` (0.98–0.9999): memory `1/(1 − λ)` samples.
    pub forgetting: T,
    /// Bound on the covariance's trace (no "bursting" when nothing moves).
    pub max_trace: T,
    /// Dead zone: prediction errors below this (the noise level) do not update.
    pub dead_zone: T,
    /// Dead zone from the measured noise level: no update while the
    /// prediction error is within this many times the chosen candidate's
    /// RMS error (`√(V/W)`: the noise, once the model is right; default 0:
    /// off). Errors the noise makes do not move the estimates; a model
    /// that is wrong makes larger ones (Åström & Wittenmark (1995)
    /// Sec. 11.2: dead zones against bounded disturbances).
    pub dead_zone_ratio: T,
    /// Excitation gate relative to the input's own jitter: no update unless
    /// `|Δu|` reached this many times its running median (what the noise
    /// through the controller moves it by) within the gate's window
    /// (default 10; 0: off). Closed-loop data in which only the noise moves
    /// the input identify the controller's inverse as much as the process
    /// (Ljung (1999) Sec. 13.4): the gate keeps the estimator to the
    /// moves that are the set point's and the loads'.
    pub excitation_ratio: T,
    /// Excitation gate: no update unless `|Δu|` reached this within the
    /// history the candidates read.
    pub min_excitation: T,
    /// Discount of the candidates' costs (the decision's memory).
    pub cost_memory: T,
    /// A new dead time must have at least this much evidence over the
    /// current one (see [`Estimate::evidence`])…
    pub switch_evidence: T,
    /// …for this many consecutive samples.
    pub switch_hold: u32,
    /// The process integrates (`a = 1`, not estimated).
    pub integrating: bool,
    /// Controller samples per estimator sample (at least 1): the estimator
    /// learns from the means of `y` and `u` over blocks of this many
    /// samples, at its period `ts·decimation` (the process's own time
    /// scale: a fine controller period gives it no more information per
    /// sample, only more noise and more work). The dead times `d_min`,
    /// `d_max` and every other count of samples here are the estimator's.
    /// Both means pass the same moving-average filter, which commutes with
    /// the process, so the block means obey the process's model (up to the
    /// block's own aliasing, small once the block is a fraction of the dead
    /// time and of the lag); the measurement noise falls by `√decimation`.
    pub decimation: usize,
    /// The pole `c` of the prefilter `L(z) = (1 − z⁻¹)/(1 − c·z⁻¹)` both
    /// the input and the output pass before the estimator sees them
    /// (`0 ≤ c < 1`; 0: plain differences). The model is linear, so the
    /// filtered signals obey it too; like differencing, `L` removes
    /// offsets and constant loads (its zero at `z = 1`), and with `c` near
    /// 1 it passes the process's band while attenuating the measurement
    /// noise differencing would amplify (Ljung (1999) Sec. 14.1, prefiltering).
    pub prefilter: T,
}

impl<T: Real> EstimatorConfig<T> {
    /// The prefilter's pole from its time constant `t` (s): `c = e^{−Ts/t}`
    /// at the estimator's period `Ts` ([`EstimatorConfig::period`])
    /// (0: plain differences).
    pub fn set_prefilter_time(&mut self, t: T) -> Result<(), Error> {
        if !(t >= T::zero() && t.is_finite()) {
            return Err(Error::OutOfRange(
                "prefilter: a time constant (s), 0 or positive",
            ));
        }
        self.prefilter = if t > T::zero() {
            (-self.period() / t).exp()
        } else {
            T::zero()
        };
        Ok(())
    }

    /// The estimator's period, `ts·decimation` (s).
    pub fn period(&self) -> T {
        self.ts * T::of(self.decimation as f64)
    }

    /// Checks every setting (the history's room is the estimator's).
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.ts, "ts")?;
        if self.decimation == 0 {
            return Err(Error::OutOfRange("decimation: at least 1"));
        }
        let unit = |v: T, name| {
            if v > T::zero() && v <= T::one() {
                Ok(())
            } else {
                Err(Error::OutOfRange(name))
            }
        };
        unit(self.forgetting, "forgetting in (0, 1]")?;
        unit(self.cost_memory, "cost_memory in (0, 1]")?;
        if !(self.prefilter >= T::zero() && self.prefilter < T::one()) {
            return Err(Error::OutOfRange("prefilter pole in [0, 1)"));
        }
        positive(self.max_trace, "max_trace")?;
        if self.d_max.is_some_and(|d| d < self.d_min) {
            return Err(Error::OutOfRange("estimator: d_max at least d_min"));
        }
        for (v, name) in [
            (self.dead_zone, "dead_zone"),
            (self.dead_zone_ratio, "dead_zone_ratio"),
            (self.min_excitation, "min_excitation"),
            (self.excitation_ratio, "excitation_ratio"),
            (self.switch_evidence, "switch_evidence"),
        ] {
            crate::real::non_negative(v, name)?;
        }
        Ok(())
    }

    /// Defaults for period `ts` and candidates from `d_min` samples:
    /// forgetting 0.999, trace ≤ 1e4, no dead zone, excitation 1e-6, cost
    /// memory 0.9995 (2000 samples), a switch of dead time at an evidence
    /// of 20 held 50 samples.
    pub fn new(ts: T, d_min: usize) -> Self {
        EstimatorConfig {
            ts,
            d_min,
            d_max: None,
            forgetting: T::of(0.999),
            max_trace: T::of(1e4),
            dead_zone: T::zero(),
            dead_zone_ratio: T::zero(),
            min_excitation: T::of(1e-6),
            excitation_ratio: T::of(10.0),
            cost_memory: T::of(0.9995),
            switch_evidence: T::of(20.0),
            switch_hold: 50,
            integrating: false,
            decimation: 1,
            prefilter: T::zero(),
        }
    }
}

/// The model's one-step output `â·x + b̂0·Δu[k−d] + b̂1·Δu[k−d−1]` from
/// its state `x` (the module's equation; an integrating model regresses
/// on the inputs alone: no `a` term).
#[inline(always)]
fn predict<T: Real>([a, b0, b1]: [T; 3], x: T, (u0, u1): (T, T), integrating: bool) -> T {
    let a = if integrating { T::zero() } else { a };
    a * x + b0 * u0 + b1 * u1
}

/// [`Estimator::evidence`] over costs of weight `weight`.
fn evidence<T: Real>(chosen: T, other: T, weight: T) -> T {
    let scale = if weight > T::zero() {
        chosen / weight
    } else {
        T::zero()
    };
    if scale > T::zero() {
        (other - chosen) / scale
    } else if other > chosen {
        T::infinity()
    } else {
        T::zero()
    }
}

/// The model in use against the process ([`Estimator::mismatch`]).
///
/// Both the model in use (the reference) and the estimator's chosen
/// candidate predict the same prefiltered output; a load or an offset adds
/// the same error to both (the model of neither holds it), so the
/// difference of their costs is the model's error alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mismatch<T> {
    /// The model's error relative to the movement it predicts:
    /// `√((V_reference − V_chosen)/E_reference)`, `E` the discounted energy
    /// of the reference's prediction — about the relative error of its gain
    /// for a gain error (0.3: the process's gain is 30 % off the model's).
    pub error: T,
    /// The evidence for the chosen candidate over the reference (as
    /// [`Estimate::evidence`]): large, the error is not the noise's.
    pub evidence: T,
}

/// The model in use, predicting without learning.
#[derive(Debug, Clone, Copy)]
struct Reference<T> {
    theta: [T; 3],
    d: usize,
    cost: T,
    energy: T,
    yhat: T,
    /// Samples learnt from (excited) since the reference was set: its
    /// comparison means something after a whole response.
    seen: usize,
    /// The chosen candidate's cost over the same samples (since the
    /// reference was set: the two compared on the same data), and the
    /// costs' weight since.
    rival: T,
    weight: T,
}

/// The process model an [`Estimator`] holds now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate<T> {
    /// Static gain `K` (integrating: the velocity gain).
    pub k: T,
    /// Time constant `τ` (s; infinite for an integrating process).
    pub tau: T,
    /// Dead time `θ` (s).
    pub theta: T,
    /// The chosen candidate dead time (whole samples).
    pub d: usize,
    /// The evidence for the chosen dead time over the best other
    /// candidate that is not its neighbour (a neighbour's dead times
    /// `[d ± 1, d ± 1 + 1]` share an end with the chosen one's `[d, d + 1]`,
    /// so it may fit as well): the other's discounted cost less the chosen one's, in
    /// units of the chosen one's mean squared error per sample
    /// (`(V_other − V_chosen)·W/V_chosen` over the costs' weight
    /// `W = Σ cost_memory^j`, `1/(1 − cost_memory)` once full; for Gaussian
    /// errors twice the log-likelihood ratio over the costs' memory
    /// (Ljung (1999) Sec. 16.4); small: an ambiguous choice; infinite:
    /// noise-free data).
    pub evidence: T,
}

/// The bank of `N` RLS estimators over the dead times `d_min … d_min + N − 1`
/// samples (to [`EstimatorConfig::d_max`] when it is shorter), sharing one
/// history of `H` input differences (`H ≥ d_min + N + 1`).
#[derive(Debug, Clone)]
pub struct Estimator<T, const N: usize, const H: usize> {
    cfg: EstimatorConfig<T>,
    bank: [Candidate<T>; N],
    /// The candidates in use: the first `n` of the bank (`d_max − d_min + 1`
    /// at most).
    n: usize,
    /// The input differences, newest first.
    hist: History<T, H>,
    last_y: T,
    last_dy: T,
    samples: u32,
    /// The costs' weight `W = Σ cost_memory^j` over the samples so far
    /// (`1/(1 − cost_memory)` once the memory is full).
    weight: T,
    chosen: usize,
    challenger_for: u32,
    /// `(K, τ, f)` of the chosen candidate, refreshed when its coefficients
    /// or the choice change (the logarithms are most of an estimate's cost).
    model: Option<(T, T, T)>,
    /// The plausible range of `a` (`0 < a < 1`; with a prior model, time
    /// constants within a factor [`SPAN`] of its).
    a_range: (T, T),
    /// The gain's sign when known (a prior model's), else 0.
    sign: T,
    /// The model in use ([`Estimator::set_reference`]).
    reference: Option<Reference<T>>,
    /// The median of the change detector's error differences `|Δe|` (its
    /// noise level).
    noise: Median<T>,
    /// The chosen candidate's coefficients as they were between one and
    /// two responses' worth of excited samples ago (the older first: the
    /// change detector's model, from before a change), and the excited
    /// samples since the newer was taken.
    snap: [[T; 3]; 2],
    snap_count: usize,
    /// The chosen simulation's last error.
    last_e: T,
    /// The weight of the candidates' `recent` errors.
    recent_weight: T,
    /// Changes of dead time the detector found (see [`Estimator::restarts`]).
    restarts: u32,
    /// Excited samples before the detector may restart the bank again.
    pause: usize,
    /// Samples after an excitation during which the estimator learns: the
    /// longest candidate dead time, and with a prior model four of its
    /// time constants more (the response to a move lasts that long).
    window: usize,
    /// The current block of controller samples: the sums of `y` and `u`,
    /// their count, and whether every one was the process's own response.
    block: (T, T, usize, bool),
    /// Samples of a load's onset still to pass unlearnt (see
    /// `Estimator::onset`).
    skip: usize,
    /// Load onsets found.
    onsets: u32,
}

/// A load's onset: at rest, the chosen model's prediction error exceeds
/// this many times the measured noise (see [`Estimator::onsets`]).
pub const ONSET: f64 = 5.0;

/// The samples of a load's onset that teach nothing (at most `d_min`: the
/// controller's answer reaches the output no sooner).
pub const ONSET_SAMPLES: usize = 4;

/// The change detector restarts the bank only when another dead time's
/// simulation leaves at most this fraction of the chosen one's squared
/// error over the last response, both less the noise's share (see
/// [`Estimator::restarts`]).
pub const EXPLAINED: f64 = 0.25;

/// With a prior model, the time constants an estimate may take lie within
/// this factor of the model's (a plausible range: a process whose lag
/// changed more than that is a different process).
pub const SPAN: f64 = 20.0;

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
            hist: History::new(cfg.prefilter, cfg.min_excitation, cfg.excitation_ratio),
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
            reference: None,
            noise: Median::new(),
            snap: [[a0, T::zero(), T::zero()]; 2],
            snap_count: 0,
            last_e: T::zero(),
            recent_weight: T::zero(),
            restarts: 0,
            pause: 0,
            block: (T::zero(), T::zero(), 0, true),
            skip: 0,
            onsets: 0,
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
        let i = d
            .checked_sub(self.cfg.d_min)
            .filter(|i| *i < self.n)
            .ok_or(Error::OutOfRange(
                "estimator: a dead time among the candidates",
            ))?;
        let ts = self.cfg.ts;
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
        self.model = self.model_of();
        self.set_reference(k, tau, theta)
    }

    /// The whole dead time `d` and the ZOH coefficients `(a, b0, b1)` of
    /// `K e^{−θs}/(τs + 1)` (`tau` infinite: `K e^{−θs}/s`; see the module
    /// documentation).
    fn coefficients(&self, k: T, tau: T, theta: T) -> Result<(usize, [T; 3]), Error> {
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
        let samples = theta / ts + T::of(1e-9);
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
            let a = (-ts / tau).exp();
            let af = a.powf(T::one() - f);
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
        });
        Ok(())
    }

    /// How far the model in use ([`Estimator::set_reference`]) is from the
    /// process, from the costs of the two on the same data (`None` without
    /// a reference, or before it was compared over a whole response's
    /// excited samples): see [`Mismatch`].
    pub fn mismatch(&self) -> Option<Mismatch<T>> {
        let r = self.reference.as_ref().filter(|r| r.seen >= self.window)?;
        self.model?;
        let best = r.rival;
        let excess = r.cost - best;
        Some(Mismatch {
            error: if r.energy > T::zero() {
                (excess.max(T::zero()) / r.energy).sqrt()
            } else {
                T::zero()
            },
            evidence: evidence(best, r.cost, r.weight),
        })
    }

    /// One controller sample: `y` measured now and `u` the input the plant
    /// received in the last period (`u_applied`); `ok` false for a sample
    /// that is not the process's own response (saturated, manual,
    /// tracking, faulted): the history moves on, nothing is learnt from
    /// its block. Returns whether a block of
    /// [`EstimatorConfig::decimation`] samples ended here (the estimator
    /// then took one sample of its own: the block's means).
    pub fn update(&mut self, y: T, u_applied: T, ok: bool) -> bool {
        if !(y.is_finite() && u_applied.is_finite()) {
            return false;
        }
        let (sy, su, n, all) = self.block;
        let n = n + 1;
        if n < self.cfg.decimation {
            self.block = (sy + y, su + u_applied, n, all && ok);
            return false;
        }
        self.block = (T::zero(), T::zero(), 0, true);
        let inv = T::one() / T::of(n as f64);
        self.sample((sy + y) * inv, (su + u_applied) * inv, all && ok);
        true
    }

    /// One estimator sample: the block's mean measurement and input.
    fn sample(&mut self, y: T, u_applied: T, ok: bool) {
        let dy = self.cfg.prefilter * self.last_dy + (y - self.last_y);
        let learn = ok && self.samples >= 2;
        if learn {
            self.learn(dy);
        }
        // the input of the period that just ended joins the history
        self.hist.push(u_applied);
        self.last_y = y;
        self.last_dy = dy;
        self.samples = self.samples.saturating_add(1);
    }

    /// A load's onset, and its samples passing: at rest (no input move
    /// within the response's time, so no candidate's prediction can
    /// change) the chosen candidate's prediction error beyond [`ONSET`]
    /// times the measured noise is a load, not the model's error. Its
    /// first [`ONSET_SAMPLES`] samples teach nothing: an output load's
    /// step is a pulse there in the differences. At the last of them every
    /// simulation (the candidates', the reference's, the detector's) takes
    /// the measured difference as its state: an input load's response
    /// decays from there as the process's own free response, which each
    /// model then predicts with its own pole — the load is part of the
    /// model's initial state, not of its parameters. The output error
    /// model with its state re-estimated at a disturbance's onset
    /// (Ljung (1999) Sec. 4.3: a step disturbance is an initial state;
    /// Åström & Wittenmark (1995) Sec. 11.2: do not adapt on data that do
    /// not carry the process's response). Returns whether this sample is
    /// one of an onset's (not learnt from).
    fn onset(&mut self, target: T) -> bool {
        let cfg = self.cfg;
        if self.skip == 0 {
            let Some(c) = self.bank.get(self.chosen) else {
                return false;
            };
            let d = cfg.d_min + self.chosen;
            let e = target - predict(c.theta, c.yhat, self.hist.pair(d), cfg.integrating);
            let floor = T::epsilon().sqrt() * (T::one() + self.last_y.abs());
            // at rest (no input move within twice the response's time), and
            // the noise measured over as long (the change detector's)
            let rest = self.window.saturating_mul(2);
            let measured = usize::try_from(self.samples).map_or(true, |n| n > rest);
            let threshold = at_least(T::of(ONSET) * self.noise_level(), floor);
            if self.hist.quiet <= rest || !measured || e.abs() <= threshold {
                return false;
            }
            // the controller's answer to it reaches the output a dead time on
            self.skip = ONSET_SAMPLES.min(d).max(1);
            self.onsets = self.onsets.saturating_add(1);
        }
        self.skip -= 1;
        let anchor = self.skip == 0;
        // the simulations go on, and at the onset's end take the measurement
        let inputs = self.hist.from(cfg.d_min);
        let pairs = inputs.iter().zip(inputs.get(1..).unwrap_or_default());
        let [snap, _] = self.snap;
        let bank = self.bank.get_mut(..self.n).unwrap_or_default();
        for (c, (&u0, &u1)) in bank.iter_mut().zip(pairs) {
            if anchor {
                (c.yhat, c.scan) = (target, target);
            } else {
                c.yhat = predict(c.theta, c.yhat, (u0, u1), cfg.integrating);
                c.scan = predict(snap, c.scan, (u0, u1), cfg.integrating);
            }
            c.psi = [T::zero(); 3];
        }
        if let Some(r) = self.reference.as_mut() {
            r.yhat = if anchor {
                target
            } else {
                predict(r.theta, r.yhat, self.hist.pair(r.d), cfg.integrating)
            };
        }
        true
    }

    /// Load onsets found so far: at rest (no input move within twice a
    /// response's time), a prediction error beyond [`ONSET`] times the
    /// measured noise, which no input move can explain; its first
    /// [`ONSET_SAMPLES`] samples teach nothing and every model's
    /// simulation takes the measurement as its state there.
    pub fn onsets(&self) -> u32 {
        self.onsets
    }

    /// The RLS step of every candidate for the new difference `dy`
    /// (`Δy[k+1]`, with the history holding `Δu[k] … `).
    fn learn(&mut self, dy: T) {
        let cfg = self.cfg;
        // the input moved by the gate's amount within the history the
        // candidates read (`Δu[k] … Δu[k−d_max−1]`)
        let excited = self.hist.quiet <= self.window;
        let inv_lam = T::one() / cfg.forgetting;
        // integrating: `Δy[k+1] − Δy[k] = b0·Δu[k−d] + b1·Δu[k−d−1]` (a = 1
        // taken to the left: the regressors are inputs only)
        let target = if cfg.integrating {
            dy - self.last_dy
        } else {
            dy
        };
        if self.onset(target) {
            return;
        }
        let (lo, hi) = self.a_range;
        let sign = self.sign;
        if let Some(r) = self.reference.as_mut() {
            let pred = predict(r.theta, r.yhat, self.hist.pair(r.d), cfg.integrating);
            let e = target - pred;
            r.cost = cfg.cost_memory * r.cost + e * e;
            r.energy = cfg.cost_memory * r.energy + pred * pred;
            r.yhat = pred;
            if excited {
                r.seen = r.seen.saturating_add(1);
            }
        }
        // consecutive candidates share an input: candidate `d`'s
        // `Δu[k−d−1]` is candidate `d + 1`'s `Δu[k−d−1]`
        // the search for the lowest cost (the first of them) rides along
        let inputs = self.hist.from(cfg.d_min);
        let pairs = inputs.iter().zip(inputs.get(1..).unwrap_or_default());
        let chosen = self.chosen;
        let mut chosen_e = T::zero();
        let (mut best, mut lowest) = (0, T::infinity());
        // the dead zone, squared: the given one, or the measured noise's
        // multiple (`|e| ≤ zone` as `e² ≤ zone²`: no square root)
        let zone2 = cfg.dead_zone * cfg.dead_zone;
        let zone2 = if cfg.dead_zone_ratio > T::zero() && self.weight > T::zero() {
            let v = self.bank.get(chosen).map_or(T::zero(), |c| c.cost) / self.weight;
            at_least(cfg.dead_zone_ratio * cfg.dead_zone_ratio * v, zone2)
        } else {
            zone2
        };
        let bank = self.bank.get_mut(..self.n).unwrap_or_default();
        for ((i, c), (&f1, &f2)) in bank.iter_mut().enumerate().zip(pairs) {
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
            if c.cost < lowest {
                (best, lowest) = (i, c.cost);
            }
            if i == chosen {
                chosen_e = e;
            }
            c.yhat = pred;
            // the gradient of the prediction, ψ[k+1] = φ[k] + â·ψ[k] (the
            // output error's Gauss–Newton direction: the recursive
            // prediction-error method, Ljung (1999) Sec. 11.3; an
            // integrating model's prediction is linear in its inputs, ψ = φ)
            let [s0, s1, s2] = if cfg.integrating {
                [f0, f1, f2]
            } else {
                let [p0, p1, p2] = c.psi;
                [f0 + t0 * p0, f1 + t0 * p1, f2 + t0 * p2]
            };
            c.psi = [s0, s1, s2];
            if !excited || e * e <= zone2 {
                continue;
            }
            // RLS with forgetting along ψ (P symmetric: six entries):
            // g = Pψ/(λ + ψᵀPψ), θ += g·e, P = (P − g·(Pψ)ᵀ)/λ
            let [[p00, p01, p02], [_, p11, p12], [_, _, p22]] = c.p;
            let q0 = p00 * s0 + p01 * s1 + p02 * s2;
            let q1 = p01 * s0 + p11 * s1 + p12 * s2;
            let q2 = p02 * s0 + p12 * s1 + p22 * s2;
            let denom = cfg.forgetting + s0 * q0 + s1 * q1 + s2 * q2;
            if !(denom > T::zero()) {
                continue;
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
            let trace = n00 + n11 + n22;
            c.p = [[n00, n01, n02], [n01, n11, n12], [n02, n12, n22]];
            // the trace bounded: no "bursting" when nothing moves
            if trace > cfg.max_trace {
                let k = cfg.max_trace / trace;
                for row in &mut c.p {
                    for x in row {
                        *x = *x * k;
                    }
                }
            }
            if sign != T::zero() {
                // projection: with the gain's sign known, both input
                // coefficients carry it (a fraction `f` in [0, 1]); a
                // coefficient of the wrong sign goes to zero along the
                // covariance's direction (the projection in the metric of
                // P⁻¹: the correlated coefficients move with it; Goodwin &
                // Sin (1984) Sec. 3.7): b0 along P's second column, b1
                // along its third. The second can carry b0 back across
                // zero, and a coefficient without a direction stays: what
                // is left of the wrong sign is cut to zero.
                let [[_, p01, p02], [_, p11, p12], [_, _, p22]] = c.p;
                let [mut t0, mut t1, mut t2] = next;
                if sign * t1 < T::zero() && p11 > T::zero() {
                    let along = t1 / p11;
                    t0 = t0 - p01 * along;
                    t2 = t2 - p12 * along;
                    t1 = T::zero();
                }
                if sign * t2 < T::zero() && p22 > T::zero() {
                    let along = t2 / p22;
                    t0 = t0 - p02 * along;
                    t1 = t1 - p12 * along;
                    t2 = T::zero();
                }
                if sign * t1 < T::zero() {
                    t1 = T::zero();
                }
                if sign * t2 < T::zero() {
                    t2 = T::zero();
                }
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
        self.weight = cfg.cost_memory * self.weight + T::one();
        if let Some(r) = self.reference.as_mut() {
            r.rival = cfg.cost_memory * r.rival + chosen_e * chosen_e;
            r.weight = cfg.cost_memory * r.weight + T::one();
        }
        let before = self.chosen;
        self.detect(target, excited);
        self.decide(best);
        if self.chosen != before {
            self.rebase();
        }
        if excited || self.chosen != before {
            self.model = self.model_of();
        }
    }

    /// The change detector: the chosen candidate's coefficients as they
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
    fn detect(&mut self, target: T, excited: bool) {
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
        self.detect_end(scan);
    }

    /// The detector before its pass over the candidates ([`Scan::step`]):
    /// the chosen dead time's error, the noise.
    fn detect_begin(&mut self, target: T, excited: bool) -> Option<Scan<T>> {
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
        let short = T::one() - T::one() / T::of(self.window.max(1) as f64);
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
        let scale = med * med / T::of(2.0 * 0.6745 * 0.6745);
        if excited {
            self.recent_weight = short * self.recent_weight + T::one();
        }
        Some(Scan {
            coef: [a, b0, b1],
            target,
            e2,
            recent_chosen,
            scale,
            // the noise's share of a recent error
            floor: self.recent_weight * scale,
            short,
            excited,
            chosen,
            evidence: cfg.switch_evidence,
            best: None,
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
    fn rebase(&mut self) {
        let now = self.bank.get(self.chosen).map(|c| c.theta);
        if let Some(now) = now {
            self.snap = [now; 2];
        }
        self.snap_count = 0;
        for c in &mut self.bank {
            c.cusum = T::zero();
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
    fn decide(&mut self, best: usize) {
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
    /// `b0 + b1` of the wrong sign or zero).
    pub fn estimate(&self) -> Option<Estimate<T>> {
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
            theta: (T::of(d as f64) + frac) * self.cfg.period(),
            d,
            evidence: self.evidence(c.cost, second),
        })
    }

    /// `(K, τ, f)` of the chosen candidate's coefficients (`None`: `b0 + b1`
    /// zero), in closed form (see the module documentation).
    fn model_of(&self) -> Option<(T, T, T)> {
        let c = self.bank.get(self.chosen)?;
        let [a, b0, b1] = c.theta;
        let b = b0 + b1;
        if !(b.abs() > T::epsilon()) {
            return None;
        }
        let ts = self.cfg.period();
        Some(if self.cfg.integrating {
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

    /// Each candidate's discounted squared prediction error, from the
    /// shortest dead time `d_min` on: the curve the choice minimises.
    pub fn costs(&self) -> impl Iterator<Item = T> + '_ {
        self.bank.iter().take(self.n).map(|c| c.cost)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::ExpectOk;

    /// A FOPDT process `K e^{−θs}/(τs + 1)` sampled exactly (ZOH, the
    /// fractional delay in `b0`, `b1`) under a PRBS-like input with a load.
    fn run(k: f64, tau: f64, theta: f64, ts: f64, n: usize, noise: f64) -> Estimator<f64, 16, 40> {
        simulate(k, tau, (theta, theta), ts, n, noise, None, |_, _| {})
    }

    /// [`run`] with the dead time `theta.0` for the first half, `theta.1`
    /// after, from a prior model (`Estimator::start_from`) if given, calling
    /// `each` with the sample's index and the estimator after each update.
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        k: f64,
        tau: f64,
        theta: (f64, f64),
        ts: f64,
        n: usize,
        noise: f64,
        prior: Option<(f64, f64, f64)>,
        each: impl FnMut(usize, &Estimator<f64, 16, 40>),
    ) -> Estimator<f64, 16, 40> {
        let cfg = EstimatorConfig::new(ts, 2);
        simulate_with(cfg, k, tau, theta, n, noise, prior, each)
    }

    /// [`simulate`] with the estimator's settings `cfg` (its period the
    /// process's sampling).
    #[allow(clippy::too_many_arguments)]
    fn simulate_with(
        cfg: EstimatorConfig<f64>,
        k: f64,
        tau: f64,
        theta: (f64, f64),
        n: usize,
        noise: f64,
        prior: Option<(f64, f64, f64)>,
        mut each: impl FnMut(usize, &Estimator<f64, 16, 40>),
    ) -> Estimator<f64, 16, 40> {
        let ts = cfg.ts;
        let a = (-ts / tau).exp();
        let parts = |theta: f64| {
            let d = (theta / ts + 1e-9).floor() as usize;
            let f = (theta / ts - d as f64).max(0.0);
            (d, k * (1.0 - a.powf(1.0 - f)), k * (a.powf(1.0 - f) - a))
        };
        let mut est: Estimator<f64, 16, 40> = Estimator::new(cfg).expect_ok();
        if let Some((k, tau, theta)) = prior {
            est.start_from(k, tau, theta).expect_ok();
        }
        let mut u_hist = [0.0f64; 64];
        let mut y = 0.0;
        let mut seed = 99u64;
        let mut u = 0.0;
        for j in 0..n {
            if j % 7 == 0 {
                u = if lcg(&mut seed) >> 63 == 1 { 1.0 } else { -1.0 };
            }
            let load = if j > n / 2 { 0.3 } else { 0.0 };
            let (d, b0, b1) = parts(if j < n / 2 { theta.0 } else { theta.1 });
            // y[j] measured; u applied over [j, j+1)
            let e = noise * (uniform(&mut seed) - 0.5);
            est.update(y + e, u, true);
            each(j, &est);
            u_hist[j % 64] = u;
            let at = |m: usize| if j >= m { u_hist[(j - m) % 64] } else { 0.0 };
            y = a * y + b0 * (at(d) + load) + b1 * (at(d + 1) + load);
        }
        est
    }

    /// `d_max` keeps the choice to the candidates up to it: a process whose
    /// dead time (12 samples) is beyond them gets none past them (what it
    /// gets is a model that cannot be the process's; the supervisor does
    /// not apply an estimate at the end of the range), where the whole
    /// bank finds its own; a `d_max` below `d_min`, or a
    /// prior model beyond it, is an error.
    #[test]
    fn d_max_bounds_the_candidates() {
        let (k, tau, theta, ts) = (1.0, 4.0, 1.25, 0.1);
        let whole = simulate(k, tau, (theta, theta), ts, 8000, 0.0, None, |_, _| {});
        assert_eq!(whole.estimate().expect_ok().d, 12);
        assert_eq!(whole.costs().count(), 16);
        let mut cfg = EstimatorConfig::new(ts, 2);
        cfg.d_max = Some(8);
        let mut longest = 0;
        let est = simulate_with(cfg, k, tau, (theta, theta), 8000, 0.0, None, |_, e| {
            longest = longest.max(e.estimate().map_or(0, |m| m.d));
        });
        assert!(longest <= 8, "{longest}");
        assert_eq!(est.costs().count(), 7);
        let mut est = est;
        assert!(est.start_from(k, tau, 0.85).is_ok());
        assert!(matches!(
            est.start_from(k, tau, 0.95),
            Err(Error::OutOfRange(_))
        ));
        cfg.d_max = Some(1);
        assert!(matches!(
            Estimator::<f64, 16, 40>::new(cfg),
            Err(Error::OutOfRange(_))
        ));
    }

    #[test]
    fn finds_gain_lag_and_fractional_dead_time() {
        for (k, tau, theta) in [(2.0, 4.0, 1.2), (0.5, 10.0, 0.75), (-1.5, 2.0, 1.05)] {
            // the load step halfway is an impulse in the differences: its
            // mark fades with the forgetting's memory (1000 samples)
            let est = run(k, tau, theta, 0.1, 16_000, 0.0);
            let m = est.estimate().expect_ok();
            assert!((m.k - k).abs() < 1e-3 * k.abs(), "{m:?}");
            assert!((m.tau - tau).abs() < 1e-3 * tau, "{m:?}");
            assert!((m.theta - theta).abs() < 0.01, "{m:?}");
        }
    }

    #[test]
    fn small_noise_keeps_the_estimates_close() {
        let est = run(2.0, 4.0, 1.25, 0.1, 20_000, 0.01);
        let m = est.estimate().expect_ok();
        assert_eq!(m.d, 12, "{m:?}");
        assert!(
            (m.k - 2.0).abs() < 0.05 * 2.0 && (m.tau - 4.0).abs() < 0.1 * 4.0,
            "{m:?}"
        );
    }

    /// A dead-time step from 10 to 14 samples: the estimate follows within
    /// a few thousand samples (the costs' memory), once the challenger has
    /// held its lead.
    #[test]
    fn follows_a_dead_time_step() {
        let est = simulate(2.0, 4.0, (1.0, 1.4), 0.1, 12_000, 0.005, None, |_, _| {});
        let m = est.estimate().expect_ok();
        // 14 samples is candidate 14 with no fraction or candidate 13 with a
        // whole one: the same model
        assert!(m.d == 14 || m.d == 13, "{m:?}");
        // the dead time to a sample, the gain within 5 %
        assert!(
            (m.theta - 1.4).abs() < 0.02 && (m.k - 2.0).abs() < 0.1,
            "{m:?}"
        );
    }

    /// A dead-time step from 10 to 14 samples after the estimator has
    /// learnt the process (under a random binary input: every sample
    /// excited): the change detector restarts the bank once, and the
    /// estimate is right within two of the detector's memories (the
    /// learning window, 2 + 16 + 4τ/Ts = 178 samples) and the bank's hold
    /// of the step, where the comparison of the costs alone (2000 samples
    /// of memory, the past to be forgotten) takes about 1900; no restart
    /// before the step.
    #[test]
    fn a_dead_time_step_is_detected_within_a_response() {
        let mut restarts_before = 0;
        let mut right_from = None;
        let est = simulate(
            2.0,
            4.0,
            (1.0, 1.4),
            0.1,
            8_000,
            0.005,
            Some((2.0, 4.0, 1.0)),
            |j, est| {
                if j < 4_000 {
                    restarts_before = est.restarts();
                    return;
                }
                let right = est
                    .estimate()
                    .is_some_and(|m| (m.theta - 1.4).abs() < 0.05 && (m.k - 2.0).abs() < 0.1);
                if !right {
                    right_from = None;
                } else if right_from.is_none() {
                    right_from = Some(j);
                }
            },
        );
        let from = right_from.expect_ok();
        let window = 2 + 16 + 160;
        assert!(from < 4_000 + 2 * window + 50, "right from sample {from}");
        assert_eq!(restarts_before, 0);
        assert_eq!(est.restarts(), 1);
    }

    /// A gain step of 30 % is no dead-time step: no restart.
    #[test]
    fn a_gain_step_restarts_nothing() {
        let mut est: Option<Estimator<f64, 16, 40>> = None;
        simulate(
            2.0,
            4.0,
            (1.0, 1.0),
            0.1,
            4_000,
            0.005,
            Some((1.4, 4.0, 1.0)),
            |_, e| {
                est = Some(e.clone());
            },
        );
        let est = est.expect_ok();
        assert_eq!(est.restarts(), 0);
        let m = est.estimate().expect_ok();
        assert!(
            (m.k - 2.0).abs() < 0.1 && (m.theta - 1.0).abs() < 0.05,
            "{m:?}"
        );
    }

    /// The thesis's integrating benchmark `0.2 e^{−7.45s}/s` at `Ts = 0.1`
    /// (74.5 samples: the half sample in `b0`, `b1`) in closed loop under a
    /// P controller with a dithered set point: the velocity gain and the
    /// dead time, fraction included.
    #[test]
    fn integrating_process_in_closed_loop() {
        let (kv, ts) = (0.2, 0.1);
        let mut cfg = EstimatorConfig::new(ts, 66);
        cfg.integrating = true;
        let mut est: Estimator<f64, 16, 90> = Estimator::new(cfg).expect_ok();
        let (d, f) = (74usize, 0.5);
        let (b0, b1) = (kv * ts * (1.0 - f), kv * ts * f);
        let mut hist = [0.0f64; 128];
        let mut y = 0.0;
        for j in 0..20_000usize {
            let r = if (j / 400) % 2 == 0 { 1.0 } else { -1.0 };
            let u = 0.5 * (r - y);
            est.update(y, u, true);
            hist[j % 128] = u;
            let at = |m: usize| if j >= m { hist[(j - m) % 128] } else { 0.0 };
            y += b0 * at(d) + b1 * at(d + 1);
        }
        let m = est.estimate().expect_ok();
        assert!(m.tau.is_infinite() && (m.k - kv).abs() < 1e-3 * kv, "{m:?}");
        assert!((m.theta - 7.45).abs() < 0.01, "{m:?}");
    }

    /// Closed-loop data in which only the noise moves the input (a P
    /// controller on `e^{−1s}/(4s + 1)` at `Ts = 0.1`, uniform noise of ±1 %
    /// on the measurement, the relative excitation gate off): started from
    /// the true model, the estimate drifts without a dead zone, and stays
    /// within 1 % with one of three times the measured noise — the noise's
    /// errors are inside it.
    #[test]
    fn the_dead_zone_keeps_noise_from_moving_the_estimate() {
        let drift = |ratio: f64| {
            let mut cfg = EstimatorConfig::new(0.1, 4);
            cfg.prefilter = (-0.1f64 / 10.0).exp();
            cfg.excitation_ratio = 0.0;
            cfg.dead_zone_ratio = ratio;
            let mut est: Estimator<f64, 16, 40> = Estimator::new(cfg).expect_ok();
            est.start_from(1.0, 4.0, 1.0).expect_ok();
            let a = (-0.1f64 / 4.0).exp();
            let (mut y, mut line, mut seed) = (0.0f64, [0.0f64; 10], 5u64);
            let mut worst = 0.0f64;
            for k in 0..40_000usize {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let n = 0.02 * (((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5);
                let u = 2.0 * (1.0 - (y + n));
                est.update(y + n, u, true);
                let late = line[k % 10];
                line[k % 10] = u;
                y = a * y + (1.0 - a) * late;
                if k > 1000 {
                    let e = est.estimate().expect_ok();
                    worst = worst.max((e.k - 1.0).abs()).max((e.tau / 4.0 - 1.0).abs());
                }
            }
            worst
        };
        let (without, with) = (drift(0.0), drift(3.0));
        assert!(without > 0.03, "without a dead zone: {without}");
        assert!(with < 0.01, "with one: {with}");
    }

    /// The running median of uniform values on [0, 1) rests, on average,
    /// at their quantile ln 1.01/(ln 1.01 − ln 0.99) ≈ 0.4975, and follows
    /// a change of scale by ten.
    #[test]
    fn the_running_median_rests_at_the_median() {
        let mut m = Median::<f64>::new();
        let mut seed = 7u64;
        let mut uniform = || uniform(&mut seed);
        let q = 1.01f64.ln() / (1.01f64.ln() - 0.99f64.ln());
        // it wanders by about 0.005/√(2·0.01) ≈ 0.035 (a step of 0.005
        // against a pull of 1 % of the distance per sample): its mean over
        // 18 000 samples is within a few thousandths of the quantile
        let mut sum = 0.0;
        for k in 0..20_000 {
            let v = m.push(uniform());
            if k >= 2_000 {
                sum += v;
            }
        }
        let mean = sum / 18_000.0;
        assert!((mean - q).abs() < 0.01, "{mean}");
        // a tenfold level is reached in ln 10/ln 1.01 ≈ 231 samples
        for _ in 0..1_000 {
            m.push(10.0 * uniform());
        }
        let mean = (0..18_000).map(|_| m.push(10.0 * uniform())).sum::<f64>() / 18_000.0;
        assert!((mean - 10.0 * q).abs() < 0.1, "{mean}");
    }

    /// The history's runs against the inputs kept in full: every start
    /// `j`, as the ring wraps, and nothing beyond its `H` entries.
    #[test]
    fn history_reads_the_inputs_newest_first() {
        let mut h = History::<f64, 5>::new(0.0, 0.0, 0.0);
        let mut all = Vec::new();
        for k in 0..13 {
            // u = k²: Δu = 2k − 1 (and 0 for the first)
            let u = f64::from(k * k);
            h.push(u);
            all.push(u - all.iter().sum::<f64>());
            // the history starts full of zeros
            let newest_first: Vec<f64> = all
                .iter()
                .rev()
                .copied()
                .chain(std::iter::repeat(0.0))
                .take(5)
                .collect();
            for j in 0..7 {
                let run: Vec<f64> = h.from(j).to_vec();
                let want: Vec<f64> = newest_first.iter().skip(j).copied().collect();
                assert_eq!(run, want, "after {} inputs, from {j}", k + 1);
            }
        }
    }

    /// The next state of Knuth's MMIX linear congruential generator (the
    /// test inputs' and noise's fixed stream).
    fn lcg(seed: &mut u64) -> u64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *seed
    }

    /// A value of the stream uniform on [0, 1) (its top 53 bits).
    fn uniform(seed: &mut u64) -> f64 {
        (lcg(seed) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// `n` samples `(y measured, u applied)` of `K e^{−d·Ts}/(τs + 1)`
    /// sampled exactly at `ts` (a whole dead time) under a PRBS-like input
    /// held 7 samples, from rest.
    fn fopdt_data(k: f64, tau: f64, d: usize, ts: f64, n: usize) -> Vec<(f64, f64)> {
        let a = (-ts / tau).exp();
        let (mut y, mut u, mut seed) = (0.0, 0.0, 7u64);
        let mut us = vec![0.0; n];
        let mut out = Vec::with_capacity(n);
        for j in 0..n {
            if j % 7 == 0 {
                u = if lcg(&mut seed) >> 63 == 1 { 1.0 } else { -1.0 };
            }
            out.push((y, u));
            us[j] = u;
            let late = if j >= d { us[j - d] } else { 0.0 };
            y = a * y + k * (1.0 - a) * late;
        }
        out
    }

    /// A sample marked not the process's own response (saturated, manual,
    /// tracking, faulted: `ok` false) teaches nothing: after a process was
    /// learnt, 5 000 samples of another (its gain of the other sign, a
    /// tenth of the lag, another dead time) leave every candidate's
    /// coefficients as they were; the same samples marked ok do move them.
    #[test]
    fn samples_not_ok_teach_nothing() {
        let learnt = || {
            let mut est: Estimator<f64, 16, 40> =
                Estimator::new(EstimatorConfig::new(0.1, 2)).expect_ok();
            for (y, u) in fopdt_data(2.0, 4.0, 10, 0.1, 6000) {
                est.update(y, u, true);
            }
            est
        };
        let mut est = learnt();
        let before: Vec<[f64; 3]> = est.bank.iter().map(|c| c.theta).collect();
        let e = est.estimate().expect_ok();
        assert!(
            (e.k - 2.0).abs() < 0.02 && (e.theta - 1.0).abs() < 0.01,
            "{e:?}"
        );
        let other = fopdt_data(-1.0, 0.4, 5, 0.1, 5000);
        for &(y, u) in &other {
            est.update(y, u, false);
        }
        let after: Vec<[f64; 3]> = est.bank.iter().map(|c| c.theta).collect();
        assert_eq!(before, after);
        let mut taught = learnt();
        for &(y, u) in &other {
            taught.update(y, u, true);
        }
        let moved: Vec<[f64; 3]> = taught.bank.iter().map(|c| c.theta).collect();
        assert_ne!(before, moved);
    }

    /// The estimates stay plausible whatever the data say: started from
    /// `e^{−1s}/(4s + 1)` (the gain's sign known, the lag within a factor
    /// [`SPAN`]), data of a process with the gain of the other sign and of
    /// one far faster (`τ = 0.05 s`, below `4/20`) or far slower (`τ =
    /// 400 s`) keep every candidate's `b0`, `b1` of the known sign (the
    /// fraction of the dead time in [0, 1]; after the two projections along
    /// the covariance a coefficient carried back across zero is cut to it)
    /// and `a` in its range, at every sample.
    #[test]
    fn estimates_are_projected_onto_plausible_models() {
        for (k, tau) in [(-1.0, 4.0), (1.0, 0.05), (1.0, 400.0), (-2.0, 0.05)] {
            let mut est: Estimator<f64, 16, 40> =
                Estimator::new(EstimatorConfig::new(0.1, 2)).expect_ok();
            est.start_from(1.0, 4.0, 1.0).expect_ok();
            let (lo, hi) = est.a_range;
            assert!(0.0 < lo && lo < hi && hi < 1.0);
            let (mut lowest_a, mut highest_a) = (f64::INFINITY, 0.0f64);
            for (y, u) in fopdt_data(k, tau, 10, 0.1, 4000) {
                est.update(y, u, true);
                for c in &est.bank {
                    let [a, b0, b1] = c.theta;
                    assert!(b0 >= 0.0 && b1 >= 0.0, "k {k}, tau {tau}: {:?}", c.theta);
                    assert!((lo..=hi).contains(&a), "k {k}, tau {tau}: {a}");
                    (lowest_a, highest_a) = (lowest_a.min(a), highest_a.max(a));
                }
                if let Some(e) = est.estimate() {
                    assert!(e.k > 0.0 && e.tau > 0.0, "{e:?}");
                    let f = e.theta / 0.1 - e.d as f64;
                    assert!((-1e-9..=1.0 + 1e-9).contains(&f), "{e:?}");
                }
            }
            // the fast process's data pushed `a` against its lower bound
            // (the slow one's move it up only slowly: within the range)
            if tau < 1.0 {
                assert_eq!(lowest_a, lo);
            }
            assert!(highest_a <= hi);
        }
    }

    /// Closed-loop data in which, after one set-point step, only loads move
    /// the loop: `K e^{−θs}/(τs + 1)` sampled exactly under a PI
    /// controller, input and output load steps at rest, uniform noise of
    /// ±`noise` on the measurement, for stable processes of several gains
    /// (of both signs), lags and dead times, some decimated. Started from
    /// the true model: without noise every load is found as an onset and
    /// the estimate stays the process's (exactly, or within 2 % when
    /// decimated; the dead time to a sample throughout); with noise the estimate never beats the true
    /// model by the evidence the supervisor asks. Without the onsets an
    /// output load's pulse, answered by the controller, was read as the
    /// process's response.
    #[test]
    fn loads_at_rest_are_onsets_not_lessons() {
        for (k, tau, d, decimation, noise) in [
            (1.6, 10.0, 12usize, 1usize, 0.0),
            (1.6, 10.0, 12, 1, 0.005),
            (2.3, 15.0, 16, 5, 0.0),
            (2.3, 15.0, 16, 5, 0.01),
            (0.7, 3.0, 10, 2, 0.0),
            (-1.2, 6.0, 8, 3, 0.005),
        ] {
            let ts = 0.5 / decimation as f64;
            let dd = d * decimation;
            let mut cfg = EstimatorConfig::new(ts, 2);
            cfg.decimation = decimation;
            let mut est: Estimator<f64, 16, 40> = Estimator::new(cfg).expect_ok();
            est.start_from(k, tau, d as f64 * 0.5).expect_ok();
            let a = (-ts / tau).exp();
            let (kp, ki) = (0.4 / k, 0.4 / k * ts / tau);
            let (mut y, mut integral, mut seed) = (0.0f64, 0.0f64, 11u64);
            let mut line = std::vec![0.0f64; dd];
            let n = 8000 * decimation;
            let loads = [(2000, 0.2, 0.0), (4000, 0.0, 0.3), (6000, -0.15, 0.0)];
            let (mut worst, mut evidence) = (0.0f64, f64::NEG_INFINITY);
            for j in 0..n {
                let at = |s: usize| j >= s * decimation;
                let d_in: f64 = loads.iter().filter(|l| at(l.0)).map(|l| l.1).sum();
                let d_out: f64 = loads.iter().filter(|l| at(l.0)).map(|l| l.2).sum();
                let meas = y + d_out + noise * (2.0 * uniform(&mut seed) - 1.0);
                let e = 1.0 - meas;
                integral += ki * e;
                let u = kp * e + integral;
                est.update(meas, u, true);
                if j > 1000 * decimation {
                    let m = est.estimate().expect_ok();
                    worst = worst
                        .max((m.k / k - 1.0).abs())
                        .max((m.tau / tau - 1.0).abs());
                    assert!((m.theta - d as f64 * 0.5).abs() <= 0.5, "{m:?}");
                    if let Some(mm) = est.mismatch() {
                        evidence = evidence.max(mm.evidence);
                    }
                }
                let late = line[j % dd];
                line[j % dd] = u + d_in;
                y = a * y + k * (1.0 - a) * late;
            }
            let case = (k, tau, d, decimation, noise);
            if noise == 0.0 {
                // every load found, and the process's model kept: exactly
                // at the controller's period; decimated, within the block
                // means' own departure from the model (their aliasing: a
                // percent or two, below any change the supervisor applies)
                assert_eq!(est.onsets(), 3, "{case:?}");
                let tol = if decimation == 1 { 1e-6 } else { 0.02 };
                assert!(worst < tol, "{case:?}: {worst}");
            } else {
                // under noise a single load's response moves the estimate
                // (its variance), never by evidence that it beats the
                // true model (what the supervisor asks before applying)
                let need = crate::adapt::AdaptiveConfig::new(cfg).validate;
                assert!(evidence < need, "{case:?}: {evidence}");
            }
        }
    }

    #[test]
    fn nothing_moves_nothing_learnt() {
        let mut est: Estimator<f64, 8, 16> =
            Estimator::new(EstimatorConfig::new(0.1, 1)).expect_ok();
        for _ in 0..100_000 {
            est.update(0.5, 0.2, true);
        }
        assert!(est.estimate().is_none());
        assert!(est.trace() <= 1e4 * (1.0 + 1e-9));
    }
}
