//! Discrete linear time-invariant blocks and the discretization of continuous ones.
//!
//! Every block is one type, [`Lti`]: a single-input single-output state-space
//! system of order `n ≤ N` (the const capacity),
//!
//! `x[k+1] = Φ·x[k] + Γ·u[k]`,  `y[k] = C·x[k] + D·u[k]`,
//!
//! stored inline (no heap). First-order lags, integrators, lead-lags,
//! second-order blocks and general rational transfer functions are
//! constructors of this type; nothing assumes stability, so integrating and
//! unstable poles work.
//!
//! A continuous block `G(s) = b(s)/a(s)` is realized in controllable canonical
//! form and discretized at the sample period `Ts` by one of:
//! - **zero-order hold** (the default, [`Discretization::Zoh`]):
//!   `Φ = e^{A·Ts}`, `Γ = ∫₀^Ts e^{A·τ} dτ · B` — exact at the sample instants for
//!   an input held constant over each period, which is what a sampled
//!   controller's actuator does; computed by scaling and squaring of the
//!   Taylor series of both integrals (valid for singular `A`, i.e. integrators);
//! - **Tustin** (bilinear, `s ← 2/Ts · (z−1)/(z+1)`, [`Discretization::Tustin`]);
//! - **pole-zero matching** (`z = e^{s·Ts}` for every pole and finite zero, the
//!   gain matched at DC — after removing poles or zeros at the origin — as used
//!   for the primary controller in García et al. (2010) Sec. 3,
//!   [`Discretization::Matched`]).

use crate::complex::Complex;
use crate::{error::Error, real::Real};
use core::ops::{Add, Div, Mul, Sub};

/// How a continuous block is turned into a discrete one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Discretization {
    /// Zero-order hold: exact for piecewise-constant inputs.
    #[default]
    Zoh,
    /// Bilinear (trapezoidal) transformation.
    Tustin,
    /// Pole-zero matching `z = e^{s Ts}` with the DC gain preserved (after the
    /// roots at the origin are removed); an improper block gets a pole at
    /// `z = 0` for each excess zero.
    Matched,
}

/// A discrete SISO state-space block of order at most `N`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "T: serde::Serialize",
        deserialize = "T: serde::Deserialize<'de> + Default + Copy"
    ))
)]
pub struct Lti<T, const N: usize> {
    #[cfg_attr(feature = "serde", serde(with = "serde_mat"))]
    phi: [[T; N]; N],
    #[cfg_attr(feature = "serde", serde(with = "serde_vec"))]
    gamma: [T; N],
    #[cfg_attr(feature = "serde", serde(with = "serde_vec"))]
    c: [T; N],
    d: T,
    #[cfg_attr(feature = "serde", serde(with = "serde_vec"))]
    x: [T; N],
    n: usize,
}

mod blocks;
mod design;
pub(crate) mod matrix;
#[cfg(feature = "serde")]
mod serde_arrays;
pub mod small;
pub mod zdomain;

#[cfg(feature = "alloc")]
pub(crate) use design::companion_entry;
pub(crate) use design::{divide_in_place, faddeev, roots, roots_upto};
pub use design::{realize, Realization};
use matrix::{array_of, mat_of, vector_of};
#[cfg(feature = "serde")]
use serde_arrays::{serde_mat, serde_vec};

impl<T: Real, const N: usize> Lti<T, N> {
    /// The order `n` of the block.
    #[inline]
    pub fn order(&self) -> usize {
        self.n
    }

    /// The state vector (its first `order()` entries are meaningful).
    #[inline]
    pub fn state(&self) -> &[T; N] {
        &self.x
    }

    /// The output the block would give for input `u` now, without advancing it.
    #[inline(always)]
    pub fn output(&self, u: T) -> T {
        if self.n <= 1 {
            let cx = match (self.c.first(), self.x.first()) {
                (Some(c), Some(x)) if self.n == 1 => *c * *x,
                _ => T::zero(),
            };
            return cx + self.d * u;
        }
        self.c
            .iter()
            .zip(self.x.iter())
            .take(self.n)
            .fold(self.d * u, |s, (c, x)| s + *c * *x)
    }

