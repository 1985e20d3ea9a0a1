#![allow(missing_docs)]
//! Sweeps, trade-offs and comparisons on one core and on every core, side
//! by side: the target is the same cost per sample per core (the time ×
//! threads ÷ samples of the "every core" line equal to the one-thread
//! line's time ÷ samples).
//!
//! A sweep's row is a closed-loop run and the characteristic equation's
//! stability verdict for its plant; a trade-off's point a run at one `λ`;
//! a comparison one run and verdict per scheme. Each thread writes into the
//! buffers of its last run (`msp::study::recycle`).
//!
//! Run: `cargo bench --bench studies --features parallel`.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use msp::sim::SetpointStep;
use msp::study::{compare, tradeoff, Perturbation, Scenario};
use msp::sweep::{sweep, Range, SweepSpec};

/// The MathWorks example's plant, its dead time 939 samples at Ts = 0.1 s.
fn scenario(controller: &str) -> Scenario {
    Scenario {
        plant: Some("5.6*e^-93.9s/(40.2s+1)".parse().expect("plant")),
        controller: Some(controller.into()),
        ts: Some(0.1),
        duration: Some(3000.0),
        setpoint: vec![SetpointStep {
            value: 1.0,
            at: 0.0,
        }],
        ..Default::default()
    }
}

/// `work` timed on a pool of one thread and on one of every core.
fn on_each_pool(c: &mut Criterion, group: &str, samples: u64, work: impl Fn() -> usize + Sync) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(samples));
    g.sample_size(10);
    for threads in [1, cores] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let name = if threads == 1 {
            "1 thread".to_string()
        } else {
            format!("{threads} threads")
        };
        g.bench_function(name, |b| b.iter(|| pool.install(&work)));
    }
    g.finish();
}

fn studies(c: &mut Criterion) {
    let base = scenario("smith");
    let spec = SweepSpec {
        gain: Range::new(-0.2, 0.2).expect("range"),
        delay: Range::new(-0.2, 0.2).expect("range"),
        tau: Range::new(0.0, 0.0).expect("range"),
        grid: 8,
        samples: 0,
        seed: 1,
        shard: (0, 1),
    };
    on_each_pool(
        c,
        "sweep: smith, 8 x 8 rows of 30 001 samples",
        64 * 30_001,
        || sweep(&base, &spec, &|_| {}).expect("sweep").len(),
    );
    let schemes: Vec<String> = ["smith", "pi", "filtered-smith", "fsp"]
        .map(String::from)
        .to_vec();
    let mut short = scenario("smith");
    short.duration = Some(1000.0);
    let points = msp::study::tradeoff_factors().len() as u64 * schemes.len() as u64;
    on_each_pool(
        c,
        "trade-off: 4 schemes x 13 lambdas, 10 001 samples each",
        points * 10_001,
        || {
            tradeoff(&short, &schemes, &|_, _| {})
                .expect("trade-off")
                .points
                .len()
        },
    );
    on_each_pool(
        c,
        "compare: 4 schemes, 30 001 samples each",
        4 * 30_001,
        || {
            compare(&base, &schemes, Perturbation::default())
                .expect("compare")
                .len()
        },
    );
}

criterion_group!(benches, studies);
criterion_main!(benches);
