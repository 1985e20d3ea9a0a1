//! The filtered Smith predictor for unstable and integrating plants: the
//! robustness filter `Fr(z)` that makes the predictor stable
//! (García et al. (2010) Sec. 3.3, Eq. 10).
//!
//! The predictor `S(z) = Gm(z)(1 − z^{−h}Fr(z))` contains the poles of the model;
//! with `Gm = Nm/(Dm⁺Dm⁻)` (`Dm⁺` the roots with `|z| ≥ 1`) and `Fr = Nr/Dr`,
//! `S` is stable when `z^h Dr(z) − Nr(z)` is divisible by `Dm⁺(z)(z − 1)`:
//! Eq. 10, `z^h Dr − Nr = Dm⁺ (z − 1) p(z)` — an exact solution exists for
//! any dead time `h` (samples) and any model order. Here `Dr` is chosen and
//! `Nr = Q(z)·c(z)` has a chosen factor `Q` (the filter's fixed zeros) and a
//! free polynomial `c` with as many coefficients as conditions: at each root
//! `x` of `Dm⁺(z)(z − 1)` of multiplicity `μ`, the derivatives `0 … μ − 1` of
//! `z^h Dr(z) − Nr(z)` vanish (repeated roots, such as the integrator's `z = 1`
//! counted twice, through derivatives). The conditions form a small linear system.

#[cfg(doc)]
use crate::delay::DelayStorage;
use crate::{error::Error, real::Real};

/// Largest number of conditions (roots with multiplicity) the solver takes.
pub const MAX_CONDITIONS: usize = 6;

/// `d^j/dz^j p(z)` at `x` for `p` in descending coefficients.
fn poly_derivative<T: Real>(p: &[T], j: usize, x: T) -> T {
    let n = p.len();
    let mut acc = T::zero();
    for (i, c) in p.iter().enumerate() {
        let power = n.saturating_sub(1).saturating_sub(i);
        if power < j {
            continue;
        }
        // power!/(power − j)! · x^(power − j)
        let mut f = T::one();
        for k in 0..j {
            f = f * T::from(power.saturating_sub(k)).unwrap_or(T::zero());
        }
        acc = acc + *c * f * x.powi(i32::try_from(power.saturating_sub(j)).unwrap_or(i32::MAX));
    }
    acc
}

/// `d^j/dz^j [z^m · p(z)]` at `x` by the product rule.
fn shifted_derivative<T: Real>(m: usize, p: &[T], j: usize, x: T) -> T {
    let mut acc = T::zero();
    let mut binom = T::one();
    for k in 0..=j {
        // (z^m)^(k) = m!/(m − k)! z^(m − k)
        let zm = if k > m {
            T::zero()
        } else {
            let mut f = T::one();
            for q in 0..k {
                f = f * T::from(m.saturating_sub(q)).unwrap_or(T::zero());
            }
            f * x.powi(i32::try_from(m.saturating_sub(k)).unwrap_or(i32::MAX))
        };
        acc = acc + binom * zm * poly_derivative(p, j.saturating_sub(k), x);
        // C(j, k + 1) = C(j, k)·(j − k)/(k + 1)
        binom = binom * T::from(j.saturating_sub(k)).unwrap_or(T::zero())
            / T::from(k.saturating_add(1)).unwrap_or(T::one());
    }
    acc
}

