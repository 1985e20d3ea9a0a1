//! The supervisor of adaptive dead-time compensation: an [`Estimator`]
//! beside a scheme with a model, and the rules that decide when its
//! estimate becomes the scheme's model.
//!
//! Each sample the estimator learns from the measurement and the input the
//! plant received; the supervisor applies a new model only when
//!
//! - the estimate has settled: taken in blocks of `settle` samples, it held
//!   still in two blocks in a row (in each, one whole dead time and the gain
//!   and the time constant within `min_change` of their mean from lowest
//!   to highest) whose means agree within half of `min_change` (half a
//!   sample for the dead time) — the later block's mean is applied; every
//!   sample's estimate counts only with its gain of the known sign, and
//!   its dead time only where chosen without ambiguity (its evidence over
//!   the candidates that are not its neighbours at least `min_evidence`,
//!   [`Estimate::evidence`]): otherwise the model's dead time stands in
//!   (a switch of dead time waits for evidence; the gain and the lag do
//!   not);
//! - it differs enough from the model in use: the gain or the time constant
//!   by `min_change` (relative), or the dead time by half a sample;
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

use super::{Estimate, Estimator, EstimatorConfig};
use crate::operate::{Gain, Operate, Tracking};
use crate::real::{at_least, at_most};
use crate::{CascadeControl, Controller, Error, FrequencyResponse, Introspect, Real};

/// How a scheme `C` is redesigned for a model `(K, τ, θ)` (`τ` infinite:
/// integrating) by its own rule at the same λ policy.
///
/// A scheme whose model can change at run time ([`Operate::set_model`]:
/// the Smith predictor) keeps its blocks and takes the primary's new gains
/// `[Kp, Ti, Td]` ([`Redesign::gains`]; `None` keeps them): any
/// `FnMut(K, τ, θ) -> Option<[T; 3]>` is one (a `fn` on a device, a
/// closure over the registry's tuning on a host), and `()` never retunes.
/// A scheme whose other blocks are designed from its model (the
/// compensator family, Karan–Dey, the filtered Smith predictor) is built
/// anew ([`Redesign::rebuild`], e.g. [`Rebuild`]): the new one runs beside
/// the old on the same measurements, tracking the output the plant
/// receives ([`Operate::apply`]), until its model's dead time and four time
/// constants have passed (its lines and states hold the loop's history),
/// then takes over from that output (its integral where the tracking left
/// it; its own law from then on, as after a bumpless return to automatic).
pub trait Redesign<T, C> {
    /// The primary's gains for the model.
    fn gains(&mut self, k: T, tau: T, theta: T) -> Option<[T; 3]> {
        let _ = (k, tau, theta);
        None
    }

    /// The scheme designed for the model. It is asked for only while no
    /// scheme it built before is warming up: the one in use and the new one
    /// are the only two alive (a redesign that lends memory to the schemes
    /// it builds needs two lots, alternately).
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<C> {
        let _ = (k, tau, theta);
        None
    }

    /// The scheme it built last has taken over: the one it replaced is
    /// gone (its memory free for the next [`Redesign::rebuild`]).
    fn took_over(&mut self) {}

    /// The dead time (s) of the scheme it built last, where that scheme
    /// runs another than the one asked for and cannot say so itself
    /// ([`Operate::dead_time`] is `None` for a scheme whose dead time is
    /// fixed when it is built): the model in use, its log and its verdict
    /// carry the dead time the loop runs.
    fn built_dead_time(&self) -> Option<T> {
        None
    }
}

impl<T, C, F: FnMut(T, T, T) -> Option<[T; 3]>> Redesign<T, C> for F {
    fn gains(&mut self, k: T, tau: T, theta: T) -> Option<[T; 3]> {
        self(k, tau, theta)
    }
}

impl<T, C> Redesign<T, C> for () {}

/// A redesign that builds the scheme anew: `F(K, τ, θ)` is the scheme
/// designed for the model ([`Redesign::rebuild`]).
#[derive(Debug, Clone, Copy)]
pub struct Rebuild<F>(pub F);

impl<T, C, F: FnMut(T, T, T) -> Option<C>> Redesign<T, C> for Rebuild<F> {
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<C> {
        (self.0)(k, tau, theta)
    }
}

/// A rebuilt scheme warming up beside the one in use.
#[derive(Debug, Clone)]
struct Shadow<T, C> {
    scheme: C,
    model: Model<T>,
    /// Samples until it takes over.
    left: u32,
    /// What its taking over is logged as.
    kind: ChangeKind,
}

