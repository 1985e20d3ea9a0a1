//! Delay lines: the dead time `e^{-θ s}` of a model, in samples.
//!
//! `y[n] = x[n − d]` for a delay `d = k + f` samples (`k` integer, `0 ≤ f < 1`).
//! A fractional delay is read by linear interpolation between the two
//! neighbouring samples:
//!
//! `y[n] = (1 − f)·x[n − k] + f·x[n − k − 1]`.
//!
//! **Interpolation error.** For a signal whose second derivative is bounded by
//! `M`, the error of linear interpolation is at most `f(1 − f)·Ts²·M/2 ≤ Ts²·M/8`;
//! in the frequency domain the interpolator's gain at `ω` is
//! `|1 − f + f·e^{−jωTs}|`, exactly 1 at DC and falling to `|1 − 2f|` at Nyquist,
//! so the error is negligible for signals sampled well above their bandwidth
//! (below 0.1 % up to `ω = 0.06/Ts` in the worst case `f = ½`). Integer delays
//! are exact.
//!
//! The storage is a ring buffer, read before it is written, so a line of
//! capacity `N` holds delays up to `N` samples. A sample's operations are
//! O(1) whatever `N` (a rescale of the history is spread over the following
//! samples, [`Delay::scale`]; only filling or offsetting the whole history
//! is O(N)); nothing allocates. The storage is generic: a fixed array
//! ([`DelayLine`]), a caller's slice ([`DelayLineRef`]) for capacities known
//! only at run time, or with `alloc` a `Vec`.

use crate::real::{finite, non_negative};
use crate::{error::Error, real::Real};

/// A delay line over any storage that dereferences to a slice of samples.
///
/// Three samples of delay in a line of eight, inline (no heap):
///
/// ```
/// use msp::DelayLine;
/// let mut line: DelayLine<f32, 8> = DelayLine::new(3.0)?;
/// let out: Vec<f32> = [1.0, 2.0, 3.0, 4.0, 5.0].iter().map(|x| line.process(*x)).collect();
/// assert_eq!(out, [0.0, 0.0, 0.0, 1.0, 2.0]);
/// // a fractional delay interpolates between neighbours
/// let mut half: DelayLine<f64, 4> = DelayLine::new(0.5)?;
/// assert_eq!((half.process(2.0), half.process(4.0)), (1.0, 3.0));
/// # Ok::<(), msp::Error>(())
/// ```
///
/// `repr(C)`, the per-sample fields first and the storage after them: a
/// line over an array is stored in place, and the sample's loads and stores
/// stay within the short offsets a Cortex-M's instructions reach from the
/// line's address whatever its capacity.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct Delay<T, S> {
    /// Position the next sample is written to; `buf[head − 1]` holds `x[n − 1]`.
    head: usize,
    /// Integer part of the delay currently applied.
    k: usize,
    /// Fractional part of the delay currently applied, in [0, 1).
    f: T,
    /// Delay currently applied, in samples.
    current: T,
    /// Delay the line moves towards, in samples.
    target: T,
    /// Largest change of the applied delay per sample (samples per sample).
    slew: T,
    /// A whole delay of at least one sample, not ramping: the short path of
    /// [`Delay::process`] (derived state: absent from old serialized lines,
    /// where `false` selects the general path, which is always correct).
    #[cfg_attr(feature = "serde", serde(default))]
    whole: bool,
    /// Nothing to ramp or rescale (derived state: `false`, as absent from
    /// old serialized lines, has the next sample look).
    #[cfg_attr(feature = "serde", serde(default))]
    quiet: bool,
    buf: S,
    /// A rescale of the history under way ([`Delay::scale`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pending: Option<Rescale<T>>,
}

/// How many stored samples a rescale multiplies per sample: two would keep
/// ahead of the read position (it moves one per sample); 32 end a line of
/// 1 000 samples in 33 samples, at about 270 instructions each on a
/// Cortex-M4F (a Smith predictor's update while its line is rescaled: 351,
/// `scripts/firmware`).
const SCALED_PER_SAMPLE: usize = 32;

