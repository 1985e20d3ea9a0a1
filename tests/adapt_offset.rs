//! Item 3 of the adaptation (#48) where the loop settles away from its set
//! point: the Smith predictor on an integrating process holds an input
//! load `d` at `K·θ·d` from the set point, and when its dead time grows
//! the loop oscillates about that offset, the control error keeping its
//! sign. The emergency path must see the oscillation all the same.

use msp::study::bank::{cases, Change, CONDITIONS};

/// The bank's integrating processes with input loads only, at msp's
/// chosen period and at ten samples of dead time, their dead time 30 % and
/// 40 % longer from 20 settling scales on, under every measurement
/// condition of the bank: the fixed model's loop diverges; the adaptive one
/// takes the emergency path (its log says so), never diverges and ends
/// within 10 % of the true model's loop (before the error's swings about
/// its level counted, at the coarse period the adaptive loop diverged with
/// the fixed one under any noise: the error stayed between −1 and −2 for
/// six periods of the growing oscillation).
#[test]
fn an_oscillation_about_a_loads_offset_is_caught() {
    let base: Vec<_> = cases(1)
        .into_iter()
        .filter(|c| c.family == "dead time ×1.6, loads" && c.plant.tau.is_none())
        .collect();
    assert_eq!(base.len(), 2 * 2 * CONDITIONS.len());
    for factor in [1.3, 1.4] {
        for mut case in base.clone() {
            case.change = case.change.map(|c| Change { factor, ..c });
            let r = case.run().unwrap();
            assert!(!r.iae_fixed.is_finite(), "{factor}: {r:?}");
            assert!(
                r.iae_adaptive.is_finite() && r.within_true(),
                "{factor}: {r:?}"
            );
            let out = case.adaptive().unwrap();
            let kinds: Vec<_> = out.report().adaptation.iter().map(|c| c.kind).collect();
            assert!(
                kinds.contains(&msp::adapt::ChangeKind::Emergency),
                "{factor}, {:?}, {:?}: {kinds:?}",
                case.plant,
                case.period
            );
        }
    }
}
