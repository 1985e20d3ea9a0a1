//! msp's engine for the browser tuner (`scripts/web OUTDIR` builds the page).
//!
//! Four calls, each a JSON document in and out, each the library code the
//! command line runs, so the page's numbers are the CLI's:
//!
//! - [`plant`]: a plant expression read as `--plant` reads it (an error with
//!   its column), its kind and the schemes that control it;
//! - [`design`]: a scenario (pairs keyed by `msp run`'s long flags, see
//!   [`query`]) tuned, run and analysed: the `msp run --report` document,
//!   the `msp margins --json` document (margins, `Ms`, the loop's exact
//!   frequency response for Bode and Nyquist), the signals to draw and the
//!   `msp run` command that reproduces it;
//! - [`tradeoff`]: the scheme's `λ` swept as `msp tradeoff -c SCHEME` does;
//! - [`csv`]: the run's CSV, as `msp run -o` writes it.
//!
//! A failure is `{"ok": false, "key": …, "message": …, "column": …}`:
//! nothing the page sends makes the engine panic (which in WebAssembly
//! would stop the page; `Cargo.toml` denies the lints that catch one).

pub mod query;

use msp::study::Scenario;
use query::Problem;
use serde::Serialize;
use wasm_bindgen::prelude::wasm_bindgen;

/// Samples drawn of each signal at most: a run of 10 000 samples is drawn
/// through every `⌈n/1200⌉`-th (a plot of 600 pixels cannot show more).
pub const DRAWN: usize = 1200;

#[derive(Debug, Serialize)]
struct Failed<'a> {
    ok: bool,
    #[serde(flatten)]
    problem: &'a Problem,
}

fn answer<T: Serialize>(r: Result<T, Problem>) -> String {
    let text = match &r {
        Ok(v) => serde_json::to_string(v),
        Err(p) => serde_json::to_string(&Failed {
            ok: false,
            problem: p,
        }),
    };
    text.unwrap_or_else(|e| {
        format!(
            "{{\"ok\":false,\"key\":\"request\",\"message\":{:?}}}",
            e.to_string()
        )
    })
}

fn run_problem(e: msp::study::RunError) -> Problem {
    Problem::new("scenario", e.to_string())
}

/// A scheme that controls the plant.
#[derive(Debug, Serialize)]
pub struct SchemeInfo {
    /// Its name (`--controller`).
    pub name: &'static str,
    /// One line.
    pub summary: &'static str,
    /// The tuned parameters' names.
    pub params: &'static [&'static str],
}

/// What [`plant`] answers.
#[derive(Debug, Serialize)]
pub struct PlantInfo {
    /// Always `true`.
    pub ok: bool,
    /// The plant as msp writes it.
    pub plant: String,
    /// `stable`, `integrating` or `unstable`.
    pub kind: msp::poly::PlantKind,
    /// The scheme msp picks for it.
    pub default: &'static str,
    /// Every single-loop scheme for its kind.
    pub schemes: Vec<SchemeInfo>,
}

/// The plant `text` (`--plant`'s grammar): its kind and its schemes.
pub fn plant_info(text: &str) -> Result<PlantInfo, Problem> {
    let p = query::plant_of("plant", text)?;
    let kind = p.kind();
    let default = msp::registry::default_for(&p)
        .map_err(|e| Problem::new("plant", e.to_string()))?
        .name;
    let schemes = msp::registry::SCHEMES
        .iter()
        .filter(|s| !s.is_cascade() && s.plants.contains(&kind))
        .map(|s| SchemeInfo {
            name: s.name,
            summary: s.summary,
            params: s.params,
        })
        .collect();
    Ok(PlantInfo {
        ok: true,
        plant: p.to_string(),
        kind,
        default,
        schemes,
    })
}

/// [`plant_info`] as JSON.
#[wasm_bindgen]
pub fn plant(text: &str) -> String {
    answer(plant_info(text))
}

/// The signals drawn: every `stride`-th sample and the last.
#[derive(Debug, Serialize, Default)]
pub struct Signals {
    /// Time (s).
    pub t: Vec<f64>,
    /// Set point.
    pub r: Vec<f64>,
    /// Measured output.
    pub y: Vec<f64>,
    /// Control.
    pub u: Vec<f64>,
    /// Input load.
    pub d: Vec<f64>,
}

fn drawn(res: &msp::sim::SimResult) -> Signals {
    let n = res.t.len();
    let stride = n.div_ceil(DRAWN).max(1);
    let keep = |i: usize| i % stride == 0 || i + 1 == n;
    let pick = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .enumerate()
            .filter(|(i, _)| keep(*i))
            .map(|(_, x)| *x)
            .collect()
    };
    Signals {
        t: pick(&res.t),
        r: pick(&res.r),
        y: pick(&res.y),
        u: pick(&res.u),
        d: pick(&res.d),
    }
}

/// `L(jω)` of the tuned loop on a log grid to the Nyquist frequency.
#[derive(Debug, Serialize, Default)]
pub struct Response {
    /// Frequencies (rad/s).
    pub w: Vec<f64>,
    /// `|L|` in dB.
    pub magnitude_db: Vec<f64>,
    /// The phase of `L` (degrees), unwrapped with the exact `−ωθ` of the delay.
    pub phase: Vec<f64>,
    /// `Re L`.
    pub re: Vec<f64>,
    /// `Im L`.
    pub im: Vec<f64>,
}

