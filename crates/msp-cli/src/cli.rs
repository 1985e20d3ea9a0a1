//! The command line as clap types: every flag, its help text and its parser.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use msp::poly::{TransferFunction, TransferMatrix};
use msp::sim::{Disturbance, SetpointStep};
use msp::study::Perturbation;

/// Dead-time compensation: Smith predictors and their modifications.
#[derive(Debug, Parser)]
#[command(name = "msp", version, about, long_about = None)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) cmd: Cmd,
}

#[derive(Debug, Subcommand)]
pub(crate) enum Cmd {
    /// Tune a controller for a plant, simulate the closed loop, write CSV, report and plot.
    Run(Box<RunArgs>),
    /// Run several controllers on the same scenario and print the thesis-style table.
    Compare(Box<CompareArgs>),
    /// Print the tuned parameters of a controller for a plant.
    Tune(Box<TuneArgs>),
    /// Gain, phase and delay margins, sensitivity peaks and the stability region, with the exact delay.
    Margins(Box<MarginsArgs>),
    /// The plant's own step response (exact delay) and its step information, no controller.
    Step(Box<StepArgs>),
    /// Many closed-loop runs over a range of plant perturbations, in parallel.
    Sweep(Box<SweepArgs>),
    /// Relay test on the plant, identify a model, tune a controller, run the closed loop.
    Autotune(Box<AutotuneArgs>),
    /// Identify a model from recorded step-test data (CSV with columns t, u, y).
    Identify(Box<IdentifyArgs>),
    /// Step-response characteristics of recorded data (MATLAB's stepinfo): CSV with columns t, y.
    Stepinfo(Box<StepinfoArgs>),
    /// Robustness against performance for every scheme that applies to the plant, lambda swept.
    Tradeoff(Box<TradeoffArgs>),
    /// List the controllers and the tuning rules.
    List,
    /// Serve a folder over HTTP on the loopback address: the browser tuner that
    /// `bash scripts/web DIR` builds (a static file server, GET only).
    Serve(Box<ServeArgs>),
}

/// How the controller is tuned (shared by every command that tunes one).
#[derive(Debug, Args)]
pub(crate) struct DesignArgs {
    /// Closed-loop time constant for tuning (s).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) lambda: Option<f64>,
    /// Tuning rule for `pid`/`pi`: imc, simc, amigo, or an ultimate-cycle rule (zn, zn-pi, ...; see `msp list`; `msp tune --rules` compares them).
    #[arg(long)]
    pub(crate) rule: Option<String>,
    /// Design target the tuning's lambda is solved for on the exact analysis:
    /// ms=1.4, pm=60 (deg), gm=3 (or 9.5dB), dm=0.3θ (of the dead time; or dm=2 s), wc=0.2 (rad/s);
    /// or, for -c pi/pid, a crossover with a phase margin (pidtune's): wc=0.006,pm=60.
    #[arg(long, value_parser = str::parse::<msp::study::Target>)]
    pub(crate) target: Option<msp::study::Target>,
    /// Override a tuned parameter or design value by its report name, e.g. --set kp=0.05;
    /// SCHEME.KEY=VALUE applies to one scheme only (for compare).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = msp::syntax::parse_assignment)]
    pub(crate) set: Vec<(String, f64)>,
}

