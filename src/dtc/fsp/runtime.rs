//! The controllers: generic over `f32`/`f64` and over the storage of the
//! dead-time-sized buffers (`Vec` on a host, arrays on a device).

#[cfg(feature = "alloc")]
use super::design::FrSpec;
use super::design::{buffer, sized, FspDesign, Realization};
use crate::delay::{samples_of, DelayStorage};
#[cfg(feature = "alloc")]
use crate::lti::small::SmallPoly;
use crate::lti::small::SMALL;
use crate::lti::zdomain::{Algebra, Frequency, Point};
use crate::params::ParamList;
use crate::{complex::Complex, error::Error, lti::Lti, pid::Pid, pid::PidConfig, real::Real};
use crate::{
    controller::CascadeControl, controller::Controller, controller::FrequencyResponse,
    controller::Introspect,
};

mod split;
mod traits;
pub use split::*;

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
    /// Amends the last committed input by `du` (it was `u + du`).
    fn amend(&mut self, du: T);
    /// The dead time the predictor is designed for (samples), when it can
    /// be redesigned for another ([`Predictor::set_dead_time`]).
    fn dead_time(&self) -> Option<T> {
        None
    }
    /// The dead time `samples` as the whole number of samples the predictor
    /// can be redesigned for, or why not (nothing changes).
    fn check_dead_time(&self, samples: T) -> Result<usize, Error> {
        let _ = samples;
        Err(Error::Unsupported(
            "this predictor is designed for its dead time: rebuild it for another",
        ))
    }
    /// Redesigns the predictor for a dead time of `samples` (whole samples,
    /// as [`Predictor::check_dead_time`] accepts them).
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.check_dead_time(samples).map(|_| ())
    }
    /// Zeroes every state.
    fn reset(&mut self);
    /// `(Su, Sy)` at `z = e^{jθ}`.
    fn response(&self, theta: T) -> (Complex<T>, Complex<T>) {
        self.response_at(&Frequency::new(theta))
    }
    /// `(Su, Sy)` at any [`Point`].
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V);
}

/// The primary controller of a predictor scheme: `u = Cr(z)·r − Cy(z)·ŷ`,
/// run and operated as any controller (a non-finite `ŷ` holds the output
/// and is a fault), with its response and last output.
pub trait Primary<T: Real>: crate::operate::Operate<T> {
    /// `(Cr, Cy)` at `z = e^{jθ}`.
    fn response(&self, theta: T) -> (Complex<T>, Complex<T>) {
        self.response_at(&Frequency::new(theta))
    }
    /// `(Cr, Cy)` at any [`Point`].
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V);
    /// The last output.
    fn output(&self) -> T;
}

impl<T: Real> Primary<T> for Pid<T> {
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V) {
        Pid::response_at(self, at)
    }
    fn output(&self) -> T {
        Pid::output(self)
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
    fault: bool,
}

impl<T: Real> Matched2Dof<T> {
    /// From the discrete prefilter `f` and controller `k`.
    pub fn new(f: Lti<T, 4>, k: Lti<T, 4>) -> Self {
        Matched2Dof {
            f,
            k,
            u: T::zero(),
            fault: false,
        }
    }
}

