//! Rational transfer functions with dead time, `G(s) = b(s)/a(s)·e^{−θs}`
//! (coefficients in descending powers of `s`), as parsed from an expression and
//! used by the simulator, the registry and analysis.

use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use crate::complex::Complex;
use crate::lti::roots;
use crate::model::{Foipdt, Fopdt, Ipdt, ProcessModel, Sopdt, Ufopdt};
use crate::{error::Error, lti::Discretization, lti::Lti};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// Largest polynomial degree an expression may build, and a transfer
/// function may have however it is made ([`TransferFunction::new`]).
pub const MAX_DEGREE: u16 = 256;

/// Largest model order the registry's controllers and the simulator's
/// state-space plants hold (`msp::registry::MAX_ORDER` too).
pub const MAX_ORDER: usize = 8;

mod display;
mod matrix;
pub use matrix::{TransferMatrix, MAX_SIZE};

/// Polynomial product (descending coefficients; defined with the
/// z-domain's rational functions, below this module).
pub use crate::lti::zdomain::mul;

/// Polynomial sum (descending coefficients).
pub fn add(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = a.len().max(b.len());
    let mut out = vec![0.0; n];
    for (o, x) in out.iter_mut().rev().zip(a.iter().rev()) {
        *o += x;
    }
    for (o, x) in out.iter_mut().rev().zip(b.iter().rev()) {
        *o += x;
    }
    out
}

/// Drops leading zero coefficients (keeps at least one coefficient).
pub fn trim(p: &[f64]) -> Vec<f64> {
    let first = p
        .iter()
        .position(|v| *v != 0.0)
        .unwrap_or(p.len().saturating_sub(1));
    let mut v: Vec<f64> = p.get(first..).unwrap_or(&[]).to_vec();
    if v.is_empty() {
        v.push(0.0);
    }
    v
}

/// Polynomial division `a / b` (descending), quotient and remainder.
pub fn div(a: &[f64], b: &[f64]) -> Result<(Vec<f64>, Vec<f64>), Error> {
    if b.first().copied().unwrap_or(0.0) == 0.0 {
        return Err(Error::Numerical("division"));
    }
    if a.len() < b.len() {
        return Ok((vec![0.0], a.to_vec()));
    }
    let mut r = a.to_vec();
    let qlen = crate::lti::divide_in_place(&mut r, b);
    let rem = r.split_off(qlen);
    Ok((r, rem))
}

/// Value of a polynomial at a real point.
pub fn eval(p: &[f64], x: f64) -> f64 {
    p.iter().fold(0.0, |acc, c| acc * x + c)
}

/// Complex roots `(re, im)` of a polynomial: the eigenvalues of its companion
/// matrix (as MATLAB's `roots`), fixed-size up to degree 16, on the heap beyond.
/// Roots at exactly zero (trailing zero coefficients: an `s^m` factor, the
/// poles of integrators) are taken out first and returned as exact zeros: a
/// multiple root's eigenvalues would scatter by `ε^{1/m}` around it, some
/// into the right half plane.
pub fn poly_roots(p: &[f64]) -> Result<Vec<(f64, f64)>, Error> {
    let p = trim(p);
    let zeros = p.iter().rev().take_while(|c| **c == 0.0).count();
    if zeros > 0 && zeros < p.len() {
        let mut out = poly_roots(p.get(..p.len() - zeros).unwrap_or(&[]))?;
        out.extend(core::iter::repeat((0.0, 0.0)).take(zeros));
        return Ok(out);
    }
    let deg = p.len().saturating_sub(1);
    if deg > 16 {
        let lead = p.first().copied().unwrap_or(1.0);
        let monic: Vec<f64> = p.iter().map(|c| c / lead).collect();
        let c = nalgebra::DMatrix::<f64>::from_fn(deg, deg, |i, j| {
            crate::lti::companion_entry(monic.get(1..).unwrap_or(&[]), deg, i, j)
        });
        let schur = nalgebra::linalg::Schur::try_new(c, f64::EPSILON, 100_000)
            .ok_or(Error::Numerical("polynomial roots"))?;
        return Ok(schur
            .complex_eigenvalues()
            .iter()
            .map(|z| (z.re, z.im))
            .collect());
    }
    let mut out = vec![Complex::<f64>::default(); deg];
    roots(&p, &mut out)?;
    Ok(out.into_iter().map(|c| (c.re, c.im)).collect())
}

