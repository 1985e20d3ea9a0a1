//! Identification of process models from recorded data: step tests and relay
//! tests, by closed forms and by least squares on the exact sampled response.

use std::vec::Vec;

use crate::autotune::{
    identify_fopdt, identify_ipdt, identify_ufopdt, RelayConfig, RelayResult, RelayState, RelayTest,
};
use crate::poly::TransferFunction;
use crate::{
    error::Error, model::Foipdt, model::Fopdt, model::Ipdt, model::ProcessModel, model::Sopdt,
    model::Ufopdt,
};

mod autotune;
pub use autotune::*;

/// Which model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum ModelKind {
    /// First order plus dead time.
    Fopdt,
    /// Second order plus dead time.
    Sopdt,
    /// Integrator plus dead time.
    Ipdt,
    /// Integrator with a first-order lag plus dead time `K e^{−Ls}/(s(Ts + 1))`.
    Foipdt,
    /// Unstable first order plus dead time `K e^{−Ls}/(Ts − 1)`: from a
    /// relay's limit cycle only (its step response runs away).
    Ufopdt,
}

impl core::str::FromStr for ModelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "fopdt" => Ok(ModelKind::Fopdt),
            "sopdt" => Ok(ModelKind::Sopdt),
            "ipdt" => Ok(ModelKind::Ipdt),
            "foipdt" => Ok(ModelKind::Foipdt),
            "ufopdt" => Ok(ModelKind::Ufopdt),
            o => Err(std::format!(
                "unknown model '{o}': use fopdt, sopdt, ipdt, foipdt or ufopdt"
            )),
        }
    }
}

/// A fitted model and how well it fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// The model.
    pub model: ProcessModel<f64>,
    /// Root-mean-square error of the model's response against the data.
    pub rmse: f64,
    /// `1 − ‖y − ŷ‖²/‖y − ȳ‖²`.
    pub r2: f64,
}

/// As `msp identify --json` and Python's `identify` give it: `{"model":
/// "fopdt", "k", "t", "l" (the model's parameters by name), "rmse", "r2"}`.
#[cfg(feature = "serde")]
impl serde::Serialize for Fit {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let (ps, n) = self.model.params();
        let mut m = s.serialize_map(Some(n + 3))?;
        m.serialize_entry("model", self.model.kind())?;
        for (k, v) in ps.iter().take(n) {
            m.serialize_entry(k, v)?;
        }
        m.serialize_entry("rmse", &self.rmse)?;
        m.serialize_entry("r2", &self.r2)?;
        m.end()
    }
}

/// Nelder–Mead minimization of `f` from `x0` with initial steps `step`.
pub fn nelder_mead(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: &[f64], iters: usize) -> Vec<f64> {
    let n = x0.len();
    let mut simplex: Vec<Vec<f64>> = std::vec![x0.to_vec()];
    for i in 0..n {
        let mut v = x0.to_vec();
        if let (Some(vi), Some(si)) = (v.get_mut(i), step.get(i)) {
            *vi += si;
        }
        simplex.push(v);
    }
    let mut fx: Vec<f64> = simplex.iter().map(|v| f(v)).collect();
    for _ in 0..iters {
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|a, b| {
            fx.get(*a)
                .unwrap_or(&f64::NAN)
                .total_cmp(fx.get(*b).unwrap_or(&f64::NAN))
        });
        simplex = order
            .iter()
            .filter_map(|i| simplex.get(*i).cloned())
            .collect();
        fx = order.iter().filter_map(|i| fx.get(*i).copied()).collect();
        let (Some(best), Some(worst)) = (fx.first().copied(), fx.last().copied()) else {
            break;
        };
        if (worst - best).abs() <= 1e-14 * (1.0 + best.abs()) {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| {
                simplex
                    .iter()
                    .take(n)
                    .map(|v| v.get(j).copied().unwrap_or(0.0))
                    .sum::<f64>()
                    / n as f64
            })
            .collect();
        let Some(w) = simplex.last().cloned() else {
            break;
        };
        let along = |t: f64| -> Vec<f64> {
            centroid
                .iter()
                .zip(&w)
                .map(|(c, x)| c + t * (c - x))
                .collect()
        };
        let xr = along(1.0);
        let fr = f(&xr);
        let second = fx.get(n.saturating_sub(1)).copied().unwrap_or(worst);
        if fr < best {
            let xe = along(2.0);
            let fe = f(&xe);
            let (x, v) = if fe < fr { (xe, fe) } else { (xr, fr) };
            replace_last(&mut simplex, &mut fx, x, v);
        } else if fr < second {
            replace_last(&mut simplex, &mut fx, xr, fr);
        } else {
            let xc = along(if fr < worst { 0.5 } else { -0.5 });
            let fc = f(&xc);
            if fc < worst.min(fr) {
                replace_last(&mut simplex, &mut fx, xc, fc);
            } else {
                let Some(b) = simplex.first().cloned() else {
                    break;
                };
                for (v, fv) in simplex.iter_mut().zip(fx.iter_mut()).skip(1) {
                    for (x, bx) in v.iter_mut().zip(&b) {
                        *x = bx + 0.5 * (*x - bx);
                    }
                    *fv = f(v);
                }
            }
        }
    }
    let best = fx
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    simplex.get(best).cloned().unwrap_or_else(|| x0.to_vec())
}

