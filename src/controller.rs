//! The traits every controller implements, split by who needs them.
//!
//! - [`Controller`]: the per-sample contract firmware uses — `update(r, y)`
//!   once per sample, `reset`, `fault`. Nothing else is needed to run a loop.
//! - [`CascadeControl`]: operation with a secondary measurement `y2`
//!   (García et al. (2010), Fig. 1); a single-loop controller takes the
//!   defaults and ignores `y2`.
//! - [`Introspect`]: internal signals and parameters by index and by name,
//!   for logging, reports and the CLI's `--set`.
//! - [`FrequencyResponse`]: the linear response at `z = e^{jθ}` for analysis.
//!
//! [`crate::LoopController`] is all four at once, with [`crate::Operate`] (modes,
//! external reset, run-time dead time), object safe: what the simulator,
//! the analysis and the scheme registry hold behind a pointer. It is
//! implemented for every type that implements the four.

#[cfg(feature = "alloc")]
use crate::lti::zdomain::Rational;
use crate::{complex::Complex, real::Real};

/// A sampled controller: call [`Controller::update`] once per sample period.
pub trait Controller<T: Real> {
    /// One sample: set point `r[k]` and measurement `y[k]` in, actuator value `u[k]` out.
    fn update(&mut self, setpoint: T, measurement: T) -> T;
    /// Returns every state to zero (the delay lines included).
    fn reset(&mut self);
    /// Returns every state to zero, as [`Controller::reset`], with the
    /// loop at rest before the next sample: every signal before it zero,
    /// the initial condition of the controller's transfer function
    /// ([`FrequencyResponse::transfer`], Python's `to_control()`). The
    /// difference is a PID's first update: after `reset` (or built new) it
    /// takes its first sample as the derivative's reference — no kick, a
    /// controller started on a running process, as pid-rs and simple-pid
    /// do — and after `reset_to_rest` it differences against zero, as the
    /// transfer function from rest does (msp's simulator starts every loop
    /// so: a step at the first sample gives the transfer function's step
    /// response, sample for sample).
    fn reset_to_rest(&mut self) {
        self.reset();
    }
    /// True when the last update received a non-finite set point or measurement
    /// and held its output instead.
    fn fault(&self) -> bool {
        false
    }
}

/// Operation in a cascade loop (García et al. (2010), Fig. 1).
pub trait CascadeControl<T: Real>: Controller<T> {
    /// One sample of a cascade loop: the primary measurement `y[k]` and the
    /// secondary (inner) measurement `y2[k]`. A single-loop controller ignores
    /// `y2` and controls `y` from the plant input directly; a cascade scheme
    /// closes its inner loop on it.
    fn update_cascade(&mut self, setpoint: T, measurement: T, inner: T) -> T {
        let _ = inner;
        self.update(setpoint, measurement)
    }
    /// True for a scheme that closes an inner loop on the secondary measurement.
    fn is_cascade(&self) -> bool {
        false
    }
}

/// Internal signals and parameters, read by index (allocation-free and object
/// safe) with their names from [`Introspect::signal_names`] and
/// [`Introspect::param_names`].
pub trait Introspect<T: Real> {
    /// Names of the internal signals, e.g. the model output and the model error.
    fn signal_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Value of internal signal `index` after the last update (NaN if out of range).
    fn signal(&self, index: usize) -> T {
        let _ = index;
        T::nan()
    }
    /// Writes every internal signal into `out` (in [`Introspect::signal_names`] order).
    fn write_signals(&self, out: &mut [T]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.signal(i);
        }
    }
    /// Internal signal by name.
    fn signal_by_name(&self, name: &str) -> Option<T> {
        self.signal_names()
            .iter()
            .position(|n| *n == name)
            .map(|i| self.signal(i))
    }
    /// Names of the parameters, as in reports and the CLI's `--set`.
    fn param_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Value of parameter `index` (NaN if out of range).
    fn param(&self, index: usize) -> T {
        let _ = index;
        T::nan()
    }
    /// Parameter by name.
    fn param_by_name(&self, name: &str) -> Option<T> {
        self.param_names()
            .iter()
            .position(|n| *n == name)
            .map(|i| self.param(i))
    }
}

