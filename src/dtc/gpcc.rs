//! The generalized predictor (GPCC's prediction structure,
//! García et al. (2010) Sec. 3.2, Fig. 7, Eqs. 1–4; Albertos & García 2009).
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
//!
//! The design runs in `f64` without allocation (model-sized polynomials in
//! fixed arrays, the `h` Markov parameters and the input history in storage
//! `S`); the predictor runs in `T` (`f32` or `f64`).

use crate::complex::Complex;
use crate::delay::{samples_of, whole_samples, Delay, DelayStorage};
use crate::dtc::fsp::{buffer, model_tf, Predictor, SmallPoly, SMALL};
use crate::lti::zdomain::{Algebra, Point};
use crate::{error::Error, lti::Discretization, lti::Lti, real::Real};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// Zeros of `Gm` with `|z|` at least this go into `Γ`.
pub const ZERO_RADIUS: f64 = 0.8;

/// The GPCC output predictor `ŷ = F1·u + F2·y + Fk(y − z^{−h}ȳ)`.
///
/// Its buffers (`F1`'s taps, the filtered inputs `Γ·u`, the line of `ȳ`)
/// have a capacity fixed at construction; within it the predictor is
/// redesigned for another dead time while it runs
/// ([`Predictor::set_dead_time`]), without allocating.
#[derive(Debug, Clone)]
pub struct GpccPredictor<T, S> {
    gamma: Lti<T, 4>,
    markov: S,
    ring: S,
    h: usize,
    newest: usize,
    f2: Lti<T, 8>,
    fk: Lti<T, 4>,
    line: Delay<T, S>,
    f1: T,
    /// The last measurement (what `F2` is assumed to see next when the
    /// predictor is redesigned between two samples).
    last_y: T,
    /// `Gn`, kept for a redesign: `F1`'s taps and `F2`'s numerator are its
    /// Markov parameters and `A^h·b`.
    gn: Lti<f64, 8>,
    /// `Gn`'s numerator, `F2`'s denominator for any dead time.
    gn_num: SmallPoly,
}

/// `(Γ numerator, Γ denominator, Gn numerator)` for the model numerator `nm`.
fn split_zeros(nm: &[f64]) -> Result<(SmallPoly, SmallPoly, SmallPoly), Error> {
    let nm = SmallPoly::new(nm)?;
    let mut bad = SmallPoly::new(&[1.0])?;
    let mut count = 0usize;
    let deg = nm.len().saturating_sub(1);
    if deg > 0 {
        let mut rts = [Complex::<f64>::default(); SMALL];
        crate::lti::roots(nm.as_slice(), &mut rts)?;
        for r in rts.iter().take(deg) {
            let (re, im) = (r.re, r.im);
            if re.hypot(im) < ZERO_RADIUS {
                continue;
            }
            if im.abs() <= 1e-12 {
                bad = bad.mul(&[1.0, -re])?;
                count = count.saturating_add(1);
            } else if im > 0.0 {
                bad = bad.mul(&[1.0, -2.0 * re, re * re + im * im])?;
                count = count.saturating_add(2);
            }
        }
    }
    // Gn numerator = nm / bad · z^count (the remainder is rounding)
    let mut q = [0.0; SMALL];
    for (d, v) in q.iter_mut().zip(nm.as_slice()) {
        *d = *v;
    }
    let qlen =
        crate::lti::divide_in_place(q.get_mut(..nm.len()).unwrap_or(&mut []), bad.as_slice())
            .max(1);
    let mut gn = [0.0; SMALL];
    for (d, v) in gn.iter_mut().zip(q.iter().take(qlen)) {
        *d = *v;
    }
    let gn = SmallPoly::new(gn.get(..qlen.saturating_add(count)).unwrap_or(&[0.0]))?;
    let mut gd = [0.0; SMALL];
    if let Some(g) = gd.first_mut() {
        *g = 1.0;
    }
    let gamma_den = SmallPoly::new(gd.get(..count.saturating_add(1)).unwrap_or(&[1.0]))?;
    Ok((bad, gamma_den, gn))
}

