//! A lag between the change detector's hypotheses that only loads show
//! (#48 items 1 and 2): the loop never ends worse than the fixed model's.
//!
//! Loads excite the process's initial slope `K/τ` more than `K` and `τ`
//! apart. After a lag ×1.6 the nearest lag hypothesis is applied (×4/3 or
//! ×2) and the level test then names a gain (×0.7 or ×1.4) for what is
//! left along `K/τ`; applied as a gain, the loop had the right `K/τ` and a
//! wrong gain, and ended up to 11.5 % worse than the fixed model's (the
//! bank's table before the rule). The supervisor takes a second hypothesis
//! of the other kind as a further step of the first one's parameter at the
//! `K/τ` it names (`Adaptive::propose`).

use msp::study::bank::{cases, Period};

/// Every case of the family over the bank's three seeds, every process,
/// measurement condition and both periods: the adaptive loop's IAE at most
/// 5 % above the fixed loop's (the bank's "events worse" bound, here for
/// the evaluated window after a change), and never diverging.
#[test]
fn a_lag_between_the_hypotheses_with_loads_does_no_harm() {
    let family = "lag ×1.6, loads";
    let mut n = 0;
    for period in [Period::Chosen, Period::Coarse] {
        for case in cases(3)
            .into_iter()
            .filter(|c| c.family == family && c.period == period)
        {
            let r = case.run().unwrap();
            assert!(r.iae_adaptive.is_finite(), "{r:?}");
            assert!(r.iae_adaptive <= 1.05 * r.iae_fixed, "{r:?}");
            n += 1;
        }
    }
    // three stable processes, five conditions, three seeds, two periods
    assert_eq!(n, 90, "{family}");
}

/// A gain between the hypotheses that only loads show, on the integrating
/// processes of the bank, at both periods, without noise, under 0.5 and
/// 2 % noise and a 10-bit converter (seed 1): the nearer gain hypothesis
/// (×0.7) is applied first (or the bank's estimate), and the factor it left (0.6/0.7 ≈ 0.86) is
/// named by the finer gains the detector simulates while a gain hypothesis
/// is the model in use ([`msp::adapt::FINE_GAINS`]: √0.7): the adaptive loop
/// ends within 10 % of the true model's IAE in 15 of the 16 cases, and
/// 25 % or more below the fixed loop's in every one. Before them: 1.16 times
/// the true model's in most of these cases, the loads teaching the bank too
/// little to refine the gain. The one case left, `0.15 e^{−5s}/s` at the
/// chosen period under 2 % noise, showed the factor 0.86 in one load's
/// response only (the others' input loads, whose ramp the load's
/// regressor takes up, hardly tell it); one response is not evidence
/// enough ([`msp::adapt::REPLICATED`]: a ramp load that levels off within a
/// response can look like a changed process in one response).
#[test]
fn a_gain_between_the_hypotheses_with_loads_is_learnt_on_integrating_processes() {
    let family = "gain ×0.6, loads";
    let conditions = [(0.0, None), (0.005, None), (0.02, None), (0.0, Some(10))];
    let (mut n, mut within) = (0, 0);
    for period in [Period::Chosen, Period::Coarse] {
        for case in cases(1).into_iter().filter(|c| {
            c.family == family
                && c.period == period
                && c.plant.tau.is_none()
                && conditions.contains(&(c.noise, c.bits))
        }) {
            let r = case.run().unwrap();
            assert!(r.applied > 0, "{r:?}");
            assert!(r.iae_adaptive <= 0.75 * r.iae_fixed, "{r:?}");
            within += usize::from(r.within_true());
            n += 1;
        }
    }
    // two integrating processes, four conditions, two periods
    assert_eq!(n, 16, "{family}");
    assert!(
        within >= 15,
        "{within} of {n} within 10 % of the true model"
    );
}

/// A gain between the hypotheses that the level test fits itself, only
/// loads moving the loop: ×0.85 (between the model in use and the nearest
/// hypothesis, ×0.7) and ×0.6, on every process of the bank (stable and
/// integrating), under every measurement condition (noise 0, 0.5, 2, 5 %,
/// a 10-bit converter), at msp's chosen period and at a coarse one (seed
/// 1). The hypotheses' fits lie on a parabola in the gain whose lowest
/// point is the response's least-squares gain (`levels/between.rs`);
/// weighed over the responses by its own sum, it is applied. Everywhere the
/// adaptive loop ends at most 5 % above the fixed loop's IAE and never
/// diverges; without noise it ends within 10 % of the true model's IAE.
/// Before it, ×0.85 without noise was 1.18 times the true model's IAE on
/// `0.8 e^{−10s}/(4s + 1)` at the chosen period (nothing applied), and ×0.6
/// there 1.64 times (applied 2 400 s after the change).
#[test]
fn a_gain_between_the_hypotheses_with_loads_is_fitted_by_the_level_test() {
    let family = "gain ×0.6, loads";
    let mut n = 0;
    for factor in [0.85, 0.6] {
        for mut case in cases(1).into_iter().filter(|c| c.family == family) {
            if let Some(change) = case.change.as_mut() {
                change.factor = factor;
            }
            let r = case.run().unwrap();
            assert!(r.iae_adaptive <= 1.05 * r.iae_fixed, "×{factor}: {r:?}");
            if case.noise == 0.0 && case.bits.is_none() {
                assert!(r.within_true() && r.applied > 0, "×{factor}: {r:?}");
            }
            n += 1;
        }
    }
    // five processes, five conditions, two periods, two factors
    assert_eq!(n, 100, "{family}");
}

/// A lag between the hypotheses that the level test fits itself, only
/// loads moving the loop: ×1.6 (between the hypotheses ×4/3 and ×2) and
/// ×1.2 (between the model in use and ×4/3), on every stable process of
/// the bank, under 0.5 and 2 % noise, at msp's chosen period and at a
/// coarse one (seed 1). The lag hypotheses' fits lie near their lowest
/// point on a parabola in the lag's logarithm (`levels/between.rs`),
/// weighed over the responses by its own sum. Everywhere the adaptive loop
/// ends at most 5 % above the fixed loop's IAE and within 10 % of the true
/// model's IAE.
#[test]
fn a_lag_between_the_hypotheses_with_loads_is_fitted_by_the_level_test() {
    let family = "lag ×1.6, loads";
    let mut n = 0;
    for factor in [1.6, 1.2] {
        for mut case in cases(1)
            .into_iter()
            .filter(|c| c.family == family && (c.noise == 0.005 || c.noise == 0.02))
        {
            if let Some(change) = case.change.as_mut() {
                change.factor = factor;
            }
            let r = case.run().unwrap();
            assert!(r.iae_adaptive <= 1.05 * r.iae_fixed, "×{factor}: {r:?}");
            assert!(r.within_true(), "×{factor}: {r:?}");
            n += 1;
        }
    }
    // three stable processes, two conditions, two periods, two factors
    assert_eq!(n, 24, "{family}");
}