/// The linear frequency response of a controller, limits inactive.
pub trait FrequencyResponse<T: Real> {
    /// The response at `z = e^{jθ}` (`θ = ω·Ts`) as the pair `(Cr, Cy)` of
    /// `u = Cr·r − Cy·y`; `None` for a controller that does not provide it.
    fn response(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        let _ = theta;
        None
    }
    /// The inner (delay-free model) loop `(Gc1 + Gc2)·Gm` at `z = e^{jθ}` of a
    /// scheme that has one.
    fn inner_response(&self, theta: T) -> Option<Complex<T>> {
        let _ = theta;
        None
    }
    /// The feedback path split as `Cy = Nc/Dc` at `z = e^{jθ}`, where `Dc` is
    /// the determinant of the controller's own internal loops (`1` for a
    /// controller without one) and neither part has a pole but those of the
    /// controller's blocks (PID, filters, the model, delay lines). With the
    /// process `P = Np/Dp` split the same way, `Dc·Dp + Nc·Np` is the closed
    /// loop's characteristic polynomial divided by its blocks' denominators,
    /// which is what the stability verdict counts the roots of
    /// ([`crate::analysis::stability`]). The default is `(Cy, 1)`: right for
    /// a controller whose `Cy` is its blocks in series and parallel.
    fn feedback_parts(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        self.response(theta)
            .map(|(_, cy)| (cy, Complex::real(T::one())))
    }
    /// How many poles of the controller's blocks lie outside the unit circle
    /// (an unstable model's; a PID, a filter or a delay line has none).
    fn unstable_poles(&self) -> usize {
        0
    }
    /// `(Cr, Cy)` of [`FrequencyResponse::response`] as rational functions of
    /// `z^{−1}` (the same composition of the same blocks; the delay lines as
    /// powers of `z^{−1}`); `None` for a controller that does not provide it.
    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(Rational, Rational)> {
        None
    }
}

/// A pointer to a controller is a controller (`&mut C`, and `Box<C>` with `alloc`).
macro_rules! forward {
    ($($ptr:ty),*) => {$(
        impl<T: Real, C: Controller<T> + ?Sized> Controller<T> for $ptr {
            #[inline(always)]
            fn update(&mut self, r: T, y: T) -> T {
                (**self).update(r, y)
            }
            fn reset(&mut self) {
                (**self).reset()
            }
            fn reset_to_rest(&mut self) {
                (**self).reset_to_rest()
            }
            fn fault(&self) -> bool {
                (**self).fault()
            }
        }
        impl<T: Real, C: CascadeControl<T> + ?Sized> CascadeControl<T> for $ptr {
            #[inline(always)]
            fn update_cascade(&mut self, r: T, y: T, y2: T) -> T {
                (**self).update_cascade(r, y, y2)
            }
            fn is_cascade(&self) -> bool {
                (**self).is_cascade()
            }
        }
        impl<T: Real, C: Introspect<T> + ?Sized> Introspect<T> for $ptr {
            fn signal_names(&self) -> &'static [&'static str] {
                (**self).signal_names()
            }
            fn signal(&self, i: usize) -> T {
                (**self).signal(i)
            }
            fn write_signals(&self, out: &mut [T]) {
                (**self).write_signals(out)
            }
            fn param_names(&self) -> &'static [&'static str] {
                (**self).param_names()
            }
            fn param(&self, i: usize) -> T {
                (**self).param(i)
            }
        }
        impl<T: Real, C: FrequencyResponse<T> + ?Sized> FrequencyResponse<T> for $ptr {
            fn response(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
                (**self).response(theta)
            }
            fn inner_response(&self, theta: T) -> Option<Complex<T>> {
                (**self).inner_response(theta)
            }
            fn feedback_parts(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
                (**self).feedback_parts(theta)
            }
            fn unstable_poles(&self) -> usize {
                (**self).unstable_poles()
            }
            #[cfg(feature = "alloc")]
            fn transfer(&self) -> Option<(Rational, Rational)> {
                (**self).transfer()
            }
        }
    )*};
}

forward!(&mut C);
#[cfg(feature = "alloc")]
forward!(alloc::boxed::Box<C>);
