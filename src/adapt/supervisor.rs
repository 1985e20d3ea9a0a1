//! The supervisor of adaptive dead-time compensation: an [`Estimator`]
//! beside a scheme with a model, and the rules that decide when its
//! estimate becomes the scheme's model.
//!
//! Each sample the estimator learns from the measurement and the input the
//! plant received; the supervisor applies a new model only when
//!
//! - the estimate has settled: taken in blocks of `settle` samples, it held
//!   still in two blocks in a row (in each, one whole dead time and the gain
//!   and the time constant within [`SPREAD`] times `min_change` of their
//!   mean from lowest to highest) whose means agree within half of
//!   `min_change` (half a sample for the dead time) — the later block's
//!   mean is applied — or within `min_change` and half of either block's
//!   spread (the estimate wanders about them: [`SPREAD`]) — their midpoint
//!   is applied; every
//!   sample's estimate counts only with its gain of the known sign, and
//!   its dead time only where chosen without ambiguity (its evidence over
//!   the candidates that are not its neighbours at least `min_evidence`,
//!   [`Estimate::evidence`]) or, when it is no neighbour of the model's,
//!   with that evidence over the model's own: otherwise the model's dead
//!   time stands in (a switch of dead time waits for evidence; the gain
//!   and the lag do not);
//! - it differs enough from the model in use: the gain or the time constant
//!   by `min_change` (relative), or the dead time by half a sample;
//! - it predicts the data since the model in use was set better than that
//!   model, with the evidence of `validate`, or, where the differences
//!   cannot tell yet, the level test weighed it so over the responses
//!   since (its challenger, with the evidence it asks of a hypothesis);
//! - `min_interval` samples have passed since the last change.
//!
//! A change moves the gain and the time constant by at most a factor
//! `max_step` (a larger difference takes several changes), through the
//! scheme's own run-time operations: [`Operate::set_model`] (the model's
//! output continues: no jump), [`Operate::set_dead_time`], and the primary
//! retuned by the caller's rule ([`Redesign::gains`], bumpless through
//! [`Operate::retune`]); a scheme whose other blocks are designed from its
//! model is rebuilt for the new one ([`Redesign::rebuild`]) and takes over
//! after warming up beside the one in use. After a change the error is watched for
//! `watch` samples: `crossings` consecutive short half-cycles of the
//! error, each reaching the band `±band` (at least four times the measured
//! noise) and keeping half the previous one's peak (an oscillation that
//! does not die out, after Hägglund (1995)'s detector, which counts the
//! error's excursions between zero crossings) restore the last good model
//! and its tuning, and
//! adaptation rests for `4·min_interval` samples. Adaptation can be frozen
//! and resumed; every change is logged (the last `L`). Supervision of this
//! kind — adapt only on information, keep a fall-back — is Åström &
//! Wittenmark (1995) Sec. 11.2.

use super::{Estimate, Estimator, SPREAD};
use crate::operate::{Gain, Operate, Tracking};
use crate::real::{at_least, at_most, near};
use crate::{
    controller::CascadeControl, controller::Controller, controller::FrequencyResponse,
    controller::Introspect, error::Error, real::Real,
};

mod block;
mod config;
mod design;
mod log;
mod proposals;
mod redesign;
mod sample;
mod slots;
mod swing;
mod traits;
mod watch;

pub use crate::operate::{AdaptiveState, Change, ChangeKind};
use block::{settled, Block, Still};
pub use config::AdaptiveConfig;
pub use log::SIGNALS;
pub use redesign::{Rebuild, Redesign};
use slots::Slots;

/// A rebuilt scheme warming up beside the one in use (in the spare place
/// of [`Slots`]).
#[derive(Debug, Clone, Copy)]
struct Shadow<T> {
    model: Model<T>,
    /// Samples until it takes over.
    left: u32,
    /// What its taking over is logged as.
    kind: ChangeKind,
}