fn replace_last(s: &mut [Vec<f64>], f: &mut [f64], x: Vec<f64>, v: f64) {
    if let (Some(sl), Some(fl)) = (s.last_mut(), f.last_mut()) {
        *sl = x;
        *fl = v;
    }
}

fn model_from(kind: ModelKind, p: &[f64]) -> Option<ProcessModel<f64>> {
    let g = |i: usize| p.get(i).copied();
    match kind {
        ModelKind::Fopdt => Fopdt::new(g(0)?, g(1)?.exp(), g(2)?.exp())
            .ok()
            .map(Into::into),
        ModelKind::Ipdt => Ipdt::new(g(0)?, g(1)?.exp()).ok().map(Into::into),
        ModelKind::Foipdt => Foipdt::new(g(0)?, g(1)?.exp(), g(2)?.exp())
            .ok()
            .map(Into::into),
        ModelKind::Sopdt => {
            let (a, b) = (g(1)?.exp(), g(2)?.exp());
            Sopdt::new(g(0)?, a.max(b), a.min(b), g(3)?.exp())
                .ok()
                .map(Into::into)
        }
        ModelKind::Ufopdt => Ufopdt::new(g(0)?, g(1)?.exp(), g(2)?.exp())
            .ok()
            .map(Into::into),
    }
}

fn params_of(m: &ProcessModel<f64>) -> Vec<f64> {
    let tiny = |x: f64| x.max(1e-9).ln();
    match *m {
        ProcessModel::Fopdt(f) => std::vec![f.k, tiny(f.t), tiny(f.l)],
        ProcessModel::Ipdt(i) => std::vec![i.k, tiny(i.l)],
        ProcessModel::Sopdt(s) => std::vec![s.k, tiny(s.t1), tiny(s.t2), tiny(s.l)],
        ProcessModel::Foipdt(f) => std::vec![f.k, tiny(f.t), tiny(f.l)],
        ProcessModel::Ufopdt(f) => std::vec![f.k, tiny(f.t), tiny(f.l)],
    }
}

/// The model's response to the deviations `u − u0` at period `ts`, plus `y0`.
/// A dead time beyond the data is the data's length: the input never
/// arrives within it either way (and a search that tries a huge dead time
/// allocates no line for it).
fn response(m: &ProcessModel<f64>, ts: f64, du: &[f64], y0: f64) -> Option<Vec<f64>> {
    let mut tf = TransferFunction::from_model(m);
    #[allow(clippy::cast_precision_loss)]
    let span = (du.len() as f64 + 1.0) * ts;
    if !(tf.delay <= span) {
        tf.delay = span;
    }
    crate::sim::open_loop(&tf, ts, du)
        .ok()
        .map(|y| y.into_iter().map(|v| v + y0).collect())
}

