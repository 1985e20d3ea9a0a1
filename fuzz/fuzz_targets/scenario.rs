//! The scenario loader (TOML and JSON) never panics, and a loaded scenario
//! runs to a result or a typed error.
#![no_main]
use libfuzzer_sys::fuzz_target;
use msp::study::Scenario;

fuzz_target!(|data: &[u8]| {
    let Ok(s) = std::str::from_utf8(data) else {
        return;
    };
    let parsed = toml::from_str::<Scenario>(s)
        .ok()
        .or_else(|| serde_json::from_str::<Scenario>(s).ok());
    if let Some(sc) = parsed {
        // keep each run short: a fuzz input may ask for a billion samples
        let ts = sc.ts.unwrap_or(0.01);
        let samples = sc.duration.unwrap_or(100.0) / ts;
        if samples.is_finite() && samples < 2e4 && sc.substeps.unwrap_or(1) < 50 {
            if let Ok(out) = sc.run() {
                assert!(out.result.y.iter().all(|y| y.is_finite()));
            }
        }
    }
});