/// A model `(K, τ, θ)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Model<T> {
    k: T,
    tau: T,
    theta: T,
}

impl<T: Copy> From<Estimate<T>> for Model<T> {
    fn from(m: Estimate<T>) -> Self {
        Model {
            k: m.k,
            tau: m.tau,
            theta: m.theta,
        }
    }
}

/// A scheme with a model, kept right by on-line identification (see the
/// module documentation): `N` candidate dead times over a history of `H`
/// inputs, a log of the last `L` changes.
///
/// A Smith predictor built for `e^{−1s}/(4s + 1)` at `Ts = 0.1 s` whose
/// process's lag doubles: with set-point changes for excitation, the model
/// in use becomes the process's, and the log says when (and when the
/// model-error alarm rose).
///
/// ```
/// use msp::adapt::{Adaptive, AdaptiveConfig, ChangeKind, EstimatorConfig};
/// use msp::{tuning, Controller, Fopdt, ProcessModel, SmithPredictor};
/// let ts = 0.1f32;
/// let model = ProcessModel::from(Fopdt::new(1.0f32, 4.0, 1.0)?);
/// let sp: SmithPredictor<f32, 1, [f32; 64]> =
///     SmithPredictor::from_model(tuning::kaya(&model, 2.0)?.config(ts), &model, ts)?;
/// let est = EstimatorConfig::new(ts, 0); // candidates 0 … 15 samples
/// let mut c: Adaptive<f32, _, _, 16, 32> =
///     Adaptive::new(sp, (1.0, 4.0, 1.0), AdaptiveConfig::new(est), ())?;
/// // the process e^{−1s}/(8s + 1), sampled exactly, 10 samples of dead time
/// let a = (-0.1f32 / 8.0).exp();
/// let (mut y, mut line) = (0.0f32, [0.0f32; 10]);
/// for k in 0..9000 {
///     let r = if (k / 300) % 2 == 0 { 1.0 } else { 0.0 };
///     let u = c.update(r, y);
///     let late = line[k % 10];
///     line[k % 10] = u;
///     y = a * y + (1.0 - a) * late;
/// }
/// let (k, tau, theta) = c.model();
/// assert!((k - 1.0).abs() < 0.05 && (tau - 8.0).abs() < 0.8 && (theta - 1.0).abs() < 0.1);
/// // the log: the model-error alarm raised when the lag doubled, the new
/// // model applied, the alarm cleared
/// let kinds: Vec<ChangeKind> = c.log().map(|l| l.kind).collect();
/// assert_eq!(kinds.first(), Some(&ChangeKind::Alarm));
/// assert!(kinds.contains(&ChangeKind::Applied));
/// # Ok::<(), msp::Error>(())
/// ```
// (fields in the order of use: those every sample reads first, then the
// scheme and the estimator, the rest after them; a Cortex-M4F's
// floating-point loads reach 1 020 bytes from a base, #48 item 7)
#[derive(Debug, Clone)]
#[repr(C)]
pub struct Adaptive<T, C, R, const N: usize, const H: usize, const L: usize = 16> {
    /// The estimator's reference is to follow the model in use before its
    /// next sample: a model applied in a call that ended an estimator
    /// sample sets it there, its coefficients and hypotheses computed in
    /// the next call (a Cortex-M4F's longest call, #48 item 7).
    refer: bool,
    /// A change decided at the end of an estimator sample's learning,
    /// taken in the next call without the estimator's work (a Cortex-M4F's
    /// longest call, #48 item 7: the choice, the supervisor's decision and
    /// the scheme's redesign had been one call).
    deferred: Option<(Model<T>, ChangeKind)>,
    /// The last measurement, for the estimator once its input is known.
    pending: Option<T>,
    ok: bool,
    frozen: bool,
    last_u: T,
    /// The last set point, and whether it moved in the current block (a
    /// set-point move starts a transient, not a half-cycle of an
    /// oscillation).
    r_last: T,
    r_moved: bool,
    /// The control error's sum over the current block, and its count.
    err: T,
    err_n: u32,
    /// Controller samples so far.
    samples: u64,
    /// The coming calls that only add their sample to the estimator's
    /// block (`Adaptive::calm_step`).
    calm: usize,
    logged: usize,
    /// A rebuilt scheme warming up to take over.
    shadow: Option<Shadow<T>>,
    /// A model whose scheme is to be rebuilt by [`Adaptive::design`]
    /// ([`AdaptiveConfig::background_design`]), and what its taking over is
    /// logged as.
    waiting: Option<(Model<T>, ChangeKind)>,
    /// The scheme in use, and a rebuilt one warming up (`shadow`).
    inner: Slots<C>,
    est: Estimator<T, N, H>,
    cfg: AdaptiveConfig<T>,
    retune: R,
    /// The model in use (set by `use_model`), and its dead time in whole
    /// estimator samples (`proposals::whole_samples`).
    model: Model<T>,
    model_d: Option<usize>,
    /// The commissioned model (the bounds' centre) and the last validated
    /// one (what an oscillation after a change restores).
    commissioned: Model<T>,
    validated: Model<T>,
    /// `1/bound` ([`AdaptiveConfig::bound`]), asked at every block.
    inv_bound: T,
    /// Estimator samples so far.
    blocks: u64,
    /// Half-cycles of a growing oscillation in a row (the emergency path).
    growing: u32,
    /// The factor on the rule's gain after detuning (1: none).
    detune: T,
    /// An edge warning was logged for the estimate as it stands.
    edge_warned: bool,
    /// The model in use is a change detector's hypothesis
    /// ([`Adaptive::propose`]), and which parameter it moved: the bank's
    /// settled estimate replaces it when it differs by a quarter of
    /// `min_change`.
    provisional: Option<proposals::Moved>,
    /// The statistics of the current block of `settle` samples.
    block: Block<T>,
    /// The last complete block's mean, when the estimate held still in it.
    settled: Option<Still<T>>,
    since: u32,
    /// The estimator's learnt samples when the model in use was set.
    learnt_from: u32,
    /// The level test's last dead-time move: the dead time before it and
    /// after it (s).
    dead_moved: Option<(T, T)>,
    rest_until: u64,
    log: [Option<Change<T>>; L],
    watching: u32,
    side: i8,
    crossed: u32,
    /// The current half-cycle of the error: its length and its peak; the
    /// peak of the one before.
    half: u32,
    peak: T,
    last_peak: T,
    /// The error's swings about its level (`swing.rs`), counted once the
    /// error held its sign for longer than a half-cycle can last.
    swing: swing::Swing<T>,
    /// The model-error alarm, and for how many samples its condition has
    /// held against its state.
    alarm: bool,
    alarm_for: u32,
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Adaptive<T, C, R, N, H, L>
{
    /// `inner` built for the model `K e^{−θs}/(τs + 1)` (`tau` infinite:
    /// `K e^{−θs}/s`), adapted as `cfg` says, its primary retuned by
    /// `retune` at each change (`()`: the gains stay).
    pub fn new(
        inner: C,
        (k, tau, theta): (T, T, T),
        cfg: AdaptiveConfig<T>,
        retune: R,
    ) -> Result<Self, Error> {
        crate::real::finite(k, "k")?;
        if k == T::zero() {
            return Err(Error::OutOfRange("k: not zero"));
        }
        if !(tau > T::zero()) {
            return Err(Error::OutOfRange("tau: positive (infinite: integrating)"));
        }
        crate::real::non_negative(theta, "theta")?;
        cfg.validate()?;
        let model = Model { k, tau, theta };
        let mut est = Estimator::new(cfg.estimator)?;
        // the estimator starts from the model (its dead time the choice
        // until evidence says otherwise)
        est.start_from(k, tau, theta)?;
        Ok(Adaptive {
            inner: Slots::new(inner),
            est,
            cfg,
            retune,
            model,
            model_d: proposals::whole_samples(&cfg.estimator, theta),
            commissioned: model,
            validated: model,
            inv_bound: T::one() / cfg.bound,
            blocks: 0,
            err: T::zero(),
            err_n: 0,
            growing: 0,
            r_last: T::zero(),
            r_moved: false,
            detune: T::one(),
            edge_warned: false,
            provisional: None,
            block: Block::default(),
            settled: None,
            since: 0,
            learnt_from: 0,
            dead_moved: None,
            samples: 0,
            calm: 0,
            frozen: false,
            rest_until: 0,
            log: [None; L],
            logged: 0,
            last_u: T::zero(),
            ok: false,
            pending: None,
            refer: false,
            deferred: None,
            watching: 0,
            side: 0,
            crossed: 0,
            half: 0,
            peak: T::zero(),
            last_peak: T::zero(),
            swing: swing::Swing::new(watch::longest_half(cfg.estimator.d_min, N)),
            alarm: false,
            alarm_for: 0,
            shadow: None,
            waiting: None,
        })
    }

    /// The scheme inside.
    pub fn inner(&self) -> &C {
        &self.inner
    }

    /// The redesign it asks for the primary's gains or a scheme anew.
    pub fn redesign(&self) -> &R {
        &self.retune
    }

    /// The estimator's current model (`None` before it means anything).
    pub fn estimate(&self) -> Option<Estimate<T>> {
        self.est.estimate()
    }

    /// The estimator.
    pub fn estimator(&self) -> &Estimator<T, N, H> {
        &self.est
    }

    /// The model in use: `(K, τ, θ)`.
    pub fn model(&self) -> (T, T, T) {
        (self.model.k, self.model.tau, self.model.theta)
    }

    /// The model a restore returns to, `(K, τ, θ)`: the last validated
    /// one (watched to the end without an oscillation, and predicting as
    /// well as the estimate or confirmed by it), else the commissioned one.
    pub fn validated(&self) -> (T, T, T) {
        let m = self.validated;
        (m.k, m.tau, m.theta)
    }

    /// Stops adapting: nothing is learnt or applied until [`Self::resume`]
    /// — but a change decided before the freeze and waiting for a call
    /// without the estimator's work (decimation ≥ 7) is still put in, within
    /// the block (a restore after an oscillation must not be lost).
    pub fn freeze(&mut self) {
        self.frozen = true;
    }

    /// Adapts again.
    pub fn resume(&mut self) {
        self.frozen = false;
    }

    /// Adaptation is frozen.
    pub fn is_frozen(&self) -> bool {
        self.frozen
    }

    /// How many changes were logged in all (the log keeps the last `L`).
    pub fn changes(&self) -> usize {
        self.logged
    }

    /// The logged changes, oldest first (the last `L`).
    pub fn log(&self) -> impl Iterator<Item = Change<T>> + '_ {
        let start = self.logged.saturating_sub(L);
        (start..self.logged).filter_map(move |i| self.log.get(i % L.max(1)).copied().flatten())
    }

