//! The cascade process (García et al. (2010), Fig. 1) sampled exactly: the
//! primary driven by the held actuator through the secondary, as one state space.

use std::vec::Vec;

use super::plant::{cuts, split_delay, vec_zeros, PlantSim, ToUsize};
use crate::delay::Delay;
use crate::poly::TransferFunction;
use crate::poly::MAX_ORDER;
use crate::{error::Error, lti::Discretization, lti::Lti};

/// The exact sampled cascade process (primary `p1` fed by the secondary `p2`),
/// stepped one held input at a time (see [`super::simulate_cascade`]).
pub struct CascadeStepper {
    p2: PlantSim,
    joint: Box<JointSim>,
}

impl CascadeStepper {
    /// The process at rest, sampled every `ts`.
    pub fn new(p1: &TransferFunction, p2: &TransferFunction, ts: f64) -> Result<Self, Error> {
        Ok(CascadeStepper {
            p2: PlantSim::new(p2, ts, 1)?,
            joint: Box::new(JointSim::new(p1, p2, ts, 1)?),
        })
    }
    /// The primary output `y` and the secondary output `y2` now.
    pub fn outputs(&self) -> (f64, f64) {
        (self.joint.output(), self.p2.output())
    }
    /// Holds `u` for one period.
    pub fn advance(&mut self, u: f64) {
        let mut sub = Vec::new();
        self.p2.advance(u, &mut sub);
        self.joint.advance(u, 0.0, &mut sub);
    }
}

/// The primary output of a cascade process, `y = P1·(P2·v(t − L1 − L2) + d0(t − L1))`,
/// as one state-space system with the two held inputs `v = u + d2` and `d0`
/// (`x = [x2; x1]`, `A = [[A2, 0], [b1·c2, A1]]`, `Bv = [b2; b1·d2]`,
/// `Bd = [0; b1]`, `C = [d1·c2, c1]`): the closed loop keeps this one state
/// bounded even when `P1` is unstable, where a sum of separately simulated
/// parts would cancel growing terms. Each period is cut where either delayed
/// input changes and at the sub-step instants; every piece is integrated
/// exactly by its own ZOH discretization.
pub(super) struct JointSim {
    c: [f64; MAX_ORDER],
    dv: f64,
    dd: f64,
    pieces: Vec<JointPiece>,
    x: [f64; MAX_ORDER],
    line_v: Delay<f64, Vec<f64>>,
    line_d: Delay<f64, Vec<f64>>,
    kv: usize,
    kd: usize,
    /// The fraction of a sample of the dead time from `v` to `y`.
    fv: f64,
    last_v: f64,
    last_d: f64,
}

struct JointPiece {
    v: Lti<f64, MAX_ORDER>,
    gd: [f64; MAX_ORDER],
    v_late: bool,
    d_late: bool,
    record: bool,
}

impl JointSim {
    pub(super) fn new(
        p1: &TransferFunction,
        p2: &TransferFunction,
        ts: f64,
        m: usize,
    ) -> Result<Self, Error> {
        Self::with_room(p1, p2, ts, m, 0.0)
    }

    /// [`JointSim::new`] whose dead time from `v` to `y` (`L1 + L2`) can
    /// later be set up to `max_delay` seconds ([`JointSim::set_dead_time`]).
    pub(super) fn with_room(
        p1: &TransferFunction,
        p2: &TransferFunction,
        ts: f64,
        m: usize,
        max_delay: f64,
    ) -> Result<Self, Error> {
        let (a2, b2, c2, d2, n2) = crate::lti::realize::<f64, MAX_ORDER>(&p2.num, &p2.den)?;
        let (a1, b1, c1, d1, n1) = crate::lti::realize::<f64, MAX_ORDER>(&p1.num, &p1.den)?;
        let n = n1.saturating_add(n2);
        if n > MAX_ORDER {
            return Err(Error::OrderTooHigh("cascade process"));
        }
        let mut a = [[0.0; MAX_ORDER]; MAX_ORDER];
        let (mut bv, mut bd, mut c) = ([0.0; MAX_ORDER], [0.0; MAX_ORDER], [0.0; MAX_ORDER]);
        let get = |m: &[[f64; MAX_ORDER]; MAX_ORDER], i: usize, j: usize| {
            m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
        };
        let at = |v: &[f64; MAX_ORDER], i: usize| v.get(i).copied().unwrap_or(0.0);
        let put = |v: &mut [f64; MAX_ORDER], i: usize, x: f64| {
            if let Some(e) = v.get_mut(i) {
                *e = x;
            }
        };
        for (i, row) in a.iter_mut().enumerate().take(n) {
            for (j, x) in row.iter_mut().enumerate().take(n) {
                *x = match (i < n2, j < n2) {
                    (true, true) => get(&a2, i, j),
                    (false, true) => at(&b1, i - n2) * at(&c2, j),
                    (false, false) => get(&a1, i - n2, j - n2),
                    (true, false) => 0.0,
                };
            }
        }
        for i in 0..n {
            if i < n2 {
                put(&mut bv, i, at(&b2, i));
                put(&mut c, i, d1 * at(&c2, i));
            } else {
                put(&mut bv, i, at(&b1, i - n2) * d2);
                put(&mut bd, i, at(&b1, i - n2));
                put(&mut c, i, at(&c1, i - n2));
            }
        }
        let (kv, fv) = split_delay(crate::delay::samples(p1.delay + p2.delay, ts)?);
        let (kd, fd) = split_delay(crate::delay::samples(p1.delay, ts)?);
        let cuts = cuts(m, &[fv, fd]);
        let mut pieces = Vec::with_capacity(cuts.len());
        let mut start = 0.0;
        for (end, record) in cuts {
            let len = (end - start) * ts;
            let v = Lti::from_state_space(&a, &bv, &c, d1 * d2, n, len, Discretization::Zoh)?;
            let gd = Lti::<f64, MAX_ORDER>::from_state_space(
                &a,
                &bd,
                &c,
                d1,
                n,
                len,
                Discretization::Zoh,
            )?
            .input_vector();
            pieces.push(JointPiece {
                v,
                gd,
                v_late: start >= fv - 1e-12,
                d_late: start >= fd - 1e-12,
                record,
            });
            start = end;
        }
        // both lines hold `k + 1` samples back (a fractional delay reads
        // `x[n−k−1]`), with room for the longest dead time the run will set
        // rounded up: a dead time a rounding below a whole number of samples
        // (7.199999999999999 s) is set as that whole number
        let room = (max_delay / ts).ceil().to_usize_checked()?;
        let kv = kv.to_usize_checked()?;
        let kd = kd.to_usize_checked()?;
        let line = |k: usize| Delay::with_storage(vec_zeros(k.max(room).saturating_add(2))?, 0.0);
        Ok(JointSim {
            c,
            dv: d1 * d2,
            dd: d1,
            pieces,
            x: [0.0; MAX_ORDER],
            line_v: line(kv)?,
            line_d: line(kd)?,
            kv,
            kd,
            fv,
            last_v: 0.0,
            last_d: 0.0,
        })
    }

