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
use crate::{Error, Real};

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
    let mut a = [[T::zero(); MAX_CONDITIONS]; MAX_CONDITIONS];
    let mut b = [T::zero(); MAX_CONDITIONS];
    let mut row = 0usize;
    for (x, mu) in roots {
        for j in 0..*mu {
            // Σ_i c_i · d^j[z^(m−1−i) Q(z)](x) = d^j[z^h Dr(z)](x)
            if let Some(r) = a.get_mut(row) {
                for (i, v) in r.iter_mut().enumerate().take(m) {
                    *v = shifted_derivative(m.saturating_sub(1).saturating_sub(i), q, j, *x);
                }
            }
            if let Some(v) = b.get_mut(row) {
                *v = shifted_derivative(h, dr, j, *x);
            }
            row = row.saturating_add(1);
        }
    }
    // Gaussian elimination with partial pivoting on the m×m system
    for col in 0..m {
        let piv = (col..m)
            .max_by(|p, q| {
                let ap = a
                    .get(*p)
                    .and_then(|r| r.get(col))
                    .map_or(T::zero(), |v| v.abs());
                let aq = a
                    .get(*q)
                    .and_then(|r| r.get(col))
                    .map_or(T::zero(), |v| v.abs());
                ap.partial_cmp(&aq).unwrap_or(core::cmp::Ordering::Equal)
            })
            .unwrap_or(col);
        a.swap(col, piv);
        b.swap(col, piv);
        let p = a
            .get(col)
            .and_then(|r| r.get(col))
            .copied()
            .unwrap_or(T::zero());
        if p.abs() <= T::epsilon() {
            return Err(Error::Numerical(
                "robustness filter (the conditions are dependent)",
            ));
        }
        let pivot_row = a.get(col).copied().unwrap_or([T::zero(); MAX_CONDITIONS]);
        let bc = b.get(col).copied().unwrap_or(T::zero());
        for r in 0..m {
            if r == col {
                continue;
            }
            let f = a
                .get(r)
                .and_then(|x| x.get(col))
                .copied()
                .unwrap_or(T::zero())
                / p;
            if let Some(rr) = a.get_mut(r) {
                for (v, pv) in rr.iter_mut().zip(pivot_row.iter()) {
                    *v = *v - f * *pv;
                }
            }
            if let Some(v) = b.get_mut(r) {
                *v = *v - f * bc;
            }
        }
    }
    let mut c = [T::zero(); MAX_CONDITIONS];
    for (i, ci) in c.iter_mut().enumerate().take(m) {
        let d = a.get(i).and_then(|r| r.get(i)).copied().unwrap_or(T::one());
        *ci = b.get(i).copied().unwrap_or(T::zero()) / d;
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

pub(crate) use self::design::buffer;
pub use self::design::{design, design_with, model_tf, FrSpec, FspDesign, SmallPoly, SMALL};
pub use self::runtime::{
    DirectForm, FilteredSmith, FspPredictor, Matched2Dof, Predicted, Predictor, Primary,
};

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

/// The design of `Fr` and `S` without allocation: model-sized polynomials in
/// fixed arrays, the dead-time-sized ones (`z^h·Dr`, `p`, the numerator of
/// `S`) in storage the caller's type provides ([`DelayStorage`]: a `Vec` on a
/// host, `[f64; C]` on a device, `C` at least `h` plus twice the model order
/// plus 8).
mod design {
    use super::{solve, MAX_CONDITIONS};
    use crate::complex::Complex;
    use crate::delay::DelayStorage;
    use crate::{Error, Lti};
    #[allow(unused_imports)] // f64 methods under no_std
    use num_traits::Float;

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
        fn lead(&self) -> f64 {
            self.c.first().copied().unwrap_or(1.0)
        }
    }

    /// Numerator and denominator (descending powers of `z`, the numerator with
    /// as many coefficients as the denominator) of a discrete block, by
    /// Faddeev–LeVerrier on its realization.
    pub fn model_tf<const N: usize>(b: &Lti<f64, N>) -> (SmallPoly, SmallPoly) {
        let n = b.order().min(N);
        let at = |m: &[[f64; N]; N], i: usize, j: usize| {
            m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
        };
        let mut den = [0.0; SMALL];
        if let Some(d0) = den.first_mut() {
            *d0 = 1.0;
        }
        let mut m = [[0.0; N]; N];
        for (i, row) in m.iter_mut().enumerate() {
            if let Some(x) = row.get_mut(i) {
                *x = 1.0;
            }
        }
        let mut ms = [[[0.0; N]; N]; N];
        for k in 1..=n {
            // A·M_{k−1}
            let mut am = [[0.0; N]; N];
            for (i, row) in am.iter_mut().enumerate().take(n) {
                for (j, x) in row.iter_mut().enumerate().take(n) {
                    *x = (0..n).map(|q| b.phi_entry(i, q) * at(&m, q, j)).sum();
                }
            }
            let tr: f64 = (0..n).map(|i| at(&am, i, i)).sum();
            let ck = -tr / f64::from(u32::try_from(k).unwrap_or(u32::MAX));
            if let Some(slot) = ms.get_mut(k - 1) {
                *slot = m;
            }
            if let Some(d) = den.get_mut(k) {
                *d = ck;
            }
            for (i, row) in am.iter_mut().enumerate() {
                if let Some(x) = row.get_mut(i) {
                    *x += ck;
                }
            }
            m = am;
        }
        // numerator: C·M_k·Γ for k = 0..n−1 (the coefficient of z^{n−1−k}), plus D·den
        let (cv, g, d) = (b.output_vector(), b.input_vector(), b.feedthrough());
        let mut num = [0.0; SMALL];
        for (k, mk) in ms.iter().enumerate().take(n) {
            let v: f64 = (0..n)
                .map(|i| {
                    cv.get(i).copied().unwrap_or(0.0)
                        * (0..n)
                            .map(|j| at(mk, i, j) * g.get(j).copied().unwrap_or(0.0))
                            .sum::<f64>()
                })
                .sum();
            if let Some(x) = num.get_mut(k + 1) {
                *x = v;
            }
        }
        for (x, ck) in num.iter_mut().zip(den.iter()).take(n + 1) {
            *x += d * ck;
        }
        let len = n + 1;
        (SmallPoly { c: num, len }, SmallPoly { c: den, len })
    }

    /// The shape of the robustness filter `Fr = Nr/Dr` whose free coefficients
    /// Eq. 10 fixes.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct FrSpec {
        /// Time constant `Tf` of the filter poles `γ = e^{−Ts/Tf}` (s).
        pub tf: f64,
        /// An optional phase lead `(z − ρ1)/(z − γ1)` given by its zero and pole
        /// time constants `(T_zero, T_pole)`: `ρ1 = e^{−Ts/T_zero}`,
        /// `γ1 = e^{−Ts/T_pole}` (García et al. (2010) Sec. 4, from the lead of `Gcd`).
        pub lead: Option<(f64, f64)>,
        /// `Nr` of the same degree as `Dr` (the biproper filters of García et al. (2010)
        /// Sec. 4: `Dr = (z − γ)^{m−1}`), or `Nr` one degree lower
        /// (`Dr = (z − γ)^m`, a strictly proper filter).
        pub biproper: bool,
    }

    /// The designed predictor: `ŷ = S(z)·u + Fr(z)·y` with `S = Gm(1 − z^{−h}Fr)`
    /// realized without the unstable poles, `S = z^{−h}·Nm(z − 1)p/(Dm⁻·Dr)`.
    #[derive(Debug, Clone)]
    pub struct FspDesign<S> {
        /// `Fr = Nr/Dr` (descending powers of z).
        pub nr: SmallPoly,
        /// Its denominator.
        pub dr: SmallPoly,
        /// Numerator of `S` in powers of `z^{−1}` (starting at `z^{−delay}`):
        /// the first [`FspDesign::s_len`] entries.
        pub s_num: S,
        /// Length of the numerator of `S`.
        pub s_len: usize,
        /// Denominator of `S` in powers of `z^{−1}` (monic).
        pub s_den: SmallPoly,
    }

    impl<S: AsRef<[f64]>> FspDesign<S> {
        /// The numerator of `S`.
        pub fn s_num(&self) -> &[f64] {
            self.s_num.as_ref().get(..self.s_len).unwrap_or(&[])
        }
    }

    /// Storage of at least `len` values.
    pub(crate) fn buffer<T: crate::Real, S: DelayStorage<T>>(len: usize) -> Result<S, Error> {
        let n = u32::try_from(len).map_err(|_| Error::DelayTooLong("predictor storage"))?;
        let s = S::for_delay(T::of(f64::from(n)))?;
        if s.as_ref().len() < len {
            return Err(Error::DelayTooLong("predictor storage"));
        }
        Ok(s)
    }

    /// Designs the filter `Fr = Nr/(z − α)^m` (`α = e^{−Ts/Tf}`) and the stable predictor
    /// `S` for the ZOH model `gm` with a dead time of `h` samples.
    ///
    /// On a device, with arrays for the dead-time-sized buffers:
    ///
    /// ```
    /// use msp::dtc::fsp::{design, FilteredSmith};
    /// use msp::Controller;
    /// // 5 e^{-6s}/(100s - 1) at Ts = 0.06 s: h = 100 samples; buffers of 128
    /// let (gm, _) = msp::ProcessModel::from(msp::Ufopdt::new(5.0, 100.0, 6.0)?).discretize::<1>(0.06)?;
    /// let d = design::<[f64; 128], 1>(&gm, 100, 0.06, 3.0)?; // Fr with Tf = 3 s, S stable
    /// let mut fsp: FilteredSmith<f32, [f32; 128]> =
    ///     FilteredSmith::new(msp::PidConfig::isa(6.87, 12.36, 0.0, 0.06), &d, Default::default())?;
    /// assert!(fsp.update(1.0, 0.0) > 0.0);
    /// # Ok::<(), msp::Error>(())
    /// ```
    pub fn design<S: DelayStorage<f64>, const N: usize>(
        gm: &Lti<f64, N>,
        h: usize,
        ts: f64,
        tf: f64,
    ) -> Result<FspDesign<S>, Error> {
        design_with(
            gm,
            h,
            ts,
            &FrSpec {
                tf,
                lead: None,
                biproper: false,
            },
        )
    }

    /// Designs `Fr` of the shape `spec` and the stable predictor `S` for the ZOH
    /// model `gm` (strictly proper) with a dead time of `h` samples: FSPCC's
    /// `Fr = kf (z − ρ1)(z − ρ2)/((z − γ1)(z − γ2))` is
    /// `FrSpec { tf, lead: Some((T_zero, T_pole)), biproper: true }`.
    pub fn design_with<S: DelayStorage<f64>, const N: usize>(
        gm: &Lti<f64, N>,
        h: usize,
        ts: f64,
        spec: &FrSpec,
    ) -> Result<FspDesign<S>, Error> {
        if gm.feedthrough() != 0.0 {
            return Err(Error::Unsupported(
                "fsp needs a strictly proper model (TransferFunction::to_model_lti gives one)",
            ));
        }
        let (nm, dm) = model_tf(gm);
        let deg = dm.len().saturating_sub(1);
        let mut rts = [Complex::<f64>::default(); SMALL];
        crate::lti::roots(dm.as_slice(), &mut rts)?;
        let (mut dplus, mut dminus) = (SmallPoly::new(&[1.0])?, SmallPoly::new(&[1.0])?);
        // the roots of Dm⁺(z)(z − 1) with multiplicities (clustered within 1e-6)
        let mut cond = [(0.0f64, 0usize); MAX_CONDITIONS];
        let mut count = 0usize;
        let mut add = |x: f64, cond: &mut [(f64, usize); MAX_CONDITIONS]| -> Result<(), Error> {
            if let Some(c) = cond
                .iter_mut()
                .take(count)
                .find(|(r, _)| (*r - x).abs() < 1e-6)
            {
                c.1 = c.1.saturating_add(1);
                return Ok(());
            }
            let slot = cond.get_mut(count).ok_or(Error::OutOfRange("roots"))?;
            *slot = (x, 1);
            count = count.saturating_add(1);
            Ok(())
        };
        add(1.0, &mut cond)?;
        for r in rts.iter().take(deg) {
            let (re, im) = (r.re, r.im);
            if re.hypot(im) >= 1.0 - 1e-9 {
                if im.abs() > 1e-9 {
                    return Err(Error::Unsupported(
                        "complex unstable poles in the filtered Smith predictor",
                    ));
                }
                add(re, &mut cond)?;
                dplus = dplus.mul(&[1.0, -re])?;
            } else if im.abs() <= 1e-12 {
                dminus = dminus.mul(&[1.0, -re])?;
            } else if im > 0.0 {
                dminus = dminus.mul(&[1.0, -2.0 * re, re * re + im * im])?;
            }
        }
        let cond = cond.get(..count).unwrap_or(&[]);
        let m: usize = cond.iter().map(|c| c.1).sum();
        let pole =
            |t: f64| -> Result<f64, Error> { Ok((-ts / crate::real::positive(t, "tf")?).exp()) };
        let alpha = pole(spec.tf)?;
        let mut dr = SmallPoly::new(&[1.0])?;
        for _ in 0..(if spec.biproper {
            m.saturating_sub(1)
        } else {
            m
        }) {
            dr = dr.mul(&[1.0, -alpha])?;
        }
        let q = match spec.lead {
            Some((t_zero, t_pole)) => {
                dr = dr.mul(&[1.0, -pole(t_pole)?])?;
                SmallPoly::new(&[1.0, -pole(t_zero)?])?
            }
            None => SmallPoly::new(&[1.0])?,
        };
        let (c, k) = solve(h, dr.as_slice(), q.as_slice(), cond)?;
        let nr = q.mul(c.get(..k).unwrap_or(&[]))?;
        // diff = z^h·Dr − Nr, then p = diff/(Dm⁺(z − 1)) in place (quotient in front)
        let dlen = h.saturating_add(dr.len());
        let mut diff: S = buffer(dlen)?;
        {
            let d = diff.as_mut();
            d.iter_mut().for_each(|v| *v = 0.0);
            for (x, v) in d.iter_mut().zip(dr.as_slice()) {
                *x = *v;
            }
            let off = dlen.saturating_sub(nr.len());
            for (i, v) in nr.as_slice().iter().enumerate() {
                if let Some(x) = d.get_mut(off.saturating_add(i)) {
                    *x -= v;
                }
            }
        }
        let divisor = dplus.mul(&[1.0, -1.0])?;
        let scale = {
            let d = diff.as_ref();
            d.iter().take(dlen).fold(1.0f64, |m, v| m.max(v.abs()))
        };
        let qlen = {
            let d = diff.as_mut().get_mut(..dlen).unwrap_or(&mut []);
            let qlen = crate::lti::divide_in_place(d, divisor.as_slice());
            if d.iter()
                .take(dlen)
                .skip(qlen)
                .any(|r| r.abs() > 1e-6 * scale)
            {
                return Err(Error::Numerical("robustness filter (Eq. 10 not satisfied)"));
            }
            qlen
        };
        // S = Nm(z − 1)p / (Dm⁻·Dr·z^h), in powers of z^{−1}
        let nm1 = SmallPoly::new(nm.as_slice())?.mul(&[1.0, -1.0])?;
        let a = dminus.mul(dr.as_slice())?;
        let a_lead = a.lead();
        let da = a.len().saturating_sub(1).saturating_add(h);
        let blen = qlen.saturating_add(nm1.len()).saturating_sub(1);
        let db = blen.saturating_sub(1);
        let s_len = da.saturating_add(1);
        let off = da.saturating_sub(db);
        let mut s_num: S = buffer(s_len)?;
        {
            let p = diff.as_ref();
            let out = s_num.as_mut();
            out.iter_mut().for_each(|v| *v = 0.0);
            for (i, ni) in nm1.as_slice().iter().enumerate() {
                for (j, pj) in p.iter().take(qlen).enumerate() {
                    if let Some(x) = out.get_mut(off.saturating_add(i).saturating_add(j)) {
                        *x += ni * pj / a_lead;
                    }
                }
            }
        }
        let mut s_den = [0.0; SMALL];
        for (d, v) in s_den.iter_mut().zip(a.as_slice()) {
            *d = v / a_lead;
        }
        Ok(FspDesign {
            nr,
            dr,
            s_num,
            s_len,
            s_den: SmallPoly::new(s_den.get(..a.len()).unwrap_or(&[1.0]))?,
        })
    }
}