/// `x mod n` (0 for an empty line: no division by zero to panic on).
#[inline(always)]
fn wrap(x: usize, n: usize) -> usize {
    x.checked_rem(n).unwrap_or(0)
}

/// A rescale of the history ([`Delay::scale`]) spread over the samples
/// that follow its call: the stored samples from the oldest the line reads
/// next (`start`) to the newest at the call first, ahead of the read
/// position, then the older ones the line has not yet overwritten.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Rescale<T> {
    g: T,
    /// Where the scale starts (a position in the storage).
    start: usize,
    /// The samples from `start` to the newest at the call.
    near: usize,
    /// The samples from `start` on scaled or passed over (overwritten).
    done: usize,
    /// The head at the call: the samples written from there on are new.
    head: usize,
}

impl<T: Real> Rescale<T> {
    /// Whether the sample stored at `pos` still waits for its factor, with
    /// `pushed` samples written since the call into a line of capacity `n`.
    /// The samples written since the call into a line of capacity `n`
    /// whose head is now `head` (one a sample; the rescale ends long before
    /// the line turns over).
    fn pushed(&self, head: usize, n: usize) -> usize {
        wrap(head + n - self.head, n)
    }

    fn waits(&self, pos: usize, pushed: usize, n: usize) -> bool {
        let o = wrap(pos + n - self.start, n);
        o >= self.done && !(o >= self.near && o - self.near < pushed)
    }
}

/// A delay line with a fixed capacity of `N` samples, stored inline.
pub type DelayLine<T, const N: usize> = Delay<T, [T; N]>;

/// A delay line over a caller-provided buffer, for capacities known only at run time.
pub type DelayLineRef<'a, T> = Delay<T, &'a mut [T]>;

impl<T: Real, const N: usize> DelayLine<T, N> {
    /// A line of capacity `N` holding `delay` samples (integer or fractional),
    /// initially filled with zeros.
    pub fn new(delay: T) -> Result<Self, Error> {
        Delay::with_storage([T::zero(); N], delay)
    }
}

/// Storage a delay line can create for itself: a fixed array (capacity `N`) or,
/// with `alloc`, a `Vec` sized to the delay.
pub trait DelayStorage<T>: AsRef<[T]> + AsMut<[T]> + Sized {
    /// Storage able to hold `samples` of delay, or [`Error::DelayTooLong`].
    fn for_delay(samples: T) -> Result<Self, Error>;
}

impl<T: Real, const N: usize> DelayStorage<T> for [T; N] {
    fn for_delay(_samples: T) -> Result<Self, Error> {
        Ok([T::zero(); N])
    }
}

#[cfg(feature = "alloc")]
impl<T: Real> DelayStorage<T> for alloc::vec::Vec<T> {
    fn for_delay(samples: T) -> Result<Self, Error> {
        let d = non_negative(samples, "delay")?;
        let cap = d.ceil().to_usize().ok_or(Error::DelayTooLong("delay"))?;
        // taken fallibly: a line the system cannot provide is an error, not an abort
        let mut v = alloc::vec::Vec::new();
        v.try_reserve_exact(cap)
            .map_err(|_| Error::OutOfMemory("delay line"))?;
        v.resize(cap, T::zero());
        Ok(v)
    }
}

impl<T: Real, S: DelayStorage<T>> Delay<T, S> {
    /// A line holding `delay` samples in storage it creates (see [`DelayStorage`]).
    pub fn new_in(delay: T) -> Result<Self, Error> {
        Delay::with_storage(S::for_delay(delay)?, delay)
    }
}