fn score(m: &ProcessModel<f64>, ts: f64, du: &[f64], y: &[f64], y0: f64) -> Fit {
    let Some(yh) = response(m, ts, du, y0) else {
        return Fit {
            model: *m,
            rmse: f64::INFINITY,
            r2: f64::NEG_INFINITY,
        };
    };
    let n = y.len().max(1) as f64;
    let sse: f64 = y.iter().zip(&yh).map(|(a, b)| (a - b) * (a - b)).sum();
    let mean = y.iter().sum::<f64>() / n;
    let sst: f64 = y.iter().map(|a| (a - mean) * (a - mean)).sum();
    Fit {
        model: *m,
        rmse: (sse / n).sqrt(),
        r2: if sst > 0.0 { 1.0 - sse / sst } else { f64::NAN },
    }
}

/// The dead time, in lags, beyond which a relay cycle's peaks no longer
/// resolve `e^{−L/T}` (10⁻⁶ of the static level: a peak's rounding and a
/// sample's timing are of that order): the FOPDT's exact relations give
/// way to a search over the recorded cycles ([`identify_relay`]).
const SATURATED: f64 = 14.0;

/// The simplex steps of the polish on a whole long record.
const POLISH: usize = 150;

/// Least-squares fit of `kind` to samples `(u, y)` taken every `ts`, starting
/// from `start`; `(u0, y0)` is the initial steady state.
pub fn least_squares(
    kind: ModelKind,
    ts: f64,
    u: &[f64],
    y: &[f64],
    u0: f64,
    y0: f64,
    start: &ProcessModel<f64>,
) -> Result<Fit, Error> {
    let du: Vec<f64> = u.iter().map(|v| v - u0).collect();
    // the squared error of the model of parameters `p` on the record `(du, y)`
    let on = |du: &[f64], y: &[f64], ts: f64, p: &[f64]| -> f64 {
        match model_from(kind, p).and_then(|m| response(&m, ts, du, y0)) {
            Some(yh) => y.iter().zip(&yh).map(|(a, b)| (a - b) * (a - b)).sum(),
            None => f64::INFINITY,
        }
    };
    let cost = |p: &[f64]| on(&du, y, ts, p);
    let mut x = params_of(start);
    if kind == ModelKind::Sopdt {
        if let ProcessModel::Fopdt(f) = start {
            // split the lag: a few starts, keep the best
            let mut best = (f64::INFINITY, x.clone());
            for r in [0.5, 0.25, 0.1] {
                let t2 = (r * f.t).max(1e-6);
                let p = std::vec![
                    f.k,
                    (f.t - t2).max(1e-6).ln(),
                    t2.ln(),
                    (f.l + 0.5 * t2).max(1e-6).ln()
                ];
                let c = cost(&p);
                if c < best.0 {
                    best = (c, p);
                }
            }
            x = best.1;
        }
    }
    let step: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| if i == 0 { 0.1 * v.abs().max(1e-6) } else { 0.2 })
        .collect();
    // a long record (a relay's cycles at 10⁵ samples of dead time: 10⁶
    // samples, each of the search's thousands of evaluations a simulation
    // of all of them) is fitted first on every `m`-th sample, at most
    // [`FIT_SAMPLES`] of them (the input held from mid-interval: a switch moves
    // by at most half an interval, either way), then polished on the whole
    // record from there with a simplex of a hundredth of the first one's
    // size and few evaluations: the cost does not grow with the record
    let m = y.len().div_ceil(FIT_SAMPLES);
    if m > 1 {
        let pick = |v: &[f64], from: usize| -> Vec<f64> {
            v.iter().skip(from).step_by(m).copied().collect()
        };
        let (du_c, y_c) = (pick(&du, m / 2), pick(y, 0));
        let n = du_c.len().min(y_c.len());
        let coarse = |p: &[f64]| {
            on(
                du_c.get(..n).unwrap_or(&[]),
                y_c.get(..n).unwrap_or(&[]),
                ts * m as f64,
                p,
            )
        };
        for _ in 0..3 {
            x = nelder_mead(&coarse, &x, &step, 4000);
        }
        let fine: Vec<f64> = step.iter().map(|s| 0.1 * s).collect();
        x = nelder_mead(&cost, &x, &fine, POLISH);
    } else {
        for _ in 0..3 {
            x = nelder_mead(&cost, &x, &step, 4000);
        }
    }
    let m = model_from(kind, &x).ok_or(Error::Numerical("least squares (no valid model found)"))?;
    Ok(score(&m, ts, &du, y, y0))
}