/// The controllers: generic over `f32`/`f64` and over the storage of the
/// dead-time-sized buffers (`Vec` on a host, arrays on a device).
mod runtime {
    use super::design::{buffer, FspDesign, SMALL};
    use crate::delay::DelayStorage;
    use crate::params::ParamList;
    use crate::{CascadeControl, Controller, FrequencyResponse, Introspect};
    use crate::{Complex, Error, Lti, Pid, PidConfig, Real};

    /// An output predictor of the predictor-based dead-time compensators:
    /// `ŷ[k] = Su(z)·u[k] + Sy(z)·y[k]`, with `Su` strictly proper (it sees
    /// the past inputs only). The filtered Smith predictor's `S`, `Fr` and the
    /// GPCC's `F1`, `F2`, `Fk` ([`crate::dtc::gpcc`]) are two such predictors.
    pub trait Predictor<T: Real> {
        /// The prediction at this sample from the past inputs and the measurement `y`.
        fn predict(&mut self, y: T) -> T;
        /// A sample whose measurement is missing: the part driven by the inputs only.
        fn predict_held(&mut self) -> T;
        /// Records the input `u[k]` applied at this sample.
        fn commit(&mut self, u: T);
        /// Zeroes every state.
        fn reset(&mut self);
        /// `(Su, Sy)` at `z = e^{jθ}`.
        fn response(&self, theta: T) -> (Complex<T>, Complex<T>);
    }

