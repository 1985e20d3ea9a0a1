//! Model-sized polynomials in fixed arrays and the transfer function of a
//! discrete block: what the dead-time compensators' designs and the
//! analysis's `z`-domain evaluation share, without allocation.

use crate::complex::Complex;
use crate::{error::Error, lti::Lti, real::Real};

/// Capacity of [`SmallPoly`].
pub const SMALL: usize = 24;

/// A polynomial of degree below [`SMALL`] (descending coefficients).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmallPoly {
    c: [f64; SMALL],
    len: usize,
}

impl SmallPoly {
    /// `p` with its leading zeros dropped (at least one coefficient kept).
    pub fn new(p: &[f64]) -> Result<Self, Error> {
        let first = p
            .iter()
            .position(|v| *v != 0.0)
            .unwrap_or(p.len().saturating_sub(1));
        let p = p.get(first..).unwrap_or(&[]);
        if p.len() > SMALL {
            return Err(Error::OrderTooHigh("polynomial"));
        }
        let mut c = [0.0; SMALL];
        for (d, v) in c.iter_mut().zip(p) {
            *d = *v;
        }
        Ok(SmallPoly {
            c,
            len: p.len().max(1),
        })
    }
    /// The coefficients.
    pub fn as_slice(&self) -> &[f64] {
        self.c.get(..self.len).unwrap_or(&[])
    }
    /// The product with `b`.
    pub fn mul(&self, b: &[f64]) -> Result<Self, Error> {
        let n = self.len.saturating_add(b.len()).saturating_sub(1);
        if n > SMALL {
            return Err(Error::OrderTooHigh("polynomial"));
        }
        let mut c = [0.0; SMALL];
        for (i, x) in self.as_slice().iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                if let Some(o) = c.get_mut(i.saturating_add(j)) {
                    *o += x * y;
                }
            }
        }
        Ok(SmallPoly { c, len: n.max(1) })
    }
    /// Number of coefficients.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Always false: a polynomial keeps one coefficient.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// The leading coefficient.
    pub(crate) fn lead(&self) -> f64 {
        self.c.first().copied().unwrap_or(1.0)
    }
}

/// Numerator and denominator (descending powers of `z`, the numerator with
/// as many coefficients as the denominator) of a discrete block, by
/// Faddeev–LeVerrier on its realization.
pub fn model_tf<T: Real, const N: usize>(b: &Lti<T, N>) -> (SmallPoly, SmallPoly) {
    let n = b.order().min(N);
    let at = |m: &[[f64; N]; N], i: usize, j: usize| {
        m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
    };
    // numerator: C·M_k·Γ for k = 0..n−1 (the coefficient of z^{n−1−k}), plus D·den
    let (cv, g, d) = (b.output_vector(), b.input_vector(), b.feedthrough());
    let mut num = [0.0; SMALL];
    let (c, len) = crate::lti::faddeev(b, |k, mk| {
        let v: f64 = (0..n)
            .map(|i| {
                cv.get(i).map_or(0.0, |c| c.f64())
                    * (0..n)
                        .map(|j| at(mk, i, j) * g.get(j).map_or(0.0, |g| g.f64()))
                        .sum::<f64>()
            })
            .sum();
        if let Some(x) = num.get_mut(k + 1) {
            *x = v;
        }
    });
    let len = len.min(SMALL);
    let mut den = [0.0; SMALL];
    for (x, v) in den.iter_mut().zip(c.iter()).take(len) {
        *x = *v;
    }
    for (x, ck) in num.iter_mut().zip(den.iter()).take(len) {
        *x += d.f64() * ck;
    }
    (SmallPoly { c: num, len }, SmallPoly { c: den, len })
}

/// `Σ p_k w^k`: Horner's rule (one complex product per tap instead of a
/// sine and cosine) as four interleaved chains in `w⁴` — the taps `4m + j`
/// summed in the chain `j` — so that a numerator spanning a long dead time
/// is not one chain of dependent products (the analysis evaluates it at
/// thousands of frequencies).
pub fn taps_at<T: Real>(p: &[T], w: Complex<T>) -> Complex<T> {
    let w2 = w * w;
    let w4 = w2 * w2;
    let mut acc = [Complex::default(); 4];
    // from the highest power down; a partial last chunk meets chains still at zero
    for chunk in p.chunks(4).rev() {
        for (a, b) in acc.iter_mut().zip(chunk) {
            *a = *a * w4 + Complex::real(*b);
        }
    }
    let [a0, a1, a2, a3] = acc;
    a0 + w * a1 + w2 * (a2 + w * a3)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The interleaved Horner sum is the polynomial's value, for every
    /// length around the chains' multiple of four: against the sum of
    /// `p_k·e^{−jkθ}` from each term's own sine and cosine.
    #[test]
    fn taps_at_is_the_polynomial() {
        for n in 0..11usize {
            let p: std::vec::Vec<f64> = (0..n).map(|k| 1.0 + 0.37 * k as f64).collect();
            for theta in [0.0, 0.3, 1.7, 3.1] {
                let got = taps_at(&p, Complex::cis(-theta));
                let want = p.iter().enumerate().fold(Complex::default(), |a, (k, b)| {
                    a + Complex::cis(-theta * k as f64).scale(*b)
                });
                let err = (got - want).abs();
                // a few roundings per term of a sum of magnitude below 25
                assert!(err < 1e-13, "n {n}, θ {theta}: {err:e}");
            }
        }
    }
}