impl<T: Real> crate::controller::Controller<T> for Matched2Dof<T> {
    fn update(&mut self, r: T, y: T) -> T {
        self.fault = !(r - y).usable();
        if self.fault {
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
        self.fault = false;
    }
    fn fault(&self) -> bool {
        self.fault
    }
}

impl<T: Real> crate::operate::Operate<T> for Matched2Dof<T> {
    /// `K`'s state moves so that its output continues from `applied` (as a
    /// PID's integrator is set in manual mode).
    fn apply(&mut self, applied: T, _how: crate::operate::Tracking) {
        if applied.usable() && self.k.shift_output(applied - self.u) {
            self.u = applied;
        }
    }
    fn retune(&mut self, _gain: crate::operate::Gain, _value: T) -> Result<(), Error> {
        Err(Error::Unsupported(
            "this primary controller is a designed filter, not a PID: rebuild it",
        ))
    }
}

impl<T: Real> Primary<T> for Matched2Dof<T> {
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V) {
        let k = at.lti(&self.k);
        (k.clone() * at.lti(&self.f), k)
    }
    fn output(&self) -> T {
        self.u
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
        DirectForm::new_in(num, den, buffer)
    }
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> DirectForm<T, S> {
    /// [`DirectForm::new`] with the numerator and the input history (each
    /// `num.len()` values) in storage from `storage` (memory the caller owns).
    pub fn new_in(
        num: &[f64],
        den: &[f64],
        mut storage: impl FnMut(usize) -> Result<S, Error>,
    ) -> Result<Self, Error> {
        if den.len() > SMALL {
            return Err(Error::OrderTooHigh("predictor denominator"));
        }
        let nlen = num.len().max(1);
        let mut nb: S = sized(storage(nlen)?, nlen)?;
        nb.as_mut().iter_mut().for_each(|v| *v = T::zero());
        for (d, v) in nb.as_mut().iter_mut().zip(num) {
            *d = T::of(*v);
        }
        let mut u_hist: S = sized(storage(nlen)?, nlen)?;
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
    /// The input `k` samples back (`u[n − k]`, `1 ≤ k ≤` the numerator's length).
    fn past_input(&self, k: usize) -> Option<T> {
        let n = self.nlen;
        if k == 0 || k > n {
            return None;
        }
        let i = (self.uh + n + 1 - k) % n;
        self.u_hist.as_ref().get(i).copied()
    }

    /// Takes over the histories of `old`, a filter with the same denominator
    /// and another numerator: its inputs as far back as it held them (the
    /// oldest repeated beyond: at a steady state every one is the same) and
    /// its past outputs.
    pub fn carry_from(&mut self, old: &Self) -> Result<(), Error> {
        if self.dlen != old.dlen || self.den != old.den {
            return Err(Error::Unsupported(
                "a new denominator: the history does not carry over",
            ));
        }
        let n = self.nlen;
        let oldest = old.past_input(old.nlen).unwrap_or(T::zero());
        for j in 0..n {
            let v = old.past_input(j + 1).unwrap_or(oldest);
            if let Some(x) = self.u_hist.as_mut().get_mut(n - 1 - j) {
                *x = v;
            }
        }
        self.uh = n.saturating_sub(1);
        self.s_hist = old.s_hist;
        self.sh = old.sh;
        Ok(())
    }

    /// Amends the newest input by `du`.
    pub fn amend_last(&mut self, du: T) {
        if let Some(x) = self.u_hist.as_mut().get_mut(self.uh) {
            *x = *x + du;
        }
    }
    /// Zeroes the history.
    pub fn reset(&mut self) {
        self.u_hist.as_mut().iter_mut().for_each(|v| *v = T::zero());
        self.s_hist.iter_mut().for_each(|v| *v = T::zero());
        self.uh = 0;
        self.sh = 0;
    }
    /// The response at any [`Point`].
    pub fn response_at<P: Point<T>>(&self, at: &P) -> P::V {
        at.taps(
            self.num.as_ref().get(..self.nlen).unwrap_or(&[]),
            self.den.get(..self.dlen).unwrap_or(&[]),
        )
    }
}

/// The filtered Smith predictor's output predictor `ŷ = S(z)·u + Fr(z)·y`
/// (García et al. (2010) Fig. 6). For a model with an unstable pole `S` is
/// evaluated in direct form over the input history (its numerator spans the
/// dead time, so the cost is proportional to it); for a stable or
/// integrating model from model-sized blocks ([`SplitForm`], `O(1)`).
/// `N` bounds the order of `Fr` and of the model's blocks.
#[derive(Debug, Clone)]
pub struct FspPredictor<T, S, const N: usize = 8> {
    fr: Lti<T, N>,
    s: SBlock<T, S, N>,
    last_s: T,
    /// What a redesign for another dead time needs (with `alloc`: the
    /// redesign allocates its scratch; a device build carries none of it).
    #[cfg(feature = "alloc")]
    plan: Option<Plan<S>>,
}

/// The model and the filter's shape a predictor was designed from, its dead
/// time, and where new storage comes from: what
/// [`FspPredictor::with_redesign`] keeps for a run-time dead-time change.
#[cfg(feature = "alloc")]
#[derive(Debug, Clone)]
pub struct Plan<S> {
    nm: SmallPoly,
    dm: SmallPoly,
    ts: f64,
    spec: FrSpec,
    h: usize,
    /// The longest dead time (samples) it may be redesigned for.
    max_h: usize,
    storage: fn(usize) -> Result<S, Error>,
}

impl<T: Real, S: DelayStorage<T>, const N: usize> FspPredictor<T, S, N> {
    /// The predictor of a design.
    pub fn new<D: AsRef<[f64]>>(d: &FspDesign<D>) -> Result<Self, Error> {
        FspPredictor::new_in(d, buffer)
    }

    /// Keeps what a redesign for another dead time needs: the model
    /// `Nm/Dm` ([`super::model_tf`]), the period, the filter's shape, the
    /// dead time `h` (samples) it was designed for and the longest `max_h`
    /// it may be given; new storage comes from `S`
    /// ([`crate::Operate::set_dead_time`] then redesigns).
    #[cfg(feature = "alloc")]
    pub fn with_redesign(
        mut self,
        nm: SmallPoly,
        dm: SmallPoly,
        ts: f64,
        spec: FrSpec,
        (h, max_h): (usize, usize),
    ) -> Self {
        self.plan = Some(Plan {
            nm,
            dm,
            ts,
            spec,
            h,
            max_h: max_h.max(h),
            storage: buffer::<T, S>,
        });
        self
    }
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>, const N: usize> FspPredictor<T, S, N> {
    /// [`FspPredictor::new`] with its two dead-time-sized buffers from
    /// `storage` (see [`DirectForm::new_in`]).
    pub fn new_in<D: AsRef<[f64]>>(
        d: &FspDesign<D>,
        storage: impl FnMut(usize) -> Result<S, Error>,
    ) -> Result<Self, Error> {
        let h = d.h;
        Ok(FspPredictor {
            fr: Lti::from_discrete_tf_of(d.nr.as_slice(), d.dr.as_slice())?,
            s: SBlock::of(d, h, storage)?,
            last_s: T::zero(),
            #[cfg(feature = "alloc")]
            plan: None,
        })
    }
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>, const N: usize> Predictor<T> for FspPredictor<T, S, N> {
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
    fn amend(&mut self, du: T) {
        self.s.amend_last(du);
    }
    #[cfg(feature = "alloc")]
    fn dead_time(&self) -> Option<T> {
        self.plan.as_ref().map(|p| T::of(p.h as f64))
    }
    #[cfg(feature = "alloc")]
    fn check_dead_time(&self, samples: T) -> Result<usize, Error> {
        let plan = self.plan.as_ref().ok_or(Error::Unsupported(
            "this predictor is designed for its dead time: rebuild it for another",
        ))?;
        const WHOLE: &str =
            "the filtered Smith predictor takes a dead time of whole samples (at least one)";
        match crate::delay::whole_samples(samples, plan.max_h, WHOLE)? {
            0 => Err(Error::Unsupported(WHOLE)),
            h => Ok(h),
        }
    }
    /// Redesigns `Fr` and `S` for `samples` (whole samples) from the kept
    /// plan: `Dr` does not depend on the dead time, so `Fr`'s state (its
    /// controllable canonical form: `Φ`, `Γ` from `Dr` alone) carries over
    /// with its new numerator, and `S`'s denominator too, so its histories
    /// carry over ([`DirectForm::carry_from`]); `S(1) = 0` and `Fr(1) = 1`
    /// for any dead time, so at a steady state the predictor is the one
    /// designed for the new dead time. The design's scratch is allocated
    /// (`alloc`); without it, or without a plan, [`Error::Unsupported`].
    #[cfg(feature = "alloc")]
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        let h = self.check_dead_time(samples)?;
        let Some(plan) = &self.plan else {
            return Err(Error::Unsupported("no redesign plan"));
        };
        // the same realization as before (its history carries over)
        let split = matches!(self.s, SBlock::Split(_));
        let d = super::design::design_form::<alloc::vec::Vec<f64>, 16>(
            &plan.nm,
            &plan.dm,
            h,
            plan.ts,
            &plan.spec,
            |n| Ok(alloc::vec![0.0; n]),
            split,
        )?;
        let mut fr: Lti<T, N> = Lti::from_discrete_tf_of(d.nr.as_slice(), d.dr.as_slice())?;
        fr.set_state(self.fr.state());
        let mut s = SBlock::of(&d, h, plan.storage)?;
        s.carry_from(&self.s)?;
        self.fr = fr;
        self.s = s;
        if let Some(plan) = &mut self.plan {
            plan.h = h;
        }
        Ok(())
    }
    fn reset(&mut self) {
        self.fr.reset();
        self.s.reset();
        self.last_s = T::zero();
    }
    fn response_at<P: Point<T>>(&self, at: &P) -> (P::V, P::V) {
        (self.s.response_at(at), at.lti(&self.fr))
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
    /// A dead time on its way to a target ([`crate::Operate::ramp_dead_time`]).
    ramp: Option<Ramp<T>>,
}

/// A predictor's dead time moving to `target` one whole sample at a time,
/// at a mean rate of `rate` samples per sample (`progress` accumulates it).
#[derive(Debug, Clone, Copy)]
struct Ramp<T> {
    target: usize,
    rate: T,
    progress: T,
}

/// The filtered Smith predictor (with a PID primary controller).
pub type FilteredSmith<T, S, const N: usize = 8> = Predicted<T, FspPredictor<T, S, N>>;

impl<T: Real, S: DelayStorage<T>, const N: usize> FilteredSmith<T, S, N> {
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
    pub fn with_predictor(k: PidConfig<T>, pred: P, params: ParamList<T>) -> Result<Self, Error> {
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
            ramp: None,
        }
    }
}

impl<T: Real, P: Predictor<T>, K: Primary<T>> Predicted<T, P, K> {
    /// One sample of a dead-time ramp: the dead time moves by a whole sample
    /// each time the accumulated rate reaches one (a redesign that fails
    /// ends the ramp where it is).
    #[cold]
    #[inline(never)]
    fn ramp_step(&mut self) {
        let Some(mut r) = self.ramp.take() else {
            return;
        };
        let Some(mut now) = self.pred.dead_time().and_then(|d| d.round().to_usize()) else {
            return;
        };
        r.progress = r.progress + r.rate;
        // (ten times 0.1 is one within rounding: √ε of slack)
        let one = T::one() - T::epsilon().sqrt();
        while r.progress >= one && now != r.target {
            let next = if r.target > now { now + 1 } else { now - 1 };
            if samples_of(next)
                .and_then(|h| self.pred.set_dead_time(h))
                .is_err()
            {
                return;
            }
            now = next;
            r.progress = r.progress - T::one();
        }
        if now != r.target {
            self.ramp = Some(r);
        }
    }
}

impl<T: Real, P: Predictor<T>, K: Primary<T>> Controller<T> for Predicted<T, P, K> {
    fn update(&mut self, r: T, y: T) -> T {
        if !(r - y).usable() {
            // the output is held (the primary's fault); the predictor keeps
            // following the actuator
            self.pred.predict_held();
            let u = self.k.update(r, T::nan());
            self.pred.commit(u);
            if self.ramp.is_some() {
                self.ramp_step();
            }
            return u;
        }
        let yhat = self.pred.predict(y);
        let u = self.k.update(r, yhat);
        self.pred.commit(u);
        self.yhat = yhat;
        if self.ramp.is_some() {
            self.ramp_step();
        }
        u
    }

    fn reset(&mut self) {
        self.k.reset();
        self.pred.reset();
        self.yhat = T::zero();
    }

    fn reset_to_rest(&mut self) {
        self.reset();
        self.k.reset_to_rest();
    }

    /// The primary's: a non-finite set point or measurement.
    fn fault(&self) -> bool {
        self.k.fault()
    }
}

impl<T: Real, P: Predictor<T>, K: Primary<T>> CascadeControl<T> for Predicted<T, P, K> {}

impl<T: Real, P: Predictor<T>, K: Primary<T>> Predicted<T, P, K> {
    /// `u = K_r r − K_y(Su u + Sy y)`, so
    /// `u = K_r/(1 + K_y Su)·r − K_y Sy/(1 + K_y Su)·y`, at any [`Point`].
    fn response_at<Q: Point<T>>(&self, at: &Q) -> (Q::V, Q::V) {
        let (kr, ky) = self.k.response_at(at);
        let (su, sy) = self.pred.response_at(at);
        let d = Q::V::one() + ky.clone() * su;
        (kr / d.clone(), ky * sy / d)
    }
}

#[cfg(all(test, feature = "std"))]
mod split_tests;
