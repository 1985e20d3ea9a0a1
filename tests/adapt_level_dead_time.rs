//! The level test's dead-time hypotheses (`src/adapt/levels/dead.rs`;
//! #48 item 2): a change of the dead time that only loads show, under a
//! noise that hides the loads' steps from the bank's differences, learnt
//! from the responses in levels; and item 1 where nothing changes.

use msp::study::bank::{cases, BankCase, Period};

/// The bank's cases of `family` on its stable processes at `period` under
/// `noise`, seeds `seeds`.
fn stable(
    family: &str,
    period: Period,
    noise: f64,
    seeds: std::ops::RangeInclusive<u64>,
) -> Vec<BankCase> {
    cases(*seeds.end())
        .into_iter()
        .filter(|c| {
            c.family == family
                && c.plant.tau.is_some()
                && c.period == period
                && c.noise == noise
                && c.bits.is_none()
                && seeds.contains(&c.seed)
        })
        .collect()
}

/// A dead time 0.7 times the model's with loads alone, ten samples of dead
/// time, 2 % noise, seeds 1 to 8 on the three stable processes (24 cases):
/// each run at most 0.9 times the fixed loop's IAE, and at least 18 within
/// 10 % of the true model's (measured: 20; the others end a sample from the
/// process's dead time, the shifts of the level test 20 and 40 %, at most
/// 1.11 times the true loop's). Before the level test weighed dead times,
/// none had a model applied: the bank's differences did not see the loads.
#[test]
fn loads_alone_teach_a_shorter_dead_time_under_noise() {
    let all = stable("dead time ×0.7, loads", Period::Coarse, 0.02, 1..=8);
    assert_eq!(all.len(), 3 * 8);
    let mut within = 0;
    for case in &all {
        let r = case.run().unwrap();
        assert!(r.iae_adaptive <= 0.9 * r.iae_fixed, "{r:?}");
        within += usize::from(r.within_true());
    }
    assert!(within >= 18, "{within} of {} within 10 %", all.len());
}

/// The same at msp's chosen period (a tenth of the dead time per estimator
/// sample) under 5 % noise, seeds 1 to 4 (12 cases): each run at most 0.9
/// times the fixed loop's IAE and within 10 % of the true model's. There
/// the bank's differences see most loads' steps; on `0.8 e^{−10s}/(4s + 1)`,
/// seed 3, they taught nothing, and without the level test's dead time the
/// run ended 1.13 times the true loop's IAE (measured).
#[test]
fn loads_alone_teach_a_shorter_dead_time_at_the_chosen_period() {
    let all = stable("dead time ×0.7, loads", Period::Chosen, 0.05, 1..=4);
    assert_eq!(all.len(), 3 * 4);
    for case in &all {
        let r = case.run().unwrap();
        assert!(r.iae_adaptive <= 0.9 * r.iae_fixed, "{r:?}");
        assert!(r.within_true(), "{r:?}");
    }
}

/// A dead time drifting to 0.7 times over ten settling scales, the set
/// point moving, 2 % noise, seeds 1 to 6 (18 cases): each run within 10 %
/// of the true model's IAE. The level test's shifts (20 and 40 %) step over
/// the process's dead time; a move back towards the dead time the last one
/// left is taken halfway (measured: `1.6 e^{−6s}/(10s + 1)`, seed 2, had
/// 4.8, 3.6 and 4.8 s applied in turn for a process's 4.2, 1.11 times the
/// true loop's IAE; halfway, 4.2 and the true loop's IAE).
#[test]
fn a_dead_time_between_the_shifts_is_bracketed() {
    let all = stable("dead time drifts ×0.7", Period::Coarse, 0.02, 1..=6);
    assert_eq!(all.len(), 3 * 6);
    for case in &all {
        let r = case.run().unwrap();
        assert!(r.within_true(), "{r:?}");
    }
}

/// Ramp loads and nothing else, msp's chosen period, 0.5 % noise, seeds 7
/// to 24 on every process (90 cases): no model applied. A ramp that ends
/// inside a response is fitted better by another dead time too, and the
/// bank's differences, whose excitation gate takes a ramp's steady input
/// for no move, learn nothing from such a loop; a dead time from the level
/// test is applied only after the bank learnt from a response's samples
/// since the model in use was set (measured without that: 9 of these
/// cases had a dead time applied, events up to 2.8 times the fixed loop's).
#[test]
fn ramps_alone_teach_no_dead_time() {
    let mut n = 0;
    for case in cases(24).into_iter().filter(|c| {
        c.family == "no change, ramps"
            && c.period == Period::Chosen
            && c.noise == 0.005
            && c.seed >= 7
    }) {
        let r = case.run().unwrap();
        assert_eq!(r.applied, 0, "{r:?}");
        n += 1;
    }
    assert_eq!(n, 5 * 18);
}
