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

/// Warnings about a run (an unstable loop).
pub fn warnings(out: &RunOutput) -> Vec<String> {
    out.result
        .diverged_at
        .map(|t| {
            format!(
                "the closed loop with {} is unstable: the output diverged at t = {} s; the data stop there",
                out.controller,
                fmt_num(t)
            )
        })
        .into_iter()
        .collect()
}

const ROWS: &[(&str, &str)] = &[
    ("Rise Time (s)", "rise_time"),
    ("Settling Time (s)", "settling_time"),
    ("Settling Min", "settling_min"),
    ("Settling Max", "settling_max"),
    ("Overshoot (%)", "overshoot"),
    ("Undershoot (%)", "undershoot"),
    ("Peak", "peak"),
    ("Peak Time (s)", "peak_time"),
    ("ISE", "ise"),
    ("IAE", "iae"),
    ("ITSE", "itse"),
    ("ITAE", "itae"),
    ("TV", "tv"),
];

fn metric(m: &Metrics, key: &str) -> f64 {
    m.fields()
        .iter()
        .find(|(k, _)| *k == key)
        .map_or(f64::NAN, |(_, v)| *v)
}

/// The thesis-style table: a row per figure, a column per controller.
pub fn compare_table(runs: &[RunOutput], p: msp::sim::Perturbation) -> String {
    let mut s = String::new();
    if let Some(first) = runs.first() {
        s.push_str(&format!(
            "plant {}  model {}  ts {} s",
            first.plant,
            first.model,
            fmt_num(first.ts)
        ));
        if p != msp::sim::Perturbation::default() {
            s.push_str(&format!(
                "  (perturbed: gain {:+}%, delay {:+}%, tau {:+}%)",
                fmt_sig(100.0 * p.gain),
                fmt_sig(100.0 * p.delay),
                fmt_sig(100.0 * p.tau)
            ));
        }
        s.push('\n');
    }
    let w = runs
        .iter()
        .map(|r| r.controller.len())
        .max()
        .unwrap_or(8)
        .max(10)
        + 2;
    let head = |s: &mut String, title: &str| {
        s.push_str(&format!("{title:<30}"));
        for r in runs {
            s.push_str(&format!("{:>w$}", r.controller));
        }
        s.push('\n');
    };
    head(&mut s, "e = r - y");
    for (label, key) in ROWS {
        s.push_str(&format!("{label:<30}"));
        for r in runs {
            s.push_str(&format!("{:>w$}", fmt_sig(metric(&r.metrics, key))));
        }
        s.push('\n');
    }
    head(&mut s, "e = r(t - θm) - y, t from θm");
    for (label, key) in ROWS
        .iter()
        .filter(|(_, k)| ["ise", "iae", "itse", "itae", "rise_time", "settling_time"].contains(k))
    {
        s.push_str(&format!("{label:<30}"));
        for r in runs {
            s.push_str(&format!(
                "{:>w$}",
                fmt_sig(metric(&r.metrics_delayed_reference, key))
            ));
        }
        s.push('\n');
    }
    for r in runs {
        for w in warnings(r) {
            s.push_str(&format!("warning: {w}\n"));
        }
    }
    s
}

/// One CSV for a comparison: `t,r`, then `NAME.y,NAME.u,NAME.SIGNAL…` per controller.
pub fn compare_csv(runs: &[&RunOutput]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::WriterBuilder::new()
        .flexible(false)
        .from_writer(Vec::new());
    let Some(first) = runs.first() else {
        return w.into_inner().map_err(|e| csv::Error::from(e.into_error()));
    };
    let mut header = vec!["t".to_string(), "r".to_string(), "d".to_string()];
    for r in runs {
        header.push(format!("{}.y", r.controller));
        header.push(format!("{}.u", r.controller));
        for (n, _) in &r.result.signals {
            header.push(format!("{}.{n}", r.controller));
        }
    }
    w.write_record(&header)?;
    let rows = runs.iter().map(|r| r.result.t.len()).max().unwrap_or(0);
    let get = |v: &Vec<f64>, i: usize| v.get(i).map_or(String::new(), |x| fmt_f(*x));
    for i in 0..rows {
        let mut row = vec![
            get(&first.result.t, i),
            get(&first.result.r, i),
            get(&first.result.d, i),
        ];
        for r in runs {
            row.push(get(&r.result.y, i));
            row.push(get(&r.result.u, i));
            for (_, v) in &r.result.signals {
                row.push(get(v, i));
            }
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// An SVG with r and every run's y on top and u below.
pub fn plot_svg(runs: &[&RunOutput]) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let Some(first) = runs.first() else {
        return Ok(String::new());
    };
    let palette = [
        BLUE,
        RED,
        GREEN,
        MAGENTA,
        CYAN,
        RGBColor(255, 140, 0),
        RGBColor(128, 0, 128),
        RGBColor(90, 90, 90),
    ];
    let color = |i: usize| palette.get(i % palette.len()).copied().unwrap_or(BLUE);
    let t_end = first.result.t.last().copied().unwrap_or(1.0).max(1e-9);
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
    // at most ~2000 points per series: the picture is the same, the file small
    let pts = |t: &Vec<f64>, v: &Vec<f64>| -> Vec<(f64, f64)> {
        let stride = (t.len() / 2000).max(1);
        t.iter()
            .copied()
            .zip(v.iter().copied())
            .step_by(stride)
            .chain(t.last().copied().zip(v.last().copied()))
            .collect()
    };
    let mut ys: Vec<&Vec<f64>> = runs.iter().map(|r| &r.result.y).collect();
    ys.push(&first.result.r);
    let us: Vec<&Vec<f64>> = runs.iter().map(|r| &r.result.u).collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, bottom) = root.split_vertically(360);
        let (ylo, yhi) = range(&ys);
        let title = if runs.len() == 1 {
            format!("{} — {}", first.controller, first.plant)
        } else {
            format!("{}", first.plant)
        };
        let mut c = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, ylo..yhi)?;
        c.configure_mesh().y_desc("r, y").draw()?;
        c.draw_series(LineSeries::new(
            pts(&first.result.t, &first.result.r),
            &BLACK,
        ))?
        .label("r")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        for (i, r) in runs.iter().enumerate() {
            let col = color(i);
            let label = if runs.len() == 1 {
                "y".to_string()
            } else {
                format!("y {}", r.controller)
            };
            c.draw_series(LineSeries::new(pts(&r.result.t, &r.result.y), &col))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col));
        }
        c.configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        let (ulo, uhi) = range(&us);
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, ulo..uhi)?;
        c2.configure_mesh().x_desc("t (s)").y_desc("u").draw()?;
        for (i, r) in runs.iter().enumerate() {
            let col = if runs.len() == 1 { RED } else { color(i) };
            c2.draw_series(LineSeries::new(pts(&r.result.t, &r.result.u), &col))?;
        }
        root.present()?;
    }
    Ok(svg)
}
