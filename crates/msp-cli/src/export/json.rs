//! The JSON documents: the run report, margins, identification and autotuning.

use msp::study::RunOutput;
use serde_json::{json, Map, Value};

use super::num;

/// The `--report` document: the library's [`msp::study::Report`].
pub(crate) fn report_json(out: &RunOutput) -> Value {
    serde_json::to_value(out.report()).unwrap_or(Value::Null)
}

/// The `msp margins --json` document: the library's [`msp::analysis::MarginsReport`].
pub(crate) fn margins_json(an: &msp::analysis::Analysis) -> Value {
    serde_json::to_value(an.report()).unwrap_or(Value::Null)
}

/// `{"model": "fopdt", "k": …, "t": …, "l": …, "rmse": …, "r2": …}`.
pub(crate) fn fit_json(fit: &msp::ident::Fit) -> Value {
    let mut o = Map::new();
    o.insert("model".into(), json!(fit.model.kind()));
    let (ps, n) = fit.model.params();
    for (k, v) in ps.iter().take(n) {
        o.insert((*k).into(), num(*v));
    }
    o.insert("rmse".into(), num(fit.rmse));
    o.insert("r2".into(), num(fit.r2));
    Value::Object(o)
}

/// The `msp autotune --report` document.
pub(crate) fn autotune_json(
    plant: &msp::poly::TransferFunction,
    out: &msp::ident::AutotuneOutput,
) -> Value {
    let r = &out.result;
    let (ku, tu) = r.ultimate();
    let mut j = report_json(&out.run);
    if let Value::Object(o) = &mut j {
        o.insert("identified".into(), fit_json(&out.fit));
        if let Some(m) = plant.exact_model() {
            let mut t = Map::new();
            t.insert("model".into(), json!(m.kind()));
            let (ps, n) = m.params();
            for (k, v) in ps.iter().take(n) {
                t.insert((*k).into(), num(*v));
            }
            o.insert("true".into(), Value::Object(t));
        }
        o.insert(
            "relay".into(),
            json!({
                "amplitude": num(r.amplitude), "hysteresis": num(r.hysteresis), "bias": num(r.bias),
                "t_up": num(r.t_up), "t_down": num(r.t_down), "period": num(r.period),
                "a_max": num(r.a_max), "a_min": num(r.a_min), "gain": r.gain().map_or(Value::Null, num),
                "ku": num(ku), "tu": num(tu), "cycles": r.cycles,
            }),
        );
    }
    j
}
