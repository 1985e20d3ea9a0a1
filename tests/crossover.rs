//! A PI or PID designed at a crossover with a phase margin (`--target
//! wc=…,pm=…`, MATLAB `pidtune(G, 'PI', wc)` with its `PhaseMargin`
//! option): `pidtune`'s published numbers, and on many plants the loop
//! `G·C` at `ωc` evaluated independently (the plant's complex response with
//! the exact delay, the controller's from its gains) against
//! `e^{j(−π + φm)}`.
use msp::model::{Foipdt, Fopdt, Ipdt, ProcessModel, Sopdt, Ufopdt};
use msp::poly::TransferFunction;
use msp::study::Scenario;
use msp::tuning::{at_crossover, pi_at, pid_at, PidGains};

/// `C(jω)` of the ISA PID `Kp(1 + 1/(Ti jω) + Td jω)`, as `(re, im)`.
fn controller(g: &PidGains<f64>, w: f64) -> (f64, f64) {
    (g.kp, g.kp * (g.td * w - 1.0 / (g.ti * w)))
}

/// `L(jωc) = G(jωc)·C(jωc)` from the plant's own complex response.
fn open_loop(plant: &TransferFunction, g: &PidGains<f64>, w: f64) -> (f64, f64) {
    let (gr, gi) = plant.freq(w);
    let (cr, ci) = controller(g, w);
    (gr * cr - gi * ci, gr * ci + gi * cr)
}

/// The MathWorks Smith predictor example's PI baseline: `pidtune(P,
/// pidstd(1,1), 0.006)` (default phase margin 60°) prints `Kp = 0.0501`,
/// `Ti = 47.3` for `P = 5.6 e^{−93.9s}/(40.2s + 1)`; through the library,
/// the model and the study alike.
#[test]
fn pidtunes_pi_for_the_mathworks_example() {
    let round = |g: &PidGains<f64>| ((g.kp * 1e4).round() / 1e4, (g.ti * 10.0).round() / 10.0);
    let w = 0.006;
    let plant: TransferFunction = "5.6e^-93.9s/(40.2s+1)".parse().unwrap();
    let (re, im) = plant.freq(w);
    let g = pi_at(re.hypot(im), plant.phase(w).unwrap(), w, 60.0).unwrap();
    assert_eq!(round(&g), (0.0501, 47.3));
    let m: ProcessModel<f64> = Fopdt::new(5.6, 40.2, 93.9).unwrap().into();
    assert_eq!(
        round(&at_crossover(&m, w, 60.0, false).unwrap()),
        (0.0501, 47.3)
    );
    let sc = Scenario {
        plant: Some(plant.clone()),
        controller: Some("pi".into()),
        target: Some("wc=0.006,pm=60".parse().unwrap()),
        ..Default::default()
    };
    let t = sc.tune_for(&plant, None).unwrap();
    let (kp, ti) = (t.params.get("kp").unwrap(), t.params.get("ti").unwrap());
    assert_eq!(
        ((kp * 1e4).round() / 1e4, (ti * 10.0).round() / 10.0),
        (0.0501, 47.3)
    );
    // the sampled loop it runs as (Ts = 0.0939 s: ωc·Ts is 6e-4 rad) keeps
    // the figures to a tenth of a degree and a part in a thousand
    let r = t.target.unwrap();
    assert!(r.lambda.is_none());
    assert!((r.pm_achieved.unwrap() - 60.0).abs() < 0.1, "{r:?}");
    assert!((r.achieved / 0.006 - 1.0).abs() < 1e-3, "{r:?}");
}

/// On FOPDT, SOPDT, IPDT, FOIPDT and unstable FOPDT models, positive and
/// negative gains, at crossovers and phase margins across what a PI (a
/// lag of 0 to 90°) or a PID (±90°) can give: `|L(jωc)| = 1` and
/// `arg L(jωc) = −180° + φm` to 1e-9, with the plant's response from the
/// transfer function (not the closed forms the design used); where the
/// controller cannot give the phase, an error, never a wrong design.
#[test]
fn the_loop_crosses_at_wc_with_the_phase_margin_on_many_plants() {
    let models: Vec<ProcessModel<f64>> = vec![
        Fopdt::new(2.0, 4.0, 3.0).unwrap().into(),
        Fopdt::new(-0.7, 12.0, 1.5).unwrap().into(),
        Sopdt::new(1.3, 6.0, 2.0, 4.0).unwrap().into(),
        Ipdt::new(0.2, 7.4).unwrap().into(),
        Foipdt::new(0.05, 3.0, 6.0).unwrap().into(),
        Ufopdt::new(5.0, 100.0, 6.0).unwrap().into(),
    ];
    let (mut designed, mut refused) = (0, 0);
    for m in &models {
        let plant = TransferFunction::from_model(m);
        let theta = m.delay();
        for wf in [0.02, 0.05, 0.1, 0.2, 0.3, 0.5] {
            let w = wf / theta;
            for pm in [30.0, 45.0, 60.0, 75.0] {
                for derivative in [false, true] {
                    match at_crossover(m, w, pm, derivative) {
                        Ok(g) => {
                            designed += 1;
                            assert!(g.ti > 0.0 && g.td >= 0.0, "{m:?} {w} {pm}: {g:?}");
                            let (lr, li) = open_loop(&plant, &g, w);
                            let want = (-180f64 + pm).to_radians();
                            assert!(
                                (lr - want.cos()).abs() < 1e-9 && (li - want.sin()).abs() < 1e-9,
                                "{m:?} at {w} rad/s, pm {pm}, derivative {derivative}: L = {lr} + {li}j"
                            );
                        }
                        Err(e) => {
                            refused += 1;
                            assert!(e.to_string().contains("crossover"), "{m:?} {w} {pm}: {e}");
                        }
                    }
                }
            }
        }
    }
    // (both outcomes occur: the test reaches the refusals too)
    assert!(
        designed > 150 && refused > 10,
        "{designed} designed, {refused} refused"
    );
}

