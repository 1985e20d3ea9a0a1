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
use crate::real::{finite, positive};
use crate::{Error, Real};
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

#[cfg(feature = "serde")]
mod serde_vec {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(
        v: &[T; N],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        v.as_slice().serialize(s)
    }
    pub fn deserialize<
        'de,
        D: Deserializer<'de>,
        T: Deserialize<'de> + Default + Copy,
        const N: usize,
    >(
        d: D,
    ) -> Result<[T; N], D::Error> {
        super::serde_fixed::<D, T, N>(d)
    }
}

#[cfg(feature = "serde")]
mod serde_mat {
    use serde::ser::SerializeSeq;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(
        m: &[[T; N]; N],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(N))?;
        for row in m {
            seq.serialize_element(row.as_slice())?;
        }
        seq.end()
    }
    pub fn deserialize<
        'de,
        D: Deserializer<'de>,
        T: Deserialize<'de> + Default + Copy,
        const N: usize,
    >(
        d: D,
    ) -> Result<[[T; N]; N], D::Error> {
        struct Row<T, const N: usize>([T; N]);
        impl<'de, T: Deserialize<'de> + Default + Copy, const N: usize> Deserialize<'de> for Row<T, N> {
            fn deserialize<D2: Deserializer<'de>>(d: D2) -> Result<Self, D2::Error> {
                super::serde_fixed::<D2, T, N>(d).map(Row)
            }
        }
        struct V<T, const N: usize>(core::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Default + Copy, const N: usize> serde::de::Visitor<'de>
            for V<T, N>
        {
            type Value = [[T; N]; N];
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                write!(f, "{N} rows")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = [[T::default(); N]; N];
                for (i, row) in out.iter_mut().enumerate() {
                    *row = a
                        .next_element::<Row<T, N>>()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?
                        .0;
                }
                Ok(out)
            }
        }
        d.deserialize_seq(V::<T, N>(core::marker::PhantomData))
    }
}

#[cfg(feature = "serde")]
fn serde_fixed<
    'de,
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de> + Default + Copy,
    const N: usize,
>(
    d: D,
) -> Result<[T; N], D::Error> {
    struct V<T, const N: usize>(core::marker::PhantomData<T>);
    impl<'de, T: serde::Deserialize<'de> + Default + Copy, const N: usize> serde::de::Visitor<'de>
        for V<T, N>
    {
        type Value = [T; N];
        fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
            write!(f, "{N} numbers")
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(
            self,
            mut a: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = [T::default(); N];
            for (i, v) in out.iter_mut().enumerate() {
                *v = a
                    .next_element()?
                    .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
            }
            Ok(out)
        }
    }
    d.deserialize_seq(V::<T, N>(core::marker::PhantomData))
}

/// A small dense matrix for design-time computations (never on the per-sample path).
#[derive(Clone, Copy)]
struct Mat<T, const N: usize> {
    a: [[T; N]; N],
    n: usize,
}

