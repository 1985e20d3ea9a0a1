//! The generalized predictor (GPCC's prediction structure,
//! `002_0ed51b14a8593ff0.txt` Sec. 3.2, Fig. 7, Eqs. 1–4; Albertos & García 2009).
//!
//! The delay-free model is split as `Gm(z) = Gn(z)·Γ(z)` (Eq. 1): `Γ` holds the
//! zeros outside or near the unit circle — here every zero with `|z| ≥ 0.8`
//! (the ZOH sampling zeros near `z = −1` of Examples 1 and 2, which would make
//! `F2` ring; Example 3's zero at `0.4418` stays in `Gn`), as
//! `Γ(z) = Π(z − z_i)/z^{n_Γ}` so that `Gn` keeps the relative degree of `Gm`.
//! With a minimal realization `(A, b, c)` of `Gn` the undelayed output is
//! predicted exactly (Eq. 2) by
//!
//! `ȳ = F1(z)·u + F2(z)·y`, `F1 = Σ_{i=1}^{h} c·A^{i−1}·b·z^{−i}·Γ(z)` (Eq. 3),
//! `F2 = c(zI − A)^{−1}A^h b / (c(zI − A)^{−1}b)` (Eq. 4).
//!
//! `F1` is a finite impulse response over the last `h` inputs (its cost grows
//! with the dead time), `F2`'s poles are the zeros of `Gn`: both are stable for
//! any plant, so no unstable model pole is ever simulated. The prediction error
//! filter `Fk` with `Fk(1) = 1` corrects the prediction with the measured error,
//!
//! `ŷ = ȳ + Fk(z)·(y − z^{−h}ȳ)`,
//!
//! so that, in the filtered Smith predictor's terms, `Fr = F2 + Fk(1 − z^{−h}F2)`
//! (Sec. 3.3) and the robust-stability test of Eq. 17 is shared.

use alloc::vec;
use alloc::vec::Vec;

use crate::delay::Delay;
use crate::dtc::fsp::{model_tf, Predictor};
use crate::poly::{div, mul, poly_roots, trim};
use crate::{Complex, Discretization, Error, Lti};

/// Zeros of `Gm` with `|z|` at least this go into `Γ`.
pub const ZERO_RADIUS: f64 = 0.8;

/// The GPCC output predictor `ŷ = F1·u + F2·y + Fk(y − z^{−h}ȳ)`.
#[derive(Debug, Clone)]
pub struct GpccPredictor {
    gamma: Lti<f64, 4>,
    markov: Vec<f64>,
    ring: Vec<f64>,
    newest: usize,
    f2: Lti<f64, 8>,
    fk: Lti<f64, 4>,
    line: Delay<f64, Vec<f64>>,
    f1: f64,
}

/// `(Γ numerator, Γ denominator, Gn numerator)`.
type Split = (Vec<f64>, Vec<f64>, Vec<f64>);

/// `(Γ numerator, Γ denominator, Gn numerator)` for the model `nm/dm`.
fn split_zeros(nm: &[f64]) -> Result<Split, Error> {
    let nm = trim(nm);
    let mut bad = vec![1.0];
    let mut count = 0usize;
    if nm.len() > 1 {
        for (re, im) in poly_roots(&nm)? {
            if re.hypot(im) < ZERO_RADIUS {
                continue;
            }
            if im.abs() <= 1e-12 {
                bad = mul(&bad, &[1.0, -re]);
                count = count.saturating_add(1);
            } else if im > 0.0 {
                bad = mul(&bad, &[1.0, -2.0 * re, re * re + im * im]);
                count = count.saturating_add(2);
            }
        }
    }
    let (core, _rem) = div(&nm, &bad)?;
    let mut gn = core;
    gn.extend(core::iter::repeat(0.0).take(count));
    let mut gamma_den = vec![1.0];
    gamma_den.extend(core::iter::repeat(0.0).take(count));
    Ok((bad, gamma_den, gn))
}

impl GpccPredictor {
    /// Designs the predictor for the ZOH model `gm` with a dead time of `h`
    /// samples; `tk` is the time constant of `Fk(s) = 1/(tk·s + 1)` (pole-zero
    /// matched at `ts`), `0` for `Fk = 1`.
    pub fn design<const N: usize>(
        gm: &Lti<f64, N>,
        h: usize,
        ts: f64,
        tk: f64,
    ) -> Result<Self, Error> {
        if gm.feedthrough() != 0.0 {
            return Err(Error::Unsupported("gpcc needs a strictly proper model"));
        }
        let (nm, dm) = model_tf(gm);
        let (gamma_num, gamma_den, gn_num) = split_zeros(&nm)?;
        if gamma_num.len() > 5 {
            return Err(Error::OrderTooHigh("gpcc: zeros near the unit circle"));
        }
        let gn: Lti<f64, 8> = Lti::from_discrete_tf(&gn_num, &dm)?;
        let c = gn.output_vector();
        let mut v = gn.input_vector();
        let mut markov = Vec::with_capacity(h);
        for _ in 0..h {
            markov.push(c.iter().zip(v.iter()).map(|(a, b)| a * b).sum::<f64>());
            v = gn.propagate(&v);
        }
        let (num_star, _) = model_tf(&gn.with_input(&v)?);
        let num_star = trim(&num_star);
        let gn_num = trim(&gn_num);
        if num_star.len() > gn_num.len() {
            return Err(Error::Unsupported(
                "gpcc: the model's relative degree is above one (F2 would be improper)",
            ));
        }
        let f2 = Lti::from_discrete_tf(&num_star, &gn_num)?;
        let fk = if tk > 0.0 {
            Lti::from_tf(&[1.0], &[tk, 1.0], ts, Discretization::Matched)?
        } else {
            Lti::gain(1.0)?
        };
        let h_real = f64::from(u32::try_from(h).map_err(|_| Error::DelayTooLong("delay"))?);
        Ok(GpccPredictor {
            gamma: Lti::from_discrete_tf(&gamma_num, &gamma_den)?,
            markov,
            ring: vec![0.0; h.max(1)],
            newest: 0,
            f2,
            fk,
            line: Delay::new_in(h_real)?,
            f1: 0.0,
        })
    }

