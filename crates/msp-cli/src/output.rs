//! Writers: CSV, the JSON report, the SVG plot, the human summary; all files atomically.

use std::io::Write;
use std::path::Path;

use msp::poly::fmt_num;
use msp::sim::{describe_ts, Metrics, RunOutput};
use serde_json::{json, Map, Value};

use crate::CliError;

/// Writes `bytes` to `path` through a temporary file in the same directory and
/// a rename, so a failure never leaves a truncated file behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let fail = |e: std::io::Error| {
        let _ = std::fs::remove_file(&tmp);
        CliError::Runtime(format!("cannot write {}: {e}", path.display()))
    };
    let mut f = std::fs::File::create(&tmp).map_err(fail)?;
    f.write_all(bytes).map_err(fail)?;
    f.sync_all().map_err(fail)?;
    drop(f);
    std::fs::rename(&tmp, path).map_err(fail)
}

/// The CSV: `t,r,y,u,d`, `d_out` when there is an output disturbance, then the
/// controller's internal signals.
pub fn csv_bytes(out: &RunOutput) -> Result<Vec<u8>, csv::Error> {
    let res = &out.result;
    let with_dout = res.d_out.iter().any(|v| *v != 0.0);
    let mut w = csv::WriterBuilder::new().from_writer(Vec::with_capacity(res.t.len() * 64));
    let mut header: Vec<&str> = vec!["t", "r", "y", "u", "d"];
    if with_dout {
        header.push("d_out");
    }
    header.extend(res.signals.iter().map(|(n, _)| n.as_str()));
    w.write_record(&header)?;
    for i in 0..res.t.len() {
        let mut row: Vec<String> = Vec::with_capacity(header.len());
        let get = |v: &Vec<f64>| v.get(i).copied().unwrap_or(f64::NAN);
        for v in [&res.t, &res.r, &res.y, &res.u, &res.d] {
            row.push(fmt_f(get(v)));
        }
        if with_dout {
            row.push(fmt_f(get(&res.d_out)));
        }
        for (_, v) in &res.signals {
            row.push(fmt_f(get(v)));
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// Shortest round-trip formatting of a float.
fn fmt_f(v: f64) -> String {
    format!("{v}")
}

/// A JSON number, or null for NaN/infinity.
pub fn num(v: f64) -> Value {
    serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
}

/// The metrics object; a figure that cannot be computed (NaN) becomes null.
fn metrics_json(m: &Metrics) -> Value {
    serde_json::to_value(m).unwrap_or(Value::Null)
}

/// The `--report` document.
pub fn report_json(out: &RunOutput, warnings: &[String]) -> Value {
    let params: Map<String, Value> = out
        .params
        .0
        .iter()
        .map(|(k, v)| (k.to_string(), num(*v)))
        .collect();
    json!({
        "plant": out.plant.to_string(),
        "plant_kind": out.plant.kind().to_string(),
        "model": out.model.to_string(),
        "ts": out.ts,
        "duration": out.duration,
        "samples": out.result.t.len(),
        "controller": {"name": out.controller, "params": params},
        "metrics": metrics_json(&out.metrics),
        "metrics_delayed_reference": metrics_json(&out.metrics_delayed_reference),
        "stable": out.result.diverged_at.is_none(),
        "warnings": warnings,
    })
}

/// Four significant digits.
pub fn fmt_sig(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let s = format!("{v:.4e}");
    let x: f64 = s.parse().unwrap_or(v);
    fmt_num(x)
}

/// The human summary for standard error.
pub fn summary(out: &RunOutput, warnings: &[String]) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "plant       {} ({})\n",
        out.plant,
        out.plant.kind()
    ));
    if out.model != out.plant {
        s.push_str(&format!("model       {}\n", out.model));
    }
    s.push_str(&format!(
        "ts          {}{}\n",
        describe_ts(&out.model, out.ts),
        if out.ts_chosen {
            "  [chosen from the plant; --ts to change]"
        } else {
            ""
        }
    ));
    s.push_str(&format!(
        "duration    {} s{}\n",
        fmt_num(out.duration),
        if out.duration_chosen {
            "  [chosen to cover settling; --duration to change]"
        } else {
            ""
        }
    ));
    let params: Vec<String> = out
        .params
        .0
        .iter()
        .map(|(k, v)| format!("{k}={}", fmt_sig(*v)))
        .collect();
    s.push_str(&format!(
        "controller  {}: {}\n",
        out.controller,
        params.join(" ")
    ));
    let m = &out.metrics;
    let d = &out.metrics_delayed_reference;
    s.push_str(&format!(
        "step        rise {} s, settling {} s, overshoot {} %, peak {} at {} s\n",
        fmt_sig(m.rise_time),
        fmt_sig(m.settling_time),
        fmt_sig(m.overshoot),
        fmt_sig(m.peak),
        fmt_sig(m.peak_time)
    ));
    s.push_str(&format!(
        "indices     IAE {}  ISE {}  ITAE {}  ITSE {}  TV {}\n",
        fmt_sig(m.iae),
        fmt_sig(m.ise),
        fmt_sig(m.itae),
        fmt_sig(m.itse),
        fmt_sig(m.tv)
    ));
    s.push_str(&format!(
        "delayed ref IAE {}  ISE {}  ITAE {}  ITSE {}  (e = r(t-θm) - y, t from θm = {} s)",
        fmt_sig(d.iae),
        fmt_sig(d.ise),
        fmt_sig(d.itae),
        fmt_sig(d.itse),
        fmt_num(out.model.delay)
    ));
    for w in warnings {
        s.push_str(&format!("\nwarning: {w}"));
    }
    s
}

/// An SVG with r and y on top and u below.
pub fn plot_svg(out: &RunOutput) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let res = &out.result;
    // at most ~2000 points per series: the picture is the same, the file small
    let stride = (res.t.len() / 2000).max(1);
    let pts = |v: &Vec<f64>| -> Vec<(f64, f64)> {
        res.t
            .iter()
            .copied()
            .zip(v.iter().copied())
            .step_by(stride)
            .chain(res.t.last().copied().zip(v.last().copied()))
            .collect()
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, bottom) = root.split_vertically(360);
        let t_end = res.t.last().copied().unwrap_or(1.0).max(1e-9);
        let range = |vs: &[&Vec<f64>]| {
            let (lo, hi) = vs
                .iter()
                .flat_map(|v| v.iter())
                .filter(|x| x.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(*x), b.max(*x))
                });
            if !lo.is_finite() {
                return (-1.0, 1.0);
            }
            let pad = ((hi - lo) * 0.08).max(1e-9);
            (lo - pad, hi + pad)
        };
        let (ylo, yhi) = range(&[&res.r, &res.y]);
        let mut c = ChartBuilder::on(&top)
            .caption(
                format!("{} — {}", out.controller, out.plant),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, ylo..yhi)?;
        c.configure_mesh().y_desc("r, y").draw()?;
        c.draw_series(LineSeries::new(pts(&res.r), &BLACK))?
            .label("r")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        c.draw_series(LineSeries::new(pts(&res.y), &BLUE))?
            .label("y")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        c.configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        let (ulo, uhi) = range(&[&res.u]);
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, ulo..uhi)?;
        c2.configure_mesh().x_desc("t (s)").y_desc("u").draw()?;
        c2.draw_series(LineSeries::new(pts(&res.u), &RED))?;
        root.present()?;
    }
    Ok(svg)
}
