//! What the multivariable loop tests share: transfer functions, Wood and
//! Berry's column, set-point steps, a random stream and msp's verdict.
#![allow(dead_code)]

use msp::analysis::mimo::{SampledLoop, TransferMatrix};
use msp::poly::TransferFunction;
use msp::sim::SetpointStep;
use msp::{LoopController, Pid, PidConfig};

pub fn tf(s: &str) -> TransferFunction {
    s.parse().unwrap()
}

/// Wood & Berry (1973), time in minutes.
pub fn wood_berry() -> TransferMatrix {
    TransferMatrix::new(vec![
        vec![tf("12.8e^-1s/(16.7s+1)"), tf("-18.9e^-3s/(21s+1)")],
        vec![tf("6.6e^-7s/(10.9s+1)"), tf("-19.4e^-3s/(14.4s+1)")],
    ])
    .unwrap()
}

/// One set-point step per loop: `(value, at)` each.
pub fn steps(each: &[(f64, f64)]) -> Vec<Vec<SetpointStep>> {
    each.iter()
        .map(|&(value, at)| vec![SetpointStep { value, at }])
        .collect()
}

pub struct Rng(pub u64);

impl Rng {
    pub fn uni(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// msp's verdict for the PI loops `pis` on `m`.
pub fn verdict(m: &TransferMatrix, pis: &[(f64, f64)], ts: f64) -> Option<bool> {
    let loops: Vec<Pid<f64>> = pis
        .iter()
        .map(|(kp, ti)| Pid::new(PidConfig::isa(*kp, *ti, 0.0, ts)).unwrap())
        .collect();
    let refs: Vec<&dyn LoopController<f64>> = loops.iter().map(|p| p as _).collect();
    SampledLoop::new(m, ts, &refs, None)
        .unwrap()
        .verdict()
        .stable
}
