//! The JSON documents: the run report, margins, identification and autotuning.

use msp::study::RunOutput;
use serde_json::{json, Map, Value};

use super::num;

/// The `--report` document: the library's [`msp::study::Report`].
pub(crate) fn report_json(out: &RunOutput) -> Value {
    serde_json::to_value(out.report()).unwrap_or(Value::Null)
}

/// The `msp margins --json` document: the library's [`msp::study::MarginsReport`].
pub(crate) fn margins_json(an: &msp::analysis::Analysis) -> Value {
    serde_json::to_value(an.report()).unwrap_or(Value::Null)
}

/// The `msp autotune --report` document.
pub(crate) fn autotune_json(
    plant: &msp::poly::TransferFunction,
    out: &msp::ident::AutotuneOutput,
) -> Value {
    let mut j = report_json(&out.run);
    if let Value::Object(o) = &mut j {
        o.insert("identified".into(), json!(out.fit));
        if let Some(m) = plant.exact_model() {
            let mut t = Map::new();
            t.insert("model".into(), json!(m.kind()));
            let (ps, n) = m.params();
            for (k, v) in ps.iter().take(n) {
                t.insert((*k).into(), num(*v));
            }
            o.insert("true".into(), Value::Object(t));
        }
        o.insert("relay".into(), json!(out.relay_report()));
    }
    j
}
