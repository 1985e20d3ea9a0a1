//! Ramp loads that level off within a response (#48 item 1): where the
//! process does not change, the level test's evidence must not rest on one
//! response ([`msp::adapt::REPLICATED`]).
//!
//! A load that ramps to a new level is no step, and the level test's load
//! regressors (a constant and the model's free response) do not cover it.
//! A smaller gain or a longer lag then fits one such response to the noise,
//! with an evidence a changed process's step response would give; the next
//! response need not repeat it (every no-change family on other seeds:
//! `tests/adapt_no_change.rs`).

use msp::study::bank::{cases, Period, CONDITIONS};

/// The bank's no-change ramps at the coarse period under every measurement
/// condition (noise 0, 0.5, 2, 5 %, a 10-bit converter), on every process,
/// seeds 4 to 8 (the reduced bank runs seed 1, the table seeds 1 to 3):
/// no event's IAE more than 5 % above the fixed loop's, and where a model
/// is applied the run is no worse than the fixed loop. Before the rule,
/// `2.3 e^{−8s}/(15s + 1)` under 2 % noise, seed 5, had a doubled lag
/// applied on one response's evidence of 59 and the next one's 2, the
/// following event 1.82 times the fixed loop's IAE.
/// (`0.8 e^{−10s}/(4s + 1)` seed 4 still has a halved gain applied, on two
/// responses that it explains as a halved gain would; the run is 11 %
/// better than the fixed loop's. Seed 9, not run here, is not yet mended:
/// `1.6 e^{−6s}/(10s + 1)` under 2 % noise has a doubled lag applied on
/// three ramp responses, 18, 3 and 94, one event 1.39 times the fixed
/// loop's.)
#[test]
fn a_ramp_load_that_levels_off_teaches_no_model() {
    let family = "no change, ramps";
    let mut n = 0;
    let mut applied = 0;
    for case in cases(8)
        .into_iter()
        .filter(|c| c.family == family && c.period == Period::Coarse && (4..=8).contains(&c.seed))
    {
        let r = case.run().unwrap();
        assert!(r.worst_event_ratio <= 1.05, "{r:?}");
        if r.applied > 0 {
            assert!(r.iae_adaptive <= r.iae_fixed, "{r:?}");
            applied += 1;
        }
        if case.plant.k == 2.3 && case.seed == 5 {
            assert_eq!(r.applied, 0, "{r:?}");
        }
        n += 1;
    }
    // five processes, five conditions, five seeds
    assert_eq!(n, 5 * CONDITIONS.len() * 5);
    assert!(applied <= 1, "{applied} of {n} cases applied a model");
}