/// Whether the plant is stable, integrating or unstable (open loop).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum PlantKind {
    /// Every pole in the open left half plane.
    Stable,
    /// Poles at the origin, none in the right half plane.
    Integrating,
    /// A pole in the right half plane.
    Unstable,
}

impl fmt::Display for PlantKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PlantKind::Stable => "stable",
            PlantKind::Integrating => "integrating",
            PlantKind::Unstable => "unstable",
        })
    }
}

/// A continuous transfer function with dead time.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TransferFunction {
    /// Numerator coefficients, descending powers of `s`.
    pub num: Vec<f64>,
    /// Denominator coefficients, descending powers of `s`.
    pub den: Vec<f64>,
    /// Dead time `θ` (s).
    pub delay: f64,
}

const ORIGIN_TOL: f64 = 1e-9;

impl TransferFunction {
    /// A validated transfer function (proper, finite, non-negative delay).
    pub fn new(num: &[f64], den: &[f64], delay: f64) -> Result<Self, Error> {
        if num.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite("num"));
        }
        if den.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite("den"));
        }
        crate::real::non_negative(delay, "delay")?;
        let num = trim(num);
        let den = trim(den);
        if den.iter().all(|v| *v == 0.0) {
            return Err(Error::Improper("den"));
        }
        if num.len() > den.len() {
            return Err(Error::Improper("num"));
        }
        // the grammar's bound, for coefficients handed in directly (a
        // degree of thousands takes the analysis seconds per root-finding)
        if den.len() > usize::from(MAX_DEGREE) + 1 {
            return Err(Error::OutOfRange(
                "den: the degree is at most 256 (as the plant grammar allows)",
            ));
        }
        Ok(TransferFunction { num, den, delay })
    }

    /// From a low-order process model.
    pub fn from_model(m: &ProcessModel<f64>) -> Self {
        let (n, d) = m.rational();
        TransferFunction {
            num: trim(&n),
            den: trim(&d),
            delay: m.delay(),
        }
    }

    /// Order of the denominator.
    pub fn order(&self) -> usize {
        self.den.len().saturating_sub(1)
    }

    /// As many zeros as poles: a direct feedthrough `G(∞) ≠ 0`.
    pub fn is_biproper(&self) -> bool {
        let num = trim(&self.num);
        !num.is_empty() && num.len() >= trim(&self.den).len()
    }

    /// Poles `(re, im)`.
    pub fn poles(&self) -> Result<Vec<(f64, f64)>, Error> {
        poly_roots(&self.den)
    }

    /// Zeros `(re, im)`.
    pub fn zeros(&self) -> Result<Vec<(f64, f64)>, Error> {
        poly_roots(&self.num)
    }

    /// A stable first-order model with this one's dead time and the size of
    /// its gain and of its fastest unstable pole, `|K|/(T s + 1)·e^{−θs}`
    /// (`T = 1/|p|`): what a tuning rule that needs a stable model is given
    /// when every parameter it would set is set by the user anyway.
    pub fn stable_stand_in(&self) -> Result<Self, Error> {
        let fastest = self
            .poles()?
            .iter()
            .filter(|(re, _)| *re > 0.0)
            .map(|(re, im)| re.hypot(*im))
            .fold(0.0f64, f64::max);
        let tau = if fastest > 0.0 { 1.0 / fastest } else { 1.0 };
        let k = self.gain().abs();
        let k = if k.is_finite() && k > 0.0 { k } else { 1.0 };
        TransferFunction::new(&[k], &[tau, 1.0], self.delay)
    }

    /// Number of poles at the origin (exact zeros at the end of the denominator).
    pub fn integrators(&self) -> usize {
        self.den.iter().rev().take_while(|v| **v == 0.0).count()
    }

    /// Stable, integrating or unstable.
    pub fn kind(&self) -> PlantKind {
        let poles = self.poles().unwrap_or_default();
        if poles.iter().any(|(re, _)| *re > ORIGIN_TOL) {
            PlantKind::Unstable
        } else if self.integrators() > 0 || poles.iter().any(|(re, im)| re.hypot(*im) <= ORIGIN_TOL)
        {
            PlantKind::Integrating
        } else {
            PlantKind::Stable
        }
    }

    /// Static gain `b(0)/a(0)` of the plant with `m` integrators removed
    /// (the velocity gain `lim s·G(s)` of an integrating plant).
    pub fn gain(&self) -> f64 {
        let m = self.integrators();
        let den = self
            .den
            .get(..self.den.len().saturating_sub(m))
            .unwrap_or(&[]);
        eval(&self.num, 0.0) / eval(den, 0.0)
    }

    /// The equivalent low-order model if the plant is exactly one
    /// (FOPDT, SOPDT with real poles, IPDT, FOIPDT, UFOPDT), else `None`.
    pub fn exact_model(&self) -> Option<ProcessModel<f64>> {
        if self.num.len() != 1 {
            return None;
        }
        let b = *self.num.first()?;
        match self.den.as_slice() {
            [a1, a0] if *a0 == 0.0 => Ipdt::new(b / a1, self.delay).ok().map(Into::into),
            [a1, a0] if a1 / a0 > 0.0 => {
                Fopdt::new(b / a0, a1 / a0, self.delay).ok().map(Into::into)
            }
            [a1, a0] => Ufopdt::new(-b / a0, -a1 / a0, self.delay)
                .ok()
                .map(Into::into),
            [a2, a1, a0] if *a0 == 0.0 && a2 / a1 > 0.0 => Foipdt::new(b / a1, a2 / a1, self.delay)
                .ok()
                .map(Into::into),
            [a2, a1, a0] => {
                // (T1 s + 1)(T2 s + 1) = T1T2 s² + (T1+T2) s + 1
                let (p, s) = (a2 / a0, a1 / a0);
                let disc = s * s - 4.0 * p;
                if disc < 0.0 || p <= 0.0 || s <= 0.0 {
                    return None;
                }
                let t1 = 0.5 * (s + disc.sqrt());
                let t2 = 0.5 * (s - disc.sqrt());
                Sopdt::new(b / a0, t1, t2, self.delay).ok().map(Into::into)
            }
            _ => None,
        }
    }

    /// Time constants `τ = −1/p` of the real stable poles, largest first, with a
    /// complex pair counted as two time constants `1/ωn`; and the RHP-zero time
    /// constants, which Skogestad's rules add to the delay.
    fn lags(&self) -> Result<(Vec<f64>, f64), Error> {
        let mut lags: Vec<f64> = self
            .poles()?
            .iter()
            .filter(|(re, im)| re.hypot(*im) > ORIGIN_TOL && *re < 0.0)
            .map(|(re, im)| 1.0 / re.hypot(*im))
            .collect();
        lags.sort_by(|a, b| b.total_cmp(a));
        let inverse: f64 = self
            .zeros()?
            .iter()
            .filter(|(re, _)| *re > ORIGIN_TOL)
            .map(|(re, _)| 1.0 / re)
            .sum();
        Ok((lags, inverse))
    }

    /// Refuses, in words a user reads, the plants that no scheme of msp can
    /// control: a zero at the origin (no static gain: a differentiating plant
    /// such as `s/(s+1)`) and more than one integrator (`1/s^2`).
    pub fn check_controllable(&self) -> Result<(), Error> {
        let at_origin = |p: &[f64]| trim(p).iter().rev().take_while(|c| **c == 0.0).count();
        let (zeros, poles) = (at_origin(&self.num), at_origin(&self.den));
        if zeros > poles {
            return Err(Error::Unsupported(
                "plants with a zero at the origin (a differentiating plant such as s/(s+1)) have no static gain, so no controller can hold a set point on them; msp's schemes need a plant with a non-zero (or integrating) static gain",
            ));
        }
        if poles > zeros.saturating_add(1) {
            return Err(Error::Unsupported(
                "plants with more than one integrator (such as 1/s^2): msp's schemes and rules control stable plants and plants with one integrator or one unstable pole, each with a dead time; close an inner loop around one integrator first (e.g. a velocity loop) and control that loop",
            ));
        }
        let all = self.poles()?;
        let nonzero = all.iter().filter(|(re, im)| re.hypot(*im) > ORIGIN_TOL);
        if nonzero
            .clone()
            .any(|(re, im)| re.abs() <= ORIGIN_TOL * re.hypot(*im).max(1.0) && *im != 0.0)
        {
            return Err(Error::Unsupported(
                "plants with poles on the imaginary axis (an undamped oscillation such as 1/(s^2+1)): msp's schemes and rules control stable plants and plants with one integrator or one unstable pole; damp the oscillation with an inner loop first and control that loop",
            ));
        }
        if poles > zeros && nonzero.clone().any(|(re, _)| *re > ORIGIN_TOL) {
            return Err(Error::Unsupported(
                "plants with an integrator and an unstable pole (such as 1/(s(s-1))): msp's schemes and rules control one or the other; stabilise the unstable pole with an inner loop first and control that loop",
            ));
        }
        Ok(())
    }

    /// A low-order model for tuning: the exact one when the plant is one,
    /// otherwise by Skogestad's half rule (SIMC, 2003): the largest time constant
    /// is kept, half of the next is added to it and the other half to the dead
    /// time, with every smaller lag and every inverse-response (RHP) zero time
    /// constant. Integrating plants give an IPDT model (all lags into the delay),
    /// a plant with one RHP pole a UFOPDT model. `second_order` asks for SOPDT
    /// (T1 = τ1, T2 = τ2 + τ3/2) for stable plants.
    pub fn reduce(&self, second_order: bool) -> Result<ProcessModel<f64>, Error> {
        self.check_controllable()?;
        if let Some(m) = self.exact_model() {
            if !second_order || !matches!(m, ProcessModel::Fopdt(_)) {
                return Ok(m);
            }
        }
        let (lags, inverse) = self.lags()?;
        let k = self.gain();
        let delay = self.delay + inverse;
        match self.kind() {
            PlantKind::Integrating => {
                Ipdt::new(k, delay + lags.iter().sum::<f64>()).map(Into::into)
            }
            PlantKind::Unstable => {
                let poles = self.poles()?;
                let rhp: Vec<_> = poles.iter().filter(|(re, _)| *re > ORIGIN_TOL).collect();
                match rhp.as_slice() {
                    [(re, im)] if *im == 0.0 => {
                        // K/((T s − 1)·rest): static gain of the rational part is −K
                        Ufopdt::new(-k, 1.0 / re, delay + lags.iter().sum::<f64>()).map(Into::into)
                    }
                    _ => Err(Error::Unsupported(
                        "plants with more than one unstable pole (such as 1/(s-1)^2): the filtered Smith predictor (fsp) and the cascade schemes control one; stabilise the others with an inner loop first",
                    )),
                }
            }
            PlantKind::Stable => {
                let t = |i: usize| lags.get(i).copied().unwrap_or(0.0);
                let rest = |from: usize| lags.iter().skip(from).sum::<f64>();
                if second_order && lags.len() >= 2 {
                    Sopdt::new(k, t(0), t(1) + t(2) / 2.0, delay + t(2) / 2.0 + rest(3))
                        .map(Into::into)
                } else if lags.is_empty() {
                    Err(Error::Unsupported(
                        "a plant without dynamics (a static gain or a pure dead time, no pole): msp's schemes and rules tune for a lag, an integrator or an unstable pole; identify the lag the process has (msp identify) and give it in the plant",
                    ))
                } else {
                    Fopdt::new(k, t(0) + t(1) / 2.0, delay + t(1) / 2.0 + rest(2)).map(Into::into)
                }
            }
        }
    }

    /// Skogestad's half rule (SIMC, 2003) for an integrating plant, `(θ, T)` of
    /// `K·e^{−θs}/(s(Ts + 1))`: the largest lag plus half of the next is `T`,
    /// the other half, the smaller lags and the inverse-response time
    /// constants join the dead time. `None` for a plant that is not
    /// integrating with one integrator.
    pub fn integrating_half_rule(&self) -> Option<(f64, f64)> {
        if self.kind() != PlantKind::Integrating || self.integrators() != 1 {
            return None;
        }
        let (lags, inverse) = self.lags().ok()?;
        let t = |i: usize| lags.get(i).copied().unwrap_or(0.0);
        let rest = lags.iter().skip(2).sum::<f64>();
        Some((self.delay + inverse + t(1) / 2.0 + rest, t(0) + t(1) / 2.0))
    }

    /// The frequency response `G(jω)` with the exact delay, as `(re, im)`.
    pub fn freq(&self, w: f64) -> (f64, f64) {
        let ev = |p: &[f64]| {
            p.iter().fold((0.0, 0.0), |(re, im), c| {
                (re * 0.0 - im * w + c, re * w + im * 0.0)
            })
        };
        let (nr, ni) = ev(&self.num);
        let (dr, di) = ev(&self.den);
        let dd = dr * dr + di * di;
        let (gr, gi) = ((nr * dr + ni * di) / dd, (ni * dr - nr * di) / dd);
        let (c, s) = ((w * self.delay).cos(), (w * self.delay).sin());
        (gr * c + gi * s, gi * c - gr * s)
    }

    /// The continuous (unwrapped) phase of `G(jω)` in radians, from the poles,
    /// zeros and the delay.
    pub fn phase(&self, w: f64) -> Result<f64, Error> {
        let arg = |(re, im): &(f64, f64)| (w - im).atan2(-re);
        let zeros: f64 = self.zeros()?.iter().map(arg).sum();
        let poles: f64 = self.poles()?.iter().map(arg).sum();
        let sign = if self.lead_sign() < 0.0 {
            -core::f64::consts::PI
        } else {
            0.0
        };
        Ok(zeros - poles + sign - w * self.delay)
    }

    /// The sign of the leading coefficients' ratio (−1: a reverse-acting
    /// plant, whose phase [`TransferFunction::phase`] starts at −180°).
    pub fn lead_sign(&self) -> f64 {
        let lead =
            self.num.first().copied().unwrap_or(1.0) / self.den.first().copied().unwrap_or(1.0);
        if lead < 0.0 {
            -1.0
        } else {
            1.0
        }
    }

    /// The ultimate point: the first frequency `ωu` where the phase reaches
    /// −180°, and the ultimate gain `Ku = 1/|G(jωu)|`, period `Tu = 2π/ωu`.
    /// `None` when the phase never gets there (e.g. a first-order lag without delay).
    pub fn ultimate(&self) -> Option<(f64, f64)> {
        let target = -core::f64::consts::PI;
        let scales = self.time_scales().ok()?;
        let fast = scales.iter().copied().fold(f64::INFINITY, f64::min);
        let slow = scales.iter().copied().fold(0.0, f64::max);
        if !fast.is_finite() {
            return None;
        }
        let (mut lo, mut hi) = (1e-4 / slow.max(1e-12), 1e-4 / slow.max(1e-12));
        let mut found = false;
        for _ in 0..400 {
            hi *= 1.1;
            if self.phase(hi).ok()? <= target {
                found = true;
                break;
            }
            lo = hi;
            if hi > 1e4 / fast {
                break;
            }
        }
        if !found {
            return None;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.phase(mid).ok()? > target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let w = 0.5 * (lo + hi);
        let (re, im) = self.freq(w);
        Some((1.0 / re.hypot(im), core::f64::consts::TAU / w))
    }

    /// The plant with its gain, dead time and time constants scaled by
    /// `(1 + gain)`, `(1 + delay)` and `(1 + tau)` (relative perturbations, e.g.
    /// `0.1` for +10 %): `K·b(s(1+τ))/a(s(1+τ))·e^{−θ(1+δ)s}`, so every time
    /// constant and every integrator's time scale changes by `(1 + tau)`.
    pub fn perturbed(&self, gain: f64, delay: f64, tau: f64) -> Result<Self, Error> {
        // a bad perturbation is named as the user gave it, not by the
        // coefficient it would spoil
        crate::real::finite(gain, "perturbation gain")?;
        crate::real::finite(delay, "perturbation delay")?;
        crate::real::finite(tau, "perturbation tau")?;
        let scale = |p: &[f64]| -> Vec<f64> {
            let deg = p.len().saturating_sub(1);
            p.iter()
                .enumerate()
                .map(|(i, c)| {
                    c * (1.0 + tau).powi(i32::try_from(deg.saturating_sub(i)).unwrap_or(0))
                })
                .collect()
        };
        let num: Vec<f64> = scale(&self.num).iter().map(|c| c * (1.0 + gain)).collect();
        TransferFunction::new(&num, &scale(&self.den), self.delay * (1.0 + delay))
    }

    /// The series connection `self·other` (dead times added).
    pub fn series(&self, other: &Self) -> Result<Self, Error> {
        TransferFunction::new(
            &mul(&self.num, &other.num),
            &mul(&self.den, &other.den),
            self.delay + other.delay,
        )
    }

    /// The delay-free part ZOH-discretized at `ts` (order at most `N`).
    pub fn to_lti<const N: usize>(&self, ts: f64) -> Result<Lti<f64, N>, Error> {
        Lti::from_tf(&self.num, &self.den, ts, Discretization::Zoh)
    }

    /// The delay-free part as a controller's model samples it, strictly proper:
    /// the ZOH discretization, and for a biproper plant `G = D + G'` the
    /// output just before the new input acts — the simulator's convention
    /// ([`crate::sim`]) and a sensor's that is read before the actuator moves:
    /// `G'(z) + D·z^{−1}` (one order more). No model is then algebraic.
    pub fn to_model_lti<const N: usize>(&self, ts: f64) -> Result<Lti<f64, N>, Error> {
        let (num, den) = (trim(&self.num), trim(&self.den));
        let lead = den.first().copied().unwrap_or(1.0);
        if num.len() < den.len() || num.iter().all(|v| *v == 0.0) {
            return self.to_lti(ts);
        }
        let d = num.first().copied().unwrap_or(0.0) / lead;
        let rest: Vec<f64> = num.iter().zip(&den).map(|(n, a)| n - d * a).collect();
        let (nz, dz) = if den.len() > 1 {
            let sp: Lti<f64, N> = Lti::from_tf(&rest, &den, ts, Discretization::Zoh)?;
            let (n, d) = crate::lti::small::model_tf(&sp);
            (n.as_slice().to_vec(), d.as_slice().to_vec())
        } else {
            (vec![0.0], vec![1.0])
        };
        // (z·N'(z) + D·Den(z)) / (z·Den(z))
        let num2 = add(
            &mul(&nz, &[1.0, 0.0]),
            &dz.iter().map(|a| d * a).collect::<Vec<f64>>(),
        );
        let den2 = mul(&dz, &[1.0, 0.0]);
        Lti::from_discrete_tf(&num2, &den2)
    }

    /// The order of [`TransferFunction::to_model_lti`]: one more for a biproper plant.
    pub fn model_order(&self) -> usize {
        let biproper =
            trim(&self.num).len() >= trim(&self.den).len() && self.num.iter().any(|v| *v != 0.0);
        self.order().saturating_add(usize::from(biproper))
    }

    /// The dead time in samples of period `ts`.
    pub fn delay_samples(&self, ts: f64) -> Result<f64, Error> {
        crate::delay::samples(self.delay, ts)
    }

    /// Time constants `1/|p|` of all non-zero poles and zeros, and the delay:
    /// the plant's characteristic times (for choosing a sample period).
    pub fn time_scales(&self) -> Result<Vec<f64>, Error> {
        let mut out: Vec<f64> = self
            .poles()?
            .into_iter()
            .chain(self.zeros()?)
            .map(|(re, im)| re.hypot(im))
            .filter(|m| *m > ORIGIN_TOL)
            .map(|m| 1.0 / m)
            .collect();
        if self.delay > 0.0 {
            out.push(self.delay);
        }
        Ok(out)
    }
}

/// `x` rounded to `digits` significant digits (at least one); non-finite
/// values and zero are returned as they are.
pub fn round_sig(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let decimals = digits.max(1) - 1;
    alloc::format!("{x:.decimals$e}").parse().unwrap_or(x)
}

/// Formats a number compactly: integers without a fraction, otherwise the
/// shortest representation that round-trips at 12 significant digits.
/// Magnitudes below `1e-4` or from `1e15` on are written with an exponent
/// (`6.5691e-22`), as a plain decimal would bury the digits in zeros.
pub fn fmt_num(x: f64) -> String {
    if x == x.trunc() && x.abs() < 1e15 {
        return alloc::format!("{x:.0}");
    }
    let v = round_sig(x, 12);
    if v != 0.0 && (v.abs() < 1e-4 || v.abs() >= 1e15) {
        return alloc::format!("{v:e}");
    }
    alloc::format!("{}", v)
}