impl<T: Real, const N: usize> Mat<T, N> {
    fn zeros(n: usize) -> Self {
        Mat {
            a: [[T::zero(); N]; N],
            n,
        }
    }
    fn eye(n: usize) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            m.set(i, i, T::one());
        }
        m
    }
    #[inline]
    fn get(&self, i: usize, j: usize) -> T {
        self.a
            .get(i)
            .and_then(|r| r.get(j))
            .copied()
            .unwrap_or(T::zero())
    }
    #[inline]
    fn set(&mut self, i: usize, j: usize, v: T) {
        if let Some(x) = self.a.get_mut(i).and_then(|r| r.get_mut(j)) {
            *x = v;
        }
    }
    fn mul(&self, b: &Self) -> Self {
        let mut c = Self::zeros(self.n);
        for i in 0..self.n {
            for j in 0..self.n {
                let mut s = T::zero();
                for k in 0..self.n {
                    s = s + self.get(i, k) * b.get(k, j);
                }
                c.set(i, j, s);
            }
        }
        c
    }
    fn add(&self, b: &Self) -> Self {
        let mut c = *self;
        for i in 0..self.n {
            for j in 0..self.n {
                c.set(i, j, self.get(i, j) + b.get(i, j));
            }
        }
        c
    }
    fn scale(&self, s: T) -> Self {
        let mut c = *self;
        for i in 0..self.n {
            for j in 0..self.n {
                c.set(i, j, self.get(i, j) * s);
            }
        }
        c
    }
    fn norm1(&self) -> T {
        let mut best = T::zero();
        for j in 0..self.n {
            let mut s = T::zero();
            for i in 0..self.n {
                s = s + self.get(i, j).abs();
            }
            best = best.max(s);
        }
        best
    }
    fn mul_vec(&self, v: &[T; N]) -> [T; N] {
        let mut out = [T::zero(); N];
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            let mut s = T::zero();
            for (k, vk) in v.iter().enumerate().take(self.n) {
                s = s + self.get(i, k) * *vk;
            }
            *o = s;
        }
        out
    }
    /// Solves `self · X = B` by Gaussian elimination with partial pivoting.
    fn solve(&self, b: &Self) -> Result<Self, Error> {
        let n = self.n;
        let mut a = *self;
        let mut x = *b;
        for col in 0..n {
            let mut piv = col;
            let mut best = a.get(col, col).abs();
            for r in col.wrapping_add(1)..n {
                if a.get(r, col).abs() > best {
                    best = a.get(r, col).abs();
                    piv = r;
                }
            }
            if !(best > T::epsilon() * a.norm1().max(T::min_positive_value())) {
                return Err(Error::Numerical("matrix inversion"));
            }
            a.a.swap(col, piv);
            x.a.swap(col, piv);
            let p = a.get(col, col);
            for r in 0..n {
                if r != col {
                    let f = a.get(r, col) / p;
                    if f != T::zero() {
                        for c in 0..n {
                            a.set(r, c, a.get(r, c) - f * a.get(col, c));
                            x.set(r, c, x.get(r, c) - f * x.get(col, c));
                        }
                    }
                }
            }
        }
        for r in 0..n {
            let p = a.get(r, r);
            for c in 0..n {
                x.set(r, c, x.get(r, c) / p);
            }
        }
        Ok(x)
    }
}

/// `e^{A h}` and `∫₀^h e^{A τ} dτ` by scaling and squaring of their Taylor series.
fn expm_and_integral<T: Real, const N: usize>(a: &Mat<T, N>, h: T) -> (Mat<T, N>, Mat<T, N>) {
    let n = a.n;
    let norm = a.norm1() * h;
    let mut squarings = 0u32;
    let mut hs = h;
    let half = T::half();
    while norm * T::powi(half, i32::try_from(squarings).unwrap_or(60)) > half && squarings < 60 {
        squarings = squarings.saturating_add(1);
        hs = hs * half;
    }
    let ah = a.scale(hs);
    // E = Σ (Ah)^k / k!,  P = h Σ (Ah)^k / (k+1)!
    let mut e = Mat::eye(n);
    let mut p = Mat::eye(n).scale(hs);
    let mut term = Mat::eye(n);
    let mut k = T::one();
    for _ in 0..30 {
        term = term.mul(&ah).scale(T::one() / k);
        e = e.add(&term);
        p = p.add(&term.scale(hs / (k + T::one())));
        k = k + T::one();
        if term.norm1() < T::epsilon() * T::of(1e-3) {
            break;
        }
    }
    for _ in 0..squarings {
        // ∫₀^{2h} = ∫₀^h + e^{Ah} ∫₀^h
        p = p.add(&e.mul(&p));
        e = e.mul(&e);
    }
    (e, p)
}

/// Strips leading zeros of a descending coefficient slice.
fn trim<T: Real>(c: &[T]) -> &[T] {
    let first = c.iter().position(|v| *v != T::zero()).unwrap_or(c.len());
    c.get(first..).unwrap_or(&[])
}