    /// The primary controller of a predictor scheme: `u = Cr(z)·r − Cy(z)·ŷ`.
    pub trait Primary<T: Real> {
        /// One sample (a non-finite `y` holds the output).
        fn update(&mut self, r: T, y: T) -> T;
        /// Zeroes every state.
        fn reset(&mut self);
        /// `(Cr, Cy)` at `z = e^{jθ}`.
        fn response(&self, theta: T) -> (Complex<T>, Complex<T>);
    }

    impl<T: Real> Primary<T> for Pid<T> {
        fn update(&mut self, r: T, y: T) -> T {
            Pid::update(self, r, y)
        }
        fn reset(&mut self) {
            Pid::reset(self)
        }
        fn response(&self, theta: T) -> (Complex<T>, Complex<T>) {
            Pid::response(self, theta)
        }
    }

    /// A discrete two-degree-of-freedom controller `u = K(z)·(F(z)·r − y)`:
    /// the pole-zero matched form of a continuous design (García et al. (2010) Sec. 4: the
    /// primary `K(z)` of FSPCC and GPCC is Uma et al.'s `Gcs` discretized this
    /// way; `F` carries the set-point weight, `F = Gcs,r/Gcs`). One integrator,
    /// in `K`, so nothing grows without bound in steady state.
    #[derive(Debug, Clone)]
    pub struct Matched2Dof<T> {
        f: Lti<T, 4>,
        k: Lti<T, 4>,
        u: T,
    }