/// Settings of an [`Adaptive`] controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveConfig<T> {
    /// The estimator's.
    pub estimator: EstimatorConfig<T>,
    /// The relative change of the gain or the time constant that is applied
    /// (default 0.05).
    pub min_change: T,
    /// Estimator samples an estimate must hold before it is applied
    /// (default 300; every count here is of the estimator's samples, of
    /// [`EstimatorConfig::period`]).
    pub settle: u32,
    /// Estimator samples between two changes at least (default 1000).
    pub min_interval: u32,
    /// The evidence for the chosen dead time over the next candidate, at
    /// least ([`Estimate::evidence`]; default 20).
    pub min_evidence: T,
    /// A change moves the gain and the time constant by at most this factor
    /// (default 2).
    pub max_step: T,
    /// The oscillation detector's band on the control error: a half-cycle
    /// of the error (between sign changes) counts when its peak exceeds
    /// this and four times the noise the estimator measures, it is shorter
    /// than four of the longest candidate dead times, and its peak is at
    /// least half the previous half-cycle's (default 0: the measured
    /// noise's band alone).
    pub band: T,
    /// Consecutive counted half-cycles after a change that restore the
    /// last validated model (default 6; the commissioned one until a change
    /// was validated).
    pub crossings: u32,
    /// Estimator samples watched after a change (default 2000); a change
    /// watched to the end without an oscillation, whose model predicts as
    /// well as the estimate, is validated: the model a later oscillation
    /// restores.
    pub watch: u32,
    /// The estimates' gain and time constant stay within this factor of
    /// the commissioned model's (default 4): beyond it an estimate is
    /// refused with a warning ([`ChangeKind::Edge`]), as one at the end of
    /// the dead-time range is.
    pub bound: T,
    /// Half-cycles of a growing oscillation of the control error (each
    /// reaching the band, each peak at least the one before) that set off
    /// the emergency path (default 4: two periods): a clear estimate is
    /// applied at once ([`ChangeKind::Emergency`]), or the primary's gain
    /// is halved ([`ChangeKind::Detuned`]).
    pub emergency: u32,
    /// The evidence by which the estimate must predict the data since the
    /// model in use was set better than it before it is applied
    /// ([`crate::adapt::Mismatch::evidence`], default 4: a likelihood
    /// ratio of `e²` for Gaussian errors); never below 0: no model is
    /// applied that predicts the recent data worse than the one in use.
    pub validate: T,
    /// Whether settled estimates are applied (default true); false: a
    /// model-error monitor only — the estimator learns, the alarm is
    /// raised and cleared, the model in use stays.
    pub apply: bool,
    /// The model error ([`crate::adapt::Mismatch::error`]) that raises the
    /// alarm when it holds for `settle` samples with the evidence of
    /// `min_evidence` (default 0.1); it clears below half of it; infinite:
    /// no alarm.
    pub alarm: T,
}

impl<T: Real> AdaptiveConfig<T> {
    /// Checks every setting (the estimator's included).
    pub fn validate(&self) -> Result<(), Error> {
        self.estimator.validate()?;
        crate::real::positive(self.min_change, "min_change")?;
        if !(self.max_step > T::one()) {
            return Err(Error::OutOfRange("max_step: above 1"));
        }
        if !(self.alarm > T::zero()) {
            return Err(Error::NotPositive("alarm"));
        }
        if !(self.bound > T::one()) {
            return Err(Error::OutOfRange("bound: above 1"));
        }
        crate::real::non_negative(self.band, "band")?;
        crate::real::non_negative(self.validate, "validate")?;
        Ok(())
    }

    /// Defaults around the estimator's settings.
    pub fn new(estimator: EstimatorConfig<T>) -> Self {
        AdaptiveConfig {
            estimator,
            min_change: T::of(0.05),
            settle: 300,
            min_interval: 1000,
            min_evidence: T::of(20.0),
            max_step: T::of(2.0),
            band: T::zero(),
            crossings: 6,
            watch: 2000,
            apply: true,
            alarm: T::of(0.1),
            bound: T::of(4.0),
            emergency: 4,
            validate: T::of(4.0),
        }
    }
}

/// What a logged change did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ChangeKind {
    /// A settled estimate became the model.
    Applied,
    /// The loop oscillated after a change: the last good model came back.
    Restored,
    /// A scheme's operation refused the model: adaptation froze.
    Refused,
    /// The model in use no longer matches the process (the entry's model
    /// is the estimate's).
    Alarm,
    /// The model in use matches again.
    Cleared,
    /// The loop was going unstable and the estimate was clear: applied at
    /// once (the entry's model).
    Emergency,
    /// The loop was going unstable without a clear estimate: the
    /// primary's gain halved (the entry's model is the one in use).
    Detuned,
    /// An estimate at the end of the dead-time range, or beyond the gain's
    /// or the time constant's bound: not applied (the entry's model is the
    /// estimate's).
    Edge,
}