    /// The model in use is `m` (its dead time in estimator samples beside it).
    pub(super) fn use_model(&mut self, m: Model<T>) {
        self.model = m;
        self.model_d = proposals::whole_samples(&self.cfg.estimator, m.theta);
    }

    /// After a change took effect: the interval starts again, and after an
    /// applied one the watch for oscillation.
    fn changed(&mut self, kind: ChangeKind) {
        self.since = 0;
        self.learnt_from = self.est.learnt();
        self.settled = None;
        self.block = Block::default();
        if matches!(kind, ChangeKind::Applied | ChangeKind::Emergency) {
            self.watching = self.cfg.watch;
            self.crossed = 0;
            self.growing = 0;
            self.side = 0;
            self.half = 0;
            self.peak = T::zero();
            self.last_peak = T::zero();
        }
    }

    fn record(&mut self, kind: ChangeKind) {
        let m = self.model;
        self.record_model(kind, m);
    }

    fn record_model(&mut self, kind: ChangeKind, m: Model<T>) {
        if let Some(slot) = self.log.get_mut(self.logged % L.max(1)) {
            *slot = Some(Change {
                sample: self.samples,
                kind,
                k: m.k,
                tau: m.tau,
                theta: m.theta,
            });
        }
        self.logged = self.logged.saturating_add(1);
    }