/// Points of the drawn frequency response.
pub const FREQUENCIES: usize = 800;

/// The tuned loop's response: the run's own controller built again (not
/// tuned again: a target's `λ` is solved once), the same process view and
/// evaluation as `msp margins` ([`msp::analysis::loop_response`]), on
/// [`FREQUENCIES`] points.
fn response_of(sc: &Scenario, out: &msp::study::RunOutput) -> Result<Response, Problem> {
    let tuned = out
        .tuned()
        .map_err(|e| Problem::new("controller", e.to_string()))?;
    let built = sc
        .build_tuned(&tuned, &out.model, None)
        .map_err(run_problem)?;
    let w = msp::analysis::grid(&out.plant, built.ts, FREQUENCIES);
    let l = msp::analysis::loop_response(
        built.controller.as_ref(),
        &out.plant,
        built.ts,
        msp::analysis::View::Sampled,
        &w,
    )
    .map_err(|e| Problem::new("controller", e.to_string()))?;
    let phase = l.phase_unwrapped(out.plant.delay);
    Ok(Response {
        magnitude_db: l.l.iter().map(|c| 20.0 * c.abs().log10()).collect(),
        re: l.l.iter().map(|c| c.re).collect(),
        im: l.l.iter().map(|c| c.im).collect(),
        w: l.w,
        phase,
    })
}

/// What [`design`] answers.
#[derive(Debug, Serialize)]
pub struct Designed {
    /// Always `true`.
    pub ok: bool,
    /// `msp run --report`'s document.
    pub report: msp::study::Report,
    /// The loop's exact frequency response (sampled view, as `msp margins`
    /// draws it): Bode and Nyquist.
    pub response: Response,
    /// The run's signals, thinned to at most [`DRAWN`] samples.
    pub signals: Signals,
    /// `msp run` with the same scenario.
    pub command: String,
}

fn scenario_of(request: &str) -> Result<(Vec<(String, String)>, Scenario), Problem> {
    let pairs = query::pairs(request)?;
    let sc = query::scenario(&pairs)?;
    Ok((pairs, sc))
}

/// The scenario of `request` tuned, run and analysed; `advised`: the
/// robustness warning's better tuning searched for and priced as `msp run`
/// does ([`msp::study::Scenario::run`]), otherwise a draft
/// ([`msp::study::Scenario::run_draft`], while a slider moves).
pub fn design_of(request: &str, advised: bool) -> Result<Designed, Problem> {
    let (pairs, sc) = scenario_of(request)?;
    let out = if advised { sc.run() } else { sc.run_draft() }.map_err(run_problem)?;
    let response = response_of(&sc, &out)?;
    let signals = drawn(&out.result);
    let report = out.report();
    msp::study::recycle(out.result);
    Ok(Designed {
        ok: true,
        report,
        response,
        signals,
        command: query::command(&pairs),
    })
}

/// [`design_of`] as JSON, advised as `msp run` is.
#[wasm_bindgen]
pub fn design(request: &str) -> String {
    answer(design_of(request, true))
}

/// [`design_of`] as JSON, a draft (a slider moving).
#[wasm_bindgen]
pub fn draft(request: &str) -> String {
    answer(design_of(request, false))
}

/// What [`tradeoff`] answers.
#[derive(Debug, Serialize)]
pub struct Traded {
    /// Always `true`.
    pub ok: bool,
    /// `msp tradeoff`'s document.
    #[serde(flatten)]
    pub tradeoff: msp::study::Tradeoff,
}

/// The trade-off of the scenario's scheme (msp's choice for the plant where
/// it names none): `msp tradeoff -c SCHEME`'s document.
pub fn tradeoff_of(request: &str) -> Result<msp::study::Tradeoff, Problem> {
    let (_, sc) = scenario_of(request)?;
    let name = match &sc.controller {
        Some(c) => c.clone(),
        None => {
            let (_, model) = sc.plant_and_model().map_err(run_problem)?;
            msp::registry::default_for(&model)
                .map_err(|e| Problem::new("controller", e.to_string()))?
                .name
                .to_string()
        }
    };
    msp::study::tradeoff(&sc, &[name], &|_, _| {}).map_err(run_problem)
}

/// [`tradeoff_of`] as JSON.
#[wasm_bindgen]
pub fn tradeoff(request: &str) -> String {
    answer(tradeoff_of(request).map(|tradeoff| Traded { ok: true, tradeoff }))
}

/// The run's CSV, as `msp run -o FILE.csv` writes it.
pub fn csv_of(request: &str) -> Result<String, Problem> {
    let (_, sc) = scenario_of(request)?;
    let out = sc.run().map_err(run_problem)?;
    let mut bytes = Vec::new();
    out.result
        .write_csv(&mut bytes)
        .map_err(|e| Problem::new("csv", e.to_string()))?;
    String::from_utf8(bytes).map_err(|e| Problem::new("csv", e.to_string()))
}

/// [`csv_of`]: the CSV text, or a failure's JSON (which starts with `{`).
#[wasm_bindgen]
pub fn csv(request: &str) -> String {
    match csv_of(request) {
        Ok(text) => text,
        Err(p) => answer::<()>(Err(p)),
    }
}