impl ChangeKind {
    /// The number the `adapt_kind` signal gives it (1 … 8).
    pub fn code(self) -> u8 {
        match self {
            ChangeKind::Applied => 1,
            ChangeKind::Restored => 2,
            ChangeKind::Refused => 3,
            ChangeKind::Alarm => 4,
            ChangeKind::Cleared => 5,
            ChangeKind::Emergency => 6,
            ChangeKind::Detuned => 7,
            ChangeKind::Edge => 8,
        }
    }

    /// The kind of a code of [`ChangeKind::code`].
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            1 => Some(ChangeKind::Applied),
            2 => Some(ChangeKind::Restored),
            3 => Some(ChangeKind::Refused),
            4 => Some(ChangeKind::Alarm),
            5 => Some(ChangeKind::Cleared),
            6 => Some(ChangeKind::Emergency),
            7 => Some(ChangeKind::Detuned),
            8 => Some(ChangeKind::Edge),
            _ => None,
        }
    }
}

/// One entry of the adaptation log: the model in use from `sample` on.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Change<T> {
    /// The sample at which it happened (counted from the first update).
    pub sample: u64,
    /// What happened.
    pub kind: ChangeKind,
    /// The model's gain `K`.
    pub k: T,
    /// The model's time constant `τ` (s; infinite: integrating).
    pub tau: T,
    /// The model's dead time `θ` (s).
    pub theta: T,
}

/// A model `(K, τ, θ)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Model<T> {
    k: T,
    tau: T,
    theta: T,
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
#[derive(Debug, Clone)]
pub struct Adaptive<T, C, R, const N: usize, const H: usize, const L: usize = 16> {
    inner: C,
    est: Estimator<T, N, H>,
    cfg: AdaptiveConfig<T>,
    retune: R,
    model: Model<T>,
    /// The commissioned model (the bounds' centre) and the last validated
    /// one (what an oscillation after a change restores).
    commissioned: Model<T>,
    validated: Model<T>,
    /// Estimator samples so far, and the control error's sum over the
    /// current block.
    blocks: u64,
    err: T,
    err_n: u32,
    /// Half-cycles of a growing oscillation in a row (the emergency path).
    growing: u32,
    /// The factor on the rule's gain after detuning (1: none).
    detune: T,
    /// An edge warning was logged for the estimate as it stands.
    edge_warned: bool,
    /// The statistics of the current block of `settle` samples.
    block: Block<T>,
    /// The last complete block's mean, when the estimate held still in it.
    settled: Option<(usize, Model<T>)>,
    since: u32,
    samples: u64,
    frozen: bool,
    rest_until: u64,
    log: [Option<Change<T>>; L],
    logged: usize,
    last_u: T,
    ok: bool,
    /// The last measurement, for the estimator once its input is known.
    pending: Option<T>,
    watching: u32,
    side: i8,
    crossed: u32,
    /// The current half-cycle of the error: its length and its peak; the
    /// peak of the one before.
    half: u32,
    peak: T,
    last_peak: T,
    /// A rebuilt scheme warming up to take over.
    shadow: Option<Shadow<T, C>>,
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
            inner,
            est,
            cfg,
            retune,
            model,
            commissioned: model,
            validated: model,
            blocks: 0,
            err: T::zero(),
            err_n: 0,
            growing: 0,
            detune: T::one(),
            edge_warned: false,
            block: Block::default(),
            settled: None,
            since: 0,
            samples: 0,
            frozen: false,
            rest_until: 0,
            log: [None; L],
            logged: 0,
            last_u: T::zero(),
            ok: false,
            pending: None,
            watching: 0,
            side: 0,
            crossed: 0,
            half: 0,
            peak: T::zero(),
            last_peak: T::zero(),
            alarm: false,
            alarm_for: 0,
            shadow: None,
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

    /// Stops adapting: nothing is learnt or applied until [`Self::resume`].
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

    /// One sample with the input the plant really received over the last
    /// period (`None`: this controller's own output).
    pub fn update_applied(&mut self, r: T, y: T, u_applied: Option<T>) -> T {
        if let Some(u) = u_applied {
            if u.is_finite() && (u - self.last_u).abs() > T::epsilon() * (T::one() + u.abs()) {
                self.last_u = u;
                self.ok = false;
            }
        }
        self.step(r, y)
    }