impl<T: Real, S: AsRef<[T]> + AsMut<[T]>> Delay<T, S> {
    /// A line over `storage` (its length is the capacity) holding `delay` samples.
    /// The storage is overwritten with zeros.
    pub fn with_storage(mut storage: S, delay: T) -> Result<Self, Error> {
        storage.as_mut().fill(T::zero());
        let mut line = Delay {
            buf: storage,
            head: 0,
            k: 0,
            f: T::zero(),
            current: T::zero(),
            target: T::zero(),
            slew: T::one(),
            whole: false,
            quiet: false,
            pending: None,
        };
        line.set_delay(delay)?;
        Ok(line)
    }

    /// The line's storage (the line given up).
    pub fn into_storage(self) -> S {
        self.buf
    }

    /// The capacity: the longest delay the line can hold, in samples.
    #[inline]
    pub fn capacity(&self) -> usize {
        self.buf.as_ref().len()
    }

    /// The delay currently applied, in samples.
    #[inline]
    pub fn delay(&self) -> T {
        self.current
    }

    /// Whether the line can take a delay of `delay` samples (non-negative,
    /// within its capacity), changing nothing.
    pub fn check(&self, delay: T) -> Result<(), Error> {
        let d = non_negative(delay, "delay")?;
        match T::from(self.capacity()) {
            Some(cap) if d <= cap => Ok(()),
            _ => Err(Error::DelayTooLong("delay")),
        }
    }

    fn apply(&mut self, delay: T) {
        let k = delay.floor();
        self.k = k.to_usize().unwrap_or(0);
        self.f = delay - k;
        self.current = delay;
        self.refresh();
    }

    fn refresh(&mut self) {
        self.quiet = self.current == self.target && self.pending.is_none();
        self.whole = self.quiet && self.f == T::zero() && self.k >= 1 && self.k <= self.capacity();
    }

    /// Changes the delay at once (the output may jump to another point of the history).
    pub fn set_delay(&mut self, delay: T) -> Result<(), Error> {
        self.check(delay)?;
        // a rescale begun in this sample, nothing scaled yet (a model's gain
        // and dead time applied together), starts again from the new read
        // position; one under way ends first
        let fresh = self
            .pending
            .filter(|r| r.done == 0 && r.head == self.head)
            .map(|r| r.g);
        if fresh.is_some() {
            self.pending = None;
        } else {
            self.settle();
        }
        self.target = delay;
        self.apply(delay);
        if let Some(g) = fresh {
            self.scale(g);
        }
        Ok(())
    }

    /// Moves the delay towards `delay` by at most the slew rate per sample
    /// (one sample per sample by default), as a conveyor whose speed changes:
    /// the read position then never jumps, and the output changes by no more
    /// than one sample's interpolation step.
    pub fn ramp_delay(&mut self, delay: T) -> Result<(), Error> {
        self.check(delay)?;
        self.settle();
        self.target = delay;
        self.refresh();
        Ok(())
    }

    /// Sets the largest change of the delay per sample used by [`Delay::ramp_delay`].
    pub fn set_slew(&mut self, samples_per_sample: T) -> Result<(), Error> {
        self.slew = crate::real::positive(samples_per_sample, "slew")?;
        Ok(())
    }

    /// Fills the history with `value`: the line then outputs `value` until new
    /// samples reach its end (bumpless start from a steady state).
    pub fn fill(&mut self, value: T) {
        self.buf.as_mut().fill(value);
        self.pending = None;
        self.refresh();
    }

    /// Adds `dv` to every sample of the history: the line then outputs what
    /// it would have, had its input always been larger by `dv`.
    pub fn offset(&mut self, dv: T) {
        self.settle();
        self.buf.as_mut().iter_mut().for_each(|x| *x = *x + dv);
    }

