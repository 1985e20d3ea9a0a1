//! Frequency-domain analysis of a sampled controller on its plant, with the
//! exact dead time `e^{−jωθ}` (never a Padé approximation).
//!
//! The loop is broken at the plant input. The controller's feedback path
//! `Cy(e^{jωTs})` comes from [`FrequencyResponse::response`] (every scheme derives it
//! from its own blocks; the tests check it against the time domain). Two
//! views of the plant:
//!
//! - **sampled-data** (default): the continuous plant behind the zero-order
//!   hold, `L(jω) = Cy(e^{jωTs}) · (1 − e^{−jωTs})/(jωTs) · P(jω)`, for
//!   `ω` up to the Nyquist frequency (aliasing neglected);
//! - **discrete**: the exact ZOH equivalent of the plant, dead time included
//!   (a fractional dead time through the modified z-transform),
//!   `L(z) = Cy(z)·P_d(z)` on `z = e^{jωTs}`.
//!
//! From `L`: the gain margin `gm` at the phase crossover `wcg`, the phase
//! margin `pm` (degrees) at the gain crossover `wcp`, the delay margin
//! `dm = pm/wcp` (s), and the peaks `ms = max|1/(1 + L)|`, `mt = max|L/(1 + L)|`
//! (key names of MATLAB's `margin` and python-control). The crossover margins
//! measure the distance to the first imaginary-axis crossing of the
//! closed-loop poles as the loop gain or delay grows from nominal, so they are
//! the loop's gain and delay limits provided the nominal loop is stable —
//! which [`Analysis::stable`] reports from a simulation of the loop: bounded
//! and coming to rest, wherever it rests (the Smith
//! predictor's controller is itself unstable on an integrating model, so
//! the open-loop Nyquist count alone would not settle it).

use core::ops::{Add, Div, Mul, Sub};
use std::vec::Vec;

use crate::complex::Complex;
use crate::controller::FrequencyResponse;
use crate::poly::TransferFunction;
use crate::{error::Error, lti::Discretization, lti::Lti};

mod continuous;
pub mod mimo;
mod report;
pub mod stability;
mod step;
mod transfer;

pub use continuous::continuous_verdict;
pub use report::{
    loop_stability, process_response, published_note, Analysis, InnerLoop, ProcessResponse,
    RegionPoint,
};
pub use stability::Stability;
pub use step::{step_grid, step_response, OpenLoopStep};
pub use transfer::{transfer, Coefficients, Transfer};

/// Which plant view the loop uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum View {
    /// Continuous plant behind a zero-order hold.
    #[default]
    Sampled,
    /// The exact discrete equivalent of the plant.
    Discrete,
    /// The continuous plant without the hold: the margins of a continuous
    /// design, as MATLAB's `margin` on `C·G` gives them (a gain is exact; a
    /// sampled controller's response approaches its continuous design as
    /// `Ts → 0`). A cascade's inner loop stays in the discrete view.
    Continuous,
}

impl View {
    /// Its name in reports: `sampled`, `discrete`, `continuous`.
    pub fn name(self) -> &'static str {
        match self {
            View::Sampled => "sampled",
            View::Discrete => "discrete",
            View::Continuous => "continuous",
        }
    }
}

/// The exact ZOH equivalent of `plant` at `ts` as a frequency response: with
/// `θ = (k + f)·Ts`, `x[n+1] = Φx[n] + Γ₁v[n−k−1] + Γ₂v[n−k]`, `y = Cx`, where
/// `Γ₁ = Φ((1 − f)Ts)·Γ(f·Ts)` and `Γ₂ = Γ((1 − f)Ts)`. A biproper plant's
/// direct term `D` acts on the input in effect just before the sample instant,
/// `D·v[n−k−1]` (the simulator's convention).
pub struct DiscretePlant {
    late: Lti<f64, 8>,
    early: Option<Lti<f64, 8>>,
    k: f64,
    direct: f64,
}