    fn step(&mut self, r: T, y: T) -> T {
        // the estimator takes the last sample's measurement with the input
        // the plant then received (known only now: a limit or an operator
        // may have changed it after that update), one sample late
        let mut ended = false;
        if let Some(y_last) = self.pending.take() {
            let learn = self.ok && !self.frozen;
            ended = self.est.update(y_last, self.last_u, learn);
        }
        self.pending = Some(y);
        self.samples = self.samples.saturating_add(1);
        let e = r - y;
        if e.is_finite() {
            self.err = self.err + e;
            self.err_n = self.err_n.saturating_add(1);
        }
        let logged = self.logged;
        if ended {
            // the supervisor runs at the estimator's period, on the
            // block's mean control error
            let mean = if self.err_n > 0 {
                self.err / T::of(f64::from(self.err_n))
            } else {
                T::zero()
            };
            (self.err, self.err_n) = (T::zero(), 0);
            self.blocks = self.blocks.saturating_add(1);
            self.since = self.since.saturating_add(1);
            self.supervise(mean);
        }
        let u = self.inner.update(r, y);
        self.last_u = u;
        self.ok = u.is_finite() && !self.inner.fault();
        self.warm(r, y, u, self.logged != logged);
        u
    }

    /// The rebuilt scheme's sample beside the one in use: it computes on
    /// the same measurement and follows the output the plant receives; when
    /// its time has come, it takes over (a sample later when this sample
    /// already logged a change: one change per sample, so that the
    /// recorded signals `adapt_changes` and `adapt_kind` name every one).
    fn warm(&mut self, r: T, y: T, u: T, logged: bool) {
        let Some(sh) = self.shadow.as_mut() else {
            return;
        };
        sh.scheme.update(r, y);
        sh.scheme.apply(u, Tracking::Full);
        sh.left = sh.left.saturating_sub(1);
        if sh.left > 0 {
            return;
        }
        if logged {
            sh.left = 1;
            return;
        }
        if let Some(sh) = self.shadow.take() {
            self.inner = sh.scheme;
            self.retune.took_over();
            self.model = sh.model;
            self.reference();
            self.record(sh.kind);
            self.changed(sh.kind);
        }
    }

