//! The scheme registry: name → tuning rule + construction + parameter names.
//!
//! The CLI and Python read this one table; adding a scheme means adding one
//! [`Scheme`] entry here.

use alloc::boxed::Box;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

use crate::delay::Delay;
use crate::dtc::compensator::ParamList;
use crate::dtc::{self, KaranDeyParams, SmithPredictor};
use crate::poly::{PlantKind, TransferFunction};
use crate::LoopController;
use crate::{tuning, Ipdt, Lti, Pid, PidConfig, ProcessModel, Real};

/// Largest model order the registry's controllers hold.
pub const MAX_ORDER: usize = 8;

/// A controller built by the registry.
pub type DynController = DynControllerOf<f64>;

/// A boxed controller in precision `T` (`f64` for the CLI and Python, `f32`
/// for firmware-like runs and benchmarks).
pub type DynControllerOf<T> = Box<dyn LoopController<T> + Send + Sync>;

/// Why a scheme could not be tuned or built.
#[derive(Debug, Clone, PartialEq)]
pub enum RegistryError {
    /// A parameter or model was rejected by the core.
    Core(crate::Error),
    /// No scheme has this name.
    UnknownScheme(String),
    /// `--set` named a parameter the scheme does not have.
    UnknownParam {
        /// The scheme.
        scheme: &'static str,
        /// The name given.
        name: String,
        /// The names it accepts.
        allowed: Vec<&'static str>,
    },
    /// The scheme cannot control this kind of plant.
    PlantKind {
        /// The scheme.
        scheme: &'static str,
        /// The plant's kind.
        kind: PlantKind,
        /// Schemes that can.
        alternatives: Vec<&'static str>,
    },
}

impl From<crate::Error> for RegistryError {
    fn from(e: crate::Error) -> Self {
        RegistryError::Core(e)
    }
}

impl fmt::Display for RegistryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RegistryError::Core(e) => write!(f, "{e}"),
            RegistryError::UnknownScheme(n) => {
                write!(
                    f,
                    "unknown controller '{n}'; available: {}",
                    names().join(", ")
                )
            }
            RegistryError::UnknownParam {
                scheme,
                name,
                allowed,
            } => {
                write!(
                    f,
                    "controller '{scheme}' has no parameter '{name}'; it has: {}",
                    allowed.join(", ")
                )
            }
            RegistryError::PlantKind {
                scheme,
                kind,
                alternatives,
            } => {
                if alternatives.is_empty() {
                    write!(f, "controller '{scheme}' cannot control an {kind} plant, and no controller in msp can yet")
                } else {
                    write!(
                        f,
                        "controller '{scheme}' cannot control an {kind} plant; use one of: {}",
                        alternatives.join(", ")
                    )
                }
            }
        }
    }
}

impl core::error::Error for RegistryError {}

/// Named parameter values, in the scheme's order.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Params(pub Vec<(&'static str, f64)>);

impl Params {
    /// The value of `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
    }
    fn req(&self, name: &'static str) -> Result<f64, crate::Error> {
        self.get(name).ok_or(crate::Error::Unsupported(name))
    }
    /// Sets an existing parameter; false when the name is unknown.
    pub fn set(&mut self, name: &str, v: f64) -> bool {
        match self.0.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => {
                slot.1 = v;
                true
            }
            None => false,
        }
    }
}

/// Design-time options for a tuning rule (from `--lambda`, `--rule` and the
/// design keys of `--set`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Design {
    /// Closed-loop time constant `λ` (s).
    pub lambda: Option<f64>,
    /// A named rule (`pid`: `imc`, `simc` or an ultimate-cycle rule).
    pub rule: Option<String>,
    /// Design values by name (`alpha`, `case`, `tde`, …).
    pub values: Vec<(String, f64)>,
}

impl Design {
    /// A design value.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.values
            .iter()
            .rev()
            .find(|(k, _)| k == name)
            .map(|(_, v)| *v)
    }
}

/// Options for building a controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Build {
    /// Sample period (s).
    pub ts: f64,
    /// Actuator lower limit.
    pub u_min: f64,
    /// Actuator upper limit.
    pub u_max: f64,
}

/// One dead-time compensation scheme.
pub struct Scheme {
    /// Name on the command line and in Python.
    pub name: &'static str,
    /// Other accepted names.
    pub aliases: &'static [&'static str],
    /// One line for `--help` and listings.
    pub summary: &'static str,
    /// Seed file and section the scheme comes from.
    pub source: &'static str,
    /// Plant kinds it can control.
    pub plants: &'static [PlantKind],
    /// Names of the tuned parameters, in report order.
    pub params: &'static [&'static str],
    /// Design keys accepted by `--set` before tuning.
    pub design: &'static [&'static str],
    /// Tuning and construction.
    pub fns: SchemeFns,
}

/// A single-loop tuning rule: model → parameters.
pub type TuneFn = fn(&TransferFunction, &Design) -> Result<Params, crate::Error>;
/// A single-loop construction: parameters + model → controller in precision `T`.
pub type BuildFn<T = f64> =
    fn(&Params, &TransferFunction, &Build) -> Result<DynControllerOf<T>, crate::Error>;

/// A construction in both precisions (the same generic function instantiated twice).
#[derive(Clone, Copy)]
pub struct Builders<F64, F32> {
    /// In `f64`.
    pub f64: F64,
    /// In `f32`.
    pub f32: F32,
}

/// The precisions a registry controller is built in.
pub trait Precision: Real {
    /// This precision's single-loop construction.
    fn single(b: &Builders<BuildFn<f64>, BuildFn<f32>>) -> BuildFn<Self>;
    /// This precision's cascade construction.
    fn cascade(b: &Builders<CascadeBuildFn<f64>, CascadeBuildFn<f32>>) -> CascadeBuildFn<Self>;
}

impl Precision for f64 {
    fn single(b: &Builders<BuildFn<f64>, BuildFn<f32>>) -> BuildFn<f64> {
        b.f64
    }
    fn cascade(b: &Builders<CascadeBuildFn<f64>, CascadeBuildFn<f32>>) -> CascadeBuildFn<f64> {
        b.f64
    }
}

impl Precision for f32 {
    fn single(b: &Builders<BuildFn<f64>, BuildFn<f32>>) -> BuildFn<f32> {
        b.f32
    }
    fn cascade(b: &Builders<CascadeBuildFn<f64>, CascadeBuildFn<f32>>) -> CascadeBuildFn<f32> {
        b.f32
    }
}
/// A cascade tuning rule: `(P1, P2, design)` → parameters.
pub type CascadeTuneFn =
    fn(&TransferFunction, &TransferFunction, &Design) -> Result<Params, crate::Error>;
