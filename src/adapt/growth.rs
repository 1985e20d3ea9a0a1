//! The model in use's simulation error, window by window: the emergency
//! path's third test for a loop going unstable, one that neither a set
//! point's moves nor the half-cycles' shape can hide.
//!
//! The error `ε` of the model in use's simulation of the estimator's
//! target (`Δy`, integrating `Δ²y`) is the loads' and the noise's alone
//! while the model is right, whatever the set point does: a load's step is
//! an impulse in it (its lag's decay after), a ramp a constant. A loop
//! going unstable drives it with a growing oscillation. So the peaks of
//! `|ε|` over windows of twice the model's dead time that grow by a
//! quarter from each window to the next, `RISES` times in a row, from a
//! window above the noise, are a growing oscillation: Hägglund's (1995)
//! detection from the error's excursions, its crossings replaced by
//! windows. Measured: an integrating process's dead time ×0.75 at a
//! thousand samples of dead time, its oscillation's half-cycles of one to
//! five estimator samples, larger and smaller in turn, none of the
//! half-cycle counts grew four in a row, and the set point's moves, each
//! starting them again, came every eight dead times: the output 5·10⁴
//! times the step away before the emergency path acted.

use super::*;

/// Windows, each with the peak a quarter above the one before, that make a
/// growing oscillation.
pub(super) const RISES: u32 = 3;

/// The ratio of a window's peak to the one before that counts as a rise.
const RISE: f64 = 1.25;

/// The peaks of the model in use's simulation error over windows, and the
/// rises in a row.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Growth<T> {
    peak: T,
    n: u32,
    last: T,
    rises: u32,
}

impl<T: Real> Growth<T> {
    /// One sample's error `e` in windows of `len` samples; a window's peak
    /// above `band` starts a run, and each next one a quarter larger
    /// carries it on.
    pub(super) fn add(&mut self, e: T, len: u32, band: T) {
        self.peak = at_least(self.peak, e.abs());
        self.n = self.n.saturating_add(1);
        if self.n < len {
            return;
        }
        let rose = self.last > band && self.peak >= T::of(RISE) * self.last;
        self.rises = if rose {
            self.rises.saturating_add(1)
        } else {
            0
        };
        self.last = self.peak;
        (self.peak, self.n) = (T::zero(), 0);
    }

    /// The last window's peak, where the windows' peaks rose `RISES` times
    /// in a row.
    pub(super) fn grown(&self) -> Option<T> {
        (self.rises >= RISES).then_some(self.last)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first window (of 20 samples) whose end finds growth in
    /// `x(k)`.
    fn first(x: impl Fn(f64) -> f64, n: usize) -> Option<usize> {
        let mut g = Growth::<f64>::default();
        (0..n).find(|&k| {
            g.add(x(k as f64), 20, 0.05);
            g.grown().is_some()
        })
    }

    /// A growing oscillation of irregular half-cycles is found within
    /// four windows of leaving the noise; one of constant or decaying
    /// amplitude, a ramp's constant error, impulses (loads' steps) of two
    /// sizes in turn, the noise alone, never are.
    #[test]
    fn growth_is_found_and_steady_or_decaying_errors_are_not() {
        let wave = |t: f64| (t * 0.9).sin() + 0.5 * (t * 2.3).sin();
        let grows = first(|t| 0.02 * 1.02f64.powf(t) * wave(t), 2000);
        // (above the band 0.05 from about t = 60; four windows on)
        assert!(grows.is_some_and(|k| (80..200).contains(&k)), "{grows:?}");
        assert_eq!(first(wave, 2000), None);
        assert_eq!(first(|t| 0.99f64.powf(t) * wave(t), 2000), None);
        assert_eq!(first(|_| 0.3, 2000), None);
        let loads = |t: f64| {
            let k = t as usize;
            match k % 160 {
                0 => 1.0,
                80 => 0.4,
                _ => 0.0,
            }
        };
        assert_eq!(first(loads, 4000), None);
        let noise = |t: f64| 0.01 * ((t * 12.9898).sin() * 43_758.545).fract();
        assert_eq!(first(noise, 4000), None);
    }
}
