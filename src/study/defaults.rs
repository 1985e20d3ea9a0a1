//! What a run chooses when the user does not: the sample period and the duration.

use std::string::String;

use crate::poly::{fmt_num, PlantKind, TransferFunction};

/// A sample period for `plant`: at most a tenth of its fastest time constant
/// and 1/1000 of its dead time. The sampled loop then reproduces the continuous
/// designs of the sources to better than 1 %: a controller designed for a
/// closed-loop time constant `τ` and sampled with forward-Euler integration
/// gives `τ − Ts/2` (e.g. the Karan–Dey MSP's IAE on the delayed reference is
/// `θ/8 − Ts/2`). The period divides the dead time into a whole number of
/// samples (then the delay is exact in the controller's model too), and
/// never into more than [`MAX_CHOSEN_SAMPLES`]: a lag below 10⁻⁴ of the dead
/// time is then shorter than a tenth of a sample, exact in the ZOH model
/// but not resolved between samples, where a finer period would give a
/// delay line, a simulation and an analysis that grow with θ/τ (θ/τ = 10⁶:
/// 10⁷ samples, half a minute and a gigabyte for `msp tune`).
pub fn choose_ts(plant: &TransferFunction) -> f64 {
    let ts = finest_ts(plant);
    if plant.delay > 0.0 {
        let n = (plant.delay / ts).ceil().clamp(1.0, MAX_CHOSEN_SAMPLES);
        plant.delay / n
    } else {
        ts
    }
}

/// [`choose_ts`] before the dead time is divided into whole samples and
/// their number capped.
fn finest_ts(plant: &TransferFunction) -> f64 {
    let scales = plant.time_scales().unwrap_or_default();
    let dyn_min = scales
        .iter()
        .copied()
        .filter(|s| (*s - plant.delay).abs() > 0.0 || plant.delay == 0.0)
        .fold(f64::INFINITY, f64::min);
    let mut ts = (dyn_min / 10.0).min(if plant.delay > 0.0 {
        plant.delay / 1000.0
    } else {
        f64::INFINITY
    });
    if !ts.is_finite() {
        ts = 0.01;
    }
    ts
}

/// The most samples of dead time a chosen period gives ([`choose_ts`]).
pub const MAX_CHOSEN_SAMPLES: f64 = 1e5;

/// A duration that covers settling: ten dead times, ten of the slowest time
/// constants, or ten times the sum of the lags, whichever is longest. The sum
/// of the lags is exact from the coefficients (`a₁/a₀` of the denominator
/// without its integrators, minus `b₁/b₀` of the numerator: the lags of
/// `∏(τᵢs + 1)` add up to the coefficient of `s`), and it is what a chain of
/// lags such as `(10s + 1)^4` takes to settle, where its slowest single time
/// constant (10 s) is not. The slowest time constant of a lightly damped pair
/// is its decay time `1/(ζωn)`, not `1/ωn` (`1/(s^2 + 0.4s + 1)` rings for 20 s).
pub fn choose_duration(plant: &TransferFunction, ts: f64) -> f64 {
    let decay = plant
        .poles()
        .unwrap_or_default()
        .into_iter()
        // a pole at the origin comes out of the eigenvalues as ±1e-17
        .filter(|(re, im)| *re < 0.0 && re.hypot(*im) > 1e-9)
        .map(|(re, _)| -1.0 / re)
        .fold(0.0, f64::max);
    let slow = plant
        .time_scales()
        .unwrap_or_default()
        .into_iter()
        .fold(decay, f64::max);
    // a₁/a₀ of a polynomial without its roots at the origin
    let ratio = |p: &[f64]| -> f64 {
        let end = p.iter().rposition(|c| *c != 0.0).map_or(0, |i| i + 1);
        match p.get(..end) {
            Some([.., a1, a0]) => a1 / a0,
            _ => 0.0,
        }
    };
    let lags = (ratio(&plant.den) - ratio(&plant.num)).abs();
    let lags = if lags.is_finite() { lags } else { 0.0 };
    (10.0 * plant.delay.max(slow).max(lags)).max(100.0 * ts)
}

/// Shown next to a chosen value: `0.074 (chosen: 100 samples of dead time)`.
pub fn describe_ts(plant: &TransferFunction, ts: f64) -> String {
    if plant.delay > 0.0 {
        let n = (plant.delay / ts).round();
        std::format!(
            "{} s ({} samples of dead time{})",
            fmt_num(ts),
            fmt_num(n),
            if plant.delay / finest_ts(plant) > MAX_CHOSEN_SAMPLES && ts == choose_ts(plant) {
                ", the most a chosen period gives: faster lags are not resolved between samples"
            } else {
                ""
            }
        )
    } else {
        std::format!("{} s", fmt_num(ts))
    }
}

/// Kind of a plant, for messages.
pub fn kind_of(plant: &TransferFunction) -> PlantKind {
    plant.kind()
}

#[cfg(test)]
mod tests {
    use super::{choose_ts, describe_ts, MAX_CHOSEN_SAMPLES};
    use crate::poly::TransferFunction;

    /// A tenth of the lag and 1/1000 of the dead time, the dead time a whole
    /// number of samples, never more than 10⁵ of them (θ/τ = 10⁶: 10 s,
    /// where a tenth of the lag would give 10⁷ samples), and the description
    /// says when the cap chose it.
    #[test]
    fn the_chosen_period_divides_the_dead_time_into_at_most_1e5_samples(
    ) -> Result<(), crate::syntax::ParseError> {
        let cases = [
            ("e^-5s/(10s+1)", 0.005, false),
            ("e^-10s/(0.5s+1)", 0.01, false),
            ("e^-1e4s/(s+1)", 0.1, false),
            ("e^-1e5s/(s+1)", 1.0, true),
            ("e^-1e6s/(s+1)", 10.0, true),
        ];
        for (text, ts, capped) in cases {
            let plant: TransferFunction = text.parse()?;
            let got = choose_ts(&plant);
            assert!((got - ts).abs() <= 1e-12 * ts, "{text}: {got}");
            let n = (plant.delay / got).round();
            assert!(n <= MAX_CHOSEN_SAMPLES, "{text}: {n}");
            let said = describe_ts(&plant, got).contains("the most a chosen period gives");
            assert_eq!(said, capped, "{text}");
        }
        Ok(())
    }
}
