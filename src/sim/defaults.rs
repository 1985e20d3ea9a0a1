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

/// [`choose_ts`] for a controller that computes in `f32` (`float32`), or
/// in `f64`. In `f32` the period is also no finer than 2⁻¹⁰ of the plant's
/// slowest time constant ([`F32_POLE_DISTANCE`]): a discrete pole
/// `e^{−Ts/τ}` is then at least 2⁻¹⁰ from 1, and the 24-bit significand
/// keeps 14 bits of that distance (at 1000 samples of dead time the
/// filtered Smith predictor of `5e^{−6s}/(100s − 1)` has its poles
/// 6·10⁻⁵ from 1, 10 bits, and its `f32` loop settles after 2 400 s
/// where the exact one takes 39 s; at 2⁻¹⁰ they agree to 10⁻⁴). The dead
/// time stays a whole number of samples, each at least that long.
pub fn choose_ts_as(plant: &TransferFunction, float32: bool) -> f64 {
    let ts = choose_ts(plant);
    let floor = f32_floor(plant);
    if !float32 || ts >= floor {
        return ts;
    }
    if plant.delay > 0.0 {
        plant.delay / (plant.delay / floor).floor().max(1.0)
    } else {
        floor
    }
}

/// The least distance from 1 of an `f32` controller's discrete poles that
/// a chosen period keeps, `Ts/τ` ([`choose_ts_as`]).
pub const F32_POLE_DISTANCE: f64 = 1.0 / 1024.0;

/// The finest period an `f32` controller is given for `plant`:
/// [`F32_POLE_DISTANCE`] of its slowest pole's time constant `1/|p|` (the
/// poles at the origin, exactly 1 when sampled, aside; 0 for none).
fn f32_floor(plant: &TransferFunction) -> f64 {
    let slowest = plant
        .poles()
        .unwrap_or_default()
        .into_iter()
        .map(|(re, im)| re.hypot(im))
        .filter(|m| *m > 1e-9)
        .map(|m| 1.0 / m)
        .fold(0.0, f64::max);
    slowest * F32_POLE_DISTANCE
}

/// For a controller in `f32` at a period finer than [`choose_ts_as`]'s
/// floor: how close to 1 the plant's slowest pole comes, what it risks and
/// the period that keeps it 2⁻¹⁰ away.
pub(crate) fn f32_note(plant: &TransferFunction, ts: f64) -> Option<String> {
    let floor = f32_floor(plant);
    if !(ts < floor * (1.0 - 1e-9)) {
        return None;
    }
    let distance = ts / floor * F32_POLE_DISTANCE;
    let bits = (24.0 + distance.log2()).round().max(0.0);
    Some(std::format!(
        "float32: at ts {} s the plant's slowest pole is {} from 1 once sampled, {} bits of an f32's 24: the controller's rounding can make its loop drift from the exact one; --ts {} keeps it 2^-10 away",
        fmt_num(ts),
        fmt_num(crate::poly::round_sig(distance, 2)),
        fmt_num(bits),
        fmt_num(crate::poly::round_sig(choose_ts_as(plant, true), 4)),
    ))
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

/// Shown next to a chosen value: `0.074 (chosen: 100 samples of dead time)`,
/// and why, where a bound chose it rather than the plant's time scales.
pub fn describe_ts(plant: &TransferFunction, ts: f64, float32: bool) -> String {
    let f32_chose = float32 && ts != choose_ts(plant) && ts == choose_ts_as(plant, true);
    let why = if f32_chose {
        ", the finest at which f32 keeps the slowest pole 2^-10 from 1"
    } else if plant.delay / finest_ts(plant) > MAX_CHOSEN_SAMPLES && ts == choose_ts(plant) {
        ", the most a chosen period gives: faster lags are not resolved between samples"
    } else {
        ""
    };
    if plant.delay > 0.0 {
        let n = (plant.delay / ts).round();
        std::format!(
            "{} s ({} samples of dead time{why})",
            fmt_num(ts),
            fmt_num(n)
        )
    } else if f32_chose {
        std::format!("{} s ({})", fmt_num(ts), why.trim_start_matches(", "))
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
            let said = describe_ts(&plant, got, false).contains("the most a chosen period gives");
            assert_eq!(said, capped, "{text}");
        }
        Ok(())
    }
}