/// The first sample where the input moves from its initial value, and the step size.
fn step_of(u: &[f64]) -> Result<(usize, f64, f64), Error> {
    let u0 = *u.first().ok_or(Error::OutOfRange("data"))?;
    let k = u
        .iter()
        .position(|v| (v - u0).abs() > 1e-12 * (1.0 + u0.abs()))
        .ok_or(Error::Unsupported(
            "the input never changes: no step in the data",
        ))?;
    let u1 = *u.last().ok_or(Error::OutOfRange("data"))?;
    Ok((k, u0, u1 - u0))
}

/// FOPDT by the two-point method (28.3 % and 63.2 % of the final change):
/// `T = 1.5 (t63 − t28)`, `L = t63 − T`, `K = Δy/Δu`.
pub fn two_point(t: &[f64], u: &[f64], y: &[f64]) -> Result<Fopdt<f64>, Error> {
    let (k0, _, du) = step_of(u)?;
    let ts_step = *t.get(k0).ok_or(Error::OutOfRange("data"))?;
    let y0 = *y.first().ok_or(Error::OutOfRange("data"))?;
    let tail = y.len().saturating_sub(y.len() / 20).max(1);
    let yf = y
        .get(tail..)
        .map_or(y0, |s| s.iter().sum::<f64>() / s.len().max(1) as f64);
    let dy = yf - y0;
    let cross = |frac: f64| -> Option<f64> {
        let level = y0 + frac * dy;
        for i in k0.max(1)..y.len() {
            let (a, b) = (*y.get(i - 1)?, *y.get(i)?);
            if (a - level) * (b - level) <= 0.0 && a != b {
                let (ta, tb) = (*t.get(i - 1)?, *t.get(i)?);
                return Some(ta + (level - a) / (b - a) * (tb - ta));
            }
        }
        None
    };
    let (t28, t63) = (
        cross(0.283).ok_or(Error::Unsupported("no 28.3 % crossing"))?,
        cross(0.632).ok_or(Error::Unsupported("no 63.2 % crossing"))?,
    );
    let tc = 1.5 * (t63 - t28);
    Fopdt::new(dy / du, tc, (t63 - tc - ts_step).max(0.0))
}

/// IPDT from the slope and intercept of the final ramp: `y ≈ y0 + K Δu (t − t_step − L)`.
pub fn slope_intercept(t: &[f64], u: &[f64], y: &[f64]) -> Result<Ipdt<f64>, Error> {
    let (k0, _, du) = step_of(u)?;
    let ts_step = *t.get(k0).ok_or(Error::OutOfRange("data"))?;
    let y0 = *y.first().ok_or(Error::OutOfRange("data"))?;
    let from = y.len() / 2;
    let (tt, yy) = (t.get(from..).unwrap_or(&[]), y.get(from..).unwrap_or(&[]));
    let n = tt.len() as f64;
    if n < 2.0 {
        return Err(Error::OutOfRange("data"));
    }
    let (mt, my) = (tt.iter().sum::<f64>() / n, yy.iter().sum::<f64>() / n);
    let sxy: f64 = tt.iter().zip(yy).map(|(a, b)| (a - mt) * (b - my)).sum();
    let sxx: f64 = tt.iter().map(|a| (a - mt) * (a - mt)).sum();
    let slope = sxy / sxx;
    let t_at_y0 = mt + (y0 - my) / slope;
    Ipdt::new(slope / du, (t_at_y0 - ts_step).max(0.0))
}