    /// The model `m` into the scheme: its delay-free part, its dead time,
    /// the primary's gains (`Ok(true)`); or a scheme whose blocks are
    /// designed from its model rebuilt for it, warming up to take over
    /// (`Ok(false)`, logged as `kind` when it does).
    fn put(&mut self, m: Model<T>, kind: ChangeKind) -> Result<bool, Error> {
        let ts = self.cfg.estimator.ts;
        match self.inner.set_model(m.k, m.tau) {
            Ok(()) => {}
            Err(Error::Unsupported(why)) => {
                // the one warming up (if any) goes before its successor is built
                self.shadow = None;
                if self.cfg.background_design {
                    self.waiting = Some((m, kind));
                    return Ok(false);
                }
                return self.rebuild(m, kind, why).map(|()| false);
            }
            Err(e) => return Err(e),
        }
        self.inner.set_dead_time(m.theta / ts)?;
        if let Some([kp, ti, td]) = self.retune.gains(m.k, m.tau, m.theta) {
            self.inner.retune(Gain::Kp, kp)?;
            self.inner.retune(Gain::Ti, ti)?;
            self.inner.retune(Gain::Td, td)?;
        }
        self.use_model(m);
        // the estimator takes it before its next sample (nothing reads the
        // reference in between)
        self.refer = true;
        Ok(true)
    }

