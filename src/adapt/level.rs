//! The load responses' gain test of an [`Estimator`]: after each load's
//! onset, over a response, the model in use's error summed back from the
//! differences the estimator sees to levels, regressed on the model in
//! use's own response to the controller's moves since, beside the load's
//! own shapes.
//!
//! In differences a response's low frequencies are lost: a gain error
//! shows in them as a slow decay of a few hundredths of the load per
//! sample, below 2 % noise in every one (measured: Page's sum over a
//! load's response of a halved gain's evidence about 1 at ten samples of
//! dead time, against the 20 a proposal needs). Summed back, the same
//! error is a level held for the response's time. With the model in use
//! `G`, the process `(1 + δ)·G` and the controller's input `u`, the level
//! error since the onset is `E = δ·Z + L + n`, `Z` the model's response to
//! the inputs since the onset and `L` the load's own: a step at the output
//! (a level), a step at the input (a level and the process's free response
//! `a^j` from the onset), a ramp (a line); `n` the noise. The least-squares
//! fit of `E` on `[Z, 1, j, a^j]` (an integrating process: `[Z, 1, j]`,
//! summed once from its second differences) separates the gain's error
//! from the load — a disturbance model in the regression (Ljung (1999)
//! Sec. 14.1: the disturbance's known shapes as extra regressors;
//! Åström & Wittenmark (1995) Sec. 11.2) — and its part of `δ` is
//! `r/I`, `I = Z⊥ᵀZ⊥` and `r = Z⊥ᵀE`, `Z⊥` the part of `Z` the load's
//! shapes do not explain (the Schur complement of their normal equations).
//! The responses' sums add (each with its own load), the older discounted by
//! [`LEVEL_MEMORY`]; `δ̂ = Σr/ΣI` with the evidence
//! `δ̂²·ΣI/σ̂² = (Σr)²/(ΣI·σ̂²)` (twice the log-likelihood ratio of `δ̂`
//! against `δ = 0`, for Gaussian noise), `σ̂²` the fits' own residual
//! variance (what no shape explains counts as noise: a response the
//! shapes do not fit weighs less).

use super::*;

/// The discount of an older load response's sums in the gain test (about
/// the last three responses count).
pub const LEVEL_MEMORY: f64 = 0.7;

/// The most a load response's fit may leave unexplained, per degree of
/// freedom, in units of the measured noise's variance.
pub const LEVEL_FIT: f64 = 4.0;

/// The gain test's state: the response under way, and the sums of those
/// before.
#[derive(Debug, Clone, Copy)]
pub(super) struct Level<T> {
    /// Samples since the response's start (`None`: no response under way).
    j: Option<usize>,
    /// The model in use's input-driven difference, and the level sums `Z`
    /// and `E` since the start, and `a^j`.
    x: T,
    z: T,
    e: T,
    pj: T,
    /// The model in use with its lag doubled (the last of [`LAGS`]): its
    /// input-driven difference, and the level sum of its difference from
    /// the model in use's (a lag's error, which the gain's is told from).
    lag: [T; 3],
    xl: T,
    zl: T,
    /// The normal equations of `[Z, 1, j/W, a^j, Zl]` and of `E`: `ΦᵀΦ`,
    /// `ΦᵀE`, `EᵀE`.
    gram: [[T; 5]; 5],
    cross: [T; 5],
    ee: T,
    /// Over the responses so far: `Σr`, `ΣI`, the residuals' sum of
    /// squares and their degrees of freedom, the responses.
    r: T,
    info: T,
    resid: T,
    dof: T,
    responses: u32,
}

impl<T: Real> Level<T> {
    /// No response fitted yet, for a model in use whose lag doubled has
    /// the coefficients `lag` (an integrating model: none).
    pub(super) fn new(lag: [T; 3]) -> Self {
        Level {
            lag,
            j: None,
            x: T::zero(),
            z: T::zero(),
            e: T::zero(),
            pj: T::one(),
            xl: T::zero(),
            zl: T::zero(),
            gram: [[T::zero(); 5]; 5],
            cross: [T::zero(); 5],
            ee: T::zero(),
            r: T::zero(),
            info: T::zero(),
            resid: T::zero(),
            dof: T::zero(),
            responses: 0,
        }
    }

    /// The gain's relative error `δ̂` and its evidence, once two responses
    /// were fitted.
    pub(super) fn estimate(&self) -> Option<(T, T)> {
        if self.responses < 2 || !(self.info > T::zero()) || !(self.dof > T::zero()) {
            return None;
        }
        let delta = self.r / self.info;
        let var = self.resid / self.dof;
        let evidence = if var > T::zero() {
            self.r * self.r / (self.info * var)
        } else {
            T::infinity()
        };
        Some((delta, evidence))
    }

    /// A response starts (a load's onset anchored).
    pub(super) fn start(&mut self, integrating: bool, noise: T) {
        self.close(integrating, noise);
        *self = Level {
            j: Some(0),
            r: self.r,
            info: self.info,
            resid: self.resid,
            dof: self.dof,
            responses: self.responses,
            ..Level::new(self.lag)
        };
    }