    /// The output for the current state ignoring the feed-through `D·u`: `C x[k]`.
    #[inline(always)]
    pub fn free_output(&self) -> T {
        match (self.n, self.c.first(), self.x.first()) {
            (0, _, _) => T::zero(),
            (1, Some(c), Some(x)) => *c * *x,
            _ => self
                .c
                .iter()
                .zip(self.x.iter())
                .take(self.n)
                .fold(T::zero(), |s, (c, x)| s + *c * *x),
        }
    }

    /// Advances one sample with input `u[k]`: returns `y[k] = C x[k] + D u[k]`
    /// and sets `x[k+1] = Φ x[k] + Γ u[k]`.
    #[inline(always)]
    pub fn step(&mut self, u: T) -> T {
        if self.n == 1 {
            // first order: the two multiply-adds, one dispatch
            if let (Some(x), Some(row), Some(g), Some(c)) = (
                self.x.first_mut(),
                self.phi.first(),
                self.gamma.first(),
                self.c.first(),
            ) {
                let x0 = *x;
                *x = row.first().copied().unwrap_or(T::zero()) * x0 + *g * u;
                return *c * x0 + self.d * u;
            }
        }
        let y = self.output(u);
        self.advance(u);
        y
    }

    /// Amends the last step as if its input had been `u + du`: by linearity
    /// the state moves by `Γ·du` (exactly what stepping with `u + du` would
    /// have given), and the output of that step by `D·du`, which is returned.
    /// How a block's state follows the value an actuator really applied.
    pub fn amend_input(&mut self, du: T) -> T {
        for (x, g) in self.x.iter_mut().zip(self.gamma.iter()).take(self.n) {
            *x = *x + *g * du;
        }
        self.d * du
    }

    /// Moves the state so that the output moves by `dy` for the same input,
    /// along the block's integrating mode: `x += w·dy` with `(Φ − I)·w = 0`,
    /// `C·w = 1` (solved in the least-squares sense, which is exact when the
    /// block has a pole at `z = 1` its output sees). A controller realized as
    /// a block then takes over from an output it did not give (manual,
    /// tracking) as a PI's integrator does: the shift persists. Returns false
    /// (and changes nothing) when no such direction exists.
    pub fn shift_output(&mut self, dy: T) -> bool {
        let n = self.n;
        if n == 0 || !dy.is_finite() {
            return false;
        }
        // M = (Φ − I)ᵀ(Φ − I) + CᵀC, w = M⁻¹·Cᵀ
        let a = mat_of(&self.phi, n) - matrix::Mat::<N>::identity();
        let c = vector_of(&self.c, n);
        let mut m = a.transpose() * a + c * c.transpose();
        for i in n..N {
            if let Some(e) = m.get_mut((i, i)) {
                *e = 1.0;
            }
        }
        let Ok(inv) = matrix::inverse(&m, n) else {
            return false;
        };
        let w = inv * c;
        let cw = c.dot(&w);
        if !(cw.abs() > 1e-12) {
            return false;
        }
        let step: [T; N] = array_of(&(w * (dy.f64() / cw)), n);
        for (x, d) in self.x.iter_mut().zip(step.iter()).take(n) {
            *x = *x + *d;
        }
        true
    }

    /// Moves the state as if every past input had been larger by `du`: for a
    /// stable block at a steady state, `x += (I − Φ)⁻¹Γ·du`, the steady
    /// state of the new input. Fails (and changes nothing) when `I − Φ` is
    /// singular (a pole at `z = 1`).
    pub fn settle(&mut self, du: T) -> Result<(), Error> {
        let step = self.equilibrium(du)?;
        for (x, d) in self.x.iter_mut().zip(step.iter()).take(self.n) {
            *x = *x + *d;
        }
        Ok(())
    }

