use super::*;
use crate::dtc::fsp::design::design_form;
use crate::dtc::fsp::{model_tf, FrSpec};
use crate::test_util::ExpectOk;
use std::vec::Vec;

/// The models of the split realization: stable of orders one and two,
/// an integrator alone and with a lag (continuous `num/den`).
const MODELS: [(&[f64], &[f64]); 4] = [
    (&[2.0], &[4.0, 1.0]),
    (&[1.5], &[3.0, 4.0, 1.0]),
    (&[0.2], &[1.0, 0.0]),
    (&[0.5], &[2.0, 1.0, 0.0]),
];

fn predictors(
    num: &[f64],
    den: &[f64],
    h: usize,
    spec: &FrSpec,
) -> (FspPredictor<f64, Vec<f64>>, FspPredictor<f64, Vec<f64>>) {
    let ts = 0.5;
    let gm: Lti<f64, 8> = Lti::from_tf(num, den, ts, crate::lti::Discretization::Zoh).expect_ok();
    let (nm, dm) = model_tf(&gm);
    let vecs = |n: usize| Ok(std::vec![0.0; n]);
    let split = design_form::<Vec<f64>, 8>(&nm, &dm, h, ts, spec, vecs, true).expect_ok();
    let direct = design_form::<Vec<f64>, 8>(&nm, &dm, h, ts, spec, vecs, false).expect_ok();
    assert!(matches!(split.s, Realization::Split { .. }));
    assert!(matches!(direct.s, Realization::Direct { .. }));
    (
        FspPredictor::new(&split).expect_ok(),
        FspPredictor::new(&direct).expect_ok(),
    )
}

fn specs() -> [FrSpec; 2] {
    [
        FrSpec {
            tf: 1.5,
            lead: None,
            biproper: false,
        },
        // FSPCC's biproper filter with a lead
        FrSpec {
            tf: 1.0,
            lead: Some((2.0, 0.7)),
            biproper: true,
        },
    ]
}

/// The split realization is the direct form of García et al. (2010)
/// Eq. 10, sample by sample (inputs of a pseudo-random sequence, amended
/// now and then as a tracking actuator does) and at every frequency: the
/// two differ by the rounding of a sum over the dead time.
#[test]
fn split_equals_the_direct_form() {
    for (num, den) in MODELS {
        for spec in specs() {
            for h in [1usize, 2, 7, 60] {
                let (mut a, mut b) = predictors(num, den, h, &spec);
                let mut seed = 12345u64;
                let mut scale = 0.0f64;
                let mut worst = 0.0f64;
                for k in 0..400 {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let u = ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.3;
                    let y = (k as f64 * 0.05).sin();
                    let (pa, pb) = (a.predict(y), b.predict(y));
                    scale = scale.max(pb.abs());
                    worst = worst.max((pa - pb).abs());
                    a.commit(u);
                    b.commit(u);
                    if k % 37 == 5 {
                        a.amend(0.25);
                        b.amend(0.25);
                    }
                }
                assert!(
                    worst <= 1e-10 * scale.max(1.0),
                    "{num:?}/{den:?} h {h}: {worst:e} of {scale:e}"
                );
                for theta in [0.0, 1e-7, 0.01, 0.3, 1.0, 3.0] {
                    let (sa, fa) = a.response(theta);
                    let (sb, fb) = b.response(theta);
                    let err = (sa - sb).abs() + (fa - fb).abs();
                    assert!(
                        err <= 1e-9 * (sb.abs() + fb.abs()).max(1.0),
                        "{num:?}/{den:?} h {h} θ {theta}: {err:e}"
                    );
                }
            }
        }
    }
}

/// A run-time dead-time change redesigns the split predictor for the new
/// dead time as it does the direct one: both carry the same inputs over,
/// their internal states differ (the direct form's past outputs, the
/// split form's blocks), so they agree once the blocks' slowest pole
/// (`e^{−0.5/4} ≈ 0.88` per sample) has forgotten the change: 100
/// samples later to `0.88¹⁰⁰ ≈ 3·10⁻⁶` of the transient.
#[test]
fn split_redesign_equals_the_direct_form() {
    let spec = specs()[0];
    for (num, den) in MODELS {
        let ts = 0.5;
        let gm: Lti<f64, 8> =
            Lti::from_tf(num, den, ts, crate::lti::Discretization::Zoh).expect_ok();
        let (nm, dm) = model_tf(&gm);
        let vecs = |n: usize| Ok(std::vec![0.0; n]);
        let mk = |split: bool| -> FspPredictor<f64, Vec<f64>> {
            let d = design_form::<Vec<f64>, 8>(&nm, &dm, 10, ts, &spec, vecs, split).expect_ok();
            FspPredictor::new(&d)
                .expect_ok()
                .with_redesign(nm, dm, ts, spec, (10, 40))
        };
        let (mut a, mut b) = (mk(true), mk(false));
        let mut worst = 0.0f64;
        for k in 0..400 {
            if k == 100 {
                a.set_dead_time(17.0).expect_ok();
                b.set_dead_time(17.0).expect_ok();
            }
            if k == 250 {
                a.set_dead_time(4.0).expect_ok();
                b.set_dead_time(4.0).expect_ok();
            }
            let y = (k as f64 * 0.07).cos();
            let u = if k < 150 { 1.0 } else { -0.5 } + 0.1 * (k as f64 * 0.3).sin();
            let d = (a.predict(y) - b.predict(y)).abs();
            if (200..250).contains(&k) || k >= 350 {
                worst = worst.max(d);
            }
            a.commit(u);
            b.commit(u);
        }
        assert!(worst < 1e-6, "{num:?}/{den:?}: {worst:e}");
    }
}

/// The compensated sliding sum does not drift: after a million f32
/// inputs of mixed magnitude it equals the exact sum of the line.
#[test]
fn sliding_sum_does_not_drift() {
    let mut s: SplitForm<f32, Vec<f32>, 2> = SplitForm::new_in(
        (&[1.0], &[1.0, -0.5]),
        (&[0.5], &[1.0, -0.5]),
        true,
        13,
        |n| Ok(std::vec![0.0f32; n]),
    )
    .expect_ok();
    let mut seed = 7u64;
    for _ in 0..1_000_000 {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u = ((seed >> 40) as f32 / (1u32 << 24) as f32 - 0.5) * 1000.0;
        s.push(u);
    }
    let exact: f64 = s.line.iter().map(|v| f64::from(*v)).sum();
    let got = f64::from(s.sum.value());
    // the line's sum to the f32 rounding of the sum itself (a plain or
    // Kahan running sum drifts by 10⁻² and 4·10⁻³ here)
    assert!(
        (got - exact).abs() <= f64::from(f32::EPSILON) * exact.abs(),
        "{got} vs {exact}"
    );
}
