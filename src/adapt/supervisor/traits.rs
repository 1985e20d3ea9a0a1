//! An adaptive controller is a controller: the shared traits, through
//! the scheme inside.

use super::*;

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Controller<T> for Adaptive<T, C, R, N, H, L>
{
    fn update(&mut self, r: T, y: T) -> T {
        self.step(r, y)
    }

    /// The scheme's reset; the estimator and the log keep what they learnt.
    fn reset(&mut self) {
        self.calm = 0;
        self.inner.reset();
        self.shadow = None;
        self.last_u = T::zero();
        self.ok = false;
        self.pending = None;
    }

    /// As [`Controller::reset`], the scheme at rest.
    fn reset_to_rest(&mut self) {
        self.reset();
        self.inner.reset_to_rest();
    }

    fn fault(&self) -> bool {
        self.inner.fault()
    }
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Operate<T> for Adaptive<T, C, R, N, H, L>
{
    /// The scheme follows the applied value; the estimator learns nothing
    /// from this sample (saturated, manual or tracking: not the process's
    /// answer to the control law) but records what the plant received.
    fn apply(&mut self, applied: T, how: Tracking) {
        self.calm = 0;
        self.inner.apply(applied, how);
        if self.shadow.is_some() {
            if let Some(spare) = self.inner.spare_mut() {
                spare.apply(applied, Tracking::Full);
            }
        }
        if applied.is_finite() && applied != self.last_u {
            self.last_u = applied;
            self.ok = false;
        }
    }
    fn dead_time(&self) -> Option<T> {
        self.inner.dead_time()
    }
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        self.inner.set_dead_time(samples)?;
        self.calm = 0;
        let theta = samples * self.cfg.estimator.ts;
        self.use_model(Model {
            theta,
            ..self.model
        });
        self.reference();
        Ok(())
    }
    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        self.inner.ramp_dead_time(samples, per_sample)?;
        self.calm = 0;
        let theta = samples * self.cfg.estimator.ts;
        self.use_model(Model {
            theta,
            ..self.model
        });
        self.reference();
        Ok(())
    }
    fn retune(&mut self, gain: Gain, value: T) -> Result<(), Error> {
        self.inner.retune(gain, value)
    }
    fn set_adapting(&mut self, on: bool) -> Result<(), Error> {
        self.frozen = !on;
        Ok(())
    }
    fn visit_log(&self, f: &mut dyn FnMut(Change<T>)) {
        for c in self.log() {
            f(c);
        }
    }
    fn adaptive_state(&self) -> Option<crate::operate::AdaptiveState<T>> {
        Some(self.state())
    }
    fn design(&mut self) -> bool {
        Adaptive::design(self)
    }
    fn set_model(&mut self, gain: T, tau: T) -> Result<(), Error> {
        self.inner.set_model(gain, tau)?;
        self.calm = 0;
        self.use_model(Model {
            k: gain,
            tau,
            ..self.model
        });
        self.reference();
        Ok(())
    }
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    CascadeControl<T> for Adaptive<T, C, R, N, H, L>
{
}

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    FrequencyResponse<T> for Adaptive<T, C, R, N, H, L>
where
    C: FrequencyResponse<T>,
{
    fn response(
        &self,
        theta: T,
    ) -> Option<(crate::complex::Complex<T>, crate::complex::Complex<T>)> {
        self.inner.response(theta)
    }
    fn inner_response(&self, theta: T) -> Option<crate::complex::Complex<T>> {
        self.inner.inner_response(theta)
    }
    fn feedback_parts(
        &self,
        theta: T,
    ) -> Option<(crate::complex::Complex<T>, crate::complex::Complex<T>)> {
        self.inner.feedback_parts(theta)
    }
    fn unstable_poles(&self) -> usize {
        self.inner.unstable_poles()
    }
}