    /// `x[k+1] = Φ x[k] + Γ1 u1 + Γ2 u2`: a step driven by two inputs
    /// through their own input vectors (a fractional dead time's sampled
    /// form: the input before and after the fraction of the period).
    #[inline(always)]
    pub fn advance_inputs(&mut self, g1: &[T; N], u1: T, g2: &[T; N], u2: T) {
        let mut next = [T::zero(); N];
        for (((xn, row), a), b) in next
            .iter_mut()
            .zip(self.phi.iter())
            .zip(g1.iter())
            .zip(g2.iter())
            .take(self.n)
        {
            *xn = row
                .iter()
                .zip(self.x.iter())
                .take(self.n)
                .fold(*a * u1 + *b * u2, |s, (p, x)| s + *p * *x);
        }
        self.x = next;
    }

    /// Advances one sample with input `u[k]`: `x[k+1] = Φ x[k] + Γ u[k]`.
    #[inline(always)]
    pub fn advance(&mut self, u: T) {
        if self.n == 1 {
            // first order: one multiply-add, no loops
            if let (Some(x), Some(row), Some(g)) =
                (self.x.first_mut(), self.phi.first(), self.gamma.first())
            {
                *x = row.first().copied().unwrap_or(T::zero()) * *x + *g * u;
            }
            return;
        }
        let mut next = [T::zero(); N];
        for ((xn, row), g) in next
            .iter_mut()
            .zip(self.phi.iter())
            .zip(self.gamma.iter())
            .take(self.n)
        {
            *xn = row
                .iter()
                .zip(self.x.iter())
                .take(self.n)
                .fold(*g * u, |s, (p, x)| s + *p * *x);
        }
        self.x = next;
    }

    /// Sets the state vector.
    #[inline]
    pub fn set_state(&mut self, x: &[T; N]) {
        self.x = *x;
    }

    /// The frequency response `C(zI − Φ)⁻¹Γ + D` at `z = e^{jθ}` (`θ = ω·Ts`).
    pub fn response(&self, theta: T) -> Complex<T> {
        self.response_z(Complex::cis(theta))
    }

    /// The frequency response at the point `z` of the unit circle.
    pub fn response_z(&self, z: Complex<T>) -> Complex<T> {
        let n = self.n;
        // first and second order in closed form (Cramer's rule, forward
        // stable for two unknowns): the analysis evaluates these thousands
        // of times per verdict
        let (phi, g, c) = (
            |i: usize, j: usize| self.phi_entry(i, j),
            |i: usize| self.gamma.get(i).copied().unwrap_or(T::zero()),
            |i: usize| self.c.get(i).copied().unwrap_or(T::zero()),
        );
        let inf = Complex::new(T::infinity(), T::zero());
        match n {
            0 => Complex::real(self.d),
            1 => {
                let den = z.sub(Complex::real(phi(0, 0)));
                if den.abs() == T::zero() {
                    return inf;
                }
                Complex::real(c(0) * g(0))
                    .div(den)
                    .add(Complex::real(self.d))
            }
            2 => {
                let (m00, m11) = (
                    z.sub(Complex::real(phi(0, 0))),
                    z.sub(Complex::real(phi(1, 1))),
                );
                let det = m00.mul(m11).sub(Complex::real(phi(0, 1) * phi(1, 0)));
                if det.abs() == T::zero() {
                    return inf;
                }
                let x0 = m11.scale(g(0)).add(Complex::real(phi(0, 1) * g(1)));
                let x1 = m00.scale(g(1)).add(Complex::real(phi(1, 0) * g(0)));
                x0.scale(c(0))
                    .add(x1.scale(c(1)))
                    .div(det)
                    .add(Complex::real(self.d))
            }
            _ => self.eliminated_response(z),
        }
    }

