//! Multivariable plants: an `n×n` transfer matrix with its own dead time in
//! every channel, the interaction measures of its pairing and the
//! decentralized PI tuning of Luyben's biggest-log-modulus method, all on
//! the exact frequency response (the delays as `e^{−jωθ}`, never Padé).
//!
//! - The relative gain array `Λ = G ∘ (G⁻¹)ᵀ` (Bristol (1966)), at steady
//!   state or at a frequency; a pairing on positive relative gains nearest 1.
//! - The Niederlinski index `NI = det G(0)/Π gᵢᵢ(0)` (Niederlinski (1971)):
//!   negative, the paired loops with integral action are unstable whatever
//!   their tuning.
//! - The biggest log modulus `Lcm = max_ω 20·log10|W/(1 + W)|`,
//!   `W = −1 + det(I + G·C)` of decentralized controllers `C = diag(cᵢ)`,
//!   and the BLT tuning: each loop's Ziegler–Nichols PI (`Kc = Ku/2.2`,
//!   `τI = Pu/1.2`) detuned by one factor `F` (`Kc/F`, `τI·F`) raised until
//!   `Lcm = 2n` dB (Luyben (1986), *Ind. Eng. Chem. Process Des. Dev.* 25,
//!   654–660: the Wood–Berry column gives `F = 2.55`, `Kc = 0.375, −0.075`,
//!   `τI = 8.29, 23.6` min).

use std::vec::Vec;

use crate::complex::Complex;
use crate::error::Error;

mod decouple;
mod sampled;

pub use decouple::{design as decoupler_design, ElementDesign, Realization};
pub use sampled::{decoupler_verdict, Decoupling, SampledLoop};

pub use crate::poly::{TransferMatrix, MAX_SIZE};

pub(crate) type C64 = Complex<f64>;

/// The determinant of the `n×n` complex matrix `a` (row-major), by
/// Gaussian elimination with partial pivoting.
pub fn det(a: &[C64], n: usize) -> C64 {
    let mut m = a.to_vec();
    let mut d = Complex::real(1.0);
    for col in 0..n {
        let pivot = pivot(&m, n, col);
        let p = at(&m, n, pivot, col);
        if p.abs() == 0.0 {
            return Complex::real(0.0);
        }
        if pivot != col {
            for k in 0..n {
                m.swap(pivot * n + k, col * n + k);
            }
            d = d.scale(-1.0);
        }
        d = d * p;
        for r in col + 1..n {
            let f = at(&m, n, r, col) / p;
            for k in col..n {
                let v = at(&m, n, r, k) - f * at(&m, n, col, k);
                if let Some(x) = m.get_mut(r * n + k) {
                    *x = v;
                }
            }
        }
    }
    d
}

/// The row from `col` down with the largest entry in column `col`.
fn pivot(m: &[C64], n: usize, col: usize) -> usize {
    (col..n).fold(col, |best, r| {
        if at(m, n, r, col).abs() > at(m, n, best, col).abs() {
            r
        } else {
            best
        }
    })
}

fn at(m: &[C64], n: usize, i: usize, j: usize) -> C64 {
    m.get(i * n + j).copied().unwrap_or(Complex::real(0.0))
}

/// The inverse of the `n×n` complex matrix `a` (row-major), by
/// Gauss–Jordan elimination with partial pivoting; `None` when singular.
pub fn inverse(a: &[C64], n: usize) -> Option<Vec<C64>> {
    let mut m = a.to_vec();
    let mut inv: Vec<C64> = (0..n * n)
        .map(|k| Complex::real(if k / n == k % n { 1.0 } else { 0.0 }))
        .collect();
    let scale = a.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    for col in 0..n {
        let pivot = pivot(&m, n, col);
        let p = at(&m, n, pivot, col);
        if !(p.abs() > 1e-13 * scale) {
            return None;
        }
        for k in 0..n {
            m.swap(pivot * n + k, col * n + k);
            inv.swap(pivot * n + k, col * n + k);
        }
        for k in 0..n {
            let (x, y) = (at(&m, n, col, k) / p, at(&inv, n, col, k) / p);
            if let Some(v) = m.get_mut(col * n + k) {
                *v = x;
            }
            if let Some(v) = inv.get_mut(col * n + k) {
                *v = y;
            }
        }
        for r in (0..n).filter(|r| *r != col) {
            let f = at(&m, n, r, col);
            for k in 0..n {
                let (x, y) = (
                    at(&m, n, r, k) - f * at(&m, n, col, k),
                    at(&inv, n, r, k) - f * at(&inv, n, col, k),
                );
                if let Some(v) = m.get_mut(r * n + k) {
                    *v = x;
                }
                if let Some(v) = inv.get_mut(r * n + k) {
                    *v = y;
                }
            }
        }
    }
    Some(inv)
}

