#![allow(missing_docs)]
//! Controller updates against a hand-written Smith-PI step, in f32 and f64.
//!
//! Run: `cargo bench --bench controllers`. Each update is timed in a loop that
//! feeds its output back through a first-order plant, so the dependency chain
//! of a real loop is measured, the same for msp and the reference.
use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use msp::dtc::karan_dey;
use msp::poly::TransferFunction;
use msp::registry::{Build, Precision, SCHEMES};
use msp::{
    Controller, Delay, DelayLine, Fopdt, Ipdt, PidConfig, ProcessModel, Real, SmithPredictor,
};

/// The minimal hand-written Smith-PI step: PI, first-order model, ring buffer.
struct HandSmith<T, const N: usize> {
    kp: T,
    ki: T,
    a: T,
    b: T,
    integ: T,
    ym: T,
    buf: [T; N],
    head: usize,
}

impl<T: Real, const N: usize> HandSmith<T, N> {
    fn new() -> Self {
        let a = T::of((-0.939f64 / 40.2).exp());
        HandSmith {
            kp: T::of(0.0764),
            ki: T::of(0.0764 * 0.939 / 40.2),
            a,
            b: T::of(5.6) * (T::one() - a),
            integ: T::zero(),
            ym: T::zero(),
            buf: [T::zero(); N],
            head: 0,
        }
    }
    #[inline(always)]
    fn update(&mut self, r: T, y: T) -> T {
        let ymd = self.buf[self.head];
        self.buf[self.head] = self.ym;
        self.head += 1;
        if self.head == N {
            self.head = 0;
        }
        let e = r - (self.ym + y - ymd);
        let u = self.kp * e + self.integ;
        self.integ = self.integ + self.ki * e;
        self.ym = self.a * self.ym + self.b * u;
        u
    }
}

fn fopdt<T: Real>() -> ProcessModel<T> {
    Fopdt::new(T::of(5.6), T::of(40.2), T::of(93.9))
        .map(Into::into)
        .expect("model")
}

fn smith<T: Real, const D: usize>(delay: f64) -> SmithPredictor<T, 1, [T; D]> {
    let ts = T::of(0.939);
    let m: ProcessModel<T> = Fopdt::new(T::of(5.6), T::of(40.2), T::of(delay * 0.939))
        .map(Into::into)
        .expect("model");
    SmithPredictor::from_model(
        PidConfig::isa(T::of(0.0764), T::of(40.2), T::zero(), ts),
        &m,
        ts,
    )
    .expect("smith")
}

/// Times `step(r, y) -> u` inside a loop closed through `y ← 0.99·y + 0.01·u`,
/// the set point switching between 1 and 2 every 4096 samples: a loop left
/// at rest lets its filters' states decay into subnormal numbers, whose
/// arithmetic is many times slower on x86 (Huang's `B` filter measured
/// 83 ns there) and is not what a running plant sees.
fn closed<T: Real>(c: &mut Criterion, group: &str, name: &str, step: impl FnMut(T, T) -> T) {
    let mut y = T::zero();
    closed_through(c, group, name, step, move |u| {
        y = T::of(0.99) * y + T::of(0.01) * u;
        y
    });
}

/// [`closed`] through the plant `plant(u) -> y` (the next measurement), a
/// sample an iteration.
fn closed_through<T: Real>(
    c: &mut Criterion,
    group: &str,
    name: &str,
    step: impl FnMut(T, T) -> T,
    plant: impl FnMut(T) -> T,
) {
    timed(c, group, name, 1, step, plant);
}

/// The samples of one cycle of the adaptive loop's set point: 4096 at 1,
/// 4096 at 2 (the estimator learns after each switch and rests between),
/// which [`timed`] takes whole per iteration for the adaptive loop: every
/// iteration the same mix of learning and rest, so that the time per sample
/// (the cycle's over `CYCLE`; criterion's throughput) does not depend on
/// where criterion's batches fall in the cycle (per-sample iterations gave
/// 29 to 40 ns from run to run for one loop that runs at 28 ns a sample).
const CYCLE: u32 = 8192;

