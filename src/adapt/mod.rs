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
//! (1993)). The same test on the model in use with its gain or its lag
//! changed names a gain's or a lag's error for the model-error alarm, and
//! a hypothesis that explains the last response with the evidence is
//! proposed to the supervisor: a loop that only loads move shows a change
//! in a few responses, from which the bank, with its long memory, would
//! take tens (see `hypotheses.rs`). An update is skipped when
//! the input has not moved clearly more than its own jitter within the
//! response's time (the excitation gate: in closed loop the noise moves the
//! input too, and data in which only the noise does identify the
//! controller as much as the process, Ljung (1999) Sec. 13.4; the bank's
//! own steps also wait for the input to depart from its drift: the
//! controller's steady answer to a ramp load, which the models would
//! explain with a gain pulled towards zero, teaches it nothing), when the
//! prediction error is within the dead zone of the noise, or when the
//! caller says the sample is not the process's own response (saturated,
//! manual, tracking, a fault).
//!
//! Where nothing moves, little runs: while the input is still for a
//! response's time the bank rests (only the chosen candidate's simulation,
//! the comparison with the model in use and the noise's measure; every
//! candidate pays the chosen one's error through one shared discount and
//! sum, see [`Estimator::is_resting`]), and while the model in use fits
//! the last response the candidates away from the chosen dead time learn in
//! turn ([`TURNS`]).

use crate::real::{at_least, at_most, near};
use crate::{error::Error, real::Real};

mod config;
mod detect;
mod estimator;
mod growth;
mod history;
mod hypotheses;
mod levels;
mod onset;
mod pass;
mod rest;
use levels::Levels;
pub use levels::{DRIFT, LEVEL_EVIDENCE, PARTIAL, REPLICATED, WATCH_DRIFT, WATCH_LIMIT};
use pass::{Pass, PARTS};
mod supervisor;
#[cfg(test)]
mod tests;

pub use config::EstimatorConfig;
pub(crate) use history::{History, Median};
pub use supervisor::{
    Adaptive, AdaptiveConfig, AdaptiveState, Change, ChangeKind, Rebuild, Redesign, SIGNALS,
};

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
    /// The cost, energy, rival cost and weight over the last response's
    /// excited samples ([`Estimator::recent_mismatch`]).
    recent: [T; 4],
    /// Its error's peaks window by window (`growth.rs`).
    growth: growth::Growth<T>,
}

/// The comparison of the model in use (cost `cost`, its prediction's
/// energy `energy`) with the best other (`best`) over costs of weight
/// `weight` (see [`Mismatch`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Costs<T> {
    cost: T,
    energy: T,
    best: T,
    weight: T,
}

impl<T: Real> Costs<T> {
    /// The [`Mismatch`] these costs give.
    pub(crate) fn mismatch(self) -> Mismatch<T> {
        let Costs {
            cost,
            energy,
            best,
            weight,
        } = self;
        Mismatch {
            error: if energy > T::zero() {
                (at_least(cost - best, T::zero()) / energy).sqrt()
            } else {
                T::zero()
            },
            evidence: evidence(best, cost, weight),
        }
    }

    /// The [`Mismatch`]'s error is at least `x` (≥ 0), without its square
    /// root and division (the alarm asks every estimator sample):
    /// `max(cost − best, 0) ≥ x²·energy`.
    pub(crate) fn error_reaches(self, x: T) -> bool {
        if self.energy > T::zero() {
            at_least(self.cost - self.best, T::zero()) >= x * x * self.energy
        } else {
            x <= T::zero()
        }
    }

    /// The [`Mismatch`]'s evidence is at least `x`, without its division:
    /// `(cost − best)·W ≥ x·best` (see [`Estimate::evidence`]).
    pub(crate) fn evidence_reaches(self, x: T) -> bool {
        let Costs {
            cost, best, weight, ..
        } = self;
        if weight > T::zero() && best / weight > T::zero() {
            (cost - best) * weight >= x * best
        } else {
            cost > best || x <= T::zero()
        }
    }
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
    /// The weight of the candidates' `recent` errors, and the least of
    /// them (kept by the detector's pass, the only one that moves them: the
    /// model-error alarm reads it every estimator sample).
    recent_weight: T,
    recent_least: T,
    /// Changes of dead time the detector found (see [`Estimator::restarts`]).
    restarts: u32,

