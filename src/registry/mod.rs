//! The scheme registry: name → tuning rule + construction + parameter names.
//!
//! The CLI and Python read this one table. A scheme is its functions in a
//! module here (its tuning, its construction from the model) plus its row in
//! [`SCHEMES`].

mod cascade;
mod common;
mod disturbance_estimator;
mod fsp;
mod integrating;
mod pid;
mod scheme;
mod smith;

use alloc::boxed::Box;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

use crate::dtc::astrom_hang_lim::{AstromHangLimParams, AstromHangLimTuning};
use crate::dtc::cascade::{
    FspccParams, FspccTuning, GpccParams, GpccTuning, KayaCascadeParams, KayaCascadeTuning,
    UmaParams, UmaTuning,
};
use crate::dtc::disturbance_estimator::{DisturbanceEstimatorParams, DisturbanceEstimatorTuning};
use crate::dtc::filtered_smith::FilteredSmithParams;
use crate::dtc::fsp::{FspParams, FspTuning};
use crate::dtc::huang::HuangParams;
use crate::dtc::kaya_atherton::KayaAthertonParams;
use crate::dtc::matausek_micic::{MatausekMicicParams, MatausekMicicTuning};
use crate::dtc::KaranDeyParams;
use crate::loop_controller::LoopController;
use crate::params::{DesignSet, ParamList, ParamSet};
use crate::poly::{PlantKind, TransferFunction};
use crate::real::Real;
use crate::tuning::{LambdaTuning, PidGains};
use common::{both, by_order};

pub use crate::poly::MAX_ORDER;

/// A controller built by the registry.
pub type DynController = DynControllerOf<f64>;

/// A boxed controller in precision `T` (`f64` for the CLI and Python, `f32`
/// for firmware-like runs and benchmarks).
pub type DynControllerOf<T> = Box<dyn LoopController<T> + Send + Sync>;

/// Why a scheme could not be tuned or built.
#[derive(Debug, Clone, PartialEq)]
pub enum RegistryError {
    /// A parameter or model was rejected by the core.
    Core(crate::error::Error),
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

impl From<crate::error::Error> for RegistryError {
    fn from(e: crate::error::Error) -> Self {
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
                    "unknown controller '{}'; available: {}",
                    clip(n),
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
                    "controller '{scheme}' has no parameter '{}'; it has: {}",
                    clip(name),
                    allowed.join(", ")
                )
            }
            RegistryError::PlantKind {
                scheme,
                kind,
                alternatives,
            } => {
                if alternatives.is_empty() {
                    write!(f, "controller '{scheme}' cannot control {} {kind} plant, and no controller in msp can yet", article(*kind))
                } else {
                    write!(
                        f,
                        "controller '{scheme}' cannot control {} {kind} plant; use one of: {}",
                        article(*kind),
                        alternatives.join(", ")
                    )
                }
            }
        }
    }
}

impl core::error::Error for RegistryError {}

/// A name as a message shows it: at most 60 characters (a 10 MB name is not
/// echoed whole).
fn clip(name: &str) -> String {
    match name.char_indices().nth(60) {
        Some((i, _)) => alloc::format!("{}…", name.get(..i).unwrap_or(name)),
        None => name.to_string(),
    }
}

/// "a" or "an" before a plant kind.
fn article(kind: PlantKind) -> &'static str {
    match kind {
        PlantKind::Integrating | PlantKind::Unstable => "an",
        PlantKind::Stable => "a",
    }
}

/// A scheme's tuned parameters: the names and values of its typed struct
/// (a [`ParamSet`], in `f64`) and the closed-loop time constant `lambda` the
/// tuning aimed for (reported after them; `--set lambda=` re-tunes).
///
/// The names come from the struct's fields only, so `--set` can change a
/// value the type has and no other.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Params {
    list: ParamList<f64>,
    lambda: Option<f64>,
    rule: Option<Rule>,
}

