//! `msp`: tune, simulate and compare dead-time compensators from the command line.

mod output;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use msp::parse::parse_plant;
use msp::registry;
use msp::sim::{Disturbance, Perturbation, RunError, Scenario, SetpointStep};

/// Dead-time compensation: Smith predictors and their modifications.
#[derive(Debug, Parser)]
#[command(name = "msp", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Tune a controller for a plant, simulate the closed loop, write CSV, report and plot.
    Run(Box<RunArgs>),
    /// Run several controllers on the same scenario and print the thesis-style table.
    Compare(Box<CompareArgs>),
    /// Print the tuned parameters of a controller for a plant.
    Tune(TuneArgs),
    /// Gain, phase and delay margins, sensitivity peaks and the stability region, with the exact delay.
    Margins(Box<MarginsArgs>),
    /// Many closed-loop runs over a range of plant perturbations, in parallel.
    Sweep(Box<SweepArgs>),
    /// Relay test on the plant, identify a model, tune a controller, run the closed loop.
    Autotune(Box<AutotuneArgs>),
    /// Identify a model from recorded step-test data (CSV with columns t, u, y).
    Identify(IdentifyArgs),
    /// List the controllers and the tuning rules.
    List,
}

/// How the controller is tuned (shared by every command that tunes one).
#[derive(Debug, Args)]
struct DesignArgs {
    /// Closed-loop time constant for tuning (s).
    #[arg(long)]
    lambda: Option<f64>,
    /// Tuning rule for `pid`: imc, simc, or an ultimate-cycle rule (zn, zn-pi, ...; see `msp list`).
    #[arg(long)]
    rule: Option<String>,
    /// Override a tuned parameter or design value by its report name, e.g. --set kp=0.05;
    /// SCHEME.KEY=VALUE applies to one scheme only (for compare).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_kv)]
    set: Vec<(String, f64)>,
}

/// Everything that describes a closed-loop scenario (shared by run and compare).
#[derive(Debug, Args)]
struct ScenarioArgs {
    /// Plant transfer function, e.g. "0.2/s*e^-7.4s".
    #[arg(long, short = 'p')]
    plant: Option<String>,
    /// Scenario file (TOML or JSON); flags given as well override its fields.
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// Model used by the controller (default: the plant itself).
    #[arg(long, short = 'm')]
    model: Option<String>,
    /// Cascade process: the secondary process, measured, feeding the plant (the primary),
    /// e.g. "2e^-2s/(20s+1)"; the default controller is then fspcc.
    #[arg(long)]
    inner_plant: Option<String>,
    /// The controller's model of the secondary process (default: the inner plant).
    #[arg(long)]
    inner_model: Option<String>,
    #[command(flatten)]
    design: DesignArgs,
    /// Sample period (s); chosen from the plant when absent.
    #[arg(long)]
    ts: Option<f64>,
    /// Duration (s); chosen from the plant when absent.
    #[arg(long)]
    duration: Option<f64>,
    /// Set-point step VALUE[@TIME] (repeatable); default 1@0.
    #[arg(long, value_name = "V[@T]", value_parser = str::parse::<SetpointStep>)]
    setpoint: Vec<SetpointStep>,
    /// Disturbance input|output|inner[:step|ramp|sine]:VALUE[@TIME][~FREQ_HZ] (repeatable);
    /// for a cascade process d2 = input, d1 = output, d0 = inner (at the secondary output).
    #[arg(long, value_name = "LOC:V@T", value_parser = str::parse::<Disturbance>, allow_hyphen_values = true)]
    disturbance: Vec<Disturbance>,
    /// Measurement-noise standard deviation.
    #[arg(long)]
    noise: Option<f64>,
    /// Noise seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Actuator lower limit.
    #[arg(long, allow_hyphen_values = true)]
    umin: Option<f64>,
    /// Actuator upper limit.
    #[arg(long, allow_hyphen_values = true)]
    umax: Option<f64>,
    /// Plant outputs per controller period in the CSV (smooth intersample plots).
    #[arg(long)]
    substeps: Option<usize>,
    /// The controller computes in f32 as firmware does (designed in f64; the
    /// plant stays exact in f64).
    #[arg(long)]
    float32: bool,
}

