//! A matrix plant (`--plant "[g11, g12; g21, g22]"`) in `run`, `tune`,
//! `margins` and `compare`: the library's `MimoScenario`, `MimoReport` and
//! `MimoOutput`, printed and written.

use msp::poly::TransferMatrix;
use msp::study::mimo::{report, MimoOutput, MimoReport};
use msp::study::MimoScenario;

use crate::cli::{CompareArgs, MarginsArgs, RunArgs, ScenarioArgs, TuneArgs};
use crate::error::CliError;
use crate::export;

/// A scenario file's matrix scenario (`plant = "[…]"`; `None`: a single
/// loop's file, read by the single-loop path).
fn from_file(path: &std::path::Path) -> Result<Option<MimoScenario>, CliError> {
    let name = format!("scenario file {}", path.display());
    let text = crate::input::open(path, &name, crate::input::SCENARIO_CAP)?.text()?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let fail = |e: String| CliError::Input(format!("{name}: {e}"));
    let file: msp::study::MimoScenarioFile = if json {
        let v: serde_json::Value = serde_json::from_str(text).map_err(|e| fail(e.to_string()))?;
        if !v["plant"]
            .as_str()
            .is_some_and(|p| p.trim_start().starts_with('['))
        {
            return Ok(None);
        }
        serde_json::from_value(v).map_err(|e| fail(e.to_string()))?
    } else {
        let v: toml::Value = toml::from_str(text).map_err(|e| fail(e.to_string()))?;
        if !v
            .get("plant")
            .and_then(toml::Value::as_str)
            .is_some_and(|p| p.trim_start().starts_with('['))
        {
            return Ok(None);
        }
        v.try_into()
            .map_err(|e: toml::de::Error| fail(e.to_string()))?
    };
    MimoScenario::try_from(file).map(Some).map_err(fail)
}

/// The matrix plant of the command line: `--plant "[…]"`, or a scenario
/// file's (`None`: a single loop).
pub(crate) fn matrix_of(s: &ScenarioArgs) -> Result<Option<TransferMatrix>, CliError> {
    if let Some(crate::cli::PlantArg::Matrix(m)) = &s.plant {
        return Ok(Some(m.clone()));
    }
    match (&s.plant, &s.scenario) {
        (None, Some(path)) => Ok(from_file(path)?.map(|sc| sc.plant)),
        _ => Ok(None),
    }
}

/// The single-loop flags given (a matrix plant refuses them by name).
fn single_loop_flags(s: &ScenarioArgs) -> Vec<&'static str> {
    let d = &s.design;
    [
        ("--model", s.model.is_some()),
        ("--inner-plant", s.inner_plant.is_some()),
        ("--inner-model", s.inner_model.is_some()),
        ("--lambda", d.lambda.is_some()),
        ("--target", d.target.is_some()),
        ("--set", !d.set.is_empty()),
        ("--setpoint", !s.setpoint.is_empty()),
        ("--disturbance", !s.disturbance.is_empty()),
        ("--quantization", s.quantization.is_some()),
        ("--umin", s.umin.is_some()),
        ("--umax", s.umax.is_some()),
        ("--float32", s.float32),
        ("--event", !s.events.is_empty()),
        ("--setpoint-ramp", s.setpoint_ramp.is_some()),
        ("--adapt", s.adapt),
        ("--monitor", s.monitor),
        ("--substeps", s.substeps.is_some()),
        ("--max-memory", s.max_memory.is_some()),
        // a matrix plant's actuator always feeds the limited value back
        ("--reset-feedback", s.reset_feedback),
        ("--adapt-delay", s.adapt_delay.is_some()),
        ("--adapt-forgetting", s.adapt_forgetting.is_some()),
        ("--adapt-prefilter", s.adapt_prefilter.is_some()),
        ("--adapt-excitation", s.adapt_excitation.is_some()),
        ("--adapt-dead-zone", s.adapt_dead_zone.is_some()),
        ("--adapt-bound", s.adapt_bound.is_some()),
        ("--adapt-background", s.adapt_background),
        ("--alarm", s.alarm.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, given)| given.then_some(name))
    .collect()
}

