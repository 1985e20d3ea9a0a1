//! The adaptation's log and the signals an adaptive controller adds to
//! its scheme's.

use super::*;

/// The signals an adaptive controller adds to its scheme's, in this order:
/// the estimate (`k_hat`, `tau_hat`, `theta_hat`; NaN before it means
/// anything) and the evidence for its dead time over the candidates that
/// cannot be the same (`evidence`, [`crate::adapt::Estimate::evidence`]:
/// small is an ambiguous choice), the model in use (`k_model`, `tau_model`, `theta_model`),
/// how many changes were logged so far (`adapt_changes`) and what the last
/// one did (`adapt_kind`: 0 none, 1 applied, 2 restored, 3 refused, 4 alarm,
/// 5 cleared, 6 emergency, 7 detuned, 8 edge, [`ChangeKind::code`]), the model's error against the process
/// (`mismatch`, [`crate::adapt::Mismatch::error`]; NaN before it means
/// anything), the alarm (`model_alarm`: 0 or 1), and the estimator's counts
/// so far: load onsets (`onsets`, [`Estimator::onsets`]), restarts of the
/// change detector (`restarts`, [`Estimator::restarts`]) and samples the
/// chosen dead time learnt from (`learnt`, [`Estimator::learnt`]: none, and
/// nothing moved the loop enough to identify the process), and the
/// responses (a load's, a set-point change's) the level test compared
/// (`responses`), took as evidence (`responses_used`,
/// [`Estimator::level_responses`]) and found a ramp load's
/// (`responses_ramps`, [`Estimator::level_ramps`]: while they outnumber
/// the ones taken since the model in use was set, the level test holds
/// back).
pub const SIGNALS: [&str; 17] = [
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
    "onsets",
    "restarts",
    "learnt",
    "responses",
    "responses_used",
    "responses_ramps",
];

/// The values of [`SIGNALS`] in a state, in their order.
fn values<T: Real>(s: &AdaptiveState<T>) -> [T; SIGNALS.len()] {
    let count = |n: u32| T::of(f64::from(n));
    [
        s.k_hat,
        s.tau_hat,
        s.theta_hat,
        s.evidence,
        s.k_model,
        s.tau_model,
        s.theta_model,
        T::of(s.adapt_changes as f64),
        T::of(f64::from(s.adapt_kind)),
        s.mismatch,
        if s.model_alarm { T::one() } else { T::zero() },
        count(s.onsets),
        count(s.restarts),
        count(s.learnt),
        count(s.responses),
        count(s.responses_used),
        count(s.responses_ramps),
    ]
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Introspect<T> for Adaptive<T, C, R, N, H, L>
where
    C: Introspect<T>,
{
    /// The scheme's signals, then [`SIGNALS`] (with `std`; without it,
    /// [`SIGNALS`] alone: the joined list is made once per scheme).
    fn signal_names(&self) -> &'static [&'static str] {
        joined(self.inner.signal_names())
    }

    fn signal(&self, i: usize) -> T {
        match i.checked_sub(self.scheme_signals()) {
            None => self.inner.signal(i),
            Some(j) => values(&self.state()).get(j).copied().unwrap_or_else(T::nan),
        }
    }

    /// The scheme's signals, then the estimate and the model once for all
    /// of [`SIGNALS`] (a run records them every sample).
    fn write_signals(&self, out: &mut [T]) {
        let own = self.scheme_signals().min(out.len());
        let (scheme, mine) = out.split_at_mut(own);
        self.inner.write_signals(scheme);
        for (o, v) in mine.iter_mut().zip(values(&self.state())) {
            *o = v;
        }
    }

    fn param_names(&self) -> &'static [&'static str] {
        self.inner.param_names()
    }

    fn param(&self, i: usize) -> T {
        self.inner.param(i)
    }
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Adaptive<T, C, R, N, H, L>
{
    /// How many of [`Introspect::signal_names`] are the scheme's: all of
    /// its own with `std`, none without (see `joined`).
    fn scheme_signals(&self) -> usize
    where
        C: Introspect<T>,
    {
        if cfg!(feature = "std") {
            self.inner.signal_names().len()
        } else {
            0
        }
    }

    /// What it knows now ([`AdaptiveState`]).
    pub fn state(&self) -> AdaptiveState<T> {
        let e = self.est.estimate();
        let m = self.model;
        let nan = T::nan();
        let (responses, responses_used) = self.est.level_responses();
        AdaptiveState {
            k_hat: e.map_or(nan, |e| e.k),
            tau_hat: e.map_or(nan, |e| e.tau),
            theta_hat: e.map_or(nan, |e| e.theta),
            evidence: e.map_or(nan, |e| e.evidence),
            k_model: m.k,
            tau_model: m.tau,
            theta_model: m.theta,
            adapt_changes: self.logged as u64,
            adapt_kind: self.log().last().map_or(0, |c| c.kind.code()),
            mismatch: self.est.mismatch().map_or(nan, |m| m.error),
            model_alarm: self.alarm,
            onsets: self.est.onsets(),
            restarts: self.est.restarts(),
            learnt: self.est.learnt(),
            responses,
            responses_used,
            responses_ramps: self.est.level_ramps(),
            frozen: self.frozen,
        }
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
