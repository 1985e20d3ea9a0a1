//! One plant sampled exactly: ZOH pieces cut at the sub-steps and at the
//! fractional dead time.

use std::vec::Vec;

use crate::delay::Delay;
use crate::poly::TransferFunction;
use crate::poly::MAX_ORDER;
use crate::{error::Error, lti::Discretization, lti::Lti};

/// One piece of a sampling period, integrated exactly by its own ZOH discretization.
pub(super) struct Piece {
    block: Lti<f64, MAX_ORDER>,
    /// Input `v[n−k]` (true) or `v[n−k−1]` (false, before the fractional delay has passed).
    late: bool,
    /// The piece ends at an intermediate output instant (sub-step).
    record: bool,
}

/// The plant as simulated: the period is cut at the sub-step instants and at
/// the instant `f·Ts` where the delayed input changes.
pub(super) struct PlantSim {
    out: Lti<f64, MAX_ORDER>,
    pieces: Vec<Piece>,
    line: Delay<f64, Vec<f64>>,
    k: usize,
    /// The fraction of a sample of the dead time (the pieces are cut at it).
    frac: f64,
    feedthrough: f64,
    last_in: f64,
    /// A fractional dead time without sub-steps: the period's two pieces
    /// as one step with two inputs (the modified z-transform),
    /// `x⁺ = Φx + Γ_late·v[n−k] + Γ_early·v[n−k−1]` with `Γ_late = Γ_b`,
    /// `Γ_early = Φ_b·Γ_a` (`a` the piece before the fraction, `b` after;
    /// Åström & Wittenmark (1997) Sec. 2.3, the ZOH of a fractional delay;
    /// `analysis::DiscretePlant` is the same form).
    folded: Option<([f64; MAX_ORDER], [f64; MAX_ORDER])>,
    /// What the plant is now (a drift event rebuilds the blocks from it).
    tf: TransferFunction,
    ts: f64,
    substeps: usize,
}

impl PlantSim {
    pub(super) fn new(plant: &TransferFunction, ts: f64, substeps: usize) -> Result<Self, Error> {
        Self::with_room(plant, ts, substeps, 0.0)
    }

    /// [`PlantSim::new`] whose dead time can later be set up to `max_delay`
    /// seconds ([`PlantSim::set_dead_time`]).
    pub(super) fn with_room(
        plant: &TransferFunction,
        ts: f64,
        substeps: usize,
        max_delay: f64,
    ) -> Result<Self, Error> {
        let (kf, f) = split_delay(plant.delay_samples(ts)?);
        let out: Lti<f64, MAX_ORDER> = plant.to_lti(ts)?;
        let cuts = cuts(substeps, &[f]);
        let mut pieces = Vec::with_capacity(cuts.len());
        let mut a = 0.0;
        for (b, record) in cuts {
            let block = Lti::from_tf(&plant.num, &plant.den, (b - a) * ts, Discretization::Zoh)?;
            pieces.push(Piece {
                block,
                late: a >= f - 1e-12,
                record,
            });
            a = b;
        }
        let folded = match pieces.as_slice() {
            [a, b] if !a.late && b.late && !a.record && !b.record => Some((
                b.block.input_vector(),
                b.block.propagate(&a.block.input_vector()),
            )),
            _ => None,
        };
        let k = kf.to_usize_checked()?;
        // the line holds the whole delay `k` (read by `process`); its capacity
        // `k + 1` keeps `v[n−k−1]` too for a fractional delay (and room for
        // the longest dead time the run will set)
        let room = (max_delay / ts).floor().max(kf).to_usize_checked()?;
        let line = Delay::with_storage(vec_zeros(room.saturating_add(1))?, kf)?;
        Ok(PlantSim {
            feedthrough: out.output(1.0) - out.free_output(),
            out,
            pieces,
            line,
            k,
            frac: f,
            last_in: 0.0,
            folded,
            tf: plant.clone(),
            ts,
            substeps,
        })
    }

    /// The plant becomes `tf` (same dead time) at this instant: its blocks
    /// are rebuilt, the dead-time line keeps its history, and `state` maps
    /// the old block's state onto the new one's.
    fn rebuild(
        &mut self,
        mut tf: TransferFunction,
        state: impl FnOnce(&Lti<f64, MAX_ORDER>, &mut Lti<f64, MAX_ORDER>),
    ) -> Result<(), Error> {
        tf.delay = (self.k as f64 + self.frac) * self.ts;
        let mut new = PlantSim::with_room(&tf, self.ts, self.substeps, 0.0)?;
        state(&self.out, &mut new.out);
        core::mem::swap(&mut new.line, &mut self.line);
        new.k = self.k;
        new.last_in = self.last_in;
        *self = new;
        Ok(())
    }

