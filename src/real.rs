//! The one numeric bound every block is generic over.

use core::fmt::{Debug, Display};

/// A floating-point sample type: `f32` for microcontrollers, `f64` for hosts.
///
/// All numeric code in `msp` is written once against this trait; there are no
/// per-type copies. Transcendental functions come from the platform with `std`
/// and from `libm` without it (through `num_traits::Float`).
pub trait Real:
    num_traits::Float + num_traits::FloatConst + Default + Debug + Display + Send + Sync + 'static
{
    /// Converts an `f64` constant or parameter to this type (rounding for `f32`).
    fn of(x: f64) -> Self;
    /// Widens to `f64` (exact for both `f32` and `f64`).
    fn f64(self) -> f64;
    /// The constant 2.
    #[inline(always)]
    fn two() -> Self {
        Self::one() + Self::one()
    }
    /// The constant 1/2.
    #[inline(always)]
    fn half() -> Self {
        Self::of(0.5)
    }
}

impl Real for f32 {
    #[inline(always)]
    #[allow(clippy::cast_possible_truncation)]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    #[inline(always)]
    fn of(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn f64(self) -> f64 {
        self
    }
}

/// Checks that `x` is finite.
#[inline]
pub(crate) fn finite<T: Real>(x: T, field: &'static str) -> Result<T, crate::Error> {
    x.is_finite()
        .then_some(x)
        .ok_or(crate::Error::NonFinite(field))
}

/// Checks that `x` is finite and strictly positive.
#[inline]
pub(crate) fn positive<T: Real>(x: T, field: &'static str) -> Result<T, crate::Error> {
    (finite(x, field)? > T::zero())
        .then_some(x)
        .ok_or(crate::Error::NotPositive(field))
}

/// Checks that `x` is finite and not negative.
#[inline]
pub(crate) fn non_negative<T: Real>(x: T, field: &'static str) -> Result<T, crate::Error> {
    (finite(x, field)? >= T::zero())
        .then_some(x)
        .ok_or(crate::Error::Negative(field))
}

/// `x` limited to `[lo, hi]` by comparisons (on a Cortex-M4 `f32::max`/`min`
/// are library calls; a NaN `x` passes through unchanged).
#[inline(always)]
pub(crate) fn clamp<T: Real>(x: T, lo: T, hi: T) -> T {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// The larger of `x` and `lo` by one comparison: `x.max(lo)` for a bound
/// that is not NaN (a NaN `x` gives `lo`, as `max` does), without the
/// library call `max` is on a Cortex-M4.
#[inline(always)]
pub(crate) fn at_least<T: Real>(x: T, lo: T) -> T {
    if x >= lo {
        x
    } else {
        lo
    }
}

/// The smaller of `x` and `hi` by one comparison: `x.min(hi)` for a bound
/// that is not NaN (a NaN `x` gives `hi`), without a library call.
#[inline(always)]
pub(crate) fn at_most<T: Real>(x: T, hi: T) -> T {
    if x <= hi {
        x
    } else {
        hi
    }
}
