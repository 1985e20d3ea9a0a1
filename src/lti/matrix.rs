//! The small dense matrices of the design: realizations and the matrix
//! exponential of ZOH discretization (never on the per-sample path).

use crate::{Error, Real};

/// A small dense matrix for design-time computations (never on the per-sample path).
#[derive(Clone, Copy)]
pub(super) struct Mat<T, const N: usize> {
    pub(super) a: [[T; N]; N],
    pub(super) n: usize,
}

impl<T: Real, const N: usize> Mat<T, N> {
    pub(super) fn zeros(n: usize) -> Self {
        Mat {
            a: [[T::zero(); N]; N],
            n,
        }
    }
    pub(super) fn eye(n: usize) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            m.set(i, i, T::one());
        }
        m
    }
    #[inline]
    pub(super) fn get(&self, i: usize, j: usize) -> T {
        self.a
            .get(i)
            .and_then(|r| r.get(j))
            .copied()
            .unwrap_or(T::zero())
    }
    #[inline]
    pub(super) fn set(&mut self, i: usize, j: usize, v: T) {
        if let Some(x) = self.a.get_mut(i).and_then(|r| r.get_mut(j)) {
            *x = v;
        }
    }
    pub(super) fn mul(&self, b: &Self) -> Self {
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
    pub(super) fn add(&self, b: &Self) -> Self {
        let mut c = *self;
        for i in 0..self.n {
            for j in 0..self.n {
                c.set(i, j, self.get(i, j) + b.get(i, j));
            }
        }
        c
    }
    pub(super) fn scale(&self, s: T) -> Self {
        let mut c = *self;
        for i in 0..self.n {
            for j in 0..self.n {
                c.set(i, j, self.get(i, j) * s);
            }
        }
        c
    }
    pub(super) fn norm1(&self) -> T {
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
    pub(super) fn mul_vec(&self, v: &[T; N]) -> [T; N] {
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
    pub(super) fn solve(&self, b: &Self) -> Result<Self, Error> {
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
pub(super) fn expm_and_integral<T: Real, const N: usize>(
    a: &Mat<T, N>,
    h: T,
) -> (Mat<T, N>, Mat<T, N>) {
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