/// Everything that describes a closed-loop scenario (shared by run and compare).
#[derive(Debug, Args)]
pub(crate) struct ScenarioArgs {
    /// Plant transfer function, e.g. "0.2/s*e^-7.4s"; for msp run also a square matrix,
    /// "[g11, g12; g21, g22]": BLT-tuned decentralized PI loops on the diagonal.
    #[arg(long, short = 'p', allow_hyphen_values = true, value_parser = parse_plant_arg)]
    pub(crate) plant: Option<PlantArg>,
    /// Scenario file (TOML or JSON); flags given as well override its fields.
    #[arg(long)]
    pub(crate) scenario: Option<PathBuf>,
    /// Model used by the controller (default: the plant itself).
    #[arg(long, short = 'm', allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) model: Option<TransferFunction>,
    /// Cascade process: the secondary process, measured, feeding the plant (the primary),
    /// e.g. "2e^-2s/(20s+1)"; the default controller is then fspcc.
    #[arg(long, allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) inner_plant: Option<TransferFunction>,
    /// The controller's model of the secondary process (default: the inner plant).
    #[arg(long, allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) inner_model: Option<TransferFunction>,
    #[command(flatten)]
    pub(crate) design: DesignArgs,
    /// Sample period (s); chosen from the plant when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) ts: Option<f64>,
    /// Duration (s); chosen from the plant when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) duration: Option<f64>,
    /// Set-point step VALUE[@TIME] (repeatable); default 1@0.
    #[arg(long, value_name = "V[@T]", value_parser = str::parse::<SetpointStep>, allow_hyphen_values = true)]
    pub(crate) setpoint: Vec<SetpointStep>,
    /// A matrix plant's set-point step of one loop, LOOP:VALUE[@TIME] (1-based, repeatable);
    /// default: loop i steps to 1 at (i-1)/n of the run.
    #[arg(long, value_name = "L:V[@T]", value_parser = msp::syntax::parse_loop_setpoint, allow_hyphen_values = true)]
    pub(crate) loop_setpoint: Vec<(usize, SetpointStep)>,
    /// A matrix plant's step load on one loop, LOOP:input|output:VALUE[@TIME] (1-based, repeatable).
    #[arg(long, value_name = "L:LOC:V[@T]", value_parser = str::parse::<msp::sim::LoopLoad>, allow_hyphen_values = true)]
    pub(crate) loop_disturbance: Vec<msp::sim::LoopLoad>,
    /// A matrix plant's disturbance through its own channel to each output, a column
    /// "[d1; d2]" (Wood-Berry's feed: "[3.8e^-8.1s/(14.9s+1); 4.9e^-3.4s/(13.2s+1)]").
    #[arg(long, value_name = "[D1; D2]", allow_hyphen_values = true, value_parser = parse_column)]
    pub(crate) disturbance_plant: Option<Column>,
    /// The --disturbance-plant's input steps, VALUE[@TIME] (repeatable).
    #[arg(long, value_name = "V[@T]", value_parser = str::parse::<SetpointStep>, allow_hyphen_values = true)]
    pub(crate) disturbance_step: Vec<SetpointStep>,
    /// A matrix plant's channel changing its dead time, ROW,COL=SECONDS@TIME (1-based, repeatable;
    /// the fraction of a sample kept).
    #[arg(long, value_name = "R,C=S@T", value_parser = str::parse::<msp::sim::ChannelDeadTime>)]
    pub(crate) channel_dead_time: Vec<msp::sim::ChannelDeadTime>,
    /// A matrix plant's loop switched by the operator, LOOP:TIME:manual=VALUE (the plant's input
    /// held; the loop's controller tracks it) or LOOP:TIME:auto (bumpless; repeatable).
    #[arg(long, value_name = "L:T:MODE", value_parser = str::parse::<msp::sim::LoopMode>, allow_hyphen_values = true)]
    pub(crate) loop_event: Vec<msp::sim::LoopMode>,
    /// Disturbance input|output|inner[:step|ramp|sine]:VALUE[@TIME][~FREQ_HZ] (repeatable);
    /// for a cascade process d2 = input, d1 = output, d0 = inner (at the secondary output).
    #[arg(long, value_name = "LOC:V@T", value_parser = str::parse::<Disturbance>, allow_hyphen_values = true)]
    pub(crate) disturbance: Vec<Disturbance>,
    /// Measurement-noise standard deviation.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) noise: Option<f64>,
    /// Noise seed.
    #[arg(long)]
    pub(crate) seed: Option<u64>,
    /// The measurement's resolution (an ADC's step, e.g. span/4096 for 12 bits).
    #[arg(long, value_name = "STEP", allow_hyphen_values = true)]
    pub(crate) quantization: Option<f64>,
    /// Actuator lower limit.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) umin: Option<f64>,
    /// Actuator upper limit.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) umax: Option<f64>,
    /// Plant outputs per controller period in the CSV (smooth intersample plots).
    #[arg(long)]
    pub(crate) substeps: Option<usize>,
    /// The controller computes in f32 as firmware does (designed in f64; the
    /// plant stays exact in f64).
    #[arg(long)]
    pub(crate) float32: bool,
    /// The memory a run may take, e.g. 4G (default 1G): a run whose delay lines and
    /// recorded signals would need more is refused before anything is allocated.
    #[arg(long, value_name = "BYTES", value_parser = msp::syntax::parse_bytes)]
    pub(crate) max_memory: Option<u64>,
    /// An operator's action TIME:ACTION (repeatable): manual=U, track=U, auto,
    /// dead-time=θ (the controller's model; θ~RATE moves it there at RATE s/s),
    /// plant-dead-time=θ (the process; for a cascade L1 + L2, the primary changing),
    /// plant-gain=K, plant-lag=τ (the process changing: its gain, its one lag's time constant;
    /// each plant-…=X~RATE drifts there at RATE per second, e.g. plant-dead-time=9~0.003),
    /// adapt-freeze, adapt-resume (with --adapt),
    /// kp=V, ti=V, td=V (the primary PID retuned, bumpless),
    /// e.g. --event 60:manual=0.3 --event 120:auto.
    #[arg(long = "event", value_name = "T:ACTION", value_parser = str::parse::<msp::sim::Operation>, allow_hyphen_values = true)]
    pub(crate) events: Vec<msp::sim::Operation>,
    /// An actuator outside the controller, MIN..MAX: the plant receives the
    /// controller's output clamped to it (the controller does not know it).
    #[arg(long, value_name = "MIN..MAX", value_parser = msp::syntax::parse_actuator, allow_hyphen_values = true)]
    pub(crate) actuator: Option<(f64, f64)>,
    /// Feed the value the plant received back to the controller each sample
    /// (external reset: no windup against --actuator).
    #[arg(long)]
    pub(crate) reset_feedback: bool,
    /// The controller's set point moves by at most RATE per second (a
    /// set-point ramp, as industrial blocks have; off by default).
    #[arg(long, value_name = "RATE", allow_hyphen_values = true)]
    pub(crate) setpoint_ramp: Option<f64>,
    /// Adaptive dead-time compensation: the Smith predictor's model (a
    /// FOPDT or IPDT model) kept right by on-line identification, its
    /// primary retuned by its rule at each change; the estimates are the
    /// CSV columns k_hat, tau_hat, theta_hat (and evidence, for the dead
    /// time over the candidates that cannot be it: small is ambiguous),
    /// the model in use k_model, tau_model, theta_model.
    #[arg(long)]
    pub(crate) adapt: bool,
    /// The dead times (s) the adaptation considers, MIN..MAX (default 0.3
    /// to 3 times the model's; at most 32 of the estimator's samples, a
    /// tenth of the model's dead time each, apart).
    #[arg(long, value_name = "MIN..MAX", value_parser = msp::syntax::parse_dead_times)]
    pub(crate) adapt_delay: Option<(f64, f64)>,
    /// The estimator's forgetting factor, in (0, 1] (default 0.999: a
    /// memory of 1000 samples).
    #[arg(long, value_name = "LAMBDA", allow_hyphen_values = true)]
    pub(crate) adapt_forgetting: Option<f64>,
    /// The estimator's prefilter time constant (s; default 0: plain
    /// differences of the block means, which a load's onset needs).
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    pub(crate) adapt_prefilter: Option<f64>,
    /// The excitation gate: no learning unless the input moved this much
    /// (and ten times its own jitter, and a hundredth of its largest move
    /// of late) within the response's time.
    #[arg(long, value_name = "DU", allow_hyphen_values = true)]
    pub(crate) adapt_excitation: Option<f64>,
    /// The estimator's dead zone in multiples of the measured noise (its
    /// RMS prediction error; default 0: off).
    #[arg(long, value_name = "RATIO", allow_hyphen_values = true)]
    pub(crate) adapt_dead_zone: Option<f64>,
    /// The adaptation's bound on the gain and the lag: estimates beyond
    /// this factor of the commissioned model's are warned of, never
    /// applied (default 4).
    #[arg(long, value_name = "FACTOR", allow_hyphen_values = true)]
    pub(crate) adapt_bound: Option<f64>,
    /// A scheme rebuilt for each model (karan-dey, fsp) is designed between
    /// samples, as a device's background task would (C:
    /// `background_design` and `msp_adaptive_design`): each new scheme a
    /// sample later than when designed in the update that applies its model.
    #[arg(long)]
    pub(crate) adapt_background: bool,
    /// Model-error monitor: the estimator watches the model in use and
    /// raises an alarm (in the report and the summary, and the CSV columns
    /// mismatch, model_alarm) when the process no longer matches it;
    /// nothing is applied (with --adapt: alarms beside the adaptation).
    #[arg(long)]
    pub(crate) monitor: bool,
    /// The model error that raises the monitor's alarm (default 0.1: 10 %).
    #[arg(long, value_name = "FRACTION", allow_hyphen_values = true)]
    pub(crate) alarm: Option<f64>,
}

