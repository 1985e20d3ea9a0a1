//! The common blocks: a first-order lag and an integrator in closed form,
//! a lead-lag and a second-order block through [`Lti::from_tf`].

use super::{Discretization, Lti};
use crate::real::{finite, positive};
use crate::{error::Error, real::Real};

impl<T: Real, const N: usize> Lti<T, N> {
    /// First-order lag `k/(τ s + 1)`, ZOH-discretized: `y[k+1] = a y[k] + k(1−a) u[k]`,
    /// `a = e^{−Ts/τ}`. A negative `τ` gives the unstable `k/(τ s + 1)` pole at `−1/τ`.
    ///
    /// In closed form, in this precision (a few dozen instructions where
    /// [`Lti::from_tf`]'s matrix exponential in `f64` costs thousands on a
    /// microcontroller without a double-precision unit: an adaptive
    /// controller discretizes each model it applies), in the realization
    /// `from_tf` gives: `(k/τ)/(s + 1/τ)`, `A = −1/τ`, `B = 1`, `C = k/τ`, so
    /// `Φ = e^{−Ts/τ}` and `Γ = ∫₀^Ts e^{−t/τ} dt = −τ·(e^{−Ts/τ} − 1)`, the
    /// difference from 1 by `exp_m1`, exact where `Ts ≪ τ` (Franklin, Powell
    /// & Workman, Sec. 4.3).
    pub fn first_order(k: T, tau: T, ts: T) -> Result<Self, Error> {
        let (k, tau, ts) = (finite(k, "k")?, finite(tau, "tau")?, positive(ts, "ts")?);
        if tau == T::zero() {
            return Err(Error::NotPositive("tau"));
        }
        let x = -ts / tau;
        Self::scalar(x.exp(), -tau * x.exp_m1(), k / tau)
    }

    /// Integrator `k/s`, ZOH-discretized: `y[k+1] = y[k] + k·Ts·u[k]`; in
    /// closed form, in `from_tf`'s realization (`A = 0`, `B = 1`, `C = k`:
    /// `Φ = 1`, `Γ = Ts`).
    pub fn integrator(k: T, ts: T) -> Result<Self, Error> {
        let (k, ts) = (finite(k, "k")?, positive(ts, "ts")?);
        Self::scalar(T::one(), ts, k)
    }

    /// The first-order block `x[k+1] = φ·x[k] + γ·u[k]`, `y = c·x`.
    fn scalar(phi: T, gamma: T, c: T) -> Result<Self, Error> {
        if N == 0 {
            return Err(Error::OrderTooHigh("den"));
        }
        let mut out = Lti {
            phi: [[T::zero(); N]; N],
            gamma: [T::zero(); N],
            c: [T::zero(); N],
            d: T::zero(),
            x: [T::zero(); N],
            n: 1,
        };
        if let Some(p) = out.phi.first_mut().and_then(|row| row.first_mut()) {
            *p = phi;
        }
        if let Some(g) = out.gamma.first_mut() {
            *g = gamma;
        }
        if let Some(o) = out.c.first_mut() {
            *o = c;
        }
        out.check_finite()
    }

    /// Lead-lag `k(a s + 1)/(b s + 1)`, ZOH-discretized; `a = b = 0` is the
    /// static gain `k` (a filter or a derivative switched off), `a > 0` needs
    /// `b > 0` (a proper block).
    ///
    /// In closed form, in this precision (as [`Lti::first_order`]: an
    /// adaptive Karan–Dey predictor designs its disturbance path's lead-lag
    /// for each model it applies), in the realization `from_tf` gives: the
    /// feedthrough `D = k·a/b` and the rest `k(1 − a/b)/(b s + 1)`, i.e.
    /// `A = −1/b`, `B = 1`, `C = k(b − a)/b²`, `Φ = e^{−Ts/b}`,
    /// `Γ = −b·(e^{−Ts/b} − 1)` (the ZOH equivalent of a first-order
    /// state model, Franklin, Powell & Workman, Sec. 4.3).
    pub fn lead_lag(k: T, a: T, b: T, ts: T) -> Result<Self, Error> {
        if a == T::zero() && b == T::zero() {
            return Self::gain(k);
        }
        let (k, a) = (finite(k, "k")?, finite(a, "a")?);
        let (b, ts) = (positive(b, "b")?, positive(ts, "ts")?);
        let x = -ts / b;
        let mut out = Self::scalar(x.exp(), -b * x.exp_m1(), k * (b - a) / (b * b))?;
        out.d = k * a / b;
        out.check_finite()
    }

    /// Second-order block `k ωₙ²/(s² + 2ζωₙ s + ωₙ²)`, ZOH-discretized.
    pub fn second_order(k: T, wn: T, zeta: T, ts: T) -> Result<Self, Error> {
        let wn = positive(wn, "wn")?;
        let zeta = finite(zeta, "zeta")?;
        Self::from_tf(
            &[finite(k, "k")? * wn * wn],
            &[T::one(), T::two() * zeta * wn, wn * wn],
            ts,
            Discretization::Zoh,
        )
    }
}
