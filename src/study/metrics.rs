//! The figures of a run, as the report, the CLI and Python print them.

use std::vec::Vec;

use crate::metrics::{step_info, IntegralIndices, StepInfo};
use crate::sim::{SetpointStep, SimResult};
use crate::Error;

/// The metrics of a run, with the key names of the JSON report and Python.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Metrics {
    /// Integral of the absolute error.
    pub iae: f64,
    /// Integral of the squared error.
    pub ise: f64,
    /// Integral of time times the absolute error.
    pub itae: f64,
    /// Integral of time times the squared error.
    pub itse: f64,
    /// Total variation of the control signal.
    pub tv: f64,
    /// Rise time 10 → 90 % (s).
    pub rise_time: f64,
    /// Settling time, 2 % band (s).
    pub settling_time: f64,
    /// Minimum after the rise.
    pub settling_min: f64,
    /// Maximum after the rise.
    pub settling_max: f64,
    /// Overshoot (%).
    pub overshoot: f64,
    /// Undershoot (%).
    pub undershoot: f64,
    /// Peak of |y|.
    pub peak: f64,
    /// Time of the peak (s).
    pub peak_time: f64,
}

impl Metrics {
    /// Every figure with its report name, in report order.
    pub fn fields(&self) -> [(&'static str, f64); 13] {
        [
            ("iae", self.iae),
            ("ise", self.ise),
            ("itae", self.itae),
            ("itse", self.itse),
            ("tv", self.tv),
            ("rise_time", self.rise_time),
            ("settling_time", self.settling_time),
            ("settling_min", self.settling_min),
            ("settling_max", self.settling_max),
            ("overshoot", self.overshoot),
            ("undershoot", self.undershoot),
            ("peak", self.peak),
            ("peak_time", self.peak_time),
        ]
    }
}

/// Metrics of `res` with the error `e = r(t − shift) − y`, time counted from
/// `shift` (0 for the plain convention; the model dead time `θm` for the
/// delayed-reference convention of Bag (2022) ch. 5).
pub fn metrics(
    res: &SimResult,
    setpoint: &[SetpointStep],
    ts: f64,
    shift: f64,
) -> Result<Metrics, Error> {
    use std::borrow::Cow;
    // the controller's samples only, whatever the sub-steps
    let stride = res.substeps.max(1);
    let first_row = res
        .t
        .iter()
        .position(|t| *t >= shift - 1e-9 * ts)
        .unwrap_or(res.t.len());
    let first = first_row.div_ceil(stride).saturating_mul(stride);
    fn rows(v: &[f64], first: usize, stride: usize) -> Cow<'_, [f64]> {
        let tail = v.get(first..).unwrap_or(&[]);
        if stride == 1 {
            Cow::Borrowed(tail)
        } else {
            Cow::Owned(tail.iter().copied().step_by(stride).collect())
        }
    }
    let (tt, yy, uu) = (
        rows(&res.t, first, stride),
        rows(&res.y, first, stride),
        rows(&res.u, first, stride),
    );
    let mut ind = IntegralIndices::new(ts)?;
    let mut steps: Vec<SetpointStep> = setpoint.to_vec();
    steps.sort_by(|a, b| a.at.total_cmp(&b.at));
    let mut next = 0usize;
    let mut r = 0.0;
    for ((t, y), u) in tt.iter().zip(yy.iter()).zip(uu.iter()) {
        let tr = t - shift;
        while let Some(s) = steps.get(next) {
            if s.at <= tr + 1e-9 * tr.abs().max(1.0) {
                r = s.value;
                next = next.saturating_add(1);
            } else {
                break;
            }
        }
        ind.push(r - y, *u);
    }
    let v = ind.value();
    let y0 = yy.first().copied().unwrap_or(0.0);
    let y_final = steps.last().map_or(0.0, |s| s.value);
    let first_step = steps.first().map_or(0.0, |s| s.at.max(0.0));
    let from = tt
        .iter()
        .position(|t| t - shift >= first_step - 1e-9 * ts)
        .unwrap_or(0);
    let s: StepInfo = step_info(
        tt.get(from..).unwrap_or(&[]),
        yy.get(from..).unwrap_or(&[]),
        y0,
        y_final,
        shift,
    );
    Ok(Metrics {
        iae: v.iae,
        ise: v.ise,
        itae: v.itae,
        itse: v.itse,
        tv: v.tv,
        rise_time: s.rise_time,
        settling_time: s.settling_time,
        settling_min: s.settling_min,
        settling_max: s.settling_max,
        overshoot: s.overshoot,
        undershoot: s.undershoot,
        peak: s.peak,
        peak_time: s.peak_time,
    })
}
