//! What `msp margins` reports: a scenario's controller analysed on its
//! process ([`crate::analysis`]: margins, the stability region, the
//! robust-stability test) and the one serde type the front ends print.

use core::ops::{Add, Div, Mul, Sub};
use std::vec::Vec;

use super::{Perturbation, RunError, Scenario, Tuned};
use crate::analysis::{
    grid, inner_margins, loop_stability, margins_of, process_response, published_note, Analysis,
    LoopResponse, Margins, ProcessResponse, RegionPoint, Stability, View,
};
use crate::complex::Complex;
use crate::error::Error;
use crate::poly::TransferFunction;

/// What `msp margins --json` prints and Python's `margins` returns (beside
/// the loop response arrays): one serde type, the same keys in both.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MarginsReport {
    /// The process.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub process: super::ProcessReport,
    /// How the plant is seen: `sampled` (behind the hold), `discrete`, `continuous`.
    pub view: &'static str,
    /// The controller (`none`: the bare plant or a pure gain).
    pub controller: super::ControllerReport,
    /// The margins and peaks at the top level (MATLAB's and python-control's names).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub margins: Margins,
    /// The nominal loop's verdict (`None`: it could not be decided; `stability` says why).
    pub stable: Option<bool>,
    /// The verdict, what decided it, and the simulation's cross-check.
    pub stability: Stability,
    /// The margins of the inner (model) loop.
    pub inner: Option<Margins>,
    /// The gain/delay stability region.
    pub region: Vec<RegionPoint>,
    /// `max|T·Δ|` (Eq. 17) for the perturbation given.
    pub robust_peak: Option<f64>,
    /// `robust_peak < 1`.
    pub robustly_stable: Option<bool>,
    /// Where a publication prints other margins for this loop, and why
    /// they differ ([`published_note`]).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub published: Option<&'static str>,
    /// The loop response's frequencies (rad/s): what the Bode and Nyquist
    /// plots draw.
    pub w: Vec<f64>,
    /// `L(jω)` at `w`, as `[re, im]` pairs.
    pub l: Vec<[f64; 2]>,
    /// The phase of `L` (degrees) at `w`, unwrapped as MATLAB's `bode`
    /// draws it ([`LoopResponse::phase_unwrapped`]).
    pub phase_unwrapped: Vec<f64>,
}

impl Analysis {
    /// The report of this analysis.
    pub fn report(&self) -> MarginsReport {
        MarginsReport {
            process: super::ProcessReport::new(
                &self.plant,
                &self.model,
                self.inner_process.as_ref(),
                self.ts,
            ),
            view: self.view.name(),
            controller: super::ControllerReport::new(self.controller, self.params.clone()),
            margins: self.margins,
            stable: self.stable,
            stability: self.stability.clone(),
            inner: self.inner,
            region: self
                .region
                .iter()
                .map(|&(gain, dm)| RegionPoint { gain, dm })
                .collect(),
            robust_peak: self.robust_peak,
            robustly_stable: self.robust_peak.map(|p| p < 1.0),
            published: published_note(&self.plant, self.controller),
            w: self.response.w.clone(),
            l: self.response.l.iter().map(|c| [c.re, c.im]).collect(),
            phase_unwrapped: self.response.phase_unwrapped(self.plant.delay),
        }
    }
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
    sc: &Scenario,
    view: View,
    uncertainty: Option<Perturbation>,
) -> Result<Analysis, RunError> {
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
    sc: &Scenario,
    tuned: &Tuned,
    view: View,
    uncertainty: Option<Perturbation>,
) -> Result<Analysis, RunError> {
    analysis_of(sc, tuned, false, view, uncertainty)
}

