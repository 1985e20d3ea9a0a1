//! Dead-time compensators and the one trait every controller implements.
//!
//! Each scheme lives in its own module and is built from the shared blocks:
//! [`crate::Pid`], [`crate::Lti`] (the delay-free model) and [`crate::Delay`]
//! (the model's dead time).

pub mod astrom_hang_lim;
pub mod cascade;
pub mod compensator;
pub mod disturbance_estimator;
pub mod filtered_smith;
pub mod fsp;
pub mod gpcc;
pub mod huang;
pub mod karan_dey;
pub mod kaya_atherton;
pub mod matausek_micic;
mod smith;
pub mod watanabe_ito;

pub use compensator::Compensator;
pub use karan_dey::{KaranDey, KaranDeyParams};
pub use smith::SmithPredictor;

use crate::Real;

/// A sampled controller: call [`Controller::update`] once per sample period.
///
/// Every scheme in `msp` implements this trait, so the simulator, the CLI and
/// Python treat them alike. Internal signals and parameters are read by index
/// (names from [`Controller::signal_names`] and [`Controller::param_names`]),
/// which keeps the trait allocation-free and object safe.
pub trait Controller<T: Real> {
    /// One sample: set point `r[k]` and measurement `y[k]` in, actuator value `u[k]` out.
    fn update(&mut self, setpoint: T, measurement: T) -> T;
    /// One sample of a cascade loop (García et al. (2010) Fig. 1): the
    /// primary measurement `y[k]` and the secondary (inner) measurement
    /// `y2[k]`. A single-loop controller ignores `y2` and controls `y` from the
    /// plant input directly; a cascade scheme closes its inner loop on it.
    fn update_cascade(&mut self, setpoint: T, measurement: T, inner: T) -> T {
        let _ = inner;
        self.update(setpoint, measurement)
    }
    /// True for a scheme that closes an inner loop on the secondary measurement.
    fn is_cascade(&self) -> bool {
        false
    }
    /// Returns every state to zero (the delay lines included).
    fn reset(&mut self);
    /// Names of the internal signals, e.g. the model output and the model error.
    fn signal_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Value of internal signal `index` after the last update (NaN if out of range).
    fn signal(&self, index: usize) -> T {
        let _ = index;
        T::nan()
    }
    /// Names of the parameters, as in reports and the CLI's `--set`.
    fn param_names(&self) -> &'static [&'static str];
    /// Value of parameter `index` (NaN if out of range).
    fn param(&self, index: usize) -> T;
    /// True when the last update received a non-finite set point or measurement
    /// and held its output instead.
    fn fault(&self) -> bool {
        false
    }
    /// Internal signal by name.
    fn signal_by_name(&self, name: &str) -> Option<T> {
        self.signal_names()
            .iter()
            .position(|n| *n == name)
            .map(|i| self.signal(i))
    }
    /// The linear frequency response at `z = e^{jθ}` (`θ = ω·Ts`) as the pair
    /// `(Cr, Cy)` of `u = Cr·r − Cy·y`, with limits inactive; `None` for a
    /// controller that does not provide it.
    fn response(&self, theta: T) -> Option<(crate::Complex<T>, crate::Complex<T>)> {
        let _ = theta;
        None
    }
    /// The inner (delay-free model) loop `(Gc1 + Gc2)·Gm` at `z = e^{jθ}` of a
    /// scheme that has one.
    fn inner_response(&self, theta: T) -> Option<crate::Complex<T>> {
        let _ = theta;
        None
    }
    /// Writes every internal signal into `out` (in [`Controller::signal_names`] order).
    fn write_signals(&self, out: &mut [T]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.signal(i);
        }
    }
    /// Parameter by name.
    fn param_by_name(&self, name: &str) -> Option<T> {
        self.param_names()
            .iter()
            .position(|n| *n == name)
            .map(|i| self.param(i))
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
            #[inline(always)]
            fn update_cascade(&mut self, r: T, y: T, y2: T) -> T {
                (**self).update_cascade(r, y, y2)
            }
            fn is_cascade(&self) -> bool {
                (**self).is_cascade()
            }
            fn reset(&mut self) {
                (**self).reset()
            }
            fn signal_names(&self) -> &'static [&'static str] {
                (**self).signal_names()
            }
            fn signal(&self, i: usize) -> T {
                (**self).signal(i)
            }
            fn param_names(&self) -> &'static [&'static str] {
                (**self).param_names()
            }
            fn param(&self, i: usize) -> T {
                (**self).param(i)
            }
            fn fault(&self) -> bool {
                (**self).fault()
            }
            fn write_signals(&self, out: &mut [T]) {
                (**self).write_signals(out)
            }
            fn response(&self, theta: T) -> Option<(crate::Complex<T>, crate::Complex<T>)> {
                (**self).response(theta)
            }
            fn inner_response(&self, theta: T) -> Option<crate::Complex<T>> {
                (**self).inner_response(theta)
            }
        }
    )*};
}

forward!(&mut C);
#[cfg(feature = "alloc")]
forward!(alloc::boxed::Box<C>);

/// The plain PID loop is a controller too (the `pid` scheme).
impl<T: Real> Controller<T> for crate::Pid<T> {
    #[inline(always)]
    fn update(&mut self, r: T, y: T) -> T {
        crate::Pid::update(self, r, y)
    }
    fn reset(&mut self) {
        crate::Pid::reset(self)
    }
    fn signal_names(&self) -> &'static [&'static str] {
        &["p", "i", "d"]
    }
    fn signal(&self, i: usize) -> T {
        let t = self.terms();
        match i {
            0 => t.p,
            1 => t.i,
            2 => t.d,
            _ => T::nan(),
        }
    }
    fn param_names(&self) -> &'static [&'static str] {
        &["kp", "ti", "td"]
    }
    fn param(&self, i: usize) -> T {
        let c = self.config();
        match i {
            0 => c.kp,
            1 => c.ti(),
            2 => c.td(),
            _ => T::nan(),
        }
    }
    fn fault(&self) -> bool {
        crate::Pid::fault(self)
    }
    fn response(&self, theta: T) -> Option<(crate::Complex<T>, crate::Complex<T>)> {
        Some(crate::Pid::response(self, theta))
    }
}

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
    #[inline]
    fn update_cascade(&mut self, r: f64, y: f64, y2: f64) -> f64 {
        f64::from(self.0.update_cascade(f32::of(r), f32::of(y), f32::of(y2)))
    }
    fn is_cascade(&self) -> bool {
        self.0.is_cascade()
    }
    fn reset(&mut self) {
        self.0.reset();
    }
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
    fn fault(&self) -> bool {
        self.0.fault()
    }
    fn response(&self, theta: f64) -> Option<(crate::Complex<f64>, crate::Complex<f64>)> {
        self.0
            .response(f32::of(theta))
            .map(|(a, b)| (widen(a), widen(b)))
    }
    fn inner_response(&self, theta: f64) -> Option<crate::Complex<f64>> {
        self.0.inner_response(f32::of(theta)).map(widen)
    }
}

fn widen(c: crate::Complex<f32>) -> crate::Complex<f64> {
    crate::Complex {
        re: f64::from(c.re),
        im: f64::from(c.im),
    }
}