#[derive(Debug, Args)]
pub(crate) struct RunArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// Controller name (see `msp list`); default by plant kind.
    #[arg(long, short = 'c')]
    pub(crate) controller: Option<String>,
    /// Forced response: a CSV of the set point and loads, sampled (columns `t`, `r`, and
    /// optionally `d` at the plant input and `d_out` at its output; the times uniform from 0,
    /// their step the controller's period), held between samples.
    #[arg(long, value_name = "FILE.csv")]
    pub(crate) input: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) files: SimulationFiles,
    /// No summary on standard error.
    #[arg(long, short = 'q')]
    pub(crate) quiet: bool,
}

#[derive(Debug, Args)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// Controllers to compare, comma separated (e.g. karan-dey,smith).
    #[arg(long, short = 'c', value_delimiter = ',', required = true)]
    pub(crate) controllers: Vec<String>,
    /// Perturbation of the plant, e.g. gain=+10%,delay=+10%,tau=-5% (inner_gain, inner_delay,
    /// inner_tau for the secondary of a cascade); the controllers keep the nominal model.
    #[arg(long, value_parser = str::parse::<Perturbation>, allow_hyphen_values = true)]
    pub(crate) perturb: Option<Perturbation>,
    #[command(flatten)]
    pub(crate) files: SimulationFiles,
}

