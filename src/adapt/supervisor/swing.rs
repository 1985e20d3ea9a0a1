//! The control error's swings about the level it settles at: the
//! emergency path's second test for a growing oscillation (Hägglund
//! (1995)'s detection from the error's excursions between crossings, the
//! crossings of its level here rather than of zero).

use super::*;

/// The half-cycles of the control error about its level, and the run of
/// sustained ones under way.
///
/// A loop may settle away from its set point — the Smith predictor on an
/// integrating process holds an input load's offset `K·θ·d` (its
/// `K(1 − e^{−θs})/s` is `Kθ` at rest) — and oscillate about that: the
/// error keeps its sign and the half-cycles about zero never begin
/// (measured: a dead time 30 % longer on 0.15 e^{−5s}/s with input loads,
/// ten samples of dead time, the error between −1 and −2 for the first six
/// periods of a growing oscillation, the loop gone before the count
/// began). The level is the error's mean exponentially weighted over the
/// longest half-cycle's samples (an oscillation's period is a few dead
/// times: several of them), followed at every sample; a step of the level
/// is one long half-cycle, which does not count. The supervisor counts
/// these swings only once the error held its sign for longer than a
/// half-cycle can last (the loop settled away from its set point): with a
/// set point that moves, the error's level follows each move's transient,
/// and counted everywhere they set the emergency path off in the middle
/// of the bank's dead-time drifts (a drift's estimate applied and 4 of 30
/// cases lost); a level started only where the count starts (from the
/// error then, or from its mean over the half-cycle that held its sign)
/// took a quantized ring, and a load's response, for growing swings.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Swing<T> {
    level: T,
    /// The level's weight, `1/max_half`.
    weight: T,
    /// The swings count (the error held its sign longer than a
    /// half-cycle lasts since the set point last moved).
    counting: bool,
    side: i8,
    /// The current half-cycle's length and peak; the one before's peak.
    half: u32,
    peak: T,
    last: T,
    /// The peak of the half-cycle on the same side before (a period ago).
    before: T,
    /// The length of the half-cycle before.
    last_half: u32,
    /// In the run of sustained half-cycles under way: its length, those
    /// larger than the one before, and its first peak.
    run: u32,
    rising: u32,
    start: T,
}

impl<T: Real> Swing<T> {
    /// The level followed with the weight `1/max_half`, nothing counted.
    pub(super) fn new(max_half: u32) -> Self {
        Swing {
            weight: T::one() / T::of(f64::from(max_half.max(1))),
            ..Swing::default()
        }
    }

    /// The swings count from now (`true`), or no longer; the level goes
    /// on.
    pub(super) fn count(&mut self, counting: bool) {
        *self = Swing {
            level: self.level,
            weight: self.weight,
            counting,
            ..Swing::default()
        };
    }

    /// Whether the swings count.
    pub(super) fn counting(&self) -> bool {
        self.counting
    }