/// Times `samples` samples an iteration of `step` in the loop through
/// `plant`, the set point switching between 1 and 2 every 4096 samples
/// (criterion's throughput: the samples).
fn timed<T: Real>(
    c: &mut Criterion,
    group: &str,
    name: &str,
    samples: u32,
    mut step: impl FnMut(T, T) -> T,
    mut plant: impl FnMut(T) -> T,
) {
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(u64::from(samples)));
    let mut y = T::zero();
    let mut k = 0u32;
    g.bench_function(name, |b| {
        b.iter(|| {
            let mut u = T::zero();
            for _ in 0..samples {
                let r = if (k >> 12) & 1 == 0 {
                    T::one()
                } else {
                    T::of(2.0)
                };
                k = k.wrapping_add(1);
                u = step(black_box(r), y);
                y = plant(u);
            }
            u
        })
    });
    g.finish();
}

fn updates<T: Real>(c: &mut Criterion, ty: &str) {
    let group = format!("update/{ty}");
    let mut hand = HandSmith::<T, 100>::new();
    closed(c, &group, "hand-written smith-pi", |r, y| hand.update(r, y));
    let mut sp = smith::<T, 128>(100.0);
    closed(c, &group, "smith", |r, y| sp.update(r, y));
    let ipdt = Ipdt::new(T::of(0.2), T::of(7.4)).expect("ipdt");
    let p = msp::tuning::karan_dey(&ipdt, ipdt.l / T::of(4.0)).expect("tuning");
    let mut kd =
        karan_dey::from_model::<T, 1, [T; 128]>(&p, &ipdt.into(), T::of(0.074)).expect("kd");
    closed(c, &group, "karan-dey", |r, y| kd.update(r, y));
    let _ = fopdt::<T>();
    adaptive::<T>(c, &group);
}

/// The adaptive Smith predictor of the firmware (16 candidate dead times
/// of 5 … 20 estimator samples, each the mean of 10 controller samples:
/// half to twice the model's 100, as `msp run --adapt` decimates, plain
/// differences) in the loop it was built for: the MathWorks process
/// itself, its dead time in a ring, the set point switching every 4096
/// samples (it learns for about a thousand after each switch and rests
/// for the rest, as in a plant), timed a whole cycle at a time ([`CYCLE`]).
fn adaptive<T: Real>(c: &mut Criterion, group: &str) {
    let ts = T::of(0.939);
    let mut est = msp::adapt::EstimatorConfig::new(ts, 5);
    est.decimation = 10;
    let mut ad = msp::adapt::Adaptive::<T, _, (), 16, 112>::new(
        smith::<T, 128>(100.0),
        (T::of(5.6), T::of(40.2), T::of(93.9)),
        msp::adapt::AdaptiveConfig::new(est),
        (),
    )
    .expect("adaptive");
    timed(
        c,
        group,
        "adaptive smith (16 candidates), a set-point cycle",
        CYCLE,
        |r, y| ad.update(r, y),
        mathworks::<T>(),
    );
    // the same predictor without the estimator, through the same process:
    // what the adaptation costs on top
    let mut sp = smith::<T, 128>(100.0);
    timed(
        c,
        group,
        "smith (the adaptive one's loop), a set-point cycle",
        CYCLE,
        |r, y| sp.update(r, y),
        mathworks::<T>(),
    );
}

/// The MathWorks process `5.6 e^{−93.9s}/(40.2s + 1)` sampled at 0.939 s
/// (its dead time a ring of 100 samples): `u` in, the next `y` out.
fn mathworks<T: Real>() -> impl FnMut(T) -> T {
    let a = T::of((-0.939f64 / 40.2).exp());
    let b = T::of(5.6) * (T::one() - a);
    let mut line = [T::zero(); 100];
    let (mut at, mut y) = (0usize, T::zero());
    move |u: T| {
        y = a * y + b * line[at];
        line[at] = u;
        at = if at + 1 == line.len() { 0 } else { at + 1 };
        y
    }
}

