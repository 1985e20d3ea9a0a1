//! The settings of a [`super::Pid`]: its gains in either form, weights,
//! filter, limits, rate limit and anti-windup, and their checks.

use super::*;

/// Parameters of a [`Pid`]. Build with [`PidConfig::isa`] or [`PidConfig::parallel`]
/// and the `with_*` methods; [`Pid::new`] validates every field.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PidConfig<T> {
    /// Proportional gain `kp`.
    pub kp: T,
    /// Integral gain `ki = Kp/Ti` (1/s); zero for P and PD.
    pub ki: T,
    /// Derivative gain `kd = Kp·Td` (s); zero for P and PI.
    pub kd: T,
    /// Derivative filter time constant `Tf = Td/N` (s); zero for an unfiltered derivative.
    pub tf: T,
    /// Set-point weight of the proportional term.
    pub b: T,
    /// Set-point weight of the derivative term (0: no derivative kick).
    pub c: T,
    /// Lower output limit.
    pub u_min: T,
    /// Upper output limit.
    pub u_max: T,
    /// Largest output change per second (infinite: none).
    pub rate_limit: T,
    /// Anti-windup method.
    pub anti_windup: AntiWindup<T>,
    /// Sample period `Ts` (s).
    pub ts: T,
}

impl<T: Real> PidConfig<T> {
    /// ISA (standard) form `Kp(1 + 1/(Ti s) + Td s)`. `ti = ∞` removes the
    /// integral action, `td = 0` the derivative. The derivative filter defaults
    /// to `N = 10`, the weights to `b = c = 1`, anti-windup to back-calculation
    /// with `Tt = √(Ti·Td)` (`Ti` for PI), no limits. Nothing is validated here.
    pub fn isa(kp: T, ti: T, td: T, ts: T) -> Self {
        let ki = if ti.is_infinite() && ti > T::zero() {
            T::zero()
        } else {
            kp / ti
        };
        let tt = if td > T::zero() && ti.is_finite() {
            (ti * td).sqrt()
        } else {
            ti
        };
        let base = Self::parallel(kp, ki, kp * td, ts);
        PidConfig {
            tf: td / T::of(10.0),
            anti_windup: if ki == T::zero() {
                AntiWindup::None
            } else {
                AntiWindup::BackCalculation { tt }
            },
            ..base
        }
    }

    /// [`PidConfig::isa`] with its own arguments checked, so that an error names
    /// the value the caller gave: `ti` must be greater than zero (infinite
    /// turns the integral off), `td` must not be negative, `kp` and `ts` finite.
    pub fn try_isa(kp: T, ti: T, td: T, ts: T) -> Result<Self, Error> {
        finite(kp, "kp")?;
        if ti.is_nan() {
            return Err(Error::NonFinite("ti"));
        }
        if !(ti > T::zero()) {
            return Err(Error::NotPositive("ti"));
        }
        non_negative(td, "td")?;
        positive(ts, "ts")?;
        // the parallel gains kp/ti and kp·td must exist: a message names the
        // ISA value that breaks them, not the derived one
        if !(kp / ti).is_finite() {
            return Err(Error::OutOfRange("ti"));
        }
        // and so must the tracking time √(Ti·Td) that isa derives
        if !(kp * td).is_finite() || !(ti.is_infinite() || (ti * td).sqrt().is_finite()) {
            return Err(Error::OutOfRange("td"));
        }
        Ok(Self::isa(kp, ti, td, ts))
    }