/// A cascade construction: `(parameters, P1, P2, build)` → controller.
pub type CascadeBuildFn<T = f64> = fn(
    &Params,
    &TransferFunction,
    &TransferFunction,
    &Build,
) -> Result<DynControllerOf<T>, crate::Error>;

/// How a scheme is tuned and built: from the plant's model, or — for a cascade
/// scheme (García et al. (2010)) — from the primary and the secondary models.
#[derive(Clone, Copy)]
pub enum SchemeFns {
    /// A single-loop scheme.
    Single {
        /// Tuning rule.
        tune: TuneFn,
        /// Construction, in `f64` and `f32`.
        build: Builders<BuildFn<f64>, BuildFn<f32>>,
    },
    /// A cascade scheme: it needs the secondary process.
    Cascade {
        /// Tuning rule.
        tune: CascadeTuneFn,
        /// Construction, in `f64` and `f32`.
        build: Builders<CascadeBuildFn<f64>, CascadeBuildFn<f32>>,
    },
}

impl fmt::Debug for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Scheme").field("name", &self.name).finish()
    }
}

fn pid_cfg<T: Real>(p: &Params, b: &Build) -> Result<PidConfig<T>, crate::Error> {
    let td = p.get("td").unwrap_or(0.0);
    Ok(
        PidConfig::isa(req(p, "kp")?, req(p, "ti")?, T::of(td), T::of(b.ts))
            .with_limits(T::of(b.u_min), T::of(b.u_max)),
    )
}

/// Parameter `name` in precision `T`.
fn req<T: Real>(p: &Params, name: &'static str) -> Result<T, crate::Error> {
    Ok(T::of(p.req(name)?))
}

/// `λ`: given, or `alpha·L`, or `default_factor·L`.
fn lambda_for(model: &ProcessModel<f64>, d: &Design, default_factor: f64) -> f64 {
    match (d.lambda.or_else(|| d.get("lambda")), d.get("alpha")) {
        (Some(l), _) => l,
        (None, Some(a)) => a * model.delay(),
        (None, None) => default_factor * model.delay(),
    }
}

/// A model's delay-free block and its dead-time line.
type ModelParts<T, const N: usize> = (Lti<T, N>, Delay<T, Vec<T>>);

/// The case number 1–6 of the disturbance estimator.
fn case_of(case: f64) -> Result<u8, crate::Error> {
    (1u8..=6)
        .find(|c| f64::from(*c) == case)
        .ok_or(crate::Error::OutOfRange("case"))
}

/// The model's delay-free part at the controller period and its dead time.
fn model_parts<T: Real, const N: usize>(
    model: &TransferFunction,
    b: &Build,
) -> Result<ModelParts<T, N>, crate::Error> {
    Ok((
        Lti::of(&model.to_model_lti::<N>(b.ts)?),
        Delay::new_in(T::of(model.delay_samples(b.ts)?))?,
    ))
}

/// The model's dead time in a line of its own (Huang's filter, Åström–Hang–Lim's M, Uma et al.'s model).
fn delay_again<T: Real>(
    model: &TransferFunction,
    b: &Build,
) -> Result<Delay<T, Vec<T>>, crate::Error> {
    Delay::new_in(T::of(model.delay_samples(b.ts)?))
}

fn integrating_model(
    plant: &TransferFunction,
    scheme: &'static str,
) -> Result<Ipdt<f64>, crate::Error> {
    match plant.reduce(false)? {
        ProcessModel::Ipdt(m) => Ok(m),
        _ => Err(crate::Error::Unsupported(scheme)),
    }
}

fn params_of(names: &'static [&'static str], values: &[f64]) -> Params {
    Params(names.iter().copied().zip(values.iter().copied()).collect())
}

/// A build function dispatched on the model order, so that the model block
/// holds no more states than it needs (the update cost grows with them).
macro_rules! by_order {
    ($f:ident) => {{
        fn dispatch<T: Real>(
            p: &Params,
            m: &TransferFunction,
            b: &Build,
        ) -> Result<DynControllerOf<T>, crate::Error> {
            match m.model_order() {
                0 | 1 => $f::<T, 1>(p, m, b),
                2 => $f::<T, 2>(p, m, b),
                3 | 4 => $f::<T, 4>(p, m, b),
                _ => $f::<T, MAX_ORDER>(p, m, b),
            }
        }
        both!(dispatch)
    }};
}

/// A generic build function in both precisions.
macro_rules! both {
    ($f:ident) => {
        Builders {
            f64: $f::<f64>,
            f32: $f::<f32>,
        }
    };
}

/// The controller's own copy of its parameters, in the scheme's report order.
fn list<T: Real>(names: &'static [&'static str], p: &Params) -> ParamList<T> {
    let values: Vec<T> = names
        .iter()
        .map(|n| T::of(p.get(n).unwrap_or(f64::NAN)))
        .collect();
    ParamList::new(names, &values)
}

// ---- pid -------------------------------------------------------------------

fn tune_pid(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = plant.reduce(true)?;
    let default_rule = if matches!(plant.reduce(false)?, ProcessModel::Fopdt(_)) {
        "imc"
    } else {
        "simc"
    };
    let rule = d.rule.as_deref().unwrap_or(default_rule);
    let (g, lambda) = match rule {
        "imc" | "imc-pid" => {
            let f = match plant.reduce(false)? {
                ProcessModel::Fopdt(f) => f,
                _ => {
                    return Err(crate::Error::Unsupported(
                        "IMC-PID needs a stable FOPDT model (use --rule simc)",
                    ))
                }
            };
            let lambda = lambda_for(&f.into(), d, 1.0);
            (tuning::imc_pid(&f, lambda)?, lambda)
        }
        "simc" => {
            let lambda = lambda_for(&m, d, 1.0);
            (tuning::simc(&m, lambda)?, lambda)
        }
        name => {
            let r = tuning::ultimate_rule(name).ok_or(crate::Error::Unsupported(
                "unknown tuning rule (see `msp list`)",
            ))?;
            let (ku, tu) = plant
                .ultimate()
                .ok_or(crate::Error::Unsupported("the plant has no ultimate point"))?;
            (tuning::ultimate_cycle(r, ku, tu)?, f64::NAN)
        }
    };
    Ok(params_of(SCHEMES_PID_PARAMS, &[g.kp, g.ti, g.td, lambda]))
}

