//! Design at one frequency: a PI or a PID whose loop crosses 0 dB at a
//! chosen frequency `ωc` with a chosen phase margin `φm` (MATLAB's
//! `pidtune(G, 'PI', wc)` with `pidtuneOptions('PhaseMargin', pm)`, 60° by
//! default).
//!
//! The loop `L = G·C` must pass through `e^{j(−π + φm)}` at `ωc`, so the
//! controller's frequency response there is fixed,
//! `C(jωc) = e^{j(−π + φm)}/G(jωc)`: a point of the Nyquist curve moved to
//! a chosen place (Åström & Hägglund (1995), *PID Controllers: Theory,
//! Design, and Tuning*, 2nd ed., ISA, the frequency-response methods). With
//! `C(jωc) = |C|·e^{jφ}`:
//!
//! - PI `Kp(1 + 1/(Ti s))`: `C(jωc) = Kp − j·Kp/(Ti ωc)`, so
//!   `Kp = |C| cos φ` and `Ti = −1/(ωc tan φ)`; a PI lags by 0 to 90°,
//!   `−90° < φ < 0`;
//! - PID `Kp(1 + 1/(Ti s) + Td s)` with `Td = α·Ti` (`α = 1/4`, the classic
//!   ratio of the Ziegler–Nichols rules): `C(jωc)/Kp = 1 + j(α x − 1/x)`,
//!   `x = Ti ωc`, so `α x² − x tan φ − 1 = 0`,
//!   `x = (tan φ + √(tan² φ + 4α))/(2α)` and `Kp = |C| cos φ`; any
//!   `−90° < φ < 90°`.
//!
//! On MathWorks' dead-time example `5.6 e^{−93.9s}/(40.2s + 1)`, `ωc =
//! 0.006 rad/s` and `φm = 60°` give `Kp = 0.0501`, `Ti = 47.3`, `pidtune`'s
//! numbers (its documentation's Smith predictor example).

use crate::error::Error;
use crate::model::ProcessModel;
use crate::real::{positive, Real};

use super::PidGains;

/// The ratio `Td/Ti` of [`pid_at`].
pub const TD_RATIO: f64 = 0.25;

/// The controller's frequency response at `wc` that puts the loop through
/// `e^{j(−π + pm)}`, as `(|C|, arg C)`, for the plant's gain `gain` and
/// unwrapped phase `phase` (radians) there.
fn needed<T: Real>(gain: T, phase: T, wc: T, pm_deg: T) -> Result<(T, T), Error> {
    positive(wc, "wc")?;
    let pm = pm_deg.to_radians();
    if !(pm > T::zero() && pm < T::of(core::f64::consts::PI)) {
        return Err(Error::OutOfRange("pm"));
    }
    if !(gain > T::zero() && gain.is_finite()) {
        return Err(Error::Unsupported(
            "the plant's gain at the crossover is zero or not finite",
        ));
    }
    if !phase.is_finite() {
        return Err(Error::NonFinite("phase"));
    }
    Ok((T::one() / gain, -T::of(core::f64::consts::PI) + pm - phase))
}
/// The PI `Kp(1 + 1/(Ti s))` whose loop with the plant crosses 0 dB at
/// `wc` rad/s with the phase margin `pm_deg`, from the plant's gain `gain`
/// and phase `phase` (radians, unwrapped: `−ωθ − atan(ωτ)` for a
/// first-order lag with dead time) at `wc` (see the module documentation).
/// A PI only lags, by less than 90°: a loop that needs more, or a lead,
/// is an error that says which way to move the crossover.
///
/// ```
/// use msp::tuning::pi_at;
/// // MathWorks' 5.6 e^{-93.9 s}/(40.2 s + 1) at 0.006 rad/s, 60° (pidtune)
/// let w: f64 = 0.006;
/// let (gain, phase) = (5.6 / (1.0 + (40.2 * w).powi(2)).sqrt(), -93.9 * w - (40.2 * w).atan());
/// let c = pi_at(gain, phase, w, 60.0)?;
/// assert_eq!(((c.kp * 1e4).round(), (c.ti * 10.0).round()), (501.0, 473.0));
/// # Ok::<(), msp::Error>(())
/// ```
pub fn pi_at<T: Real>(gain: T, phase: T, wc: T, pm_deg: T) -> Result<PidGains<T>, Error> {
    let (mag, phi) = needed(gain, phase, wc, pm_deg)?;
    let right = T::of(core::f64::consts::FRAC_PI_2);
    if !(phi < T::zero()) {
        return Err(Error::Unsupported(
            "the plant lags by 180° less the phase margin or more at the crossover, so the controller would have to lead, and a PI only lags: a lower crossover, a smaller phase margin, or a PID",
        ));
    }
    if !(phi > -right) {
        return Err(Error::Unsupported(
            "the plant lags so little at the crossover that the controller would have to lag by 90° or more, more than a PI can: a higher crossover or a larger phase margin",
        ));
    }
    Ok(PidGains {
        kp: mag * phi.cos(),
        ti: -T::one() / (wc * phi.tan()),
        td: T::zero(),
    })
}

/// The PID `Kp(1 + 1/(Ti s) + Td s)` with `Td = Ti/4` ([`TD_RATIO`]) whose
/// loop crosses 0 dB at `wc` with the phase margin `pm_deg`, from the
/// plant's gain and unwrapped phase at `wc` (see [`pi_at`] and the module
/// documentation); the controller's phase there must lie within ±90°.
pub fn pid_at<T: Real>(gain: T, phase: T, wc: T, pm_deg: T) -> Result<PidGains<T>, Error> {
    let (mag, phi) = needed(gain, phase, wc, pm_deg)?;
    let right = T::of(core::f64::consts::FRAC_PI_2);
    if !(phi < right) {
        return Err(Error::Unsupported(
            "the plant lags so much at the crossover that the controller would have to lead by 90° or more, more than a PID can: a lower crossover or a smaller phase margin",
        ));
    }
    if !(phi > -right) {
        return Err(Error::Unsupported(
            "the plant lags so little at the crossover that the controller would have to lag by 90° or more, more than a PID can: a higher crossover or a larger phase margin",
        ));
    }
    let alpha = T::of(TD_RATIO);
    let t = phi.tan();
    let x = (t + (t * t + T::of(4.0) * alpha).sqrt()) / (T::of(2.0) * alpha);
    let ti = x / wc;
    Ok(PidGains {
        kp: mag * phi.cos(),
        ti,
        td: alpha * ti,
    })
}

/// [`pi_at`], or [`pid_at`] with `derivative`, for the process model
/// `model` ([`ProcessModel::frequency_response`] at `wc`): a negative
/// process gain gives a negative `Kp` (a reverse-acting loop).
pub fn at_crossover<T: Real>(
    model: &ProcessModel<T>,
    wc: T,
    pm_deg: T,
    derivative: bool,
) -> Result<PidGains<T>, Error> {
    let (gain, phase) = model.frequency_response(wc);
    let g = if derivative {
        pid_at(gain, phase, wc, pm_deg)?
    } else {
        pi_at(gain, phase, wc, pm_deg)?
    };
    Ok(PidGains {
        kp: if model_gain(model) < T::zero() {
            -g.kp
        } else {
            g.kp
        },
        ..g
    })
}

/// The process model's gain `K`.
fn model_gain<T: Real>(model: &ProcessModel<T>) -> T {
    model.params().0.first().map_or(T::one(), |(_, k)| *k)
}
