//! The adaptation's benchmark bank (`msp::study::bank`) under heavy
//! measurement noise: its cases at the coarse period under 5 % noise where
//! a rule of the supervisor is what brings the adaptive loop within 10 % of
//! the true model's (each case failed without its rule).

use msp::study::bank::{cases, BankCase, Period};

/// The bank's cases of `family` at the coarse period under 5 % noise.
fn noisy(family: &str) -> impl Iterator<Item = BankCase> + '_ {
    cases(3).into_iter().filter(move |c| {
        c.family == family && c.period == Period::Coarse && (c.noise, c.bits) == (0.05, None)
    })
}

/// Each of the `n` cases `picked` ends within 10 % of the true model's loop.
fn all_within_true(picked: impl Iterator<Item = BankCase>, n: usize) {
    let picked: Vec<_> = picked.collect();
    assert_eq!(picked.len(), n);
    for case in picked {
        let r = case.run().unwrap();
        assert!(r.within_true(), "{r:?}");
    }
}

/// A converged estimate whose block means wander about each other by more
/// than half of `min_change` under 5 % noise is applied at their midpoint
/// ([`msp::adapt::SPREAD`]): the dead time shortened to 0.6 times on every
/// stable process of the bank, coarse period, seed 2, ends within 10 % of
/// the true model's loop (with only the means within half of `min_change`
/// applied, two of the three did not: their estimates were right and
/// never settled).
#[test]
fn a_converged_estimate_under_5_percent_noise_settles() {
    all_within_true(
        noisy("dead time ×0.6").filter(|c| c.seed == 2 && c.plant.tau.is_some()),
        3,
    );
}

/// A dead time no neighbour of the model's is taken on the evidence over
/// the model's own, though a candidate two samples away is not yet told
/// from it (`Adaptive`'s supervision, `Estimator::over_reference`): the
/// dead time shortened to 0.6 times on 1.6e^-6s/(10s+1) (seed 3), drifted
/// to 0.7 times on 0.8e^-10s/(4s+1) (seed 2), each ends within 10 % of the
/// true model's loop (with the evidence over the nearest such candidate
/// alone: 1.53 and 1.36 times it, the dead time applied late or never).
#[test]
fn a_dead_time_clearly_better_than_the_models_is_taken() {
    let picked = noisy("dead time ×0.6")
        .filter(|c| c.seed == 3 && c.plant.k == 1.6)
        .chain(noisy("dead time drifts ×0.7").filter(|c| c.seed == 2 && c.plant.k == 0.8));
    all_within_true(picked, 2);
}

/// A gain between the change detector's hypotheses (0.6 times the model's;
/// the nearest hypothesis, 0.7, applied first) on 1.6e^-6s/(10s+1) and
/// 2.3e^-8s/(15s+1), seed 1: the bank's estimate settles within 2 % of the
/// process's gain, but its prediction in the differences is not better
/// than the model in use's by the validation's margin within the run; the
/// level test weighs it on the set-point responses (no load can be in them:
/// the constant alone, no load's regressor to absorb the gain's misfit)
/// and it is applied. Each ends within 10 % of the true model's loop
/// (without the challenger: 1.15 times it).
#[test]
fn a_settled_gain_the_differences_cannot_validate_is_weighed_in_levels() {
    let picked =
        noisy("gain ×0.6").filter(|c| c.seed == 1 && (c.plant.k == 1.6 || c.plant.k == 2.3));
    all_within_true(picked, 2);
}