    impl<T: Real> Matched2Dof<T> {
        /// From the discrete prefilter `f` and controller `k`.
        pub fn new(f: Lti<T, 4>, k: Lti<T, 4>) -> Self {
            Matched2Dof { f, k, u: T::zero() }
        }
    }

    impl<T: Real> Primary<T> for Matched2Dof<T> {
        fn update(&mut self, r: T, y: T) -> T {
            if !(r.is_finite() && y.is_finite()) {
                return self.u;
            }
            let rf = self.f.step(r);
            self.u = self.k.step(rf - y);
            self.u
        }
        fn reset(&mut self) {
            self.f.reset();
            self.k.reset();
            self.u = T::zero();
        }
        fn response(&self, theta: T) -> (Complex<T>, Complex<T>) {
            let k = self.k.response(theta);
            (k * self.f.response(theta), k)
        }
    }

    /// A direct-form filter over a ring of past inputs and outputs:
    /// `s[n] = Σ_{k≥1} b_k u[n−k] − Σ_{k≥1} a_k s[n−k]` (strictly proper,
    /// `a_0 = 1`). The numerator (as long as the dead time) and the input
    /// history live in storage `S`; the denominator is model-sized.
    #[derive(Debug, Clone)]
    pub struct DirectForm<T, S> {
        num: S,
        nlen: usize,
        den: [T; SMALL],
        dlen: usize,
        u_hist: S,
        s_hist: [T; SMALL],
        uh: usize,
        sh: usize,
    }

