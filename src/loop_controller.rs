//! The controller as the simulator, the analysis and the registry see it:
//! [`LoopController`], every trait of [`crate::controller`] with
//! [`Operate`] at once; a pointer to a controller operated as the
//! controller; and [`Widened`], an `f32` controller seen as an `f64` one.
//! (Above both the traits and [`Operate`], which builds on them.)

use crate::complex::Complex;
use crate::controller::{CascadeControl, Controller, FrequencyResponse, Introspect};
#[cfg(feature = "alloc")]
use crate::lti::zdomain::Rational;
use crate::operate::{Operate, Tracking};
use crate::real::Real;

/// A controller as the simulator, the analysis and the registry see it: every
/// trait of this module, object safe (`Box<dyn LoopController<f64>>`).
pub trait LoopController<T: Real>:
    Controller<T> + CascadeControl<T> + Introspect<T> + FrequencyResponse<T> + Operate<T>
{
}

impl<T: Real, C> LoopController<T> for C where
    C: Controller<T>
        + CascadeControl<T>
        + Introspect<T>
        + FrequencyResponse<T>
        + Operate<T>
        + ?Sized
{
}

/// A pointer to a controller is operated as the controller (`&mut C`, and
/// `Box<C>` with `alloc`; the other traits: [`crate::controller`]).
macro_rules! forward_operate {
    ($($ptr:ty),*) => {$(
        impl<T: Real, C: Operate<T> + ?Sized> Operate<T> for $ptr {
            fn apply(&mut self, applied: T, how: Tracking) {
                (**self).apply(applied, how)
            }
            fn dead_time(&self) -> Option<T> {
                (**self).dead_time()
            }
            fn set_dead_time(&mut self, samples: T) -> Result<(), crate::error::Error> {
                (**self).set_dead_time(samples)
            }
            fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), crate::error::Error> {
                (**self).retune(gain, value)
            }
            fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), crate::error::Error> {
                (**self).ramp_dead_time(samples, per_sample)
            }
            fn set_model(&mut self, gain: T, tau: T) -> Result<(), crate::error::Error> {
                (**self).set_model(gain, tau)
            }
            fn set_adapting(&mut self, on: bool) -> Result<(), crate::error::Error> {
                (**self).set_adapting(on)
            }
            fn visit_log(&self, f: &mut dyn FnMut(crate::adapt::Change<T>)) {
                (**self).visit_log(f);
            }
            fn adaptive_state(&self) -> Option<crate::operate::AdaptiveState<T>> {
                (**self).adaptive_state()
            }
            fn design(&mut self) -> bool {
                (**self).design()
            }
        }
    )*};
}

forward_operate!(&mut C);
#[cfg(feature = "alloc")]
forward_operate!(alloc::boxed::Box<C>);

/// A controller that computes in `f32`, seen as an `f64` one: the set point
/// and the measurements are rounded to `f32` as a device receives them, the
/// output widened exactly. The `f64` simulator and analysis then run the
/// loop a firmware runs (`msp run --float32`).
#[derive(Debug, Clone)]
pub struct Widened<C>(pub C);

impl<C: Controller<f32>> Controller<f64> for Widened<C> {
    #[inline]
    fn update(&mut self, r: f64, y: f64) -> f64 {
        f64::from(self.0.update(f32::of(r), f32::of(y)))
    }
    fn reset(&mut self) {
        self.0.reset();
    }
    fn reset_to_rest(&mut self) {
        self.0.reset_to_rest();
    }
    fn fault(&self) -> bool {
        self.0.fault()
    }
}

impl<C: Operate<f32>> Operate<f64> for Widened<C> {
    fn apply(&mut self, applied: f64, how: Tracking) {
        self.0.apply(f32::of(applied), how);
    }
    fn dead_time(&self) -> Option<f64> {
        self.0.dead_time().map(f64::from)
    }
    fn set_dead_time(&mut self, samples: f64) -> Result<(), crate::error::Error> {
        self.0.set_dead_time(f32::of(samples))
    }
    fn retune(
        &mut self,
        gain: crate::operate::Gain,
        value: f64,
    ) -> Result<(), crate::error::Error> {
        self.0.retune(gain, f32::of(value))
    }
    fn ramp_dead_time(&mut self, samples: f64, per_sample: f64) -> Result<(), crate::error::Error> {
        self.0.ramp_dead_time(f32::of(samples), f32::of(per_sample))
    }
    fn set_model(&mut self, gain: f64, tau: f64) -> Result<(), crate::error::Error> {
        self.0.set_model(f32::of(gain), f32::of(tau))
    }
    fn set_adapting(&mut self, on: bool) -> Result<(), crate::error::Error> {
        self.0.set_adapting(on)
    }
    fn visit_log(&self, f: &mut dyn FnMut(crate::adapt::Change<f64>)) {
        self.0.visit_log(&mut |c| {
            f(crate::adapt::Change {
                sample: c.sample,
                kind: c.kind,
                k: f64::from(c.k),
                tau: f64::from(c.tau),
                theta: f64::from(c.theta),
            });
        });
    }
    fn adaptive_state(&self) -> Option<crate::operate::AdaptiveState<f64>> {
        self.0.adaptive_state().map(|s| s.map(f64::from))
    }
    fn design(&mut self) -> bool {
        self.0.design()
    }
}

impl<C: CascadeControl<f32>> CascadeControl<f64> for Widened<C> {
    #[inline]
    fn update_cascade(&mut self, r: f64, y: f64, y2: f64) -> f64 {
        f64::from(self.0.update_cascade(f32::of(r), f32::of(y), f32::of(y2)))
    }
    fn is_cascade(&self) -> bool {
        self.0.is_cascade()
    }
}

impl<C: Introspect<f32>> Introspect<f64> for Widened<C> {
    fn signal_names(&self) -> &'static [&'static str] {
        self.0.signal_names()
    }
    fn signal(&self, i: usize) -> f64 {
        f64::from(self.0.signal(i))
    }
    fn param_names(&self) -> &'static [&'static str] {
        self.0.param_names()
    }
    fn param(&self, i: usize) -> f64 {
        f64::from(self.0.param(i))
    }
}

impl<C: FrequencyResponse<f32>> FrequencyResponse<f64> for Widened<C> {
    fn response(&self, theta: f64) -> Option<(Complex<f64>, Complex<f64>)> {
        self.0
            .response(f32::of(theta))
            .map(|(a, b)| (widen(a), widen(b)))
    }
    fn inner_response(&self, theta: f64) -> Option<Complex<f64>> {
        self.0.inner_response(f32::of(theta)).map(widen)
    }
    fn feedback_parts(&self, theta: f64) -> Option<(Complex<f64>, Complex<f64>)> {
        self.0
            .feedback_parts(f32::of(theta))
            .map(|(a, b)| (widen(a), widen(b)))
    }
    fn unstable_poles(&self) -> usize {
        self.0.unstable_poles()
    }
    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(Rational, Rational)> {
        self.0.transfer()
    }
}

fn widen(c: Complex<f32>) -> Complex<f64> {
    Complex {
        re: f64::from(c.re),
        im: f64::from(c.im),
    }
}
