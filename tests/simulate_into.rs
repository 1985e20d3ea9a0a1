//! `simulate_into` reuses an earlier result's buffers and gives exactly what
//! `simulate` gives; the set point follows `setpoint_at` sample for sample.
use msp::poly::TransferFunction;
use msp::registry::{find, Build};
use msp::sim::{setpoint_at, simulate, simulate_into, SetpointStep, SimConfig, SimResult};

fn run(
    scheme: &str,
    plant: &TransferFunction,
    cfg: &SimConfig,
    into: Option<&mut SimResult>,
) -> SimResult {
    let s = find(scheme).unwrap();
    let p = s.tune_with(plant, None, &[]).unwrap();
    let b = Build {
        ts: cfg.ts,
        u_min: f64::NEG_INFINITY,
        u_max: f64::INFINITY,
    };
    let mut c = s.build_with(&p, plant, &b).unwrap();
    match into {
        None => simulate(plant, &mut c, cfg).unwrap(),
        Some(out) => {
            simulate_into(plant, &mut c, cfg, out).unwrap();
            out.clone()
        }
    }
}

#[test]
fn a_reused_result_equals_a_fresh_one() {
    let plant: TransferFunction = "0.2/s*e^-7.4s".parse().unwrap();
    let long = SimConfig::new(0.074, 60.0);
    let short = SimConfig::new(0.074, 20.0);
    let mut out = SimResult::default();
    // a long run with other signal names first, then shorter runs into the same buffers
    run("karan-dey", &plant, &long, Some(&mut out));
    for (scheme, cfg) in [("smith", &short), ("smith", &long), ("karan-dey", &short)] {
        let fresh = run(scheme, &plant, cfg, None);
        let reused = run(scheme, &plant, cfg, Some(&mut out));
        assert_eq!(fresh, reused, "{scheme}");
    }
}

#[test]
fn the_set_point_column_follows_setpoint_at() {
    let plant: TransferFunction = "5.6*e^-93.9s/(40.2s+1)".parse().unwrap();
    let ts = 0.1;
    // step times on and next to sample instants, where rounding decides
    let steps = vec![
        SetpointStep {
            value: 1.0,
            at: 0.0,
        },
        SetpointStep {
            value: 2.0,
            at: 0.3,
        },
        SetpointStep {
            value: 3.0,
            at: 0.7000000001,
        },
        SetpointStep {
            value: 4.0,
            at: 1.1 - 1e-12,
        },
        SetpointStep {
            value: -1.0,
            at: 2.05,
        },
        SetpointStep {
            value: 0.5,
            at: 2.05,
        },
    ];
    let cfg = SimConfig {
        setpoint: steps.clone(),
        ..SimConfig::new(ts, 5.0)
    };
    let res = run("smith", &plant, &cfg, None);
    for (t, r) in res.t.iter().zip(&res.r) {
        assert_eq!(*r, setpoint_at(&steps, *t), "t = {t}");
    }
}