    /// One sample `e` of the control error: the level follows it; where
    /// the swings count, whether the oscillation about the level grows — a
    /// run of sustained half-cycles (`need` at least 1; each reaching
    /// `band`, at most `max_half` samples long, at least half the one
    /// before as `Adaptive::oscillation`'s, and of about the
    /// one before's length: within half the longer one and a sample),
    /// `need` of them larger by the band than the one a period before on
    /// the same side, and the envelope grown by half since the run began.
    /// Not each larger than the one before: a growing oscillation's peaks,
    /// sampled two to four times a half-cycle at ten samples of dead time,
    /// are larger and smaller in turn (measured: the case above under
    /// 0.5 % noise, the output 10⁵ times the step away with no four in a
    /// row); a limit cycle's, a quantized ring's, do not grow by half. Of
    /// one length and compared a period apart: a stable loop's responses
    /// to loads of two sizes, input and output in turn, are half-cycles of
    /// 30 to 140 samples, larger and smaller in turn, and counted as one
    /// run they grew (measured: 0.8 e^{−10s}/(4s + 1) with the lag ×1.6,
    /// ten samples of dead time, detuned as an emergency, 1.5 times the
    /// fixed loop's IAE). `band` is asked at a half-cycle's end only (a
    /// device's longest call, #48 item 7).
    pub(super) fn grows(
        &mut self,
        e: T,
        (band, max_half): (impl FnOnce() -> T, u32),
        need: u32,
    ) -> bool {
        let x = e - self.level;
        if !x.is_finite() {
            return false;
        }
        self.level = self.level + x * self.weight;
        if !self.counting {
            return false;
        }
        self.half = self.half.saturating_add(1);
        self.peak = at_least(self.peak, x.abs());
        let side = if x > T::zero() {
            1
        } else if x < T::zero() {
            -1
        } else {
            0
        };
        if side == 0 || side == self.side {
            return false;
        }
        if self.side != 0 {
            let bd = band();
            let counts = self.half <= max_half && self.peak > bd;
            let (h, l) = (self.half, self.last_half);
            let regular = 2 * h.abs_diff(l) <= h.max(l) + 2;
            let sustained = counts && regular && self.peak >= self.last / T::of(2.0);
            if sustained {
                if self.run == 0 {
                    (self.start, self.rising) = (self.peak, 0);
                }
                self.run += 1;
                self.rising += u32::from(self.before > T::zero() && self.peak > self.before + bd);
            } else {
                (self.run, self.rising) = (0, 0);
            }
            self.before = self.last;
            self.last = self.peak;
            self.last_half = self.half;
        }
        self.side = side;
        self.half = 0;
        self.peak = T::zero();
        self.rising >= need && self.last >= T::of(1.5) * self.start
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The swings of `x(k) = level + a(k)·s(k)`, `s` a square wave of
    /// `period` samples sampled with a phase that moves (the peaks larger
    /// and smaller in turn), from 0 to `n`: whether `grows` said so, and
    /// when.
    fn first_alarm(level: f64, a: impl Fn(f64) -> f64, n: usize) -> Option<usize> {
        let mut w = Swing::<f64>::new(40);
        // (the level settled where the count starts)
        for _ in 0..400 {
            w.grows(level, (|| 0.01, 40), 4);
        }
        w.count(true);
        (0..n).find(|&k| {
            let t = k as f64;
            let s = (2.0 * core::f64::consts::PI * t / 7.3).sin();
            let jitter = 1.0 + 0.3 * (t * 1.7).sin();
            w.grows(level + a(t) * s * jitter, (|| 0.01, 40), 4)
        })
    }

    /// About a level far from zero: a growing oscillation (its envelope
    /// ×1.05 a sample, a period of 7.3 samples) is found within a few
    /// periods though its sampled
    /// peaks are larger and smaller in turn; one of constant amplitude or
    /// dying out never is.
    #[test]
    fn a_growing_swing_about_its_level_is_found_and_a_steady_one_is_not() {
        // (the level settled first: a still error for 200 samples)
        let growing = |t: f64| {
            if t < 200.0 {
                0.0
            } else {
                0.1 * 1.05f64.powf(t - 200.0)
            }
        };
        let grows = first_alarm(-3.0, growing, 400);
        assert!(grows.is_some_and(|k| (200..240).contains(&k)), "{grows:?}");
        assert_eq!(first_alarm(-3.0, |_| 0.5, 400), None);
        assert_eq!(first_alarm(-3.0, |t| 0.5 * 0.99f64.powf(t), 400), None);
        assert_eq!(first_alarm(-3.0, |_| 0.0, 400), None);
    }

    /// Whether `grows` finds growth in half-cycles of the given lengths
    /// and peaks, in turn above and below a settled level (each a
    /// half-sine, the band 0.02, the longest half-cycle 140 samples).
    fn alarms(halves: &[(usize, f64)]) -> bool {
        let mut w = Swing::<f64>::new(140);
        w.count(true);
        let mut sign = 1.0;
        let mut alarmed = false;
        for &(n, peak) in halves {
            for j in 0..n {
                let x = sign * peak * (core::f64::consts::PI * (j as f64 + 0.5) / n as f64).sin();
                alarmed |= w.grows(x, (|| 0.02, 140), 4);
            }
            sign = -sign;
        }
        alarmed
    }

    /// A stable loop's responses to loads of two sizes, input and output
    /// in turn, as swings about the level (measured on 0.8 e^{−10s}/(4s + 1),
    /// lag ×1.6, ten samples of dead time: half-cycles of 124, 59 and 30
    /// samples peaking at 0.17, 0.29, 0.29, then 136, 58, 30 at 0.18, 0.30,
    /// 0.29, and so on; here the small ones a little larger, so that after
    /// the level's drift they keep half the one before, and the run goes
    /// on), are no growing oscillation: their lengths differ (without that
    /// rule, they alarm); half-cycles of one length larger and smaller in
    /// turn do not grow a period apart; a swing growing by a fifth a
    /// half-cycle does.
    #[test]
    fn loads_of_two_sizes_are_no_growing_swing() {
        let pattern = [
            (124, 0.22),
            (59, 0.29),
            (30, 0.29),
            (136, 0.23),
            (58, 0.296),
            (30, 0.294),
        ];
        let loads: Vec<_> = pattern.iter().cycle().take(60).copied().collect();
        assert!(!alarms(&loads));
        let growing: Vec<_> = (0..12).map(|i| (20, 0.1 * 1.2f64.powi(i))).collect();
        assert!(alarms(&growing));
        // (of one length, a fifth and a half in turn)
        let alternate: Vec<_> = (0..60)
            .map(|i| (20, if i % 2 == 0 { 0.1 } else { 0.5 }))
            .collect();
        assert!(!alarms(&alternate));
    }
}
