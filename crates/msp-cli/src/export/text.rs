//! Text for people: run summaries, warnings and tables.

use msp::poly::fmt_num;
use msp::study::{describe_ts, Metrics, RunOutput};

use super::params_line;
use super::{fmt_sig, pct};

/// The human summary for standard error.
pub(crate) fn summary(out: &RunOutput, warnings: &[String]) -> String {
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
        describe_ts(&out.whole_model(), out.ts, out.float32),
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
    if out.default_scenario {
        let load = out.events.iter().find_map(|e| match e {
            msp::study::Event::Disturbance(d) => Some(d),
            msp::study::Event::Setpoint(_) => None,
        });
        if let Some(d) = load {
            s.push_str(&format!(
                "scenario    r = 1 at 0 s, input load {} at {} s  [the default; --setpoint, --disturbance, --duration to change]\n",
                fmt_sig(d.value),
                fmt_num(d.at)
            ));
        }
    }
    let params = params_line(&out.params);
    s.push_str(&format!(
        "controller  {}: {}{}\n",
        out.controller,
        params,
        if out.target.is_some() {
            "  [lambda solved for the target]"
        } else if out.lambda_chosen {
            "  [lambda chosen from the plant; --lambda to change]"
        } else {
            ""
        }
    ));
    if let Some(t) = msp::study::ControllerReport::new(out.controller, out.params.clone()).tuning {
        s.push_str(&tuning_line(&t));
    }
    if let Some(t) = &out.target {
        s.push_str(&target_line(t));
    }
    s.push_str(&design_block(&out.design));
    s.push_str(&format!(
        "stability   {}: {}\n",
        out.stability.summary(),
        out.stability.reason
    ));
    if out.stability.stable == Some(false) {
        s.push_str("robustness  none: the loop is unstable, margins do not apply\n");
    } else if let Some(r) = &out.robustness {
        s.push_str(&robustness_line(r));
    }
    let m = &out.metrics;
    let d = &out.metrics_delayed_reference;
    s.push_str(&format!(
        "step        rise {} s, settling {} s, overshoot {} %, peak {} at {} s\n",
        fmt_sig(m.step.rise_time),
        fmt_sig(m.step.settling_time),
        fmt_sig(m.step.overshoot),
        fmt_sig(m.step.peak),
        fmt_sig(m.step.peak_time)
    ));
    let ints = |i: &msp::metrics::Indices<f64>| {
        format!(
            "IAE {}  ISE {}  ITAE {}  ITSE {}",
            fmt_sig(i.iae),
            fmt_sig(i.ise),
            fmt_sig(i.itae),
            fmt_sig(i.itse)
        )
    };
    s.push_str(&format!(
        "indices     {}  TV {}\n",
        ints(&m.indices),
        fmt_sig(m.indices.tv)
    ));
    if out.events.len() > 1 {
        // the first events; the report has them all
        const SHOWN: usize = 12;
        for e in out.events.iter().take(SHOWN) {
            s.push_str(&event_line(e));
        }
        if out.events.len() > SHOWN {
            s.push_str(&format!(
                "  … {} more events in the report (--report)\n",
                out.events.len() - SHOWN
            ));
        }
    }
    s.push_str(&format!(
        "delayed ref {}  (e = r(t-θm) - y, t from θm = {} s)",
        ints(&d.indices),
        fmt_num(out.model_delay())
    ));
    for c in out.adaptation() {
        let what = match c.kind {
            msp::adapt::ChangeKind::Applied => "model",
            msp::adapt::ChangeKind::Restored => "model restored (the loop oscillated)",
            msp::adapt::ChangeKind::Refused => "model refused by the scheme, adaptation frozen",
            msp::adapt::ChangeKind::Alarm => {
                "ALARM: the model no longer matches; the process looks like"
            }
            msp::adapt::ChangeKind::Cleared => "alarm cleared: the model matches;",
            msp::adapt::ChangeKind::Emergency => {
                "EMERGENCY: the loop was going unstable (the primary detuned first where the scheme can be); the clear estimate applied:"
            }
            msp::adapt::ChangeKind::Detuned => {
                "EMERGENCY: the loop was going unstable; the primary's gain halved (first, and while no estimate is clear), model"
            }
            msp::adapt::ChangeKind::Edge => {
                "WARNING: not applied, the estimate is at the end of the dead-time range or beyond the gain's or lag's bound (--adapt-delay):"
            }
        };
        let error = c
            .mismatch
            .map(|e| format!(" (model error {} %)", fmt_sig(100.0 * e)))
            .unwrap_or_default();
        s.push_str(&format!(
            "\nadapt at {} s: {what} K = {}, tau = {} s, theta = {} s{error}",
            fmt_num(c.at),
            fmt_sig(c.k),
            fmt_sig(c.tau),
            fmt_sig(c.theta)
        ));
    }
    if let Some(e) = out.result.adaptive {
        // what the estimator learnt from: why nothing may have been applied
        let still = if e.learnt == 0 {
            " (nothing moved the loop enough to identify the process)"
        } else {
            ""
        };
        s.push_str(&format!(
            "\nestimator   learnt from {} samples{still}, {} load onsets, {} restarts, \
             {} responses compared in levels ({} taken as evidence, {} a ramp load's)",
            e.learnt, e.onsets, e.restarts, e.responses, e.responses_used, e.responses_ramps
        ));
    }
    for w in warnings {
        s.push_str(&format!("\nwarning: {w}"));
    }
    s
}