/// Every scheme as the registry builds it (dynamic dispatch), in precision `T`.
fn registry_updates<T: Precision>(c: &mut Criterion, ty: &str) {
    let group = format!("update/{ty}/registry");
    for s in SCHEMES {
        let (plant, inner): (TransferFunction, Option<TransferFunction>) = if s.is_cascade() {
            (
                common::EXAMPLE2.0.parse().expect("plant"),
                Some(common::EXAMPLE2.1.parse().expect("inner plant")),
            )
        } else if s.plants.contains(&msp::poly::PlantKind::Integrating) {
            ("0.2/s*e^-7.4s".parse().expect("plant"), None)
        } else {
            ("5.6*e^-93.9s/(40.2s+1)".parse().expect("plant"), None)
        };
        let set = common::required_settings(s.name);
        let p = s
            .tune_process(&plant, inner.as_ref(), None, None, &set)
            .expect("tune");
        let build = Build {
            ts: 0.1,
            u_min: f64::NEG_INFINITY,
            u_max: f64::INFINITY,
            max_dead_time: 0.0,
        };
        let mut ctrl = s
            .build_process_as::<T>(&p, &plant, inner.as_ref(), &build)
            .expect("build");
        if s.is_cascade() {
            // the secondary measurement follows the primary one here: the
            // timing, not the loop, is the point
            closed(c, &group, s.name, |r, y| ctrl.update_cascade(r, y, y));
        } else {
            closed(c, &group, s.name, |r, y| ctrl.update(r, y));
        }
    }
}

fn capacity(c: &mut Criterion) {
    // the cost does not grow with the dead time or the delay line's capacity
    let mut g = c.benchmark_group("smith/delay-capacity");
    g.throughput(Throughput::Elements(1));
    macro_rules! at {
        ($n:literal) => {{
            let mut sp = smith::<f64, $n>($n as f64);
            let mut y = 0.0;
            g.bench_with_input(BenchmarkId::from_parameter($n), &$n, |b, _| {
                b.iter(|| {
                    let u = sp.update(black_box(1.0), y);
                    y = 0.99 * y + 0.01 * u;
                    u
                })
            });
        }};
    }
    at!(16);
    at!(1024);
    at!(65536);
    g.finish();
    let mut g = c.benchmark_group("delay-line");
    g.throughput(Throughput::Elements(1));
    macro_rules! line {
        ($n:literal) => {{
            let mut d: DelayLine<f64, $n> = Delay::new_in(($n - 1) as f64 + 0.5).expect("line");
            let mut x = 0.0;
            g.bench_with_input(BenchmarkId::from_parameter($n), &$n, |b, _| {
                b.iter(|| {
                    x += 1.0;
                    d.process(black_box(x))
                })
            });
        }};
    }
    line!(16);
    line!(1024);
    line!(65536);
    g.finish();
    // the filtered Smith predictor of a stable plant: model-sized blocks around
    // the input line, the same cost at every dead time
    let mut g = c.benchmark_group("fsp/stable-dead-time");
    g.throughput(Throughput::Elements(1));
    for h in [16usize, 1024, 65536] {
        let (gm, _) = ProcessModel::from(Fopdt::new(1.0, 10.0, 1.0).expect("model"))
            .discretize::<1>(0.1)
            .expect("model");
        let d = msp::dtc::fsp::design::<Vec<f64>, 1>(&gm, h, 0.1, 5.0).expect("design");
        let mut fsp: msp::dtc::fsp::FilteredSmith<f64, Vec<f64>> =
            msp::dtc::fsp::FilteredSmith::new(
                PidConfig::isa(1.0, 10.0, 0.0, 0.1),
                &d,
                Default::default(),
            )
            .expect("fsp");
        // a bounded measurement (a loop through a plant without the
        // model's dead time would diverge for short ones, and the
        // non-finite path would be timed instead)
        let mut k = 0u32;
        g.bench_with_input(BenchmarkId::from_parameter(h), &h, |b, _| {
            b.iter(|| {
                k = k.wrapping_add(1);
                let y = if k & 1 == 0 { 0.4 } else { 0.6 };
                fsp.update(black_box(1.0), black_box(y))
            })
        });
    }
    g.finish();
}

/// The Wood–Berry column at 1 min: `(K, τ, θ)` of `g11, g12, g21, g22`.
const WOOD_BERRY: [(f64, f64, f64); 4] = [
    (12.8, 16.7, 1.0),
    (-18.9, 21.0, 3.0),
    (6.6, 10.9, 7.0),
    (-19.4, 14.4, 3.0),
];

/// Channel `(K, τ, θ)` sampled at 1 (ZOH, `a = e^{−1/τ}`, `b = K(1 − a)`),
/// its dead time in a ring of 8.
struct Channel<T> {
    a: T,
    b: T,
    x: T,
    ring: [T; 8],
    at: usize,
    d: usize,
}

