//! A dead time that only loads show (#48 item 2): shortened by 30 % on a
//! process whose loop only loads move (input and output steps; an
//! integrating process's, input steps).
//!
//! The change detector finds the new dead time at the first load's
//! response and restarts the bank from the model it had: the candidate at
//! the new dead time is then the model in use there, exactly. The next
//! loads teach the bank a load-biased gain before two blocks of its
//! estimate held still (measured on `2.3 e^{−8s}/(15s + 1)` without noise:
//! the right model with evidence above 10⁶ for some 100 s, then a gain
//! 10 % low, applied 3 000 s later, the loop 22 % above the true model's);
//! the supervisor applies the model in use with the new dead time at once
//! (`Adaptive::moved_dead_time`).

use msp::study::bank::{cases, Period};

/// Every process of the bank at msp's chosen period, under every
/// measurement condition (noise 0, 0.5, 2, 5 %, a 10-bit converter), two
/// seeds: a model is applied, the adaptive loop ends within 10 % of the
/// true model's IAE and 20 % better than the fixed model's (which is 30 %
/// worse than the true one's or more here; on the integrating processes it
/// diverges), and never diverges. Before the rule: 27 of the 45 stable
/// cases of three seeds within 10 %, 44 with it. Two cases miss (48 of
/// 50: `2.3 e^{−8s}/(15s + 1)` behind the 10-bit converter, both seeds,
/// 1.17 times the true model's IAE) since the block's input is the triangle the block
/// means see (`Estimator::update`): the bank has the new dead time, but
/// its gain, which the loads bias by 5 to 10 % there, keeps the model in
/// use with the new dead time from being applied (`Adaptive::moved_dead_time`).
#[test]
fn a_dead_time_only_loads_show_is_learnt_at_the_chosen_period() {
    let family = "dead time ×0.7, loads";
    let (mut n, mut within, mut misses) = (0, 0, Vec::new());
    for case in cases(2)
        .into_iter()
        .filter(|c| c.family == family && c.period == Period::Chosen)
    {
        let r = case.run().unwrap();
        assert!(r.iae_fixed >= 1.3 * r.iae_true, "{r:?}");
        assert!(r.applied > 0, "{r:?}");
        assert!(r.iae_adaptive <= 1.2 * r.iae_true, "{r:?}");
        assert!(r.iae_adaptive <= 0.82 * r.iae_fixed, "{r:?}");
        if r.within_true() {
            within += 1;
        } else {
            misses.push((case.plant.k, case.bits, case.seed));
        }
        n += 1;
    }
    // five processes, five conditions, two seeds
    assert_eq!(n, 50, "{family}");
    assert!(within >= 48, "{within} of {n} within 10 %: {misses:?}");
    assert!(
        misses.iter().all(|m| m.0 == 2.3 && m.1 == Some(10)),
        "{misses:?}"
    );
}

/// At ten samples of dead time, without noise and behind a 10-bit
/// converter (seed 1), every process: the same, the adaptive loop within
/// 10 % of the true model's IAE. The dead-time-dominant
/// `0.8 e^{−10s}/(4s + 1)` rings at a load's response as the loop built for
/// the process does; the watch after the change took it for an
/// oscillation and restored the commissioned model (1.43 times the true
/// model's IAE) until a model the data confirm and that predicts the last
/// response was left in place (`Adaptive::oscillation`).
#[test]
fn a_dead_time_only_loads_show_is_learnt_at_the_coarse_period_without_noise() {
    let family = "dead time ×0.7, loads";
    let mut n = 0;
    for case in cases(1)
        .into_iter()
        .filter(|c| c.family == family && c.period == Period::Coarse && c.noise == 0.0)
    {
        let r = case.run().unwrap();
        assert!(r.applied > 0 && r.within_true(), "{r:?}");
        n += 1;
    }
    // five processes, without noise and behind a 10-bit converter
    assert_eq!(n, 10, "{family}");
}

/// Item 4 on the same family: the dead-time range given (`--adapt-delay`)
/// ends at 0.82 times the commissioned dead time, its lowest candidate at
/// 0.8 (a tenth of the dead time a candidate, from the estimator sample
/// below the end), above the process's new 0.7. The bank's estimate is then the model in use at the range's
/// lowest dead time, which predicts the data better than the model in use
/// (without the edge's rule in `Adaptive::moved_dead_time`, applied at
/// once on four of the six): no model is applied there, the estimate at
/// the edge is warned of (`ChangeKind::Edge`) and the loop stays stable. Every stable process
/// (an integrating one's fixed loop diverges after this change: the bank's
/// table) at the chosen period, without noise and under 2 % noise (seed 1).
#[test]
fn a_dead_time_beyond_the_range_is_warned_of_and_not_applied() {
    use msp::adapt::ChangeKind;
    use msp::study::AdaptOptions;
    let family = "dead time ×0.7, loads";
    let mut n = 0;
    for case in cases(1).into_iter().filter(|c| {
        c.family == family
            && c.period == Period::Chosen
            && c.plant.tau.is_some()
            && c.bits.is_none()
            && (c.noise == 0.0 || c.noise == 0.02)
    }) {
        let theta = case.plant.theta;
        let lowest = 0.82 * theta;
        let out = case
            .adaptive_with(AdaptOptions {
                delay: Some((lowest, 3.0 * theta)),
                ..AdaptOptions::default()
            })
            .unwrap();
        let log = &out.report().adaptation;
        // (a tenth of the dead time an estimator sample: within one of the edge)
        let at_edge = |t: f64| t < lowest + 0.1 * theta;
        assert!(
            !log.iter()
                .any(|c| c.kind == ChangeKind::Applied && at_edge(c.theta)),
            "{:?}: {log:?}",
            case.plant
        );
        assert!(
            log.iter().any(|c| c.kind == ChangeKind::Edge),
            "{:?}: {log:?}",
            case.plant
        );
        assert!(out.result.diverged_at.is_none(), "{:?}", case.plant);
        n += 1;
    }
    // three processes, two conditions
    assert_eq!(n, 6, "{family}");
}