const SCHEMES_PID_PARAMS: &[&str] = &["kp", "ti", "td", "lambda"];

fn build_pid<T: Real>(
    p: &Params,
    _m: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    Ok(Box::new(Pid::new(pid_cfg(p, b)?)?))
}

// ---- smith, filtered-smith, huang ---------------------------------------------

/// Kaya's PI/PID for a stable model, the thesis's IMC-PI for an integrating one.
fn primary_gains(
    plant: &TransferFunction,
    d: &Design,
    stable_factor: f64,
) -> Result<(tuning::PidGains<f64>, f64, ProcessModel<f64>), crate::Error> {
    let m = plant.reduce(plant.order() >= 2)?;
    Ok(match m {
        ProcessModel::Ipdt(i) => {
            let lambda = lambda_for(&m, d, 0.25);
            (tuning::imc_pi_integrating(&i, lambda)?, lambda, m)
        }
        _ => {
            let lambda = lambda_for(&m, d, stable_factor);
            (tuning::kaya(&m, lambda)?, lambda, m)
        }
    })
}

fn tune_smith(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let (g, lambda, _) = primary_gains(plant, d, 1.0)?;
    Ok(params_of(SCHEMES_PID_PARAMS, &[g.kp, g.ti, g.td, lambda]))
}

fn build_smith<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    Ok(Box::new(SmithPredictor::new(pid_cfg(p, b)?, lti, delay)?))
}

/// The dominant time constant of a stable model (for filter defaults).
fn dominant_lag(m: &ProcessModel<f64>) -> f64 {
    match *m {
        ProcessModel::Fopdt(f) => f.t,
        ProcessModel::Sopdt(s) => s.t1.max(s.t2),
        _ => m.delay(),
    }
}

fn tune_filtered_smith(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // the MathWorks Smith predictor example: λ = 12.5 s for L = 93.9 s (bandwidth 0.08 rad/s) → λ = L/7.5
    let (g, lambda, m) = primary_gains(plant, d, 1.0 / 7.5)?;
    let b = d.get("b").unwrap_or(0.5 * dominant_lag(&m));
    let a = d.get("a").unwrap_or(0.0);
    Ok(params_of(
        FILTERED_PARAMS,
        &[g.kp, g.ti, g.td, a, b, lambda],
    ))
}

const FILTERED_PARAMS: &[&str] = &["kp", "ti", "td", "a", "b", "lambda"];

fn build_filtered_smith<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let f = dtc::filtered_smith::lead_lag_filter(req(p, "a")?, req(p, "b")?, T::of(b.ts))?;
    Ok(Box::new(
        dtc::filtered_smith::build(pid_cfg(p, b)?, f, lti, delay, list(FILTERED_PARAMS, p))?
            .with_limits(T::of(b.u_min), T::of(b.u_max))?,
    ))
}

fn tune_huang(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // the MathWorks Smith predictor example: Kp = 0.144 (λ ≈ 50 s ≈ L/2), B = 0.05/(40 s + 1)
    let (g, lambda, m) = primary_gains(plant, d, 0.5)?;
    let kb = d.get("kb").unwrap_or(0.05);
    let tb = d.get("tb").unwrap_or(dominant_lag(&m));
    Ok(params_of(HUANG_PARAMS, &[g.kp, g.ti, g.td, kb, tb, lambda]))
}

const HUANG_PARAMS: &[&str] = &["kp", "ti", "td", "kb", "tb", "lambda"];