    /// `F1·u` from the filtered past inputs `w = Γ·u`.
    fn f1_output(&self) -> f64 {
        let n = self.ring.len();
        self.markov
            .iter()
            .enumerate()
            .map(|(i, m)| {
                // i = 0 is w[k − 1], the newest entry
                let idx = (self.newest + n - (i % n)) % n;
                m * self.ring.get(idx).copied().unwrap_or(0.0)
            })
            .sum()
    }

    /// `(F1, F2, Fk)` at `z = e^{jθ}`.
    pub fn filters(&self, theta: f64) -> (Complex<f64>, Complex<f64>, Complex<f64>) {
        let f1 = self
            .markov
            .iter()
            .enumerate()
            .fold(Complex::default(), |a, (i, m)| {
                a + Complex::cis(-theta * (i as f64 + 1.0)).scale(*m)
            })
            * self.gamma.response(theta);
        (f1, self.f2.response(theta), self.fk.response(theta))
    }
}

impl Predictor for GpccPredictor {
    fn predict(&mut self, y: f64) -> f64 {
        self.f1 = self.f1_output();
        let ybar = self.f1 + self.f2.step(y);
        let old = self.line.process(ybar);
        ybar + self.fk.step(y - old)
    }
    fn predict_held(&mut self) -> f64 {
        self.f1 = self.f1_output();
        let ybar = self.f1 + self.f2.free_output();
        self.line.process(ybar);
        ybar
    }
    fn commit(&mut self, u: f64) {
        let w = self.gamma.step(u);
        let n = self.ring.len().max(1);
        self.newest = (self.newest + 1) % n;
        if let Some(x) = self.ring.get_mut(self.newest) {
            *x = w;
        }
    }
    fn reset(&mut self) {
        self.gamma.reset();
        self.f2.reset();
        self.fk.reset();
        self.line.reset();
        self.ring.iter_mut().for_each(|v| *v = 0.0);
        self.newest = 0;
        self.f1 = 0.0;
    }
    /// `Su = F1(1 − Fk z^{−h})`, `Sy = F2 + Fk(1 − z^{−h}F2)`.
    fn response(&self, theta: f64) -> (Complex<f64>, Complex<f64>) {
        let (f1, f2, fk) = self.filters(theta);
        let zh = Complex::cis(-theta * self.markov.len() as f64);
        let one = Complex::real(1.0);
        (f1 * (one - fk * zh), f2 + fk * (one - zh * f2))
    }
}

/// The generalized predictor controller: a primary `K` around [`GpccPredictor`].
pub type Gpcc = crate::dtc::fsp::Predicted<GpccPredictor>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dtc::fsp::Predictor;

    /// Eq. 2 holds exactly: with `y = z^{−h}Gm·u` the prediction equals `Gm·u`.
    #[test]
    fn predicts_the_undelayed_output_of_an_unstable_model() -> Result<(), Error> {
        // Example 1's overall model, T = 0.2, h = 30
        let ts = 0.2;
        let gm: Lti<f64, 8> = Lti::from_tf(
            &[1.0],
            &crate::poly::mul(&[2.0, 1.0], &[20.0, -1.0]),
            ts,
            Discretization::Zoh,
        )?;
        let h = 30;
        let mut p = GpccPredictor::design(&gm, h, ts, 36.0)?;
        let (mut model, mut plant) = (gm, gm);
        let mut line: Delay<f64, Vec<f64>> = Delay::new_in(30.0)?;
        for k in 0..400 {
            let u = if k < 50 { 1.0 } else { (k as f64 * 0.05).sin() };
            let y = line.process(plant.free_output());
            let yhat = p.predict(y);
            let ym = model.free_output();
            assert!(
                (yhat - ym).abs() < 1e-9 * ym.abs().max(1.0),
                "{k}: {yhat} {ym}"
            );
            p.commit(u);
            model.advance(u);
            plant.advance(u);
        }
        Ok(())
    }

    #[test]
    fn gamma_takes_the_sampling_zero() -> Result<(), Error> {
        // 002_… Example 1: Γ(z) = (z + 0.9704)/z, Gn = 0.00048537 z/((z − 1.01)(z − 0.9048))
        let gm: Lti<f64, 8> = Lti::from_tf(
            &[1.0],
            &crate::poly::mul(&[2.0, 1.0], &[20.0, -1.0]),
            0.2,
            Discretization::Zoh,
        )?;
        let (nm, _) = model_tf(&gm);
        let (g_num, g_den, gn) = split_zeros(&nm)?;
        assert!((g_num[1] - 0.9704).abs() < 1e-4, "{g_num:?}");
        assert_eq!(g_den, vec![1.0, 0.0]);
        let gn = trim(&gn);
        assert!((gn[0] - 0.00048537).abs() < 1e-8, "{gn:?}");
        assert_eq!(gn[1], 0.0);
        Ok(())
    }
}
