//! The filtered Smith predictor for unstable and integrating plants: the
//! robustness filter `Fr(z)` that makes the predictor stable
//! (`002_0ed51b14a8593ff0.txt` Sec. 3.3, Eq. 10).
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
        // 002_… Example 1: T = 0.2, h = 30, unstable pole e^{0.2/20}; ρ2 = 0.9957, kf = 14.9524
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

#[cfg(feature = "alloc")]
pub use self::controller::{
    design, design_with, model_tf, DirectForm, FilteredSmith, FrSpec, FspDesign, FspPredictor,
    Predicted, Predictor,
};

#[cfg(feature = "alloc")]
mod controller {
    use alloc::vec;
    use alloc::vec::Vec;

    use super::solve;
    use crate::dtc::Controller;
    use crate::{Complex, Error, Lti, Pid, PidConfig};

    /// The designed predictor: `ŷ = S(z)·u + Fr(z)·y` with `S = Gm(1 − z^{−h}Fr)`
    /// realized without the unstable poles, `S = z^{−h}·Nm(z − 1)p/(Dm⁻·Dr)`.
    #[derive(Debug, Clone)]
    pub struct FspDesign {
        /// `Fr = Nr/Dr` (descending powers of z).
        pub nr: Vec<f64>,
        /// Its denominator.
        pub dr: Vec<f64>,
        /// Numerator of `S` in powers of `z^{−1}` (starting at `z^{−delay}`).
        pub s_num: Vec<f64>,
        /// Denominator of `S` in powers of `z^{−1}` (monic).
        pub s_den: Vec<f64>,
    }

    fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
        crate::poly::mul(a, b)
    }

    use crate::poly::div;

    /// Numerator and denominator (descending powers of z) of a discrete block, by
    /// Faddeev–LeVerrier on its realization.
    fn tf_of<const N: usize>(b: &Lti<f64, N>) -> (Vec<f64>, Vec<f64>) {
        let n = b.order();
        let z = 0.3f64;
        let _ = z;
        // sample the response on n + 1 points of a circle and solve for the coefficients
        // would be ill-conditioned; LeVerrier on Φ is exact for the small orders used here
        let phi = |i: usize, j: usize| b.phi_entry(i, j);
        let mut c = vec![1.0];
        let mut m = vec![vec![0.0; n]; n];
        for (i, row) in m.iter_mut().enumerate() {
            if let Some(x) = row.get_mut(i) {
                *x = 1.0;
            }
        }
        let mut ms = Vec::with_capacity(n);
        for k in 1..=n {
            // A·M_{k−1}
            let mut am = vec![vec![0.0; n]; n];
            for (i, row) in am.iter_mut().enumerate() {
                for (j, x) in row.iter_mut().enumerate() {
                    *x = (0..n)
                        .map(|q| {
                            phi(i, q) * m.get(q).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
                        })
                        .sum();
                }
            }
            let tr: f64 = (0..n)
                .map(|i| am.get(i).and_then(|r| r.get(i)).copied().unwrap_or(0.0))
                .sum();
            let ck = -tr / k as f64;
            ms.push(m.clone());
            c.push(ck);
            for (i, row) in am.iter_mut().enumerate() {
                if let Some(x) = row.get_mut(i) {
                    *x += ck;
                }
            }
            m = am;
        }
        // numerator: C·M_k·Γ for k = 0..n−1, plus D·den
        let (cv, g, d) = (b.output_vector(), b.input_vector(), b.feedthrough());
        let mut num = vec![0.0; n + 1];
        for (k, mk) in ms.iter().enumerate() {
            let v: f64 = (0..n)
                .map(|i| {
                    cv.get(i).copied().unwrap_or(0.0)
                        * (0..n)
                            .map(|j| {
                                mk.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
                                    * g.get(j).copied().unwrap_or(0.0)
                            })
                            .sum::<f64>()
                })
                .sum();
            if let Some(x) = num.get_mut(k + 1) {
                *x = v;
            }
        }
        for (x, ck) in num.iter_mut().zip(&c) {
            *x += d * ck;
        }
        (num, c)
    }

    /// The shape of the robustness filter `Fr = Nr/Dr` whose free coefficients
    /// Eq. 10 fixes.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct FrSpec {
        /// Time constant `Tf` of the filter poles `γ = e^{−Ts/Tf}` (s).
        pub tf: f64,
        /// An optional phase lead `(z − ρ1)/(z − γ1)` given by its zero and pole
        /// time constants `(T_zero, T_pole)`: `ρ1 = e^{−Ts/T_zero}`,
        /// `γ1 = e^{−Ts/T_pole}` (`002_…` Sec. 4, from the lead of `Gcd`).
        pub lead: Option<(f64, f64)>,
        /// `Nr` of the same degree as `Dr` (the biproper filters of `002_…`
        /// Sec. 4: `Dr = (z − γ)^{m−1}`), or `Nr` one degree lower
        /// (`Dr = (z − γ)^m`, a strictly proper filter).
        pub biproper: bool,
    }

    /// The model `Gm(z)` as numerator and denominator (descending powers of `z`).
    pub fn model_tf<const N: usize>(gm: &Lti<f64, N>) -> (Vec<f64>, Vec<f64>) {
        tf_of(gm)
    }

    /// Designs the filter `Fr = Nr/(z − α)^m` (`α = e^{−Ts/Tf}`) and the stable predictor
    /// `S` for the ZOH model `gm` with a dead time of `h` samples.
    pub fn design<const N: usize>(
        gm: &Lti<f64, N>,
        h: usize,
        ts: f64,
        tf: f64,
    ) -> Result<FspDesign, Error> {
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
    /// model `gm` with a dead time of `h` samples: FSPCC's
    /// `Fr = kf (z − ρ1)(z − ρ2)/((z − γ1)(z − γ2))` is
    /// `FrSpec { tf, lead: Some((T_zero, T_pole)), biproper: true }`.
    pub fn design_with<const N: usize>(
        gm: &Lti<f64, N>,
        h: usize,
        ts: f64,
        spec: &FrSpec,
    ) -> Result<FspDesign, Error> {
        let (nm, dm) = tf_of(gm);
        if gm.feedthrough() != 0.0 {
            return Err(Error::Unsupported(
                "fsp needs a strictly proper model (TransferFunction::to_model_lti gives one)",
            ));
        }
        let roots = crate::poly::poly_roots(&dm)?;
        let mut unstable = Vec::new();
        let (mut dplus, mut dminus) = (vec![1.0], vec![1.0]);
        for (re, im) in roots {
            if re.hypot(im) >= 1.0 - 1e-9 {
                if im.abs() > 1e-9 {
                    return Err(Error::Unsupported(
                        "complex unstable poles in the filtered Smith predictor",
                    ));
                }
                unstable.push(re);
                dplus = mul(&dplus, &[1.0, -re]);
            } else if im.abs() <= 1e-12 {
                dminus = mul(&dminus, &[1.0, -re]);
            } else if im > 0.0 {
                dminus = mul(&dminus, &[1.0, -2.0 * re, re * re + im * im]);
            }
        }
        // the roots of Dm⁺(z)(z − 1) with multiplicities (clustered within 1e-6)
        let mut cond: Vec<(f64, usize)> = vec![(1.0, 1)];
        for u in unstable {
            match cond.iter_mut().find(|(x, _)| (*x - u).abs() < 1e-6) {
                Some(c) => c.1 += 1,
                None => cond.push((u, 1)),
            }
        }
        let m: usize = cond.iter().map(|c| c.1).sum();
        let pole =
            |t: f64| -> Result<f64, Error> { Ok((-ts / crate::real::positive(t, "tf")?).exp()) };
        let alpha = pole(spec.tf)?;
        let mut dr = vec![1.0];
        for _ in 0..(if spec.biproper {
            m.saturating_sub(1)
        } else {
            m
        }) {
            dr = mul(&dr, &[1.0, -alpha]);
        }
        let q = match spec.lead {
            Some((t_zero, t_pole)) => {
                dr = mul(&dr, &[1.0, -pole(t_pole)?]);
                vec![1.0, -pole(t_zero)?]
            }
            None => vec![1.0],
        };
        let (c, k) = solve(h, &dr, &q, &cond)?;
        let nr: Vec<f64> = mul(&q, &c.iter().take(k).copied().collect::<Vec<f64>>());
        // p = (z^h·Dr − Nr)/(Dm⁺(z − 1)), exactly (the remainder is rounding)
        let mut zh_dr = dr.clone();
        zh_dr.extend(core::iter::repeat(0.0).take(h));
        let nr_pad: Vec<f64> = core::iter::repeat(0.0)
            .take(zh_dr.len().saturating_sub(nr.len()))
            .chain(nr.iter().copied())
            .collect();
        let diff: Vec<f64> = zh_dr.iter().zip(&nr_pad).map(|(a, b)| a - b).collect();
        let (p, rem) = div(&diff, &mul(&dplus, &[1.0, -1.0]))?;
        let scale = diff.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1.0);
        if rem.iter().any(|r| r.abs() > 1e-6 * scale) {
            return Err(Error::Numerical("robustness filter (Eq. 10 not satisfied)"));
        }
        // S = Nm(z − 1)p / (Dm⁻·Dr·z^h), in powers of z^{-1}
        let b = mul(&mul(&nm, &[1.0, -1.0]), &p);
        let a = mul(&dminus, &dr);
        let da = a.len() - 1 + h;
        let db = crate::poly::trim(&b).len() - 1;
        let b = crate::poly::trim(&b);
        let lead = a.first().copied().unwrap_or(1.0);
        let mut s_num = vec![0.0; da - db];
        s_num.extend(b.iter().map(|v| v / lead));
        let s_den: Vec<f64> = a.iter().map(|v| v / lead).collect();
        Ok(FspDesign {
            nr,
            dr,
            s_num,
            s_den,
        })
    }

    /// An output predictor of the predictor-based dead-time compensators:
    /// `ŷ[k] = Su(z)·u[k] + Sy(z)·y[k]`, with `Su` strictly proper (it sees
    /// the past inputs only). The filtered Smith predictor's `S`, `Fr` and the
    /// GPCC's `F1`, `F2`, `Fk` ([`crate::dtc::gpcc`]) are two such predictors.
    pub trait Predictor: core::fmt::Debug {
        /// The prediction at this sample from the past inputs and the measurement `y`.
        fn predict(&mut self, y: f64) -> f64;
        /// A sample whose measurement is missing: the part driven by the inputs only.
        fn predict_held(&mut self) -> f64;
        /// Records the input `u[k]` applied at this sample.
        fn commit(&mut self, u: f64);
        /// Zeroes every state.
        fn reset(&mut self);
        /// `(Su, Sy)` at `z = e^{jθ}`.
        fn response(&self, theta: f64) -> (Complex<f64>, Complex<f64>);
    }

    /// A direct-form filter over a ring of past inputs and outputs:
    /// `s[n] = Σ_{k≥1} b_k u[n−k] − Σ_{k≥1} a_k s[n−k]` (strictly proper, `a_0 = 1`).
    #[derive(Debug, Clone)]
    pub struct DirectForm {
        num: Vec<f64>,
        den: Vec<f64>,
        u_hist: Vec<f64>,
        s_hist: Vec<f64>,
        uh: usize,
        sh: usize,
    }

    impl DirectForm {
        /// The filter `num/den` in powers of `z^{−1}` (`num[0]` is ignored: strictly proper).
        pub fn new(num: &[f64], den: &[f64]) -> Self {
            DirectForm {
                num: num.to_vec(),
                den: den.to_vec(),
                u_hist: vec![0.0; num.len().max(1)],
                s_hist: vec![0.0; den.len().max(1)],
                uh: 0,
                sh: 0,
            }
        }
        /// The output at this sample from the history.
        pub fn output(&self) -> f64 {
            let n = self.u_hist.len();
            let m = self.s_hist.len();
            let mut acc = 0.0;
            // u_hist[uh] holds u[n − 1], u_hist[uh − (k − 1)] holds u[n − k]
            for (k, b) in self.num.iter().enumerate().skip(1) {
                let idx = (self.uh + n - ((k - 1) % n)) % n;
                acc += b * self.u_hist.get(idx).copied().unwrap_or(0.0);
            }
            for (k, a) in self.den.iter().enumerate().skip(1) {
                let idx = (self.sh + m - ((k - 1) % m)) % m;
                acc -= a * self.s_hist.get(idx).copied().unwrap_or(0.0);
            }
            acc
        }
        /// Stores `u[n]` and the output `s[n]` as the newest history entries.
        pub fn push(&mut self, u: f64, s: f64) {
            let n = self.u_hist.len().max(1);
            let m = self.s_hist.len().max(1);
            self.uh = (self.uh + 1) % n;
            self.sh = (self.sh + 1) % m;
            if let Some(x) = self.u_hist.get_mut(self.uh) {
                *x = u;
            }
            if let Some(x) = self.s_hist.get_mut(self.sh) {
                *x = s;
            }
        }
        /// Zeroes the history.
        pub fn reset(&mut self) {
            self.u_hist.iter_mut().for_each(|v| *v = 0.0);
            self.s_hist.iter_mut().for_each(|v| *v = 0.0);
            self.uh = 0;
            self.sh = 0;
        }
        /// The response at `z = e^{jθ}`.
        pub fn response(&self, theta: f64) -> Complex<f64> {
            let zi = |k: usize| Complex::cis(-theta * k as f64);
            let sum = |p: &[f64]| {
                p.iter()
                    .enumerate()
                    .fold(Complex::default(), |a, (k, b)| a + zi(k).scale(*b))
            };
            sum(&self.num) / sum(&self.den)
        }
    }

    /// The filtered Smith predictor's output predictor `ŷ = S(z)·u + Fr(z)·y`
    /// (`002_0ed51b14a8593ff0.txt` Fig. 6). `S` is evaluated in direct form over
    /// the input history (its numerator spans the dead time, so the cost is
    /// proportional to it).
    #[derive(Debug, Clone)]
    pub struct FspPredictor {
        fr: Lti<f64, 8>,
        s: DirectForm,
        last_s: f64,
    }

    impl FspPredictor {
        /// The predictor of a design.
        pub fn new(d: &FspDesign) -> Result<Self, Error> {
            Ok(FspPredictor {
                fr: Lti::from_discrete_tf(&d.nr, &d.dr)?,
                s: DirectForm::new(&d.s_num, &d.s_den),
                last_s: 0.0,
            })
        }
    }

    impl Predictor for FspPredictor {
        fn predict(&mut self, y: f64) -> f64 {
            self.last_s = self.s.output();
            self.last_s + self.fr.step(y)
        }
        fn predict_held(&mut self) -> f64 {
            self.last_s = self.s.output();
            self.last_s
        }
        fn commit(&mut self, u: f64) {
            self.s.push(u, self.last_s);
        }
        fn reset(&mut self) {
            self.fr.reset();
            self.s.reset();
            self.last_s = 0.0;
        }
        fn response(&self, theta: f64) -> (Complex<f64>, Complex<f64>) {
            (self.s.response(theta), self.fr.response(theta))
        }
    }

    /// A primary controller `K` around an output predictor: `u = K(r − ŷ)`.
    /// With [`FspPredictor`] this is the filtered Smith predictor for unstable,
    /// integrating and stable plants; with [`crate::dtc::gpcc::GpccPredictor`]
    /// the generalized predictor.
    #[derive(Debug, Clone)]
    pub struct Predicted<P> {
        k: Pid<f64>,
        pred: P,
        names: &'static [&'static str],
        values: Vec<f64>,
        yhat: f64,
        fault: bool,
    }

    /// The filtered Smith predictor.
    pub type FilteredSmith = Predicted<FspPredictor>;

    impl FilteredSmith {
        /// The controller `k` around the designed predictor.
        pub fn new(
            k: PidConfig<f64>,
            d: &FspDesign,
            names: &'static [&'static str],
            values: Vec<f64>,
        ) -> Result<Self, Error> {
            Predicted::with_predictor(k, FspPredictor::new(d)?, names, values)
        }
    }

    impl<P: Predictor> Predicted<P> {
        /// The controller `k` around `pred`; `names`/`values` are the scheme's parameters.
        pub fn with_predictor(
            k: PidConfig<f64>,
            pred: P,
            names: &'static [&'static str],
            values: Vec<f64>,
        ) -> Result<Self, Error> {
            Ok(Predicted {
                k: Pid::new(k)?,
                pred,
                names,
                values,
                yhat: 0.0,
                fault: false,
            })
        }
    }

    impl<P: Predictor> Controller<f64> for Predicted<P> {
        fn update(&mut self, r: f64, y: f64) -> f64 {
            if !(r.is_finite() && y.is_finite()) {
                // the output is held; the predictor keeps following the actuator
                self.fault = true;
                self.pred.predict_held();
                let u = self.k.update(r, f64::NAN);
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
            self.yhat = 0.0;
            self.fault = false;
        }
        fn signal_names(&self) -> &'static [&'static str] {
            &["prediction"]
        }
        fn signal(&self, i: usize) -> f64 {
            if i == 0 {
                self.yhat
            } else {
                f64::NAN
            }
        }
        fn param_names(&self) -> &'static [&'static str] {
            self.names
        }
        fn param(&self, i: usize) -> f64 {
            self.values.get(i).copied().unwrap_or(f64::NAN)
        }
        fn fault(&self) -> bool {
            self.fault
        }
        fn response(&self, theta: f64) -> Option<(Complex<f64>, Complex<f64>)> {
            // u = K_r r − K_y(Su u + Sy y) → u = K_r/(1 + K_y Su)·r − K_y Sy/(1 + K_y Su)·y
            let (kr, ky) = self.k.response(theta);
            let (su, sy) = self.pred.response(theta);
            let d = Complex::real(1.0) + ky * su;
            Some((kr / d, ky * sy / d))
        }
    }
}