#[derive(Debug, Args)]
struct RunArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Controller name (see `msp list`); default by plant kind.
    #[arg(long, short = 'c')]
    controller: Option<String>,
    /// CSV output file (default: standard output).
    #[arg(long, short = 'o')]
    output: Option<PathBuf>,
    /// JSON report file.
    #[arg(long)]
    report: Option<PathBuf>,
    /// SVG plot of r, y and u.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// No summary on standard error.
    #[arg(long, short = 'q')]
    quiet: bool,
}

#[derive(Debug, Args)]
struct CompareArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Controllers to compare, comma separated (e.g. karan-dey,smith).
    #[arg(long, short = 'c', value_delimiter = ',', required = true)]
    controllers: Vec<String>,
    /// Perturbation of the plant, e.g. gain=+10%,delay=+10%,tau=-5% (inner_gain, inner_delay,
    /// inner_tau for the secondary of a cascade); the controllers keep the nominal model.
    #[arg(long, value_parser = str::parse::<Perturbation>, allow_hyphen_values = true)]
    perturb: Option<Perturbation>,
    /// CSV with a column group per controller.
    #[arg(long, short = 'o')]
    output: Option<PathBuf>,
    /// JSON report: one entry per controller.
    #[arg(long)]
    report: Option<PathBuf>,
    /// SVG plot of every controller's y and u.
    #[arg(long)]
    plot: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct MarginsArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Controller name (see `msp list`); default by plant kind.
    #[arg(long, short = 'c')]
    controller: Option<String>,
    /// Use the exact discrete equivalent of the plant instead of the continuous plant behind a hold.
    #[arg(long)]
    discrete: bool,
    /// Robust-stability test (Eq. 17, max|T·Δ| < 1) for a plant perturbation, e.g.
    /// gain=10%,delay=10%,tau=-20% (inner_gain, inner_delay, inner_tau for a cascade's secondary).
    #[arg(long, value_parser = str::parse::<Perturbation>, allow_hyphen_values = true)]
    uncertainty: Option<Perturbation>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// SVG with the Bode and Nyquist plots of the loop at the plant input.
    #[arg(long)]
    plot: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct SweepArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Controller name (see `msp list`); default by plant kind.
    #[arg(long, short = 'c')]
    controller: Option<String>,
    /// Relative gain range, e.g. -20%..+20%.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = str::parse::<msp::sweep::Range>)]
    gain: msp::sweep::Range,
    /// Relative dead-time range.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = str::parse::<msp::sweep::Range>)]
    delay: msp::sweep::Range,
    /// Relative time-constant range.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = str::parse::<msp::sweep::Range>)]
    tau: msp::sweep::Range,
    /// Points per swept axis.
    #[arg(long, default_value_t = 11, conflicts_with = "samples")]
    grid: usize,
    /// Random points instead of a grid.
    #[arg(long, default_value_t = 0)]
    samples: usize,
    /// Seed of the random points.
    #[arg(long = "sweep-seed", default_value_t = 1)]
    sweep_seed: u64,
    /// Run only shard I of N (runs whose index is I mod N), e.g. 0/4.
    #[arg(long, value_parser = parse_shard, default_value = "0/1")]
    shard: (usize, usize),
    /// Merge shard CSVs into one (no runs): msp sweep --merge a.csv b.csv -o all.csv.
    #[arg(long, num_args = 1.., conflicts_with = "plant")]
    merge: Vec<PathBuf>,
    /// CSV with one row per run (default: standard output).
    #[arg(long, short = 'o')]
    output: Option<PathBuf>,
    /// No progress bar and summary.
    #[arg(long, short = 'q')]
    quiet: bool,
}

fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("shard '{s}': expected I/N, e.g. 0/4"))?;
    let i: usize = i
        .trim()
        .parse()
        .map_err(|_| format!("shard '{s}': I is not a whole number"))?;
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| format!("shard '{s}': N is not a whole number"))?;
    if n == 0 || i >= n {
        return Err(format!("shard '{s}': need 0 <= I < N"));
    }
    Ok((i, n))
}