impl DiscretePlant {
    /// The discrete equivalent of `plant` at `ts`.
    pub fn new(plant: &TransferFunction, ts: f64) -> Result<Self, Error> {
        let d = plant.delay_samples(ts)?;
        let (mut k, mut f) = (d.floor(), d - d.floor());
        if f > 1.0 - 1e-12 {
            k += 1.0;
            f = 0.0;
        }
        // the strictly proper part and the direct term
        let num = crate::poly::trim(&plant.num);
        let den = crate::poly::trim(&plant.den);
        let direct = if num.len() >= den.len() {
            num.first().copied().unwrap_or(0.0) / den.first().copied().unwrap_or(1.0)
        } else {
            0.0
        };
        let rest: std::vec::Vec<f64> = if direct != 0.0 {
            num.iter().zip(&den).map(|(n, a)| n - direct * a).collect()
        } else {
            num
        };
        let full = Lti::<f64, 8>::from_tf(&rest, &den, ts, Discretization::Zoh)?;
        if f <= 1e-12 {
            return Ok(DiscretePlant {
                late: full,
                early: None,
                k,
                direct,
            });
        }
        // y(z) = C(zI − Φ)⁻¹[Γ₂ z^{−k} + Γ₁ z^{−k−1}] v: both pieces share Φ and C, so
        // each is the full block with its own Γ (a piece's ZOH over part of the period,
        // propagated to the period's end)
        let a = Lti::<f64, 8>::from_tf(&rest, &den, f * ts, Discretization::Zoh)?;
        let b = Lti::<f64, 8>::from_tf(&rest, &den, (1.0 - f) * ts, Discretization::Zoh)?;
        let early = full.with_input(&b.propagate(&a.input_vector()))?;
        let late = full.with_input(&b.input_vector())?;
        Ok(DiscretePlant {
            late,
            early: Some(early),
            k,
            direct,
        })
    }

    /// `P_d(e^{jθ})`.
    pub fn response(&self, theta: f64) -> Complex<f64> {
        // two sines and cosines: z^{-1} and z^{-k}; the rest from them
        let w = Complex::cis(-theta);
        let z = w.conj();
        let dk = Complex::cis(-theta * self.k);
        let dk1 = dk.mul(w);
        let late = self.late.response_z(z).mul(dk);
        let d = dk1.scale(self.direct);
        let p = match &self.early {
            None => late,
            Some(e) => late.add(e.response_z(z).mul(dk1)),
        };
        p.add(d)
    }

    /// `P_d` as a rational function of `z^{−1}`:
    /// `late·z^{−k} + (early + direct)·z^{−k−1}`.
    pub fn transfer(&self) -> crate::lti::zdomain::Rational {
        use crate::lti::zdomain::{Point, Rational, Symbolic};
        let at = Symbolic;
        let late = at.lti(&self.late) * at.delay(self.k);
        let next = at.delay(self.k + 1.0);
        let early = match &self.early {
            None => Rational::constant(0.0),
            Some(e) => at.lti(e) * next.clone(),
        };
        late + early + Rational::constant(self.direct) * next
    }
}

/// The loop transfer at the plant input on a frequency grid.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LoopResponse {
    /// Frequencies (rad/s).
    pub w: Vec<f64>,
    /// `L(jω)`.
    pub l: Vec<Complex<f64>>,
}

impl LoopResponse {
    /// The unwrapped phase of `L` (degrees), as MATLAB's `bode` draws it:
    /// continuous in `ω`, starting in `(−360°, 0°]`. The plant's dead time
    /// `delay` (s) is taken out before unwrapping and its exact `−ωθ` put
    /// back, so the phase stays right where the delay turns by more than
    /// half a turn between two grid points; the rest is unwrapped by the
    /// smallest step between neighbours.
    pub fn phase_unwrapped(&self, delay: f64) -> Vec<f64> {
        let delay = if delay.is_finite() { delay } else { 0.0 };
        let mut out = Vec::with_capacity(self.l.len());
        let mut prev = f64::NAN;
        for (w, l) in self.w.iter().zip(&self.l) {
            let rest = l.mul(Complex::cis(w * delay));
            let mut p = rest.arg().to_degrees();
            if prev.is_nan() {
                while p > 0.0 {
                    p -= 360.0;
                }
                while p <= -360.0 {
                    p += 360.0;
                }
            } else if p.is_finite() {
                p += 360.0 * ((prev - p) / 360.0).round();
            }
            if p.is_finite() {
                prev = p;
            }
            out.push(p - (w * delay).to_degrees());
        }
        out
    }
}