fn build_huang<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let line = delay_again(model, b)?;
    let c = dtc::huang::build(
        pid_cfg(p, b)?,
        req(p, "kb")?,
        req(p, "tb")?,
        lti,
        delay,
        line,
        list(HUANG_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

// ---- integrating-plant schemes -------------------------------------------------

fn tune_karan_dey(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = integrating_model(plant, "the Karan-Dey MSP needs an integrating plant")?;
    let lambda = lambda_for(&m.into(), d, 0.25);
    let k = tuning::karan_dey(&m, lambda)?;
    Ok(params_of(
        KD_PARAMS,
        &[k.kp, k.ti, k.beta, k.gamma, k.td, k.n, lambda],
    ))
}

const KD_PARAMS: &[&str] = &["kp", "ti", "beta", "gamma", "td", "n", "lambda"];

fn build_karan_dey<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let params = KaranDeyParams {
        kp: req(p, "kp")?,
        ti: req(p, "ti")?,
        beta: req(p, "beta")?,
        gamma: req(p, "gamma")?,
        td: req(p, "td")?,
        n: req(p, "n")?,
    };
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    Ok(Box::new(
        dtc::karan_dey::build(&params, lti, delay, T::of(b.ts))?
            .with_limits(T::of(b.u_min), T::of(b.u_max))?,
    ))
}

fn tune_watanabe_ito(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // The W-I loop is 1 + C·Kv/(s(1 + Ls)) (see dtc::watanabe_ito): SIMC PI for
    // an integrator with the lag L folded into the delay, τc = λ (default L/2).
    let m = integrating_model(
        plant,
        "the Watanabe-Ito predictor needs an integrating plant",
    )?;
    let lambda = lambda_for(&m.into(), d, 0.5);
    let s = lambda + m.l;
    Ok(params_of(
        WI_PARAMS,
        &[1.0 / (m.k * s), 4.0 * s, 0.0, lambda],
    ))
}

const WI_PARAMS: &[&str] = &["kp", "ti", "td", "lambda"];

fn build_watanabe_ito<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let m = integrating_model(
        model,
        "the Watanabe-Ito predictor needs an integrating plant",
    )?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::watanabe_ito::build(
        pid_cfg(p, b)?,
        T::of(m.k),
        T::of(m.l),
        lti,
        delay,
        list(WI_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_astrom_hang_lim(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // set point k/(s + k) with k = 1/λ (λ = L/4 by default); load loop
    // (1 + k1)s² + k2 s + k3 = (s + a)² with a = 1/L.
    let m = integrating_model(
        plant,
        "the Astrom-Hang-Lim predictor needs an integrating plant",
    )?;
    let lambda = lambda_for(&m.into(), d, 0.25);
    let a = d.get("a").unwrap_or(1.0 / m.l);
    Ok(params_of(
        AHL_PARAMS,
        &[1.0 / lambda, 0.0, 2.0 * a, a * a, lambda],
    ))
}

const AHL_PARAMS: &[&str] = &["k", "k1", "k2", "k3", "lambda"];

fn build_astrom_hang_lim<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let m = integrating_model(
        model,
        "the Astrom-Hang-Lim predictor needs an integrating plant",
    )?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let line = Delay::new_in(T::of(model.delay_samples(b.ts)?.floor()))?;
    let c = dtc::astrom_hang_lim::build(
        req(p, "k")?,
        req(p, "k1")?,
        req(p, "k2")?,
        req(p, "k3")?,
        T::of(m.k),
        T::of(b.ts),
        lti,
        delay,
        line,
        list(AHL_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_matausek_micic(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = integrating_model(
        plant,
        "the Matausek-Micic predictor needs an integrating plant",
    )?;
    let tr = d
        .get("tr")
        .unwrap_or_else(|| lambda_for(&m.into(), d, 0.25));
    Ok(params_of(
        MM_PARAMS,
        &[1.0 / (m.k * tr), 0.5 / (m.k * m.l), tr],
    ))
}

const MM_PARAMS: &[&str] = &["kr", "k0", "tr"];

fn build_matausek_micic<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::matausek_micic::build(
        req(p, "kr")?,
        req(p, "k0")?,
        T::of(b.ts),
        lti,
        delay,
        list(MM_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_kaya_atherton(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = match plant.reduce(false)? {
        // an integrator with a lag T acts at low frequency as K/s with T more dead time
        ProcessModel::Foipdt(f) => ProcessModel::Ipdt(Ipdt::new(f.k, f.l + f.t)?),
        other => other,
    };
    let values = match m {
        ProcessModel::Ipdt(i) => {
            // the Karan-Dey settings: Gc2 = beta·Kp (P), Gc3 from gamma·Kp with Td = λ
            let lambda = lambda_for(&m, d, 0.25);
            let k = tuning::karan_dey(&i, lambda)?;
            [k.kp, k.ti, k.beta * k.kp, 0.0, k.gamma * k.kp, k.td, lambda]
        }
        ProcessModel::Fopdt(_) | ProcessModel::Sopdt(_) => {
            // Kaya's PI on the model loop; a proportional Gc3 with loop gain 1/2,
            // stable for any dead time by the small-gain theorem
            let lambda = lambda_for(&m, d, 1.0);
            let g = tuning::kaya(&m, lambda)?;
            let k = plant.gain();
            [g.kp, g.ti, 0.0, 0.0, 0.5 / k, 0.0, lambda]
        }
        _ => {
            return Err(crate::Error::Unsupported(
                "the Kaya-Atherton predictor needs a stable or integrating plant",
            ))
        }
    };
    Ok(params_of(KA_PARAMS, &values))
}

const KA_PARAMS: &[&str] = &["kp", "ti", "kf", "tf", "kb", "td", "lambda"];

/// Kaya–Atherton's predictor on `model`, reporting `names` (without limits).
fn kaya_atherton_on<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
    names: &'static [&'static str],
) -> Result<Compensator<T, N, Vec<T>>, crate::Error> {
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    dtc::kaya_atherton::build(
        req(p, "kp")?,
        req(p, "ti")?,
        req(p, "kf")?,
        req(p, "tf")?,
        req(p, "kb")?,
        req(p, "td")?,
        T::of(b.ts),
        lti,
        delay,
        list(names, p),
    )
}

fn build_kaya_atherton<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let c = kaya_atherton_on::<T, N>(p, model, b, KA_PARAMS)?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_disturbance_estimator(
    plant: &TransferFunction,
    d: &Design,
) -> Result<Params, crate::Error> {
    let m = integrating_model(
        plant,
        "the disturbance estimator needs an integrating plant",
    )?;
    let td = d
        .get("td")
        .unwrap_or_else(|| lambda_for(&m.into(), d, 0.25));
    let case = d.get("case").unwrap_or(1.0);
    let case_n = case_of(case)?;
    let design = tuning::EstimatorDesign {
        case: case_n,
        tde: d.get("tde").unwrap_or(0.55 * m.l),
        alpha: d
            .get("alpha")
            .unwrap_or(if case == 6.0 { 0.95 } else { 0.5 }),
        w0: d.get("w0").unwrap_or(0.05),
    };
    let t = tuning::disturbance_estimator(m.k, m.l, &design)?;
    Ok(params_of(
        DE_PARAMS,
        &[
            1.0 / (m.k * td),
            td,
            case,
            t.ka,
            t.ta,
            t.tc,
            design.tde,
            design.alpha,
            design.w0,
        ],
    ))
}

const DE_PARAMS: &[&str] = &["kr", "td", "case", "ka", "ta", "tc", "tde", "alpha", "w0"];

fn build_disturbance_estimator<T: Real, const N: usize>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let case = case_of(p.req("case")?)?;
    let est = dtc::disturbance_estimator::Estimator::from_case(
        case,
        req(p, "ka")?,
        req(p, "ta")?,
        req(p, "tc")?,
        req(p, "w0")?,
    )?;
    let (lti, delay) = model_parts::<T, N>(model, b)?;
    let c = dtc::disturbance_estimator::build(
        req(p, "kr")?,
        &est,
        T::of(b.ts),
        lti,
        delay,
        list(DE_PARAMS, p),
    )?;
    Ok(Box::new(c.with_limits(T::of(b.u_min), T::of(b.u_max))?))
}

fn tune_fsp(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = plant.reduce(false)?;
    let lambda = lambda_for(&m, d, 1.0);
    let (kp, ti) = match m {
        // K/(T s − 1): the delay-free loop with a PI gets the double pole −1/λ
        ProcessModel::Ufopdt(u) => {
            let kkc = 1.0 + 2.0 * u.t / lambda;
            (kkc / u.k, kkc * lambda * lambda / u.t)
        }
        // K/s: the same placement gives the thesis's IMC-PI
        ProcessModel::Ipdt(i) => (2.0 / (i.k * lambda), 2.0 * lambda),
        _ => {
            let g = tuning::kaya(&plant.reduce(true)?, lambda)?;
            (g.kp, g.ti)
        }
    };
    let tf = d.get("tf").unwrap_or(0.5 * m.delay().max(1e-9));
    Ok(params_of(FSP_PARAMS, &[kp, ti, tf, lambda]))
}

const FSP_PARAMS: &[&str] = &["kp", "ti", "tf", "lambda"];

/// The dead time of `model` in whole samples: the predictors of García et al. (2010)
/// realize `z^{−h}` inside `S` and `F1`, so `h` must be an integer.
fn whole_samples(model: &TransferFunction, ts: f64) -> Result<usize, crate::Error> {
    let d = model.delay_samples(ts)?;
    let h = d.round();
    if (d - h).abs() > 1e-6 {
        return Err(crate::Error::Unsupported(
            "the predictor needs a dead time of a whole number of samples: choose ts = L/n",
        ));
    }
    num_traits::ToPrimitive::to_usize(&h).ok_or(crate::Error::DelayTooLong("delay"))
}

fn build_fsp<T: Real>(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let h = whole_samples(model, b.ts)?;
    let gm = model.to_model_lti::<MAX_ORDER>(b.ts)?;
    let design = dtc::fsp::design::<Vec<f64>, MAX_ORDER>(&gm, h, b.ts, p.req("tf")?)?;
    let k = PidConfig::isa(req(p, "kp")?, req(p, "ti")?, T::zero(), T::of(b.ts))
        .with_limits(T::of(b.u_min), T::of(b.u_max));
    Ok(Box::new(dtc::fsp::FilteredSmith::<T, Vec<T>>::new(
        k,
        &design,
        list(FSP_PARAMS, p),
    )?))
}

// ---- cascade schemes (García et al. (2010)) -------------------------------

use crate::dtc::cascade::{self, Cascade, Imc};
use crate::dtc::compensator::{Compensator, DisturbancePath, ErrorPath, AUX};
use crate::dtc::fsp::{FrSpec, Predicted};
use crate::dtc::gpcc::GpccPredictor;
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// A cascade scheme asked for without the secondary process.
fn needs_inner() -> RegistryError {
    RegistryError::Core(crate::Error::Unsupported(
        "a cascade scheme needs the secondary process (--inner-plant)",
    ))
}

/// The inner IMC filter time constant: given, or the secondary dead time
/// (the paper's examples: λ2 = L2 = 2 s in Example 1), or a tenth of the
/// secondary's slowest time scale when it has no dead time.
fn lambda2_for(p2: &TransferFunction, d: &Design) -> Result<f64, crate::Error> {
    if let Some(l) = d.get("lambda2") {
        return Ok(l);
    }
    if p2.delay > 0.0 {
        return Ok(p2.delay);
    }
    let slow = p2.time_scales()?.into_iter().fold(0.0, f64::max);
    Ok(if slow > 0.0 { 0.1 * slow } else { 1.0 })
}

/// The primary model `Gm e^{−Ls}` (with the inner loop closed), `λ` and the
/// pole-placed series PID `(kp, ki, kd, τ)` for it. Default `λ = 0.8·L`: Uma
/// et al.'s Example 1 design places the poles at `−1/5` for `L = 6 s`.
fn cascade_primary(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
) -> Result<(f64, f64, [f64; 4], TransferFunction), crate::Error> {
    let lambda2 = lambda2_for(p2, d)?;
    let gm = cascade::primary_model(p1, p2, lambda2)?;
    let lambda = match (d.lambda.or_else(|| d.get("lambda")), d.get("alpha")) {
        (Some(l), _) => l,
        (None, Some(a)) => a * gm.delay,
        (None, None) if gm.delay > 0.0 => 0.8 * gm.delay,
        (None, None) => lambda2,
    };
    let k = cascade::pole_placement(&gm, lambda)?;
    Ok((lambda2, lambda, k, gm))
}

/// A cascade scheme's parameters: the primary PID `kp, ki, kd, tau`, the
/// set-point weight (0.3, the paper's examples), `lambda2`, then the scheme's
/// own values from `tail(Gm)`, then `lambda`.
fn cascade_params(
    names: &'static [&'static str],
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
    tail: impl FnOnce(&TransferFunction) -> Vec<f64>,
) -> Result<Params, crate::Error> {
    let (lambda2, lambda, [kp, ki, kd, tau], gm) = cascade_primary(p1, p2, d)?;
    let mut v = alloc::vec![kp, ki, kd, tau, d.get("epsilon").unwrap_or(0.3), lambda2];
    v.extend(tail(&gm));
    v.push(lambda);
    Ok(params_of(names, &v))
}

/// The parts every cascade scheme builds: the primary model `Gm e^{−(L1+L2)s}`,
/// its ZOH block, its dead time in whole samples, the inner loop and the
/// primary controller (as Uma et al.'s PID and as FSPCC's matched `K(z)`).
struct CascadeParts<T> {
    model: TransferFunction,
    /// The primary model's delay-free part, designed in `f64`.
    gm: Lti<f64, MAX_ORDER>,
    h: usize,
    imc: Imc<T, Vec<T>>,
    /// Uma et al.'s `Gcs` as a PID (their continuous design, sampled).
    k: PidConfig<T>,
    /// The same, pole-zero matched (FSPCC's and GPCC's `K(z)`).
    km: dtc::fsp::Matched2Dof<T>,
}

/// The primary model `Gm e^{−(L1+L2)s}` and the inner IMC loop of a cascade
/// scheme (actuator limits on the inner loop's output, the plant input).
fn cascade_inner<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<(TransferFunction, Imc<T, Vec<T>>), crate::Error> {
    let lambda2 = p.req("lambda2")?;
    let imc =
        Imc::<T, Vec<T>>::design(p2, lambda2, b.ts)?.with_limits(T::of(b.u_min), T::of(b.u_max))?;
    Ok((cascade::primary_model(p1, p2, lambda2)?, imc))
}

fn cascade_parts<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<CascadeParts<T>, crate::Error> {
    let (model, imc) = cascade_inner(p, p1, p2, b)?;
    let (kp, ki, kd, tau) = (p.req("kp")?, p.req("ki")?, p.req("kd")?, p.req("tau")?);
    let epsilon = p.get("epsilon").unwrap_or(1.0);
    Ok(CascadeParts {
        gm: model.to_model_lti::<MAX_ORDER>(b.ts)?,
        h: whole_samples(&model, b.ts)?,
        model,
        imc,
        k: cascade::series_pid(
            T::of(kp),
            T::of(ki),
            T::of(kd),
            T::of(tau),
            T::of(epsilon),
            T::of(b.ts),
        )?,
        km: cascade::matched_primary(kp, ki, kd, tau, epsilon, b.ts)?,
    })
}

const FSPCC_PARAMS: &[&str] = &[
    "kp", "ki", "kd", "tau", "epsilon", "lambda2", "tf", "lead", "lag", "lambda",
];
const PREDICTED_SIGNALS: &[&str] = &["r2", "inner_error", "prediction"];
const COMPENSATOR_SIGNALS: &[&str] = &[
    "r2",
    "inner_error",
    "ym",
    "ym_delayed",
    "model_error",
    "u1",
    "u3",
];

fn tune_fspcc(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
) -> Result<Params, crate::Error> {
    cascade_params(FSPCC_PARAMS, p1, p2, d, |gm| {
        alloc::vec![
            d.get("tf").unwrap_or(0.5 * gm.delay.max(1e-9)),
            d.get("lead").unwrap_or(0.0),
            d.get("lag").unwrap_or(0.0),
        ]
    })
}

fn build_fspcc<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let c = cascade_parts(p, p1, p2, b)?;
    let (lead, lag) = (p.req("lead")?, p.req("lag")?);
    let spec = FrSpec {
        tf: p.req("tf")?,
        lead: if lead > 0.0 && lag > 0.0 {
            Some((lead, lag))
        } else {
            None
        },
        biproper: true,
    };
    let design = dtc::fsp::design_with::<Vec<f64>, MAX_ORDER>(&c.gm, c.h, b.ts, &spec)?;
    let outer = Predicted::<T, _, _>::with_primary(
        c.km,
        dtc::fsp::FspPredictor::<T, Vec<T>>::new(&design)?,
        list(FSPCC_PARAMS, p),
    );
    Ok(Box::new(Cascade::new(outer, c.imc, PREDICTED_SIGNALS)))
}

const GPCC_PARAMS: &[&str] = &[
    "kp", "ki", "kd", "tau", "epsilon", "lambda2", "tk", "lambda",
];

fn tune_gpcc(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
) -> Result<Params, crate::Error> {
    cascade_params(GPCC_PARAMS, p1, p2, d, |_| {
        alloc::vec![d.get("tk").unwrap_or(0.0)]
    })
}

fn build_gpcc<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let c = cascade_parts(p, p1, p2, b)?;
    let pred = GpccPredictor::<T, Vec<T>>::design(&c.gm, c.h, b.ts, p.req("tk")?)?;
    let outer = Predicted::<T, _, _>::with_primary(c.km, pred, list(GPCC_PARAMS, p));
    Ok(Box::new(Cascade::new(outer, c.imc, PREDICTED_SIGNALS)))
}

const UMA_PARAMS: &[&str] = &[
    "kp", "ki", "kd", "tau", "epsilon", "lambda2", "kpd", "kid", "kdd", "lead", "lag", "tf",
    "lambda",
];

fn tune_uma(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
) -> Result<Params, crate::Error> {
    // Gcd: Uma et al. tune it on a Padé approximation of the dead time, a rule
    // the sources do not give: its gains are left to --set (NaN until then)
    cascade_params(UMA_PARAMS, p1, p2, d, |_| {
        alloc::vec![
            f64::NAN,
            f64::NAN,
            f64::NAN,
            d.get("lead").unwrap_or(0.0),
            d.get("lag").unwrap_or(0.0),
            d.get("tf").unwrap_or(0.0),
        ]
    })
}

fn build_uma<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let c = cascade_parts(p, p1, p2, b)?;
    let (kpd, kid, kdd) = (p.req("kpd")?, p.req("kid")?, p.req("kdd")?);
    if [kpd, kid, kdd].iter().any(|v| v.is_nan()) {
        return Err(crate::Error::Unsupported(
            "uma: the disturbance controller Gcd has no tuning rule in the sources; set kpd, kid and kdd (and lead, lag) with --set",
        ));
    }
    let (lead, lag) = (p.req("lead")?, p.req("lag")?);
    // Gcd = (kpd + kid/s + kdd s)(lead s + 1)/(lag s + 1), pole-zero matched
    let (mut num, mut den) = if kid != 0.0 {
        (alloc::vec![kdd, kpd, kid], alloc::vec![1.0, 0.0])
    } else {
        (alloc::vec![kdd, kpd], alloc::vec![1.0])
    };
    num = crate::poly::mul(&num, &[lead, 1.0]);
    den = crate::poly::mul(&den, &[lag, 1.0]);
    let gcd = Lti::of(&Lti::<f64, AUX>::from_tf(
        &num,
        &den,
        b.ts,
        crate::Discretization::Matched,
    )?);
    let tf = p.req("tf")?;
    let err = if tf > 0.0 {
        ErrorPath::Filter(Lti::of(&Lti::<f64, AUX>::from_tf(
            &[1.0],
            &[tf, 1.0],
            b.ts,
            crate::Discretization::Matched,
        )?))
    } else {
        ErrorPath::Direct
    };
    let delay = delay_again(&c.model, b)?;
    let outer = Compensator::new(Pid::new(c.k)?, Lti::of(&c.gm), delay, list(UMA_PARAMS, p))?
        .with_error_path(err)?
        .with_disturbance(DisturbancePath::Block(gcd));
    Ok(Box::new(Cascade::new(outer, c.imc, COMPENSATOR_SIGNALS)))
}