/// The library's scenario from the command line.
fn scenario(
    m: &TransferMatrix,
    s: &ScenarioArgs,
    controller: Option<&str>,
) -> Result<MimoScenario, CliError> {
    let refused = single_loop_flags(s);
    if !refused.is_empty() {
        return Err(CliError::Input(format!(
            "a matrix plant does not take {} yet: its set points are --loop-setpoint LOOP:V@T, its loads --loop-disturbance LOOP:input|output:V@T, a disturbance through its own channels --disturbance-plant \"[d1; d2]\" with --disturbance-step V@T, a channel's dead-time change --channel-dead-time ROW,COL=SECONDS@T, an operator's --loop-event LOOP:T:manual=V|auto",
            refused.join(", ")
        )));
    }
    // the file's scenario, then the flags: a value given replaces the
    // file's, a list given adds to it
    let mut sc = match &s.scenario {
        Some(path) => from_file(path)?.ok_or_else(|| {
            CliError::Input(format!(
                "scenario file {}: its plant is a single loop's, and --plant a matrix",
                path.display()
            ))
        })?,
        None => MimoScenario {
            plant: m.clone(),
            controller: None,
            rule: None,
            ts: None,
            duration: None,
            setpoints: Vec::new(),
            events: msp::sim::MimoEvents::default(),
        },
    };
    let n = m.size();
    sc.plant = m.clone();
    // a file's set point for a loop the plant given by --plant lacks is an
    // error, not a step dropped
    if sc.setpoints.iter().skip(n).any(|s| !s.is_empty()) {
        return Err(CliError::Input(format!(
            "the scenario file sets a loop beyond the {n} of --plant"
        )));
    }
    sc.setpoints.resize(n, Vec::new());
    let mut setpoints = std::mem::take(&mut sc.setpoints);
    for (l, step) in &s.loop_setpoint {
        setpoints
            .get_mut(*l)
            .ok_or_else(|| {
                CliError::Input(format!(
                    "--loop-setpoint {}: the plant has {n} loops",
                    l + 1
                ))
            })?
            .push(*step);
    }
    let ev = &mut sc.events;
    match (&s.disturbance_plant, s.disturbance_step.is_empty()) {
        (Some(channels), _) => {
            ev.disturbance = Some(msp::sim::DisturbanceVector {
                channels: channels.0.clone(),
                steps: s.disturbance_step.clone(),
            });
        }
        (None, false) => match &mut ev.disturbance {
            Some(d) => d.steps.extend(s.disturbance_step.iter().copied()),
            None => {
                return Err(CliError::Input(
                    "--disturbance-step needs --disturbance-plant \"[d1; d2]\" (the disturbance's channel to each output)".into(),
                ))
            }
        },
        (None, true) => {}
    }
    ev.loads.extend(s.loop_disturbance.iter().copied());
    ev.dead_times.extend(s.channel_dead_time.iter().copied());
    ev.modes.extend(s.loop_event.iter().copied());
    if let Some(v) = s.noise {
        ev.noise = v;
    }
    if let Some(v) = s.seed {
        ev.seed = v;
    }
    if s.actuator.is_some() {
        ev.actuator = s.actuator;
    }
    sc.setpoints = setpoints;
    if controller.is_some() {
        sc.controller = controller.map(str::to_string);
    }
    if s.design.rule.is_some() {
        sc.rule.clone_from(&s.design.rule);
    }
    sc.ts = s.ts.or(sc.ts);
    sc.duration = s.duration.or(sc.duration);
    Ok(sc)
}

