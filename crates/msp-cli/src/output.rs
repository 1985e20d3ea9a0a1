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
pub fn csv_bytes(out: &RunOutput) -> std::io::Result<Vec<u8>> {
    let mut v = Vec::with_capacity(out.result.t.len() * 64);
    out.result.write_csv(&mut v)?;
    Ok(v)
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
    let mut j = json!({
        "plant": out.plant.to_string(),
        "plant_kind": out.plant.kind().to_string(),
        "model": out.model.to_string(),
        "ts": out.ts,
        "duration": out.duration,
        "samples": out.result.t.len(),
        "controller": {"name": out.controller, "params": params},
        "float32": out.float32,
        "metrics": metrics_json(&out.metrics),
        "metrics_delayed_reference": metrics_json(&out.metrics_delayed_reference),
        "stable": out.result.diverged_at.is_none(),
        "warnings": warnings,
    });
    if let Some((p2, m2)) = &out.inner {
        j["inner_plant"] = json!(p2.to_string());
        j["inner_model"] = json!(m2.to_string());
    }
    j
}

/// `kp=0.0764 ti=40.2 …` for summaries.
pub fn params_line(p: &msp::registry::Params) -> String {
    p.0.iter()
        .map(|(k, v)| format!("{k}={}", fmt_sig(*v)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A relative change as a signed percentage: `+10`, `-5`, `0`.
fn pct(x: f64) -> String {
    let v = fmt_sig(100.0 * x);
    if x > 0.0 {
        format!("+{v}")
    } else {
        v
    }
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
    if let Some((p2, m2)) = &out.inner {
        s.push_str(&format!("inner plant {} ({})\n", p2, p2.kind()));
        if m2 != p2 {
            s.push_str(&format!("inner model {m2}\n"));
        }
    }
    s.push_str(&format!(
        "ts          {}{}\n",
        describe_ts(&out.whole_model(), out.ts),
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
    let params = params_line(&out.params);
    s.push_str(&format!("controller  {}: {}\n", out.controller, params));
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
        fmt_num(out.model_delay())
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
pub fn compare_table(
    runs: &[RunOutput],
    margins: &[Option<msp::analysis::Margins>],
    p: msp::sim::Perturbation,
) -> String {
    let mut s = String::new();
    if let Some(first) = runs.first() {
        s.push_str(&format!(
            "plant {}  model {}  ts {} s",
            first.plant,
            first.model,
            fmt_num(first.ts)
        ));
        if let Some((p2, m2)) = &first.inner {
            s.push_str(&format!("\ninner plant {p2}  inner model {m2}"));
        }
        if p != msp::sim::Perturbation::default() {
            s.push_str(&format!(
                "  (perturbed: gain {}%, delay {}%, tau {}%",
                pct(p.gain),
                pct(p.delay),
                pct(p.tau)
            ));
            if first.inner.is_some() {
                s.push_str(&format!(
                    "; inner gain {}%, delay {}%, tau {}%",
                    pct(p.inner_gain),
                    pct(p.inner_delay),
                    pct(p.inner_tau)
                ));
            }
            s.push(')');
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
    head(&mut s, "frequency domain (loop at the controller output)");
    type Figure = fn(&msp::analysis::Margins) -> f64;
    let freq: [(&str, Figure); 4] = [
        ("Gm (dB)", |m| m.gm_db),
        ("Pm (Degrees)", |m| m.pm),
        ("Wco (rad/s)", |m| m.wcg),
        ("Wpm (rad/s)", |m| m.wcp),
    ];
    for (label, f) in freq {
        s.push_str(&format!("{label:<30}"));
        for m in margins.iter().take(runs.len()) {
            s.push_str(&format!(
                "{:>w$}",
                m.as_ref().map_or("-".to_string(), |m| fmt_sig(f(m)))
            ));
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

/// The `msp margins --json` document: MATLAB/python-control key names at the top level.
pub fn margins_json(an: &msp::analysis::Analysis) -> Value {
    let mut o = Map::new();
    o.insert("plant".into(), json!(an.plant.to_string()));
    o.insert("model".into(), json!(an.model.to_string()));
    if let Some((p2, m2)) = &an.inner_process {
        o.insert("inner_plant".into(), json!(p2.to_string()));
        o.insert("inner_model".into(), json!(m2.to_string()));
    }
    o.insert("ts".into(), num(an.ts));
    let params: Map<String, Value> = an
        .params
        .0
        .iter()
        .map(|(k, v)| (k.to_string(), num(*v)))
        .collect();
    o.insert(
        "controller".into(),
        json!({"name": an.controller, "params": params}),
    );
    for (k, v) in an.margins.fields() {
        o.insert(k.into(), num(v));
    }
    o.insert("stable".into(), json!(an.stable));
    if let Some(inner) = &an.inner {
        let m: Map<String, Value> = inner
            .fields()
            .iter()
            .map(|(k, v)| (k.to_string(), num(*v)))
            .collect();
        o.insert("inner".into(), Value::Object(m));
    }
    o.insert(
        "region".into(),
        Value::Array(
            an.region
                .iter()
                .map(|(k, d)| json!({"gain": num(*k), "dm": num(*d)}))
                .collect(),
        ),
    );
    if let Some(p) = an.robust_peak {
        o.insert("robust_peak".into(), num(p));
        o.insert("robustly_stable".into(), json!(p < 1.0));
    }
    Value::Object(o)
}

/// The human `msp margins` report.
pub fn margins_text(an: &msp::analysis::Analysis) -> String {
    let m = &an.margins;
    let mut s = String::new();
    s.push_str(&format!("plant       {}\n", an.plant));
    if an.model != an.plant {
        s.push_str(&format!("model       {}\n", an.model));
    }
    let params = params_line(&an.params);
    s.push_str(&format!(
        "controller  {}: {}  (ts {} s)\n",
        an.controller,
        params,
        fmt_num(an.ts)
    ));
    s.push_str(&format!(
        "gain margin   gm = {} ({} dB) at wcg = {} rad/s\n",
        fmt_sig(m.gm),
        fmt_sig(m.gm_db),
        fmt_sig(m.wcg)
    ));
    s.push_str(&format!(
        "phase margin  pm = {} deg at wcp = {} rad/s\n",
        fmt_sig(m.pm),
        fmt_sig(m.wcp)
    ));
    s.push_str(&format!("delay margin  dm = {} s\n", fmt_sig(m.dm)));
    s.push_str(&format!(
        "peaks         ms = {}, mt = {}\n",
        fmt_sig(m.ms),
        fmt_sig(m.mt)
    ));
    if m.gm_lower > 0.0 {
        s.push_str(&format!("lower gain limit {}\n", fmt_sig(m.gm_lower)));
    }
    if let Some(i) = &an.inner {
        s.push_str(&format!(
            "inner loop    gm = {} pm = {} deg at {} rad/s\n",
            fmt_sig(i.gm),
            fmt_sig(i.pm),
            fmt_sig(i.wcp)
        ));
    }
    s.push_str(&format!(
        "nominal loop  {}\n",
        if an.stable {
            "stable (simulated)"
        } else {
            "NOT stable in simulation: the margins are not limits"
        }
    ));
    s.push_str("stability region: gain factor -> delay margin (s)\n");
    for (k, d) in &an.region {
        s.push_str(&format!("  {:>8} -> {}\n", fmt_sig(*k), fmt_sig(*d)));
    }
    if let Some(p) = an.robust_peak {
        s.push_str(&format!(
            "robust stability max|T·Δ| = {} ({})\n",
            fmt_sig(p),
            if p < 1.0 {
                "robustly stable"
            } else {
                "not guaranteed"
            }
        ));
    }
    s
}

/// Bode magnitude and phase and the Nyquist plot of the loop at the plant input.
pub fn bode_svg(an: &msp::analysis::Analysis) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let r = &an.response;
    let mag: Vec<(f64, f64)> =
        r.w.iter()
            .zip(&r.l)
            .map(|(w, l)| (*w, 20.0 * l.abs().log10()))
            .collect();
    // unwrapped phase along the grid
    let mut phase = Vec::with_capacity(r.l.len());
    let mut prev = 0.0f64;
    let mut offset = 0.0;
    for (i, (w, l)) in r.w.iter().zip(&r.l).enumerate() {
        let p = l.arg().to_degrees();
        if i > 0 {
            if p - prev > 180.0 {
                offset -= 360.0;
            } else if p - prev < -180.0 {
                offset += 360.0;
            }
        }
        prev = p;
        phase.push((*w, p + offset));
    }
    let finite = |v: &[(f64, f64)]| {
        v.iter()
            .map(|p| p.1)
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            })
    };
    let (w0, w1) = (
        r.w.first().copied().unwrap_or(1e-3),
        r.w.last().copied().unwrap_or(1.0),
    );
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 700)).into_drawing_area();
        root.fill(&WHITE)?;
        let (left, right) = root.split_horizontally(600);
        let (top, bottom) = left.split_vertically(350);
        let (mlo, mhi) = finite(&mag);
        let mut c = ChartBuilder::on(&top)
            .caption(
                format!(
                    "{} on {}: gm {} dB, pm {} deg",
                    an.controller,
                    an.plant,
                    fmt_sig(an.margins.gm_db),
                    fmt_sig(an.margins.pm)
                ),
                ("sans-serif", 15),
            )
            .margin(8)
            .x_label_area_size(25)
            .y_label_area_size(50)
            .build_cartesian_2d((w0..w1).log_scale(), (mlo.max(-120.0) - 5.0)..(mhi + 5.0))?;
        c.configure_mesh().y_desc("|L| (dB)").draw()?;
        c.draw_series(LineSeries::new(mag.iter().copied(), &BLUE))?;
        c.draw_series(LineSeries::new([(w0, 0.0), (w1, 0.0)], &BLACK.mix(0.4)))?;
        let (plo, phi) = finite(&phase);
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(
                (w0..w1).log_scale(),
                (plo.max(-3600.0) - 10.0)..(phi + 10.0),
            )?;
        c2.configure_mesh()
            .x_desc("ω (rad/s)")
            .y_desc("arg L (deg)")
            .draw()?;
        c2.draw_series(LineSeries::new(phase.iter().copied(), &RED))?;
        c2.draw_series(LineSeries::new(
            [(w0, -180.0), (w1, -180.0)],
            &BLACK.mix(0.4),
        ))?;
        let pts: Vec<(f64, f64)> =
            r.l.iter()
                .filter(|l| l.abs() < 10.0)
                .map(|l| (l.re, l.im))
                .collect();
        let mut c3 = ChartBuilder::on(&right)
            .caption("Nyquist (|L| < 10)", ("sans-serif", 15))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(-3.0..2.0, -3.0..2.0)?;
        c3.configure_mesh().x_desc("Re L").y_desc("Im L").draw()?;
        c3.draw_series(LineSeries::new(pts, &BLUE))?;
        c3.draw_series(std::iter::once(Circle::new((-1.0, 0.0), 4, RED.filled())))?;
        root.present()?;
    }
    Ok(svg)
}

const SWEEP_HEAD: &[&str] = &["index", "gain", "delay", "tau", "stable"];

/// One CSV row per run: the perturbation, the verdict, the metrics and the largest |u|.
pub fn sweep_csv(rows: &[msp::sweep::SweepRow]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::with_capacity(rows.len() * 200));
    let mut header: Vec<&str> = SWEEP_HEAD.to_vec();
    let names: Vec<&str> = rows
        .first()
        .map(|r| r.metrics.fields().iter().map(|(k, _)| *k).collect())
        .unwrap_or_default();
    header.extend(&names);
    header.push("max_abs_u");
    w.write_record(&header)?;
    for r in rows {
        let mut rec = vec![
            r.index.to_string(),
            fmt_f(r.gain),
            fmt_f(r.delay),
            fmt_f(r.tau),
            r.stable.to_string(),
        ];
        rec.extend(r.metrics.fields().iter().map(|(_, v)| fmt_f(*v)));
        rec.push(fmt_f(r.max_abs_u));
        w.write_record(&rec)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// The worst cases of a sweep.
pub fn sweep_summary(rows: &[msp::sweep::SweepRow]) -> String {
    let unstable = rows.iter().filter(|r| !r.stable).count();
    let mut s = format!("{} runs, {} unstable\n", rows.len(), unstable);
    let worst = |name: &str, key: fn(&msp::sweep::SweepRow) -> f64| -> String {
        match rows
            .iter()
            .filter(|r| key(r).is_finite())
            .max_by(|a, b| key(a).total_cmp(&key(b)))
        {
            Some(r) => format!(
                "worst {name:<14} {:>10}  at gain {}%, delay {}%, tau {}% (index {})\n",
                fmt_sig(key(r)),
                pct(r.gain),
                pct(r.delay),
                pct(r.tau),
                r.index
            ),
            None => String::new(),
        }
    };
    s.push_str(&worst("iae", |r| r.metrics.iae));
    s.push_str(&worst("overshoot (%)", |r| r.metrics.overshoot));
    s.push_str(&worst("settling (s)", |r| r.metrics.settling_time));
    s.push_str(&worst("max |u|", |r| r.max_abs_u));
    for r in rows.iter().filter(|r| !r.stable).take(5) {
        s.push_str(&format!(
            "unstable: gain {}%, delay {}%, tau {}%\n",
            pct(r.gain),
            pct(r.delay),
            pct(r.tau)
        ));
    }
    s
}

/// Concatenates shard CSVs (same header) and orders the rows by index.
pub fn merge_sweeps(paths: &[std::path::PathBuf]) -> Result<Vec<u8>, CliError> {
    let mut header: Option<csv::StringRecord> = None;
    let mut rows: Vec<(usize, csv::StringRecord)> = Vec::new();
    for p in paths {
        let mut r = csv::Reader::from_path(p)
            .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?;
        let h = r
            .headers()
            .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?
            .clone();
        match &header {
            None => header = Some(h),
            Some(first) if *first != h => {
                return Err(CliError::Input(format!(
                    "{}: its columns differ from the first file's",
                    p.display()
                )))
            }
            Some(_) => {}
        }
        for rec in r.records() {
            let rec = rec.map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?;
            let idx: usize = rec.get(0).and_then(|x| x.parse().ok()).ok_or_else(|| {
                CliError::Input(format!("{}: a row without an index", p.display()))
            })?;
            rows.push((idx, rec));
        }
    }
    rows.sort_by_key(|(i, _)| *i);
    let mut w = csv::Writer::from_writer(Vec::new());
    if let Some(h) = header {
        w.write_record(&h)
            .map_err(|e| CliError::Runtime(e.to_string()))?;
    }
    for (_, r) in rows {
        w.write_record(&r)
            .map_err(|e| CliError::Runtime(e.to_string()))?;
    }
    w.into_inner().map_err(|e| CliError::Runtime(e.to_string()))
}

/// `{"model": "fopdt", "k": …, "t": …, "l": …, "rmse": …, "r2": …}`.
pub fn fit_json(fit: &msp::ident::Fit) -> Value {
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
pub fn autotune_json(
    plant: &msp::poly::TransferFunction,
    out: &msp::ident::AutotuneOutput,
) -> Value {
    let r = &out.result;
    let (ku, tu) = r.ultimate();
    let mut j = report_json(&out.run, &warnings(&out.run));
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

/// The human autotune summary.
pub fn autotune_text(
    plant: &msp::poly::TransferFunction,
    out: &msp::ident::AutotuneOutput,
) -> String {
    let r = &out.result;
    let (ku, tu) = r.ultimate();
    let mut s = String::new();
    s.push_str(&format!("plant       {plant}\n"));
    s.push_str(&format!(
        "relay       h {} eps {} bias {}: period {} s (up {} s, down {} s), output {}..{}, {} cycles\n",
        fmt_sig(r.amplitude),
        fmt_sig(r.hysteresis),
        fmt_sig(r.bias),
        fmt_sig(r.period),
        fmt_sig(r.t_up),
        fmt_sig(r.t_down),
        fmt_sig(r.a_min),
        fmt_sig(r.a_max),
        r.cycles
    ));
    s.push_str(&format!(
        "            Ku {} Tu {} s (describing function)\n",
        fmt_sig(ku),
        fmt_sig(tu)
    ));
    s.push_str(&format!(
        "identified  {}  (rmse {}, r2 {})\n",
        msp::poly::TransferFunction::from_model(&out.fit.model),
        fmt_sig(out.fit.rmse),
        fmt_sig(out.fit.r2)
    ));
    let params = params_line(&out.run.params);
    s.push_str(&format!("controller  {}: {}\n", out.run.controller, params));
    let m = &out.run.metrics;
    s.push_str(&format!(
        "closed loop rise {} s, settling {} s, overshoot {} %, IAE {}\n",
        fmt_sig(m.rise_time),
        fmt_sig(m.settling_time),
        fmt_sig(m.overshoot),
        fmt_sig(m.iae)
    ));
    for w in warnings(&out.run) {
        s.push_str(&format!("warning: {w}\n"));
    }
    s
}