/// The filters of the GPCC predictor for a ZOH model with a dead time of `h`
/// samples (García et al. (2010) Sec. 3.2): `Γ = gamma_num/gamma_den` holds the
/// model's zeros near or outside the unit circle, `Gn` is the rest of the
/// model, `F1` the FIR of `Gn`'s first `h` Markov parameters, and
/// `F2 = f2_num/f2_den` what `Gn` gives after them.
#[derive(Debug, Clone)]
pub struct GpccFilters {
    /// Numerator of `Γ` (descending powers of `z`).
    pub gamma_num: SmallPoly,
    /// Denominator of `Γ`.
    pub gamma_den: SmallPoly,
    /// Numerator of `F2`.
    pub f2_num: SmallPoly,
    /// Denominator of `F2`.
    pub f2_den: SmallPoly,
    /// `Gn`, whose Markov parameters are `F1`'s taps.
    pub gn: Lti<f64, 8>,
}

/// `F2`'s numerator for `h` samples: the numerator of `c(zI − A)⁻¹A^h b`
/// (Eq. 4), whose denominator is `Gn`'s numerator of length `gn_len`.
fn f2_numerator(gn: &Lti<f64, 8>, gn_len: usize, h: usize) -> Result<SmallPoly, Error> {
    let mut v = gn.input_vector();
    for _ in 0..h {
        v = gn.propagate(&v);
    }
    let (num_star, _) = model_tf(&gn.with_input(&v)?);
    let f2_num = SmallPoly::new(num_star.as_slice())?;
    if f2_num.len() > gn_len {
        return Err(Error::Unsupported(
            "gpcc: the model's relative degree is above one (F2 would be improper)",
        ));
    }
    Ok(f2_num)
}

/// `Gn`'s first `h` Markov parameters `c·A^{i−1}·b` (`F1`'s taps).
fn markov_parameters(gn: &Lti<f64, 8>, h: usize) -> impl Iterator<Item = f64> + '_ {
    let c = gn.output_vector();
    let mut v = gn.input_vector();
    (0..h).map(move |_| {
        let m = c.iter().zip(v.iter()).map(|(a, b)| a * b).sum::<f64>();
        v = gn.propagate(&v);
        m
    })
}

impl GpccFilters {
    /// Designs the filters for `gm` (strictly proper) and `h` samples.
    pub fn design<const N: usize>(gm: &Lti<f64, N>, h: usize) -> Result<Self, Error> {
        if gm.feedthrough() != 0.0 {
            return Err(Error::Unsupported("gpcc needs a strictly proper model"));
        }
        let (nm, dm) = model_tf(gm);
        let (gamma_num, gamma_den, gn_num) = split_zeros(nm.as_slice())?;
        if gamma_num.len() > 5 {
            return Err(Error::OrderTooHigh("gpcc: zeros near the unit circle"));
        }
        let gn: Lti<f64, 8> = Lti::from_discrete_tf(gn_num.as_slice(), dm.as_slice())?;
        let f2_num = f2_numerator(&gn, gn_num.len(), h)?;
        Ok(GpccFilters {
            gamma_num,
            gamma_den,
            f2_num,
            f2_den: gn_num,
            gn,
        })
    }

    /// `F1`'s taps, the first `h` Markov parameters of `Gn`, in order.
    pub fn f1_taps(&self, h: usize) -> impl Iterator<Item = f64> + '_ {
        markov_parameters(&self.gn, h)
    }
}

impl<T: Real, S: DelayStorage<T>> GpccPredictor<T, S> {
    /// Designs the predictor for the ZOH model `gm` with a dead time of `h`
    /// samples; `tk` is the time constant of `Fk(s) = 1/(tk·s + 1)` (pole-zero
    /// matched at `ts`), `0` for `Fk = 1`.
    pub fn design<const N: usize>(
        gm: &Lti<f64, N>,
        h: usize,
        ts: f64,
        tk: f64,
    ) -> Result<Self, Error> {
        Self::design_with_room(gm, (h, h), ts, tk)
    }

