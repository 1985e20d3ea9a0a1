//! The delay-free model of a predictor and its dead-time line.
//!
//! Every scheme that runs a model of the plant beside it (the Smith
//! predictor, the compensators of the Karan–Dey family, the inner IMC loop
//! of a cascade) needs the same signals each sample:
//!
//! `y_m[k] = G_m·u` (the prediction of `y[k + d]`), `y_m[k − d]` and the
//! model error `ε[k] = y[k] − y_m[k − d]`,
//!
//! the first read from the model before it is advanced (the model is
//! strictly proper, so `y_m[k]` does not depend on `u[k]`), the second from
//! the delay line. With a perfect model `ε` is the disturbance's effect
//! alone (Smith's structure, Bag (2022) Eq. 4.5).

use crate::delay::Delay;
use crate::{complex::Complex, error::Error, lti::Lti, real::Real};

/// The model `G_m` (order `≤ N`, strictly proper) and its dead time `d`
/// (a [`Delay`] over storage `S`), with the last `y_m[k]`, `y_m[k − d]` and `ε[k]`.
///
/// `repr(C)`, the signals first: a line over an array is stored in place,
/// and the per-sample stores stay within the short offsets a Cortex-M's
/// load and store instructions reach from the block's address.
#[derive(Debug, Clone)]
#[repr(C)]
pub struct DelayedModel<T, const N: usize, S> {
    ym: T,
    ym_delayed: T,
    error: T,
    model: Lti<T, N>,
    line: Delay<T, S>,
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> DelayedModel<T, N, S> {
    /// The model and its line. A model with direct feed-through is refused
    /// (`Error::Improper("model")`): the predictor's loop would be algebraic.
    pub fn new(model: Lti<T, N>, line: Delay<T, S>) -> Result<Self, Error> {
        if model.feedthrough() != T::zero() {
            return Err(Error::Improper("model"));
        }
        Ok(DelayedModel {
            model,
            line,
            ym: T::zero(),
            ym_delayed: T::zero(),
            error: T::zero(),
        })
    }

    /// The sample's `(y_m[k], ε[k])` for the measurement `y[k]`; the line
    /// takes `y_m[k]` in. A non-finite `y` gives a non-finite `ε` to the
    /// caller, and the stored error keeps its last finite value (the state
    /// and the reported signals never hold a NaN). Call [`Self::advance`]
    /// with the sample's input after it.
    #[inline(always)]
    pub fn predict(&mut self, y: T) -> (T, T) {
        let (ym, ym_d) = self.read();
        let error = y - ym_d;
        // a measurement a controller does not compute with is not kept
        if y.usable() {
            self.error = error;
        }
        (ym, error)
    }

    /// [`Self::predict`] for a caller that has checked that `y` is finite:
    /// the error is stored as it is, one test less on the per-sample path.
    #[inline(always)]
    pub fn predict_finite(&mut self, y: T) -> (T, T) {
        let (ym, ym_d) = self.read();
        let error = y - ym_d;
        self.error = error;
        (ym, error)
    }

    /// The sample's `y_m[k]` without a measurement: the model is taken as
    /// exact (`ε[k] = 0`).
    #[inline(always)]
    pub fn predict_exact(&mut self) -> T {
        self.error = T::zero();
        self.read().0
    }

    /// `(y_m[k], y_m[k − d])`, stored; the line takes `y_m[k]` in.
    #[inline(always)]
    fn read(&mut self) -> (T, T) {
        let ym = self.model.free_output();
        let ym_d = self.line.process(ym);
        self.ym = ym;
        self.ym_delayed = ym_d;
        (ym, ym_d)
    }

    /// Advances the model with the sample's input `u[k]`.
    #[inline(always)]
    pub fn advance(&mut self, u: T) {
        self.model.advance(u);
    }

    /// Amends the last input by `du` (the plant received `u + du`).
    pub fn amend_input(&mut self, du: T) {
        self.model.amend_input(du);
    }

    /// The delay-free model becomes `model` (strictly proper) at this
    /// instant, its state set so that its output continues from the old
    /// model's (a first-order model's state is its output: exact; a higher
    /// order takes the least-norm state with that output). The line keeps
    /// the old model's outputs of the last `d` samples, so the predictor's
    /// `y_m[k − d]` moves to the new model over one dead time, without a jump.
    pub fn set_model(&mut self, model: Lti<T, N>) -> Result<(), Error> {
        if model.feedthrough() != T::zero() {
            return Err(Error::Improper("model"));
        }
        let y = self.model.free_output();
        self.model = model;
        self.model.reset();
        self.model.set_output(y);
        Ok(())
    }

    /// The model's outputs, its state's and its line's, times `g`: what
    /// they would be had the model's gain always been `g` times its own —
    /// for a new model that differs from the old by its gain, its exact
    /// response to the past inputs, so that `y_m[k] − y_m[k − d]` (the
    /// Smith predictor's correction) does not jump where the old model had
    /// settled. Call it after [`Self::set_model`] with the ratio of the new
    /// model's gain to the old one's. The call costs a constant: the line's
    /// samples are multiplied over the following samples, 32 in each, those
    /// read next first ([`Delay::scale`]; a line of 1 000 samples is
    /// rescaled in 33 samples), and nothing is added to the sample's path
    /// otherwise (read through a scale instead, every update cost two
    /// multiplications: the Smith predictor's 79 instructions on a
    /// Cortex-M4F became 84). A `g` that is not a finite positive number
    /// changes nothing.
    pub fn rescale(&mut self, g: T) {
        if !(g > T::zero() && g.is_finite()) {
            return;
        }
        let x = self.model.state().map(|x| x * g);
        self.model.set_state(&x);
        self.line.scale(g);
    }

    /// The delay-free model.
    pub fn block(&self) -> &Lti<T, N> {
        &self.model
    }

    /// `y_m[k]` of the last sample.
    pub fn prediction(&self) -> T {
        self.ym
    }

    /// `y_m[k − d]` of the last sample.
    pub fn delayed_prediction(&self) -> T {
        self.ym_delayed
    }

    /// `ε = y − y_m[k − d]` of the last sample.
    pub fn error(&self) -> T {
        self.error
    }

    /// `[y_m[k], y_m[k − d], ε[k]]`: the signals a predictor reports.
    pub fn signals(&self) -> [T; 3] {
        [self.ym, self.ym_delayed, self.error]
    }

    /// The dead-time line.
    pub fn line(&self) -> &Delay<T, S> {
        &self.line
    }

    /// The dead-time line, mutable (a new dead time at run time).
    pub fn line_mut(&mut self) -> &mut Delay<T, S> {
        &mut self.line
    }

    /// How many poles of the model lie outside the unit circle.
    pub fn unstable_poles(&self) -> usize {
        self.model.unstable_poles()
    }

    /// `(G_m(e^{jθ}), e^{−jθd})` at the normalized frequency `θ = ωTs`.
    pub fn response(&self, theta: T) -> (Complex<T>, Complex<T>) {
        (
            self.model.response(theta),
            Complex::delay_response(theta, self.line.delay()),
        )
    }

    /// `(G_m, z^{−d})` at any [`Point`](crate::lti::zdomain::Point).
    pub fn response_at<P: crate::lti::zdomain::Point<T>>(&self, at: &P) -> (P::V, P::V) {
        (at.lti(&self.model), at.delay(self.line.delay()))
    }

    /// Zeroes the model, the line and the stored signals.
    pub fn reset(&mut self) {
        self.model.reset();
        self.line.reset();
        self.ym = T::zero();
        self.ym_delayed = T::zero();
        self.error = T::zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{delay::DelayLine, lti::Discretization};

    /// A first-order lag `1/(s + 1)` behind 3 samples: `y_m[k − 3]` is
    /// `y_m[k]` three samples late, the step response of the ZOH model is
    /// `1 − e^{−k·Ts}` (its closed form), and `ε = y − y_m[k − 3]`.
    #[test]
    fn delayed_prediction_is_the_prediction_d_samples_late() -> Result<(), Error> {
        let ts = 0.1_f64;
        let model = Lti::<f64, 2>::from_tf(&[1.0], &[1.0, 1.0], ts, Discretization::Zoh)?;
        let line = DelayLine::<f64, 8>::new(3.0)?;
        let mut m = DelayedModel::new(model, line)?;
        let mut ym = [0.0; 20];
        let mut last = 0.0;
        for k in 0..ym.len() {
            let (now, error) = m.predict(0.5);
            assert!((now - (1.0 - (-(k as f64) * ts).exp())).abs() < 1e-12);
            if let Some(slot) = ym.get_mut(k) {
                *slot = now;
            }
            let late = k.checked_sub(3).and_then(|j| ym.get(j)).map_or(0.0, |v| *v);
            assert_eq!(m.delayed_prediction(), late);
            assert_eq!(error, 0.5 - late);
            assert_eq!(m.signals(), [now, late, error]);
            last = error;
            m.advance(1.0);
        }
        let (_, nan) = m.predict(f64::NAN);
        assert!(nan.is_nan());
        assert!(m.signals().iter().all(|v| v.is_finite()));
        assert_eq!(m.error(), last);
        assert_eq!(m.predict_exact(), m.prediction());
        assert_eq!(m.error(), 0.0);
        m.reset();
        assert_eq!(m.signals(), [0.0; 3]);
        assert_eq!(m.predict(1.0), (0.0, 1.0));
        Ok(())
    }

    /// After `set_model(g·G)` and `rescale(g)` the model and its line are
    /// those of a model that was always `g·G` (the same inputs, from the
    /// start): its prediction and its delayed copy from then on, to
    /// rounding, on a line of 37.5 samples; twice (the gains compound); a
    /// factor that is not a finite positive number is refused.
    #[test]
    fn a_rescaled_model_is_the_model_that_always_had_that_gain() -> Result<(), Error> {
        let ts = 0.1_f64;
        let lag = |k: f64| Lti::<f64, 2>::from_tf(&[k], &[2.0, 1.0], ts, Discretization::Zoh);
        let input = |k: usize| (0.3 * k as f64).sin() + if k > 40 { 1.0 } else { 0.0 };
        let mut m = DelayedModel::new(lag(1.0)?, DelayLine::<f64, 64>::new(37.5)?)?;
        let mut gains = [(0.5, 0.5), (4.0, 2.0)].into_iter();
        let mut truth = DelayedModel::new(lag(1.0)?, DelayLine::<f64, 64>::new(37.5)?)?;
        for k in 0..300 {
            if k % 100 == 99 {
                if let Some((g, total)) = gains.next() {
                    m.set_model(lag(total)?)?;
                    m.rescale(g);
                    truth = DelayedModel::new(lag(total)?, DelayLine::<f64, 64>::new(37.5)?)?;
                    for j in 0..k {
                        truth.predict(0.0);
                        truth.advance(input(j));
                    }
                }
            }
            let (a, b) = (m.predict(0.0), truth.predict(0.0));
            assert!(
                (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12,
                "{k}: {a:?} {b:?}"
            );
            m.advance(input(k));
            truth.advance(input(k));
        }
        // a factor that is not a finite positive number changes nothing
        for g in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
            let mut same = m.clone();
            same.rescale(g);
            assert_eq!(same.predict(0.0), m.clone().predict(0.0), "{g}");
        }
        Ok(())
    }

    #[test]
    fn a_model_with_feedthrough_is_refused() -> Result<(), Error> {
        let model = Lti::<f64, 2>::from_tf(&[1.0, 0.0], &[1.0, 1.0], 0.1, Discretization::Zoh)?;
        let line = DelayLine::<f64, 4>::new(1.0)?;
        assert_eq!(
            DelayedModel::new(model, line).err(),
            Some(Error::Improper("model"))
        );
        Ok(())
    }
}