    impl<T: Real, S: DelayStorage<T>> DirectForm<T, S> {
        /// The filter `num/den` in powers of `z^{−1}` (`num[0]` is ignored: strictly proper).
        pub fn new(num: &[f64], den: &[f64]) -> Result<Self, Error> {
            if den.len() > SMALL {
                return Err(Error::OrderTooHigh("predictor denominator"));
            }
            let nlen = num.len().max(1);
            let mut nb: S = buffer(nlen)?;
            nb.as_mut().iter_mut().for_each(|v| *v = T::zero());
            for (d, v) in nb.as_mut().iter_mut().zip(num) {
                *d = T::of(*v);
            }
            let mut u_hist: S = buffer(nlen)?;
            u_hist.as_mut().iter_mut().for_each(|v| *v = T::zero());
            let mut dn = [T::zero(); SMALL];
            for (d, v) in dn.iter_mut().zip(den) {
                *d = T::of(*v);
            }
            Ok(DirectForm {
                num: nb,
                nlen,
                den: dn,
                dlen: den.len().max(1),
                u_hist,
                s_hist: [T::zero(); SMALL],
                uh: 0,
                sh: 0,
            })
        }
    }

    impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> DirectForm<T, S> {
        /// The output at this sample from the history.
        pub fn output(&self) -> T {
            let (n, m) = (self.nlen, self.dlen);
            let num = self.num.as_ref().get(1..n).unwrap_or(&[]);
            let uh = self.u_hist.as_ref().get(..n).unwrap_or(&[]);
            // u[n − k] for k = 1, 2, … runs backwards from u_hist[uh] and wraps:
            // two contiguous pieces, no index arithmetic per term
            let (front, back) = uh.split_at((self.uh + 1).min(uh.len()));
            let mut acc = T::zero();
            let mut coeffs = num.iter();
            // (the history first in the zip: it is the one that runs out)
            for (u, b) in front.iter().rev().zip(coeffs.by_ref()) {
                acc = acc + *b * *u;
            }
            for (u, b) in back.iter().rev().zip(coeffs) {
                acc = acc + *b * *u;
            }
            for (k, a) in self.den.iter().enumerate().take(m).skip(1) {
                let idx = (self.sh + m - ((k - 1) % m)) % m;
                acc = acc - *a * self.s_hist.get(idx).copied().unwrap_or(T::zero());
            }
            acc
        }
        /// Stores `u[n]` and the output `s[n]` as the newest history entries.
        pub fn push(&mut self, u: T, s: T) {
            self.uh = (self.uh + 1) % self.nlen.max(1);
            self.sh = (self.sh + 1) % self.dlen.max(1);
            if let Some(x) = self.u_hist.as_mut().get_mut(self.uh) {
                *x = u;
            }
            if let Some(x) = self.s_hist.get_mut(self.sh) {
                *x = s;
            }
        }
        /// Zeroes the history.
        pub fn reset(&mut self) {
            self.u_hist.as_mut().iter_mut().for_each(|v| *v = T::zero());
            self.s_hist.iter_mut().for_each(|v| *v = T::zero());
            self.uh = 0;
            self.sh = 0;
        }
        /// The response at `z = e^{jθ}`.
        pub fn response(&self, theta: T) -> Complex<T> {
            let zi =
                |k: usize| Complex::cis(-theta * T::of(f64::from(u32::try_from(k).unwrap_or(0))));
            let sum = |p: &[T]| {
                p.iter()
                    .enumerate()
                    .fold(Complex::default(), |a, (k, b)| a + zi(k).scale(*b))
            };
            sum(self.num.as_ref().get(..self.nlen).unwrap_or(&[]))
                / sum(self.den.get(..self.dlen).unwrap_or(&[]))
        }
    }