#[derive(Debug, Args)]
struct AutotuneArgs {
    /// The (simulated) plant the relay test runs on.
    #[arg(long, short = 'p')]
    plant: String,
    /// Relay amplitude h.
    #[arg(long, default_value_t = 1.0)]
    relay_amplitude: f64,
    /// Relay hysteresis (default: three noise standard deviations).
    #[arg(long)]
    hysteresis: Option<f64>,
    /// Relay bias for the static gain (default: 0 for integrating plants, 0.2 h otherwise).
    #[arg(long, allow_hyphen_values = true)]
    bias: Option<f64>,
    /// Measurement-noise standard deviation.
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Noise seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Model to identify: ipdt, fopdt or sopdt (default by plant kind).
    #[arg(long, value_parser = str::parse::<msp::ident::ModelKind>)]
    model: Option<msp::ident::ModelKind>,
    /// Controller to tune (default by the identified model).
    #[arg(long, short = 'c')]
    controller: Option<String>,
    /// Sample period (s).
    #[arg(long)]
    ts: Option<f64>,
    /// Safety band on the output during the relay test.
    #[arg(long, default_value_t = f64::INFINITY)]
    band: f64,
    /// Duration of the closed-loop run (s).
    #[arg(long)]
    duration: Option<f64>,
    /// CSV of the closed-loop run.
    #[arg(long, short = 'o')]
    output: Option<PathBuf>,
    /// JSON report.
    #[arg(long)]
    report: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct IdentifyArgs {
    /// CSV with columns t, u, y (a step in u).
    #[arg(long)]
    data: PathBuf,
    /// Model to fit.
    #[arg(long, default_value = "fopdt", value_parser = str::parse::<msp::ident::ModelKind>)]
    model: msp::ident::ModelKind,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Args)]
struct TuneArgs {
    /// Plant (or model) transfer function.
    #[arg(long, short = 'p')]
    plant: String,
    /// Cascade process: the secondary process (the default controller is then fspcc).
    #[arg(long)]
    inner_plant: Option<String>,
    /// Sample period (s) for the robust-stability test; chosen from the plant when absent.
    #[arg(long)]
    ts: Option<f64>,
    /// Also report the robust-stability test (Eq. 17, max|T·Δ| < 1) for this perturbation,
    /// e.g. delay=20%,tau=-20%.
    #[arg(long, value_parser = str::parse::<Perturbation>, allow_hyphen_values = true)]
    uncertainty: Option<Perturbation>,
    /// Controller name; default by plant kind.
    #[arg(long, short = 'c')]
    controller: Option<String>,
    #[command(flatten)]
    design: DesignArgs,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

fn parse_kv(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected KEY=VALUE, got '{s}'"))?;
    Ok((k.trim().to_string(), msp::sim::parse_number(v, k.trim())?))
}

/// A failure, with the exit status it maps to.
#[derive(Debug)]
pub enum CliError {
    /// Bad input: exit status 2.
    Input(String),
    /// Failure while running: exit status 1.
    Runtime(String),
}

impl From<RunError> for CliError {
    fn from(e: RunError) -> Self {
        CliError::Input(e.to_string())
    }
}

fn load_scenario(path: &Path) -> Result<Scenario, CliError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        CliError::Input(format!("cannot read scenario file {}: {e}", path.display()))
    })?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if is_json {
        serde_json::from_str(&text)
            .map_err(|e| CliError::Input(format!("scenario file {}: {e}", path.display())))
    } else {
        toml::from_str(&text)
            .map_err(|e| CliError::Input(format!("scenario file {}: {e}", path.display())))
    }
}

fn scenario_from(a: &ScenarioArgs) -> Result<Scenario, CliError> {
    let mut sc = match &a.scenario {
        Some(p) => load_scenario(p)?,
        None => Scenario::default(),
    };
    if let Some(p) = &a.plant {
        sc.plant.clone_from(p);
    }
    if sc.plant.trim().is_empty() && a.plant.is_none() && a.scenario.is_none() {
        return Err(CliError::Input(
            "give a plant: --plant \"0.2/s*e^-7.4s\" (or --scenario FILE)".into(),
        ));
    }
    macro_rules! over {
        ($($f:ident),*) => {$( if a.$f.is_some() { sc.$f = a.$f.clone(); } )*};
    }
    over!(
        model,
        inner_plant,
        inner_model,
        ts,
        duration,
        noise,
        seed,
        umin,
        umax,
        substeps
    );
    if a.design.lambda.is_some() {
        sc.lambda = a.design.lambda;
    }
    if a.design.rule.is_some() {
        sc.rule.clone_from(&a.design.rule);
    }
    for (k, v) in &a.design.set {
        sc.set.insert(k.clone(), *v);
    }
    if !a.setpoint.is_empty() {
        sc.setpoint.clone_from(&a.setpoint);
    }
    sc.disturbance.extend(a.disturbance.iter().copied());
    sc.float32 |= a.float32;
    Ok(sc)
}

