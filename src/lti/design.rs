//! Construction and discretization of [`Lti`] blocks: realization,
//! ZOH, Tustin and pole-zero matching.

use super::matrix::{array_of, expm_and_integral, inverse, mat_of, rows_of, vector_of, Mat};
use super::{Discretization, Lti};
use crate::complex::Complex;
use crate::real::{finite, positive};
use crate::{error::Error, real::Real};
use core::ops::{Add, Div, Mul, Sub};

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
        // a coefficient beyond this precision's range is refused, not rounded to ∞
        Self::of(&Lti::<f64, N>::from_tf(num, den, ts, method)?).check_finite()
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
        // the controllable canonical form: first row −a, ones below the diagonal
        let (a, c, d, n) = companion::<T, N>(num, den)?;
        let tail = a.map(|x| x.f64());
        let am = Mat::<N>::from_fn(|i, j| companion_entry(&tail, n, i, j));
        let mut b = [T::zero(); N];
        if let Some(b0) = b.first_mut() {
            *b0 = T::one();
        }
        Self::from_state_space_mat(&am, n, &b, &c, d, ts, method)
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
        Self::from_state_space_mat(&mat_of(a, n), n, b, c, d, ts, method)
    }

    /// Discretizes `(A, B, C, D)` (order `n`, `A` in the leading block), in `f64`.
    fn from_state_space_mat(
        a: &Mat<N>,
        n: usize,
        b: &[T; N],
        c: &[T; N],
        d: T,
        ts: T,
        method: Discretization,
    ) -> Result<Self, Error> {
        let (b, c, d, h) = (vector_of(b, n), vector_of(c, n), d.f64(), ts.f64());
        let (phi, gamma, c, d) = match method {
            // Φ = e^{Ah}, Γ = ∫₀^h e^{Aτ}dτ·B (Franklin, Powell & Workman,
            // Digital Control of Dynamic Systems, Sec. 4.3)
            Discretization::Zoh | Discretization::Matched => {
                let (e, p) = expm_and_integral(a, h);
                (e, p * b, c, d)
            }
            Discretization::Tustin => {
                // scipy's bilinear form: M = I − A h/2,
                // Φ = M⁻¹(I + A h/2), Γ = M⁻¹ B h, C_d = C M⁻¹, D_d = D + C Γ / 2.
                let ah2 = a * (h * 0.5);
                let eye = Mat::<N>::identity();
                let minv = inverse(&(eye - ah2), n)?;
                let gamma = minv * b * h;
                let cd = (c.transpose() * minv).transpose();
                (minv * (eye + ah2), gamma, cd, d + c.dot(&gamma) * 0.5)
            }
        };
        let out = Lti {
            phi: rows_of(&phi, n),
            gamma: array_of(&gamma, n),
            c: array_of(&c, n),
            d: T::of(d),
            x: [T::zero(); N],
            n,
        };
        out.check_finite()
    }

    pub(super) fn check_finite(self) -> Result<Self, Error> {
        let ok = self.phi.iter().flatten().all(|v| v.is_finite())
            && self.gamma.iter().all(|v| v.is_finite())
            && self.c.iter().all(|v| v.is_finite())
            && self.d.is_finite();
        if ok {
            Ok(self)
        } else {
            Err(Error::Numerical(
                "discretization: a coefficient overflowed (a gain too large for f64, or a sample period too long for an unstable pole)",
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

/// Roots of a real polynomial (descending coefficients): the eigenvalues of
/// its companion matrix (nalgebra's real Schur decomposition, as MATLAB's and
/// numpy's `roots`); `out` receives `deg` roots. Degrees up to 16.
pub(crate) fn roots<T: Real>(p: &[T], out: &mut [Complex<T>]) -> Result<(), Error> {
    roots_upto::<16, T>(p, out)
}

/// [`roots`] of a polynomial of degree at most `D`. Degrees 1 and 2 are
/// solved in closed form (the quadratic without cancellation:
/// `q = −(b + sign(b)√(b² − 4c))/2`, roots `q` and `c/q`); with `D ≤ 2` the
/// Schur decomposition is not compiled in at all, so that a device designing
/// a first- or second-order block links no code that could panic (nalgebra's
/// decompositions assert their indices).
pub(crate) fn roots_upto<const D: usize, T: Real>(
    p: &[T],
    out: &mut [Complex<T>],
) -> Result<(), Error> {
    let p = trim(p);
    let deg = p.len().saturating_sub(1);
    if deg == 0 {
        return Ok(());
    }
    if deg > out.len() || deg > D {
        return Err(Error::OrderTooHigh("polynomial"));
    }
    let lead = p.first().map_or(1.0, |x| x.f64());
    let mut monic = [0.0f64; 17];
    for (m, c) in monic.iter_mut().zip(p.iter()) {
        *m = c.f64() / lead;
    }
    let (found, k) = if deg <= 2 {
        low_degree_roots(&monic, deg)
    } else if D <= 2 {
        return Err(Error::OrderTooHigh("polynomial"));
    } else if deg <= 4 {
        companion_roots_4(&monic, deg)?
    } else if deg <= 16 {
        companion_roots_16(&monic, deg)?
    } else {
        return Err(Error::OrderTooHigh("polynomial"));
    };
    if k != deg {
        return Err(Error::Numerical("polynomial roots"));
    }
    for (o, (re, im)) in out.iter_mut().zip(found.iter()).take(deg) {
        if !(re.is_finite() && im.is_finite()) {
            return Err(Error::Numerical("polynomial roots"));
        }
        // a pair split by rounding from a double real root is real
        let im = if im.abs() < 1e-9 * (1.0 + re.abs()) {
            0.0
        } else {
            *im
        };
        *o = Complex::new(T::of(*re), T::of(im));
    }
    Ok(())
}

/// The roots of a monic polynomial of degree 1 or 2, `(re, im)`, and their count.
fn low_degree_roots(monic: &[f64; 17], deg: usize) -> ([(f64, f64); 16], usize) {
    let mut out = [(0.0, 0.0); 16];
    let (b, c) = (monic[1], monic[2]);
    if deg == 1 {
        out[0] = (-b, 0.0);
        return (out, 1);
    }
    let disc = b * b - 4.0 * c;
    if disc >= 0.0 {
        let q = -0.5 * (b + b.signum() * num_traits::Float::sqrt(disc));
        let r2 = if q == 0.0 { 0.0 } else { c / q };
        out[0] = (q, 0.0);
        out[1] = (r2, 0.0);
    } else {
        let im = 0.5 * num_traits::Float::sqrt(-disc);
        out[0] = (-0.5 * b, im);
        out[1] = (-0.5 * b, -im);
    }
    (out, 2)
}

/// Entry `(i, j)` of the companion matrix of the monic polynomial
/// `sᵈ + a₁sᵈ⁻¹ + … + a_d` with `tail = [a₁, …, a_d]`: `−a₁ … −a_d` in the
/// first row, ones below the diagonal, zero outside the leading `d×d` block.
/// It is the controllable canonical form's `A`, and its eigenvalues are the
/// polynomial's roots.
pub(crate) fn companion_entry(tail: &[f64], deg: usize, i: usize, j: usize) -> f64 {
    if i == 0 && j < deg {
        -tail.get(j).copied().unwrap_or(0.0)
    } else if i < deg && j.wrapping_add(1) == i {
        1.0
    } else {
        0.0
    }
}

/// The roots of the monic polynomial `monic[..=deg]` at a fixed matrix size
/// `M ≥ deg`: the companion matrix in the leading block, a sentinel beyond
/// every root (Cauchy's bound) on the rest of the diagonal. The blocks are
/// decoupled by a zero on the subdiagonal, so the sentinels come back exactly
/// and are dropped. Returns the roots `(re, im)` and their count.
macro_rules! companion_roots {
    ($name:ident, $m:literal) => {
        fn $name(monic: &[f64; 17], deg: usize) -> Result<([(f64, f64); 16], usize), Error> {
            let bound = monic
                .iter()
                .skip(1)
                .take(deg)
                .fold(0.0f64, |m, c| m.max(c.abs()))
                + 1.0;
            let sentinel = 2.0 * bound + 1.0;
            let c = nalgebra::SMatrix::<f64, $m, $m>::from_fn(|i, j| {
                if i >= deg && i == j {
                    sentinel
                } else {
                    companion_entry(monic.get(1..).unwrap_or(&[]), deg, i, j)
                }
            });
            let schur = nalgebra::linalg::Schur::try_new(c, f64::EPSILON, 10_000)
                .ok_or(Error::Numerical("polynomial roots"))?;
            let mut out = [(0.0, 0.0); 16];
            let mut k = 0usize;
            for z in schur.complex_eigenvalues().iter() {
                if z.im == 0.0 && z.re == sentinel {
                    continue;
                }
                if let Some(o) = out.get_mut(k) {
                    *o = (z.re, z.im);
                }
                k = k.saturating_add(1);
            }
            Ok((out, k))
        }
    };
}
companion_roots!(companion_roots_4, 4);
companion_roots!(companion_roots_16, 16);

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

/// Capacity of [`char_poly`]: blocks up to this order.
pub(crate) const CHAR_POLY: usize = 25;

/// The characteristic polynomial `det(zI − Φ) = zⁿ + c₁zⁿ⁻¹ + … + cₙ` of a
/// block (descending coefficients, `n + 1` of them) by Faddeev–LeVerrier:
/// `M₀ = I`, `cₖ = −tr(Φ·Mₖ₋₁)/k`, `Mₖ = Φ·Mₖ₋₁ + cₖI`. `each(k, Mₖ)` sees
/// `M₀ … Mₙ₋₁` (the adjugate's coefficients: `adj(zI − Φ) = Σ Mₖ zⁿ⁻¹⁻ᵏ`,
/// from which a transfer function's numerator follows).
pub(crate) fn faddeev<T: Real, const N: usize>(
    b: &Lti<T, N>,
    mut each: impl FnMut(usize, &[[f64; N]; N]),
) -> ([f64; CHAR_POLY], usize) {
    let n = b.order().min(N).min(CHAR_POLY - 1);
    let mut c = [0.0; CHAR_POLY];
    if let Some(c0) = c.first_mut() {
        *c0 = 1.0;
    }
    let at = |m: &[[f64; N]; N], i: usize, j: usize| {
        m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
    };
    let mut m = [[0.0; N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        if let Some(x) = row.get_mut(i) {
            *x = 1.0;
        }
    }
    for k in 1..=n {
        each(k - 1, &m);
        // Φ·M_{k−1}
        let mut am = [[0.0; N]; N];
        for (i, row) in am.iter_mut().enumerate().take(n) {
            for (j, x) in row.iter_mut().enumerate().take(n) {
                *x = (0..n).map(|q| b.phi_entry(i, q).f64() * at(&m, q, j)).sum();
            }
        }
        let tr: f64 = (0..n).map(|i| at(&am, i, i)).sum();
        let ck = -tr / f64::from(u32::try_from(k).unwrap_or(u32::MAX));
        if let Some(x) = c.get_mut(k) {
            *x = ck;
        }
        for (i, row) in am.iter_mut().enumerate() {
            if let Some(x) = row.get_mut(i) {
                *x += ck;
            }
        }
        m = am;
    }
    (c, n + 1)
}

/// The characteristic polynomial of a block ([`faddeev`]).
pub(crate) fn char_poly<T: Real, const N: usize>(b: &Lti<T, N>) -> ([f64; CHAR_POLY], usize) {
    faddeev(b, |_, _| {})
}

/// How many roots of the real polynomial `p` (descending coefficients) lie
/// outside the unit circle. Roots on the circle at `z = ±1` (integrators,
/// and the Nyquist-frequency pole) are divided out first and count as
/// inside; the rest are counted by the argument principle: the winding
/// number of `p(e^{jθ})` about the origin is the number of roots inside the
/// circle (a polynomial has no poles), sampled finely enough that no step
/// turns by more than a quarter turn.
pub(crate) fn roots_outside(p: &[f64]) -> usize {
    let mut c = [0.0; CHAR_POLY];
    let p = trim(p);
    let mut len = p.len().min(CHAR_POLY);
    for (x, v) in c.iter_mut().zip(p) {
        *x = *v;
    }
    let scale = |c: &[f64]| c.iter().fold(0.0f64, |s, v| s + v.abs());
    // divide out roots at z = 1 and z = −1: p(z) = (z − r)·q(z)
    for r in [1.0f64, -1.0] {
        while len > 1 {
            let at = c.iter().take(len).fold(0.0f64, |acc, v| acc * r + *v);
            if at.abs() > 1e-10 * scale(c.get(..len).unwrap_or(&[])) {
                break;
            }
            let mut acc = 0.0;
            for x in c.iter_mut().take(len - 1) {
                acc = acc * r + *x;
                *x = acc;
            }
            len -= 1;
        }
    }
    let deg = len.saturating_sub(1);
    if deg == 0 {
        return 0;
    }
    let coeffs = c.get(..len).unwrap_or(&[]);
    let eval = |theta: f64| {
        let z = Complex::cis(theta);
        coeffs.iter().fold(Complex::real(0.0), |acc, v| {
            acc.mul(z).add(Complex::real(*v))
        })
    };
    let steps = 64 * (deg + 1);
    let mut turned = 0.0;
    let mut prev = eval(0.0);
    for k in 1..=steps {
        #[allow(clippy::cast_precision_loss)] // at most 64·25
        let theta = core::f64::consts::TAU * k as f64 / steps as f64;
        let next = eval(theta);
        turned += next.div(prev).arg();
        prev = next;
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let inside = num_traits::Float::round(turned / core::f64::consts::TAU).max(0.0) as usize;
    deg.saturating_sub(inside)
}