fn check_coeffs<T: Real>(c: &[T], field: &'static str) -> Result<(), Error> {
    for v in c {
        finite(*v, field)?;
    }
    Ok(())
}

/// The normalized companion data of `b(s)/a(s)`: monic denominator tail `a₁…aₙ`,
/// strictly-proper numerator `c₁…cₙ` and feed-through `d`.
fn companion<T: Real, const N: usize>(
    num: &[T],
    den: &[T],
) -> Result<([T; N], [T; N], T, usize), Error> {
    check_coeffs(num, "num")?;
    check_coeffs(den, "den")?;
    let den = trim(den);
    let num = trim(num);
    let lead = *den.first().ok_or(Error::Improper("den"))?;
    let n = den.len().saturating_sub(1);
    if num.len() > den.len() {
        return Err(Error::Improper("num"));
    }
    if n > N {
        return Err(Error::OrderTooHigh("den"));
    }
    let mut a = [T::zero(); N];
    for (ai, di) in a.iter_mut().zip(den.iter().skip(1)) {
        *ai = *di / lead;
    }
    // numerator padded to n+1 coefficients, normalized by the denominator's lead
    let pad = den.len().saturating_sub(num.len());
    let b = |i: usize| -> T {
        if i < pad {
            T::zero()
        } else {
            num.get(i.wrapping_sub(pad)).copied().unwrap_or(T::zero()) / lead
        }
    };
    let d = b(0);
    let mut c = [T::zero(); N];
    for (i, ci) in c.iter_mut().enumerate().take(n) {
        let ai = a.get(i).copied().unwrap_or(T::zero());
        *ci = b(i.wrapping_add(1)) - d * ai;
    }
    Ok((a, c, d, n))
}

/// A continuous realization `(A, b, c, d, n)` of `num(s)/den(s)` in
/// controllable canonical form (`ẋ = Ax + b·u`, `y = c·x + d·u`, order `n ≤ N`).
pub type Realization<T, const N: usize> = ([[T; N]; N], [T; N], [T; N], T, usize);

/// The controllable canonical realization of the continuous `num(s)/den(s)`
/// (descending coefficients), the one [`Lti::from_tf`] discretizes.
pub fn realize<T: Real, const N: usize>(num: &[T], den: &[T]) -> Result<Realization<T, N>, Error> {
    let (a, c, d, n) = companion::<T, N>(num, den)?;
    let mut am = [[T::zero(); N]; N];
    if let Some(row) = am.first_mut() {
        for (x, aj) in row.iter_mut().zip(a.iter()).take(n) {
            *x = -*aj;
        }
    }
    for i in 1..n {
        if let Some(v) = am.get_mut(i).and_then(|r| r.get_mut(i.wrapping_sub(1))) {
            *v = T::one();
        }
    }
    let mut b = [T::zero(); N];
    if n > 0 {
        if let Some(b0) = b.first_mut() {
            *b0 = T::one();
        }
    }
    Ok((am, b, c, d, n))
}

/// Capacity of the coefficient lists the `*_of` constructors convert.
const CAST: usize = 24;

/// `p` converted to `T`, in a fixed array (its length alongside).
fn cast_coeffs<T: Real>(p: &[f64]) -> Result<([T; CAST], usize), Error> {
    if p.len() > CAST {
        return Err(Error::OrderTooHigh("polynomial"));
    }
    let mut o = [T::zero(); CAST];
    for (d, v) in o.iter_mut().zip(p) {
        *d = T::of(*v);
    }
    Ok((o, p.len()))
}

impl<T: Real, const N: usize> Lti<T, N> {
    /// [`Lti::from_tf`] for coefficients designed in `f64`: the block is
    /// discretized in `f64` (pole-zero matching finds roots, ZOH takes a
    /// matrix exponential: in `f32` a pole near `z = 1` would lose most of its
    /// distance to 1) and then rounded to this precision ([`Lti::of`]).
    pub fn from_tf_of(
        num: &[f64],
        den: &[f64],
        ts: f64,
        method: Discretization,
    ) -> Result<Self, Error> {
        Ok(Self::of(&Lti::<f64, N>::from_tf(num, den, ts, method)?))
    }

