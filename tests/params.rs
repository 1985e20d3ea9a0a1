//! A scheme's parameters are its type's fields: the names the registry lists,
//! reports and accepts in `--set` are exactly the serde keys of the scheme's
//! parameter struct, and a name the type does not have is refused.
mod common;
use msp::dtc::astrom_hang_lim::AstromHangLimParams;
use msp::dtc::cascade::{FspccParams, GpccParams, KayaCascadeParams, UmaParams};
use msp::dtc::disturbance_estimator::DisturbanceEstimatorParams;
use msp::dtc::filtered_smith::FilteredSmithParams;
use msp::dtc::fsp::FspParams;
use msp::dtc::huang::HuangParams;
use msp::dtc::kaya_atherton::KayaAthertonParams;
use msp::dtc::matausek_micic::MatausekMicicParams;
use msp::dtc::KaranDeyParams;
use msp::registry::{RegistryError, SCHEMES};
use msp::tuning::PidGains;
use serde::{de::DeserializeOwned, Serialize};

/// The serde keys of `P`, in order.
fn keys<P: Default + Serialize>() -> Vec<String> {
    match serde_json::to_value(P::default()).unwrap() {
        serde_json::Value::Object(m) => m.keys().cloned().collect(),
        v => panic!("not a struct: {v}"),
    }
}

/// Deserializes a JSON object into a parameter struct.
type Deserialize = fn(serde_json::Value) -> Result<(), String>;

/// The scheme's typed struct, by the scheme's name: its serde keys, and a
/// check that a scheme's reported parameters deserialize into it.
fn typed(scheme: &str) -> (Vec<String>, Deserialize) {
    fn de<P: DeserializeOwned>(v: serde_json::Value) -> Result<(), String> {
        serde_json::from_value::<P>(v)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
    macro_rules! of {
        ($t:ty) => {
            (keys::<$t>(), de::<$t>)
        };
    }
    match scheme {
        "pid" | "pi" | "smith" | "watanabe-ito" => of!(PidGains),
        "filtered-smith" => of!(FilteredSmithParams),
        "huang" => of!(HuangParams),
        "astrom-hang-lim" => of!(AstromHangLimParams),
        "matausek-micic" => of!(MatausekMicicParams),
        "kaya-atherton" => of!(KayaAthertonParams),
        "karan-dey" => of!(KaranDeyParams),
        "fsp" => of!(FspParams),
        "disturbance-estimator" => of!(DisturbanceEstimatorParams),
        "fspcc" => of!(FspccParams),
        "gpcc" => of!(GpccParams),
        "uma" => of!(UmaParams),
        "kaya-cascade" => of!(KayaCascadeParams),
        other => panic!("scheme {other} has no entry here: add its parameter struct"),
    }
}

#[test]
fn every_scheme_lists_exactly_its_types_fields() {
    let mut sorted: Vec<&str> = SCHEMES.iter().map(|s| s.name).collect();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), SCHEMES.len(), "scheme names are unique");
    for s in SCHEMES {
        let (fields, _) = typed(s.name);
        let mut listed: Vec<String> = s.params.iter().map(|n| n.to_string()).collect();
        listed.sort_unstable();
        assert_eq!(listed, fields, "{}", s.name);
    }
}

#[test]
fn the_tuned_parameters_are_the_type_and_set_reaches_only_its_fields() {
    for s in SCHEMES {
        let t = common::tuned(s, 0.0);
        let tuned = &t.params;

        // the report's parameters (without the design value lambda) are the struct
        let mut report = serde_json::to_value(tuned).unwrap();
        let lambda = report.as_object_mut().unwrap().remove("lambda");
        assert_eq!(lambda.is_some(), tuned.lambda().is_some(), "{}", s.name);
        let (_, de) = typed(s.name);
        // NaN (an unset gain) is written as null, which the struct does not take
        let finite = report.as_object().unwrap().values().all(|v| !v.is_null());
        if finite {
            de(report.clone()).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        }
        let mut extra = report.clone();
        extra["not_a_field"] = 1.0.into();
        assert!(
            de(extra).is_err(),
            "{}: an unknown key was accepted",
            s.name
        );

        // every field can be set after tuning, and the controller reports it
        for (i, name) in s.params.iter().enumerate() {
            if s.design.contains(name) {
                continue; // a design key re-tunes: checked by its own scheme tests
            }
            let v = tuned.get(name).unwrap();
            let p = t
                .retune(name, v)
                .unwrap_or_else(|e| panic!("{} {name}: {e}", s.name));
            assert_eq!(p.get(name).map(f64::to_bits), Some(v.to_bits()));
            let c = t.controller_of::<f64>(&p);
            if !c.param_names().is_empty() {
                assert_eq!(c.param_names().get(i), Some(name), "{}", s.name);
            }
        }

        // a name of another scheme's type, or none, is refused with the type's names
        for bogus in ["not_a_field", "kb", "beta", "k3", "tk", "lambda2"] {
            if s.params.contains(&bogus) || s.design.contains(&bogus) {
                continue;
            }
            match t.retune(bogus, 1.0) {
                Err(RegistryError::UnknownParam { name, allowed, .. }) => {
                    assert_eq!(name, bogus);
                    for f in s.params {
                        assert!(allowed.contains(f), "{}: {f} not offered", s.name);
                    }
                }
                other => panic!("{} accepted {bogus}: {other:?}", s.name),
            }
        }
    }
}

/// Every design key a scheme lists (its typed design struct's fields) reaches
/// its tuning: setting it changes the tuned parameters. A field declared but
/// never read by the rule fails here.
#[test]
fn every_design_key_is_read_by_its_tuning() {
    for s in SCHEMES {
        let t = common::tuned(s, 0.0);
        let bits = |p: &msp::registry::Params| -> Vec<u64> {
            p.iter()
                .map(|(_, v)| v.to_bits())
                .chain(p.lambda().map(f64::to_bits))
                .collect()
        };
        assert_eq!(&s.design[..2], &["lambda", "alpha"], "{}", s.name);
        for key in s.design {
            // a value no default takes: case 2 of the estimator, else 0.37 or 3.7
            let candidates: &[f64] = if *key == "case" { &[2.0] } else { &[0.37, 3.7] };
            let changed = candidates
                .iter()
                .any(|v| t.retune(key, *v).is_ok_and(|p| bits(&p) != bits(&t.params)));
            assert!(changed, "{}: --set {key}=… changes nothing", s.name);
        }
    }
}