    /// Excited samples before the detector may restart the bank again.
    pause: usize,
    /// Samples after an excitation during which the estimator learns: the
    /// longest candidate dead time, and with a prior model four of its
    /// time constants more (the response to a move lasts that long).
    window: usize,
    /// Samples without an input move after which the estimator rests: the
    /// window, or the longest dead time and four of the chosen model's
    /// time constants where that is longer (see `rest.rs`).
    rest_after: usize,
    /// The recent comparisons' memory per excited sample, `1 − 1/window`
    /// (the change detector's and the alarm's).
    short: T,
    /// The current block of controller samples: the sums of `y` and `u`,
    /// their count, and whether every one was the process's own response.
    block: (T, T, usize, bool),
    /// The current block's sum of the input's partial sums `Σ_p Σ_{i<p} u_i`
    /// (the triangle's falling side, `Estimator::update`).
    partial: T,
    /// The block before's input triangle's rising side `Σ_p (p + 1)·u_p`,
    /// and whether every sample was the process's own.
    before: Option<(T, bool)>,
    /// Samples of a load's onset still to pass unlearnt (see
    /// `Estimator::onset`).
    skip: usize,
    /// An onset's samples taken into the models' state, and its samples
    /// seen.
    settled: (u32, u32),
    /// Load onsets found.
    onsets: u32,
    /// The chosen candidate's error magnitude at the last of an onset's
    /// samples (a new load among them starts them again).
    onset_error: T,
    /// A block's learning under way (see `Estimator::advance`).
    pending: Option<Pass<T>>,
    /// The estimate as of the last pass's end ([`Estimator::estimate`]).
    current: Option<Estimate<T>>,
    /// At rest (see `rest.rs`): only the chosen candidate's simulation
    /// runs, and every candidate's cost is `g·V + s` with the shared
    /// discount and sum `rest = (g, s)`, applied when the input moves.
    resting: bool,
    rest: (T, T),
    /// The model in use with other gains and lags, at its dead time
    /// ([`HYPOTHESES`]; see `hypotheses.rs`): what the model-error alarm
    /// compares the model in use with besides the other dead times, and
    /// what the supervisor may apply ([`Estimator::proposal`]).
    hyp: [Hypothesis<T>; HYPOTHESES],
    /// The gain hypotheses are [`FINE_GAINS`] (a gain hypothesis is the
    /// model in use: [`Estimator::refine`]).
    fine: bool,
    /// The hypothesis that passes the proposal's test, as of the last
    /// excited sample, and for how many excited samples in a row it has.
    proposal: Option<usize>,
    proposal_for: usize,
    /// The hypothesis that explains most of the model in use's recent
    /// error, as of the last excited sample (the model-error alarm's).
    explaining: Option<usize>,
    /// The model in use fits the last response (see [`TURNS`]), and the
    /// excited samples so far, whose count takes the candidates in turn.
    fits: bool,
    turn: usize,
    /// The samples the chosen candidate learnt from so far (wrapping).
    learnt: u32,
    /// The target's energy over the last response (as `recent_weight`):
    /// what a [`MATERIAL`] error is measured against.
    energy: T,
    /// The level test over each load's response (see `levels.rs`).
    levels: Levels<T>,
}

/// One of the change detector's hypotheses about the process's gain or
/// lag: the model in use with its gain or its lag times a factor
/// ([`GAINS`], [`LAGS`]), simulated at its dead time.
#[derive(Debug, Clone, Copy)]
struct Hypothesis<T> {
    coef: [T; 3],
    /// Its simulated output `Δŷ[k]`, Page's sum of the evidence for it
    /// against the model in use, and its squared error over about the last
    /// response (as a candidate's `scan`, `cusum` and `recent`).
    yhat: T,
    cusum: T,
    recent: T,
}

/// The gain factors the change detector simulates: a process whose gain
/// went to 0.7 or 1.3 times the model's is explained by one of them to
/// within a quarter of the model's error ([`EXPLAINED`]).
pub const GAINS: [f64; 4] = [0.5, 0.7, 1.4, 2.0];