    /// The static gain (velocity gain of an integrating plant) becomes `k`:
    /// the numerator is scaled by `r = k/K` and the state by `1/r`, which is
    /// the plant whose input gain changed now — its output does not jump,
    /// and from here on each input acts `r` times as much (exact for any
    /// order: the state's dynamics do not depend on the numerator).
    pub(super) fn set_gain(&mut self, k: f64) -> Result<(), Error> {
        let r = k / self.tf.gain();
        if !(r.is_finite() && r != 0.0) {
            return Err(Error::Unsupported(
                "plant-gain: the plant's gain is zero or undefined, so it cannot be scaled to another",
            ));
        }
        let mut tf = self.tf.clone();
        tf.num.iter_mut().for_each(|c| *c *= r);
        self.rebuild(tf, |old, new| {
            let mut x = *old.state();
            x.iter_mut().for_each(|v| *v /= r);
            new.set_state(&x);
        })
    }

    /// The time constant of a plant with one lag, `K/(τs + 1)` (or
    /// `(b1 s + b0)/(τs + 1)`), becomes `tau` at the same gain; its state is
    /// its output, which does not jump.
    pub(super) fn set_lag(&mut self, tau: f64) -> Result<(), Error> {
        let (_, a0) = self.one_lag()?;
        let mut tf = self.tf.clone();
        tf.den = std::vec![tau * a0, a0];
        let y = self.out.free_output();
        self.rebuild(tf, |_, new| new.set_output(y))
    }

    /// The denominator `a1·s + a0` of a stable plant with one lag.
    fn one_lag(&self) -> Result<(f64, f64), Error> {
        match self.tf.den.as_slice() {
            [a1, a0] if *a1 != 0.0 && *a0 != 0.0 && *a1 / *a0 > 0.0 => Ok((*a1, *a0)),
            _ => Err(Error::Unsupported(
                "plant-lag changes the time constant of a stable plant with one lag, K/(τs+1): this plant has another denominator",
            )),
        }
    }

    /// The time constant `τ` of a plant with one lag.
    pub(super) fn lag(&self) -> Result<f64, Error> {
        self.one_lag().map(|(a1, a0)| a1 / a0)
    }

    /// The static gain (velocity gain of an integrating plant).
    pub(super) fn gain(&self) -> f64 {
        self.tf.gain()
    }

    /// The dead time (samples).
    pub(super) fn dead_time(&self) -> f64 {
        #[allow(clippy::cast_precision_loss)] // a delay line's length
        let k = self.k as f64;
        k + self.frac
    }

    /// Changes the dead time to `samples` (the process's transport delay
    /// changes): the line reads further back or nearer, so at a steady state
    /// nothing moves. The fraction of a sample must stay what it was (the
    /// exact sub-sample pieces are cut at it).
    pub(super) fn set_dead_time(&mut self, samples: f64) -> Result<(), Error> {
        let (kf, f) = split_delay(samples);
        if (f - self.frac).abs() > 1e-9 {
            return Err(Error::Unsupported(
                "a plant dead-time change must keep the dead time's fraction of a sample (give whole samples)",
            ));
        }
        let k = kf.to_usize_checked()?;
        self.line.set_delay(kf)?;
        self.k = k;
        Ok(())
    }

    /// One piece spans the period: a whole number of samples of dead time
    /// and no sub-steps.
    pub(super) fn is_one_piece(&self) -> bool {
        self.pieces.len() == 1
    }

    /// [`PlantSim::advance`] of a plant in one piece: `out` is that very
    /// discretization, driven by `v[n−k]`.
    #[inline(always)]
    pub(super) fn advance_one_piece(&mut self, v: f64) {
        let now = self.line.process(v);
        self.out.advance(now);
        self.last_in = now;
    }

    /// Output at the current instant (before the new input is applied).
    #[inline]
    pub(super) fn output(&self) -> f64 {
        self.out.free_output() + self.feedthrough * self.last_in
    }

