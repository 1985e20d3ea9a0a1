//! Inverted decoupling and the decoupled dead-time compensator.
//!
//! The inverted decoupler (Wade (1997)) computes the plant's inputs from
//! the loops' outputs `v` as
//!
//! `uᵢ = vᵢ − Σ_{j≠i} dᵢⱼ·uⱼ`,  `dᵢⱼ = gᵢⱼ/gᵢᵢ`,
//!
//! so that `yᵢ = Σⱼ gᵢⱼuⱼ = gᵢᵢ·(vᵢ − Σ_{j≠i} dᵢⱼuⱼ) + Σ_{j≠i} gᵢⱼuⱼ =
//! gᵢᵢ·vᵢ`: loop `i` sees its diagonal channel alone, whatever `n`. Each
//! `dᵢⱼ` is a delay of `θᵢⱼ − θᵢᵢ` (realizable when it is not negative)
//! and the ratio of the two channels' rational parts (stable when `gᵢᵢ`
//! has no zero in the right half-plane, proper when `gᵢᵢ`'s relative
//! degree is not above `gᵢⱼ`'s); the design (`msp::study`) checks these
//! conditions and says what it does where one fails.
//!
//! The decoupler is a loop of its own: where a `dᵢⱼ` passes its input
//! through in the same sample, the inputs are the solution of
//! `(I + B)·u = v − a`, `a` the elements' outputs for a zero input now and
//! `B` their direct terms (the `n×n` system solved each sample). Its
//! internal stability — `det(I + D(z))` without zeros outside the unit
//! circle, i.e. `det G` without them, since `I + D = diag(gᵢᵢ)⁻¹·G` — is a
//! property of the plant, checked by the design as well.

use core::ops::Mul;

use super::{solve, MultiController};
use crate::complex::Complex;
use crate::controller::Controller;
use crate::delay::Delay;
use crate::error::Error;
use crate::lti::Lti;
use crate::real::Real;

/// One decoupling element `dᵢⱼ`: a delay line (`θᵢⱼ − θᵢᵢ` in samples,
/// its fraction interpolated as [`crate::delay`] does) and a block of
/// order `≤ M` (the ratio's rational part, with its direct term).
#[derive(Debug, Clone)]
pub struct Element<T, const M: usize, S> {
    line: Delay<T, S>,
    block: Lti<T, M>,
}

impl<T: Real, const M: usize, S: AsRef<[T]> + AsMut<[T]>> Element<T, M, S> {
    /// The element from its block and line.
    pub fn new(block: Lti<T, M>, line: Delay<T, S>) -> Self {
        Element { line, block }
    }

    /// The element's output if its input were `x` now (nothing advances).
    #[inline(always)]
    fn peek(&self, x: T) -> T {
        self.block.output(self.line.peek(x))
    }

    /// Advances with the sample's input `x`.
    #[inline(always)]
    fn step(&mut self, x: T) {
        let d = self.line.process(x);
        self.block.step(d);
    }

    /// `d(e^{jθ})`: the block's response and the line's (as it
    /// interpolates).
    pub fn response(&self, theta: T) -> Complex<T> {
        self.block
            .response(theta)
            .mul(Complex::delay_response(theta, self.line.delay()))
    }

    /// How many of the block's poles lie outside the unit circle.
    pub fn unstable_poles(&self) -> usize {
        self.block.unstable_poles()
    }

    /// The line's delay (samples).
    pub fn delay(&self) -> T {
        self.line.delay()
    }

    /// The block's order.
    pub fn order(&self) -> usize {
        self.block.order()
    }

    fn reset(&mut self) {
        self.line.reset();
        self.block.reset();
    }
}

/// The inverted decoupler of an `N×N` plant: element `(i, j)` off the
/// diagonal is `dᵢⱼ` or absent (no coupling to cancel).
#[derive(Debug, Clone)]
pub struct InvertedDecoupler<T, const N: usize, const M: usize, S> {
    elements: [[Option<Element<T, M, S>>; N]; N],
    /// The last inputs (held when the sample's system is singular).
    last: [T; N],
    fault: bool,
}