/// The analysis of `tuned` (`bare`: the plant alone or a pure gain).
fn analysis_of(
    sc: &Scenario,
    tuned: &Tuned,
    bare: bool,
    view: View,
    uncertainty: Option<Perturbation>,
) -> Result<Analysis, RunError> {
    let (plant, model) = sc.plant_and_model()?;
    let inner = sc.inner_process()?;
    // a duration given is a duration, even where the analysis chooses its own
    if let Some(d) = sc.duration {
        crate::real::positive(d, "duration")?;
    }
    let built = sc.build_tuned(tuned, &model, inner.as_ref().map(|(_, m)| m))?;
    let ctrl = built.controller.as_ref();
    let ts = built.ts;
    if ctrl.response(0.1).is_none() {
        return Err(RunError::Invalid(Error::Unsupported(
            "this controller has no frequency response",
        )));
    }
    let cascade = ctrl.is_cascade();
    // the process as the controller's loop sees it, and its perturbed twin
    let imc = inner_imc(tuned, inner.as_ref(), cascade, ts)?;
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
    let inner_loop = match (p2, &imc, &inner) {
        (Some(p2), Some(q), Some((_, m2))) => Some((p2, q, m2)),
        _ => None,
    };
    // the continuous view of the plant alone or behind a gain: the
    // continuous loop's own equation; a sampled controller's loop is the
    // sampled one whatever the view
    let continuous = view == View::Continuous && bare && inner.is_none();
    let verdict = if continuous {
        let k = built.params.get("kp").unwrap_or(1.0);
        crate::analysis::continuous_verdict(&plant, k)
    } else {
        let mut v = loop_stability(ctrl, &shown, inner_loop, ts);
        if view == View::Continuous {
            v.reason.push_str(&std::format!(
                " (of the sampled loop at ts = {} s: the controller is sampled, whatever the view of the plant)",
                crate::poly::fmt_num(ts)
            ));
        } else if shown.is_biproper() {
            v.reason.push_str(
                " (the plant's direct feedthrough acts a sample late in the sampled loop, as the simulator applies it: the controller's computation takes its sample)",
            );
        }
        v
    };
    let m = margins_of(&loop_fn, &w);
    // the crossover margins are distances to instability from a stable loop:
    // of an unstable loop they are no margins at all
    let m = if verdict.stable == Some(false) {
        Margins::unstable()
    } else {
        m
    };
    let inner_m = if cascade {
        None
    } else {
        inner_margins(ctrl, &shown, ts)
    };
    let top = if m.gm.is_finite() { m.gm } else { 4.0 };
    let reg: Vec<(f64, f64)> = if verdict.stable == Some(false) {
        Vec::new()
    } else {
        (1..=12)
            .map(|i| 0.25 + (top - 0.25) * f64::from(i) / 12.0)
            .filter(|k| *k < top)
            .map(|k| {
                // a factor below the lower gain limit is unstable: no delay margin
                let dm = if k <= m.gm_lower {
                    f64::NAN
                } else {
                    margins_of(&|wi| loop_fn(wi).scale(k), &w).dm
                };
                (k, dm)
            })
            .collect()
    };
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
    // the plotted response: the log grid, and up to ten times the highest
    // crossover a point every 0.1/θ rad/s, so that the curve turns smoothly
    // with the dead time (at most 4000 more points)
    let mut wr = grid(&grid_plant, ts, 800);
    let wc = [m.wcg, m.wcp]
        .into_iter()
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold(f64::NAN, f64::max);
    let theta = plant.delay;
    if wc.is_finite() && theta > 0.0 {
        let top = (10.0 * wc).min(0.999 * core::f64::consts::PI / ts);
        let step = (0.1 / theta).max(top / 4000.0);
        let lo = wr.first().copied().unwrap_or(0.0);
        let mut x = step;
        while x < top {
            if x > lo {
                wr.push(x);
            }
            x += step;
        }
        wr.sort_by(f64::total_cmp);
        wr.dedup();
    }
    let response = LoopResponse {
        l: wr.iter().map(|wi| loop_fn(*wi)).collect(),
        w: wr,
    };
    // a step of the nominal loop, long enough to show a slow instability
    let mut probe = sc.clone();
    probe.ts = Some(ts);
    probe.duration = Some(super::choose_duration(&grid_plant, ts) * 3.0);
    probe.disturbance.clear();
    probe.noise = None;
    let stability = match probe.run_tuned(tuned, plant.clone(), model.clone(), inner.clone()) {
        // the simulator runs the sampled loop: of a continuous loop with a
        // direct feedthrough (which it applies a sample late) it says nothing
        Ok(_) if continuous && shown.is_biproper() => {
            let mut v = verdict;
            v.reason.push_str(
                "; not cross-checked by the simulation, which applies the direct feedthrough a sample late",
            );
            v
        }
        Ok(out) => verdict.with_simulation(super::stable(&out), out.duration),
        Err(e) => {
            let mut v = verdict;
            v.reason.push_str(&std::format!(
                "; the cross-checking simulation could not run: {e}"
            ));
            v
        }
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
        stable: stability.stable,
        stability,
        region: reg,
        robust_peak,
        response,
    })
}

/// The IMC loop a cascade scheme closes around the secondary process (as the
/// controller builds it), or `None` for a single loop.
fn inner_imc(
    tuned: &Tuned,
    inner: Option<&(TransferFunction, TransferFunction)>,
    cascade: bool,
    ts: f64,
) -> Result<Option<crate::dtc::cascade::Imc<f64, Vec<f64>>>, RunError> {
    Ok(match (inner, cascade) {
        (Some((_, m2)), true) => Some(crate::dtc::cascade::Imc::<f64, Vec<f64>>::design(
            m2,
            tuned
                .params
                .typed::<f64, crate::dtc::cascade::CascadePrimary>()?
                .lambda2,
            ts,
        )?),
        _ => None,
    })
}

/// The stability verdict ([`loop_stability`]) of the scenario's loop with
/// the controller `tuned` for `model` on `plant` (and a cascade's
/// secondary process and model), not yet cross-checked by a simulation.
pub fn tuned_stability(
    sc: &Scenario,
    tuned: &Tuned,
    plant: &TransferFunction,
    model: &TransferFunction,
    inner: Option<&(TransferFunction, TransferFunction)>,
) -> Stability {
    let run = || -> Result<Stability, RunError> {
        let built = sc.build_tuned(tuned, model, inner.map(|(_, m)| m))?;
        let ctrl = built.controller.as_ref();
        let cascade = ctrl.is_cascade();
        let imc = inner_imc(tuned, inner, cascade, built.ts)?;
        let (whole, parts) = match (inner, &imc) {
            (Some((p2, m2)), Some(q)) => (plant.clone(), Some((p2, q, m2))),
            (Some((p2, _)), None) => (plant.series(p2)?, None),
            (None, _) => (plant.clone(), None),
        };
        Ok(loop_stability(ctrl, &whole, parts, built.ts))
    };
    run().unwrap_or_else(|e| Stability::unknown(std::format!("{e}")))
}

/// The P-only "controller" of a bare loop: `kp` from `set` (default 1),
/// no integral, no derivative; no other key applies.
fn bare_gain(sc: &Scenario) -> Result<Tuned, RunError> {
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
    Ok(Tuned {
        scheme: crate::registry::find("pid")?,
        params: crate::registry::Params::of(&crate::tuning::PidGains {
            kp,
            ti: f64::INFINITY,
            td: 0.0,
        }),
        lambda_chosen: false,
        target: None,
    })
}