    /// Applies plant input `v[n]` over one period; the outputs at the
    /// intermediate sub-step instants are appended to `sub`.
    #[inline]
    pub(super) fn advance(&mut self, v: f64, sub: &mut Vec<f64>) {
        if self.is_one_piece() {
            self.advance_one_piece(v);
            return;
        }
        let now = self.line.peek_back(v, self.k);
        let before = self.line.peek_back(v, self.k.saturating_add(1));
        self.line.process(v);
        if let Some((late, early)) = &self.folded {
            self.out.advance_inputs(late, now, early, before);
            self.last_in = now;
            return;
        }
        let mut x = *self.out.state();
        for p in &mut self.pieces {
            let input = if p.late { now } else { before };
            p.block.set_state(&x);
            p.block.step(input);
            x = *p.block.state();
            if p.record {
                self.out.set_state(&x);
                sub.push(self.out.free_output() + self.feedthrough * input);
            }
        }
        self.out.set_state(&x);
        self.last_in = now;
    }
}

/// `n` zeros, taken fallibly: a line the system cannot provide is an
/// error, not an abort.
pub(super) fn vec_zeros(n: usize) -> Result<Vec<f64>, Error> {
    vec_zeros_for(n, "plant dead-time line")
}

/// `n` zeros for `what`, taken fallibly.
pub(super) fn vec_zeros_for(n: usize, what: &'static str) -> Result<Vec<f64>, Error> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| Error::OutOfMemory(what))?;
    v.resize(n, 0.0);
    Ok(v)
}

pub(super) trait ToUsize {
    fn to_usize_checked(self) -> Result<usize, Error>;
}
impl ToUsize for f64 {
    fn to_usize_checked(self) -> Result<usize, Error> {
        num_traits::ToPrimitive::to_usize(&self).ok_or(Error::DelayTooLong("delay"))
    }
}

/// The exact sampled plant, stepped one held input at a time.
pub struct PlantStepper(PlantSim);

impl PlantStepper {
    /// The plant at rest, sampled every `ts`.
    pub fn new(plant: &TransferFunction, ts: f64) -> Result<Self, Error> {
        Ok(PlantStepper(PlantSim::new(plant, ts, 1)?))
    }
    /// [`PlantStepper::new`] whose dead time can later be set up to
    /// `max_delay` seconds ([`PlantStepper::set_dead_time`]).
    pub fn with_room(plant: &TransferFunction, ts: f64, max_delay: f64) -> Result<Self, Error> {
        Ok(PlantStepper(PlantSim::with_room(plant, ts, 1, max_delay)?))
    }
    /// The dead time becomes `samples` (its fraction of a sample kept).
    pub fn set_dead_time(&mut self, samples: f64) -> Result<(), Error> {
        self.0.set_dead_time(samples)
    }
    /// The output now.
    pub fn output(&self) -> f64 {
        self.0.output()
    }
    /// Holds `u` for one period.
    pub fn advance(&mut self, u: f64) {
        let mut sub = Vec::new();
        self.0.advance(u, &mut sub);
    }
}

/// The plant's response at the sample instants to the held input `u[k]`
/// (exact: ZOH discretization and the modified z-transform for the dead time);
/// `y[k]` is the output at `k·ts`, before `u[k]` acts.
pub fn open_loop(plant: &TransferFunction, ts: f64, u: &[f64]) -> Result<Vec<f64>, Error> {
    let mut p = PlantSim::new(plant, ts, 1)?;
    let mut sub = Vec::new();
    let mut y = Vec::with_capacity(u.len());
    for uk in u {
        y.push(p.output());
        p.advance(*uk, &mut sub);
    }
    Ok(y)
}

/// The breakpoints of a period as fractions of it: the `m` sub-step instants
/// (recorded, but for the period's end) and where a delayed input changes
/// (the fractions `f`).
pub(super) fn cuts(m: usize, fractions: &[f64]) -> Vec<(f64, bool)> {
    let m = m.max(1);
    let mut cuts: Vec<(f64, bool)> = (1..=m).map(|j| (j as f64 / m as f64, j < m)).collect();
    for f in fractions {
        if *f > 0.0 && !cuts.iter().any(|(c, _)| (c - f).abs() < 1e-12) {
            cuts.push((*f, false));
        }
    }
    cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
    cuts
}

/// Whole samples and fraction of a delay.
pub(super) fn split_delay(d: f64) -> (f64, f64) {
    let mut k = d.floor();
    let mut f = d - k;
    if f >= 1.0 - 1e-12 {
        k += 1.0;
        f = 0.0;
    }
    if f <= 1e-12 {
        f = 0.0;
    }
    (k, f)
}