    /// Multiplies every sample of the history by `g`: the line then
    /// outputs what it would have, had its input always been `g` times
    /// what it was. The call costs a constant: the stored samples are
    /// multiplied over the following [`Delay::process`] calls, 32 in each,
    /// those the line reads next first (ahead of the read position, which
    /// moves one per sample), then the older ones it has not overwritten.
    /// Every read ([`Delay::peek`], [`Delay::peek_back`], [`Delay::last`])
    /// sees the scaled history meanwhile; an operation that moves the read
    /// position or writes the history ends the rescale first (a delay
    /// change, [`Delay::push`], another rescale), so it may cost O(N) there.
    /// A line ramping to a new delay is rescaled at once.
    pub fn scale(&mut self, g: T) {
        self.settle();
        let n = self.capacity();
        if n == 0 {
            return;
        }
        // x[n − k − 1] (a fractional delay's older neighbour) up to the newest
        let near = self.k.saturating_add(1).min(n);
        self.pending = Some(Rescale {
            g,
            start: wrap(self.head + n - near, n),
            near,
            done: 0,
            head: self.head,
        });
        if self.current != self.target {
            self.settle();
        }
        self.refresh();
    }

    /// Multiplies the next `count` stored samples of a rescale under way.
    fn scale_some(&mut self, mut count: usize) {
        let Some(mut r) = self.pending else {
            return;
        };
        let n = self.capacity();
        let pushed = r.pushed(self.head, n);
        let buf = self.buf.as_mut();
        while count > 0 && r.done < n {
            if r.done >= r.near {
                // past the newest at the call: the older samples, those
                // from the call's head on overwritten since
                r.done = r.done.max(r.near.saturating_add(pushed));
                if r.done >= n {
                    break;
                }
            }
            // a contiguous run: to the phase's end, the storage's, or the count's
            let end = if r.done < r.near { r.near } else { n };
            let pos = wrap(r.start + r.done, n);
            let run = count.min(end - r.done).min(n - pos);
            if let Some(xs) = buf.get_mut(pos..pos + run) {
                xs.iter_mut().for_each(|x| *x = *x * r.g);
            }
            r.done += run;
            count -= run;
        }
        self.pending = (r.done < n).then_some(r);
        self.refresh();
    }

    /// Ends a rescale under way (if any) at once.
    #[inline]
    pub fn settle(&mut self) {
        if self.pending.is_some() {
            self.finish();
        }
    }

    /// The rest of a rescale under way, at once (rare: out of line).
    #[cold]
    #[inline(never)]
    fn finish(&mut self) {
        self.scale_some(usize::MAX);
    }

    /// Whether a rescale is under way ([`Delay::scale`]).
    pub fn is_rescaling(&self) -> bool {
        self.pending.is_some()
    }

    /// Adds `dx` to the newest sample (the last pushed): the line then
    /// outputs what it would have, had that input been larger by `dx`.
    pub fn amend_newest(&mut self, dx: T) {
        self.settle();
        let n = self.capacity();
        if n == 0 {
            return;
        }
        let at = if self.head == 0 { n - 1 } else { self.head - 1 };
        if let Some(x) = self.buf.as_mut().get_mut(at) {
            *x = *x + dx;
        }
    }

    /// Fills the history with zeros.
    pub fn reset(&mut self) {
        self.fill(T::zero());
    }

    /// Where `x[n − j]` is stored, `1 ≤ j ≤` the capacity.
    #[inline(always)]
    fn index(&self, j: usize) -> usize {
        // head < n and 1 <= j <= n, so the index is in 0..n without overflow.
        if self.head >= j {
            self.head.wrapping_sub(j)
        } else {
            self.head.wrapping_add(self.capacity()).wrapping_sub(j)
        }
    }

    /// `x[n − j]` for `j ≥ 1` as stored; `j` must be at most the capacity.
    #[inline(always)]
    fn past(&self, j: usize) -> T {
        self.buf
            .as_ref()
            .get(self.index(j))
            .copied()
            .unwrap_or(T::zero())
    }

    /// `x[n − j]`, with `j = 0` the current input, as stored.
    #[inline(always)]
    fn tap(&self, x: T, j: usize) -> T {
        if j == 0 {
            x
        } else {
            self.past(j)
        }
    }