    /// Changes the dead time from the plant input to `y` to `samples`
    /// (`L1 + L2`): the primary's transport delay `L1` changes, `L2` stays,
    /// so both lines read further back or nearer by the same whole number
    /// of samples (at a steady state nothing moves). The fraction of a sample
    /// must stay what it was.
    /// The dead time from the plant input to `y` (samples).
    pub(super) fn dead_time(&self) -> f64 {
        #[allow(clippy::cast_precision_loss)] // a delay line's length
        let now = self.kv as f64 + self.fv;
        now
    }

    pub(super) fn set_dead_time(&mut self, samples: f64) -> Result<(), Error> {
        let now = self.dead_time();
        let shift = samples - now;
        if !shift.is_finite() || (shift - shift.round()).abs() > 1e-9 {
            return Err(Error::Unsupported(
                "a plant dead-time change must keep the dead time's fraction of a sample (give whole samples)",
            ));
        }
        #[allow(clippy::cast_possible_truncation)] // a whole number, checked against the lines
        let shift = shift.round() as i64;
        let moved = |k: usize| {
            i64::try_from(k)
                .ok()
                .and_then(|k| k.checked_add(shift))
                .and_then(|k| usize::try_from(k).ok())
        };
        let (kv, kd) = match (moved(self.kv), moved(self.kd)) {
            (Some(kv), Some(kd)) => (kv, kd),
            _ => {
                return Err(Error::Unsupported(
                    "a cascade's plant dead time (L1 + L2, input to primary output) shorter than the secondary's L2",
                ))
            }
        };
        if kv.saturating_add(2) > self.line_v.capacity()
            || kd.saturating_add(2) > self.line_d.capacity()
        {
            return Err(Error::DelayTooLong("plant dead time"));
        }
        self.kv = kv;
        self.kd = kd;
        Ok(())
    }

    fn free(&self) -> f64 {
        self.c.iter().zip(&self.x).map(|(c, x)| c * x).sum()
    }

    pub(super) fn output(&self) -> f64 {
        self.free() + self.dv * self.last_v + self.dd * self.last_d
    }

    pub(super) fn advance(&mut self, v: f64, d: f64, sub: &mut Vec<f64>) {
        let v_now = self.line_v.peek_back(v, self.kv);
        let v_before = self.line_v.peek_back(v, self.kv.saturating_add(1));
        let d_now = self.line_d.peek_back(d, self.kd);
        let d_before = self.line_d.peek_back(d, self.kd.saturating_add(1));
        self.line_v.process(v);
        self.line_d.process(d);
        for p in &mut self.pieces {
            let vi = if p.v_late { v_now } else { v_before };
            let di = if p.d_late { d_now } else { d_before };
            p.v.set_state(&self.x);
            p.v.step(vi);
            let xv = *p.v.state();
            for ((x, a), g) in self.x.iter_mut().zip(xv.iter()).zip(p.gd.iter()) {
                *x = a + g * di;
            }
            if p.record {
                let y = self.c.iter().zip(&self.x).map(|(c, x)| c * x).sum::<f64>()
                    + self.dv * vi
                    + self.dd * di;
                sub.push(y);
            }
        }
        self.last_v = v_now;
        self.last_d = d_now;
    }
}