pub(crate) const ROWS: &[(&str, &str)] = &[
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

pub(crate) fn metric(m: &Metrics, key: &str) -> f64 {
    m.fields()
        .find(|(k, _)| *k == key)
        .map_or(f64::NAN, |(_, v)| v)
}

/// The thesis-style table: a row per figure, a column per controller.
pub(crate) fn compare_table(
    runs: &[RunOutput],
    margins: &[Option<msp::analysis::Margins>],
    p: msp::study::Perturbation,
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
        if p != msp::study::Perturbation::default() {
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
    s.push_str(&format!("{:<30}", "stable (characteristic eq.)"));
    for r in runs {
        s.push_str(&format!("{:>w$}", r.stability.summary()));
    }
    s.push('\n');
    for (label, key) in ROWS {
        s.push_str(&format!("{label:<30}"));
        for r in runs {
            s.push_str(&format!("{:>w$}", fmt_sig(metric(&r.metrics, key))));
        }
        s.push('\n');
    }
    head(&mut s, "frequency domain (loop at the controller output)");
    type Figure = fn(&msp::analysis::Margins) -> f64;
    let freq: [(&str, Figure); 5] = [
        ("Gm (dB)", |m| m.gm_db),
        ("Pm (Degrees)", |m| m.pm),
        ("Wco (rad/s)", |m| m.wcg),
        ("Wpm (rad/s)", |m| m.wcp),
        ("Ms", |m| m.ms),
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
        for w in r.warnings() {
            s.push_str(&format!("warning: {w}\n"));
        }
    }
    s
}

/// The human `msp margins` report.
pub(crate) fn margins_text(an: &msp::analysis::Analysis) -> String {
    let m = &an.margins;
    let mut s = String::new();
    s.push_str(&format!("plant       {}\n", an.plant));
    if an.model != an.plant {
        s.push_str(&format!("model       {}\n", an.model));
    }
    let view = match an.view {
        msp::analysis::View::Sampled => "the plant behind a hold",
        msp::analysis::View::Discrete => "the plant's exact discrete equivalent",
        msp::analysis::View::Continuous => "the continuous plant, no hold",
    };
    if an.bare {
        let kp = an.params.get("kp").unwrap_or(1.0);
        let gain = if kp == 1.0 {
            "L = G".to_string()
        } else {
            format!("L = {}·G", fmt_sig(kp))
        };
        s.push_str(&format!(
            "controller  none: {gain} (ts {} s; {view})\n",
            fmt_num(an.ts)
        ));
    } else {
        s.push_str(&format!(
            "controller  {}: {}  (ts {} s; {view})\n",
            an.controller,
            params_line(&an.params),
            fmt_num(an.ts)
        ));
    }
    s.push_str(&format!(
        "nominal loop  {}: {}\n",
        an.stability.summary(),
        an.stability.reason
    ));
    if an.stable == Some(false) {
        s.push_str("margins       none: the loop is unstable, margins do not apply\n");
    } else {
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
    }
    if let Some(note) = msp::analysis::published_note(&an.plant, an.controller) {
        s.push_str(&format!("note          {note}\n"));
    }
    if let Some(i) = &an.inner {
        s.push_str(&format!(
            "inner loop    gm = {} pm = {} deg at {} rad/s\n",
            fmt_sig(i.gm),
            fmt_sig(i.pm),
            fmt_sig(i.wcp)
        ));
    }
    if !an.region.is_empty() {
        s.push_str("stability region: gain factor -> delay margin (s)\n");
        for (k, d) in &an.region {
            if d.is_nan() {
                s.push_str(&format!("  {:>8} -> unstable\n", fmt_sig(*k)));
            } else {
                s.push_str(&format!("  {:>8} -> {}\n", fmt_sig(*k), fmt_sig(*d)));
            }
        }
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

/// The worst cases of a sweep.
pub(crate) fn sweep_summary(rows: &[msp::sweep::SweepRow]) -> String {
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
    s.push_str(&worst("iae", |r| r.metrics.indices.iae));
    s.push_str(&worst("overshoot (%)", |r| r.metrics.step.overshoot));
    s.push_str(&worst("settling (s)", |r| r.metrics.step.settling_time));
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

/// The human autotune summary.
pub(crate) fn autotune_text(
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
        fmt_sig(m.step.rise_time),
        fmt_sig(m.step.settling_time),
        fmt_sig(m.step.overshoot),
        fmt_sig(m.indices.iae)
    ));
    for w in out.run.warnings() {
        s.push_str(&format!("warning: {w}\n"));
    }
    s
}

/// One event of a run: a set-point step's step information, a disturbance's
/// rejection figures.
pub(crate) fn event_line(e: &msp::study::Event) -> String {
    match e {
        msp::study::Event::Setpoint(s) => format!(
            "  r -> {} at {} s: rise {} s, settling {} s, overshoot {} %, IAE {}\n",
            fmt_sig(s.value),
            fmt_num(s.at),
            fmt_sig(s.step.rise_time),
            fmt_sig(s.step.settling_time),
            fmt_sig(s.step.overshoot),
            fmt_sig(s.iae)
        ),
        msp::study::Event::Disturbance(d) => format!(
            "  {} {} at {} s: peak deviation {} at +{} s, recovered (2 %) after {} s, IAE {}\n",
            match d.location {
                msp::sim::Location::Input => "load",
                msp::sim::Location::Output => "output disturbance",
                msp::sim::Location::Inner => "inner disturbance",
            },
            fmt_sig(d.value),
            fmt_num(d.at),
            fmt_sig(d.peak_deviation),
            fmt_sig(d.peak_time),
            fmt_sig(d.recovery_time),
            fmt_sig(d.iae)
        ),
    }
}

/// The designed quantities, one per line under `design`: numbers, lists, and
/// filters as `num(z)/den(z)` coefficient lists.
pub(crate) fn design_block(d: &msp::registry::DesignReport) -> String {
    use msp::registry::DesignValue;
    if d.is_empty() {
        return String::new();
    }
    let list = |v: &[f64]| {
        format!(
            "[{}]",
            v.iter().map(|x| fmt_sig(*x)).collect::<Vec<_>>().join(", ")
        )
    };
    let mut s = String::from("design\n");
    for (k, v) in d {
        let text = match v {
            DesignValue::Scalar(x) => fmt_sig(*x),
            DesignValue::List(v) => list(v),
            DesignValue::StableRange { param, low, high } => format!(
                "{} < {param} < {} (the loop is stable for the model)",
                fmt_sig(*low),
                fmt_sig(*high)
            ),
            DesignValue::Filter { num, den } => {
                format!(
                    "num {} / den {} (powers of z, descending)",
                    list(num),
                    list(den)
                )
            }
        };
        s.push_str(&format!("  {k:<11} = {text}\n"));
    }
    s
}

/// `robustness gm 2.1 (6.4 dB), pm 33°, dm 1.2 s, Ms 2.5, Mt 1.9`.
pub(crate) fn robustness_line(m: &msp::analysis::Margins) -> String {
    format!(
        "robustness  gm {} ({} dB), pm {}°, dm {} s, Ms {}, Mt {}\n",
        fmt_sig(m.gm),
        fmt_sig(m.gm_db),
        fmt_sig(m.pm),
        fmt_sig(m.dm),
        fmt_sig(m.ms),
        fmt_sig(m.mt)
    )
}

/// The `msp step` summary: the plant, the final value and MATLAB's `stepinfo`.
pub(crate) fn step_text(s: &msp::analysis::OpenLoopStep) -> String {
    let chosen = |k: &str| {
        if s.chosen.contains(&k) {
            format!("  [chosen from the plant; --{k} to change]")
        } else {
            String::new()
        }
    };
    let mut out = format!("plant       {} ({})\n", s.plant, s.plant_kind);
    out.push_str(&format!(
        "ts          {} s{}\n",
        fmt_num(s.ts),
        chosen("ts")
    ));
    out.push_str(&format!(
        "duration    {} s{}\n",
        fmt_num(s.duration),
        chosen("duration")
    ));
    match s.dc_gain {
        Some(k) => out.push_str(&format!("final value {} (the static gain)\n", fmt_sig(k))),
        None => out.push_str(&format!(
            "final value none: the {} plant's response does not settle\n",
            s.plant_kind
        )),
    }
    let i = &s.info;
    out.push_str(&format!(
        "step        rise {} s, settling {} s, overshoot {} %, undershoot {} %, peak {} at {} s\n",
        fmt_sig(i.rise_time),
        fmt_sig(i.settling_time),
        fmt_sig(i.overshoot),
        fmt_sig(i.undershoot),
        fmt_sig(i.peak),
        fmt_sig(i.peak_time)
    ));
    for w in &s.warnings {
        out.push_str(&format!("warning: {w}\n"));
    }
    out
}

/// `tuning      rule zn (Ku 2.26, Tu 3.1 s); ISA form, N = 10, b = 1, c = 1`.
/// The design target and what the loop reaches: `target      ms=1.4: lambda = 6.1 gives ms = 1.4`.
pub(crate) fn target_line(t: &msp::study::TargetReport) -> String {
    let mut s = format!("target      {}: {}\n", t.target, t.outcome());
    if let Some(b) = &t.branch {
        s.push_str(&format!("            {b}\n"));
    }
    s
}

pub(crate) fn tuning_line(t: &msp::study::TuningReport) -> String {
    let ultimate = match (t.ku, t.tu) {
        (Some(ku), Some(tu)) => format!(" (Ku {}, Tu {} s)", fmt_sig(ku), fmt_sig(tu)),
        _ => String::new(),
    };
    format!(
        "tuning      rule {}{ultimate}; {} form, N = {}, b = {}, c = {}\n",
        t.rule,
        t.form.to_uppercase(),
        fmt_sig(t.n),
        fmt_sig(t.b),
        fmt_sig(t.c)
    )
}