    /// A block designed (discretized) in `f64`, in this precision: every
    /// coefficient and state rounded with [`Real::of`].
    pub fn of(b: &Lti<f64, N>) -> Self {
        let vec = |v: &[f64; N]| v.map(T::of);
        Lti {
            phi: b.phi.map(|row| row.map(T::of)),
            gamma: vec(&b.gamma),
            c: vec(&b.c),
            d: T::of(b.d),
            x: vec(&b.x),
            n: b.n,
        }
    }

    /// [`Lti::from_discrete_tf`] for coefficients designed in `f64`.
    pub fn from_discrete_tf_of(num: &[f64], den: &[f64]) -> Result<Self, Error> {
        let ((n, nl), (d, dl)) = (cast_coeffs::<T>(num)?, cast_coeffs::<T>(den)?);
        Self::from_discrete_tf(n.get(..nl).unwrap_or(&[]), d.get(..dl).unwrap_or(&[]))
    }

    /// A static gain `y = k·u` (order 0).
    pub fn gain(k: T) -> Result<Self, Error> {
        Ok(Lti {
            phi: [[T::zero(); N]; N],
            gamma: [T::zero(); N],
            c: [T::zero(); N],
            d: finite(k, "k")?,
            x: [T::zero(); N],
            n: 0,
        })
    }

    /// A continuous transfer function `num(s)/den(s)` (coefficients in descending
    /// powers of `s`) discretized at `ts` by `method`.
    pub fn from_tf(num: &[T], den: &[T], ts: T, method: Discretization) -> Result<Self, Error> {
        let ts = positive(ts, "ts")?;
        match method {
            Discretization::Matched => return Self::matched(num, den, ts),
            Discretization::Zoh | Discretization::Tustin => {}
        }
        let (a, c, d, n) = companion::<T, N>(num, den)?;
        let mut am = Mat::<T, N>::zeros(n);
        for (j, aj) in a.iter().enumerate().take(n) {
            am.set(0, j, -*aj);
        }
        for i in 1..n {
            am.set(i, i.wrapping_sub(1), T::one());
        }
        let mut b = [T::zero(); N];
        if let Some(b0) = b.first_mut() {
            *b0 = T::one();
        }
        Self::from_state_space_mat(&am, &b, &c, d, ts, method)
    }

    /// A continuous state-space system `(A, B, C, D)` of order `n ≤ N` (only the
    /// leading `n×n` block of `a` is used) discretized at `ts` by ZOH or Tustin.
    #[allow(clippy::too_many_arguments)]
    pub fn from_state_space(
        a: &[[T; N]; N],
        b: &[T; N],
        c: &[T; N],
        d: T,
        n: usize,
        ts: T,
        method: Discretization,
    ) -> Result<Self, Error> {
        if n > N {
            return Err(Error::OrderTooHigh("n"));
        }
        for row in a {
            check_coeffs(row, "a")?;
        }
        check_coeffs(b, "b")?;
        check_coeffs(c, "c")?;
        finite(d, "d")?;
        let ts = positive(ts, "ts")?;
        if method == Discretization::Matched {
            return Err(Error::Unsupported(
                "pole-zero matching of a state-space model",
            ));
        }
        Self::from_state_space_mat(&Mat { a: *a, n }, b, c, d, ts, method)
    }