    /// The frequency response by complex Gaussian elimination with partial
    /// pivoting on `[zI − Φ | Γ]`, for any order.
    fn eliminated_response(&self, z: Complex<T>) -> Complex<T> {
        let n = self.n;
        // augmented system [zI − Φ | Γ], complex Gaussian elimination
        let mut a = [[Complex::<T>::default(); N]; N];
        let mut b = [Complex::<T>::default(); N];
        for i in 0..n {
            for j in 0..n {
                let phi = self
                    .phi
                    .get(i)
                    .and_then(|r| r.get(j))
                    .copied()
                    .unwrap_or(T::zero());
                let v = if i == j {
                    z.sub(Complex::real(phi))
                } else {
                    Complex::real(-phi)
                };
                if let Some(x) = a.get_mut(i).and_then(|r| r.get_mut(j)) {
                    *x = v;
                }
            }
            if let Some(x) = b.get_mut(i) {
                *x = Complex::real(self.gamma.get(i).copied().unwrap_or(T::zero()));
            }
        }
        let at = |a: &[[Complex<T>; N]; N], i: usize, j: usize| {
            a.get(i).and_then(|r| r.get(j)).copied().unwrap_or_default()
        };
        for col in 0..n {
            let mut piv = col;
            for r in col..n {
                if at(&a, r, col).abs() > at(&a, piv, col).abs() {
                    piv = r;
                }
            }
            a.swap(col, piv);
            b.swap(col, piv);
            let p = at(&a, col, col);
            if p.abs() == T::zero() {
                return Complex::new(T::infinity(), T::zero());
            }
            for r in 0..n {
                if r != col {
                    let f = at(&a, r, col).div(p);
                    for c in 0..n {
                        let v = at(&a, r, c).sub(f.mul(at(&a, col, c)));
                        if let Some(x) = a.get_mut(r).and_then(|row| row.get_mut(c)) {
                            *x = v;
                        }
                    }
                    let bc = b.get(col).copied().unwrap_or_default();
                    if let Some(x) = b.get_mut(r) {
                        *x = x.sub(f.mul(bc));
                    }
                }
            }
        }
        let mut y = Complex::real(self.d);
        for i in 0..n {
            let xi = b.get(i).copied().unwrap_or_default().div(at(&a, i, i));
            y = y.add(xi.scale(self.c.get(i).copied().unwrap_or(T::zero())));
        }
        y
    }

    /// `Φ[i][j]` (0 outside the order).
    pub fn phi_entry(&self, i: usize, j: usize) -> T {
        self.phi
            .get(i)
            .and_then(|r| r.get(j))
            .copied()
            .unwrap_or(T::zero())
    }

    /// The output vector `C`.
    pub fn output_vector(&self) -> [T; N] {
        self.c
    }

    /// The feed-through `D`.
    pub fn feedthrough(&self) -> T {
        self.d
    }

    /// The input vector `Γ`.
    pub fn input_vector(&self) -> [T; N] {
        self.gamma
    }

    /// `Φ·v`.
    pub fn propagate(&self, v: &[T; N]) -> [T; N] {
        array_of(&(mat_of(&self.phi, self.n) * vector_of(v, self.n)), self.n)
    }

    /// The same block with another input vector `Γ`.
    pub fn with_input(&self, gamma: &[T; N]) -> Result<Self, Error> {
        Lti {
            gamma: *gamma,
            ..*self
        }
        .check_finite()
    }

    /// Zeroes the state.
    pub fn reset(&mut self) {
        self.x = [T::zero(); N];
    }

    /// Sets the state to the equilibrium for a constant input `u` (bumpless
    /// start): `x = (I − Φ)⁻¹ Γ u`. Fails for a block with a pole at `z = 1`
    /// (an integrator has no equilibrium for `u ≠ 0`); use [`Lti::set_output`] then.
    pub fn set_steady(&mut self, u: T) -> Result<(), Error> {
        self.x = self.equilibrium(u)?;
        Ok(())
    }

