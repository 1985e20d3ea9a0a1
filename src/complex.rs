//! A minimal complex number for frequency responses and root finding (no_std).

use core::ops::Add;

use crate::real::Real;

/// `re + j·im`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Complex<T> {
    /// Real part.
    pub re: T,
    /// Imaginary part.
    pub im: T,
}

impl<T: Real> Complex<T> {
    /// `re + j·im`.
    #[inline]
    pub fn new(re: T, im: T) -> Self {
        Complex { re, im }
    }
    /// A real number.
    #[inline]
    pub fn real(re: T) -> Self {
        Complex { re, im: T::zero() }
    }
    /// `e^{jφ}`.
    #[inline]
    pub fn cis(phi: T) -> Self {
        Complex::new(phi.cos(), phi.sin())
    }
    /// Product with a real number.
    #[inline]
    pub fn scale(self, k: T) -> Self {
        Complex::new(self.re * k, self.im * k)
    }
    /// Modulus. `√(re² + im²)` directly where neither square can overflow
    /// or lose precision to underflow (|re|, |im| within `2^±500` for
    /// `f64`, `2^±60` for `f32`: the analysis's values), `hypot` outside,
    /// whose scaling costs several times more.
    #[inline]
    pub fn abs(self) -> T {
        let m = self.re.abs().max(self.im.abs());
        let (lo, hi) = if core::mem::size_of::<T>() >= 8 {
            (T::of(3.054936363499605e-151), T::of(3.273390607896142e150))
        } else {
            (T::of(8.673617e-19), T::of(1.1529215e18))
        };
        if m > lo && m < hi {
            (self.re * self.re + self.im * self.im).sqrt()
        } else {
            self.re.hypot(self.im)
        }
    }
    /// The complex conjugate `re − j·im`.
    #[inline]
    pub fn conj(self) -> Self {
        Complex::new(self.re, -self.im)
    }
    /// Argument in (−π, π].
    #[inline]
    pub fn arg(self) -> T {
        self.im.atan2(self.re)
    }
    /// `e^{(re + j im)·ts}`.
    #[inline]
    pub fn exp_scaled(self, ts: T) -> Self {
        let m = (self.re * ts).exp();
        Complex::new(m * (self.im * ts).cos(), m * (self.im * ts).sin())
    }
    /// `z^{−k}` for `z` on the unit circle given as `e^{jθ}` (`theta`), fractional `k` by
    /// the delay line's linear interpolation: `(1 − f) z^{−⌊k⌋} + f z^{−⌊k⌋−1}`.
    pub fn delay_response(theta: T, k: T) -> Self {
        let kf = k.floor();
        let f = k - kf;
        let a = Complex::cis(-theta * kf);
        let b = Complex::cis(-theta * (kf + T::one()));
        a.scale(T::one() - f).add(b.scale(f))
    }
}

impl<T: Real> core::ops::Add for Complex<T> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Complex::new(self.re + o.re, self.im + o.im)
    }
}

impl<T: Real> core::ops::Sub for Complex<T> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Complex::new(self.re - o.re, self.im - o.im)
    }
}

impl<T: Real> core::ops::Mul for Complex<T> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl<T: Real> core::ops::Div for Complex<T> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Complex::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}