    /// The filtered Smith predictor's output predictor `ŷ = S(z)·u + Fr(z)·y`
    /// (García et al. (2010) Fig. 6). `S` is evaluated in direct form over
    /// the input history (its numerator spans the dead time, so the cost is
    /// proportional to it).
    #[derive(Debug, Clone)]
    pub struct FspPredictor<T, S> {
        fr: Lti<T, 8>,
        s: DirectForm<T, S>,
        last_s: T,
    }

    impl<T: Real, S: DelayStorage<T>> FspPredictor<T, S> {
        /// The predictor of a design.
        pub fn new<D: AsRef<[f64]>>(d: &FspDesign<D>) -> Result<Self, Error> {
            Ok(FspPredictor {
                fr: Lti::from_discrete_tf_of(d.nr.as_slice(), d.dr.as_slice())?,
                s: DirectForm::new(d.s_num(), d.s_den.as_slice())?,
                last_s: T::zero(),
            })
        }
    }

    impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> Predictor<T> for FspPredictor<T, S> {
        fn predict(&mut self, y: T) -> T {
            self.last_s = self.s.output();
            self.last_s + self.fr.step(y)
        }
        fn predict_held(&mut self) -> T {
            self.last_s = self.s.output();
            self.last_s
        }
        fn commit(&mut self, u: T) {
            self.s.push(u, self.last_s);
        }
        fn reset(&mut self) {
            self.fr.reset();
            self.s.reset();
            self.last_s = T::zero();
        }
        fn response(&self, theta: T) -> (Complex<T>, Complex<T>) {
            (self.s.response(theta), self.fr.response(theta))
        }
    }

