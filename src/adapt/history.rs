//! The input history an [`super::Estimator`] reads, and the running median
//! it measures jitter and noise with.

use crate::real::Real;

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