    fn from_state_space_mat(
        a: &Mat<T, N>,
        b: &[T; N],
        c: &[T; N],
        d: T,
        ts: T,
        method: Discretization,
    ) -> Result<Self, Error> {
        let n = a.n;
        let (phi, gamma, c, d) = match method {
            Discretization::Zoh | Discretization::Matched => {
                let (e, p) = expm_and_integral(a, ts);
                (e, p.mul_vec(b), *c, d)
            }
            Discretization::Tustin => {
                // scipy's bilinear form: M = I − A h/2,
                // Φ = M⁻¹(I + A h/2), Γ = M⁻¹ B h, C_d = C M⁻¹, D_d = D + C Γ / 2.
                let ah2 = a.scale(ts * T::half());
                let m = Mat::eye(n).add(&ah2.scale(-T::one()));
                let minv = m.solve(&Mat::eye(n))?;
                let phi = minv.mul(&Mat::eye(n).add(&ah2));
                let g0 = minv.mul_vec(b);
                let mut gamma = [T::zero(); N];
                for (g, v) in gamma.iter_mut().zip(g0.iter()) {
                    *g = *v * ts;
                }
                let mut cd = [T::zero(); N];
                for (j, cj) in cd.iter_mut().enumerate().take(n) {
                    let mut s = T::zero();
                    for (k, ck) in c.iter().enumerate().take(n) {
                        s = s + *ck * minv.get(k, j);
                    }
                    *cj = s;
                }
                let cg = c
                    .iter()
                    .zip(gamma.iter())
                    .take(n)
                    .fold(T::zero(), |s, (a, b)| s + *a * *b);
                (phi, gamma, cd, d + cg * T::half())
            }
        };
        let out = Lti {
            phi: phi.a,
            gamma,
            c,
            d,
            x: [T::zero(); N],
            n,
        };
        out.check_finite()
    }

    fn check_finite(self) -> Result<Self, Error> {
        let ok = self.phi.iter().flatten().all(|v| v.is_finite())
            && self.gamma.iter().all(|v| v.is_finite())
            && self.c.iter().all(|v| v.is_finite())
            && self.d.is_finite();
        if ok {
            Ok(self)
        } else {
            Err(Error::Numerical(
                "discretization (overflow: sample period too long for an unstable pole?)",
            ))
        }
    }

    /// A discrete transfer function `num(z)/den(z)` (descending powers of `z`),
    /// realized in controllable canonical form.
    pub fn from_discrete_tf(num: &[T], den: &[T]) -> Result<Self, Error> {
        // the same canonical form as the continuous one, read as Φ and Γ
        let (phi, gamma, c, d, n) = realize::<T, N>(num, den)?;
        Lti {
            phi,
            gamma,
            c,
            d,
            x: [T::zero(); N],
            n,
        }
        .check_finite()
    }

    /// First-order lag `k/(τ s + 1)`, ZOH-discretized: `y[k+1] = a y[k] + k(1−a) u[k]`,
    /// `a = e^{−Ts/τ}`. A negative `τ` gives the unstable `k/(τ s + 1)` pole at `−1/τ`.
    pub fn first_order(k: T, tau: T, ts: T) -> Result<Self, Error> {
        let tau = finite(tau, "tau")?;
        if tau == T::zero() {
            return Err(Error::NotPositive("tau"));
        }
        Self::from_tf(
            &[finite(k, "k")?],
            &[tau, T::one()],
            ts,
            Discretization::Zoh,
        )
    }

    /// Integrator `k/s`, ZOH-discretized: `y[k+1] = y[k] + k·Ts·u[k]`.
    pub fn integrator(k: T, ts: T) -> Result<Self, Error> {
        Self::from_tf(
            &[finite(k, "k")?],
            &[T::one(), T::zero()],
            ts,
            Discretization::Zoh,
        )
    }