const KAYA_CASCADE_PARAMS: &[&str] = &["kp", "ti", "kf", "tf", "kb", "td", "lambda2", "lambda"];

fn tune_kaya_cascade(
    p1: &TransferFunction,
    p2: &TransferFunction,
    d: &Design,
) -> Result<Params, crate::Error> {
    let lambda2 = lambda2_for(p2, d)?;
    let gm = cascade::primary_model(p1, p2, lambda2)?;
    let single = tune_kaya_atherton(&gm, d)?;
    let mut values: Vec<f64> = KA_PARAMS
        .iter()
        .map(|n| single.get(n).unwrap_or(f64::NAN))
        .collect();
    values.insert(6, lambda2);
    Ok(params_of(KAYA_CASCADE_PARAMS, &values))
}

fn build_kaya_cascade<T: Real>(
    p: &Params,
    p1: &TransferFunction,
    p2: &TransferFunction,
    b: &Build,
) -> Result<DynControllerOf<T>, crate::Error> {
    let (gm, imc) = cascade_inner(p, p1, p2, b)?;
    let outer = kaya_atherton_on::<T, MAX_ORDER>(p, &gm, b, KAYA_CASCADE_PARAMS)?;
    Ok(Box::new(Cascade::new(outer, imc, COMPENSATOR_SIGNALS)))
}