    /// [`GpccPredictor::design`] with buffers for a dead time of up to
    /// `room` samples (at least `h`; an array storage's length when that is
    /// more), so that [`Predictor::set_dead_time`] can lengthen it.
    pub fn design_with_room<const N: usize>(
        gm: &Lti<f64, N>,
        (h, room): (usize, usize),
        ts: f64,
        tk: f64,
    ) -> Result<Self, Error> {
        let f = GpccFilters::design(gm, h)?;
        let cap = room.max(h).max(1);
        let mut markov: S = buffer(cap)?;
        markov.as_mut().iter_mut().for_each(|x| *x = T::zero());
        for (slot, m) in markov.as_mut().iter_mut().zip(f.f1_taps(h)) {
            *slot = T::of(m);
        }
        let gn = f.gn;
        let (gamma_num, gamma_den, num_star, gn_num) =
            (f.gamma_num, f.gamma_den, f.f2_num, f.f2_den);
        let fk = if tk > 0.0 {
            Lti::from_tf(
                &[T::one()],
                &[T::of(tk), T::one()],
                T::of(ts),
                Discretization::Matched,
            )?
        } else {
            Lti::gain(T::one())?
        };
        let ring: S = buffer(cap)?;
        Ok(GpccPredictor {
            gamma: Lti::from_discrete_tf_of(gamma_num.as_slice(), gamma_den.as_slice())?,
            markov,
            ring,
            h,
            newest: 0,
            f2: Lti::from_discrete_tf_of(num_star.as_slice(), gn_num.as_slice())?,
            fk,
            line: Delay::with_storage(buffer(cap)?, samples_of(h)?)?,
            f1: T::zero(),
            last_y: T::zero(),
            gn,
            gn_num,
        })
    }
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> GpccPredictor<T, S> {
    /// `F1·u` from the filtered past inputs `w = Γ·u`.
    fn f1_output(&self) -> T {
        let ring = self.ring.as_ref();
        let n = ring.len().max(1);
        self.markov
            .as_ref()
            .iter()
            .take(self.h)
            .enumerate()
            .fold(T::zero(), |acc, (i, m)| {
                // i = 0 is w[k − 1], the newest entry
                let idx = (self.newest + n - (i % n)) % n;
                acc + *m * ring.get(idx).copied().unwrap_or(T::zero())
            })
    }

    /// `(F1, F2, Fk)` at any [`Point`]: `F1 = Σ_{i=1}^{h} m_i·z^{−i}·Γ`.
    pub fn filters<P: Point<T>>(&self, at: &P) -> (P::V, P::V, P::V) {
        // Σ_{i=1}^{h} m_i·z^{−i} = z^{−1}·Σ_{i=0}^{h−1} m_{i+1}·z^{−i}
        let taps = self.markov.as_ref().get(..self.h).unwrap_or(&[]);
        let f1 = at.backward() * at.taps(taps, &[T::one()]) * at.lti(&self.gamma);
        (f1, at.lti(&self.f2), at.lti(&self.fk))
    }
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> Predictor<T> for GpccPredictor<T, S> {
    fn predict(&mut self, y: T) -> T {
        self.last_y = y;
        self.f1 = self.f1_output();
        let ybar = self.f1 + self.f2.step(y);
        let old = self.line.process(ybar);
        ybar + self.fk.step(y - old)
    }
    fn predict_held(&mut self) -> T {
        self.f1 = self.f1_output();
        let ybar = self.f1 + self.f2.free_output();
        self.line.process(ybar);
        ybar
    }
    fn commit(&mut self, u: T) {
        let w = self.gamma.step(u);
        let n = self.ring.as_ref().len().max(1);
        self.newest = (self.newest + 1) % n;
        if let Some(x) = self.ring.as_mut().get_mut(self.newest) {
            *x = w;
        }
    }
    fn amend(&mut self, du: T) {
        let dw = self.gamma.amend_input(du);
        if let Some(x) = self.ring.as_mut().get_mut(self.newest) {
            *x = *x + dw;
        }
    }
    fn dead_time(&self) -> Option<T> {
        samples_of(self.h).ok()
    }
    fn check_dead_time(&self, samples: T) -> Result<usize, Error> {
        let room = self.ring.as_ref().len().min(self.markov.as_ref().len());
        whole_samples(
            samples,
            room,
            "the generalized predictor takes a dead time of whole samples",
        )
    }
    /// Redesigns `F1` and `F2` for `samples` (whole samples, within the
    /// buffers' capacity) without allocating. `Γ` and `F2`'s denominator
    /// (`Gn`'s numerator) do not depend on the dead time, so `Γ`'s and
    /// `F2`'s states carry over (`F2` realized in controllable canonical form
    /// from its denominator); the past filtered inputs are kept, so a longer
    /// `F1` reads inputs that really were applied. The line of `ȳ` holds
    /// what the old filters predicted: it and `Fk`'s state are moved by the
    /// difference `Δ` of the two designs' next `ȳ`, which is exactly what the
    /// new design would hold at a steady state (at a steady state of a
    /// perfect model `Δ = 0`: `ȳ = Gm(1)·u` for any dead time).
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        let h = self.check_dead_time(samples)?;
        let f2_num = f2_numerator(&self.gn, self.gn_num.len(), h)?;
        let mut f2: Lti<T, 8> =
            Lti::from_discrete_tf_of(f2_num.as_slice(), self.gn_num.as_slice())?;
        f2.set_state(self.f2.state());
        // the next ȳ of the old design, then of the new one
        let old = self.f1_output() + self.f2.output(self.last_y);
        self.line.set_delay(samples_of(h)?)?;
        for (slot, m) in self
            .markov
            .as_mut()
            .iter_mut()
            .zip(markov_parameters(&self.gn, h))
        {
            *slot = T::of(m);
        }
        self.h = h;
        self.f2 = f2;
        let delta = self.f1_output() + self.f2.output(self.last_y) - old;
        self.line.offset(delta);
        // Fk(1) = 1 is stable (a matched first-order lag, or a gain)
        self.fk.settle(-delta)
    }
    fn reset(&mut self) {
        self.gamma.reset();
        self.f2.reset();
        self.fk.reset();
        self.line.reset();
        self.ring.as_mut().iter_mut().for_each(|v| *v = T::zero());
        self.newest = 0;
        self.f1 = T::zero();
        self.last_y = T::zero();
    }
    /// `Su = F1(1 − Fk z^{−h})`, `Sy = F2 + Fk(1 − z^{−h}F2)`.
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V) {
        let (f1, f2, fk) = self.filters(at);
        let zh = at.delay(T::of(f64::from(u32::try_from(self.h).unwrap_or(0))));
        let one = P::V::one();
        (
            f1 * (one.clone() - fk.clone() * zh.clone()),
            f2.clone() + fk * (one - zh * f2),
        )
    }
}

