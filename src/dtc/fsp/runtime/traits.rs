//! The predicted controller as an operated controller with a frequency
//! response: `Operate`, `Introspect` and `FrequencyResponse`.

use super::*;

impl<T: Real, P: Predictor<T>, K: Primary<T>> crate::operate::Operate<T> for Predicted<T, P, K> {
    /// The primary controller follows `applied` and the predictor records it
    /// as the input of the last sample.
    fn apply(&mut self, applied: T, how: crate::operate::Tracking) {
        let u = self.k.output();
        if !(applied.is_finite() && u.is_finite()) {
            return;
        }
        self.k.apply(applied, how);
        self.pred.amend(applied - u);
    }

    fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), Error> {
        self.k.retune(gain, value)
    }

    fn dead_time(&self) -> Option<T> {
        self.pred.dead_time()
    }

    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.pred.set_dead_time(samples)?;
        self.ramp = None;
        Ok(())
    }

    /// The predictor is redesigned for whole samples only: the dead time
    /// moves by one sample at a time, each time the rate `per_sample`
    /// accumulated since the last move reaches one (at 0.1, one sample every
    /// ten), until it reaches `samples` (checked now: whole, within the room
    /// built in).
    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        let rate = crate::real::positive(per_sample, "slew")?;
        let target = self.pred.check_dead_time(samples)?;
        self.ramp = Some(Ramp {
            target,
            rate,
            progress: T::zero(),
        });
        Ok(())
    }
}

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
        Some(self.response_at(&Frequency::new(theta)))
    }

    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(crate::lti::zdomain::Rational, crate::lti::zdomain::Rational)> {
        Some(self.response_at(&crate::lti::zdomain::Symbolic))
    }

    /// `Nc = K_y·Sy`, `Dc = 1 + K_y·Su`: the primary's loop around the
    /// predictor, whose blocks are stable by design (the predictor is
    /// realized without the model's unstable poles).
    fn feedback_parts(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        let at = Frequency::new(theta);
        let (_, ky) = self.k.response_at(&at);
        let (su, sy) = self.pred.response_at(&at);
        Some((ky * sy, Complex::real(T::one()) + ky * su))
    }
}
