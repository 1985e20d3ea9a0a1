//! The design-time linear algebra of the blocks, on nalgebra's fixed-size
//! matrices in `f64` (a block for `f32` is designed in `f64` and rounded
//! once): realizations, the matrix exponential of ZOH discretization, solves.
//! Never on the per-sample path.
//!
//! A block of order `n` lives in the leading `n×n` corner of an `N×N` matrix;
//! the rest is zero, which every product, sum and exponential below carries
//! through unchanged (a solve puts ones on the unused diagonal).

use nalgebra::{SMatrix, SVector};

use crate::{Error, Real};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// An `N×N` design matrix.
pub(crate) type Mat<const N: usize> = SMatrix<f64, N, N>;
/// An `N`-vector of the design.
pub(crate) type Vector<const N: usize> = SVector<f64, N>;

/// The leading `n×n` block of `a`, widened to `f64`.
pub(super) fn mat_of<T: Real, const N: usize>(a: &[[T; N]; N], n: usize) -> Mat<N> {
    Mat::from_fn(|i, j| {
        if i < n && j < n {
            a.get(i).and_then(|r| r.get(j)).map_or(0.0, |v| v.f64())
        } else {
            0.0
        }
    })
}

/// The leading `n×n` block of `m` as rows of `T` (zero outside).
pub(super) fn rows_of<T: Real, const N: usize>(m: &Mat<N>, n: usize) -> [[T; N]; N] {
    let mut out = [[T::zero(); N]; N];
    for (i, row) in out.iter_mut().enumerate().take(n) {
        for (j, x) in row.iter_mut().enumerate().take(n) {
            *x = T::of(m.get((i, j)).copied().unwrap_or(0.0));
        }
    }
    out
}

/// The first `n` entries of `v`, widened to `f64`.
pub(super) fn vector_of<T: Real, const N: usize>(v: &[T; N], n: usize) -> Vector<N> {
    Vector::from_fn(|i, _| {
        if i < n {
            v.get(i).map_or(0.0, |x| x.f64())
        } else {
            0.0
        }
    })
}

/// The first `n` entries of `v` as an array of `T` (zero after).
pub(super) fn array_of<T: Real, const N: usize>(v: &Vector<N>, n: usize) -> [T; N] {
    let mut out = [T::zero(); N];
    for (o, x) in out.iter_mut().zip(v.iter()).take(n) {
        *o = T::of(*x);
    }
    out
}

/// The 1-norm (largest column sum of magnitudes).
fn norm1<const N: usize>(a: &SMatrix<f64, N, N>) -> f64 {
    a.column_iter()
        .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Solves `A·X = B` for the leading `n×n` block of `a` and the leading `n`
/// rows of `b`; refuses a matrix singular to working precision.
pub(crate) fn solve<const N: usize, const C: usize>(
    a: &Mat<N>,
    b: &SMatrix<f64, N, C>,
    n: usize,
) -> Result<SMatrix<f64, N, C>, Error> {
    Ok(inverse(a, n)? * b)
}

/// The inverse of the leading `n×n` block of `a` (zero outside it), by LU
/// with partial pivoting. The factorization runs at a fixed size (4, or 16
/// for larger blocks) so that nalgebra's decompositions see a concrete dimension.
pub(crate) fn inverse<const N: usize>(a: &Mat<N>, n: usize) -> Result<Mat<N>, Error> {
    if n <= 4 {
        inverse_at::<4, N>(a, n)
    } else if n <= 16 {
        inverse_at::<16, N>(a, n)
    } else {
        Err(Error::OrderTooHigh("n"))
    }
}

fn inverse_at<const M: usize, const N: usize>(a: &Mat<N>, n: usize) -> Result<Mat<N>, Error>
where
    nalgebra::Const<M>: nalgebra::DimMin<nalgebra::Const<M>, Output = nalgebra::Const<M>>,
{
    // the leading block, ones on the rest of the diagonal
    let am = SMatrix::<f64, M, M>::from_fn(|i, j| match (i < n && j < n, i == j) {
        (true, _) => a.get((i, j)).copied().unwrap_or(0.0),
        (false, true) => 1.0,
        (false, false) => 0.0,
    });
    let scale = norm1(&am).max(f64::MIN_POSITIVE);
    let lu = am.lu();
    let smallest = lu
        .u()
        .diagonal()
        .iter()
        .fold(f64::INFINITY, |m, x| m.min(x.abs()));
    if !(smallest > f64::EPSILON * scale) {
        return Err(Error::Numerical("matrix inversion"));
    }
    let inv = lu
        .try_inverse()
        .ok_or(Error::Numerical("matrix inversion"))?;
    Ok(Mat::<N>::from_fn(|i, j| {
        if i < n && j < n {
            inv.get((i, j)).copied().unwrap_or(0.0)
        } else {
            0.0
        }
    }))
}

/// `e^{A h}` and `∫₀^h e^{A τ} dτ` (Moler & Van Loan (2003), method 3) by
/// scaling and squaring of their Taylor
/// series (the integral is what ZOH needs for `Γ`, and it exists for a
/// singular `A`: integrators).
pub(super) fn expm_and_integral<const N: usize>(a: &Mat<N>, h: f64) -> (Mat<N>, Mat<N>) {
    let norm = norm1(a) * h;
    let mut squarings = 0i32;
    let mut hs = h;
    while norm * 0.5f64.powi(squarings) > 0.5 && squarings < 60 {
        squarings = squarings.saturating_add(1);
        hs *= 0.5;
    }
    let ah = a * hs;
    // E = Σ (Ah)^k / k!,  P = h Σ (Ah)^k / (k+1)!
    let mut e = Mat::<N>::identity();
    let mut p = Mat::<N>::identity() * hs;
    let mut term = Mat::<N>::identity();
    let mut k = 1.0;
    for _ in 0..30 {
        term = term * ah / k;
        e += term;
        p += term * (hs / (k + 1.0));
        k += 1.0;
        if norm1(&term) < f64::EPSILON * 1e-3 {
            break;
        }
    }
    for _ in 0..squarings {
        // ∫₀^{2h} = ∫₀^h + e^{Ah} ∫₀^h
        p += e * p;
        e = e * e;
    }
    (e, p)
}