/// Evaluates `L` at `w` (rad/s).
pub fn loop_at(
    controller: &dyn FrequencyResponse<f64>,
    process: &dyn Fn(f64) -> Complex<f64>,
    ts: f64,
    w: f64,
) -> Option<Complex<f64>> {
    let (_, cy) = controller.response(w * ts)?;
    Some(cy.mul(process(w)))
}

crate::params::figures! {
    /// Stability margins and sensitivity peaks (names as MATLAB's `margin` and python-control).
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub struct Margins {
        /// Gain margin (absolute ratio); infinite without a phase crossover.
        pub gm: f64,
        /// Gain margin in dB.
        pub gm_db: f64,
        /// Phase margin (degrees); infinite without a gain crossover.
        pub pm: f64,
        /// Phase-crossover frequency (rad/s).
        pub wcg: f64,
        /// Gain-crossover frequency (rad/s).
        pub wcp: f64,
        /// Delay margin (s): the extra dead time that makes the loop oscillate.
        pub dm: f64,
        /// Peak of the sensitivity `|1/(1 + L)|`.
        pub ms: f64,
        /// Peak of the complementary sensitivity `|L/(1 + L)|`.
        pub mt: f64,
        /// Lower gain limit (a loop that is only conditionally stable loses
        /// stability when its gain falls below this factor; 0 if none).
        pub gm_lower: f64,
    }
}

impl Margins {
    /// The figures of an unstable loop: every margin and peak NaN (`null` in
    /// JSON). A crossover margin is the distance to instability of a stable
    /// loop; of an unstable loop it measures nothing.
    pub fn unstable() -> Self {
        Margins {
            gm: f64::NAN,
            gm_db: f64::NAN,
            pm: f64::NAN,
            wcg: f64::NAN,
            wcp: f64::NAN,
            dm: f64::NAN,
            ms: f64::NAN,
            mt: f64::NAN,
            gm_lower: f64::NAN,
        }
    }
}