impl<T: Real, const N: usize, const M: usize, S: AsRef<[T]> + AsMut<[T]>>
    InvertedDecoupler<T, N, M, S>
{
    /// The decoupler from its elements; an element on the diagonal is an
    /// error (`uᵢ` is `vᵢ` there by construction).
    pub fn new(elements: [[Option<Element<T, M, S>>; N]; N]) -> Result<Self, Error> {
        let diagonal = elements
            .iter()
            .enumerate()
            .any(|(i, row)| row.get(i).is_some_and(Option::is_some));
        if diagonal {
            return Err(Error::OutOfRange(
                "inverted decoupler: an element on the diagonal",
            ));
        }
        Ok(InvertedDecoupler {
            elements,
            last: [T::zero(); N],
            fault: false,
        })
    }

    /// The inputs `u` for the loops' outputs `v` (one sample): the
    /// solution of `(I + B)·u = v − a` (see the module documentation).
    /// A non-finite `v` or a singular system holds the last inputs and
    /// sets [`InvertedDecoupler::fault`].
    #[inline]
    pub fn update(&mut self, v: &[T; N], u: &mut [T; N]) {
        let mut a = [[T::zero(); N]; N];
        let mut b = *v;
        for (i, ((row, el_row), bi)) in a
            .iter_mut()
            .zip(self.elements.iter())
            .zip(b.iter_mut())
            .enumerate()
        {
            if let Some(x) = row.get_mut(i) {
                *x = T::one();
            }
            for (x, el) in row.iter_mut().zip(el_row.iter()) {
                if let Some(el) = el {
                    let free = el.peek(T::zero());
                    *x = *x + (el.peek(T::one()) - free);
                    *bi = *bi - free;
                }
            }
        }
        self.fault = !v.iter().all(|x| x.is_finite()) || !solve(&mut a, &mut b);
        if self.fault {
            *u = self.last;
        } else {
            *u = b;
        }
        self.last = *u;
        for row in self.elements.iter_mut() {
            for (el, x) in row.iter_mut().zip(u.iter()) {
                if let Some(el) = el {
                    el.step(*x);
                }
            }
        }
    }

    /// The last sample could not be solved (or `v` was not finite): its
    /// inputs are the sample's before.
    pub fn fault(&self) -> bool {
        self.fault
    }

    /// Element `(i, j)`.
    pub fn element(&self, i: usize, j: usize) -> Option<&Element<T, M, S>> {
        self.elements.get(i)?.get(j)?.as_ref()
    }

    /// `D(e^{jθ})` (zero on the diagonal and where no element is), by rows.
    pub fn response(&self, theta: T) -> [[Complex<T>; N]; N] {
        let mut d = [[Complex::real(T::zero()); N]; N];
        for (row, el_row) in d.iter_mut().zip(self.elements.iter()) {
            for (x, el) in row.iter_mut().zip(el_row.iter()) {
                if let Some(el) = el {
                    *x = el.response(theta);
                }
            }
        }
        d
    }

    /// How many of the elements' poles lie outside the unit circle.
    pub fn unstable_poles(&self) -> usize {
        self.elements
            .iter()
            .flatten()
            .flatten()
            .map(Element::unstable_poles)
            .sum()
    }

    /// Every element's state to zero.
    pub fn reset(&mut self) {
        self.elements
            .iter_mut()
            .flatten()
            .flatten()
            .for_each(Element::reset);
        self.last = [T::zero(); N];
        self.fault = false;
    }
}

/// The decoupled dead-time compensator: loop `i`'s controller `C` (a
/// Smith predictor on `gᵢᵢ`) computes `vᵢ` from `rᵢ` and `yᵢ`, and the
/// [`InvertedDecoupler`] turns `v` into the plant's inputs. With the
/// decoupler exact, loop `i`'s process is `gᵢᵢ` alone, and a predictor
/// whose model is `gᵢᵢ` sees no coupling at all.
#[derive(Debug, Clone)]
pub struct Decoupled<T, C, const N: usize, const M: usize, S> {
    loops: [C; N],
    decoupler: InvertedDecoupler<T, N, M, S>,
    v: [T; N],
}

impl<T: Real, C: Controller<T>, const N: usize, const M: usize, S: AsRef<[T]> + AsMut<[T]>>
    Decoupled<T, C, N, M, S>
{
    /// The loops' controllers and the decoupler.
    pub fn new(loops: [C; N], decoupler: InvertedDecoupler<T, N, M, S>) -> Self {
        Decoupled {
            loops,
            decoupler,
            v: [T::zero(); N],
        }
    }

    /// The loops' controllers.
    pub fn loop_controllers(&self) -> &[C; N] {
        &self.loops
    }

    /// The decoupler.
    pub fn decoupler(&self) -> &InvertedDecoupler<T, N, M, S> {
        &self.decoupler
    }

    /// The loops' last outputs `v` (the decoupler's inputs).
    pub fn loop_outputs(&self) -> &[T; N] {
        &self.v
    }
}

impl<T: Real, C: Controller<T>, const N: usize, const M: usize, S: AsRef<[T]> + AsMut<[T]>>
    MultiController<T> for Decoupled<T, C, N, M, S>
{
    fn loops(&self) -> usize {
        N
    }

    #[inline]
    fn update(&mut self, r: &[T], y: &[T], u: &mut [T]) {
        for (((c, v), r), y) in self.loops.iter_mut().zip(self.v.iter_mut()).zip(r).zip(y) {
            *v = c.update(*r, *y);
        }
        let mut out = [T::zero(); N];
        self.decoupler.update(&self.v, &mut out);
        for (u, x) in u.iter_mut().zip(out) {
            *u = x;
        }
    }

    fn reset_to_rest(&mut self) {
        self.loops.iter_mut().for_each(Controller::reset_to_rest);
        self.decoupler.reset();
        self.v = [T::zero(); N];
    }
}