    /// The estimator's reference follows the model in use.
    fn reference(&mut self) {
        let m = self.model;
        // a gain hypothesis in use: what it left, the finer gains name
        self.est
            .refine(matches!(self.provisional, Some(proposals::Moved::Gain)));
        // a model the estimator cannot weigh (a dead time beyond its
        // history) leaves no reference: no alarm rather than a wrong one
        let _ = self.est.set_reference(m.k, m.tau, m.theta);
    }

    fn supervise(&mut self, e: T) {
        if self.oscillation(e) {
            return;
        }
        if self.watching > 0 {
            self.watching -= 1;
            // watched to the end without an oscillation, and predicting
            // as well as the estimate, or the estimate within `min_change`
            // of it: validated
            if self.watching == 0 && (!self.beats_model() || self.confirmed()) {
                self.validated = self.model;
            }
        }
        if self.frozen {
            return;
        }
        // one change per sample: an alarm raised or cleared now defers the
        // rest to the next sample
        let logged = self.logged;
        self.watch_model();
        if self.logged != logged {
            return;
        }
        if !self.cfg.apply
            || self.blocks < self.rest_until
            || self.shadow.is_some()
            || self.waiting.is_some()
        {
            return;
        }
        // an estimate at an edge is warned of and never applied, but it
        // does not keep a hypothesis that explains the data from being
        // proposed (measured: a loop that only loads move, whose bank
        // learnt a load-biased lag beyond the bounds, kept the right gain
        // hypothesis waiting for the rest of the run)
        // (a gain the level test fitted between its hypotheses is the
        // freest of the proposals: where the bank's dead time explains the
        // data as well, the dead time first — measured on the bank's dead
        // time ×0.7 with loads, a gain ×0.82 fitted to a shorter dead
        // time's responses)
        let edge = self.edge();
        let dead_first = self.est.level_between().is_some() && self.moved_dead_time();
        if dead_first
            || self.propose()
            || edge
            || self.moved_dead_time()
            || self.level_dead_time()
            || self.challenged()
        {
            return;
        }
        // the estimate in blocks of `settle` samples: a block in which it held
        // still (one whole dead time throughout, the gain and the time
        // constant within SPREAD·min_change from lowest to highest, every sample
        // plausible) gives its mean; two such blocks in a row whose means
        // agree settle the estimate (see SPREAD)
        let e = self.est.estimate().and_then(|m| self.plausible(m));
        self.block.add(e, self.est.learnt());
        if self.block.count < self.cfg.settle {
            return;
        }
        let block = core::mem::take(&mut self.block);
        let tol = self.cfg.min_change;
        let now = block.still(tol * T::of(SPREAD), self.est.window());
        let prev = core::mem::replace(&mut self.settled, now);
        let period = self.cfg.estimator.period();
        let Some(m) = now.and_then(|now| settled(prev?, now, tol, period)) else {
            return;
        };
        if self.since < self.cfg.min_interval {
            return;
        }
        let tol = if self.provisional.is_some() {
            tol / T::of(4.0)
        } else {
            tol
        };
        if !self.differs(m, tol) {
            self.edge_warned = false;
            return;
        }
        // beyond the bounds: never applied (an estimate there is warned
        // of by edge() as it stands)
        if !self.within_bounds(m) {
            return;
        }
        // the estimate must predict the recent data better than the model
        // in use; where its differences cannot tell yet, the level test
        // weighs it over the responses to come (`challenged`)
        if !self.beats_model() {
            self.est
                .challenge((m.k, m.tau, m.theta), self.cfg.min_change);
            return;
        }
        self.apply(m);
        self.provisional = None;
    }

