//! The inverted decoupler of a sampled multivariable plant
//! ([`crate::mimo::InvertedDecoupler`]) and its realizability.
//!
//! Each element is the ratio of two channels' exact sampled transfer
//! functions ([`DiscretePlant::transfer`], the dead time as whole samples
//! plus its fraction), `dᵢⱼ(z) = gᵢⱼ(z)/gᵢᵢ(z)`, so that loop `i`'s process
//! is `gᵢᵢ(z)` at every sample instant (the identity of the module
//! [`crate::mimo`]). Written in `w = z⁻¹` as `Nᵢⱼ·Dᵢᵢ/(Dᵢⱼ·Nᵢᵢ)`, the
//! element is realizable when
//!
//! 1. it is causal: `gᵢⱼ`'s delay from input to first response (samples)
//!    is not shorter than `gᵢᵢ`'s (the dead-time condition: `θᵢⱼ ≥ θᵢᵢ`
//!    up to what the sampling adds), and
//! 2. it is stable: `gᵢᵢ(z)` has no zero outside the unit circle (a zero
//!    of `gᵢᵢ(s)` in the right half-plane samples to one, and so can the
//!    zero a fractional dead time adds: `b₀ + b₁z⁻¹` with `b₁ > b₀` once
//!    the fraction passes about one half), and `gᵢⱼ` itself is stable.
//!
//! Where an element fails, msp does not give up the scheme: a non-causal
//! element loses its advance (its delay is cut to zero: the coupling's
//! first samples after a move of `uⱼ` are not cancelled), and an unstable
//! one is replaced by its steady-state value `gᵢⱼ(1)/gᵢᵢ(1)` (static
//! decoupling: exact at rest, not in the transient), or left out where
//! that is not finite. Each element's [`Realization`] says which, and why.

use std::string::String;
use std::vec::Vec;

use super::super::DiscretePlant;
use crate::error::Error;
use crate::poly::{poly_roots, TransferMatrix};

/// How an element of the decoupler is realized.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(tag = "as", rename_all = "snake_case"))]
pub enum Realization {
    /// `gᵢⱼ/gᵢᵢ` exactly.
    Exact,
    /// `gᵢⱼ/gᵢᵢ` without the advance it would need (`samples` of it).
    WithoutAdvance {
        /// The advance left out (samples).
        samples: usize,
    },
    /// The steady-state ratio only.
    Static {
        /// Why the dynamic ratio cannot be used.
        reason: String,
    },
    /// Left out: no coupling to cancel, or none that can be.
    Absent {
        /// Why.
        reason: String,
    },
}

/// One element `dᵢⱼ(w) = w^delay·num(w)/den(w)` (ascending powers of
/// `w = z⁻¹`, `den(0) = 1`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ElementDesign {
    /// The output's row (0-based).
    pub row: usize,
    /// The input's column (0-based).
    pub col: usize,
    /// How it is realized.
    pub realization: Realization,
    /// Whole samples of delay.
    pub delay: usize,
    /// Numerator, ascending powers of `z⁻¹`.
    pub num: Vec<f64>,
    /// Denominator, ascending powers of `z⁻¹`.
    pub den: Vec<f64>,
}

impl ElementDesign {
    /// In words, for a report.
    pub fn describe(&self) -> String {
        let at = std::format!("d{}{}", self.row + 1, self.col + 1);
        match &self.realization {
            Realization::Exact => std::format!("{at} = g{0}{1}/g{0}{0}: exact", self.row + 1, self.col + 1),
            Realization::WithoutAdvance { samples } => std::format!(
                "{at}: g{0}{1} responds {samples} sample{s} sooner than g{0}{0} (θ{0}{1} < θ{0}{0}): the ratio would need an advance, so its delay is cut to zero and the coupling's first {samples} sample{s} after a move of u{1} are not cancelled",
                self.row + 1,
                self.col + 1,
                s = if *samples == 1 { "" } else { "s" }
            ),
            Realization::Static { reason } => {
                std::format!("{at}: static, the steady-state ratio only ({reason})")
            }
            Realization::Absent { reason } => std::format!("{at}: none ({reason})"),
        }
    }
}