/// A log-spaced grid from the plant's slowest time scale to the Nyquist frequency.
pub fn grid(plant: &TransferFunction, ts: f64, points: usize) -> Vec<f64> {
    let scales = plant.time_scales().unwrap_or_default();
    let slow = scales.iter().copied().fold(ts, f64::max);
    let lo = 1e-3 / slow;
    let hi = 0.999 * core::f64::consts::PI / ts;
    let n = points.max(16);
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// The loop response on a grid.
pub fn loop_response(
    controller: &dyn FrequencyResponse<f64>,
    plant: &TransferFunction,
    ts: f64,
    view: View,
    w: &[f64],
) -> Result<LoopResponse, Error> {
    let process = process_response(plant, None, ts, view)?;
    let mut out = LoopResponse {
        w: Vec::with_capacity(w.len()),
        l: Vec::with_capacity(w.len()),
    };
    for &wi in w {
        let l = loop_at(controller, &process, ts, wi).ok_or(Error::Unsupported(
            "this controller has no frequency response",
        ))?;
        out.w.push(wi);
        out.l.push(l);
    }
    Ok(out)
}

/// The root of `f(w) = 0` between a sign change at `a < b`: regula falsi
/// on `ln w` with the Illinois modification (Dowell & Jarratt (1971); the
/// retained end's value is halved when it is kept twice, so both ends move
/// and the convergence is superlinear), to the relative precision of `f64` in `w` — a few
/// evaluations where bisection took 80, which matters for a long dead time,
/// whose loop crosses the negative real axis hundreds of times.
fn refine(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (mut xa, mut xb) = (a.ln(), b.ln());
    let (mut fa, mut fb) = (f(a), f(b));
    if !(fa.is_finite() && fb.is_finite()) || (fa > 0.0) == (fb > 0.0) {
        return (a * b).sqrt();
    }
    let mut side = 0i8;
    for _ in 0..100 {
        let x = (xa * fb - xb * fa) / (fb - fa);
        let x = if x > xa.min(xb) && x < xa.max(xb) {
            x
        } else {
            0.5 * (xa + xb)
        };
        if (xb - xa).abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0) {
            return x.exp();
        }
        let fx = f(x.exp());
        if fx == 0.0 || !fx.is_finite() {
            return x.exp();
        }
        if (fx > 0.0) == (fb > 0.0) {
            (xb, fb) = (x, fx);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            (xa, fa) = (x, fx);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    (0.5 * (xa + xb)).exp()
}

/// Margins of `controller` on `plant` at period `ts` (the nominal closed loop
/// is assumed stable; see the module documentation).
pub fn margins(
    controller: &dyn FrequencyResponse<f64>,
    plant: &TransferFunction,
    ts: f64,
    view: View,
) -> Result<Margins, Error> {
    margins_on(controller, plant, ts, view, 6000)
}

/// [`margins`] on a grid of `points` frequencies (the crossovers and peaks
/// are refined between grid points, so a coarser grid only risks missing a
/// crossing narrower than its spacing).
pub fn margins_on(
    controller: &dyn FrequencyResponse<f64>,
    plant: &TransferFunction,
    ts: f64,
    view: View,
    points: usize,
) -> Result<Margins, Error> {
    if controller.response(0.1).is_none() {
        return Err(Error::Unsupported(
            "this controller has no frequency response",
        ));
    }
    let process = process_response(plant, None, ts, view)?;
    let at =
        |wi: f64| loop_at(controller, &process, ts, wi).unwrap_or(Complex::new(f64::NAN, f64::NAN));
    Ok(margins_of(&at, &grid(plant, ts, points)))
}

/// Margins of the inner (delay-free model) loop of a multi-loop scheme, if it has one.
pub fn inner_margins(
    controller: &dyn FrequencyResponse<f64>,
    plant: &TransferFunction,
    ts: f64,
) -> Option<Margins> {
    controller.inner_response(0.1)?;
    let at = |wi: f64| {
        controller
            .inner_response(wi * ts)
            .unwrap_or(Complex::new(f64::NAN, f64::NAN))
    };
    Some(margins_of(&at, &grid(plant, ts, 6000)))
}

/// Margins of any loop function `at(ω)` on the grid `w`.
pub fn margins_of(at: &dyn Fn(f64) -> Complex<f64>, w: &[f64]) -> Margins {
    let l: Vec<Complex<f64>> = w.iter().map(|wi| at(*wi)).collect();
    let mut gm_hi = f64::INFINITY;
    let mut gm_lo = 0.0f64;
    let mut wcg = f64::NAN;
    let mut pm = f64::INFINITY;
    let mut wcp = f64::NAN;
    let mut dm = f64::INFINITY;
    let (mut ms, mut mt) = (0.0f64, 0.0f64);
    let (mut ms_at, mut mt_at) = (0usize, 0usize);
    let sens = |li: Complex<f64>| Complex::real(1.0).div(Complex::real(1.0).add(li)).abs();
    let comp = |li: Complex<f64>| li.div(Complex::real(1.0).add(li)).abs();
    for (i, li) in l.iter().enumerate() {
        if sens(*li) > ms {
            (ms, ms_at) = (sens(*li), i);
        }
        if comp(*li) > mt {
            (mt, mt_at) = (comp(*li), i);
        }
        let (Some(next), Some(&wa), Some(&wb)) = (l.get(i + 1), w.get(i), w.get(i + 1)) else {
            break;
        };
        // phase crossover: Im L changes sign with Re L < 0
        if (li.im > 0.0) != (next.im > 0.0) && (li.re < 0.0 || next.re < 0.0) {
            let wx = refine(&|x| at(x).im, wa, wb);
            let lx = at(wx);
            if lx.re < 0.0 {
                let k = 1.0 / lx.abs();
                if k > 1.0 && k < gm_hi {
                    gm_hi = k;
                    wcg = wx;
                }
                if k <= 1.0 {
                    gm_lo = gm_lo.max(k);
                }
            }
        }
        // gain crossover: |L| crosses 1
        if (li.abs() > 1.0) != (next.abs() > 1.0) {
            let wx = refine(&|x| at(x).abs() - 1.0, wa, wb);
            let lx = at(wx);
            let mut p = 180.0 + lx.arg().to_degrees();
            if p > 180.0 {
                p -= 360.0;
            }
            if p.abs() < pm.abs() {
                pm = p;
                wcp = wx;
            }
            // extra delay τ with arg(L e^{−jωτ}) = −180°: τ = (π + arg L)/ω (mod 2π/ω)
            let mut phase = core::f64::consts::PI + lx.arg();
            while phase < 0.0 {
                phase += 2.0 * core::f64::consts::PI;
            }
            dm = dm.min(phase / wx);
        }
    }
    // the peaks between the grid points on each side of the largest sample
    let ms = peak(&|x| sens(at(x)), w, ms_at).max(ms);
    let mt = peak(&|x| comp(at(x)), w, mt_at).max(mt);
    Margins {
        gm: gm_hi,
        gm_db: 20.0 * gm_hi.log10(),
        pm,
        wcg,
        wcp,
        dm,
        ms,
        mt,
        gm_lower: gm_lo,
    }
}

/// The maximum of `f` between the grid points either side of `w[i]` (the
/// largest sample), by golden-section search on `ln ω` to the relative
/// precision of `f64` (`f` is unimodal there when the grid resolves the peak).
fn peak(f: &dyn Fn(f64) -> f64, w: &[f64], i: usize) -> f64 {
    let lo = w.get(i.saturating_sub(1)).copied();
    let hi = w.get(i + 1).or(w.get(i)).copied();
    let (Some(lo), Some(hi)) = (lo, hi) else {
        return f64::NAN;
    };
    if !(lo > 0.0 && hi > lo) {
        return f64::NAN;
    }
    let g = |x: f64| f(x.exp());
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo.ln(), hi.ln());
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (g(c), g(d));
    for _ in 0..80 {
        if fc > fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - r * (b - a);
            fc = g(c);
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + r * (b - a);
            fd = g(d);
        }
        if b - a < 1e-14 * a.abs().max(1.0) {
            break;
        }
    }
    fc.max(fd)
}

