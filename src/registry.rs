//! The scheme registry: name → tuning rule + construction + parameter names.
//!
//! The CLI and Python read this one table; adding a scheme means adding one
//! [`Scheme`] entry here.

use alloc::boxed::Box;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

use crate::delay::Delay;
use crate::dtc::{Controller, KaranDey, KaranDeyParams, SmithPredictor};
use crate::poly::{PlantKind, TransferFunction};
use crate::{tuning, Pid, PidConfig, ProcessModel};

/// Largest model order the registry's controllers hold.
pub const MAX_ORDER: usize = 8;

/// A controller built by the registry.
pub type DynController = Box<dyn Controller<f64> + Send + Sync>;

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

/// Design-time options for a tuning rule (from `--lambda` and `--set`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Design {
    /// Closed-loop time constant `λ` (s).
    pub lambda: Option<f64>,
    /// Kaya's speed factor `α` (`λ = α·L`).
    pub alpha: Option<f64>,
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
    /// Tuning rule: model → parameters.
    pub tune: fn(&TransferFunction, &Design) -> Result<Params, crate::Error>,
    /// Construction: parameters + model → controller.
    pub build: fn(&Params, &TransferFunction, &Build) -> Result<DynController, crate::Error>,
}

impl fmt::Debug for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Scheme").field("name", &self.name).finish()
    }
}

fn pid_cfg(p: &Params, b: &Build) -> Result<PidConfig<f64>, crate::Error> {
    let td = p.get("td").unwrap_or(0.0);
    Ok(PidConfig::isa(p.req("kp")?, p.req("ti")?, td, b.ts).with_limits(b.u_min, b.u_max))
}

fn lambda_for(model: &ProcessModel<f64>, d: &Design, default_factor: f64) -> f64 {
    match (d.lambda, d.alpha) {
        (Some(l), _) => l,
        (None, Some(a)) => a * model.delay(),
        (None, None) => default_factor * model.delay(),
    }
}

fn tune_pid(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    // SIMC (Skogestad 2003) on the half-rule model: τc = λ (default θ).
    let m = plant.reduce(true)?;
    let theta = m.delay();
    let tc = lambda_for(&m, d, 1.0);
    let (kp, ti, td) = match m {
        ProcessModel::Fopdt(f) => (f.t / (f.k * (tc + theta)), f.t.min(4.0 * (tc + theta)), 0.0),
        ProcessModel::Sopdt(s) => (
            s.t1 / (s.k * (tc + theta)),
            s.t1.min(4.0 * (tc + theta)),
            s.t2,
        ),
        ProcessModel::Ipdt(i) => (1.0 / (i.k * (tc + theta)), 4.0 * (tc + theta), 0.0),
        ProcessModel::Foipdt(i) => (1.0 / (i.k * (tc + theta)), 4.0 * (tc + theta), i.t),
        ProcessModel::Ufopdt(_) => {
            return Err(crate::Error::Unsupported(
                "SIMC tuning of an unstable plant",
            ))
        }
    };
    Ok(Params(alloc::vec![
        ("kp", kp),
        ("ti", ti),
        ("td", td),
        ("lambda", tc)
    ]))
}

fn build_pid(p: &Params, _m: &TransferFunction, b: &Build) -> Result<DynController, crate::Error> {
    Ok(Box::new(Pid::new(pid_cfg(p, b)?)?))
}

fn tune_smith(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let m = plant.reduce(plant.order() >= 2)?;
    let (g, lambda) = match m {
        ProcessModel::Ipdt(i) => {
            // The thesis compares the Smith predictor with the MSP's own PI (Sec. 5.2).
            let lambda = lambda_for(&m, d, 0.25);
            (tuning::imc_pi_integrating(&i, lambda)?, lambda)
        }
        _ => {
            let lambda = lambda_for(&m, d, 1.0);
            (tuning::kaya(&m, lambda)?, lambda)
        }
    };
    Ok(Params(alloc::vec![
        ("kp", g.kp),
        ("ti", g.ti),
        ("td", g.td),
        ("lambda", lambda)
    ]))
}

