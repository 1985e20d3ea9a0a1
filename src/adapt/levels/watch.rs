//! The watch at rest: Page's two-sided test on the model in use's
//! residual in levels, which opens a load's response the onset test does
//! not see (see `levels.rs`).

use super::*;

/// The watch's drift per sample, in units of the noise in levels: a
/// departure of the level by less is not a load.
pub const WATCH_DRIFT: f64 = 1.0;

/// The watch's threshold, in units of the noise in levels: Page's sum of
/// the departures beyond [`WATCH_DRIFT`] that make a load's response. For
/// white noise the test's mean time between false alarms is about
/// `e^{2·ν·h}` samples (Basseville & Nikiforov (1993) Sec. 5.2: some
/// 10⁷ here); an output load of six times the noise is found in two
/// samples.
pub const WATCH_LIMIT: f64 = 8.0;

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// One sample at rest of the watch for a load the onset test does not
    /// see (under noise a load's step in the differences is within five
    /// times the noise, and the controller's answer within the excitation
    /// gate): Page's two-sided test for a change of the mean of the model in
    /// use's residual in levels `R` (`e_ref` its difference; Page (1954);
    /// Basseville & Nikiforov (1993) Sec. 2.2), `S⁺ = max(0, S⁺ + R − R̄ −
    /// νσ)` and `S⁻` alike, `ν` [`WATCH_DRIFT`] and `σ` the noise in
    /// levels; the mean `R̄` follows the residual while both sums are zero.
    /// (The residual, not the measurement: the controller's answer to the
    /// noise moves the measurement's level at rest, the model in use
    /// predicts it.) Past [`WATCH_LIMIT`]·σ a load's response opens there,
    /// compared at its end as an onset's: the load began before, so its
    /// step is not in the response's data (the sums' last zero, the test's
    /// estimate of the change's time, falls under noise tens of samples
    /// early as often as not).
    pub(in crate::adapt) fn levels_watch(&mut self, e_ref: T) {
        if self.cfg.prefilter != T::zero() || self.levels.open.is_some() {
            return;
        }
        let integrating = self.cfg.integrating;
        let deviation = self.level_deviation();
        let short = self.short;
        let level = self.last_y;
        let lv = &mut self.levels;
        let [r, v, mean, hi, lo] = lv.watch;
        // the residual in levels
        let (r, v) = if integrating {
            (r + v + e_ref, v + e_ref)
        } else {
            (r + e_ref, v)
        };
        if !lv.watched {
            lv.watch = [r, v, r, T::zero(), T::zero()];
            lv.watched = true;
            return;
        }
        // (and at least a thousandth of the measurement's level: without
        // noise, a model's own departure from the process at rest, a
        // block mean's aliasing, is no load)
        let floor = T::of(1e-3) * (T::one() + level.abs());
        let sigma = at_least(deviation, floor);
        let dev = r - mean;
        let drift = T::of(WATCH_DRIFT) * sigma;
        let hi = at_least(hi + dev - drift, T::zero());
        let lo = at_least(lo - dev - drift, T::zero());
        let mean = if hi == T::zero() && lo == T::zero() {
            short * mean + (T::one() - short) * r
        } else {
            mean
        };
        lv.watch = [r, v, mean, hi, lo];
        if hi.max(lo) > T::of(WATCH_LIMIT) * sigma {
            self.levels_open(true);
        }
    }

    /// The estimator is awake (the input moved): the watch starts again at
    /// the next rest.
    pub(in crate::adapt) fn levels_wake(&mut self) {
        self.levels.watched = false;
    }
}
