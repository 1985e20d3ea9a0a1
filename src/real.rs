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
    /// The largest control error a controller computes with (so the
    /// largest set point or measurement, the other being small):
    /// 2³² (4.3·10⁹) in `f32`, 2²⁵⁶ (1.2·10⁷⁷) in `f64`, the fourth root
    /// of the largest number: a predictor's filters multiply a measurement
    /// by gains and their states by it again, and at √MAX one product of
    /// them overflows (a finite spike then poisons the state for good).
    const USABLE: Self;
    /// Whether `self` can be computed with: `|x| ≤ USABLE`. A controller
    /// asks it of its control error `r − y` (one comparison, as the test
    /// for NaN and ±∞ it replaces; a set point or measurement beyond the
    /// bound makes the error so): NaN, ±∞ and a finite number beyond it are
    /// a fault alike, the output held and the fault raised until the inputs
    /// are usable again (no state computed from them).
    #[inline(always)]
    fn usable(self) -> bool {
        self.abs() <= Self::USABLE
    }
    /// `self` and `other` usable together: `|self| + |other| ≤ USABLE`,
    /// one comparison (NaN and ±∞ fail it); the adaptive estimator's test
    /// of a measurement and the input the plant received.
    #[inline(always)]
    fn usable_with(self, other: Self) -> bool {
        self.abs() + other.abs() <= Self::USABLE
    }
}

