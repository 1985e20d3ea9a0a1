//! Performance indices: streaming integral indices (no_std, O(1) memory) and,
//! with `std`, MATLAB-style step information.
//!
//! Integral indices (Bag (2022) Sec. 3.x, Eqs. for ISE/IAE/ITAE,
//! and TV of ch. 5): `IAE = ∫|e|dt`, `ISE = ∫e²dt`, `ITAE = ∫t|e|dt`,
//! `ITSE = ∫t e² dt`, `TV = Σ|u[k] − u[k−1]|`. The integrals use the
//! trapezoidal rule over the samples; sums are compensated (Kahan), and time
//! is computed as `k·Ts` rather than accumulated, so f32 runs of millions of
//! samples do not drift.

use crate::real::positive;
use crate::{error::Error, real::Real};

/// A sum that stays accurate over millions of terms: in `f32` (where a plain
/// running sum drifts after ~10⁵ terms) a double word `s + c`, each
/// addition's rounding error carried exactly by Knuth's TwoSum and folded
/// back (Ogita, Rump & Oishi (2005), "Accurate sum and dot product", *SIAM
/// J. Sci. Comput.* 26(6), Alg. 4.4), so that a sum whose terms also leave
/// it (a sliding window) does not drift either; plain in `f64` (relative
/// error below `n·2⁻⁵³`, 10⁻⁹ after 10⁷ terms).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Sum<T> {
    s: T,
    c: T,
}

impl<T: Real> Sum<T> {
    /// Adds `x`.
    #[inline]
    pub fn add(&mut self, x: T) {
        if core::mem::size_of::<T>() >= 8 {
            self.s = self.s + x;
            return;
        }
        // TwoSum: t + e = s + x exactly
        let t = self.s + x;
        let z = t - self.s;
        let e = (self.s - (t - z)) + (x - z);
        // the error joins the low word, renormalized into the pair
        let lo = self.c + e;
        self.s = t + lo;
        self.c = lo - (self.s - t);
    }
    /// The sum.
    #[inline]
    pub fn value(&self) -> T {
        self.s + self.c
    }
}

/// Streaming IAE, ISE, ITAE, ITSE and TV.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct IntegralIndices<T> {
    ts: T,
    k: u64,
    prev_e: T,
    prev_u: T,
    iae: Sum<T>,
    ise: Sum<T>,
    itae: Sum<T>,
    itse: Sum<T>,
    tv: Sum<T>,
}

crate::params::figures! {
    /// The values of the integral indices.
    #[derive(Debug, Clone, Copy, PartialEq, Default)]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub struct Indices<T> {
        /// Integral of the absolute error.
        pub iae: T,
        /// Integral of the squared error.
        pub ise: T,
        /// Integral of time times the absolute error.
        pub itae: T,
        /// Integral of time times the squared error.
        pub itse: T,
        /// Total variation of the control signal.
        pub tv: T,
    }
}

impl<T: Real> IntegralIndices<T> {
    /// Indices for samples every `ts` seconds; time starts at 0 with the first sample.
    pub fn new(ts: T) -> Result<Self, Error> {
        Ok(IntegralIndices {
            ts: positive(ts, "ts")?,
            k: 0,
            prev_e: T::zero(),
            prev_u: T::zero(),
            iae: Sum::default(),
            ise: Sum::default(),
            itae: Sum::default(),
            itse: Sum::default(),
            tv: Sum::default(),
        })
    }

    /// Adds sample `k`: error `e[k]` and control `u[k]`. Non-finite samples are skipped.
    #[inline]
    pub fn push(&mut self, e: T, u: T) {
        if !(e.is_finite() && u.is_finite()) {
            return;
        }
        if self.k > 0 {
            let h = self.ts;
            let t1 = T::from(self.k).unwrap_or(T::zero()) * h;
            let t0 = t1 - h;
            let (e0, e1) = (self.prev_e, e);
            let half = T::half() * h;
            self.iae.add(half * (e0.abs() + e1.abs()));
            self.ise.add(half * (e0 * e0 + e1 * e1));
            self.itae.add(half * (t0 * e0.abs() + t1 * e1.abs()));
            self.itse.add(half * (t0 * e0 * e0 + t1 * e1 * e1));
            self.tv.add((u - self.prev_u).abs());
        }
        self.prev_e = e;
        self.prev_u = u;
        self.k = self.k.saturating_add(1);
    }

    /// The indices so far.
    pub fn value(&self) -> Indices<T> {
        Indices {
            iae: self.iae.value(),
            ise: self.ise.value(),
            itae: self.itae.value(),
            itse: self.itse.value(),
            tv: self.tv.value(),
        }
    }