/// The relative gain array `Λ = G ∘ (G⁻¹)ᵀ` of the complex matrix `g`
/// (row-major, `n×n`): `λᵢⱼ = gᵢⱼ·(G⁻¹)ⱼᵢ` (Bristol (1966)). Every row and
/// column sums to 1.
pub fn rga_of(g: &[C64], n: usize) -> Result<Vec<C64>, Error> {
    let inv = inverse(g, n).ok_or(Error::Numerical("the gain matrix is singular: no RGA"))?;
    Ok((0..n * n)
        .map(|k| at(g, n, k / n, k % n) * at(&inv, n, k % n, k / n))
        .collect())
}

/// The steady-state relative gain array of `m` (row-major).
pub fn rga(m: &TransferMatrix) -> Result<Vec<f64>, Error> {
    let g: Vec<C64> = m.steady_state()?.into_iter().map(Complex::real).collect();
    Ok(rga_of(&g, m.size())?.into_iter().map(|l| l.re).collect())
}

/// The RGA at `ω` (rad/s), row-major.
pub fn rga_at(m: &TransferMatrix, w: f64) -> Result<Vec<C64>, Error> {
    rga_of(&m.response(w), m.size())
}

/// The RGA at one frequency: `|λᵢⱼ(jω)|` by rows.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RgaPoint {
    /// The frequency (rad/s).
    pub w: f64,
    /// `|λᵢⱼ(jω)|`, by rows.
    pub magnitude: Vec<Vec<f64>>,
}

/// The frequency-dependent RGA of `m` (Bristol (1966) at `jω`; how the
/// interaction moves from steady state toward the loops' bandwidth): its
/// magnitudes at `points` frequencies, logarithmically from a tenth of the
/// slowest time scale's frequency to the fastest's.
pub fn rga_over(m: &TransferMatrix, points: usize) -> Result<Vec<RgaPoint>, Error> {
    let n = m.size();
    let (slow, fast) = m.scales();
    let (lo, hi) = ((0.1 / slow).ln(), (1.0 / fast).ln().max((0.1 / slow).ln()));
    let points = points.max(2);
    (0..points)
        .map(|k| {
            #[allow(clippy::cast_precision_loss)]
            let w = (lo + (hi - lo) * k as f64 / (points - 1) as f64).exp();
            let l = rga_at(m, w)?;
            Ok(RgaPoint {
                w,
                magnitude: l
                    .chunks(n)
                    .map(|r| r.iter().map(|c| c.abs()).collect())
                    .collect(),
            })
        })
        .collect()
}

/// The pairing the steady-state RGA `lambda` (row-major, `n×n`) suggests:
/// `pairing[i]` is the input of output `i`, the permutation whose relative
/// gains are all positive with the least `Σ|λ − 1|` (Bristol's rule: pair
/// on relative gains near 1, never on negative ones); `None` when every
/// permutation has a non-positive one.
pub fn pairing(lambda: &[f64], n: usize) -> Option<Vec<usize>> {
    let mut best: Option<(f64, Vec<usize>)> = None;
    let mut perm: Vec<usize> = (0..n).collect();
    permutations(&mut perm, 0, &mut |p| {
        let ls: Vec<f64> = p
            .iter()
            .enumerate()
            .map(|(i, &j)| lambda.get(i * n + j).copied().unwrap_or(0.0))
            .collect();
        if ls.iter().all(|l| *l > 0.0) {
            let cost: f64 = ls.iter().map(|l| (l - 1.0).abs()).sum();
            if best.as_ref().map_or(true, |(c, _)| cost < *c) {
                best = Some((cost, p.to_vec()));
            }
        }
    });
    best.map(|(_, p)| p)
}

fn permutations(p: &mut [usize], k: usize, f: &mut impl FnMut(&[usize])) {
    if k + 1 >= p.len() {
        f(p);
        return;
    }
    for i in k..p.len() {
        p.swap(k, i);
        permutations(p, k + 1, f);
        p.swap(k, i);
    }
}

