//! The noise a response's residual sums are judged against, and the tests
//! every model's fit passes by it (`levels.rs`): the model in use's, its
//! hypotheses', the factors between them, the other dead times', the
//! challenger's. One place, so that each weighs a response alike; and the
//! noise's measures in levels and, behind a converter, its rounding's.

use super::*;

/// The level test's noise is at least this fraction of the response's
/// energy per sample (its level's variance about its mean over the
/// response): a misfit of 1 % of the response in RMS is as much as it
/// tells apart where the noise measure reads less (noise-free data, a
/// converter's steps; measured on the bank: a 10-bit converter at rest
/// reads no noise, and the model's own 0.01 % of misfit was evidence).
pub(super) const FLOOR: f64 = 1e-4;

/// The drift test's threshold: the share of the best fit's residual a
/// drift regressor takes, in units of the noise's variance (`χ²` with one
/// degree of freedom: two standard deviations, passed by white residuals
/// 95 times in 100), beyond which a response holds a ramp load and teaches
/// nothing (measured on the bank: at three standard deviations, ramp loads
/// at the coarse period under 5 % noise still had models applied).
pub const DRIFT: f64 = 4.0;

/// The noise over one response: its variance per sample `σ²`, the residual
/// sum of squares pure noise leaves, `(n − p)·σ²` for `p` fitted
/// parameters, and three times that sum's spread, `3σ²·√(2(n − p))` (`χ²`
/// with `n − p` degrees of freedom; Söderström & Stoica (1989) Ch. 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Noise<T> {
    pub(super) sigma2: T,
    pub(super) noise: T,
    pub(super) spread: T,
    /// The rounding is the noise ([`Noise::undithered`]).
    rounded: bool,
}

impl<T: Real> Noise<T> {
    /// Over `n` samples with `params` parameters fitted: `σ²` the measured
    /// variance `measured`, at least half the best fit's residual `v_best`
    /// per degree of freedom (a noise measure that reads too little does
    /// not make every misfit evidence) and [`FLOOR`] of the response's
    /// `energy` per sample.
    pub(super) fn new(n: T, params: T, measured: T, v_best: T, energy: T) -> Self {
        let dof = at_least(n - params, T::one());
        let sigma2 = at_least(measured, v_best / (T::of(2.0) * dof));
        let sigma2 = at_least(sigma2, T::of(FLOOR) * energy / n);
        Noise {
            sigma2,
            noise: dof * sigma2,
            spread: T::of(3.0) * sigma2 * (T::of(2.0) * dof).sqrt(),
            rounded: false,
        }
    }

    /// The same noise, `rounded`: a converter's rounding is the noise, no
    /// noise dithering it ([`Noise::steady`]).
    pub(super) fn undithered(self, rounded: bool) -> Self {
        Noise { rounded, ..self }
    }

    /// A fit leaving `v` leaves the noise alone (within its spread).
    pub(super) fn fits(&self, v: T) -> bool {
        v - self.noise <= self.spread
    }

    /// A fit leaving `v` explains the response against the model in use's
    /// `v_ref`: to the noise, and at most [`EXPLAINED`] of the model in
    /// use's excess over it.
    pub(super) fn explains(&self, v: T, v_ref: T) -> bool {
        self.fits(v) && self.leaves(v, v_ref, T::of(EXPLAINED))
    }

    /// A fit leaving `v` leaves at most the share `share` of the model in
    /// use's excess over the noise, `v_ref − noise`.
    pub(super) fn leaves(&self, v: T, v_ref: T, share: T) -> bool {
        v - self.noise <= share * (v_ref - self.noise)
    }

    /// A fit leaving `v` explained the response better than the model in
    /// use's `v_ref`, to the noise (a streak's response).
    pub(super) fn better(&self, v: T, v_ref: T) -> bool {
        self.fits(v) && v < v_ref
    }

    /// The response stands out of the noise: the measurement's `energy`
    /// about its mean at least 1.5 times the noise's. A load the controller
    /// holds the measurement against shows in the input, and a model of a
    /// smaller gain, whose prediction of the input's move is nearer to a
    /// still measurement, explains it "better" (measured on the bank: ramp
    /// loads at the coarse period under 2 % noise, the measurement's
    /// variance within twice the noise's, had a halved gain and a doubled
    /// lag applied; a response within a converter's step, likewise). Not
    /// the differences' [`MATERIAL`] test: a doubled lag changes less than
    /// 1 % of a load's response in levels.
    pub(super) fn seen(&self, energy: T) -> bool {
        energy >= T::of(1.5) * self.noise
    }

