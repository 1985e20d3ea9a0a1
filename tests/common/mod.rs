#![allow(dead_code, missing_docs)]

/// `|a − b| ≤ atol + rtol·|b|`.
pub fn close(a: f64, b: f64, rtol: f64, atol: f64) -> bool {
    (a - b).abs() <= atol + rtol * b.abs()
}

#[track_caller]
pub fn assert_close(a: f64, b: f64, rtol: f64, atol: f64) {
    assert!(
        close(a, b, rtol, atol),
        "{a} is not within rtol {rtol}, atol {atol} of {b}"
    );
}

/// García et al.'s Example 2 cascade process (García et al. (2010)):
/// the integrating primary and the secondary.
pub const EXAMPLE2: (&str, &str) = ("2e^-2s/s", "4e^-2s/(s+1)");

/// The `--set` values a scheme needs beyond its tuning: Uma et al.'s
/// disturbance controller `Gcd` has no rule in the sources, so it gets the PD
/// of García et al.'s Example 2; every other scheme none.
pub fn required_settings(scheme: &str) -> Vec<(String, f64)> {
    if scheme == "uma" {
        vec![
            ("kpd".into(), 0.0436),
            ("kid".into(), 0.0),
            ("kdd".into(), 0.1206),
        ]
    } else {
        vec![]
    }
}

/// A plant the scheme can control, its secondary process for a cascade
/// scheme, and a sample period: García et al.'s Example 2 for a cascade, the
/// thesis's integrating plant (Bag (2022)), the MathWorks example's stable
/// plant, García et al.'s unstable plant.
pub fn plant_for(
    scheme: &msp::registry::Scheme,
) -> (
    msp::poly::TransferFunction,
    Option<msp::poly::TransferFunction>,
    f64,
) {
    use msp::poly::PlantKind;
    let tf = |s: &str| s.parse::<msp::poly::TransferFunction>().unwrap();
    if scheme.is_cascade() {
        (tf(EXAMPLE2.0), Some(tf(EXAMPLE2.1)), 0.1)
    } else if scheme.plants.contains(&PlantKind::Integrating) {
        (tf("0.2/s*e^-7.4s"), None, 0.074)
    } else if scheme.plants.contains(&PlantKind::Stable) {
        (tf("5.6*e^-93.9s/(40.2s+1)"), None, 0.939)
    } else {
        (tf("5*e^-6s/(100s-1)"), None, 0.06)
    }
}

/// A scheme tuned for its [`plant_for`] plant (with the settings it needs)
/// and the build options of the tests that run it in a loop: actuator
/// limits ±10, `max_dead_time` seconds of room for the model's dead time.
pub struct Tuned {
    pub scheme: &'static msp::registry::Scheme,
    pub p1: msp::poly::TransferFunction,
    pub p2: Option<msp::poly::TransferFunction>,
    pub ts: f64,
    pub params: msp::registry::Params,
    pub build: msp::registry::Build,
}

/// The build options of the tests' loops: period `ts`, actuator limits ±10,
/// no room beyond the model's dead time.
#[allow(dead_code)] // not every test file builds a controller
pub fn limits(ts: f64) -> msp::registry::Build {
    msp::registry::Build {
        ts,
        u_min: -10.0,
        u_max: 10.0,
        max_dead_time: 0.0,
    }
}

pub fn tuned(scheme: &'static msp::registry::Scheme, max_dead_time: f64) -> Tuned {
    let (p1, p2, ts) = plant_for(scheme);
    let set = required_settings(scheme.name);
    let params = scheme
        .tune_process(&p1, p2.as_ref(), None, None, &set)
        .unwrap_or_else(|e| panic!("{}: {e}", scheme.name));
    let build = msp::registry::Build {
        max_dead_time,
        ..limits(ts)
    };
    Tuned {
        scheme,
        p1,
        p2,
        ts,
        params,
        build,
    }
}

// not every test file uses every helper
#[allow(dead_code)]
impl Tuned {
    /// The tuned controller in precision `T`, for the plant.
    pub fn controller<T: msp::registry::Precision>(&self) -> msp::registry::DynControllerOf<T> {
        self.controller_of(&self.params)
    }

    /// The controller of the parameters `p`, in precision `T`, for the plant.
    pub fn controller_of<T: msp::registry::Precision>(
        &self,
        p: &msp::registry::Params,
    ) -> msp::registry::DynControllerOf<T> {
        self.scheme
            .build_process_as::<T>(p, &self.p1, self.p2.as_ref(), &self.build)
            .unwrap_or_else(|e| panic!("{}: {e}", self.scheme.name))
    }

    /// The scheme tuned again for the plant with `--set name=value` after
    /// the settings it needs.
    pub fn retune(
        &self,
        name: &str,
        value: f64,
    ) -> Result<msp::registry::Params, msp::registry::RegistryError> {
        let mut set = required_settings(self.scheme.name);
        set.push((name.to_string(), value));
        self.scheme
            .tune_process(&self.p1, self.p2.as_ref(), None, None, &set)
    }
}

/// White Gaussian noise of unit deviation: Box–Muller on a xorshift64
/// stream from `state` (nonzero), deterministic.
pub fn gaussian(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        let mut uni = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (u1, u2) = (uni(), uni());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

// the schemes' tests (schemes.rs, scheme_runs.rs): a scenario and its run
use msp::sim::Disturbance;
use msp::study::{RunOutput, Scenario};

/// The default scenario on `plant`.
pub fn scenario(plant: &str) -> Scenario {
    Scenario {
        plant: Some(plant.parse().unwrap_or_else(|e| panic!("{plant}: {e}"))),
        ..Default::default()
    }
}

pub fn run(plant: &str, controller: &str, f: impl FnOnce(&mut Scenario)) -> RunOutput {
    let mut sc = Scenario {
        controller: Some(controller.into()),
        ..scenario(plant)
    };
    f(&mut sc);
    sc.run().unwrap_or_else(|e| panic!("{controller}: {e}"))
}

pub fn load(value: f64, at: f64) -> Disturbance {
    Disturbance::input_step(value, at)
}

pub fn set(sc: &mut Scenario, kv: &[(&str, f64)]) {
    for (k, v) in kv {
        sc.set.insert((*k).into(), *v);
    }
}

pub const IPDT: &str = "0.2/s*e^-7.4s";