    /// Number of samples pushed.
    pub fn samples(&self) -> u64 {
        self.k
    }
}

#[cfg(feature = "std")]
crate::params::figures! {
    /// Step-response characteristics with MATLAB's `stepinfo` definitions
    /// (python-control's `step_info` key names); NaN where a figure cannot be computed.
    #[derive(Debug, Clone, Copy, PartialEq)]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub struct StepInfo {
        /// Time from 10 % to 90 % of the step (s).
        pub rise_time: f64,
        /// Time after which `|y − y_final|` stays within 2 % of the step (s).
        pub settling_time: f64,
        /// Smallest `y` once the response has risen (reached 90 %).
        pub settling_min: f64,
        /// Largest `y` once the response has risen.
        pub settling_max: f64,
        /// Overshoot beyond the final value, % of the step.
        pub overshoot: f64,
        /// Undershoot below the initial value (opposite to the step), % of the step.
        pub undershoot: f64,
        /// Peak of `|y|`.
        pub peak: f64,
        /// Time of the peak (s).
        pub peak_time: f64,
    }
}

/// The thresholds of [`step_info_with`] (MATLAB's `SettlingTimeThreshold`
/// and `RiseTimeLimits`, python-control's names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfoOptions {
    /// The settling band, a fraction of the step (default 0.02).
    pub settling_threshold: f64,
    /// The rise time's lower and upper fractions of the step (default 0.1, 0.9).
    pub rise_limits: (f64, f64),
}

impl Default for StepInfoOptions {
    fn default() -> Self {
        StepInfoOptions {
            settling_threshold: 0.02,
            rise_limits: (0.1, 0.9),
        }
    }
}

/// Step information of recorded data (MATLAB's `stepinfo(y, t, yfinal,
/// yinit)`, python-control's `step_info(y, T, yfinal)`): the step from
/// `y_init` (default 0) to `y_final` (default the last sample), applied at
/// `t = 0` (data that start later: at the first sample), times measured
/// from it. The data are checked: as many
/// times as values, at least two, finite, times strictly increasing; the
/// thresholds within (0, 1), the rise limits increasing.
#[cfg(feature = "std")]
pub fn step_info_of_data(
    t: &[f64],
    y: &[f64],
    y_init: Option<f64>,
    y_final: Option<f64>,
    opts: StepInfoOptions,
) -> Result<StepInfo, crate::error::Error> {
    use crate::error::Error;
    if t.len() != y.len() {
        return Err(Error::Unsupported("t and y must have the same length"));
    }
    if t.len() < 2 {
        return Err(Error::OutOfRange("at least two samples"));
    }
    if t.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(Error::NonFinite("t and y"));
    }
    if t.windows(2).any(|w| matches!(w, [a, b] if b <= a)) {
        return Err(Error::Unsupported("the times must increase strictly"));
    }
    let (lo, hi) = opts.rise_limits;
    let in01 = |v: f64| v > 0.0 && v < 1.0;
    if !(in01(opts.settling_threshold) && in01(lo) && in01(hi) && lo < hi) {
        return Err(Error::OutOfRange(
            "settling_threshold in (0, 1), rise_limits 0 < low < high < 1",
        ));
    }
    let y0 = y_init.unwrap_or(0.0);
    let yf = match y_final {
        Some(v) => v,
        None => y.last().copied().unwrap_or(f64::NAN),
    };
    if !(y0.is_finite() && yf.is_finite()) {
        return Err(Error::NonFinite("yinit, yfinal"));
    }
    // the step at t = 0 (MATLAB's convention, and msp's own step data, whose
    // first row is the rest before it), or at the first sample of data
    // that start later
    let origin = t.first().copied().unwrap_or(0.0).max(0.0);
    Ok(step_info_with(t, y, y0, yf, origin, opts))
}

/// Step information of `y(t)` for a step from `y0` to `y_final`; times are
/// measured from `origin`. Crossings are located by linear interpolation
/// between samples.
#[cfg(feature = "std")]
pub fn step_info(t: &[f64], y: &[f64], y0: f64, y_final: f64, origin: f64) -> StepInfo {
    step_info_with(t, y, y0, y_final, origin, StepInfoOptions::default())
}