/// The named rule a PI/PID was tuned by, with the ultimate gain and period
/// an ultimate-cycle rule read from the plant.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Rule {
    /// `imc` (IMC-PID, Bag (2022) Eqs. 3.19–3.27), `simc` (Skogestad
    /// (2003)), an ultimate-cycle rule of Bag (2022) Tables 3.2/3.3 (`zn`,
    /// …), or `given` (every gain set by the user).
    pub name: &'static str,
    /// The ultimate gain (ultimate-cycle rules).
    pub ku: Option<f64>,
    /// The ultimate period (s; ultimate-cycle rules).
    pub tu: Option<f64>,
    /// The set-point weights `(b, c)` of the proportional and derivative
    /// terms the rule gives (AMIGO); `None`: the PID's defaults.
    pub weights: Option<(f64, f64)>,
}

impl Params {
    /// The parameters of a typed struct.
    pub fn of<P: ParamSet<f64>>(p: &P) -> Self {
        Params {
            list: ParamList::of(p),
            lambda: None,
            rule: None,
        }
    }
    /// The same, tuned by the named `rule`.
    pub fn with_rule(mut self, rule: Rule) -> Self {
        self.rule = Some(rule);
        self
    }
    /// The named rule a PI/PID was tuned by (`None` for a scheme whose
    /// tuning is its source's own: the report's `source` names it).
    pub fn rule(&self) -> Option<Rule> {
        self.rule
    }
    /// The same, every tuned parameter given by the user: no `λ` and no
    /// rule stand behind it (a PI/PID's tuning reads `given`).
    pub fn as_given(mut self) -> Self {
        self.lambda = None;
        self.rule = self.rule.map(|_| Rule {
            name: "given",
            ku: None,
            tu: None,
            weights: None,
        });
        self
    }
    /// The same, tuned for the closed-loop time constant `lambda`.
    pub fn with_lambda(mut self, lambda: f64) -> Self {
        self.lambda = Some(lambda);
        self
    }
    /// The typed struct `P` in precision `T` (every field of `P` read by name;
    /// `P` may be a part of the scheme's struct, the PID of a predictor).
    pub fn typed<T: Real, P: ParamSet<T>>(&self) -> Result<P, crate::error::Error> {
        P::from_list(&self.list)
    }
    /// The value of `name` (`lambda` included).
    pub fn get(&self, name: &str) -> Option<f64> {
        match (name, self.lambda) {
            ("lambda", Some(l)) => Some(l),
            _ => self.list.get(name),
        }
    }
    /// Sets a parameter of the scheme's type; false when the type has no such field.
    pub fn set(&mut self, name: &str, v: f64) -> bool {
        self.list.set(name, v)
    }
    /// The closed-loop time constant the tuning aimed for.
    pub fn lambda(&self) -> Option<f64> {
        self.lambda
    }
    /// `(name, value)` pairs in report order: the struct's fields, then `lambda`.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.list.iter().chain(self.lambda.map(|l| ("lambda", l)))
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Params {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(None)?;
        for (k, v) in self.iter() {
            m.serialize_entry(k, &v)?;
        }
        m.end()
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
    /// Design values by name (`alpha`, `case`, `tde`, …): the keys of the
    /// scheme's [`DesignSet`], read back with [`Design::typed`].
    pub values: Vec<(String, f64)>,
}

impl Design {
    /// The scheme's typed design inputs: every value by its field name (a name
    /// the type lacks is skipped: the registry passes only the scheme's
    /// [`DesignSet::NAMES`]), `--lambda` over `--set lambda=`.
    pub fn typed<D: DesignSet>(&self) -> D {
        let mut d = D::default();
        for (k, v) in &self.values {
            d.set(k, *v);
        }
        if let Some(l) = self.lambda {
            d.set_lambda(l);
        }
        d
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
    /// The longest dead time (s) the controller's model will be given at run
    /// time ([`crate::Operate::set_dead_time`]): its delay line holds at
    /// least this, or the model's own dead time when that is longer (`0`).
    pub max_dead_time: f64,
}

impl Build {
    /// Period `ts`, no actuator limits, the model's own dead time.
    pub fn unlimited(ts: f64) -> Self {
        Build {
            ts,
            u_min: f64::NEG_INFINITY,
            u_max: f64::INFINITY,
            max_dead_time: 0.0,
        }
    }
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
    /// Names of the tuned parameters, in report order: the fields of the
    /// scheme's [`ParamSet`] (`lambda`, a design key, follows in reports).
    pub params: &'static [&'static str],
    /// Design keys accepted by `--set` before tuning.
    pub design: &'static [&'static str],
    /// The designed quantities a publication prints beside the tuned
    /// parameters (filters, their gains, zeros and poles), for the schemes
    /// that design more than their parameters.
    pub describe: Option<DescribeFn>,
    /// Tuning and construction.
    pub fns: SchemeFns,
}