/// The generalized predictor controller: a primary `K` around [`GpccPredictor`].
pub type Gpcc<T, S> = crate::dtc::fsp::Predicted<T, GpccPredictor<T, S>>;

#[cfg(test)]
mod tests {
    use super::*;

    fn example1() -> Result<Lti<f64, 8>, Error> {
        // García et al. (2010) Example 1's overall model 1/((2s + 1)(20s − 1)), T = 0.2
        Lti::from_tf(&[1.0], &[40.0, 18.0, -1.0], 0.2, Discretization::Zoh)
    }

    type Arrays = GpccPredictor<f64, [f64; 64]>;

    /// Runs the predictor designed for `gm` and 30 samples on the plant
    /// `z^{−30}Gm` for `n` samples with input `u(k)`, `at(k, p, line)` before
    /// each sample (a change of dead time), and checks Eq. 2 at every sample:
    /// the prediction equals the undelayed model's output.
    fn predicts_exactly(
        gm: Lti<f64, 8>,
        n: u32,
        u: impl Fn(u32) -> f64,
        mut at: impl FnMut(u32, &mut Arrays, &mut Delay<f64, [f64; 64]>) -> Result<(), Error>,
    ) -> Result<Arrays, Error> {
        let mut p: Arrays = GpccPredictor::design(&gm, 30, 0.2, 36.0)?;
        let (mut model, mut plant) = (gm, gm);
        let mut line: Delay<f64, [f64; 64]> = Delay::new_in(30.0)?;
        for k in 0..n {
            at(k, &mut p, &mut line)?;
            let y = line.process(plant.free_output());
            let yhat = p.predict(y);
            let ym = model.free_output();
            assert!(
                (yhat - ym).abs() < 1e-9 * ym.abs().max(1.0),
                "{k}: {yhat} {ym}"
            );
            p.commit(u(k));
            model.advance(u(k));
            plant.advance(u(k));
        }
        Ok(p)
    }

