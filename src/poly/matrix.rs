//! An `n×n` matrix of transfer functions, each with its own dead time: a
//! multivariable plant (its analysis: [`crate::analysis::mimo`]).

use alloc::vec::Vec;

use super::TransferFunction;
use crate::complex::Complex;
use crate::error::Error;

type C64 = Complex<f64>;

/// The largest plant handled (`n×n`).
pub const MAX_SIZE: usize = 8;

/// An `n×n` matrix of transfer functions, each with its own dead time
/// (row `i`: output `i`; column `j`: input `j`).
#[derive(Debug, Clone, PartialEq)]
pub struct TransferMatrix {
    n: usize,
    /// Row-major.
    entries: Vec<TransferFunction>,
}

impl TransferMatrix {
    /// The matrix of `rows`, square, `1 ≤ n ≤` [`MAX_SIZE`].
    pub fn new(rows: Vec<Vec<TransferFunction>>) -> Result<Self, Error> {
        let n = rows.len();
        if n == 0 || n > MAX_SIZE {
            return Err(Error::OutOfRange("the matrix's size"));
        }
        if rows.iter().any(|r| r.len() != n) {
            return Err(Error::Unsupported(
                "a transfer matrix must be square: as many inputs as outputs",
            ));
        }
        Ok(TransferMatrix {
            n,
            entries: rows.into_iter().flatten().collect(),
        })
    }

    /// Its size `n`.
    pub fn size(&self) -> usize {
        self.n
    }

    /// The entry `(i, j)`: from input `j` to output `i`.
    pub fn get(&self, i: usize, j: usize) -> Option<&TransferFunction> {
        if i < self.n && j < self.n {
            self.entries.get(i * self.n + j)
        } else {
            None
        }
    }

    /// `G(jω)`, row-major.
    pub fn response(&self, w: f64) -> Vec<C64> {
        self.entries
            .iter()
            .map(|g| {
                let (re, im) = g.freq(w);
                Complex::new(re, im)
            })
            .collect()
    }

    /// `G(0)`, row-major: every entry's static gain (an integrating entry
    /// has none: an error).
    pub fn steady_state(&self) -> Result<Vec<f64>, Error> {
        self.entries
            .iter()
            .map(|g| {
                if g.integrators() > 0 {
                    Err(Error::Unsupported(
                        "an integrating entry has no steady-state gain (the RGA at a frequency applies)",
                    ))
                } else {
                    Ok(g.gain())
                }
            })
            .collect()
    }

    /// The slowest and fastest time scales of the entries (s), for a
    /// frequency grid.
    pub fn scales(&self) -> (f64, f64) {
        let mut slow: f64 = 0.0;
        let mut fast = f64::INFINITY;
        for g in &self.entries {
            for t in g.time_scales().unwrap_or_default() {
                slow = slow.max(t);
                fast = fast.min(t);
            }
            if g.delay > 0.0 {
                slow = slow.max(g.delay);
                fast = fast.min(g.delay);
            }
        }
        if !fast.is_finite() || slow <= 0.0 {
            (1.0, 1.0)
        } else {
            (slow, fast)
        }
    }
}

impl core::fmt::Display for TransferMatrix {
    /// MATLAB's matrix syntax, `[g11, g12; g21, g22]`, every entry in the
    /// plant grammar (`0` for a channel without coupling).
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("[")?;
        for (k, g) in self.entries.iter().enumerate() {
            if k > 0 {
                f.write_str(if k % self.n == 0 { "; " } else { ", " })?;
            }
            if g.num.iter().all(|c| *c == 0.0) {
                f.write_str("0")?;
            } else {
                write!(f, "{g}")?;
            }
        }
        f.write_str("]")
    }
}
