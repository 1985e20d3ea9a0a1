//! What `msp margins` reports: the loop's margins on the scenario's plant,
//! its stability region and robust-stability test.

use core::ops::{Add, Div, Mul, Sub};
use std::string::String;
use std::vec::Vec;

use super::{grid, inner_margins, margins_of, DiscretePlant, LoopResponse, Margins, View};
use crate::complex::Complex;
use crate::poly::TransferFunction;
use crate::Error;

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
    /// The process.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub process: crate::study::ProcessReport,
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
            process: crate::study::ProcessReport::new(
                &self.plant,
                &self.model,
                self.inner_process.as_ref(),
                self.ts,
            ),
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
    let bare = matches!(sc.controller.as_deref().map(str::trim), None | Some("none"));
    if bare {
        return analysis_of(sc, &bare_gain(sc)?, true, view, uncertainty);
    }
    let (_, model) = sc.plant_and_model()?;
    let inner = sc.inner_process()?;
    let tuned = sc.tune_for(&model, inner.as_ref().map(|(_, m)| m))?;
    analysis_of(sc, &tuned, false, view, uncertainty)
}

/// [`analyze`] of a controller already tuned for the scenario's process
/// (as `msp tune --uncertainty` has it), not tuned again.
pub fn analyze_tuned(
    sc: &crate::study::Scenario,
    tuned: &crate::study::Tuned,
    view: View,
    uncertainty: Option<crate::study::Perturbation>,
) -> Result<Analysis, crate::study::RunError> {
    analysis_of(sc, tuned, false, view, uncertainty)
}

/// The analysis of `tuned` (`bare`: the plant alone or a pure gain).
fn analysis_of(
    sc: &crate::study::Scenario,
    tuned: &crate::study::Tuned,
    bare: bool,
    view: View,
    uncertainty: Option<crate::study::Perturbation>,
) -> Result<Analysis, crate::study::RunError> {
    let (plant, model) = sc.plant_and_model()?;
    let inner = sc.inner_process()?;
    let built = sc.build_tuned(tuned, &model, inner.as_ref().map(|(_, m)| m))?;
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
        match probe.run_tuned(tuned, plant.clone(), model.clone(), inner.clone()) {
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