    /// A fit whose drift regressor takes `drift` of its residual leaves no
    /// drift ([`DRIFT`]). Where the rounding is the noise, in units of its
    /// largest square, `(q/2)²`, three times its variance `q²/12`: without
    /// a noise that dithers it, the rounding's error is no independent
    /// uniform noise (Widrow, Kollár & Liu (1996)) but a function of the
    /// signal, bounded by half a quantum, and a regressor can take up to
    /// the bound's share of it (measured on the bank: a noise-free gain
    /// ×0.6 with loads behind a 10-bit converter, every response's best
    /// fit within the rounding and its drift 8 to 11 times the variance,
    /// none counted and the gain left at the first step, 0.7; now 44 of
    /// 45 such cases within 10 % of the true model's IAE, 41 before, and
    /// no model applied without a change behind converters of 8 to 12
    /// bits that was not applied before).
    pub(super) fn steady(&self, drift: T) -> bool {
        let bound = if self.rounded { 3.0 } else { 1.0 };
        drift <= T::of(DRIFT * bound) * self.sigma2
    }
}

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// The noise's standard deviation in levels: the target's noise is
    /// the first (integrating: second) difference of white noise, whose own
    /// differences the measure reads (variance `3σ²`, `10σ²`: `σ` is
    /// `1/√3`, `1/√10` of the measure's); at least a quantum's (`q/√12`,
    /// the rounding's uniform error: below it the measure of a converter's
    /// steps reads a still measurement as noise-free; Widrow & Kollár
    /// (2008)). No square root: the watch reads it every sample at rest.
    pub(super) fn level_deviation(&self) -> T {
        let (measured, rounding) = self.level_noises();
        at_least(measured, rounding)
    }

    /// The two parts of [`Estimator::level_deviation`]: the measured
    /// noise's and the rounding's.
    pub(super) fn level_noises(&self) -> (T, T) {
        let q = self.levels.quantum;
        let rounding = if q.is_finite() {
            q * T::of(0.288_675_134_594_812_9)
        } else {
            T::zero()
        };
        (self.noise_level() * self.level_share(), rounding)
    }

    /// The measured noise's standard deviation in levels over the
    /// measure's ([`Estimator::level_deviation`]): `1/√3`, integrating
    /// `1/√10`.
    fn level_share(&self) -> T {
        T::of(if self.cfg.integrating {
            0.316_227_766_016_837_94
        } else {
            0.577_350_269_189_625_8
        })
    }

    /// The noise the onset test measures a prediction error against
    /// ([`Estimator::noise_level`]'s measure), at least a converter's
    /// rounding's ([`Estimator::level_deviation`]'s floor, in the measure's
    /// unit): a still measurement behind a converter toggles between two
    /// steps, a difference of a quantum that the measure, its median near
    /// zero where the toggles are rare, reads as a load's onset (measured
    /// on the bank: a noise-free loop behind a 10-bit converter had an
    /// onset every three or four samples at rest, each opening a level
    /// response that the next one dropped, and the level test compared
    /// three responses in a run of forty loads; now the bank's lag ×1.6
    /// with loads 87 of 90 cases within 10 % of the true model's IAE, 81
    /// before). Only where the measurement is a converter's: its last
    /// [`GRID`] nonzero differences or more whole multiples of the quantum
    /// (the smallest difference of a continuous noise is no quantum, and
    /// one read from raw samples is none of the block means' either: an
    /// estimator fed the means, `spread_learning_is_the_learning_of_one_call`,
    /// had onsets the decimating one had not).
    pub(in crate::adapt) fn onset_noise(&self) -> T {
        if self.levels.on_grid < GRID {
            return self.noise_level();
        }
        let (_, rounding) = self.level_noises();
        at_least(self.noise_level(), rounding / self.level_share())
    }
}

/// The nonzero differences of the raw measurement in a row, each a whole
/// multiple of the smallest, that make it a converter's
/// ([`Estimator::onset_noise`]): a continuous noise's differences fall on
/// the grid of the smallest one by chance once in some 500 (within a
/// thousandth of a step either way), sixteen in a row never.
const GRID: u16 = 16;

/// The index and value of the largest of Page's sums `sums` (the first
/// where several are); `(0, 0)` where none is above zero.
pub(super) fn top<T: Real>(sums: impl IntoIterator<Item = T>) -> (usize, T) {
    sums.into_iter()
        .enumerate()
        .fold((0, T::zero()), |m, (i, s)| if s > m.1 { (i, s) } else { m })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The noise over 100 samples with two parameters: the measured
    /// variance where it is the largest, else half the best fit's residual
    /// per degree of freedom or the energy's floor; the residual of pure
    /// noise `98σ²` and its spread `3σ²√196 = 42σ²`; the tests at their
    /// edges (the drift's, where the rounding is the noise, at three times
    /// the variance).
    #[test]
    fn the_noise_and_its_tests() {
        let n = Noise::new(100.0, 2.0, 1.0, 98.0, 1.0);
        assert_eq!(
            n,
            Noise {
                sigma2: 1.0,
                noise: 98.0,
                spread: 42.0,
                rounded: false,
            }
        );
        assert_eq!(Noise::new(100.0, 2.0, 1.0, 392.0, 1.0).sigma2, 2.0);
        let floor: f64 = Noise::new(100.0, 2.0, 1.0, 1.0, 3e6).sigma2;
        assert!((floor - 3.0).abs() <= 1e-14, "{floor}");
        assert!(n.fits(140.0) && !n.fits(140.5));
        // at most a quarter of the excess 98 + 160 leaves
        assert!(n.explains(138.0, 258.0) && !n.explains(139.0, 258.0));
        assert!(n.leaves(114.0, 258.0, 0.1) && !n.leaves(114.5, 258.0, 0.1));
        assert!(n.better(139.0, 140.0) && !n.better(140.0, 140.0));
        assert!(n.seen(147.0) && !n.seen(146.0));
        assert!(n.steady(DRIFT) && !n.steady(DRIFT + 0.5));
        // the rounding as the noise: its largest square, three variances
        let r = n.undithered(true);
        assert!(r.steady(3.0 * DRIFT) && !r.steady(3.0 * DRIFT + 0.5));
        assert_eq!(r.undithered(false), n);
        assert_eq!(top([0.0, 2.0, 1.0, 2.0]), (1, 2.0));
        assert_eq!(top([0.0, 0.0]), (0, 0.0));
    }
}
