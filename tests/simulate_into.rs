//! `simulate_into` reuses an earlier result's buffers and gives exactly what
//! `simulate` gives; the set point follows `setpoint_at` sample for sample.
use msp::poly::TransferFunction;
use msp::registry::{find, Build};
use msp::sim::{
    setpoint_at, simulate, simulate_into, Disturbance, Location, SetpointStep, Shape, SimConfig,
    SimResult,
};

fn run(
    scheme: &str,
    plant: &TransferFunction,
    cfg: &SimConfig,
    into: Option<&mut SimResult>,
) -> SimResult {
    let s = find(scheme).unwrap();
    let p = s.tune_with(plant, None, &[]).unwrap();
    let b = Build::unlimited(cfg.ts);
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
    // a long run with other signal names and loads first (the load columns
    // of the runs after it must not keep them), then runs into the same buffers
    let mut loaded = long.clone();
    loaded.disturbances = [Location::Input, Location::Output]
        .into_iter()
        .map(|location| Disturbance {
            location,
            shape: Shape::Step,
            value: 0.1,
            at: 5.0,
            freq: 0.0,
        })
        .collect();
    run("karan-dey", &plant, &loaded, Some(&mut out));
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

/// The disturbance columns are the closed-form sums of every disturbance at
/// every sample (steps from their instant, ramps `v·(t − at)`, sines
/// `v·sin(2πf(t − at))`), whatever their number and order in the scenario.
#[test]
fn disturbance_events_equal_the_closed_form_sums() {
    use msp::sim::{Disturbance, Location, Shape};
    let plant: TransferFunction = "2*e^-0.5s/(3s+1)".parse().unwrap();
    let ts = 0.05;
    // out of time order, ties, a step between samples, and moving shapes
    let mut ds = Vec::new();
    for k in 0..40 {
        let at = ((k * 7919) % 97) as f64 * 0.031;
        let shape = match k % 5 {
            3 => Shape::Ramp,
            4 => Shape::Sine,
            _ => Shape::Step,
        };
        ds.push(Disturbance {
            location: if k % 2 == 0 {
                Location::Input
            } else {
                Location::Output
            },
            shape,
            value: 0.01 * (k as f64 - 20.0),
            at,
            freq: 0.3,
        });
    }
    let cfg = SimConfig {
        disturbances: ds.clone(),
        ..SimConfig::new(ts, 4.0)
    };
    let res = run("smith", &plant, &cfg, None);
    let closed_form = |loc: Location, t: f64| -> f64 {
        ds.iter()
            .filter(|d| d.location == loc && d.at <= t + 1e-9 * t.abs().max(1.0))
            .map(|d| {
                let dt = (t - d.at).max(0.0);
                match d.shape {
                    Shape::Step => d.value,
                    Shape::Ramp => d.value * dt,
                    Shape::Sine => d.value * (std::f64::consts::TAU * d.freq * dt).sin(),
                }
            })
            .sum()
    };
    // summed in another order: equal to the rounding of some 40 terms
    for (i, t) in res.t.iter().enumerate() {
        let (a, b) = (res.d[i], closed_form(Location::Input, *t));
        assert!((a - b).abs() <= 1e-13, "input at t = {t}: {a} vs {b}");
        let (a, b) = (res.d_out[i], closed_form(Location::Output, *t));
        assert!((a - b).abs() <= 1e-13, "output at t = {t}: {a} vs {b}");
    }
}

/// Recording only `t`, `y` and `u` changes nothing in them.
#[test]
fn recording_less_gives_the_same_loop() {
    use msp::sim::{Disturbance, Location, Record, Shape};
    let plant: TransferFunction = "5.6*e^-93.9s/(40.2s+1)".parse().unwrap();
    let full = SimConfig {
        setpoint: vec![SetpointStep {
            value: 1.0,
            at: 0.0,
        }],
        disturbances: vec![Disturbance {
            location: Location::Input,
            shape: Shape::Step,
            value: -0.1,
            at: 400.0,
            freq: 0.0,
        }],
        noise: 0.01,
        seed: 7,
        ..SimConfig::new(1.0, 800.0)
    };
    let lean = SimConfig {
        record: Record::OutputAndInput,
        ..full.clone()
    };
    let a = run("smith", &plant, &full, None);
    let mut reused = a.clone();
    let b = run("smith", &plant, &lean, Some(&mut reused));
    assert_eq!((&a.t, &a.y, &a.u), (&b.t, &b.y, &b.u));
    assert!(b.r.is_empty() && b.d.is_empty() && b.signals.is_empty());
    assert!(!a.r.is_empty() && !a.signals.is_empty());
}

/// The engine's plain loop (one plant in one piece, step schedules only) is
/// the general loop compiled without what it does not need: a zero ramp
/// disturbance sends the same run through the general loop, and every
/// recorded column agrees to the bit — with set-point steps, load and output
/// steps ending segments, a divergence-free run to the end, and every column.
#[test]
fn the_plain_loop_is_the_general_loop() {
    use msp::sim::{Disturbance, Location, Record, Shape};
    let plant: TransferFunction = "5.6*e^-93.9s/(40.2s+1)".parse().unwrap();
    let step = |location, value, at| Disturbance {
        location,
        shape: Shape::Step,
        value,
        at,
        freq: 0.0,
    };
    for record in [Record::All, Record::OutputAndInput] {
        let plain = SimConfig {
            setpoint: vec!["1@0".parse().unwrap(), "2@300".parse().unwrap()],
            disturbances: vec![
                step(Location::Input, -0.1, 150.0),
                step(Location::Output, 0.05, 450.0),
            ],
            record,
            ..SimConfig::new(0.939, 600.0)
        };
        let mut general = plain.clone();
        general.disturbances.push(Disturbance {
            shape: Shape::Ramp,
            ..step(Location::Input, 0.0, 10.0)
        });
        for scheme in ["smith", "pi", "huang", "fsp"] {
            let a = run(scheme, &plant, &plain, None);
            let b = run(scheme, &plant, &general, None);
            assert!(a.y.len() > 600, "{scheme}: {} rows", a.y.len());
            assert_eq!(a, b, "{scheme}, {record:?}");
        }
    }
}

/// A quantized measurement: the controller sees the noisy output rounded to
/// the resolution — a PI controller's proportional term `Kp·(r − y_meas)`,
/// with `r` on the grid, is `Kp` times a multiple of the step at every
/// sample; without quantization the noise puts it off the grid.
#[test]
fn the_controller_sees_the_quantized_measurement() {
    let plant: TransferFunction = "1*e^-1s/(4s+1)".parse().unwrap();
    let q = 1.0 / 64.0;
    let mut cfg = SimConfig::new(0.1, 30.0);
    cfg.setpoint = vec![SetpointStep {
        value: 1.0,
        at: 0.0,
    }];
    cfg.noise = 0.01;
    cfg.seed = 3;
    let kp = find("pi")
        .unwrap()
        .tune_with(&plant, None, &[])
        .unwrap()
        .get("kp")
        .unwrap();
    let off_grid = |cfg: &SimConfig| {
        let r = run("pi", &plant, cfg, None);
        let (_, p) = r.signals.iter().find(|(n, _)| n == "p_term").unwrap();
        p.iter()
            .filter(|p| {
                let steps = *p / kp / q;
                (steps - steps.round()).abs() > 1e-6
            })
            .count()
    };
    assert!(off_grid(&cfg) > 100);
    cfg.quantization = q;
    assert_eq!(off_grid(&cfg), 0);
}
