//! A scheme's transfer functions, written once and read two ways: as values
//! at a frequency `z = e^{jθ}` (the analysis, [`Frequency`]) and, with
//! `alloc`, as rational functions of `w = z^{−1}` with their coefficients
//! ([`Symbolic`], [`Rational`]: what `msp tune --json` prints and Python's
//! `Controller.to_control()` hands to python-control).
//!
//! A scheme composes its blocks' transfer functions with `+ − × ÷`
//! ([`Algebra`]); a [`Point`] says what each block is there (a PID's pair, a
//! state-space block, a delay of `k` samples, a tapped line). The same
//! composition gives the frequency response and the coefficients, so the two
//! cannot disagree.

use crate::complex::Complex;
use crate::lti::Lti;
use crate::real::Real;
use core::ops::{Add, Div, Mul, Sub};

/// What a transfer function is at a [`Point`]: closed under `+ − × ÷`, with
/// the constants.
pub trait Algebra<T: Real>:
    Clone + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The constant `x`.
    fn constant(x: T) -> Self;
    /// The constant 1.
    fn one() -> Self {
        Self::constant(T::one())
    }
    /// The constant 0.
    fn zero() -> Self {
        Self::constant(T::zero())
    }
}

impl<T: Real> Algebra<T> for Complex<T> {
    #[inline(always)]
    fn constant(x: T) -> Self {
        Complex::real(x)
    }
}

/// Where a scheme's blocks are evaluated.
pub trait Point<T: Real> {
    /// The value of a transfer function there.
    type V: Algebra<T>;
    /// `w = z^{−1}`.
    fn backward(&self) -> Self::V;
    /// A state-space block `C(zI − Φ)^{−1}Γ + D`.
    fn lti<const N: usize>(&self, b: &Lti<T, N>) -> Self::V;
    /// A delay of `k` samples, fractional by linear interpolation as the
    /// delay line realizes it: `(1 − f)·w^{⌊k⌋} + f·w^{⌊k⌋+1}`, `f = k − ⌊k⌋`.
    fn delay(&self, k: T) -> Self::V;
    /// A tapped line `Σ num_k w^k / Σ den_k w^k`.
    fn taps(&self, num: &[T], den: &[T]) -> Self::V;
    /// The moving sum `Σ_{k=1}^{h} w^k`.
    fn window(&self, h: usize) -> Self::V;
}

/// The point `z = e^{jθ}` (`θ = ω·Ts`), with `z^{−1}` computed once for
/// every block evaluated there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frequency<T> {
    theta: T,
    w: Complex<T>,
}

impl<T: Real> Frequency<T> {
    /// The point `e^{jθ}`.
    #[inline]
    pub fn new(theta: T) -> Self {
        Frequency {
            theta,
            w: Complex::cis(-theta),
        }
    }
}

impl<T: Real> Point<T> for Frequency<T> {
    type V = Complex<T>;
    #[inline]
    fn backward(&self) -> Complex<T> {
        self.w
    }
    #[inline]
    fn lti<const N: usize>(&self, b: &Lti<T, N>) -> Complex<T> {
        b.response_z(self.w.conj())
    }
    #[inline]
    fn delay(&self, k: T) -> Complex<T> {
        Complex::delay_response(self.theta, k)
    }
    fn taps(&self, num: &[T], den: &[T]) -> Complex<T> {
        crate::lti::small::taps_at(num, self.w) / crate::lti::small::taps_at(den, self.w)
    }
    /// In closed form: the Dirichlet kernel `e^{−jθ(h+1)/2}·sin(hθ/2)/sin(θ/2)`
    /// (`h` at θ = 0).
    fn window(&self, h: usize) -> Complex<T> {
        let theta = self.theta;
        let h = T::of(f64::from(u32::try_from(h).unwrap_or(u32::MAX)));
        let two = T::two();
        let half = (theta / two).sin();
        let ratio = if half.abs() > T::epsilon() {
            (theta * h / two).sin() / half
        } else {
            h
        };
        Complex::cis(-theta * (h + T::one()) / two).scale(ratio)
    }
}

#[cfg(feature = "alloc")]
pub use symbolic::{mul, Rational, Symbolic};

#[cfg(feature = "alloc")]
mod symbolic {
    use super::{Algebra, Point};
    use crate::complex::Complex;
    use crate::lti::Lti;
    use crate::real::Real;
    use alloc::vec;
    use alloc::vec::Vec;
    use core::ops::{Add, Div, Mul, Sub};

