//! The figures of a run, as the report, the CLI and Python print them.

use std::vec::Vec;

use crate::metrics::{step_info, Indices, IntegralIndices, StepInfo};
use crate::sim::{SetpointStep, SimResult};
use crate::Error;

/// The metrics of a run, with the key names of the JSON report and Python:
/// the integral indices of the error and the step information of the
/// response, one flat object (`iae`, …, `tv`, `rise_time`, …, `peak_time`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Metrics {
    /// IAE, ISE, ITAE, ITSE and TV.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub indices: Indices<f64>,
    /// Rise and settling times, overshoot, peak (as MATLAB's `stepinfo`).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub step: StepInfo,
}

impl Metrics {
    /// Every figure with its report name, in report order.
    pub fn fields(&self) -> [(&'static str, f64); 13] {
        [
            ("iae", self.indices.iae),
            ("ise", self.indices.ise),
            ("itae", self.indices.itae),
            ("itse", self.indices.itse),
            ("tv", self.indices.tv),
            ("rise_time", self.step.rise_time),
            ("settling_time", self.step.settling_time),
            ("settling_min", self.step.settling_min),
            ("settling_max", self.step.settling_max),
            ("overshoot", self.step.overshoot),
            ("undershoot", self.step.undershoot),
            ("peak", self.step.peak),
            ("peak_time", self.step.peak_time),
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
    // no sample in the window (a run that diverged before `shift`): no
    // figure, never a 0 that reads as a perfect loop
    if tt.len() < 2 {
        let nan = f64::NAN;
        return Ok(Metrics {
            indices: Indices {
                iae: nan,
                ise: nan,
                itae: nan,
                itse: nan,
                tv: nan,
            },
            step: step_info(&[], &[], 0.0, nan, shift),
        });
    }
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
    let indices = ind.value();
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
    Ok(Metrics { indices, step: s })
}