/// One designed quantity: a number, a list of numbers (the poles a filter
/// cancels), or a discrete transfer function in descending powers of `z`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub enum DesignValue {
    /// A number.
    Scalar(f64),
    /// Numbers.
    List(Vec<f64>),
    /// The open interval a tuned parameter must lie in for the loop on the
    /// model to be stable, as a source derives it (Karan–Dey's
    /// `0 < γ < 1/(θm·K·Kp)`, Bag (2022) Eq. 4.49); the robustness warnings
    /// check the parameter against it.
    StableRange {
        /// The parameter, by its report name.
        param: &'static str,
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// `num(z)/den(z)`.
    Filter {
        /// Numerator, descending powers of `z`.
        num: Vec<f64>,
        /// Denominator, descending powers of `z`.
        den: Vec<f64>,
    },
}

/// The designed quantities of a scheme by name, in the order a paper gives them.
pub type DesignReport = Vec<(&'static str, DesignValue)>;

/// Serde for a [`DesignReport`]: an object `{name: value, …}`.
#[cfg(feature = "serde")]
pub fn serialize_design<S: serde::Serializer>(d: &DesignReport, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(Some(d.len()))?;
    for (k, v) in d {
        m.serialize_entry(k, v)?;
    }
    m.end()
}

/// What a scheme designs from its parameters, for its model (and a cascade's
/// secondary model) at the period `ts`.
pub type DescribeFn = fn(
    &Params,
    &TransferFunction,
    Option<&TransferFunction>,
    f64,
) -> Result<DesignReport, crate::error::Error>;

/// A single-loop tuning rule: model → parameters.
pub type TuneFn = fn(&TransferFunction, &Design) -> Result<Params, crate::error::Error>;
/// A single-loop construction: parameters + model → controller in precision `T`.
pub type BuildFn<T = f64> =
    fn(&Params, &TransferFunction, &Build) -> Result<DynControllerOf<T>, crate::error::Error>;

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
    fn(&TransferFunction, &TransferFunction, &Design) -> Result<Params, crate::error::Error>;
/// A cascade construction: `(parameters, P1, P2, build)` → controller.
pub type CascadeBuildFn<T = f64> = fn(
    &Params,
    &TransferFunction,
    &TransferFunction,
    &Build,
) -> Result<DynControllerOf<T>, crate::error::Error>;

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

/// The rows of [`SCHEMES`], one a scheme: its name and aliases, the plant
/// kinds it controls, its parameter and design types (their fields are the
/// names `--set` takes and the report prints); `Single` or `Cascade` with its
/// tuning, its construction and what it describes beyond its parameters; the
/// line `msp list` prints and the publication it follows.
macro_rules! schemes {
    ($(
        $name:literal [$($alias:literal),*] $plants:ident $params:ident $design:ident
        $kind:ident($tune:path, $build:expr, $describe:expr) $summary:literal $source:literal;
    )*) => {
        &[$(Scheme {
            name: $name,
            aliases: &[$($alias),*],
            summary: $summary,
            source: $source,
            plants: common::$plants,
            params: $params::<f64>::NAMES,
            design: $design::NAMES,
            describe: $describe,
            fns: SchemeFns::$kind { tune: $tune, build: $build },
        }),*]
    };
}

/// Every scheme, in listing order: adding one is its module (tuning and
/// construction) and its row here.
pub static SCHEMES: &[Scheme] = schemes! {
    "pid" [] STABLE_INT PidGains LambdaTuning
        Single(pid::tune_pid, both!(pid::build_pid), None)
        "plain PI/PID feedback, the baseline: IMC-PID (default), SIMC, or an ultimate-cycle rule (--rule)"
        "Bag (2022) Eqs. 3.19-3.27, Tables 3.2-3.3";
    "pi" [] STABLE_INT PidGains LambdaTuning
        Single(pid::tune_pi, both!(pid::build_pid), None)
        "plain PI feedback (td = 0): SIMC on the first-order model (default), or a PI ultimate-cycle rule (--rule)"
        "Bag (2022) Eqs. 3.19-3.27, Tables 3.2-3.3";
    "smith" ["sp"] STABLE_INT PidGains LambdaTuning
        Single(smith::tune_smith, by_order!(smith::build_smith), None)
        "classic Smith predictor; PI/PID by Kaya 2003 (lambda = L), IMC-PI for integrating plants"
        "Kaya (2003) Eqs. 18-33";
    "filtered-smith" [] STABLE FilteredSmithParams LambdaTuning
        Single(smith::tune_filtered_smith, by_order!(smith::build_filtered_smith), None)
        "Smith predictor with a filter F = (1 + a s)/(1 + b s) on the model error"
        "the MathWorks Smith predictor example";
    "huang" [] STABLE HuangParams LambdaTuning
        Single(smith::tune_huang, by_order!(smith::build_huang), None)
        "Smith predictor with Huang's approximate inverse of dead time F = (1+B)/(1+B e^-Ls)"
        "the MathWorks Smith predictor example";
    "watanabe-ito" ["wi"] INT PidGains LambdaTuning
        Single(integrating::tune_watanabe_ito, by_order!(integrating::build_watanabe_ito), None)
        "Watanabe-Ito predictor for integrating plants: the predictor's static gain removed"
        "Bag (2022) Sec. 4.4.1";
    "astrom-hang-lim" ["ahl"] INT AstromHangLimParams AstromHangLimTuning
        Single(integrating::tune_astrom_hang_lim, by_order!(integrating::build_astrom_hang_lim), None)
        "Astrom-Hang-Lim predictor for integrating plants: set-point and load responses decoupled"
        "Bag (2022) Sec. 4.4.2, Eqs. 4.13-4.17";
    "matausek-micic" ["mm"] INT MatausekMicicParams MatausekMicicTuning
        Single(integrating::tune_matausek_micic, by_order!(common::compensator<MatausekMicicParams>), None)
        "Matausek-Micic predictor for integrating plants: P set point, P load feedback"
        "Bag (2022) Sec. 4.4.3, refs [8], [52]";
    "kaya-atherton" ["ka", "pi-pd"] STABLE_INT KayaAthertonParams LambdaTuning
        Single(integrating::tune_kaya_atherton, by_order!(common::compensator<KayaAthertonParams>), None)
        "Kaya-Atherton PI-PD Smith predictor: Gc1 PI, Gc2 P/PD, Gc3 = kb(Td s+1)/(0.1 Td s+1)"
        "Bag (2022) Sec. 4.4.3, Eq. 4.18";
    "karan-dey" ["msp"] INT KaranDeyParams LambdaTuning
        Single(integrating::tune_karan_dey, by_order!(common::compensator<KaranDeyParams>), Some(integrating::describe_karan_dey))
        "Karan-Dey three-controller modified Smith predictor for integrating plants (lambda = L/4)"
        "Bag (2022) Sec. 4.5";
    "fsp" ["filtered-smith-unstable"] ALL FspParams FspTuning
        Single(fsp::tune_fsp, both!(fsp::build_fsp), Some(fsp::describe_fsp))
        "filtered Smith predictor for unstable, integrating and stable plants: Fr(z) from the Diophantine condition"
        "García et al. (2010) Sec. 3, Eq. 10";
    "disturbance-estimator" ["de"] INT DisturbanceEstimatorParams DisturbanceEstimatorTuning
        Single(disturbance_estimator::tune_disturbance_estimator, by_order!(common::compensator<DisturbanceEstimatorParams>), None)
        "Smith predictor with a disturbance estimator for integrating plants, cases 1-6 (--set case=N)"
        "Draganović et al. (2001)";
    "fspcc" [] ALL FspccParams FspccTuning
        Cascade(cascade::tune_fspcc, both!(cascade::build_fspcc), Some(cascade::describe_fspcc))
        "cascade: filtered Smith predictor (Fr from Eq. 10) outside an IMC inner loop"
        "García et al. (2010) Sec. 3.1, Figs. 5-6, Eq. 10";
    "gpcc" [] ALL GpccParams GpccTuning
        Cascade(cascade::tune_gpcc, both!(cascade::build_gpcc), Some(cascade::describe_gpcc))
        "cascade: generalized predictor (F1, F2, Gamma, Fk) outside an IMC inner loop"
        "García et al. (2010) Sec. 3.2, Fig. 7, Eqs. 1-4";
    "uma" ["uma-2009"] ALL UmaParams UmaTuning
        Cascade(cascade::tune_uma, both!(cascade::build_uma), None)
        "cascade competitor: Uma et al. 2009 modified Smith predictor (Gcs, Gcd, Gf; set Gcd's gains)"
        "García et al. (2010) Sec. 2.3, Fig. 4";
    "kaya-cascade" ["kaya-2008"] STABLE_INT KayaCascadeParams KayaCascadeTuning
        Cascade(cascade::tune_kaya_cascade, both!(cascade::build_kaya_cascade), None)
        "cascade competitor: Kaya et al. 2008 Smith predictor in the outer loop (Gc1, Gc3, Gd)"
        "García et al. (2010) Sec. 2.2, Fig. 3";
};

/// All scheme names.
pub fn names() -> Vec<&'static str> {
    SCHEMES.iter().map(|s| s.name).collect()
}

