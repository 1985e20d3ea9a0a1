//! The input history an [`super::Estimator`] reads, and the running median
//! it measures jitter and noise with.

use crate::real::{at_least, at_most, Real};

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
            // (a median that decays to nothing restarts from the next value
            // rather than pass through the subnormal numbers)
            crate::real::normal(
                self.value
                    * if m > self.value {
                        T::one() + step
                    } else {
                        T::one() - step
                    },
            )
        } else {
            m
        };
        self.value
    }
}

/// The median of five numbers by a selection network of seven comparisons
/// (no sort, no branch): `med₃(e, max(min(a, b), min(c, d)),
/// min(max(a, b), max(c, d)))` — the pairs' larger minimum and smaller
/// maximum bound two numbers from each side, and `e` decides between them
/// (checked against a sort in the tests).
pub(crate) fn median5<T: Real>([a, b, c, d, e]: [T; 5]) -> T {
    let f = at_least(at_most(a, b), at_most(c, d));
    let g = at_most(at_least(a, b), at_least(c, d));
    at_least(at_most(f, g), at_most(at_least(f, g), e))
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
    /// The excitation gate's threshold, and how many entries ago a move
    /// reached it, `ratio` times the jitter and [`FLOOR`] of the largest
    /// move of late (0: the newest).
    gate: T,
    pub(crate) quiet: usize,
    /// The gate's threshold relative to the input's jitter, and the jitter:
    /// a running median of `|Δu|` (what noise through the controller moves
    /// the input by when nothing else does).
    ratio: T,
    jitter: Median<T>,
    /// How many entries ago `Δu` departed from its drift by the gate's
    /// amount, and the drift: an exponential mean of `Δu` with the step
    /// `drift_step` (`m ← m + β·(med₅Δu − m)`, the median of the last five
    /// `Δu`). A ramp load holds the controller's `Δu` at a constant that
    /// no model of the process explains without the load (the output's
    /// differences are zero there, the models predict the constant through
    /// their gain), and a gate on `|Δu|` alone lets the bank learn from all
    /// of it (measured: a gain 2.3 estimated 1.91 over a few ramps, 10-bit
    /// converter, and applied); the bank learns only after departures from
    /// the drift (a ramp's start and end, not its steady part). The
    /// comparisons with the model in use and its hypotheses keep the plain
    /// gate: they only hold back or propose what a response shows, and a
    /// loop that only loads move shows a change in the controller's slow
    /// answer to them (measured: with the drift's gate there too, a gain
    /// halved on 0.8 e^{−10s}/(4s + 1) at ten samples of dead time was
    /// never proposed).
    pub(crate) steady: usize,
    drift: T,
    drift_step: T,
    /// The largest `|Δu|` of late, forgotten at the drift's step (`p ←
    /// max(|Δu|, (1 − β)·p)`): a move under [`FLOOR`] of it is no move.
    peak: T,
}

/// The least move, as a fraction of the largest of late, that the gate
/// counts. A sample's share of the information the bank's least squares
/// gather is its regressor's square (`φφᵀ`, the input's moves and the
/// model's answer to them: the estimate's covariance is the noise's
/// variance over `Σψψᵀ`, Ljung (1999) Sec. 9.3), so a move under 1 % of
/// the largest one within the memory adds under 10⁻⁴ of that move's:
/// nothing the bank can resolve. Without it a loop without noise (a
/// simulation, a converter finer than the loop's jitter) keeps the bank
/// learning along the input's exponential approach to its new level until
/// the moves fall under the absolute gate, 10⁻⁶ of a unit move some
/// fourteen closed-loop time constants later. Measured: the bench's cycle
/// (`benches/controllers.rs`) learns in 29 % fewer samples, and the bank
/// (`docs/adapt-bank.md`) moved by one median in the third decimal.
pub(crate) const FLOOR: f64 = 0.01;

impl<T: Real, const H: usize> History<T, H> {
    /// A history with the prefilter's pole, the gate's threshold, its
    /// ratio to the jitter and the drift's step.
    pub(crate) fn new(pole: T, gate: T, ratio: T, drift_step: T) -> Self {
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
            steady: usize::MAX,
            drift: T::zero(),
            drift_step,
            peak: T::zero(),
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
        self.peak = crate::real::normal(at_least(m, self.peak - self.drift_step * self.peak));
        let floor = T::of(FLOOR) * self.peak;
        let moves = |m: T| m >= self.gate && m >= self.ratio * jitter && m >= floor;
        self.quiet = if moves(m) {
            0
        } else {
            self.quiet.saturating_add(1)
        };
        // the departure from the drift; the drift follows the median of the
        // last five `Δu` (this one's and four before): a step's pulse, or
        // its two parts when it falls inside a block of means, does not
        // pull it (no echo of a step counted as moves after it), a ramp's
        // steady `Δu` does
        let departed = moves((du - self.drift).abs());
        self.steady = if departed {
            0
        } else {
            self.steady.saturating_add(1)
        };
        let last = self.from(0);
        let at = |i: usize| last.get(i).copied().unwrap_or(T::zero());
        let persistent = median5([du, at(0), at(1), at(2), at(3)]);
        self.drift = crate::real::normal(self.drift + self.drift_step * (persistent - self.drift));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A move under [`FLOOR`] of the largest of late is no move: after a
    /// step, the input's approach to its new level (`Δu = 0.1·e^{−k/10}`,
    /// jitter of 10⁻⁸ before it) stops counting where it falls under 1 %
    /// of the step's move forgotten at the drift's step, `0.1·(1 − β)^k`:
    /// at `k = ln 100/(1/10 + ln(1 − β))` (≈ 95 for β = 1/20), not where it
    /// meets ten times the jitter, whose median rises a percent a sample
    /// toward it (125 without the floor).
    #[test]
    fn a_tail_under_a_hundredth_of_the_move_is_no_move() {
        let beta = 1.0 / 20.0;
        let mut h: History<f64, 8> = History::new(0.0, 1e-12, 10.0, beta);
        let mut u = 0.0;
        for j in 0..400 {
            u += if j % 2 == 0 { 1e-8 } else { -1e-8 };
            h.push(u);
        }
        let mut last_move = None;
        for k in 0..400 {
            u += 0.1 * (-(k as f64) / 10.0).exp();
            h.push(u);
            if h.quiet == 0 {
                last_move = Some(k);
            }
        }
        let end = 100f64.ln() / (0.1 + (1.0 - beta).ln());
        let last = last_move.map_or(-1.0, |k| k as f64);
        assert!((last - end).abs() <= 1.0, "{last} against {end}");
    }
}
