//! timing
fn main() {
    let sc = msp::sim::Scenario {
        plant: "5.6*e^-93.9s/(40.2s+1)".into(),
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let mut n = 0;
    for _ in 0..300 {
        let o = sc.run().unwrap();
        n += o.result.t.len();
    }
    let dt = t0.elapsed();
    println!(
        "{:.1} ns/sample, {:.3} ms/run",
        dt.as_nanos() as f64 / n as f64,
        dt.as_secs_f64() * 1e3 / 300.0
    );
}