    /// A primary controller `K` around an output predictor: `u = K(r − ŷ)`.
    /// With [`FspPredictor`] this is the filtered Smith predictor for unstable,
    /// integrating and stable plants; with [`crate::dtc::gpcc::GpccPredictor`]
    /// the generalized predictor.
    #[derive(Debug, Clone)]
    pub struct Predicted<T, P, K = Pid<T>> {
        k: K,
        pred: P,
        params: ParamList<T>,
        yhat: T,
        fault: bool,
    }

    /// The filtered Smith predictor (with a PID primary controller).
    pub type FilteredSmith<T, S> = Predicted<T, FspPredictor<T, S>>;

    impl<T: Real, S: DelayStorage<T>> FilteredSmith<T, S> {
        /// The controller `k` around the designed predictor.
        pub fn new<D: AsRef<[f64]>>(
            k: PidConfig<T>,
            d: &FspDesign<D>,
            params: ParamList<T>,
        ) -> Result<Self, Error> {
            Predicted::with_predictor(k, FspPredictor::new(d)?, params)
        }
    }

    impl<T: Real, P: Predictor<T>> Predicted<T, P> {
        /// The PID `k` around `pred`, reporting `params`.
        pub fn with_predictor(
            k: PidConfig<T>,
            pred: P,
            params: ParamList<T>,
        ) -> Result<Self, Error> {
            Ok(Predicted::with_primary(Pid::new(k)?, pred, params))
        }
    }

    impl<T: Real, P: Predictor<T>, K: Primary<T>> Predicted<T, P, K> {
        /// Any primary controller `k` around `pred`, reporting `params`.
        pub fn with_primary(k: K, pred: P, params: ParamList<T>) -> Self {
            Predicted {
                k,
                pred,
                params,
                yhat: T::zero(),
                fault: false,
            }
        }
    }

    impl<T: Real, P: Predictor<T>, K: Primary<T>> Controller<T> for Predicted<T, P, K> {
        fn update(&mut self, r: T, y: T) -> T {
            if !(r.is_finite() && y.is_finite()) {
                // the output is held; the predictor keeps following the actuator
                self.fault = true;
                self.pred.predict_held();
                let u = self.k.update(r, T::nan());
                self.pred.commit(u);
                return u;
            }
            self.fault = false;
            let yhat = self.pred.predict(y);
            let u = self.k.update(r, yhat);
            self.pred.commit(u);
            self.yhat = yhat;
            u
        }

        fn reset(&mut self) {
            self.k.reset();
            self.pred.reset();
            self.yhat = T::zero();
            self.fault = false;
        }

        fn fault(&self) -> bool {
            self.fault
        }
    }

    impl<T: Real, P: Predictor<T>, K: Primary<T>> CascadeControl<T> for Predicted<T, P, K> {}

    impl<T: Real, P: Predictor<T>, K: Primary<T>> Introspect<T> for Predicted<T, P, K> {
        fn signal_names(&self) -> &'static [&'static str] {
            &["prediction"]
        }

        fn signal(&self, i: usize) -> T {
            if i == 0 {
                self.yhat
            } else {
                T::nan()
            }
        }

        fn param_names(&self) -> &'static [&'static str] {
            self.params.names()
        }

        fn param(&self, i: usize) -> T {
            self.params.value(i)
        }
    }

    impl<T: Real, P: Predictor<T>, K: Primary<T>> FrequencyResponse<T> for Predicted<T, P, K> {
        fn response(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
            // u = K_r r − K_y(Su u + Sy y) → u = K_r/(1 + K_y Su)·r − K_y Sy/(1 + K_y Su)·y
            let (kr, ky) = self.k.response(theta);
            let (su, sy) = self.pred.response(theta);
            let d = Complex::real(T::one()) + ky * su;
            Some((kr / d, ky * sy / d))
        }
    }
}