/// The report's lines: the interaction measures, the design, the verdict.
fn report_lines(r: &MimoReport, iae: Option<&[f64]>) -> Vec<String> {
    let n = r.design.loops.len();
    let mut out = vec![format!(
        "plant       {} ({n}x{n}), ts = {} s",
        r.plant,
        export::fmt_sig(r.design.ts)
    )];
    match &r.rga {
        Some(rga) => {
            for (i, row) in rga.iter().enumerate() {
                let cells: Vec<String> = row.iter().map(|x| export::fmt_sig(*x)).collect();
                let label = if i == 0 { "rga" } else { "" };
                out.push(format!("{label:<11} [{}]", cells.join(", ")));
            }
        }
        None => out
            .push("rga         none at steady state (an integrating channel): see rga(jω)".into()),
    }
    let l11: Vec<(f64, f64)> = r
        .rga_over_frequency
        .iter()
        .filter_map(|p| p.magnitude.first()?.first().map(|m| (p.w, *m)))
        .collect();
    if let (Some(first), Some(last)) = (l11.first(), l11.last()) {
        let least =
            l11.iter().copied().fold(
                (f64::NAN, f64::INFINITY),
                |a, b| if b.1 < a.1 { b } else { a },
            );
        out.push(format!(
            "rga(jω)     |λ11| {} at {} rad/s … {} at {} rad/s, least {} at {} rad/s",
            export::fmt_sig(first.1),
            export::fmt_sig(first.0),
            export::fmt_sig(last.1),
            export::fmt_sig(last.0),
            export::fmt_sig(least.1),
            export::fmt_sig(least.0)
        ));
    }
    out.push(match &r.pairing {
        Some(p) => {
            let pairs: Vec<String> = p
                .iter()
                .enumerate()
                .map(|(i, j)| format!("y{}-u{}", i + 1, j + 1))
                .collect();
            format!(
                "pairing     {} (positive relative gains nearest 1)",
                pairs.join(", ")
            )
        }
        None => "pairing     none with every relative gain positive".into(),
    });
    if let Some(ni) = r.niederlinski {
        out.push(format!(
            "niederlinski {}{}",
            export::fmt_sig(ni),
            if ni < 0.0 {
                " (negative: the diagonal loops with integral action are unstable for every tuning)"
            } else {
                ""
            }
        ));
    }
    let d = &r.design;
    let summary = msp::study::MIMO_SCHEMES
        .iter()
        .find(|x| x.name == d.scheme)
        .map_or("", |x| x.summary);
    out.push(format!(
        "controller  {}: {summary}; F = {}",
        d.scheme,
        export::fmt_sig(d.f)
    ));
    for (i, l) in d.loops.iter().enumerate() {
        let p: Vec<String> = l
            .iter()
            .map(|(k, v)| format!("{k} = {}", export::fmt_sig(v)))
            .collect();
        let rule = match d.rule {
            Some(msp::analysis::mimo::LoopRule::Simc) => "SIMC",
            _ => "Ziegler-Nichols",
        };
        let zn = r
            .alone
            .as_ref()
            .and_then(|z| z.get(i))
            .map_or(String::new(), |z| {
                format!(
                    "  ({rule} alone: kp = {}, ti = {})",
                    export::fmt_sig(z.kp),
                    export::fmt_sig(z.ti)
                )
            });
        let e = iae
            .and_then(|v| v.get(i))
            .map_or(String::new(), |v| format!("; IAE {}", export::fmt_sig(*v)));
        out.push(format!("  loop {}    {}{zn}{e}", i + 1, p.join(", ")));
    }
    for e in &d.decoupler {
        out.push(format!("  decoupler {}", e.describe()));
    }
    out.push(format!(
        "stability   {}: {}",
        r.stability.summary(),
        r.stability.reason
    ));
    if let Some(v) = &r.decoupler_stability {
        out.push(format!("decoupler   {}: {}", v.summary(), v.reason));
    }
    out.push(format!(
        "Lcm         {} dB (biggest log modulus of the sampled loop)",
        export::fmt_sig(r.lcm)
    ));
    out
}

