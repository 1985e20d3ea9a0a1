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
use std::string::String;
use std::vec::Vec;

use crate::complex::Complex;
use crate::poly::TransferFunction;
use crate::FrequencyResponse;
use crate::{Discretization, Error, Lti};

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
        let late = self.late.response(theta).mul(Complex::cis(-theta * self.k));
        let d = Complex::cis(-theta * (self.k + 1.0)).scale(self.direct);
        let p = match &self.early {
            None => late,
            Some(e) => late.add(e.response(theta).mul(Complex::cis(-theta * (self.k + 1.0)))),
        };
        p.add(d)
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

impl Margins {
    /// Every figure with its report name.
    pub fn fields(&self) -> [(&'static str, f64); 9] {
        [
            ("gm", self.gm),
            ("gm_db", self.gm_db),
            ("pm", self.pm),
            ("wcg", self.wcg),
            ("wcp", self.wcp),
            ("dm", self.dm),
            ("ms", self.ms),
            ("mt", self.mt),
            ("gm_lower", self.gm_lower),
        ]
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

/// Bisection of `f(w) = 0` between a sign change.
fn refine(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let mut fa = f(a);
    for _ in 0..80 {
        let m = (a * b).sqrt();
        let fm = f(m);
        if (fm > 0.0) == (fa > 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    (a * b).sqrt()
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
    /// Whether a simulation of the nominal loop comes to rest (bounded and
    /// settling, wherever it settles; [`crate::sweep::stable`]), or `None`
    /// when that simulation could not run ([`Analysis::probe_note`] says why).
    pub stable: Option<bool>,
    /// Why the stability probe could not run, when it could not.
    pub probe_note: Option<String>,
    /// `(gain factor, delay margin)` pairs: the combined gain/delay stability region.
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

/// What `msp margins --json` prints and Python's `margins` returns (beside
/// the loop response arrays): one serde type, the same keys in both.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MarginsReport {
    /// The plant.
    pub plant: String,
    /// The controller's model.
    pub model: String,
    /// A cascade's secondary process.
    pub inner_plant: Option<String>,
    /// The controller's model of the secondary process.
    pub inner_model: Option<String>,
    /// Sample period (s).
    pub ts: f64,
    /// How the plant is seen: `sampled` (behind the hold), `discrete`, `continuous`.
    pub view: &'static str,
    /// The controller (`none`: the bare plant or a pure gain).
    pub controller: crate::study::ControllerReport,
    /// The margins and peaks at the top level (MATLAB's and python-control's names).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub margins: Margins,
    /// The nominal loop's verdict (`None`: the probe could not run).
    pub stable: Option<bool>,
    /// Why the probe could not run.
    pub probe_note: Option<String>,
    /// The margins of the inner (model) loop.
    pub inner: Option<Margins>,
    /// The gain/delay stability region.
    pub region: Vec<RegionPoint>,
    /// `max|T·Δ|` (Eq. 17) for the perturbation given.
    pub robust_peak: Option<f64>,
    /// `robust_peak < 1`.
    pub robustly_stable: Option<bool>,
}

impl Analysis {
    /// The report of this analysis.
    pub fn report(&self) -> MarginsReport {
        MarginsReport {
            plant: self.plant.to_string(),
            model: self.model.to_string(),
            inner_plant: self.inner_process.as_ref().map(|(p, _)| p.to_string()),
            inner_model: self.inner_process.as_ref().map(|(_, m)| m.to_string()),
            ts: self.ts,
            view: self.view.name(),
            controller: crate::study::ControllerReport {
                name: self.controller,
                params: self.params.clone(),
            },
            margins: self.margins,
            stable: self.stable,
            probe_note: self.probe_note.clone(),
            inner: self.inner,
            region: self
                .region
                .iter()
                .map(|&(gain, dm)| RegionPoint { gain, dm })
                .collect(),
            robust_peak: self.robust_peak,
            robustly_stable: self.robust_peak.map(|p| p < 1.0),
        }
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

/// Margins, stability region and the robust-stability test of Eq. 17 of a
/// scenario's controller on its process. `uncertainty` perturbs the plant (and,
/// for a cascade process, the secondary through its `inner_*` fields): the
/// multiplicative uncertainty is exact, `Δ(ω) = P_perturbed(jω)/P(jω) − 1`
/// (for a gain error `δk` and a delay error `δθ` this is
/// `(1 + δk)e^{−jωθδθ} − 1`, Bag (2022) Eqs. 4.54–4.57), and
/// `robust_peak = max_ω |T(jω)·Δ(jω)|` over `ω ∈ (0, π/Ts)`.
///
/// Without a controller (`controller` absent or `"none"`) the loop is the bare
/// plant, `L = G` (MATLAB's `margin(G)`), or a pure gain `L = kp·G` with
/// `set = {kp: K}`; its nominal loop is the unity feedback around it.
pub fn analyze(
    sc: &crate::study::Scenario,
    view: View,
    uncertainty: Option<crate::study::Perturbation>,
) -> Result<Analysis, crate::study::RunError> {
    let (plant, model) = sc.plant_and_model()?;
    let inner = sc.inner_process()?;
    let bare = matches!(sc.controller.as_deref().map(str::trim), None | Some("none"));
    let tuned = if bare {
        bare_gain(sc)?
    } else {
        sc.tune_for(&model, inner.as_ref().map(|(_, m)| m))?
    };
    let built = sc.build_tuned(&tuned, &model, inner.as_ref().map(|(_, m)| m))?;
    let ctrl = built.controller.as_ref();
    let ts = built.ts;
    if ctrl.response(0.1).is_none() {
        return Err(crate::study::RunError::Invalid(Error::Unsupported(
            "this controller has no frequency response",
        )));
    }
    let cascade = ctrl.is_cascade();
    // the process as the controller's loop sees it, and its perturbed twin
    let imc = match (&inner, cascade) {
        (Some((_, m2)), true) => Some(crate::dtc::cascade::Imc::<f64, Vec<f64>>::design(
            m2,
            tuned
                .params
                .typed::<f64, crate::dtc::cascade::CascadePrimary>()?
                .lambda2,
            ts,
        )?),
        _ => None,
    };
    let whole =
        |p1: &TransferFunction, p2: Option<&TransferFunction>| -> Result<TransferFunction, Error> {
            match (p2, cascade) {
                (Some(p2), false) => p1.series(p2),
                _ => Ok(p1.clone()),
            }
        };
    let proc_of =
        |p1: &TransferFunction, p2: Option<&TransferFunction>| -> Result<ProcessResponse, Error> {
            let main = whole(p1, p2)?;
            let parts = match (p2, &imc, &inner) {
                (Some(p2), Some(q), Some((_, m2))) => Some((p2, q, m2)),
                _ => None,
            };
            process_response(&main, parts, ts, view)
        };
    let p2 = inner.as_ref().map(|(p, _)| p);
    let process = proc_of(&plant, p2)?;
    let shown = whole(&plant, p2)?;
    let grid_plant = match p2 {
        Some(p2) => plant.series(p2)?,
        None => plant.clone(),
    };
    let w = grid(&grid_plant, ts, 6000);
    let loop_fn = |wi: f64| -> Complex<f64> {
        match ctrl.response(wi * ts) {
            Some((_, cy)) => cy.mul(process(wi)),
            None => Complex::new(f64::NAN, f64::NAN),
        }
    };
    let m = margins_of(&loop_fn, &w);
    let inner_m = if cascade {
        None
    } else {
        inner_margins(ctrl, &shown, ts)
    };
    let top = if m.gm.is_finite() { m.gm } else { 4.0 };
    let reg: Vec<(f64, f64)> = (1..=12)
        .map(|i| 0.25 + (top - 0.25) * f64::from(i) / 12.0)
        .filter(|k| *k < top)
        .map(|k| (k, margins_of(&|wi| loop_fn(wi).scale(k), &w).dm))
        .collect();
    let robust_peak = match uncertainty {
        Some(u) => {
            let p1u = plant.perturbed(u.gain, u.delay, u.tau)?;
            let p2u = match p2 {
                Some(p2) => Some(p2.perturbed(u.inner_gain, u.inner_delay, u.inner_tau)?),
                None => None,
            };
            let perturbed = proc_of(&p1u, p2u.as_ref())?;
            Some(w.iter().fold(0.0f64, |acc, wi| {
                let l = loop_fn(*wi);
                let t = l.div(Complex::real(1.0).add(l));
                let delta = perturbed(*wi).div(process(*wi)).sub(Complex::real(1.0));
                acc.max(t.abs() * delta.abs())
            }))
        }
        None => None,
    };
    let wr = grid(&grid_plant, ts, 800);
    let response = LoopResponse {
        l: wr.iter().map(|wi| loop_fn(*wi)).collect(),
        w: wr,
    };
    // a step of the nominal loop, long enough to show a slow instability
    let mut probe = sc.clone();
    probe.ts = Some(ts);
    probe.duration = Some(crate::study::choose_duration(&grid_plant, ts) * 3.0);
    probe.disturbance.clear();
    probe.noise = None;
    let (stable, probe_note) =
        match probe.run_tuned(&tuned, plant.clone(), model.clone(), inner.clone()) {
            Ok(out) => (Some(crate::sweep::stable(&out)), None),
            Err(e) => (
                None,
                Some(std::format!("the probe simulation could not run: {e}")),
            ),
        };
    Ok(Analysis {
        plant,
        model,
        inner_process: inner,
        ts,
        controller: if bare { "none" } else { built.scheme },
        bare,
        view,
        params: built.params,
        margins: m,
        inner: inner_m,
        stable,
        probe_note,
        region: reg,
        robust_peak,
        response,
    })
}

/// The P-only "controller" of a bare loop: `kp` from `set` (default 1),
/// no integral, no derivative; no other key applies.
fn bare_gain(sc: &crate::study::Scenario) -> Result<crate::study::Tuned, crate::study::RunError> {
    let mut kp = 1.0;
    for (k, v) in &sc.set {
        match k.strip_prefix("none.").unwrap_or(k) {
            "kp" => kp = crate::real::finite(*v, "kp")?,
            other => {
                return Err(crate::registry::RegistryError::UnknownParam {
                    scheme: "none",
                    name: other.into(),
                    allowed: std::vec!["kp"],
                }
                .into())
            }
        }
    }
    Ok(crate::study::Tuned {
        scheme: crate::registry::find("pid")?,
        params: crate::registry::Params::of(&crate::tuning::PidGains {
            kp,
            ti: f64::INFINITY,
            td: 0.0,
        }),
        lambda_chosen: false,
    })
}

/// The open-loop step response of a plant, as MATLAB's `step` and
/// `stepinfo` (python-control's `step_response` and `step_info`) give it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OpenLoopStep {
    /// The plant.
    pub plant: String,
    /// Its kind: stable, integrating or unstable.
    pub plant_kind: String,
    /// Sample period of `t` (s).
    pub ts: f64,
    /// Simulated time (s).
    pub duration: f64,
    /// Which of `ts` and `duration` were chosen (not given).
    pub chosen: Vec<&'static str>,
    /// The final value, the static gain `G(0)` (`None` for a plant whose
    /// response does not settle: integrating or unstable).
    pub dc_gain: Option<f64>,
    /// Rise and settling times, overshoot, peak (NaN where the response
    /// does not settle).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub info: crate::metrics::StepInfo,
    /// Time (s).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub t: Vec<f64>,
    /// The output for a unit step at `t = 0`.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub y: Vec<f64>,
}

/// Samples in an open-loop step response with a chosen period.
const STEP_SAMPLES: f64 = 4000.0;
/// The most samples an open-loop step response may take.
const STEP_MAX_SAMPLES: f64 = 1e8;

/// The unit step response of `plant` with its exact dead time: the ZOH
/// equivalent at `ts` gives the continuous response at the sample instants
/// exactly (the input is constant between them; the dead time's fraction of
/// a sample by the modified z-transform), and the step information uses
/// MATLAB's `stepinfo` definitions with the static gain as the final value.
/// `duration` defaults to [`crate::study::choose_duration`] (ten dead times,
/// ten slowest time constants, ten times the sum of the lags; 10 s for a pure
/// integrator), `ts` to `duration/4000`.
pub fn step_response(
    plant: &TransferFunction,
    ts: Option<f64>,
    duration: Option<f64>,
) -> Result<OpenLoopStep, Error> {
    let duration_given = duration.is_some();
    let duration = match duration {
        Some(d) => crate::real::positive(d, "duration")?,
        None => {
            let d = crate::study::choose_duration(plant, 0.0);
            if d > 0.0 && d.is_finite() {
                d
            } else {
                10.0
            }
        }
    };
    let ts_given = ts.is_some();
    let ts = match ts {
        Some(ts) => crate::real::positive(ts, "ts")?,
        None => duration / STEP_SAMPLES,
    };
    let n = (duration / ts).round() + 1.0;
    if !(n <= STEP_MAX_SAMPLES) {
        return Err(Error::OutOfRange(
            "ts: more than 1e8 samples in the duration",
        ));
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // at most 1e8
    let n = n as usize;
    let y = crate::sim::open_loop(plant, ts, &std::vec![1.0; n])?;
    #[allow(clippy::cast_precision_loss)]
    let t: Vec<f64> = (0..n).map(|k| k as f64 * ts).collect();
    let kind = plant.kind();
    let dc_gain = (kind == crate::poly::PlantKind::Stable).then(|| plant.gain());
    let info = crate::metrics::step_info(&t, &y, 0.0, dc_gain.unwrap_or(f64::NAN), 0.0);
    Ok(OpenLoopStep {
        plant: plant.to_string(),
        plant_kind: kind.to_string(),
        ts,
        duration,
        chosen: [("ts", !ts_given), ("duration", !duration_given)]
            .into_iter()
            .filter_map(|(k, c)| c.then_some(k))
            .collect(),
        dc_gain,
        info,
        t,
        y,
    })
}