    /// After a change took effect: the interval starts again, and after an
    /// applied one the watch for oscillation.
    fn changed(&mut self, kind: ChangeKind) {
        self.since = 0;
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
                let scheme = self
                    .retune
                    .rebuild(m.k, m.tau, m.theta)
                    .ok_or(Error::Unsupported(why))?;
                // the model in use is the one built: its dead time as the
                // scheme runs it (a filtered Smith predictor's is rounded
                // to a sample; one without a run-time dead time says so
                // through its redesign)
                let m = Model {
                    theta: scheme
                        .dead_time()
                        .map(|d| d * ts)
                        .or_else(|| self.retune.built_dead_time())
                        .unwrap_or(m.theta),
                    ..m
                };
                // its dead time and four time constants (an integrating
                // model's: four dead times) fill its lines and settle it
                let span = if m.tau.is_finite() { m.tau } else { m.theta };
                let samples = ((m.theta + T::of(4.0) * span) / ts).ceil();
                let left = num_traits::ToPrimitive::to_u32(&samples)
                    .unwrap_or(u32::MAX)
                    .clamp(1, 100_000);
                self.shadow = Some(Shadow {
                    scheme,
                    model: m,
                    left,
                    kind,
                });
                return Ok(false);
            }
            Err(e) => return Err(e),
        }
        self.inner.set_dead_time(m.theta / ts)?;
        if let Some([kp, ti, td]) = self.retune.gains(m.k, m.tau, m.theta) {
            self.inner.retune(Gain::Kp, kp)?;
            self.inner.retune(Gain::Ti, ti)?;
            self.inner.retune(Gain::Td, td)?;
        }
        self.model = m;
        self.reference();
        Ok(true)
    }

    /// The estimator's reference follows the model in use.
    fn reference(&mut self) {
        let m = self.model;
        // a model the estimator cannot weigh (a dead time beyond its
        // history) leaves no reference: no alarm rather than a wrong one
        let _ = self.est.set_reference(m.k, m.tau, m.theta);
    }

    /// The model-error alarm: raised when the error reached `alarm` with
    /// the evidence of `min_evidence` for `settle` samples, cleared when it
    /// stayed below half of it as long; each logged.
    fn watch_model(&mut self) {
        if !self.cfg.alarm.is_finite() {
            return;
        }
        let Some(mm) = self.est.mismatch() else {
            return;
        };
        let against = if self.alarm {
            mm.error < self.cfg.alarm / T::of(2.0)
        } else {
            mm.error >= self.cfg.alarm && mm.evidence >= self.cfg.min_evidence
        };
        self.alarm_for = if against {
            self.alarm_for.saturating_add(1)
        } else {
            0
        };
        if self.alarm_for >= self.cfg.settle {
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
    pub fn mismatch(&self) -> Option<super::Mismatch<T>> {
        self.est.mismatch()
    }

    /// The control error's half-cycles (between sign changes, at the
    /// estimator's period): after a change, `crossings` sustained ones
    /// restore the last validated model; at any time, `emergency` growing
    /// ones set off the emergency path. Returns whether it acted.
    fn oscillation(&mut self, e: T) -> bool {
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
            // transient the change met) starts the count again; one at
            // least as large as the one before is growing
            if self.side != 0 {
                let counts = self.peak > self.band() && self.half <= self.max_half();
                let sustained = counts && self.peak >= self.last_peak / T::of(2.0);
                let growing = counts && self.last_peak > T::zero() && self.peak >= self.last_peak;
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
            self.restore();
            return true;
        }
        // growing half-cycles, or (once detuned) ones that go on
        let detuned_still = self.detune < T::one() && self.crossed >= self.cfg.crossings;
        if (self.growing >= self.cfg.emergency.max(1) || detuned_still) && !self.frozen {
            self.growing = 0;
            self.crossed = 0;
            self.emergency();
            return true;
        }
        false
    }

    /// Back to the last validated model and its tuning; adaptation rests
    /// for `4·min_interval`.
    fn restore(&mut self) {
        let back = self.validated;
        self.shadow = None;
        self.detune = T::one();
        self.take(back, ChangeKind::Restored);
        self.rest_until = self
            .blocks
            .saturating_add(4 * u64::from(self.cfg.min_interval));
    }

    /// The loop is going unstable: a clear estimate (its dead time chosen
    /// with the evidence of `min_evidence`, predicting the recent data
    /// better than the model in use with as much, within the bounds) is
    /// applied at once; without one the primary's gain is halved (a
    /// dead-time loop detuned is stable for a larger model error: its
    /// robustness bound `|ΔG/G| < |1 + C G₀|/|C G₀|` grows as the gain
    /// falls, Bag (2022) Eqs. 4.52–4.58 for the integrating case); each
    /// logged.
    fn emergency(&mut self) {
        let clear = self
            .est
            .estimate()
            .and_then(|m| self.plausible(m))
            .filter(|m| m.evidence >= self.cfg.min_evidence)
            .filter(|_| self.beats_model())
            .map(|m| Model {
                k: m.k,
                tau: m.tau,
                theta: m.theta,
            })
            .filter(|m| self.within_bounds(*m));
        if let (Some(m), true) = (clear, self.cfg.apply) {
            self.shadow = None;
            self.detune = T::one();
            self.take(m, ChangeKind::Emergency);
            return;
        }
        let m = self.model;
        let detuned = self.detune / T::of(2.0);
        if let Some([kp, _, _]) = self.retune.gains(m.k, m.tau, m.theta) {
            if self.inner.retune(Gain::Kp, kp * detuned).is_ok() {
                self.detune = detuned;
                self.record(ChangeKind::Detuned);
                self.since = 0;
                return;
            }
        }
        // nothing this scheme can do by itself: said, once per episode
        if !self.alarm {
            self.alarm = true;
            self.record_model(ChangeKind::Alarm, m);
        }
    }

    /// The estimate as it stands lies at the end of the dead-time range or
    /// beyond the bounds, and predicts the data better than the model in
    /// use (the process has left what the search may find): a warning,
    /// logged once while it lasts ([`ChangeKind::Edge`], with the estimate),
    /// and nothing applied. Returns whether it is so.
    fn edge(&mut self) -> bool {
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
    fn beats_model(&self) -> bool {
        self.est
            .mismatch()
            .is_some_and(|mm| mm.evidence >= self.cfg.validate)
    }

    /// `m`'s gain and time constant within [`AdaptiveConfig::bound`] of the
    /// commissioned model's.
    fn within_bounds(&self, m: Model<T>) -> bool {
        let c = self.commissioned;
        let b = self.cfg.bound;
        let inside = |x: T, x0: T| {
            if x0.is_infinite() || x.is_infinite() {
                x0.is_infinite() == x.is_infinite()
            } else {
                let r = x / x0;
                r >= T::one() / b && r <= b
            }
        };
        inside(m.k, c.k) && inside(m.tau, c.tau)
    }

    fn supervise(&mut self, e: T) {
        if self.oscillation(e) {
            return;
        }
        if self.watching > 0 {
            self.watching -= 1;
            // watched to the end without an oscillation, and predicting
            // as well as the estimate: validated
            if self.watching == 0 && !self.beats_model() {
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
        if !self.cfg.apply || self.blocks < self.rest_until || self.shadow.is_some() {
            return;
        }
        if self.edge() {
            return;
        }
        // the estimate in blocks of `settle` samples: a block in which it held
        // still (one whole dead time throughout, the gain and the time
        // constant within `min_change` from lowest to highest, every sample
        // plausible) gives its mean; two such blocks in a row whose means
        // agree within half of `min_change` settle the estimate
        let e = self.est.estimate().and_then(|m| self.plausible(m));
        self.block.add(e);
        if self.block.count < self.cfg.settle {
            return;
        }
        let block = core::mem::take(&mut self.block);
        let tol = self.cfg.min_change;
        let now = block.still(tol);
        let prev = core::mem::replace(&mut self.settled, now);
        let Some((d, m)) = now else {
            return;
        };
        let half = tol / T::of(2.0);
        let period = self.cfg.estimator.period();
        let agree = prev.is_some_and(|(pd, p)| {
            pd == d
                && near(p.k, m.k, half)
                && near(p.tau, m.tau, half)
                && (p.theta - m.theta).abs() <= period / T::of(2.0)
        });
        if !agree || self.since < self.cfg.min_interval {
            return;
        }
        let cur = self.model;
        let differs = !near(cur.k, m.k, self.cfg.min_change)
            || !near(cur.tau, m.tau, self.cfg.min_change)
            || (cur.theta - m.theta).abs() > period / T::of(2.0);
        if !differs {
            self.edge_warned = false;
            return;
        }
        // beyond the bounds: never applied (an estimate there is warned
        // of by edge() as it stands)
        if !self.within_bounds(m) {
            return;
        }
        // the estimate must predict the recent data better than the model
        // in use
        if !self.beats_model() {
            return;
        }
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

    /// The model `m` into the scheme as a change of kind `kind`: logged
    /// and taking effect now, or when the rebuilt scheme takes over; a
    /// scheme that refuses it goes back to the model in use (a part may
    /// have been applied), and adaptation freezes, logged as refused.
    fn take(&mut self, m: Model<T>, kind: ChangeKind) {
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

    /// The oscillation detector's band: the one given, and at least four
    /// times the measurement noise the estimator measures (a half-cycle of
    /// the noise alone does not reach it: a device need not know its
    /// noise).
    fn band(&self) -> T {
        self.cfg.band.max(T::of(4.0) * self.est.noise_level())
    }

    /// The longest half-cycle of an oscillation: four times the longest
    /// candidate dead time (a detuned dead-time loop oscillates with a
    /// period of about two to four dead times).
    fn max_half(&self) -> u32 {
        let d = self.cfg.estimator.d_min.saturating_add(N);
        u32::try_from(d.saturating_mul(4)).unwrap_or(u32::MAX)
    }

    /// An estimate worth applying: the gain of the model's sign, a finite
    /// positive time constant (or an integrating model for an integrating
    /// one); its dead time where it was chosen without ambiguity, the
    /// model's where not (a switch of dead time waits for evidence; the
    /// gain and the lag do not).
    fn plausible(&self, m: Estimate<T>) -> Option<Estimate<T>> {
        let integrating = self.cfg.estimator.integrating;
        let ok = (m.k > T::zero()) == (self.model.k > T::zero())
            && m.k.is_finite()
            && (integrating || (m.tau.is_finite() && m.tau > T::zero()));
        if !ok {
            return None;
        }
        let ts = self.cfg.estimator.period();
        // the model's whole samples (truncation: θ/Ts is not negative)
        let d = num_traits::ToPrimitive::to_usize(&(self.model.theta / ts + T::of(1e-9)));
        if m.evidence >= self.cfg.min_evidence || d == Some(m.d) {
            return Some(m);
        }
        Some(Estimate {
            theta: self.model.theta,
            d: d.unwrap_or(m.d),
            ..m
        })
    }
}

/// The estimates of a block of samples.
#[derive(Debug, Clone, Copy, Default)]
struct Block<T> {
    count: u32,
    /// Samples without a plausible estimate.
    missing: u32,
    d: Option<usize>,
    /// Whether every estimate of the block had the dead time `d`.
    one_d: bool,
    sum: Model<T>,
    lo: Model<T>,
    hi: Model<T>,
}

impl<T: Real> Block<T> {
    fn add(&mut self, e: Option<Estimate<T>>) {
        self.count = self.count.saturating_add(1);
        let Some(e) = e else {
            self.missing = self.missing.saturating_add(1);
            return;
        };
        match self.d {
            None => {
                self.d = Some(e.d);
                self.one_d = true;
                self.lo = Model {
                    k: e.k,
                    tau: e.tau,
                    theta: e.theta,
                };
                self.hi = self.lo;
            }
            Some(d) => {
                self.one_d &= d == e.d;
                self.lo.k = at_most(e.k, self.lo.k);
                self.hi.k = at_least(e.k, self.hi.k);
                self.lo.tau = at_most(e.tau, self.lo.tau);
                self.hi.tau = at_least(e.tau, self.hi.tau);
            }
        }
        self.sum.k = self.sum.k + e.k;
        self.sum.tau = self.sum.tau + e.tau;
        self.sum.theta = self.sum.theta + e.theta;
    }

    /// The block's dead time and mean model when the estimate held still in
    /// it: every sample plausible, one dead time, the gain and the time
    /// constant within `tol` of their mean from lowest to highest.
    fn still(&self, tol: T) -> Option<(usize, Model<T>)> {
        let d = self.d?;
        if self.missing > 0 || !self.one_d || self.count == 0 {
            return None;
        }
        let n = T::of(f64::from(self.count));
        let mean = Model {
            k: self.sum.k / n,
            tau: self.sum.tau / n,
            theta: self.sum.theta / n,
        };
        let narrow = |lo: T, hi: T, m: T| m.is_infinite() || hi - lo <= tol * m.abs();
        (narrow(self.lo.k, self.hi.k, mean.k) && narrow(self.lo.tau, self.hi.tau, mean.tau))
            .then_some((d, mean))
    }
}

/// `b` within the fraction `rel` of `a` (both infinite: equal).
fn near<T: Real>(a: T, b: T, rel: T) -> bool {
    if a.is_infinite() || b.is_infinite() {
        return a == b;
    }
    (a - b).abs() <= rel * a.abs()
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Controller<T> for Adaptive<T, C, R, N, H, L>
{
    fn update(&mut self, r: T, y: T) -> T {
        self.step(r, y)
    }

    /// The scheme's reset; the estimator and the log keep what they learnt.
    fn reset(&mut self) {
        self.inner.reset();
        self.shadow = None;
        self.last_u = T::zero();
        self.ok = false;
        self.pending = None;
    }

    fn fault(&self) -> bool {
        self.inner.fault()
    }
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Operate<T> for Adaptive<T, C, R, N, H, L>
{
    /// The scheme follows the applied value; the estimator learns nothing
    /// from this sample (saturated, manual or tracking: not the process's
    /// answer to the control law) but records what the plant received.
    fn apply(&mut self, applied: T, how: Tracking) {
        self.inner.apply(applied, how);
        if let Some(sh) = self.shadow.as_mut() {
            sh.scheme.apply(applied, Tracking::Full);
        }
        if applied.is_finite() && applied != self.last_u {
            self.last_u = applied;
            self.ok = false;
        }
    }
    fn dead_time(&self) -> Option<T> {
        self.inner.dead_time()
    }
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.inner.set_dead_time(samples)?;
        self.model.theta = samples * self.cfg.estimator.ts;
        self.reference();
        Ok(())
    }
    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        self.inner.ramp_dead_time(samples, per_sample)?;
        self.model.theta = samples * self.cfg.estimator.ts;
        self.reference();
        Ok(())
    }
    fn retune(&mut self, gain: Gain, value: T) -> Result<(), Error> {
        self.inner.retune(gain, value)
    }
    fn set_adapting(&mut self, on: bool) -> Result<(), Error> {
        self.frozen = !on;
        Ok(())
    }
    fn visit_log(&self, f: &mut dyn FnMut(Change<T>)) {
        for c in self.log() {
            f(c);
        }
    }
    fn set_model(&mut self, gain: T, tau: T) -> Result<(), Error> {
        self.inner.set_model(gain, tau)?;
        self.model.k = gain;
        self.model.tau = tau;
        self.reference();
        Ok(())
    }
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    CascadeControl<T> for Adaptive<T, C, R, N, H, L>
{
}

/// The signals an adaptive controller adds to its scheme's, in this order:
/// the estimate (`k_hat`, `tau_hat`, `theta_hat`; NaN before it means
/// anything) and the evidence for its dead time over the candidates that
/// cannot be the same (`evidence`, [`crate::adapt::Estimate::evidence`]:
/// small is an ambiguous choice), the model in use (`k_model`, `tau_model`, `theta_model`),
/// how many changes were logged so far (`adapt_changes`) and what the last
/// one did (`adapt_kind`: 0 none, 1 applied, 2 restored, 3 refused, 4 alarm,
/// 5 cleared, 6 emergency, 7 detuned, 8 edge, [`ChangeKind::code`]), the model's error against the process
/// (`mismatch`, [`crate::adapt::Mismatch::error`]; NaN before it means
/// anything) and the alarm (`model_alarm`: 0 or 1).
pub const SIGNALS: [&str; 11] = [
    "k_hat",
    "tau_hat",
    "theta_hat",
    "evidence",
    "k_model",
    "tau_model",
    "theta_model",
    "adapt_changes",
    "adapt_kind",
    "mismatch",
    "model_alarm",
];

impl<
        T: Real,
        C: Operate<T> + Introspect<T>,
        R: Redesign<T, C>,
        const N: usize,
        const H: usize,
        const L: usize,
    > Introspect<T> for Adaptive<T, C, R, N, H, L>
{
    /// The scheme's signals, then [`SIGNALS`] (with `std`; without it,
    /// [`SIGNALS`] alone: the joined list is made once per scheme).
    fn signal_names(&self) -> &'static [&'static str] {
        joined(self.inner.signal_names())
    }

    fn signal(&self, i: usize) -> T {
        let own = self.signal_names().len() - SIGNALS.len();
        if i < own {
            return self.inner.signal(i);
        }
        let e = self.est.estimate();
        let m = self.model;
        match i - own {
            0 => e.map_or(T::nan(), |e| e.k),
            1 => e.map_or(T::nan(), |e| e.tau),
            2 => e.map_or(T::nan(), |e| e.theta),
            3 => e.map_or(T::nan(), |e| e.evidence),
            4 => m.k,
            5 => m.tau,
            6 => m.theta,
            7 => T::of(self.logged as f64),
            8 => T::of(f64::from(self.log().last().map_or(0, |c| c.kind.code()))),
            9 => self.est.mismatch().map_or(T::nan(), |m| m.error),
            10 => {
                if self.alarm {
                    T::one()
                } else {
                    T::zero()
                }
            }
            _ => T::nan(),
        }
    }

    fn param_names(&self) -> &'static [&'static str] {
        self.inner.param_names()
    }

    fn param(&self, i: usize) -> T {
        self.inner.param(i)
    }
}

impl<
        T: Real,
        C: Operate<T> + FrequencyResponse<T>,
        R: Redesign<T, C>,
        const N: usize,
        const H: usize,
        const L: usize,
    > FrequencyResponse<T> for Adaptive<T, C, R, N, H, L>
{
    fn response(&self, theta: T) -> Option<(crate::Complex<T>, crate::Complex<T>)> {
        self.inner.response(theta)
    }
    fn inner_response(&self, theta: T) -> Option<crate::Complex<T>> {
        self.inner.inner_response(theta)
    }
    fn feedback_parts(&self, theta: T) -> Option<(crate::Complex<T>, crate::Complex<T>)> {
        self.inner.feedback_parts(theta)
    }
    fn unstable_poles(&self) -> usize {
        self.inner.unstable_poles()
    }
}

/// The scheme's signal names followed by [`SIGNALS`], made once per list.
#[cfg(feature = "std")]
fn joined(inner: &'static [&'static str]) -> &'static [&'static str] {
    use std::sync::Mutex;
    type Joined = (usize, usize, &'static [&'static str]);
    static CACHE: Mutex<std::vec::Vec<Joined>> = Mutex::new(std::vec::Vec::new());
    let key = (inner.as_ptr() as usize, inner.len());
    let Ok(mut cache) = CACHE.lock() else {
        return &SIGNALS;
    };
    if let Some((_, _, j)) = cache.iter().find(|(p, n, _)| (*p, *n) == key) {
        return j;
    }
    let mut v = std::vec::Vec::with_capacity(inner.len() + SIGNALS.len());
    v.extend_from_slice(inner);
    v.extend_from_slice(&SIGNALS);
    let j: &'static [&'static str] = std::boxed::Box::leak(v.into_boxed_slice());
    cache.push((key.0, key.1, j));
    j
}

/// Without `std`: [`SIGNALS`] alone.
#[cfg(not(feature = "std"))]
fn joined(_inner: &'static [&'static str]) -> &'static [&'static str] {
    &SIGNALS
}