/// `msp tune --plant "[…]"`: the interaction measures and the design of
/// `-c pi` (BLT, the default), `smith` or `decoupled`, with the verdict.
pub(crate) fn tune(m: &TransferMatrix, a: &TuneArgs) -> Result<(), CliError> {
    if a.inner_plant.is_some() || a.rules || a.uncertainty.is_some() {
        return Err(CliError::Input(
            "a matrix plant's tuning takes -c pi|smith|decoupled and --ts: drop --inner-plant, --rules and --uncertainty".into(),
        ));
    }
    print_report(
        m,
        a.controller.as_deref(),
        a.design.rule.as_deref(),
        a.ts,
        a.json,
    )
}

/// The report of `scheme` (`pi` when `None`) on `m`, as JSON or text.
fn print_report(
    m: &TransferMatrix,
    scheme: Option<&str>,
    rule: Option<&str>,
    ts: Option<f64>,
    json: bool,
) -> Result<(), CliError> {
    let r = report(m, scheme.unwrap_or("pi"), rule, ts)?;
    if json {
        return export::print_json(&r);
    }
    for line in report_lines(&r, None) {
        export::outln!("{line}")?;
    }
    Ok(())
}

/// `msp margins --plant "[…]"`: the same report (the sampled loop's
/// verdict and biggest log modulus are its margins).
pub(crate) fn margins(m: &TransferMatrix, a: &MarginsArgs) -> Result<(), CliError> {
    if a.plot.is_some()
        || a.nyquist.is_some()
        || a.uncertainty.is_some()
        || a.continuous
        || a.discrete
    {
        return Err(CliError::Input(
            "a matrix plant's margins are the sampled loop's verdict and biggest log modulus: drop --plot, --nyquist, --uncertainty, --continuous and --discrete".into(),
        ));
    }
    let sc = scenario(m, &a.scenario, a.controller.as_deref())?;
    print_report(
        m,
        sc.controller.as_deref(),
        sc.rule.as_deref(),
        sc.ts,
        a.json,
    )
}

/// The CSV of runs: `t`, then per run and loop `r, y, u` (prefixed by
/// the scheme's name when there are several runs).
fn csv(outs: &[MimoOutput]) -> String {
    let Some(first) = outs.first() else {
        return String::new();
    };
    let n = first.run.y.len();
    let mut text = String::from("t");
    for o in outs {
        let prefix = if outs.len() > 1 {
            format!("{}.", o.report.design.scheme)
        } else {
            String::new()
        };
        for i in 1..=n {
            text.push_str(&format!(",{prefix}r{i},{prefix}y{i},{prefix}u{i}"));
        }
    }
    text.push('\n');
    for (k, t) in first.run.t.iter().enumerate() {
        text.push_str(&export::fmt_f(*t));
        for o in outs {
            let r = &o.run;
            for i in 0..n {
                for col in [&r.r, &r.y, &r.u] {
                    let v = col
                        .get(i)
                        .and_then(|c| c.get(k))
                        .copied()
                        .unwrap_or(f64::NAN);
                    text.push(',');
                    text.push_str(&export::fmt_f(v));
                }
            }
        }
        text.push('\n');
    }
    text
}

fn interaction_lines(o: &MimoOutput) -> Vec<String> {
    o.interaction
        .iter()
        .map(|x| {
            let dev: Vec<String> = x.deviation.iter().map(|d| export::fmt_sig(*d)).collect();
            format!(
                "step        loop {} at {} s: largest deviation of each output {}",
                x.step_loop + 1,
                export::fmt_sig(x.at),
                dev.join(", ")
            )
        })
        .collect()
}