/// The closed-form response of the models is the transfer function's:
/// the gain, and the unwrapped phase of `TransferFunction::phase` (with the
/// reverse-acting half turn taken out), at frequencies up to past the
/// third phase crossing.
#[test]
fn the_models_frequency_response_is_the_transfer_functions() {
    let models: Vec<ProcessModel<f64>> = vec![
        Fopdt::new(-2.0, 4.0, 3.0).unwrap().into(),
        Sopdt::new(1.3, 6.0, 2.0, 4.0).unwrap().into(),
        Ipdt::new(0.2, 7.4).unwrap().into(),
        Foipdt::new(0.05, 3.0, 6.0).unwrap().into(),
        Ufopdt::new(5.0, 100.0, 6.0).unwrap().into(),
    ];
    for m in &models {
        let plant = TransferFunction::from_model(m);
        for i in 1..200 {
            let w = f64::from(i) * 0.01;
            let (gain, phase) = m.frequency_response(w);
            let (re, im) = plant.freq(w);
            let turn = if plant.lead_sign() < 0.0 {
                std::f64::consts::PI
            } else {
                0.0
            };
            assert!((gain / re.hypot(im) - 1.0).abs() < 1e-12, "{m:?} {w}");
            assert!(
                (phase - (plant.phase(w).unwrap() + turn)).abs() < 1e-9,
                "{m:?} {w}"
            );
        }
    }
}

/// What a PI cannot do is said: the loop asking the controller to lead
/// (the crossover past the plant's `−180° + φm`), or to lag by 90° or more;
/// out-of-range inputs are refused by name.
#[test]
fn impossible_crossovers_are_refused_with_the_reason() {
    let m: ProcessModel<f64> = Fopdt::new(5.6, 40.2, 93.9).unwrap().into();
    let lead = at_crossover(&m, 0.1, 60.0, false).unwrap_err().to_string();
    assert!(
        lead.contains("a PI only lags") && lead.contains("lower crossover"),
        "{lead}"
    );
    let lag = at_crossover(&m, 1e-4, 30.0, false).unwrap_err().to_string();
    assert!(
        lag.contains("90°") && lag.contains("higher crossover"),
        "{lag}"
    );
    assert!(pi_at(1.0, -1.0, 0.0, 60.0).is_err());
    assert!(pi_at(1.0, -1.0, 0.1, 180.0).is_err());
    assert!(pid_at(f64::NAN, -1.0, 0.1, 60.0).is_err());
    // and through the study: only a PI or a PID, never beside --lambda
    let plant: TransferFunction = "5.6e^-93.9s/(40.2s+1)".parse().unwrap();
    let base = Scenario {
        plant: Some(plant.clone()),
        target: Some("wc=0.006,pm=60".parse().unwrap()),
        ..Default::default()
    };
    let smith = Scenario {
        controller: Some("smith".into()),
        ..base.clone()
    };
    assert!(smith
        .tune_for(&plant, None)
        .unwrap_err()
        .to_string()
        .contains("PI or a PID"));
    let both = Scenario {
        controller: Some("pi".into()),
        lambda: Some(10.0),
        ..base
    };
    assert!(both.tune_for(&plant, None).is_err());
    // a --set beside it (a gain, the λ rule's alpha, a typo) is refused,
    // never dropped
    for name in ["kp", "alpha", "kpp"] {
        let mut given = both.clone();
        given.lambda = None;
        given.set.insert(name.into(), 1.0);
        let e = given.tune_for(&plant, None).unwrap_err().to_string();
        assert!(
            e.contains(name) && (e.contains("drop --set") || e.contains("no parameter")),
            "{e}"
        );
    }
    assert!("wc=0.006,ms=1.4".parse::<msp::study::Target>().is_err());
    assert_eq!(
        "pm=45,wc=0.2"
            .parse::<msp::study::Target>()
            .unwrap()
            .to_string(),
        "wc=0.2,pm=45"
    );
}