    /// A step, then a sine from sample `from` on.
    fn step_then_sine(from: u32) -> impl Fn(u32) -> f64 {
        move |k| {
            if k < from {
                1.0
            } else {
                (f64::from(k) * 0.05).sin()
            }
        }
    }

    /// Eq. 2 holds exactly: with `y = z^{−h}Gm·u` the prediction equals `Gm·u`.
    #[test]
    fn predicts_the_undelayed_output_of_an_unstable_model() -> Result<(), Error> {
        let p = predicts_exactly(example1()?, 400, step_then_sine(50), |_, _, _| Ok(()))?;
        // the prediction-error filter passes steps: Fk(1) = 1
        let (_, _, fk) = p.filters(&crate::lti::zdomain::Frequency::new(1e-9));
        assert!((fk.re - 1.0).abs() < 1e-9 && fk.im.abs() < 1e-6, "{fk:?}");
        Ok(())
    }

    /// A redesign at a steady state, in array storage (no allocation): the
    /// plant's dead time and the predictor's move from 30 to 40 samples
    /// together, and Eq. 2 goes on holding exactly; beyond the arrays'
    /// capacity, or between samples, the dead time is refused unchanged.
    #[test]
    fn takes_a_new_dead_time_within_its_arrays() -> Result<(), Error> {
        // a stable model at a steady state (Example 1's poles mirrored)
        let gm = Lti::from_tf(&[1.0], &[40.0, 22.0, 1.0], 0.2, Discretization::Zoh)?;
        let change = |k, p: &mut Arrays, line: &mut Delay<f64, [f64; 64]>| {
            if k != 2200 {
                return Ok(());
            }
            let whole =
                Error::Unsupported("the generalized predictor takes a dead time of whole samples");
            assert_eq!(p.set_dead_time(64.5), Err(whole));
            assert_eq!(p.set_dead_time(65.0), Err(Error::DelayTooLong("delay")));
            assert_eq!(p.dead_time(), Some(30.0));
            p.set_dead_time(40.0)?;
            assert_eq!(p.dead_time(), Some(40.0));
            line.set_delay(40.0)
        };
        predicts_exactly(gm, 2600, step_then_sine(2300), change)?;
        Ok(())
    }

    #[test]
    fn gamma_takes_the_sampling_zero() -> Result<(), Error> {
        // García et al. (2010) Example 1: Γ(z) = (z + 0.9704)/z, Gn = 0.00048537 z/((z − 1.01)(z − 0.9048))
        let (nm, _) = model_tf(&example1()?);
        let (g_num, g_den, gn) = split_zeros(nm.as_slice())?;
        assert!((g_num.as_slice()[1] - 0.9704).abs() < 1e-4, "{g_num:?}");
        assert_eq!(g_den.as_slice(), &[1.0, 0.0]);
        assert!((gn.as_slice()[0] - 0.00048537).abs() < 1e-8, "{gn:?}");
        assert_eq!(gn.as_slice()[1], 0.0);
        Ok(())
    }
}
