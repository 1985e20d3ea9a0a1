//! The adaptive controller at the library's level (`msp::adapt::Adaptive`
//! around a scheme, a redesign of the caller's, the loop written out): a
//! quiet hour changes nothing, a redesign builds beside the scheme in use,
//! an oscillating change is undone, noise restores nothing, and samples
//! that are not the process's response teach nothing.

mod common;

use msp::adapt::ChangeKind;

const TS: f64 = 0.1;

/// An hour of steady state with 2 % measurement noise after 15 minutes of
/// set-point changes: only the noise moves the input (through the
/// controller), which the excitation gate tells from a move — the
/// estimates move less than 3 %, the dead time does not switch, the model
/// in use does not change, the covariance's trace stays bounded, and the
/// dead-time change detector never fires.
#[test]
fn a_quiet_hour_changes_nothing() {
    use msp::adapt::{Adaptive, AdaptiveConfig, EstimatorConfig};
    use msp::{tuning, Controller, Fopdt, ProcessModel, SmithPredictor};
    let ts = 0.1;
    let model = ProcessModel::from(Fopdt::new(1.0, 4.0, 1.0).unwrap());
    let sp: SmithPredictor<f64, 1, [f64; 64]> =
        SmithPredictor::from_model(tuning::kaya(&model, 2.0).unwrap().config(ts), &model, ts)
            .unwrap();
    let mut est = EstimatorConfig::new(ts, 0);
    est.prefilter = (-ts / 10.0f64).exp();
    let max_trace = est.max_trace;
    let mut c: Adaptive<f64, _, _, 16, 32> =
        Adaptive::new(sp, (1.0, 4.0, 1.0), AdaptiveConfig::new(est), ()).unwrap();
    let a = (-ts / 4.0f64).exp();
    let (mut y, mut line) = (0.0f64, [0.0f64; 10]);
    // Gaussian noise: SplitMix64 and Box–Muller
    let mut state = 11u64;
    let mut uniform = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut gaussian =
        move || (-2.0 * (1.0 - uniform()).ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
    let (busy, quiet) = (9000usize, 36_000usize);
    let mut start = None;
    let mut changes = 0;
    for k in 0..busy + quiet {
        let r = if k < busy && (k / 300) % 2 == 0 {
            0.0
        } else {
            1.0
        };
        let u = c.update(r, y + 0.02 * gaussian());
        if k % 997 == 0 {
            // the recorded row (all signals at once) is signal by signal
            use msp::Introspect;
            let names = c.signal_names();
            let mut row = vec![0.0; names.len()];
            c.write_signals(&mut row);
            for (i, v) in row.iter().enumerate() {
                let one = c.signal(i);
                assert!(
                    *v == one || (v.is_nan() && one.is_nan()),
                    "{}: {v} vs {one}",
                    names[i]
                );
            }
            assert_eq!(c.signal_by_name("theta_model"), Some(1.0));
        }
        let late = line[k % 10];
        line[k % 10] = u;
        y = a * y + (1.0 - a) * late;
        if k == busy {
            start = c.estimate();
            changes = c.changes();
        }
        if let (Some(s), true) = (start, k > busy) {
            let e = c.estimate().unwrap();
            assert_eq!(e.d, s.d, "sample {k}: the dead time switched");
            assert!(
                (e.k - s.k).abs() < 0.03 * s.k,
                "sample {k}: {e:?} from {s:?}"
            );
            assert!(
                (e.tau - s.tau).abs() < 0.03 * s.tau,
                "sample {k}: {e:?} from {s:?}"
            );
            assert!(c.estimator().trace() <= max_trace * (1.0 + 1e-12));
        }
    }
    let s = start.expect("an estimate after the busy quarter hour");
    assert!(
        (s.k - 1.0).abs() < 0.05 && (s.tau - 4.0).abs() < 0.4,
        "{s:?}"
    );
    assert_eq!(c.changes(), changes, "the model changed in the quiet hour");
    // nothing drifted: the dead-time change detector never fired
    assert_eq!(c.estimator().restarts(), 0);
}

/// Storage lent by a redesign to the scheme it builds, counting the lots
/// alive.
struct Lent {
    v: Vec<f64>,
    alive: std::rc::Rc<std::cell::Cell<usize>>,
}

impl AsRef<[f64]> for Lent {
    fn as_ref(&self) -> &[f64] {
        &self.v
    }
}

impl AsMut<[f64]> for Lent {
    fn as_mut(&mut self) -> &mut [f64] {
        &mut self.v
    }
}

impl Drop for Lent {
    fn drop(&mut self) {
        self.alive.set(self.alive.get() - 1);
    }
}

type LentKd = msp::dtc::karan_dey::KaranDey<f64, 1, Lent>;

/// A redesign that builds the Karan–Dey predictor anew on lent storage,
/// recording how many lots were alive at each rebuild and each takeover.
struct Lender {
    alive: std::rc::Rc<std::cell::Cell<usize>>,
    /// The most lots alive when a rebuild was asked for.
    most: usize,
    took_over: usize,
}

impl Lender {
    fn build(&mut self, k: f64, theta: f64) -> Option<LentKd> {
        let m = msp::Ipdt::new(k, theta).ok()?;
        let p = msp::tuning::karan_dey(&m, msp::tuning::karan_dey_default_lambda(&m)).ok()?;
        let (block, _) = msp::ProcessModel::from(msp::Ipdt::new(k, 0.0).ok()?)
            .discretize::<1>(TS)
            .ok()?;
        self.alive.set(self.alive.get() + 1);
        let lot = Lent {
            v: vec![0.0; 40],
            alive: self.alive.clone(),
        };
        let line = msp::Delay::with_storage(lot, theta / TS).ok()?;
        msp::dtc::compensator::build(&p, TS, block, line).ok()
    }
}

impl msp::adapt::Redesign<f64, LentKd> for Lender {
    fn rebuild(&mut self, k: f64, tau: f64, theta: f64) -> Option<LentKd> {
        assert!(tau.is_infinite());
        self.most = self.most.max(self.alive.get());
        self.build(k, theta)
    }

    fn took_over(&mut self) {
        self.took_over += 1;
    }
}

/// The process gain of [`a_redesign_builds_beside_the_one_in_use_only`] at
/// sample `k`: up by a fifth, then down below the model's.
fn gain(k: usize) -> f64 {
    match k {
        0..1500 => 0.5,
        1500..12_000 => 0.6,
        _ => 0.42,
    }
}

/// A scheme rebuilt at each change asks its redesign for a new one only
/// while the one in use is the only one alive (a device lends two lots of
/// memory, alternately), and hears of every takeover: the count of
/// takeovers is the log's applied and restored changes, and after the run
/// one scheme (or one and its successor warming up) is alive. The
/// Karan–Dey loop with the old model rings after each set-point step; a
/// change that meets the ringing dying out is not taken for an oscillation
/// (it stays: the model in use becomes the process's).
#[test]
fn a_redesign_builds_beside_the_one_in_use_only() {
    let (c, alive, _) = karan_dey_adapting(false, |_| false);
    let took = c
        .log()
        .filter(|e| matches!(e.kind, ChangeKind::Applied | ChangeKind::Restored))
        .count();
    assert!(took >= 2 && c.changes() <= 16, "{took}");
    let r = c.redesign();
    assert_eq!(r.took_over, took);
    assert_eq!(r.most, 1);
    assert!((1..=2).contains(&alive.get()));
    assert!((c.model().0 - gain(24_000)).abs() < 0.03, "{:?}", c.model());
}

/// With `background_design` the update that applies a model leaves its
/// design to `Adaptive::design`: called between samples (as a device's
/// background task would), the same models are taken, each design a
/// sample later, the lent lots as before; never called, the scheme in use
/// and its model stay (a model waits, said by `is_designing`).
#[test]
fn a_design_in_the_background_waits_for_its_call() {
    let (inline, _, _) = karan_dey_adapting(false, |_| false);
    let (c, alive, designs) = karan_dey_adapting(true, |c| c.design());
    let applied = |c: &Kd| {
        c.log()
            .filter(|e| e.kind == ChangeKind::Applied)
            .map(|e| (e.k, e.theta))
            .collect::<Vec<_>>()
    };
    let (a, b) = (applied(&inline), applied(&c));
    assert_eq!(a.len(), b.len());
    for ((k1, t1), (k2, t2)) in a.iter().zip(&b) {
        assert!(
            (k1 - k2).abs() < 0.01 * k1 && (t1 - t2).abs() < 0.05,
            "{a:?} {b:?}"
        );
    }
    assert!(
        designs >= 2 && designs == c.redesign().took_over,
        "{designs}"
    );
    assert_eq!(c.redesign().most, 1);
    assert!((1..=2).contains(&alive.get()));
    assert!(!c.is_designing());
    // never designed: nothing taken, the loop the fixed predictor's
    let (idle, _, none) = karan_dey_adapting(true, |_| false);
    assert_eq!(none, 0);
    assert!(idle.is_designing());
    assert_eq!(idle.redesign().took_over, 0);
    assert_eq!(idle.model(), (0.5, f64::INFINITY, 1.0));
    assert!(idle.log().all(|e| e.kind != ChangeKind::Applied));
}

type Kd = msp::adapt::Adaptive<f64, LentKd, Lender, 16, 512>;

/// The Karan–Dey predictor of `0.5 e^{−1s}/s` at [`TS`], rebuilt by a
/// [`Lender`] at each change (in the background with `background`, `step`
/// called after each update and counted where it returns true), on the
/// process whose gain is [`gain`], the set point alternating every 30 s,
/// 24 000 samples; the redesign's count of lots alive.
fn karan_dey_adapting(
    background: bool,
    mut step: impl FnMut(&mut Kd) -> bool,
) -> (Kd, std::rc::Rc<std::cell::Cell<usize>>, usize) {
    use msp::adapt::{AdaptiveConfig, EstimatorConfig};
    use msp::Controller;
    let alive = std::rc::Rc::new(std::cell::Cell::new(0));
    let mut lender = Lender {
        alive: alive.clone(),
        most: 0,
        took_over: 0,
    };
    let first = lender.build(0.5, 1.0).unwrap();
    let mut est = EstimatorConfig::new(TS, 4);
    est.integrating = true;
    est.set_prefilter_time(2.5).unwrap();
    let mut cfg = AdaptiveConfig::new(est);
    cfg.background_design = background;
    let mut c: Kd = Kd::new(first, (0.5, f64::INFINITY, 1.0), cfg, lender).unwrap();
    let (mut y, mut line) = (0.0, std::collections::VecDeque::from(vec![0.0; 10]));
    let mut steps = 0;
    for k in 0..24_000 {
        let r = ((k / 300) % 2) as f64;
        let u = c.update(r, y);
        steps += usize::from(step(&mut c));
        line.push_back(u);
        let late = line.pop_front().unwrap();
        y += TS * gain(k) * late;
    }
    (c, alive, steps)
}

/// What a run of [`smith_run`] leaves: the control error without the
/// noise, the log, the model in use and the noise the estimator measured.
struct SmithRun {
    err: Vec<f64>,
    log: Vec<msp::adapt::Change<f64>>,
    model: (f64, f64, f64),
    noise: f64,
}

impl SmithRun {
    fn kinds(&self) -> Vec<msp::adapt::ChangeKind> {
        self.log.iter().map(|e| e.kind).collect()
    }
}

/// The Smith predictor on `e^{−1s}/(4s + 1)` sampled at 0.1 s (the
/// primary Kaya's PI at `λ = 1 s`), adapted by `cfg` with the primary's
/// gains from `gains`, over 9 000 samples with the process gain `k(i)` at
/// sample `i` and white measurement noise of deviation `noise` (fixed
/// seed); the set point alternates every 30 s.
fn smith_run(
    cfg: msp::adapt::AdaptiveConfig<f64>,
    gains: impl FnMut(f64, f64, f64) -> Option<[f64; 3]>,
    k: impl Fn(usize) -> f64,
    noise: f64,
) -> SmithRun {
    use msp::Controller;
    let model: msp::ProcessModel<f64> = msp::Fopdt::new(1.0, 4.0, 1.0).unwrap().into();
    let pi = msp::PidConfig::isa(4.0, 4.0, 0.0, TS);
    let sp: msp::SmithPredictor<f64, 1, [f64; 64]> =
        msp::SmithPredictor::from_model(pi, &model, TS).unwrap();
    let mut c: msp::adapt::Adaptive<f64, _, _, 16, 64> =
        msp::adapt::Adaptive::new(sp, (1.0, 4.0, 1.0), cfg, gains).unwrap();
    let a = (-TS / 4.0f64).exp();
    let mut gauss = common::gaussian(0x2545_f491_4f6c_dd1d);
    let (mut x, mut line) = (0.0, std::collections::VecDeque::from(vec![0.0; 10]));
    let mut err = Vec::new();
    for i in 0..9000 {
        let r = ((i / 300) % 2) as f64;
        let y = x + noise * gauss();
        let u = c.update(r, y);
        err.push(r - x);
        line.push_back(u);
        let late = line.pop_front().unwrap();
        x = a * x + (1.0 - a) * k(i) * late;
    }
    SmithRun {
        err,
        log: c.log().collect(),
        model: c.model(),
        noise: c.estimator().noise_level(),
    }
}

fn adapt_config() -> msp::adapt::AdaptiveConfig<f64> {
    let mut est = msp::adapt::EstimatorConfig::new(TS, 4);
    est.set_prefilter_time(10.0).unwrap();
    msp::adapt::AdaptiveConfig::new(est)
}

/// Kaya's PI for a model (`λ = 1 s`).
fn kaya(k: f64, tau: f64, _theta: f64) -> Option<[f64; 3]> {
    Some([tau / k, tau, 0.0])
}

/// A change that makes the loop oscillate is undone: the primary's gains
/// for the new model (the process gain rose 30 %) are made to give an
/// integral action of 1.3 per sample, and the growing oscillation that
/// follows restores the last good model (the commissioned one, or one
/// applied before that the loop bore) and its tuning; the loop settles
/// again. The same change with the rule's own gains stays.
#[test]
fn an_oscillating_change_restores_the_last_good_model() {
    use msp::adapt::ChangeKind::{Applied, Restored};
    let drift = |i: usize| if i < 1500 { 1.0 } else { 1.3 };
    let wild = |k: f64, tau: f64, theta: f64| {
        let [kp, ti, td] = kaya(k, tau, theta)?;
        Some(if (k - 1.0).abs() < 1e-12 {
            [kp, ti, td]
        } else {
            [kp, kp * TS / 1.3, td]
        })
    };
    let run = smith_run(adapt_config(), wild, drift, 0.0);
    let kinds = run.kinds();
    // (a change the loop bears is kept: the first one restored is the
    // change applied just before it, back to the last good model)
    let restored = kinds
        .iter()
        .position(|k| *k == Restored)
        .expect("a restore");
    let applied = kinds
        .get(..restored)
        .and_then(|k| k.iter().rposition(|k| *k == Applied));
    let Some(applied) = applied else {
        panic!("{kinds:?}")
    };
    // back to the commissioned model, or to one applied before the
    // change that oscillated (which the loop bore for its watch: validated)
    let back = run.log[restored];
    let back = (back.k, back.tau, back.theta);
    let earlier = run.log[..applied]
        .iter()
        .filter(|c| c.kind == Applied)
        .any(|c| (c.k, c.tau, c.theta) == back);
    assert!(back == (1.0, 4.0, 1.0) || earlier, "{:?}", run.log);
    let ok = smith_run(adapt_config(), kaya, drift, 0.0);
    assert!(!ok.kinds().contains(&Restored), "{:?}", ok.kinds());
    // both settled at the end of the last half period
    for e in [&run.err, &ok.err] {
        assert!(e.last().unwrap().abs() < 1e-3, "{:?}", e.last());
    }
}

/// The oscillation detector's band rises above the noise it measures: with
/// 2 % measurement noise and no band given (a device need not know its
/// noise), a right change is not taken for an oscillation (the noise
/// crosses zero every few samples, each half-cycle short) and stays; the
/// model in use becomes the process's.
#[test]
fn noise_alone_restores_nothing() {
    use msp::adapt::ChangeKind::{Applied, Restored};
    let drift = |i: usize| if i < 1500 { 1.0 } else { 1.3 };
    let run = smith_run(adapt_config(), kaya, drift, 0.02);
    let kinds = run.kinds();
    assert!(kinds.contains(&Applied), "{kinds:?}");
    assert!(!kinds.contains(&Restored), "{kinds:?}");
    assert!((run.model.0 - 1.3).abs() < 0.05 * 1.3, "{:?}", run.model);
    // the noise as the estimator measures it: about the deviation given
    let sigma = run.noise;
    assert!((0.01..0.03).contains(&sigma), "{sigma}");
}

/// No sample that is not the process's answer to the control law teaches
/// the estimator: with the process's gain 30 % up, 3 000 samples in manual
/// (the operator's output followed, `Operate::apply`) and 3 000 with the
/// actuator saturated (`update_applied` with what it really took) leave
/// the estimate exactly as it was; the same 3 000 samples in automatic
/// move it.
#[test]
fn manual_and_saturated_samples_teach_nothing() {
    use msp::operate::{Operate, Tracking};
    use msp::Controller;
    let build = || {
        let model: msp::ProcessModel<f64> = msp::Fopdt::new(1.0, 4.0, 1.0).unwrap().into();
        let pi = msp::PidConfig::isa(4.0, 4.0, 0.0, TS);
        let sp: msp::SmithPredictor<f64, 1, [f64; 64]> =
            msp::SmithPredictor::from_model(pi, &model, TS).unwrap();
        let c: msp::adapt::Adaptive<f64, _, _, 16, 64> =
            msp::adapt::Adaptive::new(sp, (1.0, 4.0, 1.0), adapt_config(), kaya).unwrap();
        c
    };
    let a = (-TS / 4.0f64).exp();
    // a process state and its input line, shared by the phases
    struct Plant {
        x: f64,
        line: std::collections::VecDeque<f64>,
    }
    let step = |p: &mut Plant, u: f64, k: f64| {
        p.line.push_back(u);
        let late = p.line.pop_front().unwrap();
        p.x = a * p.x + (1.0 - a) * k * late;
    };
    let r = |i: usize| ((i / 300) % 2) as f64;
    // learnt on the process as modelled
    let warm = || {
        let mut c = build();
        let mut p = Plant {
            x: 0.0,
            line: vec![0.0; 10].into(),
        };
        for i in 0..3000 {
            let u = c.update(r(i), p.x);
            step(&mut p, u, 1.0);
        }
        (c, p)
    };
    // the model estimated (the evidence, from the costs, moves with any data)
    let model = |c: &msp::adapt::Estimate<f64>| (c.k, c.tau, c.theta, c.d);
    let (mut manual, mut pm) = warm();
    let before = model(&manual.estimate().unwrap());
    for i in 3000..6000 {
        manual.update(r(i), pm.x);
        // the operator's output, moving as a set point would
        let u = 2.0 * r(i) - 0.5;
        manual.apply(u, Tracking::Full);
        step(&mut pm, u, 1.3);
    }
    assert_eq!(model(&manual.estimate().unwrap()), before);
    let (mut saturated, mut ps) = warm();
    let mut took = 0.0;
    for i in 3000..6000 {
        let u = saturated.update_applied(r(i), ps.x, Some(took));
        // the actuator's range ends near where the loop rests: it saturates
        // at every move
        took = u.clamp(-0.05, 0.05);
        step(&mut ps, took, 1.3);
    }
    assert_eq!(model(&saturated.estimate().unwrap()), before);
    let (mut auto, mut pa) = warm();
    for i in 3000..6000 {
        let u = auto.update(r(i), pa.x);
        step(&mut pa, u, 1.3);
    }
    let moved = model(&auto.estimate().unwrap());
    assert!((moved.0 - 1.3).abs() < (before.0 - 1.3).abs(), "{moved:?}");
}