    /// The estimate `m` applied, its gain and time constant at most a
    /// factor `max_step` from the model in use's.
    fn apply(&mut self, m: Model<T>) {
        let cur = self.model;
        let step = self.cfg.max_step;
        let limit = |old: T, new: T| {
            if old.is_infinite() || new.is_infinite() {
                new
            } else {
                new.max(old / step).min(old * step)
            }
        };
        let target = Model {
            k: if cur.k > T::zero() {
                limit(cur.k, m.k)
            } else {
                -limit(-cur.k, -m.k)
            },
            tau: limit(cur.tau, m.tau),
            theta: m.theta,
        };
        self.detune = T::one();
        self.take(target, ChangeKind::Applied);
    }

    /// The model `m` into the scheme as a change of kind `kind`: in the
    /// next call in which the estimator has no work, where a block has
    /// calls enough for one after its learning's parts (`deferred`), else
    /// now ([`Adaptive::take_now`]).
    fn take(&mut self, m: Model<T>, kind: ChangeKind) {
        // a model watched for half the watch without an oscillation, which
        // the data confirm, is validated when a new one replaces it before
        // its watch ends (measured: an integrating process's dead time
        // ×0.75, the emergency path's model right for 1 600 estimator
        // samples, a later proposal replaced it, oscillated, and the restore
        // went back to the commissioned model, under which the loop had
        // diverged, and it diverged again)
        let half_watched = self.watching > 0 && self.watching <= self.cfg.watch / 2;
        if kind == ChangeKind::Applied && half_watched && (!self.beats_model() || self.confirmed())
        {
            self.validated = self.model;
        }
        if self.cfg.estimator.decimation >= super::pass::PARTS + 2 {
            self.deferred = Some((m, kind));
        } else {
            self.take_now(m, kind);
        }
    }

    /// The model `m` into the scheme as a change of kind `kind`: logged
    /// and taking effect now, or when the rebuilt scheme takes over; a
    /// scheme that refuses it goes back to the model in use (a part may
    /// have been applied), and adaptation freezes, logged as refused.
    fn take_now(&mut self, m: Model<T>, kind: ChangeKind) {
        let cur = self.model;
        match self.put(m, kind) {
            Ok(true) => {
                self.record(kind);
                self.changed(kind);
            }
            Ok(false) => {}
            Err(_) => {
                let _ = self.put(cur, ChangeKind::Restored);
                self.shadow = None;
                self.frozen = true;
                self.record(ChangeKind::Refused);
            }
        }
    }
}