/// Step-test identification of `kind` from samples every `ts` (uniform `t`):
/// the closed-form estimate, refined by least squares.
///
/// The input must be an open-loop test: held constant between a few steps.
/// An input that changes at more than ten samples and more than 1 % of them
/// is refused — that is a controller's output (closed-loop data), where `u`
/// is correlated with the output's disturbances and noise and a step-test
/// fit is biased (a PI loop's data gave a gain of 14.9 for a plant of 5.6).
pub fn identify_step(kind: ModelKind, t: &[f64], u: &[f64], y: &[f64]) -> Result<Fit, Error> {
    let fit = identify_step_fit(kind, t, u, y)?;
    // a fit without a finite error fitted nothing (times or values beyond
    // what the model's numbers can hold, such as times scaled by 1e-300)
    if !fit.rmse.is_finite() {
        return Err(Error::Numerical(
            "identification (the model's response is not finite on these data: rescale the time or the values)",
        ));
    }
    // worse than the data's mean: no model of this kind was found in them
    if fit.r2 < 0.0 {
        return Err(Error::Numerical(
            "identification (the best model fits worse than a constant, r² < 0: the time scale or the values are beyond what the fit can use, or the data hold no step response)",
        ));
    }
    Ok(fit)
}

/// [`identify_step`] before its fit is checked.
fn identify_step_fit(kind: ModelKind, t: &[f64], u: &[f64], y: &[f64]) -> Result<Fit, Error> {
    if t.len() != u.len() || t.len() != y.len() || t.len() < 10 {
        return Err(Error::OutOfRange("data"));
    }
    for (name, col) in [("time", t), ("input", u), ("output", y)] {
        if let Some(row) = col.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFiniteAt(name, row));
        }
    }
    if let Some(row) = t.windows(2).position(|w| w.get(1) <= w.first()) {
        return Err(Error::NotIncreasing("time", row.saturating_add(1)));
    }
    let range = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let changes = u
        .windows(2)
        .filter(|w| match (w.first(), w.get(1)) {
            (Some(a), Some(b)) => (b - a).abs() > 1e-9 * range,
            _ => false,
        })
        .count();
    if changes > 10 && changes * 100 > u.len() {
        return Err(Error::Unsupported(
            "the input is not an open-loop step test: it changes at most samples, as a controller's output does (closed-loop data); identify from an open-loop step in u, or run a relay test (msp autotune)",
        ));
    }
    let ts = match (t.first(), t.get(1)) {
        (Some(a), Some(b)) => b - a,
        _ => return Err(Error::OutOfRange("data")),
    };
    let (u0, y0) = (*u.first().unwrap_or(&0.0), *y.first().unwrap_or(&0.0));
    let start: ProcessModel<f64> = match kind {
        ModelKind::Ipdt => slope_intercept(t, u, y)?.into(),
        ModelKind::Foipdt => {
            let i = slope_intercept(t, u, y)?;
            Foipdt::new(i.k, (0.3 * i.l).max(ts), 0.7 * i.l)?.into()
        }
        ModelKind::Fopdt | ModelKind::Sopdt => two_point(t, u, y)?.into(),
        ModelKind::Ufopdt => {
            return Err(Error::Unsupported(
                "an unstable model runs away in a step test: identify it from a relay's limit cycle (msp autotune --model ufopdt)",
            ))
        }
    };
    // Each cost evaluation of the fit simulates the model over the data, and
    // the search takes thousands of them: beyond FIT_SAMPLES rows the fit
    // runs on every m-th sample, phased so that the input's first step falls
    // on a kept sample (the input is then held over each kept interval, so
    // the ZOH model at m·ts is exact for it), and the fit figures are scored
    // on every row. The cost stays linear in the rows.
    let m = u.len().div_ceil(FIT_SAMPLES).max(1);
    if m == 1 {
        return least_squares(kind, ts, u, y, u0, y0, &start);
    }
    let (k0, _, _) = step_of(u)?;
    let phase = k0 % m;
    let pick = |v: &[f64]| -> Vec<f64> { v.iter().skip(phase).step_by(m).copied().collect() };
    #[allow(clippy::cast_precision_loss)] // m ≤ rows
    let coarse = least_squares(kind, ts * m as f64, &pick(u), &pick(y), u0, y0, &start)?;
    let du: Vec<f64> = u.iter().map(|v| v - u0).collect();
    Ok(score(&coarse.model, ts, &du, y, y0))
}

