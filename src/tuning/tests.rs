use super::*;
use crate::{model::Fopdt, model::Sopdt};

#[test]
fn kaya_examples_2_and_3() -> Result<(), Box<dyn std::error::Error>> {
    // Kaya (2003) Example 2: FOPDT e^{-10.87s}/(1.27s+1), α = 0.5 → Kc = 0.234, Ti = 1.27
    let m = ProcessModel::Fopdt(Fopdt::<f64>::new(1.0, 1.27, 10.87)?);
    let g = kaya_alpha(&m, 0.5)?;
    assert!((g.kp - 0.234).abs() < 5e-4, "{}", g.kp);
    assert_eq!(g.ti, 1.27);
    // SOPDT e^{-10s}/(s+1)^2, α = 0.5 → Kc = 0.400, Ti = 2, Td = 0.5
    let m = ProcessModel::Sopdt(Sopdt::<f64>::new(1.0, 1.0, 1.0, 10.0)?);
    let g = kaya_alpha(&m, 0.5)?;
    assert!((g.kp - 0.4).abs() < 1e-12);
    assert_eq!((g.ti, g.td), (2.0, 0.5));
    Ok(())
}

#[test]
fn imc_pid_and_simc() -> Result<(), Box<dyn std::error::Error>> {
    let m = Fopdt::<f64>::new(2.0, 10.0, 4.0)?;
    let g = imc_pid(&m, 4.0)?;
    assert!((g.kp - 12.0 / (2.0 * 6.0)).abs() < 1e-12);
    assert_eq!(g.ti, 12.0);
    assert!((g.td - 40.0 / 24.0).abs() < 1e-12);
    let s = simc(&m.into(), 4.0)?;
    assert!((s.kp - 10.0 / 16.0).abs() < 1e-12 && s.ti == 10.0);
    Ok(())
}

#[test]
fn disturbance_estimator_matches_the_paper() -> Result<(), Box<dyn std::error::Error>> {
    // Draganović et al. (2001) Sec. 4: Kv = 1, L = 6.8
    let d = |case, tde, alpha| EstimatorDesign {
        case,
        tde,
        alpha,
        w0: 0.05,
    };
    let t = |case, tde: f64, alpha: f64| {
        disturbance_estimator(1.0f64, 6.8, &d(case, tde, alpha)).unwrap_or(EstimatorTuning {
            ka: f64::NAN,
            ta: f64::NAN,
            tc: f64::NAN,
            estimator: crate::dtc::disturbance_estimator::Estimator {
                a: [f64::NAN; 3],
                c: [f64::NAN; 3],
            },
        })
    };
    assert!((t(1, 0.0, 0.5).ka - 0.074).abs() < 5e-4);
    assert!((t(2, 0.0, 0.5).ka - 0.136).abs() < 5e-4);
    let c3 = t(3, 0.55 * 6.8, 0.5);
    assert!(
        (c3.ka - 0.089).abs() < 5e-4 && (c3.ta - 3.4).abs() < 0.01 && (c3.tc - 1.36).abs() < 0.02
    );
    let c4 = t(4, 0.0, 0.5);
    assert!(
        (c4.ka - 0.065).abs() < 5e-4 && (c4.ta - 42.636).abs() < 0.02,
        "{c4:?}"
    );
    let c5 = t(5, 0.0, 0.7);
    assert!(
        (c5.ka - 0.077).abs() < 5e-4 && (c5.ta - 33.728).abs() < 0.06,
        "{c5:?}"
    );
    let c5b = t(5, 0.0, 0.85);
    assert!((c5b.ka - 0.092).abs() < 5e-4 && (c5b.ta - 25.4456).abs() < 0.01);
    Ok(())
}

#[test]
fn ultimate_rules() -> Result<(), Box<dyn std::error::Error>> {
    let zn = ultimate_rule("zn").ok_or("no rule zn")?;
    let g = ultimate_cycle(zn, 2.0f64, 10.0)?;
    assert_eq!((g.kp, g.ti, g.td), (1.2, 5.0, 1.25));
    assert!(ultimate_rule("zn-pi").is_some() && ultimate_rule("nope").is_none());
    Ok(())
}

#[test]
fn karan_dey_thesis_settings() -> Result<(), Box<dyn std::error::Error>> {
    // Bag (2022) Sec. 4.5.3: 0.2/s e^{-7.4s} → Kp = 5.4, Ti = 3.70, β = 0.25, Td = 1.85, γ ≈ 0.06
    let m = Ipdt::<f64>::new(0.2, 7.4)?;
    let p = karan_dey(&m, karan_dey_default_lambda(&m))?;
    assert!((p.kp - 5.4).abs() < 0.01, "{}", p.kp);
    assert!((p.ti - 3.70).abs() < 1e-12);
    assert!((p.beta - 0.25).abs() < 1e-12);
    assert!((p.td - 1.85).abs() < 1e-12);
    assert!((p.gamma - 0.0625).abs() < 1e-12);
    // 0.05/s e^{-6s} → Kp = 26.67, Ti = 3.00, Td = 1.50
    let m = Ipdt::<f64>::new(0.05, 6.0)?;
    let p = karan_dey(&m, karan_dey_default_lambda(&m))?;
    assert!((p.kp - 26.67).abs() < 0.005);
    assert!((p.ti - 3.0).abs() < 1e-12 && (p.td - 1.5).abs() < 1e-12);
    Ok(())
}