    /// The equilibrium state for the constant input `u`: `(I − Φ)⁻¹ Γ u`.
    fn equilibrium(&self, u: T) -> Result<[T; N], Error> {
        let n = self.n;
        if n == 1 {
            // the first order in this precision, the elimination's operations
            // (`(1/(1 − φ))·(γ·u)`, refused where `1 − φ` is 0): no `f64`
            // arithmetic, which a microcontroller without a double-precision
            // unit emulates
            let (phi, gamma) = (
                self.phi_entry(0, 0),
                self.gamma.first().copied().unwrap_or(T::zero()),
            );
            let m = T::one() - phi;
            if m == T::zero() || !m.is_finite() {
                return Err(Error::Numerical("matrix inversion"));
            }
            let mut x = [T::zero(); N];
            if let Some(x0) = x.first_mut() {
                *x0 = T::one() / m * (gamma * u);
            }
            return Ok(x);
        }
        let m = matrix::Mat::<N>::identity() - mat_of(&self.phi, n);
        let x = matrix::solve(&m, &(vector_of(&self.gamma, n) * u.f64()), n)?;
        Ok(array_of(&x, n))
    }

    /// Sets the state so that the free output is `y` while an integrating block
    /// stays at rest for zero input: the state is scaled along `C`'s direction
    /// (least-norm state giving output `y`).
    pub fn set_output(&mut self, y: T) {
        let cc = self
            .c
            .iter()
            .take(self.n)
            .fold(T::zero(), |s, c| s + *c * *c);
        if cc > T::zero() {
            for (x, c) in self.x.iter_mut().zip(self.c.iter()).take(self.n) {
                *x = *c * y / cc;
            }
        }
    }

    /// How many poles of the block (eigenvalues of `Φ`) lie outside the unit
    /// circle; poles at `z = ±1` count as inside (an integrator is marginal,
    /// not unstable).
    pub fn unstable_poles(&self) -> usize {
        let (c, len) = design::char_poly(self);
        design::roots_outside(c.get(..len).unwrap_or(&[]))
    }

    /// The DC gain `C (I − Φ)⁻¹ Γ + D`, or an error for a pole at `z = 1`.
    pub fn dc_gain(&self) -> Result<T, Error> {
        let mut probe = *self;
        probe.set_steady(T::one())?;
        Ok(probe.output(T::one()))
    }
}

#[cfg(all(test, feature = "std"))]
mod tests {
    use super::{Discretization, Lti};
    use crate::complex::Complex;
    use crate::test_util::ExpectOk;
    use core::ops::Sub;

    /// The closed forms of first and second order are the general
    /// elimination's response (to rounding), on and off the unit circle,
    /// with and without a direct term, real and complex poles, at and near a
    /// pole.
    #[test]
    fn low_orders_in_closed_form_are_the_elimination() {
        // (plant, numerator and denominator in descending powers of s, order)
        let plants: [(&str, &[f64], &[f64], usize); 7] = [
            ("2/(3s+1)", &[2.0], &[3.0, 1.0], 1),
            ("(s+1)/(2s+1)", &[1.0, 1.0], &[2.0, 1.0], 1),
            ("-0.5/s", &[-0.5], &[1.0, 0.0], 1),
            ("(s+2)/((3s+1)(0.5s+1))", &[1.0, 2.0], &[1.5, 3.5, 1.0], 2),
            ("(2s-1)/(s^2+0.4s+1)", &[2.0, -1.0], &[1.0, 0.4, 1.0], 2),
            (
                "(0.3s^2+s+2)/(s^2+0.02s+4)",
                &[0.3, 1.0, 2.0],
                &[1.0, 0.02, 4.0],
                2,
            ),
            ("1/(s(4s+1))", &[1.0], &[4.0, 1.0, 0.0], 2),
        ];
        for (plant, num, den, order) in plants {
            let lti = Lti::<f64, 4>::from_tf(num, den, 0.7, Discretization::Zoh).expect_ok();
            assert_eq!(lti.order(), order, "{plant}");
            for k in 0..400 {
                let theta = f64::from(k) * 0.00787 + 1e-9;
                for radius in [1.0, 0.6, 1.7] {
                    let z = Complex::cis(theta).scale(radius);
                    let (fast, general) = (lti.response_z(z), lti.eliminated_response(z));
                    let err = fast.sub(general).abs();
                    assert!(
                        err <= 1e-12 * general.abs().max(1.0),
                        "{plant} at z = {z:?}: {fast:?} against {general:?}"
                    );
                }
            }
        }
    }
}