/// `msp run --plant "[…]"`: CSV columns `t, r1, y1, u1, r2, y2, u2, …`,
/// the report the library's `MimoOutput`, the plot a panel per output and
/// per input.
pub(crate) fn run(m: &TransferMatrix, a: &RunArgs) -> Result<(), CliError> {
    if a.input.is_some() {
        return Err(CliError::Input(
            "a matrix plant's run takes no --input yet".into(),
        ));
    }
    let sc = scenario(m, &a.scenario, a.controller.as_deref())?;
    let mut files = super::plan(&a.files, &[("--scenario", a.scenario.scenario.as_ref())])?;
    let out = export::busy("simulating", a.quiet, || sc.run())?;
    if let Some(p) = &a.files.report {
        let text = serde_json::to_vec_pretty(&out).map_err(|e| CliError::Runtime(e.to_string()))?;
        files.add(p, text);
    }
    if let Some(p) = &a.files.plot {
        let svg = export::svg::mimo_svg(std::slice::from_ref(&out))
            .map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    use std::io::IsTerminal;
    let to_terminal = a.files.output.is_none() && std::io::stdout().is_terminal();
    if !to_terminal {
        let text = csv(std::slice::from_ref(&out));
        files.add_or_print(a.files.output.as_ref(), text.into_bytes())?;
    }
    files.commit()?;
    if !a.quiet || to_terminal {
        export::noteln!(
            "run         {} s, {} samples",
            export::fmt_sig(out.duration),
            out.run.t.len()
        );
        for line in report_lines(&out.report, Some(&out.iae)) {
            export::noteln!("{line}");
        }
        for (i, events) in out.events.iter().enumerate() {
            export::noteln!("events      loop {}", i + 1);
            for e in events {
                export::noteln!("{}", export::text::event_line(e).trim_end());
            }
        }
        for line in interaction_lines(&out) {
            export::noteln!("{line}");
        }
    }
    Ok(())
}

/// `msp compare --plant "[…]" -c pi,decoupled`: the schemes on the same
/// scenario, a row per scheme.
pub(crate) fn compare(m: &TransferMatrix, a: &CompareArgs) -> Result<(), CliError> {
    if a.perturb.is_some() {
        return Err(CliError::Input(
            "a matrix plant's compare takes no --perturb yet: give the plant itself (a channel's dead time can change with --channel-dead-time)".into(),
        ));
    }
    let mut files = super::plan(&a.files, &[("--scenario", a.scenario.scenario.as_ref())])?;
    let mut outs = Vec::new();
    for c in &a.controllers {
        let sc = scenario(m, &a.scenario, Some(c))?;
        outs.push(export::busy("simulating", false, || sc.run())?);
    }
    if let Some(p) = &a.files.output {
        files.add(p, csv(&outs).into_bytes());
    }
    if let Some(p) = &a.files.report {
        let text =
            serde_json::to_vec_pretty(&outs).map_err(|e| CliError::Runtime(e.to_string()))?;
        files.add(p, text);
    }
    if let Some(p) = &a.files.plot {
        let svg =
            export::svg::mimo_svg(&outs).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        files.add(p, svg.into_bytes());
    }
    files.commit()?;
    let n = m.size();
    let mut head = format!(
        "{:<10} {:>8} {:>9} {:>9}",
        "scheme", "F", "Lcm dB", "stable"
    );
    for i in 1..=n {
        head.push_str(&format!(" {:>10}", format!("IAE{i}")));
    }
    head.push_str(&format!(" {:>12}", "interaction"));
    export::outln!("{head}")?;
    for o in &outs {
        let r = &o.report;
        let mut row = format!(
            "{:<10} {:>8} {:>9} {:>9}",
            r.design.scheme,
            export::fmt_sig(r.design.f),
            export::fmt_sig(r.lcm),
            r.stability.summary()
        );
        for v in &o.iae {
            row.push_str(&format!(" {:>10}", export::fmt_sig(*v)));
        }
        // the largest deviation of an output whose own set point did not step
        let worst = o
            .interaction
            .iter()
            .flat_map(|x| {
                x.deviation
                    .iter()
                    .enumerate()
                    .filter(move |(i, _)| *i != x.step_loop)
                    .map(|(_, d)| *d)
            })
            .fold(0.0f64, f64::max);
        row.push_str(&format!(" {:>12}", export::fmt_sig(worst)));
        export::outln!("{row}")?;
    }
    Ok(())
}