/// Solves Eq. 10 for the free coefficients `c` (descending) of `Nr = Q·c`.
///
/// `h`: the dead time in samples; `dr`: the chosen denominator; `q`: the
/// chosen factor of the numerator; `roots`: the real roots of `Dm⁺(z)(z − 1)`
/// with their multiplicities. Returns `c` (its length is the number of conditions).
pub fn solve<T: Real>(
    h: usize,
    dr: &[T],
    q: &[T],
    roots: &[(T, usize)],
) -> Result<([T; MAX_CONDITIONS], usize), Error> {
    let m: usize = roots.iter().map(|(_, mu)| *mu).sum();
    if m == 0 || m > MAX_CONDITIONS {
        return Err(Error::OutOfRange("roots"));
    }
    let mut a = crate::lti::matrix::Mat::<MAX_CONDITIONS>::zeros();
    let mut b = crate::lti::matrix::Vector::<MAX_CONDITIONS>::zeros();
    let mut row = 0usize;
    for (x, mu) in roots {
        for j in 0..*mu {
            // Σ_i c_i · d^j[z^(m−1−i) Q(z)](x) = d^j[z^h Dr(z)](x)
            for i in 0..m {
                let v = shifted_derivative(m.saturating_sub(1).saturating_sub(i), q, j, *x);
                if let Some(e) = a.get_mut((row, i)) {
                    *e = v.f64();
                }
            }
            if let Some(e) = b.get_mut(row) {
                *e = shifted_derivative(h, dr, j, *x).f64();
            }
            row = row.saturating_add(1);
        }
    }
    let x = crate::lti::matrix::solve(&a, &b, m)
        .map_err(|_| Error::Numerical("robustness filter (the conditions are dependent)"))?;
    let mut c = [T::zero(); MAX_CONDITIONS];
    for (i, ci) in c.iter_mut().enumerate().take(m) {
        *ci = T::of(x.get(i).copied().unwrap_or(0.0));
    }
    if c.iter().any(|v| !v.is_finite()) {
        return Err(Error::Numerical("robustness filter"));
    }
    Ok((c, m))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::ExpectOk;

    /// Fr = kf (z − ρ1)(z − ρ2)/((z − γ1)(z − γ2)): with Q = z − ρ1 the free part is
    /// c = kf·z − kf·ρ2.
    fn second_order(h: usize, pole: f64, g1: f64, g2: f64, r1: f64) -> (f64, f64) {
        let dr = [1.0, -(g1 + g2), g1 * g2];
        let (c, m) = solve(h, &dr, &[1.0, -r1], &[(1.0, 1), (pole, 1)]).expect_ok();
        assert_eq!(m, 2);
        (c[0], -c[1] / c[0])
    }

    #[test]
    fn garcia_example_1() -> Result<(), Box<dyn std::error::Error>> {
        // García et al. (2010) Example 1: T = 0.2, h = 30, unstable pole e^{0.2/20}; ρ2 = 0.9957, kf = 14.9524
        let (kf, r2) = second_order(30, (0.2f64 / 20.0).exp(), 0.2494, 0.9945, 0.9355);
        assert!((kf - 14.9524).abs() / 14.9524 < 5e-3, "{kf}");
        assert!((r2 - 0.9957).abs() < 5e-4, "{r2}");
        Ok(())
    }

    #[test]
    fn garcia_example_3() -> Result<(), Box<dyn std::error::Error>> {
        // Example 3: T = 0.1, h = 10, pole 1.036; ρ2 = 0.9894, kf = 1.8739
        let (kf, r2) = second_order(10, 1.036, 0.7825, 0.9835, 0.8187);
        assert!((kf - 1.8739).abs() / 1.8739 < 5e-3, "{kf}");
        assert!((r2 - 0.9894).abs() < 5e-4, "{r2}");
        Ok(())
    }

    #[test]
    fn garcia_example_2_needs_h_30() -> Result<(), Box<dyn std::error::Error>> {
        // Example 2: integrating model, Fr = kf (z − ρ)/(z − e^{−T}), T = 0.1; the double
        // root at z = 1 through the derivative. The printed ρ = 0.9753, kf = 3.8549 come
        // out with h = 30 samples (the seeds' README), not with the 40 of the plant's delays.
        let dr = [1.0, -(-0.1f64).exp()];
        let (c, _) = solve(30, &dr, &[1.0], &[(1.0, 2)])?;
        let (kf, rho) = (c[0], -c[1] / c[0]);
        assert!((kf - 3.8549).abs() / 3.8549 < 5e-3, "{kf}");
        assert!((rho - 0.9753).abs() < 5e-4, "{rho}");
        let (c40, _) = solve(40, &dr, &[1.0], &[(1.0, 2)])?;
        assert!((c40[0] - 3.8549).abs() > 0.5);
        Ok(())
    }
}

mod design;
mod runtime;

pub(crate) use self::design::buffer;
pub use self::design::{
    design, design_in, design_tf_in, design_with, FrSpec, FspDesign, Realization,
};
// the block-level polynomials the designs are written in (`crate::lti::small`)
#[cfg(feature = "alloc")]
pub use self::runtime::Plan;
pub use self::runtime::{
    DirectForm, FilteredSmith, FspPredictor, Matched2Dof, Predicted, Predictor, Primary, SplitForm,
};
pub use crate::lti::small::{model_tf, taps_at, SmallPoly, SMALL};

crate::params::param_struct! {
    /// Parameters of the filtered Smith predictor: the PI primary controller
    /// and the time constant `Tf` of the robustness filter `Fr`.
    pub struct FspParams {
        /// Proportional gain `Kp` of the PI.
        kp: Finite,
        /// Integral time `Ti` of the PI (s).
        ti: Positive,
        /// Robustness filter time constant `Tf` (s), García et al. (2010) Eq. 10.
        tf: Positive,
    }
}

crate::params::design_struct! {
    /// Design inputs of the filtered Smith predictor of García et al. (2010).
    pub struct FspTuning {
        /// Robustness filter time constant `Tf` (s); default `L/2`.
        tf,
    }
}
