//! One model's fit over a response of the level test: its simulation from
//! the response's start, the residual in levels, the load's regressor and
//! the sums of the least-squares problem (see `levels.rs`).

use super::*;

/// One model's fit over a response: its simulation, the residual's level,
/// the load's regressor and the sums of the least-squares problem.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fit<T> {
    /// The model's simulated difference `Δŷ[k]` from the response's start.
    pub(super) x: T,
    /// The residual's first sum (an integrating model's target is the
    /// second difference).
    pub(super) v: T,
    /// The residual in levels.
    pub(super) r: T,
    /// The load's regressor `q[k]`.
    pub(super) q: T,
    /// `Σr, Σr², Σr·q, Σq, Σq², Σr·p, Σq·p` (`p` the drift's regressor).
    pub(super) s: [T; 7],
}

impl<T: Real> Fit<T> {
    /// One sample of the response: the model `coef` (its inputs `u`) on
    /// the target `target`, the drift's regressor `p`.
    #[inline(always)]
    pub(super) fn step(&mut self, coef: [T; 3], u: (T, T), target: T, p: T, integrating: bool) {
        self.x = predict(coef, self.x, u, integrating);
        let e = target - self.x;
        if integrating {
            self.v = self.v + e;
            self.r = self.r + self.v;
        } else {
            self.r = self.r + e;
        }
        let pole = if integrating { T::one() } else { coef[0] };
        self.q = pole * self.q + T::one();
        let [sr, srr, srq, sq, sqq, srp, sqp] = self.s;
        let (r, q) = (self.r, self.q);
        self.s = [
            sr + r,
            srr + r * r,
            srq + r * q,
            sq + q,
            sqq + q * q,
            srp + r * p,
            sqp + q * p,
        ];
    }

    pub(super) fn zero() -> Self {
        Fit {
            x: T::zero(),
            v: T::zero(),
            r: T::zero(),
            q: T::zero(),
            s: [T::zero(); 7],
        }
    }

    /// The residual sum of squares after the least-squares fit of
    /// `c0 + c1·q` (of `c0` alone where `q` is nearly constant over the
    /// response: a lag far shorter than the period), and how much of it a
    /// drift `c2·p[k]` would take (the third regressor's share: the LDLᵀ
    /// factors of the regressors' Gram matrix, `z = L⁻¹b`, the residual
    /// `Σr² − z1²/D1 − z2²/D2` and the drift's `z3²/D3`; Golub & Van Loan
    /// (2013) Sec. 4.1), over `n` samples with `Σp, Σp²` `p`.
    pub(super) fn rss(&self, n: T, [sp, spp]: [T; 2]) -> (T, T) {
        let [sr, srr, srq, sq, sqq, srp, sqp] = self.s;
        if !(n > T::zero()) {
            return (srr, T::zero());
        }
        let tiny = T::epsilon();
        let (l21, l31) = (sq / n, sp / n);
        let (z1, d2) = (sr, sqq - l21 * sq);
        let z2 = srq - l21 * z1;
        let mut rss = srr - z1 * z1 / n;
        let mut l32 = T::zero();
        if d2 > tiny * sqq {
            rss = rss - z2 * z2 / d2;
            l32 = (sqp - l31 * sq) / d2;
        }
        let (d3, z3) = (spp - l31 * sp - l32 * l32 * d2, srp - l31 * z1 - l32 * z2);
        let drift = if d3 > tiny * spp {
            z3 * z3 / d3
        } else {
            T::zero()
        };
        (at_least(rss, T::zero()), drift)
    }
}
