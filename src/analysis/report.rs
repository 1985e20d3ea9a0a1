//! What `msp margins` reports: the loop's margins on the scenario's plant,
//! its stability region and robust-stability test.

use core::ops::{Add, Div, Mul, Sub};
use std::string::String;
use std::vec::Vec;

use super::{DiscretePlant, LoopResponse, Margins, View};
use crate::complex::Complex;
use crate::error::Error;
use crate::poly::TransferFunction;

/// Everything `msp margins` reports.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The plant.
    pub plant: TransferFunction,
    /// The controller's model.
    pub model: TransferFunction,
    /// Cascade processes: the secondary process and its model.
    pub inner_process: Option<(TransferFunction, TransferFunction)>,
    /// Sample period.
    pub ts: f64,
    /// The controller (`none`: the bare plant, or a pure gain `kp`).
    pub controller: &'static str,
    /// The loop is the bare plant or a pure gain, `L = kp·G`: no controller.
    pub bare: bool,
    /// Its parameters.
    pub params: crate::registry::Params,
    /// How the plant is seen: behind the hold, discrete, or continuous.
    pub view: View,
    /// Margins of the loop at the plant input.
    pub margins: Margins,
    /// Margins of the inner (model) loop, for schemes that have one.
    pub inner: Option<Margins>,
    /// The nominal loop's verdict: [`Analysis::stability`]'s, `None` when
    /// it could not be decided.
    pub stable: Option<bool>,
    /// The verdict from the characteristic equation, what decided it and
    /// the simulation's cross-check ([`super::stability`]).
    pub stability: super::Stability,
    /// `(gain factor, delay margin)` pairs: the combined gain/delay stability
    /// region (empty for an unstable loop; a NaN delay margin where the
    /// factor is below the lower gain limit, i.e. unstable).
    pub region: Vec<(f64, f64)>,
    /// `max|T·Δ|` (Eq. 17) for the given perturbation, if one was given.
    pub robust_peak: Option<f64>,
    /// The loop response for plots.
    pub response: LoopResponse,
}

/// One point of the stability region: a loop gain factor and the delay
/// margin of the loop with that gain.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RegionPoint {
    /// The factor on the loop gain.
    pub gain: f64,
    /// The delay margin at that gain (s).
    pub dm: f64,
}

/// Bag (2022) prints margins for its two benchmark plants `0.2e^{−7.4s}/s`
/// and `0.05e^{−6s}/s` under the Karan–Dey MSP and (model 1) the Smith
/// predictor (Tables 5.1–5.17) that are not the feedback loop's: a note
/// saying so for those plants and schemes (`docs/fidelity.md`; the
/// computation that reproduces every printed row is `tests/thesis_margins.rs`).
pub fn published_note(plant: &TransferFunction, controller: &str) -> Option<&'static str> {
    let Some(crate::model::ProcessModel::Ipdt(m)) = plant.exact_model() else {
        return None;
    };
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
    let model1 = near(m.k, 0.2) && near(m.l, 7.4);
    let model2 = near(m.k, 0.05) && near(m.l, 6.0);
    match controller {
        "karan-dey" if model1 => Some(
            "Bag (2022) Table 5.1 prints 7.56 dB, 26.4 deg for this plant: the open loop with the \
             measured output disconnected and a first-order Pade delay, not the feedback loop msp \
             reports; see docs/fidelity.md",
        ),
        "karan-dey" if model2 => Some(
            "Bag (2022) Table 5.5 prints 7.57 dB, 26.3 deg for this plant: the open loop with the \
             measured output disconnected and a first-order Pade delay, not the feedback loop msp \
             reports; see docs/fidelity.md",
        ),
        "smith" if model1 => Some(
            "Bag (2022) Table 5.1 prints 6.02 dB, 56.0 deg for this plant: the Smith predictor's \
             loop with a first-order Pade delay, not the exact delay msp uses; see docs/fidelity.md",
        ),
        _ => None,
    }
}

/// A cascade's secondary process, the controller's IMC loop and its model of the secondary.
pub type InnerLoop<'a> = (
    &'a TransferFunction,
    &'a crate::dtc::cascade::Imc<f64, Vec<f64>>,
    &'a TransferFunction,
);

/// The frequency response `ω ↦ P(jω)` of the process a controller's loop acts on.
pub type ProcessResponse = Box<dyn Fn(f64) -> Complex<f64>>;

