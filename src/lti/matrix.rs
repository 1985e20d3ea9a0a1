//! The design-time linear algebra of the blocks, on nalgebra's fixed-size
//! matrices in `f64` (a block for `f32` is designed in `f64` and rounded
//! once): realizations, the matrix exponential of ZOH discretization, solves.
//! Never on the per-sample path.
//!
//! A block of order `n` lives in the leading `n×n` corner of an `N×N` matrix;
//! the rest is zero, which every product, sum and exponential below carries
//! through unchanged (a solve puts ones on the unused diagonal).

use nalgebra::{SMatrix, SVector};

use crate::{error::Error, real::Real};
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

/// The inverse of the leading `n×n` block of `a` (zero outside it), by
/// Gauss–Jordan elimination with partial pivoting; a pivot below
/// `ε·‖A‖₁` is a matrix singular to working precision.
///
/// Written out on nalgebra's storage rather than with nalgebra's `LU`: its
/// index assertions would link a panic path into every device build that
/// designs a block (the C library is checked to have none), and here each
/// access is a checked `get` that cannot panic.
pub(crate) fn inverse<const N: usize>(a: &Mat<N>, n: usize) -> Result<Mat<N>, Error> {
    if n > N {
        return Err(Error::OrderTooHigh("n"));
    }
    let scale = norm1(a).max(f64::MIN_POSITIVE);
    let mut m = *a;
    let mut inv = Mat::<N>::zeros();
    for i in 0..n {
        if let Some(x) = inv.get_mut((i, i)) {
            *x = 1.0;
        }
    }
    let at = |m: &Mat<N>, i: usize, j: usize| m.get((i, j)).copied().unwrap_or(0.0);
    for col in 0..n {
        // the largest pivot of the column at or below the diagonal
        let (piv, size) = (col..n)
            .map(|r| (r, at(&m, r, col).abs()))
            .fold((col, -1.0), |best, c| if c.1 > best.1 { c } else { best });
        if !(size > f64::EPSILON * scale) {
            return Err(Error::Numerical("matrix inversion"));
        }
        if piv != col {
            for j in 0..n {
                for x in [&mut m, &mut inv] {
                    let (p, c) = (at(x, piv, j), at(x, col, j));
                    if let Some(e) = x.get_mut((piv, j)) {
                        *e = c;
                    }
                    if let Some(e) = x.get_mut((col, j)) {
                        *e = p;
                    }
                }
            }
        }
        let d = at(&m, col, col);
        for j in 0..n {
            for x in [&mut m, &mut inv] {
                if let Some(e) = x.get_mut((col, j)) {
                    *e /= d;
                }
            }
        }
        for r in (0..n).filter(|r| *r != col) {
            let f = at(&m, r, col);
            if f == 0.0 {
                continue;
            }
            for j in 0..n {
                for x in [&mut m, &mut inv] {
                    let v = at(x, col, j);
                    if let Some(e) = x.get_mut((r, j)) {
                        *e -= f * v;
                    }
                }
            }
        }
    }
    Ok(inv)
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