    /// A rational function of `w = z^{−1}`, `gain·Π num_i(w) / Π den_j(w)`,
    /// each factor a polynomial in ascending powers of `w`. The factors are
    /// the blocks' own polynomials: a product cancels a factor that appears
    /// in both (the same block's denominator brought back by a division), so
    /// a scheme's transfer function comes out without the common factors its
    /// composition would otherwise leave (a PID's `1 − w` and its
    /// derivative filter's pole in both parts of `Cr = G1r/(1 + …)`). A sum
    /// multiplies out over the least common multiple of the two factor lists.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Rational {
        gain: f64,
        num: Vec<Vec<f64>>,
        den: Vec<Vec<f64>>,
    }

    /// The point "every `z`": blocks as [`Rational`] functions.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
    pub struct Symbolic;

    /// Polynomial product (the coefficients in either order, the same in
    /// both factors and the product; `msp::poly::mul`).
    pub fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
        if a.is_empty() || b.is_empty() {
            return Vec::new();
        }
        let mut out = vec![0.0; a.len().saturating_add(b.len()).saturating_sub(1)];
        for (i, x) in a.iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                if let Some(o) = out.get_mut(i.saturating_add(j)) {
                    *o += x * y;
                }
            }
        }
        out
    }

    fn product(factors: &[Vec<f64>]) -> Vec<f64> {
        factors.iter().fold(vec![1.0], |acc, f| mul(&acc, f))
    }

    /// `p` without its trailing zeros (`[]` for the zero polynomial).
    fn trimmed(mut p: Vec<f64>) -> Vec<f64> {
        while p.last() == Some(&0.0) {
            p.pop();
        }
        p
    }

    impl Rational {
        /// `num(w)/den(w)` (ascending powers of `w`).
        pub fn new(num: &[f64], den: &[f64]) -> Self {
            Rational {
                gain: 1.0,
                num: vec![num.to_vec()],
                den: vec![den.to_vec()],
            }
            .normalized()
        }

        /// The constant `x`.
        pub fn constant(x: f64) -> Self {
            Rational {
                gain: x,
                num: Vec::new(),
                den: Vec::new(),
            }
        }

        /// Constant factors into the gain, `1` factors dropped, common
        /// factors of numerator and denominator cancelled.
        fn normalized(mut self) -> Self {
            for list in [&mut self.num, &mut self.den] {
                for f in list.iter_mut() {
                    *f = trimmed(core::mem::take(f));
                }
            }
            let mut gain = self.gain;
            self.num.retain(|f| match f.as_slice() {
                [] => {
                    gain = 0.0;
                    false
                }
                [c] => {
                    gain *= c;
                    false
                }
                _ => true,
            });
            self.den.retain(|f| match f.as_slice() {
                [] => {
                    gain = f64::NAN;
                    false
                }
                [c] => {
                    gain /= c;
                    false
                }
                _ => true,
            });
            self.gain = gain;
            if gain == 0.0 {
                self.num.clear();
                self.den.clear();
                return self;
            }
            let mut i = 0;
            while let Some(f) = self.num.get(i) {
                if let Some(j) = self.den.iter().position(|g| g == f) {
                    self.num.swap_remove(i);
                    self.den.swap_remove(j);
                } else {
                    i += 1;
                }
            }
            self
        }

        /// Numerator and denominator multiplied out, ascending powers of `w`,
        /// the denominator's lowest nonzero coefficient 1 and common powers
        /// of `w` removed. The same lists are the descending powers of `z`
        /// once both are padded to one length ([`Rational::in_z`]).
        pub fn polynomials(&self) -> (Vec<f64>, Vec<f64>) {
            let mut num = trimmed(product(&self.num));
            num.iter_mut().for_each(|c| *c *= self.gain);
            let mut den = trimmed(product(&self.den));
            let lead = |p: &[f64]| p.iter().position(|c| *c != 0.0);
            let shift = match (lead(&num), lead(&den)) {
                (Some(a), Some(b)) => a.min(b),
                (None, Some(b)) => b,
                _ => 0,
            };
            num.drain(..shift.min(num.len()));
            den.drain(..shift.min(den.len()));
            if let Some(&d0) = den.iter().find(|c| **c != 0.0) {
                num.iter_mut().for_each(|c| *c /= d0);
                den.iter_mut().for_each(|c| *c /= d0);
            }
            if num.is_empty() {
                num.push(0.0);
            }
            (num, den)
        }

        /// The descending powers of `z` (as MATLAB's `tf(num, den, Ts)` and
        /// python-control's `TransferFunction(num, den, dt)` take them): the
        /// lists of [`Rational::polynomials`] padded with zeros to one length.
        pub fn in_z(&self) -> (Vec<f64>, Vec<f64>) {
            let (mut num, mut den) = self.polynomials();
            let n = num.len().max(den.len());
            num.resize(n, 0.0);
            den.resize(n, 0.0);
            (num, den)
        }

        /// The value at `z` (`w = 1/z`).
        pub fn eval(&self, z: Complex<f64>) -> Complex<f64> {
            let w = Complex::real(1.0) / z;
            let at = |p: &[f64]| {
                p.iter()
                    .rev()
                    .fold(Complex::default(), |a, c| a * w + Complex::real(*c))
            };
            let num = self
                .num
                .iter()
                .fold(Complex::real(self.gain), |a, f| a * at(f));
            self.den.iter().fold(num, |a, f| a / at(f))
        }
    }

    impl Mul for Rational {
        type Output = Rational;
        fn mul(mut self, o: Rational) -> Rational {
            self.gain *= o.gain;
            self.num.extend(o.num);
            self.den.extend(o.den);
            self.normalized()
        }
    }

    impl Div for Rational {
        type Output = Rational;
        fn div(self, o: Rational) -> Rational {
            self * Rational {
                gain: 1.0 / o.gain,
                num: o.den,
                den: o.num,
            }
        }
    }

    impl Add for Rational {
        type Output = Rational;
        fn add(self, o: Rational) -> Rational {
            if o.gain == 0.0 {
                return self;
            }
            if self.gain == 0.0 {
                return o;
            }
            // the least common multiple of the two denominators' factor lists
            let mut rest_a = self.den;
            let mut common = Vec::new();
            let mut rest_b = Vec::new();
            for f in o.den {
                if let Some(i) = rest_a.iter().position(|g| *g == f) {
                    common.push(rest_a.swap_remove(i));
                } else {
                    rest_b.push(f);
                }
            }
            let mut a = product(&self.num);
            a.iter_mut().for_each(|c| *c *= self.gain);
            let mut b = product(&o.num);
            b.iter_mut().for_each(|c| *c *= o.gain);
            let mut num = mul(&a, &product(&rest_b));
            let other = mul(&b, &product(&rest_a));
            if num.len() < other.len() {
                num.resize(other.len(), 0.0);
            }
            for (x, y) in num.iter_mut().zip(other) {
                *x += y;
            }
            common.extend(rest_a);
            common.extend(rest_b);
            Rational {
                gain: 1.0,
                num: vec![num],
                den: common,
            }
            .normalized()
        }
    }

    impl Sub for Rational {
        type Output = Rational;
        fn sub(self, mut o: Rational) -> Rational {
            o.gain = -o.gain;
            self + o
        }
    }

    impl<T: Real> Algebra<T> for Rational {
        fn constant(x: T) -> Self {
            Rational::constant(x.f64())
        }
    }

    impl<T: Real> Point<T> for Symbolic {
        type V = Rational;
        fn backward(&self) -> Rational {
            Rational::new(&[0.0, 1.0], &[1.0])
        }
        fn lti<const N: usize>(&self, b: &Lti<T, N>) -> Rational {
            let (num, den) = crate::lti::small::model_tf(b);
            Rational::new(num.as_slice(), den.as_slice())
        }
        fn delay(&self, k: T) -> Rational {
            let whole = k.floor();
            let f = (k - whole).f64();
            let n = usize::try_from(whole.to_u64().unwrap_or(0)).unwrap_or(0);
            let mut p = vec![0.0; n];
            p.push(1.0 - f);
            if f != 0.0 {
                p.push(f);
            }
            Rational::new(&p, &[1.0])
        }
        fn taps(&self, num: &[T], den: &[T]) -> Rational {
            let widen = |p: &[T]| p.iter().map(|c| c.f64()).collect::<Vec<_>>();
            Rational::new(&widen(num), &widen(den))
        }
        fn window(&self, h: usize) -> Rational {
            let mut p = vec![1.0; h + 1];
            if let Some(c) = p.first_mut() {
                *c = 0.0;
            }
            Rational::new(&p, &[1.0])
        }
    }
}