const STABLE: &[PlantKind] = &[PlantKind::Stable];
const ALL: &[PlantKind] = &[
    PlantKind::Stable,
    PlantKind::Integrating,
    PlantKind::Unstable,
];
const STABLE_INT: &[PlantKind] = &[PlantKind::Stable, PlantKind::Integrating];
const INT: &[PlantKind] = &[PlantKind::Integrating];

/// Every scheme, in listing order.
pub static SCHEMES: &[Scheme] = &[
    Scheme {
        name: "pid",
        aliases: &["pi"],
        summary: "plain PI/PID feedback, the baseline: IMC-PID (default), SIMC, or an ultimate-cycle rule (--rule)",
        source: "Bag (2022) Eqs. 3.19-3.27, Tables 3.2-3.3",
        plants: STABLE_INT,
        params: SCHEMES_PID_PARAMS,
        design: &["lambda", "alpha"],
        fns: SchemeFns::Single {
            tune: tune_pid,
            build: both!(build_pid),
        },
    },
    Scheme {
        name: "smith",
        aliases: &["sp"],
        summary: "classic Smith predictor; PI/PID by Kaya 2003 (lambda = L), IMC-PI for integrating plants",
        source: "Kaya (2003) Eqs. 18-33",
        plants: STABLE_INT,
        params: SCHEMES_PID_PARAMS,
        design: &["lambda", "alpha"],
        fns: SchemeFns::Single {
            tune: tune_smith,
            build: by_order!(build_smith),
        },
    },
    Scheme {
        name: "filtered-smith",
        aliases: &[],
        summary: "Smith predictor with a filter F = (1 + a s)/(1 + b s) on the model error",
        source: "the MathWorks Smith predictor example",
        plants: STABLE,
        params: FILTERED_PARAMS,
        design: &["lambda", "alpha", "a", "b"],
        fns: SchemeFns::Single {
            tune: tune_filtered_smith,
            build: by_order!(build_filtered_smith),
        },
    },
    Scheme {
        name: "huang",
        aliases: &[],
        summary: "Smith predictor with Huang's approximate inverse of dead time F = (1+B)/(1+B e^-Ls)",
        source: "the MathWorks Smith predictor example",
        plants: STABLE,
        params: HUANG_PARAMS,
        design: &["lambda", "alpha", "kb", "tb"],
        fns: SchemeFns::Single {
            tune: tune_huang,
            build: by_order!(build_huang),
        },
    },
    Scheme {
        name: "watanabe-ito",
        aliases: &["wi"],
        summary: "Watanabe-Ito predictor for integrating plants: the predictor's static gain removed",
        source: "Bag (2022) Sec. 4.4.1",
        plants: INT,
        params: WI_PARAMS,
        design: &["lambda", "alpha"],
        fns: SchemeFns::Single {
            tune: tune_watanabe_ito,
            build: by_order!(build_watanabe_ito),
        },
    },
    Scheme {
        name: "astrom-hang-lim",
        aliases: &["ahl"],
        summary: "Astrom-Hang-Lim predictor for integrating plants: set-point and load responses decoupled",
        source: "Bag (2022) Sec. 4.4.2, Eqs. 4.13-4.17",
        plants: INT,
        params: AHL_PARAMS,
        design: &["lambda", "alpha", "a"],
        fns: SchemeFns::Single {
            tune: tune_astrom_hang_lim,
            build: by_order!(build_astrom_hang_lim),
        },
    },
    Scheme {
        name: "matausek-micic",
        aliases: &["mm"],
        summary: "Matausek-Micic predictor for integrating plants: P set point, P load feedback",
        source: "Bag (2022) Sec. 4.4.3, refs [8], [52]",
        plants: INT,
        params: MM_PARAMS,
        design: &["lambda", "alpha", "tr"],
        fns: SchemeFns::Single {
            tune: tune_matausek_micic,
            build: by_order!(build_matausek_micic),
        },
    },
    Scheme {
        name: "kaya-atherton",
        aliases: &["ka", "pi-pd"],
        summary: "Kaya-Atherton PI-PD Smith predictor: Gc1 PI, Gc2 P/PD, Gc3 = kb(Td s+1)/(0.1 Td s+1)",
        source: "Bag (2022) Sec. 4.4.3, Eq. 4.18",
        plants: STABLE_INT,
        params: KA_PARAMS,
        design: &["lambda", "alpha"],
        fns: SchemeFns::Single {
            tune: tune_kaya_atherton,
            build: by_order!(build_kaya_atherton),
        },
    },
    Scheme {
        name: "karan-dey",
        aliases: &["msp"],
        summary: "Karan-Dey three-controller modified Smith predictor for integrating plants (lambda = L/4)",
        source: "Bag (2022) Sec. 4.5",
        plants: INT,
        params: KD_PARAMS,
        design: &["lambda", "alpha"],
        fns: SchemeFns::Single {
            tune: tune_karan_dey,
            build: by_order!(build_karan_dey),
        },
    },
    Scheme {
        name: "fsp",
        aliases: &["filtered-smith-unstable"],
        summary: "filtered Smith predictor for unstable, integrating and stable plants: Fr(z) from the Diophantine condition",
        source: "García et al. (2010) Sec. 3, Eq. 10",
        plants: ALL,
        params: FSP_PARAMS,
        design: &["lambda", "alpha", "tf"],
        fns: SchemeFns::Single {
            tune: tune_fsp,
            build: both!(build_fsp),
        },
    },
    Scheme {
        name: "disturbance-estimator",
        aliases: &["de"],
        summary: "Smith predictor with a disturbance estimator for integrating plants, cases 1-6 (--set case=N)",
        source: "Draganović et al. (2001)",
        plants: INT,
        params: DE_PARAMS,
        design: &["lambda", "td", "case", "tde", "alpha", "w0"],
        fns: SchemeFns::Single {
            tune: tune_disturbance_estimator,
            build: by_order!(build_disturbance_estimator),
        },
    },
    Scheme {
        name: "fspcc",
        aliases: &[],
        summary: "cascade: filtered Smith predictor (Fr from Eq. 10) outside an IMC inner loop",
        source: "García et al. (2010) Sec. 3.1, Figs. 5-6, Eq. 10",
        plants: ALL,
        params: FSPCC_PARAMS,
        design: &["lambda", "alpha", "lambda2", "epsilon", "tf", "lead", "lag"],
        fns: SchemeFns::Cascade {
            tune: tune_fspcc,
            build: both!(build_fspcc),
        },
    },
    Scheme {
        name: "gpcc",
        aliases: &[],
        summary: "cascade: generalized predictor (F1, F2, Gamma, Fk) outside an IMC inner loop",
        source: "García et al. (2010) Sec. 3.2, Fig. 7, Eqs. 1-4",
        plants: ALL,
        params: GPCC_PARAMS,
        design: &["lambda", "alpha", "lambda2", "epsilon", "tk"],
        fns: SchemeFns::Cascade {
            tune: tune_gpcc,
            build: both!(build_gpcc),
        },
    },
    Scheme {
        name: "uma",
        aliases: &["uma-2009"],
        summary: "cascade competitor: Uma et al. 2009 modified Smith predictor (Gcs, Gcd, Gf; set Gcd's gains)",
        source: "García et al. (2010) Sec. 2.3, Fig. 4",
        plants: ALL,
        params: UMA_PARAMS,
        design: &["lambda", "alpha", "lambda2", "epsilon", "lead", "lag", "tf"],
        fns: SchemeFns::Cascade {
            tune: tune_uma,
            build: both!(build_uma),
        },
    },
    Scheme {
        name: "kaya-cascade",
        aliases: &["kaya-2008"],
        summary: "cascade competitor: Kaya et al. 2008 Smith predictor in the outer loop (Gc1, Gc3, Gd)",
        source: "García et al. (2010) Sec. 2.2, Fig. 3",
        plants: STABLE_INT,
        params: KAYA_CASCADE_PARAMS,
        design: &["lambda", "alpha", "lambda2"],
        fns: SchemeFns::Cascade {
            tune: tune_kaya_cascade,
            build: both!(build_kaya_cascade),
        },
    },
];