fn write_or_print(path: Option<&PathBuf>, bytes: &[u8]) -> Result<(), CliError> {
    match path {
        Some(p) => output::write_atomic(p, bytes),
        None => {
            use std::io::Write;
            std::io::stdout()
                .write_all(bytes)
                .map_err(|e| CliError::Runtime(format!("writing to standard output: {e}")))
        }
    }
}

fn run(a: &RunArgs) -> Result<(), CliError> {
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    let out = sc.run()?;
    let warnings = output::warnings(&out);
    // everything is computed: now write, each file atomically
    let csv =
        output::csv_bytes(&out).map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
    write_or_print(a.output.as_ref(), &csv)?;
    if let Some(p) = &a.report {
        let text = serde_json::to_vec_pretty(&output::report_json(&out, &warnings))
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        output::write_atomic(p, &text)?;
    }
    if let Some(p) = &a.plot {
        let svg = output::plot_svg(&[&out]).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        output::write_atomic(p, svg.as_bytes())?;
    }
    if !a.quiet {
        eprintln!("{}", output::summary(&out, &warnings));
    }
    Ok(())
}

fn compare(a: &CompareArgs) -> Result<(), CliError> {
    let sc = scenario_from(&a.scenario)?;
    let runs = msp::sim::compare(&sc, &a.controllers, a.perturb.unwrap_or_default())?;
    let margins: Vec<Option<msp::analysis::Margins>> = a
        .controllers
        .iter()
        .map(|c| {
            let mut one = sc.clone();
            one.controller = Some(c.clone());
            one.ts = runs.first().map(|r| r.ts);
            if one.inner_plant.is_some() {
                // the cascade's loop is broken at the inner set point
                return msp::analysis::analyze(&one, msp::analysis::View::Discrete, None)
                    .ok()
                    .map(|an| an.margins);
            }
            let (_, model) = one.parse().ok()?;
            let plant = runs.first()?.plant.clone();
            let built = one.build_controller(&model).ok()?;
            msp::analysis::margins(
                built.controller.as_ref(),
                &plant,
                built.ts,
                msp::analysis::View::Sampled,
            )
            .ok()
        })
        .collect();
    let table = output::compare_table(&runs, &margins, a.perturb.unwrap_or_default());
    let refs: Vec<&msp::sim::RunOutput> = runs.iter().collect();
    if let Some(p) = &a.output {
        let csv = output::compare_csv(&refs)
            .map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
        output::write_atomic(p, &csv)?;
    }
    if let Some(p) = &a.report {
        let j: Vec<serde_json::Value> = runs
            .iter()
            .map(|r| output::report_json(r, &output::warnings(r)))
            .collect();
        let text = serde_json::to_vec_pretty(&j).map_err(|e| CliError::Runtime(e.to_string()))?;
        output::write_atomic(p, &text)?;
    }
    if let Some(p) = &a.plot {
        let svg = output::plot_svg(&refs).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        output::write_atomic(p, svg.as_bytes())?;
    }
    print!("{table}");
    Ok(())
}

fn margins(a: &MarginsArgs) -> Result<(), CliError> {
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    let view = if a.discrete {
        msp::analysis::View::Discrete
    } else {
        msp::analysis::View::Sampled
    };
    let an = msp::analysis::analyze(&sc, view, a.uncertainty)?;
    if let Some(p) = &a.plot {
        let svg = output::bode_svg(&an).map_err(|e| CliError::Runtime(format!("plot: {e}")))?;
        output::write_atomic(p, svg.as_bytes())?;
    }
    if a.json {
        let text = serde_json::to_string_pretty(&output::margins_json(&an))
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        println!("{text}");
    } else {
        print!("{}", output::margins_text(&an));
    }
    Ok(())
}

