//! Controllers of multivariable plants: `n` loops, one call a sample,
//! `update(&r, &y, &mut u)`, allocation-free.
//!
//! - [`Decentralized`]: a single-loop controller on each loop of the
//!   pairing (the BLT-tuned PI loops of Luyben (1986), or a Smith predictor
//!   on each diagonal channel: the decentralized dead-time compensator).
//! - [`Decoupled`]: a Smith predictor on each diagonal channel behind an
//!   [`InvertedDecoupler`] (Wade (1997)'s inverted decoupling, with
//!   dead-time compensation in each decoupled loop as in Garrido et al.
//!   (2016)): each loop's process is then its own diagonal channel, so each
//!   predictor sees the single-loop process it was designed for.
//!
//! Construction from a transfer matrix, with the decoupler's realizability
//! conditions checked, is in `msp::study` (it needs the plant grammar).

mod decoupler;

pub use decoupler::{fopdt_element, fopdt_element_samples, Decoupled, Element, InvertedDecoupler};

use core::marker::PhantomData;

use crate::controller::Controller;
use crate::operate::{Operate, Tracking};
use crate::real::Real;

/// A controller of `n` loops: set points `r`, measurements `y` in, the
/// inputs `u` out, each slice `n` long (loop `i` closes output `i`
/// through input `i`: the pairing is the plant's diagonal).
pub trait MultiController<T: Real> {
    /// How many loops (`n`).
    fn loops(&self) -> usize;
    /// One sample: `r[k]` and `y[k]` in, `u[k]` out. Slices shorter than
    /// [`MultiController::loops`] are read as far as they go (the loops
    /// beyond them keep their inputs).
    fn update(&mut self, setpoints: &[T], measurements: &[T], inputs: &mut [T]);
    /// Input `loop_index` of the last update was `u` where the plant
    /// received it (the loop in manual: `Tracking::Full`, the loop's
    /// output follows it and its return to automatic is bumpless; an
    /// actuator that limited it: `Tracking::Reset`, external reset feedback,
    /// no windup): the controller is amended as if it had computed that.
    fn applied(&mut self, loop_index: usize, u: T, how: Tracking);
    /// Every state to zero, the loop at rest before the next sample (as
    /// [`Controller::reset_to_rest`] of each single-loop part).
    fn reset_to_rest(&mut self);
}

/// Independent single-loop controllers, one per loop, over storage `L`
/// (`[C; N]` on firmware, a `Vec` on a host).
#[derive(Debug, Clone)]
pub struct Decentralized<C, L> {
    loops: L,
    _c: PhantomData<C>,
}

impl<C, L: AsRef<[C]> + AsMut<[C]>> Decentralized<C, L> {
    /// The loops, in the pairing's order.
    pub fn new(loops: L) -> Self {
        Decentralized {
            loops,
            _c: PhantomData,
        }
    }

    /// Loop `i`'s controller.
    pub fn get(&self, i: usize) -> Option<&C> {
        self.loops.as_ref().get(i)
    }

    /// The loops.
    pub fn parts(&self) -> &[C] {
        self.loops.as_ref()
    }
}

impl<T: Real, C: Operate<T>, L: AsRef<[C]> + AsMut<[C]>> MultiController<T>
    for Decentralized<C, L>
{
    fn applied(&mut self, loop_index: usize, u: T, how: Tracking) {
        if let Some(c) = self.loops.as_mut().get_mut(loop_index) {
            c.apply(u, how);
        }
    }

    fn loops(&self) -> usize {
        self.loops.as_ref().len()
    }

    #[inline]
    fn update(&mut self, r: &[T], y: &[T], u: &mut [T]) {
        for (((c, r), y), u) in self.loops.as_mut().iter_mut().zip(r).zip(y).zip(u) {
            *u = c.update(*r, *y);
        }
    }

    fn reset_to_rest(&mut self) {
        self.loops
            .as_mut()
            .iter_mut()
            .for_each(Controller::reset_to_rest);
    }
}

/// Solves `a·x = b` in place (`b` becomes `x`) by Gaussian elimination with
/// partial pivoting; `false` (and `b` unspecified) when `a` is singular.
pub(crate) fn solve<T: Real, const N: usize>(a: &mut [[T; N]; N], b: &mut [T; N]) -> bool {
    for col in 0..N {
        let mut pivot = col;
        let mut size = T::zero();
        for (r, row) in a.iter().enumerate().skip(col) {
            let x = row.get(col).map_or(T::zero(), |x| x.abs());
            if x > size {
                (pivot, size) = (r, x);
            }
        }
        if !(size > T::zero()) || !size.is_finite() {
            return false;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (top, rest) = a.split_at_mut(col + 1);
        let (b_top, b_rest) = b.split_at_mut(col + 1);
        let (Some(prow), Some(&bp)) = (top.last(), b_top.last()) else {
            return false;
        };
        let pv = prow.get(col).copied().unwrap_or(T::one());
        for (row, bi) in rest.iter_mut().zip(b_rest.iter_mut()) {
            let f = row.get(col).copied().unwrap_or(T::zero()) / pv;
            for (x, p) in row.iter_mut().zip(prow.iter()).skip(col) {
                *x = *x - f * *p;
            }
            *bi = *bi - f * bp;
        }
    }
    // back substitution, the last row first
    for col in (0..N).rev() {
        let (Some(row), Some(&bc)) = (a.get(col), b.get(col)) else {
            return false;
        };
        let known = row
            .iter()
            .zip(b.iter())
            .skip(col + 1)
            .fold(T::zero(), |s, (x, v)| s + *x * *v);
        let pv = row.get(col).copied().unwrap_or(T::one());
        if let Some(x) = b.get_mut(col) {
            *x = (bc - known) / pv;
        }
    }
    b.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_agrees_with_the_product() {
        let mut a: [[f64; 3]; 3] = [[2.0, 1.0, -1.0], [-3.0, -1.0, 2.0], [-2.0, 1.0, 2.0]];
        let mut b = [8.0, -11.0, -3.0];
        assert!(solve(&mut a, &mut b));
        // the textbook system's solution (2, 3, −1)
        for (x, e) in b.iter().zip([2.0, 3.0, -1.0]) {
            assert!((x - e).abs() < 1e-12, "{b:?}");
        }
        let mut s = [[1.0, 2.0], [2.0, 4.0]];
        let mut v = [1.0, 2.0];
        assert!(!solve(&mut s, &mut v));
    }
}