/// The Niederlinski index `det G(0)/Π gᵢᵢ(0)` of the diagonal pairing:
/// negative, integral control of these loops is unstable for every tuning
/// (Niederlinski (1971); sufficient for `n = 2`, where it is `1/λ11`).
pub fn niederlinski(m: &TransferMatrix) -> Result<f64, Error> {
    let g = m.steady_state()?;
    let n = m.size();
    let c: Vec<C64> = g.iter().map(|x| Complex::real(*x)).collect();
    let diag: f64 = (0..n)
        .map(|i| g.get(i * n + i).copied().unwrap_or(0.0))
        .product();
    if diag == 0.0 {
        return Err(Error::Numerical(
            "a diagonal gain is zero: no Niederlinski index",
        ));
    }
    Ok(det(&c, n).re / diag)
}

/// A decentralized PI loop `Kc(1 + 1/(τI s))` on the diagonal.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PiLoop {
    /// The gain `Kc`.
    pub kp: f64,
    /// The integral time `τI` (s).
    pub ti: f64,
}

/// The biggest log modulus of decentralized PI loops `loops` on the
/// diagonal of `m` (dB): `max_ω 20·log10|W/(1 + W)|`, `W = −1 + det(I +
/// G(jω)·C(jω))` (Luyben (1986)), over a logarithmic grid of 400 points a
/// decade from a hundredth of the slowest time scale's frequency to ten
/// times the fastest's, the peak refined by golden-section search.
pub fn biggest_log_modulus(m: &TransferMatrix, loops: &[PiLoop]) -> f64 {
    let n = m.size();
    let lc = |w: f64| {
        let g = m.response(w);
        let mut a = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                let c = loops.get(j).map_or(Complex::real(0.0), |l| {
                    Complex::new(l.kp, -l.kp / (l.ti * w))
                });
                let one = if i == j { 1.0 } else { 0.0 };
                a.push(Complex::real(one) + at(&g, n, i, j) * c);
            }
        }
        let w_ = det(&a, n) - Complex::real(1.0);
        20.0 * (w_ / (w_ + Complex::real(1.0))).abs().log10()
    };
    let (slow, fast) = m.scales();
    peak(&lc, (0.01 / slow).ln(), (10.0 / fast).ln())
}

/// The largest value of `f` over `ln x ∈ [lo, hi]`: a logarithmic grid of
/// 400 points a decade (at most 40 decades), the grid's peak refined by
/// golden-section search on `ln x`.
pub(super) fn peak(f: &dyn Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let lc = f;
    // (a grid of at most 400 points a decade over 40 decades)
    let decades = ((hi - lo) / core::f64::consts::LN_10).clamp(1.0, 40.0);
    let points = num_traits::ToPrimitive::to_usize(&(decades * 400.0).ceil()).unwrap_or(400);
    let step = (hi - lo) / points as f64;
    let (mut best, mut at_k) = (f64::NEG_INFINITY, 0);
    for k in 0..=points {
        let v = lc((lo + step * k as f64).exp());
        if v > best {
            (best, at_k) = (v, k);
        }
    }
    // golden section on ln x around the grid's peak
    let (mut a, mut b) = (
        lo + step * (at_k as f64 - 1.0),
        lo + step * (at_k as f64 + 1.0),
    );
    let r = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..60 {
        let (c, d) = (b - r * (b - a), a + r * (b - a));
        if lc(c.exp()) > lc(d.exp()) {
            b = d;
        } else {
            a = c;
        }
    }
    best.max(lc(((a + b) / 2.0).exp()))
}

/// The BLT tuning of decentralized PI loops (Luyben (1986)).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Blt {
    /// The detuning factor `F`.
    pub f: f64,
    /// The loops, in diagonal order.
    pub loops: Vec<PiLoop>,
    /// Each loop's PI alone, before detuning (BLT's: Ziegler–Nichols).
    pub alone: Vec<PiLoop>,
    /// The biggest log modulus reached (dB), `2n`.
    pub lcm: f64,
}