impl<T: Real> Channel<T> {
    fn new((k, tau, theta): (f64, f64, f64)) -> Self {
        let a = (-1.0 / tau).exp();
        Channel {
            a: T::of(a),
            b: T::of(k * (1.0 - a)),
            x: T::zero(),
            ring: [T::zero(); 8],
            at: 0,
            d: theta as usize,
        }
    }
    /// Holds `u[k]` over the period: `y[k + 1] = a·y[k] + b·u[k − θ]`.
    #[inline(always)]
    fn step(&mut self, u: T) -> T {
        let late = self.ring[(self.at + 8 - self.d) % 8];
        self.ring[self.at] = u;
        self.at = (self.at + 1) % 8;
        self.x = self.a * self.x + self.b * late;
        self.x
    }
}

/// Loop `i`'s Smith predictor on `gᵢᵢ` (λ = θᵢᵢ: `Kc = τ/(K·λ)`, `τI = τ`).
fn wb_smith<T: Real>(i: usize) -> SmithPredictor<T, 1, [T; 8]> {
    let (k, tau, theta) = WOOD_BERRY[i * 3];
    let m: ProcessModel<T> = Fopdt::new(T::of(k), T::of(tau), T::of(theta))
        .map(Into::into)
        .expect("model");
    let cfg = PidConfig::isa(T::of(tau / (k * theta)), T::of(tau), T::zero(), T::one());
    SmithPredictor::from_model(cfg, &m, T::one()).expect("smith")
}

/// A 2×2 closed-loop sample (#51 item 8): the Wood–Berry column under the
/// decoupled Smith predictors and under decentralized ones (`no_std`
/// forms, arrays), beside one loop of its diagonal under one Smith
/// predictor, each through its exactly sampled channels.
fn mimo<T: Real>(c: &mut Criterion, ty: &str) {
    use msp::mimo::{fopdt_element, Decentralized, Decoupled, InvertedDecoupler, MultiController};
    let group = format!("update/{ty}/mimo");
    let fopdt = |i: usize| {
        let (k, t, l) = WOOD_BERRY[i];
        Fopdt::new(T::of(k), T::of(t), T::of(l)).expect("model")
    };
    let el = |i: usize, j: usize| {
        Some(
            fopdt_element(&fopdt(i * 2 + j), &fopdt(i * 3), T::one(), [T::zero(); 8])
                .expect("element"),
        )
    };
    let decoupler =
        InvertedDecoupler::new([[None, el(0, 1)], [el(1, 0), None]]).expect("decoupler");
    let mut decoupled = Decoupled::new([wb_smith::<T>(0), wb_smith::<T>(1)], decoupler);
    let mut decentralized = Decentralized::new([wb_smith::<T>(0), wb_smith::<T>(1)]);
    let two = |c: &mut Criterion, name: &str, ctl: &mut dyn MultiController<T>| {
        let mut g = c.benchmark_group(&group);
        g.throughput(Throughput::Elements(1));
        let mut plant: [Channel<T>; 4] = WOOD_BERRY.map(Channel::new);
        let (mut y, mut u, mut k) = ([T::zero(); 2], [T::zero(); 2], 0u32);
        g.bench_function(name, |b| {
            b.iter(|| {
                k = k.wrapping_add(1);
                let r = if (k >> 8) & 1 == 0 {
                    T::one()
                } else {
                    T::zero()
                };
                ctl.update(&[black_box(r), T::zero()], &y, &mut u);
                let [g11, g12, g21, g22] = &mut plant;
                y = [
                    g11.step(u[0]) + g12.step(u[1]),
                    g21.step(u[0]) + g22.step(u[1]),
                ];
                u[0]
            })
        });
        g.finish();
    };
    two(c, "2x2 decoupled smith (wood-berry)", &mut decoupled);
    two(
        c,
        "2x2 decentralized smith (wood-berry)",
        &mut decentralized,
    );
    let mut one = wb_smith::<T>(0);
    let mut ch = Channel::<T>::new(WOOD_BERRY[0]);
    closed_through(
        c,
        &group,
        "1x1 smith (wood-berry's g11)",
        |r, y| one.update(r, y),
        move |u| ch.step(u),
    );
}

fn all(c: &mut Criterion) {
    mimo::<f64>(c, "f64");
    mimo::<f32>(c, "f32");
    updates::<f64>(c, "f64");
    updates::<f32>(c, "f32");
    registry_updates::<f64>(c, "f64");
    registry_updates::<f32>(c, "f32");
    capacity(c);
}

criterion_group!(benches, all);
criterion_main!(benches);