/// The rows a least-squares search simulates at most ([`identify_step`],
/// [`least_squares`]).
const FIT_SAMPLES: usize = 20_000;

/// Bytes a relay experiment records per sample: `u` and `y` in `f64` ([`RelayRun`]).
const RELAY_BYTES_PER_SAMPLE: f64 = 16.0;

/// A relay experiment on a simulated plant, with measurement noise.
#[derive(Debug, Clone)]
pub struct RelayRun {
    /// How it ended.
    pub state: RelayState<f64>,
    /// Actuator values.
    pub u: Vec<f64>,
    /// Measured outputs.
    pub y: Vec<f64>,
    /// Sample period.
    pub ts: f64,
}

/// Runs the relay experiment `cfg` on `plant` (exact sampled-data simulation),
/// with Gaussian measurement noise of standard deviation `noise`.
pub fn relay_experiment(
    plant: &TransferFunction,
    cfg: RelayConfig<f64>,
    noise: f64,
    seed: u64,
) -> Result<RelayRun, Error> {
    let mut test = RelayTest::new(cfg)?;
    let mut rng = crate::sim::Noise::new(seed);
    let mut us = Vec::new();
    let mut ys = Vec::new();
    // the plant starts at its steady state (u0, y0): simulated in deviations
    let mut plant_sim = crate::sim::PlantStepper::new(plant, cfg.ts)?;
    for _ in 0..=cfg.max_samples {
        let y = plant_sim.output() + cfg.y0;
        let y_meas = y + if noise > 0.0 {
            noise * rng.gaussian()
        } else {
            0.0
        };
        let u = test.update(y_meas);
        us.push(u);
        ys.push(y_meas);
        plant_sim.advance(u - cfg.u0);
        if test.state() != RelayState::Running {
            break;
        }
    }
    Ok(RelayRun {
        state: test.state(),
        u: us,
        y: ys,
        ts: cfg.ts,
    })
}

/// The unstable FOPDT `m`'s limit cycle under the relay of `r` against the
/// last recorded period (from the record's last switch up, at `−ε`): its
/// rms error and `r²` there. The model's cycle in closed form, from the
/// switch up at `t = 0`: the input `u₋` for `L` more seconds, down to its
/// own `a₋`, then `u₊` up to `+ε` at its own `P₊`, then `u₊` for `L`, up to
/// `a₊`, then `u₋` (see [`crate::autotune`]).
fn cycle_fit(run: &RelayRun, r: &RelayResult<f64>, m: &Ufopdt<f64>) -> Fit {
    let (up, dn, eps) = (r.bias + r.amplitude, r.bias - r.amplitude, r.hysteresis);
    let (k, t, l) = (m.k, m.t, m.l);
    let e = (l / t).exp();
    let a_min = -k * dn + (k * dn - eps) * e;
    let a_max = -k * up + (eps + k * up) * e;
    let t_up = l + t * ((k * up + eps) / (a_min + k * up)).ln();
    let model = |s: f64| -> f64 {
        let run_away = |level: f64, from: f64, dt: f64| -level + (from + level) * (dt / t).exp();
        if s < l {
            run_away(k * dn, -eps, s)
        } else if s < t_up {
            run_away(k * up, a_min, s - l)
        } else if s < t_up + l {
            run_away(k * up, eps, s - t_up)
        } else {
            run_away(k * dn, a_max, s - t_up - l)
        }
    };
    let y0 = run.y.first().copied().unwrap_or(0.0);
    let dy: Vec<f64> = run.y.iter().map(|v| v - y0).collect();
    // the last crossing of −ε downwards, interpolated in its sample
    let end = (1..dy.len()).rev().find_map(|i| {
        let (a, b) = (*dy.get(i - 1)?, *dy.get(i)?);
        #[allow(clippy::cast_precision_loss)]
        (a >= -eps && b < -eps).then(|| run.ts * ((i - 1) as f64 + (-eps - a) / (b - a)))
    });
    let (mut sse, mut sum, mut sum2, mut n) = (0.0, 0.0, 0.0, 0.0f64);
    if let Some(end) = end {
        let start = end - r.period;
        for (i, v) in dy.iter().enumerate() {
            #[allow(clippy::cast_precision_loss)]
            let s = i as f64 * run.ts - start;
            if (0.0..r.period).contains(&s) {
                sse += (v - model(s)).powi(2);
                (sum, sum2, n) = (sum + v, sum2 + v * v, n + 1.0);
            }
        }
    }
    let sst = sum2 - sum * sum / n.max(1.0);
    Fit {
        model: (*m).into(),
        rmse: if n > 0.0 {
            (sse / n).sqrt()
        } else {
            f64::INFINITY
        },
        r2: if sst > 0.0 { 1.0 - sse / sst } else { f64::NAN },
    }
}