/// All scheme names.
pub fn names() -> Vec<&'static str> {
    SCHEMES.iter().map(|s| s.name).collect()
}

/// The scheme called `name` (or one of its aliases).
pub fn find(name: &str) -> Result<&'static Scheme, RegistryError> {
    let key = name.trim().to_ascii_lowercase().replace('_', "-");
    SCHEMES
        .iter()
        .find(|s| s.name == key || s.aliases.contains(&key.as_str()))
        .ok_or_else(|| RegistryError::UnknownScheme(name.to_string()))
}

/// The default scheme for a plant: the Karan–Dey MSP for integrating plants,
/// the Smith predictor (Kaya tuning) for stable ones, the filtered Smith
/// predictor for unstable ones.
pub fn default_for(kind: PlantKind) -> Result<&'static Scheme, RegistryError> {
    match kind {
        PlantKind::Integrating => find("karan-dey"),
        PlantKind::Stable => find("smith"),
        PlantKind::Unstable => find("fsp"),
    }
}

impl Scheme {
    /// Tunes on `model`, applying `overrides` (design keys before tuning,
    /// parameter names after). Unknown names are an error naming the valid ones.
    pub fn tune_with(
        &'static self,
        model: &TransferFunction,
        lambda: Option<f64>,
        overrides: &[(String, f64)],
    ) -> Result<Params, RegistryError> {
        self.tune_rule(model, lambda, None, overrides)
    }

