//! The adaptive Karan–Dey predictor on the device, its scheme designed
//! anew for each model it applies: in the background (`background_design`,
//! `Adaptive::design` called between samples, as a background task would),
//! so that no update carries a design (#48 item 7); the design's own cost
//! measured apart, with the filtered Smith predictor's (f64) for reference.

use super::{fail, loops, Ticks};
use msp::dtc::fsp::FilteredSmith;
use msp::dtc::karan_dey::{self, KaranDey};

/// The Karan–Dey predictor of `loops::karan_dey` (0.2 e^{−7.4s}/s at
/// 0.074 s, 100 samples of dead time).
pub type Kd = KaranDey<f32, 1, [f32; loops::CAP]>;

/// It kept right by a bank of 16 candidate dead times (5 … 20 estimator
/// samples of 10 controller samples), rebuilt by the thesis's rule at each
/// change.
pub type AdaptiveKd =
    msp::adapt::Adaptive<f32, Kd, msp::adapt::Rebuild<fn(f32, f32, f32) -> Option<Kd>>, 16, 112>;

/// The predictor for the model `k e^{−θs}/s` (`tau` infinite): Bag
/// (2022)'s tuning at `λ = θ/4`, built at 0.074 s.
#[inline(never)]
pub fn karan_dey_for(k: f32, tau: f32, theta: f32) -> Option<Kd> {
    if tau.is_finite() {
        return None;
    }
    let ipdt = msp::Ipdt::new(k, theta).ok()?;
    let p = msp::tuning::karan_dey(&ipdt, theta / 4.0).ok()?;
    karan_dey::from_model(&p, &ipdt.into(), 0.074).ok()
}

/// One update of the adaptive Karan–Dey predictor.
#[inline(never)]
pub fn adaptive_kd_step(c: &mut AdaptiveKd, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

/// The design a model waits for (between samples).
#[inline(never)]
fn adaptive_kd_design(c: &mut AdaptiveKd) -> bool {
    c.design()
}

/// The longest update, its number, the models applied and the longest
/// design (SysTick ticks) of the adaptive Karan–Dey predictor on a process
/// whose gain is half its model's ([`applying`]), and its RAM (bytes: the
/// predictor in use, the place of the one warming up, the estimator).
pub fn karan_dey_applying() -> ((u32, usize, usize, u32), usize) {
    let Some(kd) = karan_dey_for(0.2, f32::INFINITY, 7.4) else {
        fail()
    };
    let mut est = msp::adapt::EstimatorConfig::new(0.074, 5);
    est.decimation = 10;
    est.integrating = true;
    let mut cfg = msp::adapt::AdaptiveConfig::new(est);
    cfg.background_design = true;
    let redesign = msp::adapt::Rebuild(karan_dey_for as fn(f32, f32, f32) -> Option<Kd>);
    let Ok(mut c) = AdaptiveKd::new(kd, (0.2, f32::INFINITY, 7.4), cfg, redesign) else {
        fail()
    };
    let process: msp::ProcessModel<f32> = match msp::Ipdt::new(0.1, 7.4) {
        Ok(m) => m.into(),
        Err(_) => fail(),
    };
    let mut plant = loops::Plant::new(&process, 0.074);
    let ram = core::mem::size_of_val(&c);
    (
        applying(&mut c, &mut plant, adaptive_kd_step, adaptive_kd_design),
        ram,
    )
}

/// The adaptive controller `c` on `plant`, the set point stepping between
/// 1 and 0.5 every 2 500 samples (12 000 in all), each `update` timed and
/// after it `design` (a model's waiting scheme designed, as a background
/// task would between samples; timed apart): the most ticks one update
/// took and its number, how many models were applied, the most ticks of a
/// design.
pub fn applying<C: msp::Operate<f32>>(
    c: &mut C,
    plant: &mut loops::Plant<f32>,
    mut update: impl FnMut(&mut C, f32, f32) -> f32,
    mut design: impl FnMut(&mut C) -> bool,
) -> (u32, usize, usize, u32) {
    let (mut ticks, mut designs) = (Ticks::default(), Ticks::default());
    for k in 0..12_000 {
        let r = if (k / 2500) % 2 == 0 { 1.0 } else { 0.5 };
        let y = plant.output();
        ticks.tick(true);
        let u = update(c, r, y);
        ticks.tick(false);
        plant.advance(u);
        designs.tick(true);
        design(c);
        designs.tick(false);
    }
    let mut applied = 0;
    c.visit_log(&mut |ch| {
        applied += usize::from(ch.kind == msp::adapt::ChangeKind::Applied);
    });
    (ticks.max, ticks.max_at, applied, designs.max)
}

/// The filtered Smith predictor of `loops::fsp` designed for a new model
/// (its filter and predictor in f64), as its adaptive redesign does.
#[inline(never)]
fn fsp_design(k: f64, t: f64, l: f64) -> Option<FilteredSmith<f32, [f32; loops::CAP]>> {
    let ts = 0.06;
    let m: msp::ProcessModel<f64> = msp::Ufopdt::new(k, t, l).ok()?.into();
    let (gm, _) = m.discretize::<1>(ts).ok()?;
    let h = msp::Real::f64(l / ts + 0.5) as usize;
    let d = msp::dtc::fsp::design::<[f64; loops::CAP], 1>(&gm, h, ts, l / 2.0).ok()?;
    let kkc = 1.0 + 2.0 * t / l;
    let pi = msp::PidConfig::isa((kkc / k) as f32, (kkc * l * l / t) as f32, 0.0, ts as f32);
    FilteredSmith::new(pi, &d, msp::ParamList::default()).ok()
}

/// The SysTick ticks of one filtered Smith design.
pub fn fsp_design_ticks() -> u32 {
    let mut t = Ticks::default();
    t.tick(true);
    let ok = fsp_design(5.5, 90.0, 6.6).is_some();
    t.tick(false);
    if !ok {
        fail()
    }
    t.max
}