/// Models from a relay run: the exact closed forms, then (with `refine`) a
/// least-squares fit to the recorded cycles, which removes the bias that
/// measurement noise puts on the peaks.
pub fn identify_relay(
    run: &RelayRun,
    r: &RelayResult<f64>,
    kind: ModelKind,
    cfg: &RelayConfig<f64>,
    refine: bool,
) -> Result<Fit, Error> {
    // the exact relations need the cycle to carry the lag: with a dead time
    // of many lags the output reaches its static level every half period,
    // `e^{−L/T}` is below what the peaks resolve, and the search starts
    // from a lag a twentieth of the dead time read off the half periods
    let mut searched = false;
    let start: ProcessModel<f64> = match kind {
        // exact from the cycle; its fit scored on the last recorded cycle
        // (a least-squares search would simulate a model that runs away)
        ModelKind::Ufopdt => return Ok(cycle_fit(run, r, &identify_ufopdt(r)?)),
        ModelKind::Ipdt => identify_ipdt(r)?.into(),
        ModelKind::Foipdt => {
            // the IPDT fit's dead time split between the lag and the delay
            let i = identify_ipdt(r)?;
            Foipdt::new(i.k, (0.3 * i.l).max(run.ts), 0.7 * i.l)?.into()
        }
        ModelKind::Fopdt | ModelKind::Sopdt => {
            let k = r.gain().ok_or(Error::Unsupported(
                "FOPDT/SOPDT identification needs the gain: run the relay with a bias",
            ))?;
            match identify_fopdt(r, k) {
                Ok(m) if m.l < SATURATED * m.t => m.into(),
                _ => {
                    searched = true;
                    let l = 0.9 * r.t_up.min(r.t_down);
                    Fopdt::new(k, (l / 20.0).max(run.ts), l)?.into()
                }
            }
        }
    };
    let du: Vec<f64> = run.u.iter().map(|v| v - cfg.u0).collect();
    if !refine && !searched && matches!(kind, ModelKind::Fopdt | ModelKind::Ipdt) {
        return Ok(score(&start, run.ts, &du, &run.y, cfg.y0));
    }
    let fit = least_squares(kind, run.ts, &run.u, &run.y, cfg.u0, cfg.y0, &start)?;
    // a dead time past the experiment is no fit, whatever the number says
    #[allow(clippy::cast_precision_loss)]
    if !(fit.model.delay() < run.ts * run.u.len() as f64) {
        return Err(Error::Unsupported(
            "the model does not fit the relay data: its dead time runs past the experiment (for an integrating process use the ipdt or foipdt model)",
        ));
    }
    Ok(fit)
}