/// The files a simulation writes (`msp run`, `msp compare`).
#[derive(Debug, Args)]
pub(crate) struct SimulationFiles {
    /// CSV of the simulated signals, a column group per controller (`-`:
    /// standard output; `msp run` without it prints the CSV into a pipe or a
    /// redirection, a summary on a terminal).
    #[arg(long, short = 'o')]
    pub(crate) output: Option<PathBuf>,
    /// JSON report, an entry per controller (`-`: standard output).
    #[arg(long)]
    pub(crate) report: Option<PathBuf>,
    /// SVG plot of r, y and u (of every controller).
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct MarginsArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// Controller name (see `msp list`); absent or `none`: the bare plant, L = G
    /// (with --set kp=K a pure gain, L = K·G).
    #[arg(long, short = 'c')]
    pub(crate) controller: Option<String>,
    /// Use the exact discrete equivalent of the plant instead of the continuous plant behind a hold.
    #[arg(long, conflicts_with = "continuous")]
    pub(crate) discrete: bool,
    /// The continuous plant without the hold (MATLAB's `margin` of a continuous design).
    #[arg(long)]
    pub(crate) continuous: bool,
    /// Robust-stability test (Eq. 17, max|T·Δ| < 1) for a plant perturbation, e.g.
    /// gain=10%,delay=10%,tau=-20% (inner_gain, inner_delay, inner_tau for a cascade's secondary).
    #[arg(long, value_parser = str::parse::<Perturbation>, allow_hyphen_values = true)]
    pub(crate) uncertainty: Option<Perturbation>,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
    /// SVG with the Bode and Nyquist plots of the loop at the plant input.
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// SVG with the Nyquist plot alone, with the unit circle and the Ms circle.
    #[arg(long)]
    pub(crate) nyquist: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct SweepArgs {
    #[command(flatten)]
    pub(crate) scenario: ScenarioArgs,
    /// Controller name (see `msp list`); default by plant kind.
    #[arg(long, short = 'c')]
    pub(crate) controller: Option<String>,
    /// Relative gain range, e.g. -20%..+20%.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = str::parse::<msp::sweep::Range>)]
    pub(crate) gain: msp::sweep::Range,
    /// Relative dead-time range.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = str::parse::<msp::sweep::Range>)]
    pub(crate) delay: msp::sweep::Range,
    /// Relative time-constant range.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = str::parse::<msp::sweep::Range>)]
    pub(crate) tau: msp::sweep::Range,
    /// Points per swept axis.
    #[arg(long, default_value_t = 11, conflicts_with = "samples")]
    pub(crate) grid: usize,
    /// Random points instead of a grid.
    #[arg(long, default_value_t = 0)]
    pub(crate) samples: usize,
    /// Seed of the random points.
    #[arg(long = "sweep-seed", default_value_t = 1)]
    pub(crate) sweep_seed: u64,
    /// Run only shard I of N (runs whose index is I mod N), e.g. 0/4.
    #[arg(long, value_parser = parse_shard, default_value = "0/1")]
    pub(crate) shard: (usize, usize),
    /// Merge shard CSVs into one (no runs): msp sweep --merge a.csv b.csv -o all.csv.
    #[arg(long, num_args = 1.., conflicts_with = "plant")]
    pub(crate) merge: Vec<PathBuf>,
    /// CSV with one row per run (absent or `-`: standard output).
    #[arg(long, short = 'o')]
    pub(crate) output: Option<PathBuf>,
    /// No progress bar and summary.
    #[arg(long, short = 'q')]
    pub(crate) quiet: bool,
}

pub(crate) fn parse_shard(s: &str) -> Result<(usize, usize), String> {
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
pub(crate) struct AutotuneArgs {
    /// The (simulated) plant the relay test runs on.
    #[arg(long, short = 'p', allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) plant: TransferFunction,
    /// Relay amplitude h; the relay acts in the plant's direction (a reverse-acting
    /// plant gets -|h|).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub(crate) relay_amplitude: f64,
    /// Relay hysteresis (default: three noise standard deviations).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) hysteresis: Option<f64>,
    /// Relay bias for the static gain (default: 0 for integrating plants, 0.2 h otherwise).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) bias: Option<f64>,
    /// Measurement-noise standard deviation.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub(crate) noise: f64,
    /// Noise seed.
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// Model to identify: ipdt, foipdt, fopdt, sopdt or ufopdt (default: the plain model of
    /// the plant's kind, or the one with a lag where the relay data shows it; ufopdt, the
    /// unstable FOPDT, for an unstable plant, from a biased relay).
    #[arg(long, value_parser = str::parse::<msp::ident::ModelKind>)]
    pub(crate) model: Option<msp::ident::ModelKind>,
    /// Controller to tune (default by the identified model).
    #[arg(long, short = 'c')]
    pub(crate) controller: Option<String>,
    /// Sample period (s).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) ts: Option<f64>,
    /// Safety band on the output during the relay test.
    #[arg(long, default_value_t = f64::INFINITY, allow_hyphen_values = true)]
    pub(crate) band: f64,
    /// Duration of the closed-loop run (s).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) duration: Option<f64>,
    /// CSV of the closed-loop run (`-`: standard output).
    #[arg(long, short = 'o')]
    pub(crate) output: Option<PathBuf>,
    /// JSON report (`-`: standard output).
    #[arg(long)]
    pub(crate) report: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct StepArgs {
    /// Plant transfer function, e.g. "2*e^-5s/(10s+1)^4".
    #[arg(long, short = 'p', allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) plant: TransferFunction,
    /// Sample period of the response (s); the duration over 4000 when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) ts: Option<f64>,
    /// Duration (s); chosen from the plant when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) duration: Option<f64>,
    /// CSV with columns t, u, y (`-`: standard output): the plant at rest one
    /// sample before the unit step, then its response, as `msp identify` reads it.
    #[arg(long, short = 'o')]
    pub(crate) output: Option<PathBuf>,
    /// SVG plot of the response.
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
    /// The memory the response and its CSV may take, e.g. 4G (default 1G): a longer
    /// one is refused before anything is computed.
    #[arg(long, value_name = "BYTES", value_parser = msp::syntax::parse_bytes)]
    pub(crate) max_memory: Option<u64>,
}

#[derive(Debug, Args)]
pub(crate) struct IdentifyArgs {
    /// CSV with a time, an input and an output column (an open-loop step in the input).
    #[arg(long)]
    pub(crate) data: PathBuf,
    /// The time column (default: `t`, or `time`).
    #[arg(long)]
    pub(crate) time: Option<String>,
    /// The input column (the actuator; default: `u`).
    #[arg(long, default_value = "u")]
    pub(crate) input: String,
    /// The output column (the measurement; default: `y`).
    #[arg(long, default_value = "y")]
    pub(crate) output: String,
    /// Model to fit.
    #[arg(long, default_value = "fopdt", value_parser = str::parse::<msp::ident::ModelKind>)]
    pub(crate) model: msp::ident::ModelKind,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

#[derive(Debug, Args)]
pub(crate) struct TradeoffArgs {
    /// Plant transfer function.
    #[arg(long, short = 'p', allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) plant: TransferFunction,
    /// The controllers' model (default: the plant).
    #[arg(long, short = 'm', allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) model: Option<TransferFunction>,
    /// The schemes, comma separated (default: every single-loop scheme for the plant tuned by lambda).
    #[arg(long, short = 'c', value_delimiter = ',')]
    pub(crate) controllers: Vec<String>,
    /// Sample period (s); chosen from the plant when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) ts: Option<f64>,
    /// The table as CSV (`-` for standard output).
    #[arg(long, short = 'o')]
    pub(crate) output: Option<PathBuf>,
    /// The picture: Ms against IAE (load and set point), a curve per scheme, its own tuning marked.
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
    /// No progress on a terminal.
    #[arg(long, short = 'q')]
    pub(crate) quiet: bool,
}

#[derive(Debug, Args)]
pub(crate) struct ServeArgs {
    /// The folder to serve (its index.html at /).
    pub(crate) dir: PathBuf,
    /// The port (0: one the system picks; the address is printed).
    #[arg(long, default_value_t = 8000)]
    pub(crate) port: u16,
    /// The address to listen on: the loopback address unless another is named.
    #[arg(long, default_value = "127.0.0.1")]
    pub(crate) bind: std::net::IpAddr,
}

/// Arguments of `msp stepinfo`.
#[derive(Debug, Args)]
pub(crate) struct StepinfoArgs {
    /// CSV with a time and an output column: a step response, the step at the first sample.
    #[arg(long)]
    pub(crate) data: PathBuf,
    /// The time column (default: `t`, or `time`).
    #[arg(long)]
    pub(crate) time: Option<String>,
    /// The output column (default: `y`).
    #[arg(long, default_value = "y")]
    pub(crate) output: String,
    /// The final value (default: the last sample), MATLAB's yfinal.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) yfinal: Option<f64>,
    /// The value before the step (default 0), MATLAB's yinit.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) yinit: Option<f64>,
    /// The settling band, a fraction of the step.
    #[arg(long, default_value_t = 0.02)]
    pub(crate) settling_threshold: f64,
    /// The rise time's limits, fractions of the step: LOW,HIGH.
    #[arg(long, default_value = "0.1,0.9", value_parser = parse_pair)]
    pub(crate) rise_limits: (f64, f64),
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `LOW,HIGH`.
pub(crate) fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("expected LOW,HIGH, got '{s}'"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{}' is not a number", v.trim()))
    };
    Ok((num(a)?, num(b)?))
}

#[derive(Debug, Args)]
pub(crate) struct TuneArgs {
    /// Plant (or model) transfer function; or a square matrix of them, MATLAB's way,
    /// "[g11, g12; g21, g22]" (0 for no coupling): the RGA, the Niederlinski index and
    /// BLT-tuned decentralized PI loops.
    #[arg(long, short = 'p', allow_hyphen_values = true, value_parser = parse_plant_arg)]
    pub(crate) plant: PlantArg,
    /// Cascade process: the secondary process (the default controller is then fspcc).
    #[arg(long, allow_hyphen_values = true, value_parser = str::parse::<TransferFunction>)]
    pub(crate) inner_plant: Option<TransferFunction>,
    /// Sample period (s) for the robust-stability test; chosen from the plant when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) ts: Option<f64>,
    /// Also report the robust-stability test (Eq. 17, max|T·Δ| < 1) for this perturbation,
    /// e.g. delay=20%,tau=-20%.
    #[arg(long, value_parser = str::parse::<Perturbation>, allow_hyphen_values = true)]
    pub(crate) uncertainty: Option<Perturbation>,
    /// Controller name; default by plant kind.
    #[arg(long, short = 'c')]
    pub(crate) controller: Option<String>,
    #[command(flatten)]
    pub(crate) design: DesignArgs,
    /// Every PI/PID tuning rule (imc, simc, amigo and the ultimate-cycle rules of
    /// `msp list`) applied to the plant, with the Ms and margins each one gives.
    #[arg(long, conflicts_with_all = ["controller", "uncertainty", "inner_plant"])]
    pub(crate) rules: bool,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
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

    /// Every field of a scenario file is a flag of `msp run` and `msp compare`
    /// (`inner_plant` as `--inner-plant`), so the two ways in cannot diverge.
    #[test]
    fn run_and_compare_take_every_scenario_field() {
        let cmd = Cli::command();
        for sub in ["run", "compare"] {
            let sub = cmd.find_subcommand(sub).unwrap();
            let flags: Vec<String> = sub
                .get_arguments()
                .filter_map(|a| a.get_long())
                .map(|l| l.replace('-', "_"))
                .collect();
            for field in msp::study::Scenario::FIELDS {
                // compare names its schemes with --controllers; an event is
                // given per flag (--event, repeatable)
                let field = match (sub.get_name(), *field) {
                    ("compare", "controller") => "controllers",
                    (_, "events") => "event",
                    _ => field,
                };
                assert!(
                    flags.iter().any(|f| f == field),
                    "msp {} has no flag for the scenario field '{field}'",
                    sub.get_name()
                );
            }
        }
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

/// A plant argument: a transfer function, or a matrix of them.
#[derive(Debug, Clone)]
pub(crate) enum PlantArg {
    Single(TransferFunction),
    Matrix(TransferMatrix),
}

/// `[…]` is a matrix ([`msp::syntax::parse_matrix`]), anything else a plant.
fn parse_plant_arg(s: &str) -> Result<PlantArg, msp::syntax::ParseError> {
    if s.trim_start().starts_with('[') {
        s.parse().map(PlantArg::Matrix)
    } else {
        s.parse().map(PlantArg::Single)
    }
}

/// `LOOP:VALUE[@TIME]`, the loop 1-based.
/// A column of transfer functions (one value to clap, not a list of them).
#[derive(Debug, Clone)]
pub(crate) struct Column(pub(crate) Vec<TransferFunction>);

fn parse_column(s: &str) -> Result<Column, msp::syntax::ParseError> {
    msp::syntax::parse_column(s).map(Column)
}