    /// One sample of the response under way: `target` the estimator's
    /// target, `(u0, u1)` the model in use's inputs, `coef` its
    /// coefficients; the response closes after `window` samples.
    pub(super) fn step(
        &mut self,
        target: T,
        (u0, u1): (T, T),
        coef: [T; 3],
        integrating: bool,
        window: usize,
        noise: T,
    ) {
        let Some(j) = self.j else {
            return;
        };
        let [a, b0, b1] = coef;
        let a = if integrating { T::zero() } else { a };
        self.x = a * self.x + b0 * u0 + b1 * u1;
        self.z = self.z + self.x;
        self.e = self.e + target - self.x;
        let [al, bl0, bl1] = self.lag;
        self.xl = al * self.xl + bl0 * u0 + bl1 * u1;
        self.zl = self.zl + self.xl - self.x;
        let w = T::of(window.max(1) as f64);
        let phi = if integrating {
            [self.z, T::one(), T::of(j as f64) / w, T::zero(), T::zero()]
        } else {
            [self.z, T::one(), T::of(j as f64) / w, self.pj, self.zl]
        };
        for (row, p) in self.gram.iter_mut().zip(phi) {
            for (g, q) in row.iter_mut().zip(phi) {
                *g = *g + p * q;
            }
        }
        for (c, p) in self.cross.iter_mut().zip(phi) {
            *c = *c + p * self.e;
        }
        self.ee = self.ee + self.e * self.e;
        self.pj = crate::real::normal(self.pj * coef[0]);
        self.j = Some(j + 1);
        if j + 1 >= window {
            self.close(integrating, noise);
        }
    }

    /// The response under way ends: its fit joins the sums when the
    /// load's shapes and the model's responses leave no more than
    /// [`LEVEL_FIT`] times the noise's variance `noise²` per degree of
    /// freedom (a response they do not fit, such as a ramp's bend, tells
    /// nothing of the gain).
    pub(super) fn close(&mut self, integrating: bool, noise: T) {
        let Some(n) = self.j.take() else {
            return;
        };
        let shapes = if integrating { 2 } else { 4 };
        let Some((info, r, rest)) = schur(&self.gram, &self.cross, self.ee, shapes) else {
            return;
        };
        let dof = T::of(n as f64) - T::of((shapes + 1) as f64);
        if !(info > T::zero()) || !(dof > T::zero()) {
            return;
        }
        let resid = at_least(rest - r * r / info, T::zero());
        #[cfg(feature = "std")]
        if std::env::var("DBG6").is_ok() {
            let f = |x: T| x.to_f64().unwrap_or(0.0);
            std::eprintln!("segment n {} delta {:.3} sd {:.3} resid/dof {:.2e} noise2 {:.2e} total delta {:.3} resp {}", n, f(r / info), f((resid / dof / info).sqrt()), f(resid / dof), f(noise * noise), f((m_r(self) + r) / (m_i(self) + info)), self.responses);
        }
        if resid > T::of(LEVEL_FIT) * noise * noise * dof {
            return;
        }
        let m = T::of(LEVEL_MEMORY);
        self.r = m * self.r + r;
        self.info = m * self.info + info;
        self.resid = m * self.resid + resid;
        self.dof = m * self.dof + dof;
        self.responses = self.responses.saturating_add(1);
        #[cfg(feature = "std")]
        if std::env::var("DBG6").is_ok() {
            std::eprintln!("  estimate {:?}", self.estimate().map(|(a, b)| (a.to_f64(), b.to_f64())));
        }
    }
}

/// The part of regressor 0 (and of the target) that regressors
/// `1..=shapes` do not explain, from the normal equations `gram`, `cross`
/// and `ee`: `(Z⊥ᵀZ⊥, Z⊥ᵀE, E⊥ᵀE⊥)`, by Cholesky's factor of the shapes'
/// block (`None`: not positive definite).
fn schur<T: Real>(gram: &[[T; 5]; 5], cross: &[T; 5], ee: T, shapes: usize) -> Option<(T, T, T)> {
    // the shapes' block N = L·Lᵀ, and L⁻¹ applied to N's column of Z and to
    // the shapes' products with E: then Z⊥ᵀZ⊥ = ZᵀZ − |L⁻¹n_Z|², etc.
    let mut l = [[T::zero(); 4]; 4];
    let at = |i: usize, k: usize| gram.get(i + 1).and_then(|r| r.get(k + 1)).copied();
    for i in 0..shapes {
        for k in 0..=i {
            let mut s = at(i, k)?;
            for m in 0..k {
                s = s - *l.get(i)?.get(m)? * *l.get(k)?.get(m)?;
            }
            let v = if i == k {
                if !(s > T::zero()) {
                    return None;
                }
                s.sqrt()
            } else {
                s / *l.get(k)?.get(k)?
            };
            *l.get_mut(i)?.get_mut(k)? = v;
        }
    }
    let solve = |b: [T; 4]| -> Option<[T; 4]> {
        let mut y = [T::zero(); 4];
        for i in 0..shapes {
            let mut s = *b.get(i)?;
            for m in 0..i {
                s = s - *l.get(i)?.get(m)? * *y.get(m)?;
            }
            *y.get_mut(i)? = s / *l.get(i)?.get(i)?;
        }
        Some(y)
    };
    let col = |i: usize| gram.get(i + 1).and_then(|r| r.first()).copied().unwrap_or(T::zero());
    let cr = |i: usize| cross.get(i + 1).copied().unwrap_or(T::zero());
    let nz = solve([col(0), col(1), col(2), col(3)])?;
    let ne = solve([cr(0), cr(1), cr(2), cr(3)])?;
    let dot = |a: &[T; 4], b: &[T; 4]| {
        a.iter()
            .zip(b)
            .take(shapes)
            .fold(T::zero(), |s, (x, y)| s + *x * *y)
    };
    let zz = gram.first()?.first().copied()?;
    let ze = cross.first().copied()?;
    Some((zz - dot(&nz, &nz), ze - dot(&nz, &ne), ee - dot(&ne, &ne)))
}

#[cfg(feature = "std")]
fn m_r<T: Real>(l: &Level<T>) -> T { T::of(LEVEL_MEMORY) * l.r }
#[cfg(feature = "std")]
fn m_i<T: Real>(l: &Level<T>) -> T { T::of(LEVEL_MEMORY) * l.info }