/// The scheme called `name` (or one of its aliases).
///
/// Every single-loop scheme, tuned by its source's rule and built for a
/// plant, runs behind the same [`crate::Controller`] interface:
///
/// ```
/// use msp::poly::TransferFunction;
/// use msp::registry::{self, Build};
/// let plant: TransferFunction = "0.2/s*e^-7.4s".parse()?;
/// let build = Build { ts: 0.074, u_min: f64::NEG_INFINITY, u_max: f64::INFINITY, max_dead_time: 0.0 };
/// for name in ["smith", "karan-dey", "watanabe-ito", "astrom-hang-lim", "fsp"] {
///     let scheme = registry::find(name)?;
///     let params = scheme.tune_with(&plant, None, &[])?;
///     let mut c = scheme.build_with(&params, &plant, &build)?;
///     assert!(c.update(1.0, 0.0) > 0.0, "{name}");
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn find(name: &str) -> Result<&'static Scheme, RegistryError> {
    let key = name.trim().to_ascii_lowercase().replace('_', "-");
    SCHEMES
        .iter()
        .find(|s| s.name == key || s.aliases.contains(&key.as_str()))
        .ok_or_else(|| RegistryError::UnknownScheme(name.to_string()))
}

/// The default scheme for a model: the Karan–Dey MSP for an IPDT model with
/// a dead time (the integrating case of Bag (2022)); for any other integrating
/// model whose half-rule reduction `K·e^{−θs}/(s(Ts + 1))` is dead-time
/// dominant (`θ ≥ T`, `θ > 0`), the Matausek–Micić predictor (tuned on that
/// reduction, it holds the whole model in its predictor); otherwise — lags
/// dominate, or no dead time at all, where a predictor has nothing to
/// compensate and a predictor tuned on `θ + T` can even destabilise
/// `2/(s(2s + 1)^2)` — the SIMC PID on the reduction, which rejects an input
/// load with zero steady error. The Smith predictor (Kaya tuning) for stable
/// models with a dead time, the PID (IMC-PID or SIMC) for delay-free ones,
/// the filtered Smith predictor for unstable ones.
pub fn default_for(model: &TransferFunction) -> Result<&'static Scheme, RegistryError> {
    match model.kind() {
        PlantKind::Integrating => match (model.exact_model(), model.integrating_half_rule()) {
            (Some(crate::model::ProcessModel::Ipdt(m)), _) if m.l > 0.0 => find("karan-dey"),
            (_, Some((theta, t))) if theta >= t && theta > 0.0 => find("matausek-micic"),
            _ => find("pid"),
        },
        // a predictor has no dead time to compensate on a delay-free plant:
        // the PID it would run anyway, named as what it is
        PlantKind::Stable if model.delay <= 0.0 => find("pid"),
        PlantKind::Stable => find("smith"),
        PlantKind::Unstable => find("fsp"),
    }
}

/// A cascade scheme asked for without the secondary process.
fn needs_inner() -> RegistryError {
    RegistryError::Core(crate::error::Error::Unsupported(
        "a cascade scheme needs the secondary process (--inner-plant)",
    ))
}