    /// [`Self::tap`] with the factor of a rescale under way where the
    /// sample still waits for it.
    fn tap_scaled(&self, x: T, j: usize) -> T {
        let v = self.tap(x, j);
        match self.pending {
            Some(r) if j > 0 => {
                let n = self.capacity();
                if r.waits(self.index(j), r.pushed(self.head, n), n) {
                    v * r.g
                } else {
                    v
                }
            }
            _ => v,
        }
    }

    /// `x[n − j]` for input `x[n]` and `j ≤ capacity`, without advancing the line.
    #[inline]
    pub fn peek_back(&self, x: T, j: usize) -> T {
        if j > self.capacity() {
            T::zero()
        } else {
            self.tap_scaled(x, j)
        }
    }

    /// Reads the delayed sample for input `x[n]` without advancing the line.
    #[inline(always)]
    pub fn peek(&self, x: T) -> T {
        if self.pending.is_none() {
            self.peek_stored(x)
        } else {
            self.peek_scaled(x)
        }
    }

    /// [`Self::peek`] during a rescale (rare: out of line).
    #[cold]
    #[inline(never)]
    fn peek_scaled(&self, x: T) -> T {
        let a = self.tap_scaled(x, self.k);
        if self.f == T::zero() {
            a
        } else {
            let b = self.tap_scaled(x, self.k.wrapping_add(1));
            a + self.f * (b - a)
        }
    }

    /// [`Self::peek`] from the history as stored: what [`Self::process`]
    /// reads once its rescale step has passed the read position, and what
    /// a line no rescale is under way in reads (an owner that never
    /// rescales its line: no test on the sample's path).
    #[inline(always)]
    pub(crate) fn peek_stored(&self, x: T) -> T {
        let a = self.tap(x, self.k);
        if self.f == T::zero() {
            a
        } else {
            let b = self.tap(x, self.k.wrapping_add(1));
            a + self.f * (b - a)
        }
    }

    /// A sample's step of a ramped delay change or of a rescale (rare:
    /// kept out of the hot path).
    #[cold]
    #[inline(never)]
    fn cold_step(&mut self) {
        if self.current != self.target {
            let step = crate::real::clamp(self.target - self.current, -self.slew, self.slew);
            let next = self.current + step;
            self.apply(next);
        }
        self.scale_some(SCALED_PER_SAMPLE);
        self.refresh();
    }

    /// Pushes `x[n]` without reading (after [`Delay::peek`] read the
    /// sample's output; a ramped delay change does not move, a rescale
    /// under way ends first).
    #[inline]
    pub fn push(&mut self, x: T) {
        self.settle();
        self.push_stored(x);
    }

    /// [`Self::push`] without the rescale's check (see [`Self::peek_stored`]).
    #[inline(always)]
    pub(crate) fn push_stored(&mut self, x: T) {
        let head = self.head;
        let buf = self.buf.as_mut();
        let n = buf.len();
        if let Some(slot) = buf.get_mut(head) {
            *slot = x;
            let h = head.wrapping_add(1);
            self.head = if h >= n { 0 } else { h };
        }
    }

    /// Pushes `x[n]` and returns `x[n − d]`.
    #[inline]
    pub fn process(&mut self, x: T) -> T {
        let y = if self.whole {
            // x[n − k] from the history, nothing to interpolate or ramp
            self.past(self.k)
        } else {
            if !self.quiet {
                self.cold_step();
            }
            self.peek_stored(x)
        };
        self.push_stored(x);
        y
    }

    /// The most recent input, `x[n − 1]` (zero for an empty line).
    #[inline]
    pub fn last(&self) -> T {
        if self.capacity() == 0 {
            T::zero()
        } else {
            self.tap_scaled(T::zero(), 1)
        }
    }
}

/// Converts a delay in seconds to samples, checking it.
pub fn samples<T: Real>(delay_s: T, ts: T) -> Result<T, Error> {
    let ts = crate::real::positive(ts, "ts")?;
    let d = non_negative(finite(delay_s, "delay")?, "delay")?;
    Ok(d / ts)
}