fn build_smith(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynController, crate::Error> {
    let lti = model.to_lti::<MAX_ORDER>(b.ts)?;
    let delay = Delay::<f64, Vec<f64>>::new_in(model.delay_samples(b.ts)?)?;
    Ok(Box::new(SmithPredictor::new(pid_cfg(p, b)?, lti, delay)?))
}

fn tune_karan_dey(plant: &TransferFunction, d: &Design) -> Result<Params, crate::Error> {
    let ProcessModel::Ipdt(m) = plant.reduce(false)? else {
        return Err(crate::Error::Unsupported(
            "the Karan-Dey MSP needs an integrating plant",
        ));
    };
    let lambda = lambda_for(&m.into(), d, 0.25);
    let k = tuning::karan_dey(&m, lambda)?;
    Ok(Params(alloc::vec![
        ("kp", k.kp),
        ("ti", k.ti),
        ("beta", k.beta),
        ("gamma", k.gamma),
        ("td", k.td),
        ("n", k.n),
        ("lambda", lambda),
    ]))
}

fn build_karan_dey(
    p: &Params,
    model: &TransferFunction,
    b: &Build,
) -> Result<DynController, crate::Error> {
    let params = KaranDeyParams {
        kp: p.req("kp")?,
        ti: p.req("ti")?,
        beta: p.req("beta")?,
        gamma: p.req("gamma")?,
        td: p.req("td")?,
        n: p.req("n")?,
    };
    let lti = model.to_lti::<MAX_ORDER>(b.ts)?;
    let delay = Delay::<f64, Vec<f64>>::new_in(model.delay_samples(b.ts)?)?;
    Ok(Box::new(
        KaranDey::new(params, lti, delay, b.ts)?.with_limits(b.u_min, b.u_max)?,
    ))
}

/// Every scheme, in listing order.
pub static SCHEMES: &[Scheme] = &[
    Scheme {
        name: "pid",
        aliases: &["pi"],
        summary: "plain PI/PID feedback (SIMC tuning on the half-rule model), the baseline",
        source: "000_3f0725a46e29ef08.txt ch. 3",
        plants: &[PlantKind::Stable, PlantKind::Integrating],
        params: &["kp", "ti", "td", "lambda"],
        design: &["lambda", "alpha"],
        tune: tune_pid,
        build: build_pid,
    },
    Scheme {
        name: "smith",
        aliases: &["sp"],
        summary: "classic Smith predictor; PI/PID by Kaya 2003 (lambda = L), IMC-PI for integrating plants",
        source: "001_8c052250023526e6.txt Eqs. 18-33",
        plants: &[PlantKind::Stable, PlantKind::Integrating],
        params: &["kp", "ti", "td", "lambda"],
        design: &["lambda", "alpha"],
        tune: tune_smith,
        build: build_smith,
    },
    Scheme {
        name: "karan-dey",
        aliases: &["msp"],
        summary: "Karan-Dey three-controller modified Smith predictor for integrating plants (lambda = L/4)",
        source: "000_3f0725a46e29ef08.txt Sec. 4.5",
        plants: &[PlantKind::Integrating],
        params: &["kp", "ti", "beta", "gamma", "td", "n", "lambda"],
        design: &["lambda", "alpha"],
        tune: tune_karan_dey,
        build: build_karan_dey,
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
/// the Smith predictor (Kaya tuning) for stable ones.
pub fn default_for(kind: PlantKind) -> Result<&'static Scheme, RegistryError> {
    match kind {
        PlantKind::Integrating => find("karan-dey"),
        PlantKind::Stable => find("smith"),
        PlantKind::Unstable => Err(RegistryError::PlantKind {
            scheme: "smith",
            kind,
            alternatives: SCHEMES
                .iter()
                .filter(|s| s.plants.contains(&kind))
                .map(|s| s.name)
                .collect(),
        }),
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
        let mut design = Design {
            lambda,
            alpha: None,
        };
        for (k, v) in overrides {
            match k.as_str() {
                "lambda" => design.lambda = Some(*v),
                "alpha" => design.alpha = Some(*v),
                _ => {}
            }
        }
        let mut params = (self.tune)(model, &design)?;
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
        Ok((self.build)(params, model, b)?)
    }
}