/// [`step_info`] with other thresholds: the rise time between the fractions
/// `opts.rise_limits` of the step, the settling time into the band of
/// `opts.settling_threshold` of the step, `settling_min`/`settling_max` once
/// the response has reached the upper rise limit.
#[cfg(feature = "std")]
pub fn step_info_with(
    t: &[f64],
    y: &[f64],
    y0: f64,
    y_final: f64,
    origin: f64,
    opts: StepInfoOptions,
) -> StepInfo {
    let (r_lo, r_hi) = opts.rise_limits;
    let nan = f64::NAN;
    let mut out = StepInfo {
        rise_time: nan,
        settling_time: nan,
        settling_min: nan,
        settling_max: nan,
        overshoot: nan,
        undershoot: nan,
        peak: nan,
        peak_time: nan,
    };
    let n = t.len().min(y.len());
    let (t, y) = (t.get(..n).unwrap_or(&[]), y.get(..n).unwrap_or(&[]));
    if n < 2 {
        return out;
    }
    let step = y_final - y0;
    let valid = step.is_finite() && step != 0.0;
    let inv = if valid { 1.0 / step } else { 0.0 };
    // one forward pass: peak of |y|, extremes of the normalized response
    // z = (y − y0)/step, the 10 % and 90 % crossings (interpolated), and the
    // extremes of y once the response has risen
    let (mut peak, mut peak_i) = (f64::NEG_INFINITY, 0usize);
    let (mut zmax, mut zmin) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut t10, mut t90) = (None, None);
    let (mut smin, mut smax) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut tp, mut zp) = (nan, nan);
    for (i, (ti, yi)) in t.iter().zip(y).enumerate() {
        if yi.abs() > peak {
            peak = yi.abs();
            peak_i = i;
        }
        let z = (yi - y0) * inv;
        zmax = zmax.max(z);
        zmin = zmin.min(z);
        let cross = |level: f64| {
            if i == 0 || zp == z {
                *ti
            } else {
                tp + (level - zp) / (z - zp) * (ti - tp)
            }
        };
        if t10.is_none() && z >= r_lo {
            t10 = Some(cross(r_lo));
        }
        if t90.is_none() && z >= r_hi {
            t90 = Some(cross(r_hi));
        }
        if t90.is_some() {
            smin = smin.min(*yi);
            smax = smax.max(*yi);
        }
        tp = *ti;
        zp = z;
    }
    out.peak = peak;
    out.peak_time = t.get(peak_i).map_or(nan, |x| x - origin);
    if !valid {
        return out;
    }
    if let (Some(a), Some(b)) = (t10, t90) {
        out.rise_time = b - a;
    }
    if t90.is_some() {
        out.settling_min = smin;
        out.settling_max = smax;
    }
    // settling: the last sample outside the band, interpolated to the band edge
    let band = opts.settling_threshold;
    let z = |i: usize| y.get(i).map_or(nan, |v| (v - y0) * inv);
    out.settling_time = match (0..n).rev().find(|i| (z(*i) - 1.0).abs() > band) {
        None => 0.0,
        Some(i) if i.wrapping_add(1) >= n => nan,
        Some(i) => {
            let (za, zb) = (z(i), z(i.wrapping_add(1)));
            let edge = if za > 1.0 { 1.0 + band } else { 1.0 - band };
            let f = if zb != za {
                (edge - za) / (zb - za)
            } else {
                0.0
            };
            match (t.get(i), t.get(i.wrapping_add(1))) {
                (Some(ta), Some(tb)) => ta + f.clamp(0.0, 1.0) * (tb - ta) - origin,
                _ => nan,
            }
        }
    };
    let pos = |x: f64| if x > 0.0 { x } else { 0.0 };
    out.overshoot = 100.0 * pos(zmax - 1.0);
    out.undershoot = 100.0 * pos(-zmin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integral_indices_of_an_exponential() -> Result<(), Box<dyn std::error::Error>> {
        // e = e^{-t}: IAE = 1, ISE = 1/2, ITAE = 1, ITSE = 1/4
        let h = 1e-3;
        let mut m = IntegralIndices::new(h)?;
        for k in 0..40_000 {
            m.push((-(k as f64) * h).exp(), 0.0);
        }
        let v = m.value();
        assert!((v.iae - 1.0).abs() < 1e-6);
        assert!((v.ise - 0.5).abs() < 1e-6);
        assert!((v.itae - 1.0).abs() < 1e-6);
        assert!((v.itse - 0.25).abs() < 1e-6);
        Ok(())
    }

    #[test]
    fn step_info_of_first_order() -> Result<(), Box<dyn std::error::Error>> {
        let tau = 2.0;
        let t: Vec<f64> = (0..20_001).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = t.iter().map(|t| 1.0 - (-t / tau).exp()).collect();
        let s = step_info(&t, &y, 0.0, 1.0, 0.0);
        assert!(
            (s.rise_time - tau * 9f64.ln()).abs() < 1e-5,
            "{}",
            s.rise_time
        );
        assert!((s.settling_time - tau * 50f64.ln()).abs() < 1e-5);
        assert_eq!(s.overshoot, 0.0);
        Ok(())
    }
}