/// `samples` as a whole number of samples, at most `room` (within
/// rounding: 7.2 s / 0.06 s is 120.00000000000001); `what` names the
/// predictor in the error.
pub(crate) fn whole_samples<T: Real>(
    samples: T,
    room: usize,
    what: &'static str,
) -> Result<usize, Error> {
    let whole = samples.round();
    let h = whole
        .to_usize()
        .filter(|_| (samples - whole).abs() <= T::of(1e-6))
        .ok_or(Error::Unsupported(what))?;
    if h > room {
        return Err(Error::DelayTooLong("delay"));
    }
    Ok(h)
}

/// `h` whole samples as a delay in `T`.
pub(crate) fn samples_of<T: Real>(h: usize) -> Result<T, Error> {
    let n = u32::try_from(h).map_err(|_| Error::DelayTooLong("delay"))?;
    Ok(T::of(f64::from(n)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_delay_is_exact() -> Result<(), Box<dyn std::error::Error>> {
        let mut d: DelayLine<f64, 4> = DelayLine::new(3.0)?;
        let out: Vec<f64> = (1..=8).map(|i| d.process(i as f64)).collect();
        assert_eq!(out, [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        Ok(())
    }

    #[test]
    fn zero_delay_and_zero_capacity() -> Result<(), Box<dyn std::error::Error>> {
        let mut d: DelayLine<f64, 0> = DelayLine::new(0.0)?;
        assert_eq!(d.process(2.5), 2.5);
        assert_eq!(
            DelayLine::<f64, 0>::new(0.5).err(),
            Some(Error::DelayTooLong("delay"))
        );
        Ok(())
    }

    #[test]
    fn capacity_is_the_longest_delay() -> Result<(), Box<dyn std::error::Error>> {
        let mut d: DelayLine<f64, 3> = DelayLine::new(3.0)?;
        let out: Vec<f64> = (1..=5).map(|i| d.process(i as f64)).collect();
        assert_eq!(out, [0.0, 0.0, 0.0, 1.0, 2.0]);
        assert!(DelayLine::<f64, 3>::new(3.0001).is_err());
        assert_eq!(
            DelayLine::<f64, 3>::new(f64::NAN).err(),
            Some(Error::NonFinite("delay"))
        );
        assert_eq!(
            DelayLine::<f64, 3>::new(-1.0).err(),
            Some(Error::Negative("delay"))
        );
        Ok(())
    }

    #[test]
    fn fractional_delay_interpolates_linearly() -> Result<(), Box<dyn std::error::Error>> {
        let mut d: DelayLine<f64, 8> = DelayLine::new(2.25)?;
        let out: Vec<f64> = (0..8).map(|i| d.process((i * i) as f64)).collect();
        // x[n] = n^2, y[n] = 0.75 x[n-2] + 0.25 x[n-3]
        for (n, y) in out.iter().enumerate().skip(3) {
            let e = 0.75 * ((n - 2) * (n - 2)) as f64 + 0.25 * ((n - 3) * (n - 3)) as f64;
            assert!((y - e).abs() < 1e-12);
        }
        Ok(())
    }

    #[test]
    fn fill_gives_a_steady_output() -> Result<(), Box<dyn std::error::Error>> {
        let mut d: DelayLine<f32, 5> = DelayLine::new(4.5)?;
        d.fill(2.0);
        assert_eq!(d.process(0.0), 2.0);
        Ok(())
    }

    #[test]
    fn slice_storage() -> Result<(), Box<dyn std::error::Error>> {
        let mut storage = [9.0f64; 10];
        let mut d = DelayLineRef::with_storage(&mut storage[..], 2.0)?;
        assert_eq!(d.process(1.0), 0.0);
        assert_eq!(d.process(2.0), 0.0);
        assert_eq!(d.process(3.0), 1.0);
        Ok(())
    }
}