/// The process seen from the controller's output at `ω` (rad/s): the plant
/// (sampled-data or discrete view), or for a cascade scheme the primary loop's
/// process `r2 → y` with the inner IMC loop closed, exactly in the discrete
/// view (García et al. (2010) Sec. 3.3):
/// `P(z) = P12(z)·Q(z)/(1 + Q(z)(P2(z) − P2m(z)))`, `P12` and `P2` the ZOH
/// equivalents of `P1·P2` and `P2` with their dead times, `Q` and `P2m` the
/// controller's IMC filter and secondary model.
pub fn process_response(
    plant: &TransferFunction,
    inner: Option<InnerLoop<'_>>,
    ts: f64,
    view: View,
) -> Result<ProcessResponse, Error> {
    if let Some((p2, imc, p2m)) = inner {
        let p12 = DiscretePlant::new(&plant.series(p2)?, ts)?;
        let d2 = DiscretePlant::new(p2, ts)?;
        let m2 = DiscretePlant::new(p2m, ts)?;
        let imc = imc.clone();
        return Ok(Box::new(move |w: f64| {
            let th = w * ts;
            let q = imc.q_response(th);
            let one = Complex::real(1.0);
            p12.response(th)
                .mul(q)
                .div(one.add(q.mul(d2.response(th).sub(m2.response(th)))))
        }));
    }
    let plant = plant.clone();
    Ok(match view {
        View::Discrete => {
            let dp = DiscretePlant::new(&plant, ts)?;
            Box::new(move |w: f64| dp.response(w * ts))
        }
        View::Continuous => Box::new(move |w: f64| {
            let (re, im) = plant.freq(w);
            Complex::new(re, im)
        }),
        View::Sampled => Box::new(move |w: f64| {
            let theta = w * ts;
            let (re, im) = plant.freq(w);
            let zoh = Complex::real(1.0)
                .sub(Complex::cis(-theta))
                .div(Complex::new(0.0, theta));
            Complex::new(re, im).mul(zoh)
        }),
    })
}

/// How many poles of `p` lie in the open right half-plane (outside the unit
/// circle once sampled), or why that is not a count the verdict can use
/// (poles on the imaginary axis away from the origin sample onto the unit
/// circle, where the indentation at `z = 1` does not reach).
pub(super) fn right_half_plane_poles(p: &TransferFunction) -> Result<usize, String> {
    let poles = p
        .poles()
        .map_err(|e| std::format!("the plant's poles could not be found: {e}"))?;
    let mut n = 0;
    for (re, im) in poles {
        let size = re.hypot(im);
        if re > 1e-9 * size {
            n += 1;
        } else if im != 0.0 && re.abs() <= 1e-9 * size {
            return Err(String::from(
                "the plant has undamped poles on the imaginary axis: the verdict is left to the simulation",
            ));
        }
    }
    Ok(n)
}

/// The stability verdict of `controller` on `plant` (for a cascade scheme,
/// the primary process with the secondary `inner` loop closed) at `ts`: the
/// characteristic equation of the exact sampled loop
/// ([`super::stability`]), the process being the plant's ZOH equivalent
/// with its dead time, `P = Np/1`, or for a cascade
/// `P = P12·Q / (1 + Q(P2 − P2m))` (its determinant apart).
pub fn loop_stability(
    controller: &dyn crate::loop_controller::LoopController<f64>,
    plant: &TransferFunction,
    inner: Option<InnerLoop<'_>>,
    ts: f64,
) -> super::Stability {
    let unknown = super::Stability::unknown;
    let whole = match inner {
        Some((p2, _, _)) => match plant.series(p2) {
            Ok(w) => w,
            Err(e) => return unknown(std::format!("{e}")),
        },
        None => plant.clone(),
    };
    let open = match (right_half_plane_poles(plant), inner) {
        (Err(e), _) => return unknown(e),
        (Ok(n), None) => n,
        (Ok(n), Some((p2, _, _))) => match right_half_plane_poles(p2) {
            Ok(0) => n,
            Ok(_) => {
                return unknown(String::from(
                    "the secondary process is unstable: the verdict is left to the simulation",
                ))
            }
            Err(e) => return unknown(e),
        },
    } + controller.unstable_poles();
    let delay = whole.delay_samples(ts).unwrap_or(0.0);
    let own = controller.dead_time().unwrap_or(0.0);
    #[allow(clippy::cast_precision_loss)]
    let rate = delay + 2.0 * own + whole.order() as f64 + 16.0;
    let parts = |theta: f64| controller.feedback_parts(theta);
    let fail = |e: Error| unknown(std::format!("{e}"));
    match inner {
        None => {
            let dp = match DiscretePlant::new(plant, ts) {
                Ok(d) => d,
                Err(e) => return fail(e),
            };
            let process = |theta: f64| (dp.response(theta), Complex::real(1.0));
            super::stability::verdict(&parts, &process, open, rate)
        }
        Some((p2, imc, p2m)) => {
            let (p12, d2, m2) = match (
                DiscretePlant::new(&whole, ts),
                DiscretePlant::new(p2, ts),
                DiscretePlant::new(p2m, ts),
            ) {
                (Ok(a), Ok(b), Ok(c)) => (a, b, c),
                (Err(e), _, _) | (_, Err(e), _) | (_, _, Err(e)) => return fail(e),
            };
            let process = |theta: f64| {
                let q = imc.q_response(theta);
                (
                    p12.response(theta).mul(q),
                    Complex::real(1.0).add(q.mul(d2.response(theta).sub(m2.response(theta)))),
                )
            };
            super::stability::verdict(&parts, &process, open, rate)
        }
    }
}