fn sweep(a: &SweepArgs) -> Result<(), CliError> {
    if !a.merge.is_empty() {
        let csv = output::merge_sweeps(&a.merge)?;
        return write_or_print(a.output.as_ref(), &csv);
    }
    let mut sc = scenario_from(&a.scenario)?;
    if a.controller.is_some() {
        sc.controller.clone_from(&a.controller);
    }
    let spec = msp::sweep::SweepSpec {
        gain: a.gain,
        delay: a.delay,
        tau: a.tau,
        grid: a.grid,
        samples: a.samples,
        seed: a.sweep_seed,
        shard: a.shard,
    };
    let total = msp::sweep::points(&spec).len();
    use std::io::IsTerminal;
    let bar = if !a.quiet && std::io::stderr().is_terminal() {
        indicatif::ProgressBar::new(total as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let rows = msp::sweep::sweep(&sc, &spec, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    let csv =
        output::sweep_csv(&rows).map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
    write_or_print(a.output.as_ref(), &csv)?;
    if !a.quiet {
        eprint!("{}", output::sweep_summary(&rows));
    }
    Ok(())
}

fn autotune(a: &AutotuneArgs) -> Result<(), CliError> {
    let plant = parse_plant(&a.plant)
        .map_err(|e| CliError::Input(format!("invalid plant expression: {e}")))?;
    let o = msp::ident::AutotuneOptions {
        amplitude: a.relay_amplitude,
        hysteresis: a.hysteresis,
        bias: a.bias,
        noise: a.noise,
        seed: a.seed,
        model: a.model,
        controller: a.controller.clone(),
        ts: a.ts,
        band: a.band,
    };
    let base = Scenario {
        duration: a.duration,
        ..Default::default()
    };
    let out = msp::ident::autotune(&plant, &o, &base).map_err(|e| match e {
        msp::ident::AutotuneError::Run(r) => CliError::from(r),
        msp::ident::AutotuneError::Ident(
            msp::Error::NotPositive(_)
            | msp::Error::Negative(_)
            | msp::Error::NonFinite(_)
            | msp::Error::OutOfRange(_),
        ) => CliError::Input(e.to_string()),
        other => CliError::Runtime(other.to_string()),
    })?;
    let report = output::autotune_json(&plant, &out);
    if let Some(p) = &a.output {
        let csv = output::csv_bytes(&out.run)
            .map_err(|e| CliError::Runtime(format!("writing CSV: {e}")))?;
        output::write_atomic(p, &csv)?;
    }
    if let Some(p) = &a.report {
        let text =
            serde_json::to_vec_pretty(&report).map_err(|e| CliError::Runtime(e.to_string()))?;
        output::write_atomic(p, &text)?;
    }
    print!("{}", output::autotune_text(&plant, &out));
    Ok(())
}

fn identify(a: &IdentifyArgs) -> Result<(), CliError> {
    let mut r = csv::Reader::from_path(&a.data)
        .map_err(|e| CliError::Input(format!("{}: {e}", a.data.display())))?;
    let head = r
        .headers()
        .map_err(|e| CliError::Input(format!("{}: {e}", a.data.display())))?
        .clone();
    let col = |name: &str| {
        head.iter().position(|h| h.trim() == name).ok_or_else(|| {
            CliError::Input(format!(
                "{}: no column '{name}' (need t, u, y)",
                a.data.display()
            ))
        })
    };
    let (ct, cu, cy) = (col("t")?, col("u")?, col("y")?);
    let (mut t, mut u, mut y) = (Vec::new(), Vec::new(), Vec::new());
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| CliError::Input(format!("{}: {e}", a.data.display())))?;
        let num = |c: usize| -> Result<f64, CliError> {
            rec.get(c)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    CliError::Input(format!(
                        "{}: row {}: not a finite number in column {}",
                        a.data.display(),
                        line + 2,
                        c + 1
                    ))
                })
        };
        t.push(num(ct)?);
        u.push(num(cu)?);
        y.push(num(cy)?);
    }
    let fit = msp::ident::identify_step(a.model, &t, &u, &y)
        .map_err(|e| CliError::Input(format!("identification failed: {e}")))?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&output::fit_json(&fit))
                .map_err(|e| CliError::Runtime(e.to_string()))?
        );
    } else {
        println!(
            "model  {}",
            msp::poly::TransferFunction::from_model(&fit.model)
        );
        let (ps, n) = fit.model.params();
        for (k, v) in ps.iter().take(n) {
            println!("  {k:<3} = {}", output::fmt_sig(*v));
        }
        println!(
            "fit    rmse {}  r2 {}",
            output::fmt_sig(fit.rmse),
            output::fmt_sig(fit.r2)
        );
    }
    Ok(())
}