/// The inverted decoupler of `m` sampled at `ts`: its off-diagonal
/// elements, row by row (see the module documentation).
pub fn design(m: &TransferMatrix, ts: f64) -> Result<Vec<ElementDesign>, Error> {
    let n = m.size();
    let mut sampled = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let g = m.get(i, j).ok_or(Error::OutOfRange("the matrix's size"))?;
            sampled.push(DiscretePlant::new(g, ts)?.transfer().polynomials());
        }
    }
    let at = |i: usize, j: usize| sampled.get(i * n + j);
    let mut out = Vec::new();
    for i in 0..n {
        let (Some((nii, dii)), Some(gii)) = (at(i, i), m.get(i, i)) else {
            return Err(Error::OutOfRange("the matrix's size"));
        };
        if nii.iter().all(|c| *c == 0.0) {
            return Err(Error::Unsupported(
                "a diagonal channel is zero: the decoupler divides by it",
            ));
        }
        for j in (0..n).filter(|j| *j != i) {
            let (Some((nij, dij)), Some(gij)) = (at(i, j), m.get(i, j)) else {
                return Err(Error::OutOfRange("the matrix's size"));
            };
            out.push(element(
                i,
                j,
                (nij, dij),
                (nii, dii),
                gij.gain() / gii.gain(),
            )?);
        }
    }
    Ok(out)
}

/// Leading zero coefficients.
fn valuation(p: &[f64]) -> usize {
    p.iter().position(|c| *c != 0.0).unwrap_or(p.len())
}

/// Roots of `p` (ascending powers of `w`) inside the closed unit disc of
/// `w`: poles of `1/p` on or outside the unit circle of `z`.
fn unstable_in_w(p: &[f64]) -> Result<bool, Error> {
    let desc: Vec<f64> = p.iter().rev().copied().collect();
    Ok(poly_roots(&desc)?
        .iter()
        .any(|(re, im)| re.hypot(*im) <= 1.0 + 1e-9))
}

fn element(
    i: usize,
    j: usize,
    (nij, dij): (&Vec<f64>, &Vec<f64>),
    (nii, dii): (&Vec<f64>, &Vec<f64>),
    static_ratio: f64,
) -> Result<ElementDesign, Error> {
    let base = ElementDesign {
        row: i,
        col: j,
        realization: Realization::Exact,
        delay: 0,
        num: std::vec![0.0],
        den: std::vec![1.0],
    };
    if nij.iter().all(|c| *c == 0.0) {
        return Ok(ElementDesign {
            realization: Realization::Absent {
                reason: String::from("no coupling"),
            },
            ..base
        });
    }
    let stat = |reason: String| {
        if static_ratio.is_finite() && static_ratio != 0.0 {
            ElementDesign {
                realization: Realization::Static { reason },
                num: std::vec![static_ratio],
                ..base.clone()
            }
        } else {
            ElementDesign {
                realization: Realization::Absent {
                    reason: std::format!("{reason}; its steady-state ratio is not finite"),
                },
                ..base.clone()
            }
        }
    };
    // w^a·N'(w)/D(w): the numerator's valuation is the delay (whole samples
    // to the first response; the denominators have D(0) = 1 up to a common
    // power, which polynomials() removed from each channel alone)
    let lead = |p: &Vec<f64>| p.get(valuation(p)..).unwrap_or(&[]).to_vec();
    let (vij, vii) = (
        valuation(nij) as i64 - valuation(dij) as i64,
        valuation(nii) as i64 - valuation(dii) as i64,
    );
    let num = crate::poly::mul(&lead(nij), &lead(dii));
    let den = crate::poly::mul(&lead(dij), &lead(nii));
    if unstable_in_w(&lead(dij))? {
        return Ok(stat(std::format!(
            "g{}{} is not stable: its ratio would not be",
            i + 1,
            j + 1
        )));
    }
    if unstable_in_w(&lead(nii))? {
        return Ok(stat(std::format!(
            "g{0}{0}(z) has a zero outside the unit circle (a right-half-plane zero, or a fractional dead time's): its inverse is unstable",
            i + 1
        )));
    }
    let d0 = den.first().copied().unwrap_or(1.0);
    let num: Vec<f64> = num.iter().map(|c| c / d0).collect();
    let den: Vec<f64> = den.iter().map(|c| c / d0).collect();
    let delay = vij - vii;
    Ok(if delay >= 0 {
        ElementDesign {
            delay: usize::try_from(delay).unwrap_or(0),
            num,
            den,
            ..base
        }
    } else {
        ElementDesign {
            realization: Realization::WithoutAdvance {
                samples: usize::try_from(-delay).unwrap_or(0),
            },
            num,
            den,
            ..base
        }
    })
}