impl Real for f32 {
    const USABLE: Self = 4_294_967_296.0; // 2^32
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
    // 2^256
    const USABLE: Self = 1.157920892373162e77;
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
pub(crate) fn finite<T: Real>(x: T, field: &'static str) -> Result<T, crate::error::Error> {
    x.is_finite()
        .then_some(x)
        .ok_or(crate::error::Error::NonFinite(field))
}

/// Checks that `x` is finite and strictly positive.
#[inline]
pub(crate) fn positive<T: Real>(x: T, field: &'static str) -> Result<T, crate::error::Error> {
    (finite(x, field)? > T::zero())
        .then_some(x)
        .ok_or(crate::error::Error::NotPositive(field))
}

/// Checks that `x` is finite and not negative.
#[inline]
pub(crate) fn non_negative<T: Real>(x: T, field: &'static str) -> Result<T, crate::error::Error> {
    (finite(x, field)? >= T::zero())
        .then_some(x)
        .ok_or(crate::error::Error::Negative(field))
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

/// `b` within the fraction `rel` of `a` (either infinite: equal).
pub(crate) fn near<T: Real>(a: T, b: T, rel: T) -> bool {
    if a.is_infinite() || b.is_infinite() {
        return a == b;
    }
    (a - b).abs() <= rel * a.abs()
}

/// The larger of `x` and `lo` by one comparison: `x.max(lo)` for a bound
/// that is not NaN (a NaN `x` gives `lo`, as `max` does), without the
/// library call `max` is on a Cortex-M4. The strict comparison is x86's
/// `maxsd` (`x > lo ? x : lo`), one instruction where `x >= lo` took four
/// (a compare and a blend); equal ones give `lo` (the same number, but for
/// the sign of a zero).
#[inline(always)]
pub(crate) fn at_least<T: Real>(x: T, lo: T) -> T {
    if x > lo {
        x
    } else {
        lo
    }
}

/// The smaller of `x` and `hi` by one comparison: `x.min(hi)` for a bound
/// that is not NaN (a NaN `x` gives `hi`), without a library call (x86's
/// `minsd`, as [`at_least`]).
#[inline(always)]
pub(crate) fn at_most<T: Real>(x: T, hi: T) -> T {
    if x < hi {
        x
    } else {
        hi
    }
}

/// `x`, or 0 where it is subnormal (`|x|` below the smallest normal
/// number): a state that decays geometrically without input (a filter at
/// rest, a discounted sum of zero errors) would otherwise reach the
/// subnormal range, where each operation on a host costs a hundred times a
/// normal one (measured: an adaptive loop at rest went from 19 to 65 ns a
/// sample). One comparison and a select.
#[inline(always)]
pub(crate) fn normal<T: Real>(x: T) -> T {
    if x.abs() >= T::min_positive_value() {
        x
    } else {
        T::zero()
    }
}

/// The index and value of the smallest of `xs`, the first where several
/// are (`None`: none, or every one NaN; a NaN is never the smallest).
pub(crate) fn arg_min<T: Real>(xs: impl IntoIterator<Item = T>) -> Option<(usize, T)> {
    xs.into_iter()
        .enumerate()
        .fold(None, |m: Option<(usize, T)>, (i, x)| match m {
            Some((_, low)) if !(x < low) => m,
            _ if x.is_nan() => m,
            _ => Some((i, x)),
        })
}

#[cfg(test)]
mod tests {
    use super::{arg_min, at_least, at_most, Real};

    /// `at_least`/`at_most` are `max`/`min` against a bound: the larger
    /// (smaller) of two, the bound for a NaN, the bound's own zero where
    /// the two are equal zeros (the strict comparison), in both precisions.
    #[test]
    fn bounds_take_the_bound_for_nan_and_equal_values() {
        for (x, b) in [(1.0, 2.0), (2.0, 1.0), (-3.0, -3.0), (f64::INFINITY, 0.0)] {
            assert_eq!(at_least(x, b), x.max(b));
            assert_eq!(at_most(x, b), x.min(b));
        }
        assert_eq!(at_least(f64::NAN, 1.0), 1.0);
        assert_eq!(at_most(f64::NAN, -1.0), -1.0);
        assert_eq!(at_least(f32::NAN, 0.5), 0.5);
        assert!(at_least(-0.0f64, 0.0).is_sign_positive());
        assert!(at_most(0.0f64, -0.0).is_sign_negative());
    }

    /// The first of the smallest, NaN passed over wherever it stands, and
    /// none of nothing or of NaN alone; against a search by sorting.
    #[test]
    fn arg_min_is_the_first_of_the_smallest_and_never_nan() {
        let nan = f64::NAN;
        assert_eq!(arg_min([3.0, 1.0, 2.0, 1.0]), Some((1, 1.0)));
        assert_eq!(arg_min([nan, 2.0, nan, -1.0, nan]), Some((3, -1.0)));
        assert_eq!(arg_min([f64::INFINITY, nan]), Some((0, f64::INFINITY)));
        assert_eq!(arg_min(core::iter::empty::<f64>()), None);
        assert_eq!(arg_min([nan, nan]), None);
        let xs = [0.5, -0.25, 7.0, -0.25, 3.0];
        let mut sorted: Vec<(f64, usize)> = xs.iter().enumerate().map(|(i, &x)| (x, i)).collect();
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap_or(core::cmp::Ordering::Equal));
        assert_eq!(arg_min(xs), Some((sorted[0].1, sorted[0].0)));
    }

    /// The bounds are the powers of two the docs state; the bound itself
    /// is usable, the next number above it and NaN, ±∞ are not, in either
    /// sign; `usable_with` bounds the sum of the magnitudes.
    #[test]
    fn usable_is_the_bound_on_the_magnitude() {
        assert_eq!(f32::USABLE, 2f32.powi(32));
        assert_eq!(f64::USABLE, 2f64.powi(256));
        let up32 = f32::from_bits(f32::USABLE.to_bits() + 1);
        let up64 = f64::from_bits(f64::USABLE.to_bits() + 1);
        for s in [1.0f32, -1.0] {
            assert!((s * f32::USABLE).usable() && (s * 0.0).usable() && (s * 1e9).usable());
            assert!(!(s * up32).usable() && !(s * f32::INFINITY).usable() && !(s * 5e9).usable());
        }
        for s in [1.0f64, -1.0] {
            assert!((s * f64::USABLE).usable() && (s * 1e76).usable());
            assert!(!(s * up64).usable() && !(s * f64::INFINITY).usable() && !(s * 1e78).usable());
        }
        assert!(!f32::NAN.usable() && !f64::NAN.usable());
        assert!(1.0f32.usable_with(-2.0) && !f64::USABLE.usable_with(f64::USABLE));
        assert!(!1.0f64.usable_with(f64::NAN));
    }
}