fn tune(a: &TuneArgs) -> Result<(), CliError> {
    let sc = Scenario {
        plant: a.plant.clone(),
        inner_plant: a.inner_plant.clone(),
        controller: a.controller.clone(),
        lambda: a.design.lambda,
        rule: a.design.rule.clone(),
        set: a.design.set.iter().cloned().collect(),
        ts: a.ts,
        ..Scenario::default()
    };
    let (plant, model) = sc.parse()?;
    let inner = sc.parse_inner()?.map(|(p2, _)| p2);
    let (scheme, params) = sc.tune_for(&model, inner.as_ref())?;
    // Eq. 17 on the tuned controller, when asked for
    let robust = match a.uncertainty {
        Some(u) => msp::analysis::analyze(&sc, msp::analysis::View::Discrete, Some(u))?.robust_peak,
        None => None,
    };
    if a.json {
        let p: serde_json::Map<String, serde_json::Value> = params
            .0
            .iter()
            .map(|(k, v)| (k.to_string(), output::num(*v)))
            .collect();
        let mut j = serde_json::json!({"plant": plant.to_string(), "controller": {"name": scheme.name, "params": p}});
        if let Some(i) = &inner {
            j["inner_plant"] = serde_json::json!(i.to_string());
        }
        if let Some(r) = robust {
            j["robust_peak"] = output::num(r);
            j["robustly_stable"] = serde_json::json!(r < 1.0);
        }
        println!(
            "{}",
            serde_json::to_string_pretty(&j).map_err(|e| CliError::Runtime(e.to_string()))?
        );
    } else {
        println!("plant       {} ({})", plant, plant.kind());
        if let Some(i) = &inner {
            println!("inner plant {} ({})", i, i.kind());
        }
        println!("controller  {}  [{}]", scheme.name, scheme.source);
        for (k, v) in &params.0 {
            println!("  {k:<8} = {}", output::fmt_sig(*v));
        }
        if let Some(r) = robust {
            println!(
                "robust stability max|T·Δ| = {} ({})",
                output::fmt_sig(r),
                if r < 1.0 {
                    "robustly stable"
                } else {
                    "not guaranteed"
                }
            );
        }
    }
    Ok(())
}

fn list() {
    println!("controllers:");
    for s in registry::SCHEMES {
        let aliases = if s.aliases.is_empty() {
            String::new()
        } else {
            format!(" (alias {})", s.aliases.join(", "))
        };
        println!("  {:<22}{aliases}  {}", s.name, s.summary);
        println!(
            "  {:<22}  params: {}; source: {}",
            "",
            s.params.join(", "),
            s.source
        );
    }
    println!("tuning rules for `pid` (--rule): imc (IMC-PID, Eqs. 3.25-3.27), simc (Skogestad), and from Ku, Tu:");
    for r in msp::tuning::PI_RULES.iter().chain(msp::tuning::PID_RULES) {
        println!(
            "  {:<20} Kc = {} Ku, Ti = {} Tu, Td = {} Tu  ({})",
            r.name, r.a, r.b, r.c, r.note
        );
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let res = match &cli.cmd {
        Cmd::Run(a) => run(a),
        Cmd::Compare(a) => compare(a),
        Cmd::Tune(a) => tune(a),
        Cmd::Margins(a) => margins(a),
        Cmd::Sweep(a) => sweep(a),
        Cmd::Autotune(a) => autotune(a),
        Cmd::Identify(a) => identify(a),
        Cmd::List => {
            list();
            Ok(())
        }
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Input(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(CliError::Runtime(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;
    use msp::sim::{Location, Shape};

    #[test]
    fn cli_is_well_formed() {
        Cli::command().debug_assert();
    }

    #[test]
    fn disturbance_syntax() {
        let d = "input:0.1@20".parse::<Disturbance>().unwrap();
        assert_eq!(
            (d.location, d.shape, d.value, d.at),
            (Location::Input, Shape::Step, 0.1, 20.0)
        );
        let d = "output:sine:0.2@5~0.05".parse::<Disturbance>().unwrap();
        assert_eq!(
            (d.shape, d.value, d.at, d.freq),
            (Shape::Sine, 0.2, 5.0, 0.05)
        );
        let d = "input:-0.1@30".parse::<Disturbance>().unwrap();
        assert_eq!(d.value, -0.1);
        assert!("middle:1@2".parse::<Disturbance>().is_err());
    }

    #[test]
    fn perturbation_syntax() {
        let p = "gain=+10%,delay=-5%,tau=0.2"
            .parse::<Perturbation>()
            .unwrap();
        assert!((p.gain - 0.1).abs() < 1e-12 && (p.delay + 0.05).abs() < 1e-12 && p.tau == 0.2);
        assert!("mass=1".parse::<Perturbation>().is_err());
    }
}