/// The delay margin of the loop with its gain scaled by each factor in
/// `gains`: the combined gain-and-delay region that keeps the loop stable is
/// below this curve (Bag (2022) Eqs. 4.55–4.57 bound the same
/// region through the complementary sensitivity).
pub fn region(
    controller: &dyn FrequencyResponse<f64>,
    plant: &TransferFunction,
    ts: f64,
    view: View,
    gains: &[f64],
) -> Result<Vec<(f64, f64)>, Error> {
    let process = process_response(plant, None, ts, view)?;
    let w = grid(plant, ts, 6000);
    Ok(gains
        .iter()
        .map(|k| {
            let at = |wi: f64| {
                loop_at(controller, &process, ts, wi)
                    .unwrap_or(Complex::new(f64::NAN, f64::NAN))
                    .scale(*k)
            };
            (*k, margins_of(&at, &w).dm)
        })
        .collect())
}

/// The robust stability test for a multiplicative uncertainty `Δ(ω)`
/// (Bag (2022) Eq. 4.52, García et al. (2010) Eq. 17):
/// `max_ω |T(jω)·Δ(jω)| < 1`. Returns that peak (the loop is robustly stable
/// when it is below 1). For a gain error `δk` and a delay error `δθ` the
/// uncertainty is `Δ = (1 + δk)e^{−jω·δθ} − 1` (Eqs. 4.54–4.57).
pub fn robust_stability(
    controller: &dyn FrequencyResponse<f64>,
    plant: &TransferFunction,
    ts: f64,
    view: View,
    delta: &dyn Fn(f64) -> f64,
) -> Result<f64, Error> {
    let lr = loop_response(controller, plant, ts, view, &grid(plant, ts, 6000))?;
    Ok(lr
        .w
        .iter()
        .zip(&lr.l)
        .map(|(w, l)| l.div(Complex::real(1.0).add(*l)).abs() * delta(*w))
        .fold(0.0, f64::max))
}

/// `|Δ(jω)|` for a relative gain error and an absolute extra dead time (s).
pub fn gain_delay_uncertainty(gain: f64, delay: f64) -> impl Fn(f64) -> f64 {
    move |w| {
        Complex::cis(-w * delay)
            .scale(1.0 + gain)
            .sub(Complex::real(1.0))
            .abs()
    }
}