/// How each diagonal loop's PI is set alone, before the common detuning
/// (serialized by its name, `zn` or `simc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum LoopRule {
    /// Ziegler–Nichols from the loop's ultimate point: `Kc = Ku/2.2`,
    /// `τI = Pu/1.2` (BLT, Luyben (1986)).
    #[cfg_attr(feature = "serde", serde(rename = "zn"))]
    ZieglerNichols,
    /// Skogestad's SIMC on the loop's first-order (or integrating) model
    /// with `τc = θ`: `Kc = T/(K(τc + θ))`, `τI = min(T, 4(τc + θ))`
    /// ([`crate::tuning::simc`]).
    #[cfg_attr(feature = "serde", serde(rename = "simc"))]
    Simc,
}

impl LoopRule {
    /// By name: `zn` (BLT's, the default) or `simc`.
    pub fn from_name(name: &str) -> Result<Self, Error> {
        match name {
            "zn" | "blt" => Ok(LoopRule::ZieglerNichols),
            "simc" => Ok(LoopRule::Simc),
            _ => Err(Error::Unsupported(
                "a matrix plant's PI loops are set by rule zn (BLT) or simc, then detuned together",
            )),
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            LoopRule::ZieglerNichols => "zn",
            LoopRule::Simc => "simc",
        }
    }
}

/// Each diagonal loop's PI alone by `rule` (a reverse-acting entry: a
/// negative gain).
pub fn loops_alone(m: &TransferMatrix, rule: LoopRule) -> Result<Vec<PiLoop>, Error> {
    let n = m.size();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let g = m.get(i, i).ok_or(Error::OutOfRange("the matrix's size"))?;
        out.push(match rule {
            LoopRule::ZieglerNichols => {
                let sign = g.lead_sign();
                // (−G: the gain scaled by 1 − 2)
                let positive = if sign < 0.0 {
                    g.perturbed(-2.0, 0.0, 0.0)?
                } else {
                    g.clone()
                };
                let (ku, pu) = positive.ultimate().ok_or(Error::Unsupported(
                    "a diagonal entry has no ultimate point (its phase never reaches -180°): BLT needs one per loop",
                ))?;
                PiLoop {
                    kp: sign * ku / 2.2,
                    ti: pu / 1.2,
                }
            }
            LoopRule::Simc => {
                let model = g.reduce(false)?;
                let theta = model.delay();
                if !(theta > 0.0) {
                    return Err(Error::Unsupported(
                        "SIMC's τc = θ needs a dead time in every diagonal channel",
                    ));
                }
                let p = crate::tuning::simc(&model, theta)?;
                PiLoop { kp: p.kp, ti: p.ti }
            }
        });
    }
    Ok(out)
}

/// The BLT tuning of `m`'s diagonal loops (Luyben (1986)): each loop's
/// Ziegler–Nichols PI alone ([`loops_alone`]) detuned together
/// ([`detune`]) to `lcm_db` (Luyben's `2n` dB: `None`).
pub fn blt(m: &TransferMatrix, lcm_db: Option<f64>) -> Result<Blt, Error> {
    detune(m, loops_alone(m, LoopRule::ZieglerNichols)?, lcm_db)
}

/// Loops `alone` detuned by the factor `F ≥ 1` (`Kc/F`, `τI·F`) that brings
/// the biggest log modulus to `lcm_db` (`2n` dB: `None`), by bisection on
/// `ln F` (Luyben (1986)'s procedure, from any starting loops).
pub fn detune(m: &TransferMatrix, alone: Vec<PiLoop>, lcm_db: Option<f64>) -> Result<Blt, Error> {
    let n = m.size();
    #[allow(clippy::cast_precision_loss)]
    let target = lcm_db.unwrap_or(2.0 * n as f64);
    let zn = alone;
    let detuned = |f: f64| -> Vec<PiLoop> {
        zn.iter()
            .map(|l| PiLoop {
                kp: l.kp / f,
                ti: l.ti * f,
            })
            .collect()
    };
    let lcm_of = |f: f64| biggest_log_modulus(m, &detuned(f));
    if lcm_of(1.0) <= target {
        return Ok(Blt {
            f: 1.0,
            loops: detuned(1.0),
            lcm: lcm_of(1.0),
            alone: zn,
        });
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    while lcm_of(hi.exp()) > target {
        lo = hi;
        hi += 1.0;
        if hi > 10.0 {
            return Err(Error::Numerical(
                "no detuning factor up to e^10 brings the biggest log modulus down to its target",
            ));
        }
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if lcm_of(mid.exp()) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let f = (0.5 * (lo + hi)).exp();
    Ok(Blt {
        f,
        loops: detuned(f),
        lcm: lcm_of(f),
        alone: zn,
    })
}