    /// Lead-lag `k(a s + 1)/(b s + 1)`, ZOH-discretized.
    pub fn lead_lag(k: T, a: T, b: T, ts: T) -> Result<Self, Error> {
        let b = positive(b, "b")?;
        Self::from_tf(
            &[finite(k, "k")? * finite(a, "a")?, k],
            &[b, T::one()],
            ts,
            Discretization::Zoh,
        )
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

    /// `x[k+1] = Φ x[k] + Γ u[k]` without computing the output.
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
        let n = self.n;
        let z = Complex::cis(theta);
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
        Mat {
            a: self.phi,
            n: self.n,
        }
        .mul_vec(v)
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
        let n = self.n;
        let m = Mat::eye(n).add(&Mat { a: self.phi, n }.scale(-T::one()));
        let mut g = Mat::<T, N>::zeros(n);
        for (i, gi) in self.gamma.iter().enumerate().take(n) {
            g.set(i, 0, *gi * u);
        }
        let x = m.solve(&g)?;
        for (i, xi) in self.x.iter_mut().enumerate().take(n) {
            *xi = x.get(i, 0);
        }
        Ok(())
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

    /// The DC gain `C (I − Φ)⁻¹ Γ + D`, or an error for a pole at `z = 1`.
    pub fn dc_gain(&self) -> Result<T, Error> {
        let mut probe = *self;
        probe.set_steady(T::one())?;
        Ok(probe.output(T::one()))
    }

    fn matched(num: &[T], den: &[T], ts: T) -> Result<Self, Error> {
        check_coeffs(num, "num")?;
        check_coeffs(den, "den")?;
        let num = trim(num);
        let den = trim(den);
        let nz = num.len().saturating_sub(1);
        let np = den.len().saturating_sub(1);
        // an improper controller (a PD, a PID with a lead) gets a pole at z = 0
        // for each excess zero: a backward difference, causal
        let order = nz.max(np);
        if order > N || order > MAX_MATCHED {
            return Err(Error::OrderTooHigh("den"));
        }
        let mut zr = [Complex::<T>::default(); MAX_MATCHED];
        let mut pr = [Complex::<T>::default(); MAX_MATCHED];
        roots(num, &mut zr)?;
        roots(den, &mut pr)?;
        let zn = poly_from_roots(zr.get(..nz).unwrap_or(&[]), ts);
        let zd = poly_from_roots(pr.get(..np).unwrap_or(&[]), ts);
        // DC match after removing roots at the origin: lim s^m·b/a at s = 0
        // against lim ((z−1)/Ts)^m·b_d/a_d at z = 1.
        let cont = strip_origin_value(num) / strip_origin_value(den);
        let disc = strip_one_value(&zn, nz.saturating_add(1), ts)
            / strip_one_value(&zd, np.saturating_add(1), ts);
        if !(disc.is_finite() && disc != T::zero()) {
            return Err(Error::Numerical("pole-zero matching gain"));
        }
        let k = cont / disc;
        let mut nb = zn;
        for v in nb.iter_mut() {
            *v = *v * k;
        }
        // zd is zero beyond its degree: the first order + 1 entries are zd·z^(nz − np)
        Self::from_discrete_tf(
            nb.get(..nz.saturating_add(1)).unwrap_or(&[]),
            zd.get(..order.saturating_add(1)).unwrap_or(&[]),
        )
    }
}

/// Largest order pole-zero matching handles.
const MAX_MATCHED: usize = 16;

/// Value at `s = 0` of a polynomial with its roots at the origin removed (lowest
/// non-zero coefficient), descending coefficients.
fn strip_origin_value<T: Real>(p: &[T]) -> T {
    p.iter()
        .rev()
        .find(|v| **v != T::zero())
        .copied()
        .unwrap_or(T::one())
}

/// Value at `z = 1` of `p(z)/((z−1)/ts)^m` where `m` is the multiplicity of the root
/// at 1, for monic descending coefficients `p[..len]`.
fn strip_one_value<T: Real>(p: &[T], len: usize, ts: T) -> T {
    let mut c = [T::zero(); MAX_MATCHED + 1];
    for (d, s) in c.iter_mut().zip(p.iter().take(len)) {
        *d = *s;
    }
    let mut len = len;
    loop {
        let v: T = c.iter().take(len).fold(T::zero(), |s, x| s + *x);
        if v.abs() > T::of(1e-9) * c.iter().take(len).fold(T::zero(), |s, x| s + x.abs())
            || len <= 1
        {
            return v;
        }
        // synthetic division by (z − 1), then scale by ts
        let mut acc = T::zero();
        for x in c.iter_mut().take(len.saturating_sub(1)) {
            acc = acc + *x;
            *x = acc * ts;
        }
        len = len.saturating_sub(1);
    }
}

/// Roots of a real polynomial (descending coefficients) by the Durand–Kerner
/// iteration; `out` receives `deg` roots.
pub(crate) fn roots<T: Real>(p: &[T], out: &mut [Complex<T>]) -> Result<(), Error> {
    let deg = p.len().saturating_sub(1);
    if deg == 0 {
        return Ok(());
    }
    if deg > out.len() {
        return Err(Error::OrderTooHigh("polynomial"));
    }
    let lead = p.first().copied().unwrap_or(T::one());
    let eval = |z: Complex<T>| -> Complex<T> {
        p.iter().fold(Complex::default(), |acc, c| {
            acc.mul(z).add(Complex::new(*c / lead, T::zero()))
        })
    };
    let seed = Complex::new(T::of(0.4), T::of(0.9));
    // radius bound: 1 + max |a_i / a_0|
    let r = p
        .iter()
        .skip(1)
        .fold(T::zero(), |m, c| m.max((*c / lead).abs()))
        + T::one();
    let mut z = Complex::new(T::one(), T::zero());
    for o in out.iter_mut().take(deg) {
        *o = z.mul(Complex::new(r, T::zero()));
        z = z.mul(seed);
    }
    for _ in 0..500 {
        let mut delta = T::zero();
        for i in 0..deg {
            let zi = out.get(i).copied().unwrap_or_default();
            let mut den = Complex::new(T::one(), T::zero());
            for (j, zj) in out.iter().enumerate().take(deg) {
                if j != i {
                    den = den.mul(zi.sub(*zj));
                }
            }
            let step = eval(zi).div(den);
            if let Some(o) = out.get_mut(i) {
                *o = zi.sub(step);
            }
            delta = delta.max(step.abs());
        }
        if delta < T::epsilon() * T::of(16.0) * r {
            break;
        }
    }
    for o in out.iter_mut().take(deg) {
        if o.im.abs() < T::of(1e-9) * (T::one() + o.re.abs()) {
            o.im = T::zero();
        }
        if !(o.re.is_finite() && o.im.is_finite()) {
            return Err(Error::Numerical("polynomial roots"));
        }
    }
    Ok(())
}

/// Monic polynomial (descending coefficients, real parts) with roots `e^{r·ts}`.
/// Long division in place of `a` (descending coefficients) by `b`: afterwards
/// the first `a.len() − b.len() + 1` entries hold the quotient and the rest
/// the remainder. Returns the quotient's length (0 when `b` is the longer).
pub(crate) fn divide_in_place<T: Real>(a: &mut [T], b: &[T]) -> usize {
    let lead = b.first().copied().unwrap_or(T::one());
    let qlen = a.len().saturating_add(1).saturating_sub(b.len());
    for i in 0..qlen {
        let f = a.get(i).copied().unwrap_or(T::zero()) / lead;
        for (j, bj) in b.iter().enumerate().skip(1) {
            if let Some(x) = a.get_mut(i.saturating_add(j)) {
                *x = *x - f * *bj;
            }
        }
        if let Some(x) = a.get_mut(i) {
            *x = f;
        }
    }
    qlen
}

fn poly_from_roots<T: Real>(r: &[Complex<T>], ts: T) -> [T; MAX_MATCHED + 1] {
    let mut c = [Complex::<T>::default(); MAX_MATCHED + 1];
    if let Some(c0) = c.first_mut() {
        *c0 = Complex::new(T::one(), T::zero());
    }
    let mut len = 1usize;
    for root in r.iter().take(MAX_MATCHED) {
        let z = root.exp_scaled(ts);
        // multiply by (x − z): c'[i] = c[i] − z·c[i−1]
        let mut prev = Complex::default();
        for ci in c.iter_mut().take(len.saturating_add(1)) {
            let cur = *ci;
            *ci = cur.sub(z.mul(prev));
            prev = cur;
        }
        len = len.saturating_add(1);
    }
    let mut out = [T::zero(); MAX_MATCHED + 1];
    for (o, v) in out.iter_mut().zip(c.iter()) {
        *o = v.re;
    }
    out
}