    /// [`Scheme::tune_with`] with a named rule (`--rule`).
    pub fn tune_rule(
        &'static self,
        model: &TransferFunction,
        lambda: Option<f64>,
        rule: Option<&str>,
        overrides: &[(String, f64)],
    ) -> Result<Params, RegistryError> {
        self.tune_process(model, None, lambda, rule, overrides)
    }

    /// True for a cascade scheme (it needs the secondary process).
    pub fn is_cascade(&self) -> bool {
        matches!(self.fns, SchemeFns::Cascade { .. })
    }

    /// Tunes on the primary `model` and, for a cascade process, the secondary
    /// `inner` model. A single-loop scheme on a cascade process controls the
    /// whole series `P1·P2` from the plant input (the secondary measurement unused).
    pub fn tune_process(
        &'static self,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        lambda: Option<f64>,
        rule: Option<&str>,
        overrides: &[(String, f64)],
    ) -> Result<Params, RegistryError> {
        let whole;
        let model = match (inner, self.is_cascade()) {
            (Some(p2), false) => {
                whole = model.series(p2)?;
                &whole
            }
            _ => model,
        };
        let kind = model.kind();
        if !self.plants.contains(&kind) {
            return Err(RegistryError::PlantKind {
                scheme: self.name,
                kind,
                alternatives: SCHEMES
                    .iter()
                    .filter(|s| s.plants.contains(&kind))
                    .map(|s| s.name)
                    .collect(),
            });
        }
        let design = Design {
            lambda,
            rule: rule.map(ToString::to_string),
            values: overrides
                .iter()
                .filter(|(k, _)| self.design.contains(&k.as_str()))
                .cloned()
                .collect(),
        };
        let mut params = match (self.fns, inner) {
            (SchemeFns::Cascade { tune, .. }, Some(p2)) => tune(model, p2, &design)?,
            (SchemeFns::Cascade { .. }, None) => return Err(needs_inner()),
            (SchemeFns::Single { tune, .. }, _) => tune(model, &design)?,
        };
        for (k, v) in overrides {
            if self.design.contains(&k.as_str()) {
                continue;
            }
            if !params.set(k, *v) {
                let mut allowed: Vec<&'static str> = self.params.to_vec();
                allowed.extend(self.design.iter().filter(|d| !self.params.contains(d)));
                return Err(RegistryError::UnknownParam {
                    scheme: self.name,
                    name: k.clone(),
                    allowed,
                });
            }
        }
        Ok(params)
    }

    /// Builds the controller.
    pub fn build_with(
        &self,
        params: &Params,
        model: &TransferFunction,
        b: &Build,
    ) -> Result<DynController, RegistryError> {
        self.build_process(params, model, None, b)
    }

    /// Builds the controller for the primary `model` and, for a cascade
    /// process, the secondary `inner` model.
    pub fn build_process(
        &self,
        params: &Params,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        b: &Build,
    ) -> Result<DynController, RegistryError> {
        self.build_process_as::<f64>(params, model, inner, b)
    }

    /// [`Scheme::build_process`] in precision `T` (`f32` for a controller that
    /// computes as firmware does; the design and discretization run in `f64`).
    pub fn build_process_as<T: Precision>(
        &self,
        params: &Params,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        b: &Build,
    ) -> Result<DynControllerOf<T>, RegistryError> {
        Ok(match (self.fns, inner) {
            (SchemeFns::Cascade { build, .. }, Some(p2)) => {
                T::cascade(&build)(params, model, p2, b)?
            }
            (SchemeFns::Cascade { .. }, None) => return Err(needs_inner()),
            (SchemeFns::Single { build, .. }, Some(p2)) => {
                T::single(&build)(params, &model.series(p2)?, b)?
            }
            (SchemeFns::Single { build, .. }, None) => T::single(&build)(params, model, b)?,
        })
    }
}