/// The gain factors the change detector simulates while a gain
/// hypothesis is the model in use: the square roots of [`GAINS`]. A gain
/// between two of them (0.6 times the model's) is named first by the
/// nearer (0.7), which leaves a factor within `√2` of one (0.6/0.7 ≈ 0.86)
/// that none of [`GAINS`] explains to within [`EXPLAINED`]; one of these
/// does (√0.7 ≈ 0.84).
pub const FINE_GAINS: [f64; 4] = [
    core::f64::consts::FRAC_1_SQRT_2,
    0.836_660_026_534_075_6,
    1.183_215_956_619_923_2,
    core::f64::consts::SQRT_2,
];

/// The lag factors the change detector simulates (a stable process's):
/// the time constant times 1/2, 2/3, 4/3, 2, whose coefficients `a^{1/l}`
/// are squares and square roots of the model's (no logarithm in a
/// microcontroller's longest call).
pub const LAGS: [f64; 4] = [0.5, 2.0 / 3.0, 4.0 / 3.0, 2.0];

/// The change detector's gain and lag hypotheses.
pub const HYPOTHESES: usize = GAINS.len() + LAGS.len();

/// While the model in use fits the last response (its error within
/// [`MATERIAL`] of the response), a candidate other than the chosen dead
/// time and its two neighbours learns on every `TURNS`th excited sample, in
/// turn; otherwise every candidate learns on every one. Each candidate's
/// equations hold sample by sample, so one updated on a fraction of them
/// converges to the same coefficients (its forgetting's memory longer in
/// time). The far candidates matter when the process has changed much,
/// and then the model in use no longer fits and all learn alike: their
/// costs compare models fitted alike (measured: with the far candidates
/// learning in turn throughout, an integrating loop's growing oscillation
/// after its dead time rose 60 % let the oscillation's alias, a dead time
/// one period shorter and learnt more often, win the emergency). While it
/// fits, the chosen dead time and its neighbours, which a drift reaches
/// first, learn on every sample. A pass's RLS steps fall from `N` to about
/// `3 + N/TURNS` in normal operation, most of the estimator's arithmetic
/// (#48 item 7: host cost).
pub const TURNS: usize = 4;

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

/// The model in use fits the last response (the far candidates learn in
/// turn, [`TURNS`]) while the chosen simulation's squared error over it,
/// less the noise's share, is below this fraction squared of the target's
/// energy over it: a model error of 10 % of the response, not the block
/// means' departure from the model (a percent or two) that noise-free data
/// make significant. (A hypothesis's proposal is not held to it: see
/// `Estimator::test_hypotheses`.)
pub const MATERIAL: f64 = 0.1;

/// With a prior model, the time constants an estimate may take lie within
/// this factor of the model's (a plausible range: a process whose lag
/// changed more than that is a different process).
pub const SPAN: f64 = 20.0;

/// How far a settle block's estimates may spread, lowest to highest, in
/// units of `min_change` ([`AdaptiveConfig::min_change`]), for the block
/// to count as still; two still blocks in a row must then have means
/// within half of `min_change` (the later one is applied), or within
/// `min_change` and within half of either block's spread, where the
/// estimate wanders about them rather than moves (a trend moves a block's
/// mean from the last one's by about the block's own spread): then their
/// midpoint is applied, within half of `min_change` of each. The means'
/// agreement is the convergence test: a block's spread under measurement
/// noise is its samples', wider than its mean's by the square root of the
/// samples it averages. Measured on the bank (`docs/adapt-bank.md`): a
/// spread of one `min_change` held 37 of 108 changes at the coarse period
/// under 5 % noise more than 10 % from the true model's loop, most of them
/// held back (a converged estimate whose samples wander by more); four
/// left 15; with the means held to half of `min_change` alone, 6 (the
/// means of a converged estimate wandering by more); with the midpoint of
/// wandering means, 3. The midpoint without the spread's test applied a
/// gain still converging after a dead-time step, 8 % short of the
/// process's, and left it (`tests/adapt.rs`). The families where nothing
/// changes apply nothing either way.
pub const SPREAD: f64 = 4.0;
