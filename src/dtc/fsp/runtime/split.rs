//! The predictor's split form: model-sized blocks around the input line
//! whose sum is the direct form's (see [`super::SplitForm`]).

use super::*;

/// `S` from the model's blocks around a line of the last `h` inputs
/// ([`Realization::Split`]): `S = A·(W + z^{−h}·σ·B)`, `O(1)` per sample
/// whatever the dead time.
///
/// With `window` (a single integrator) `W·u` is the sum of the last `h`
/// inputs, kept as a compensated sum ([`crate::metrics::Sum`]: each input
/// added and the one leaving the window subtracted on its own), so that
/// rounding does not accumulate over a long run, and `σ = 1`; without it
/// `W = 1`, `σ = −1`.
#[derive(Debug, Clone)]
pub struct SplitForm<T, S, const N: usize> {
    a: Lti<T, N>,
    b: Lti<T, N>,
    window: bool,
    /// `u[n − h] … u[n − 1]`, the oldest at `at`.
    pub(super) line: S,
    h: usize,
    at: usize,
    /// The sliding sum of the line.
    pub(super) sum: crate::metrics::Sum<T>,
    /// `A`'s input at this sample (with `window`).
    q: T,
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>, const N: usize> SplitForm<T, S, N> {
    /// The blocks `A = a.0/a.1`, `B = b.0/b.1` (descending powers of z) and
    /// a line of `h ≥ 1` inputs in storage from `storage`.
    pub fn new_in(
        a: (&[f64], &[f64]),
        b: (&[f64], &[f64]),
        window: bool,
        h: usize,
        mut storage: impl FnMut(usize) -> Result<S, Error>,
    ) -> Result<Self, Error> {
        let a: Lti<T, N> = Lti::from_discrete_tf_of(a.0, a.1)?;
        let b: Lti<T, N> = Lti::from_discrete_tf_of(b.0, b.1)?;
        if h == 0 || (!window && a.feedthrough() != T::zero()) {
            return Err(Error::Unsupported(
                "the split predictor needs a dead time of a sample or more and a strictly proper model",
            ));
        }
        let mut line: S = sized(storage(h)?, h)?;
        line.as_mut().iter_mut().for_each(|v| *v = T::zero());
        Ok(SplitForm {
            a,
            b,
            window,
            line,
            h,
            at: 0,
            sum: crate::metrics::Sum::default(),
            q: T::zero(),
        })
    }

    /// `S`'s output at this sample (from the past inputs).
    #[inline]
    pub fn output(&mut self) -> T {
        if self.window {
            self.q = self.sum.value() + self.b.free_output();
            self.a.output(self.q)
        } else {
            self.a.free_output()
        }
    }

    /// Records `u[n]`.
    #[inline]
    pub fn push(&mut self, u: T) {
        let Some(slot) = self.line.as_mut().get_mut(self.at) else {
            return;
        };
        let old = *slot;
        *slot = u;
        self.at = if self.at + 1 >= self.h {
            0
        } else {
            self.at + 1
        };
        if self.window {
            self.a.advance(self.q);
            self.b.advance(old);
            // each term on its own: `u − old` would round
            self.sum.add(u);
            self.sum.add(-old);
        } else {
            let f = self.b.step(old);
            self.a.advance(u - f);
        }
    }

    /// Amends the newest input by `du`.
    pub fn amend_last(&mut self, du: T) {
        let newest = if self.at == 0 {
            self.h - 1
        } else {
            self.at - 1
        };
        if let Some(x) = self.line.as_mut().get_mut(newest) {
            *x = *x + du;
        }
        if self.window {
            self.sum.add(du);
        } else {
            self.a.amend_input(du);
        }
    }

    /// Takes over `old`'s line (the newest inputs, the oldest repeated
    /// beyond what it held) and its blocks' states: `A` is the same block
    /// and `B`'s denominator `Dr` does not depend on the dead time (its
    /// controllable canonical state carries over with the new numerator).
    pub fn carry_from(&mut self, old: &Self) {
        let past = |k: usize| -> T {
            // u[n − k], 1 ≤ k ≤ old.h
            let i = (old.at + old.h - k.min(old.h)) % old.h.max(1);
            old.line.as_ref().get(i).copied().unwrap_or(T::zero())
        };
        let h = self.h;
        for j in 0..h {
            if let Some(x) = self.line.as_mut().get_mut(h - 1 - j) {
                *x = past(j + 1);
            }
        }
        self.at = 0;
        self.a.set_state(old.a.state());
        self.b.set_state(old.b.state());
        self.sum = crate::metrics::Sum::default();
        if self.window {
            for k in 0..h {
                let v = self.line.as_ref().get(k).copied().unwrap_or(T::zero());
                self.sum.add(v);
            }
        }
    }

    /// Zeroes the line and the blocks.
    pub fn reset(&mut self) {
        self.line.as_mut().iter_mut().for_each(|v| *v = T::zero());
        self.a.reset();
        self.b.reset();
        self.at = 0;
        self.sum = crate::metrics::Sum::default();
        self.q = T::zero();
    }

    /// The response at any [`Point`]: `A·(W + z^{−h}·B)` with the window
    /// `W = Σ_{k=1}^{h} z^{−k}` (at a frequency, the Dirichlet kernel), or
    /// `A·(1 − z^{−h}·B)`.
    pub fn response_at<P: Point<T>>(&self, at: &P) -> P::V {
        let delay = at.delay(T::of(f64::from(u32::try_from(self.h).unwrap_or(u32::MAX))));
        if self.window {
            at.lti(&self.a) * (at.window(self.h) + delay * at.lti(&self.b))
        } else {
            at.lti(&self.a) * (P::V::one() - delay * at.lti(&self.b))
        }
    }
}

/// `S` in one of its two realizations.
#[derive(Debug, Clone)]
pub(super) enum SBlock<T, S, const N: usize> {
    Direct(DirectForm<T, S>),
    Split(SplitForm<T, S, N>),
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>, const N: usize> SBlock<T, S, N> {
    pub(super) fn of<D: AsRef<[f64]>>(
        d: &FspDesign<D>,
        h: usize,
        storage: impl FnMut(usize) -> Result<S, Error>,
    ) -> Result<Self, Error> {
        Ok(match &d.s {
            Realization::Direct { den, .. } => {
                SBlock::Direct(DirectForm::new_in(d.s_num(), den.as_slice(), storage)?)
            }
            Realization::Split { a, b, window } => SBlock::Split(SplitForm::new_in(
                (a.0.as_slice(), a.1.as_slice()),
                (b.0.as_slice(), b.1.as_slice()),
                *window,
                h,
                storage,
            )?),
        })
    }
    #[inline]
    pub(super) fn output(&mut self) -> T {
        match self {
            SBlock::Direct(s) => s.output(),
            SBlock::Split(s) => s.output(),
        }
    }
    #[inline]
    pub(super) fn push(&mut self, u: T, s_now: T) {
        match self {
            SBlock::Direct(s) => s.push(u, s_now),
            SBlock::Split(s) => s.push(u),
        }
    }
    pub(super) fn amend_last(&mut self, du: T) {
        match self {
            SBlock::Direct(s) => s.amend_last(du),
            SBlock::Split(s) => s.amend_last(du),
        }
    }
    #[cfg(feature = "alloc")]
    pub(super) fn carry_from(&mut self, old: &Self) -> Result<(), Error> {
        match (self, old) {
            (SBlock::Direct(s), SBlock::Direct(o)) => s.carry_from(o),
            (SBlock::Split(s), SBlock::Split(o)) => {
                s.carry_from(o);
                Ok(())
            }
            _ => Err(Error::Unsupported(
                "a new realization: the history does not carry over",
            )),
        }
    }
    pub(super) fn reset(&mut self) {
        match self {
            SBlock::Direct(s) => s.reset(),
            SBlock::Split(s) => s.reset(),
        }
    }
    pub(super) fn response_at<P: Point<T>>(&self, at: &P) -> P::V {
        match self {
            SBlock::Direct(s) => s.response_at(at),
            SBlock::Split(s) => s.response_at(at),
        }
    }
}