    /// Parallel form `kp + ki/s + kd s` (with the same defaults as [`PidConfig::isa`];
    /// the filter is `Tf = kd/(10·kp)` when `kp ≠ 0`). A reverse-acting
    /// controller (for a plant of negative gain) has all three gains negative.
    pub fn parallel(kp: T, ki: T, kd: T, ts: T) -> Self {
        let tf = if kp != T::zero() {
            (kd / (kp * T::of(10.0))).abs()
        } else {
            T::zero()
        };
        let tt = if ki != T::zero() && kp != T::zero() {
            (kp / ki).abs()
        } else {
            ts
        };
        PidConfig {
            kp,
            ki,
            kd,
            tf,
            b: T::one(),
            c: T::one(),
            u_min: T::neg_infinity(),
            u_max: T::infinity(),
            rate_limit: T::infinity(),
            anti_windup: if ki == T::zero() {
                AntiWindup::None
            } else {
                AntiWindup::BackCalculation { tt }
            },
            ts,
        }
    }

    /// Output limits `[u_min, u_max]`.
    pub fn with_limits(mut self, u_min: T, u_max: T) -> Self {
        self.u_min = u_min;
        self.u_max = u_max;
        self
    }
    /// Derivative filter `Tf = Td/N` (`N` typically 5–20).
    pub fn with_filter(mut self, n: T) -> Self {
        let td = if self.kp != T::zero() {
            self.kd / self.kp
        } else {
            T::zero()
        };
        self.tf = if n.is_infinite() { T::zero() } else { td / n };
        self
    }
    /// Derivative filter time constant `Tf` directly (s).
    pub fn with_filter_time(mut self, tf: T) -> Self {
        self.tf = tf;
        self
    }
    /// Set-point weights `b` (proportional) and `c` (derivative).
    pub fn with_weights(mut self, b: T, c: T) -> Self {
        self.b = b;
        self.c = c;
        self
    }
    /// Anti-windup method.
    pub fn with_anti_windup(mut self, aw: AntiWindup<T>) -> Self {
        self.anti_windup = aw;
        self
    }
    /// Largest output change per second.
    pub fn with_rate_limit(mut self, per_second: T) -> Self {
        self.rate_limit = per_second;
        self
    }

    /// Integral time `Ti = kp/ki` (∞ without integral action).
    pub fn ti(&self) -> T {
        if self.ki == T::zero() {
            T::infinity()
        } else {
            self.kp / self.ki
        }
    }
    /// Derivative time `Td = kd/kp`.
    pub fn td(&self) -> T {
        if self.kp == T::zero() {
            T::zero()
        } else {
            self.kd / self.kp
        }
    }

    /// Checks every field; the error names the first one that is wrong.
    pub fn validate(&self) -> Result<(), Error> {
        finite(self.kp, "kp")?;
        // direct acting: kp, ki, kd ≥ 0; reverse acting (a plant of negative
        // gain): all ≤ 0. A term of the other sign would act against the others.
        if self.kp < T::zero() {
            if finite(self.ki, "ki")? > T::zero() {
                return Err(Error::OutOfRange("ki"));
            }
            if finite(self.kd, "kd")? > T::zero() {
                return Err(Error::OutOfRange("kd"));
            }
        } else {
            non_negative(self.ki, "ki")?;
            non_negative(self.kd, "kd")?;
        }
        non_negative(self.tf, "tf")?;
        finite(self.b, "b")?;
        finite(self.c, "c")?;
        positive(self.ts, "ts")?;
        if self.u_min.is_nan() {
            return Err(Error::NonFinite("u_min"));
        }
        if self.u_max.is_nan() {
            return Err(Error::NonFinite("u_max"));
        }
        if self.u_min > self.u_max {
            return Err(Error::InvalidLimits("u_min"));
        }
        if self.u_min == T::infinity() {
            return Err(Error::NonFinite("u_min"));
        }
        if self.u_max == T::neg_infinity() {
            return Err(Error::NonFinite("u_max"));
        }
        if self.rate_limit.is_nan() {
            return Err(Error::NonFinite("rate_limit"));
        }
        if !(self.rate_limit > T::zero()) {
            return Err(Error::NotPositive("rate_limit"));
        }
        if let AntiWindup::BackCalculation { tt } = self.anti_windup {
            positive(tt, "tt")?;
        }
        Ok(())
    }
}
