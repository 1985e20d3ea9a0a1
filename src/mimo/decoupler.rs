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
//! `B` their direct terms, constant: `(I + B)⁻¹` is found once, at
//! construction, and each sample multiplies by it (nothing to solve where
//! every element is delayed by a sample or more, as most are). Its
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
use crate::operate::{Operate, Tracking};
use crate::real::Real;

/// One decoupling element `dᵢⱼ`: a delay line (`θᵢⱼ − θᵢᵢ` in samples,
/// its fraction interpolated as [`crate::delay`] does) and a block of
/// order `≤ M` (the ratio's rational part, with its direct term).
#[derive(Debug, Clone)]
pub struct Element<T, const M: usize, S> {
    line: Delay<T, S>,
    block: Lti<T, M>,
    /// The weight of the sample's own input in the line's output (`1 − d`
    /// for a delay `d` below a sample, else 0), and in the element's (times
    /// the block's direct term).
    weight: T,
    direct: T,
    /// The line's output for a zero input now ([`Element::free`]'s).
    pending: T,
}

impl<T: Real, const M: usize, S: AsRef<[T]> + AsMut<[T]>> Element<T, M, S> {
    /// The element from its block and line (a rescale under way in it
    /// ended first: the element reads and writes its line unchecked, and
    /// never rescales it).
    pub fn new(block: Lti<T, M>, mut line: Delay<T, S>) -> Self {
        line.settle();
        let d = line.delay();
        let weight = if d < T::one() {
            T::one() - d
        } else {
            T::zero()
        };
        Element {
            weight,
            direct: block.feedthrough() * weight,
            pending: T::zero(),
            line,
            block,
        }
    }

    /// The element's output for a zero input now (nothing advances but
    /// the line's reading, kept for [`Element::step`]).
    #[inline(always)]
    fn free(&mut self) -> T {
        self.pending = self.line.peek_stored(T::zero());
        self.block.output(self.pending)
    }

    /// Advances with the sample's input `x` (after [`Element::free`]: the
    /// line's output is its reading plus `x`'s weight).
    #[inline(always)]
    fn step(&mut self, x: T) {
        self.line.push_stored(x);
        self.block.step(self.pending + self.weight * x);
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
        self.pending = T::zero();
    }

    /// The last step's input was `x + dx`, not `x`.
    fn amend(&mut self, dx: T) {
        self.line.amend_newest(dx);
        self.block.amend_input(self.weight * dx);
    }
}

/// The inverted decoupler of an `N×N` plant: element `(i, j)` off the
/// diagonal is `dᵢⱼ` or absent (no coupling to cancel).
#[derive(Debug, Clone)]
pub struct InvertedDecoupler<T, const N: usize, const M: usize, S> {
    elements: [[Option<Element<T, M, S>>; N]; N],
    /// `(I + B)⁻¹`, where some element has a direct term (`None`: `I`).
    inverse: Option<[[T; N]; N]>,
    /// The last inputs (held when the sample's system is singular).
    last: [T; N],
    fault: bool,
}

impl<T: Real, const N: usize, const M: usize, S: AsRef<[T]> + AsMut<[T]>>
    InvertedDecoupler<T, N, M, S>
{
    /// The decoupler from its elements; an element on the diagonal is an
    /// error (`uᵢ` is `vᵢ` there by construction), and so is a singular
    /// `I + B` (the elements' direct terms leave the inputs undetermined).
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
        let mut b = [[T::zero(); N]; N];
        let mut coupled = false;
        for (i, (row, el_row)) in b.iter_mut().zip(elements.iter()).enumerate() {
            if let Some(x) = row.get_mut(i) {
                *x = T::one();
            }
            for (x, el) in row.iter_mut().zip(el_row.iter()) {
                if let Some(el) = el {
                    *x = *x + el.direct;
                    coupled |= el.direct != T::zero();
                }
            }
        }
        // (I + B)⁻¹, column by column
        let inverse = if coupled {
            let mut inv = [[T::zero(); N]; N];
            for j in 0..N {
                let mut e = [T::zero(); N];
                if let Some(x) = e.get_mut(j) {
                    *x = T::one();
                }
                let mut a = b;
                if !solve(&mut a, &mut e) {
                    return Err(Error::Numerical(
                        "inverted decoupler: I + B is singular (the elements' direct terms leave the inputs undetermined)",
                    ));
                }
                for (row, x) in inv.iter_mut().zip(e) {
                    if let Some(y) = row.get_mut(j) {
                        *y = x;
                    }
                }
            }
            Some(inv)
        } else {
            None
        };
        Ok(InvertedDecoupler {
            elements,
            inverse,
            last: [T::zero(); N],
            fault: false,
        })
    }

    /// The inputs `u` for the loops' outputs `v` (one sample): the
    /// solution of `(I + B)·u = v − a` (see the module documentation).
    /// A non-finite `v` holds the last inputs and sets
    /// [`InvertedDecoupler::fault`].
    #[inline]
    pub fn update(&mut self, v: &[T; N], u: &mut [T; N]) {
        let mut rhs = *v;
        for (bi, el_row) in rhs.iter_mut().zip(self.elements.iter_mut()) {
            for el in el_row.iter_mut().flatten() {
                *bi = *bi - el.free();
            }
        }
        let solved = match &self.inverse {
            None => rhs,
            Some(inv) => {
                let mut out = [T::zero(); N];
                for (o, row) in out.iter_mut().zip(inv.iter()) {
                    *o = row
                        .iter()
                        .zip(rhs.iter())
                        .fold(T::zero(), |s, (m, x)| s + *m * *x);
                }
                out
            }
        };
        self.fault = !solved.iter().all(|x| x.is_finite());
        *u = if self.fault { self.last } else { solved };
        self.last = *u;
        for row in self.elements.iter_mut() {
            for (el, x) in row.iter_mut().zip(u.iter()) {
                if let Some(el) = el {
                    el.step(*x);
                }
            }
        }
    }

    /// The last sample's `v` was not finite: its inputs are the sample's
    /// before.
    pub fn fault(&self) -> bool {
        self.fault
    }

    /// Input `j` of the last update was `u` (not what was computed): the
    /// elements that read it are amended, and the loops' outputs that give
    /// the inputs as they are, `v + (I + B)·Δu`, are returned by the change
    /// of each (`Δv`).
    pub fn applied(&mut self, j: usize, u: T) -> [T; N] {
        let mut dv = [T::zero(); N];
        let Some(last) = self.last.get_mut(j) else {
            return dv;
        };
        let du = u - *last;
        *last = u;
        if let Some(x) = dv.get_mut(j) {
            *x = du;
        }
        for (row, d) in self.elements.iter_mut().zip(dv.iter_mut()) {
            if let Some(Some(el)) = row.get_mut(j) {
                el.amend(du);
                *d = *d + el.direct * du;
            }
        }
        dv
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

impl<T: Real, C: Operate<T>, const N: usize, const M: usize, S: AsRef<[T]> + AsMut<[T]>>
    MultiController<T> for Decoupled<T, C, N, M, S>
{
    fn applied(&mut self, loop_index: usize, u: T, how: Tracking) {
        let dv = self.decoupler.applied(loop_index, u);
        for ((c, v), d) in self.loops.iter_mut().zip(self.v.iter_mut()).zip(dv) {
            if d != T::zero() {
                *v = *v + d;
                c.apply(*v, how);
            }
        }
    }

    fn loops(&self) -> usize {
        N
    }

    #[inline]
    fn update(&mut self, r: &[T], y: &[T], u: &mut [T]) {
        for (((c, v), r), y) in self.loops.iter_mut().zip(self.v.iter_mut()).zip(r).zip(y) {
            *v = c.update(*r, *y);
        }
        match <&mut [T; N]>::try_from(&mut *u) {
            Ok(out) => self.decoupler.update(&self.v, out),
            Err(_) => {
                let mut out = [T::zero(); N];
                self.decoupler.update(&self.v, &mut out);
                for (u, x) in u.iter_mut().zip(out) {
                    *u = x;
                }
            }
        }
    }

    fn reset_to_rest(&mut self) {
        self.loops.iter_mut().for_each(Controller::reset_to_rest);
        self.decoupler.reset();
        self.v = [T::zero(); N];
    }
}

/// The element `dᵢⱼ = gᵢⱼ(z)/gᵢᵢ(z)` of two first-order-plus-dead-time
/// channels sampled at `ts`, for firmware (no allocation; its line over
/// `storage`). A channel `K e^{−θs}/(τs + 1)` with `θ = (k + f)·ts` samples
/// exactly (ZOH, the fraction `f` of a sample split over the period) to
///
/// `g(z) = z^{−k−1}·(b₀ + b₁z⁻¹)/(1 − a·z⁻¹)`,  `a = e^{−ts/τ}`,
/// `b₀ = K(1 − a^{1−f})`, `b₁ = K(a^{1−f} − a)`,
///
/// so `dᵢⱼ = z^{−(kᵢⱼ−kᵢᵢ)}·(b₀ᵢⱼ + b₁ᵢⱼz⁻¹)(1 − aᵢᵢz⁻¹) / ((b₀ᵢᵢ + b₁ᵢᵢz⁻¹)(1 −
/// aᵢⱼz⁻¹))`, the host design's ratio for these channels
/// (`msp::analysis::mimo::decoupler_design`). Errors where it is not
/// realizable: `kᵢⱼ < kᵢᵢ` (it would need an advance) or `|b₁ᵢᵢ/b₀ᵢᵢ| ≥ 1`
/// (the zero of `gᵢᵢ(z)` outside the unit circle: a fraction of a sample
/// above about one half).
pub fn fopdt_element<T: Real, S: AsRef<[T]> + AsMut<[T]>>(
    gij: &crate::model::Fopdt<T>,
    gii: &crate::model::Fopdt<T>,
    ts: T,
    storage: S,
) -> Result<Element<T, 2, S>, Error> {
    let (kij, aij, b0ij, b1ij) = sampled_fopdt(gij, ts)?;
    let (kii, aii, b0ii, b1ii) = sampled_fopdt(gii, ts)?;
    let delay = advance_free(kij, kii)?;
    let c = b1ii / b0ii;
    if !(c.abs() < T::one()) {
        return Err(Error::Unsupported(
            "decoupler: g_ii(z) has its zero outside the unit circle (a dead time's fraction above about half a sample): its inverse is unstable",
        ));
    }
    let num = [
        b0ij / b0ii,
        (b1ij - b0ij * aii) / b0ii,
        -(b1ij * aii) / b0ii,
    ];
    let den = [T::one(), c - aij, -(c * aij)];
    // whole samples of dead time in g_ii and g_ij: both end in 0, a common
    // factor z (the first-order block then)
    let block = if num[2] == T::zero() && den[2] == T::zero() {
        Lti::from_discrete_tf(&num[..2], &den[..2])?
    } else {
        Lti::from_discrete_tf(&num, &den)?
    };
    let line = Delay::with_storage(storage, delay)?;
    Ok(Element::new(block, line))
}

/// A channel `K e^{−θs}/(τs + 1)` sampled at `ts`: `(k, a, b₀, b₁)` of
/// [`fopdt_element`]'s `g(z)`, the fraction of a sample within 1e-9 of a
/// whole one taken as whole.
fn sampled_fopdt<T: Real>(g: &crate::model::Fopdt<T>, ts: T) -> Result<(T, T, T, T), Error> {
    let ts = crate::real::positive(ts, "ts")?;
    let d = crate::delay::samples(g.l, ts)?;
    let (mut k, mut f) = (d.floor(), d - d.floor());
    if f > T::one() - T::of(1e-9) {
        (k, f) = (k + T::one(), T::zero());
    }
    let a = (-ts / g.t).exp();
    let a1f = a.powf(T::one() - f);
    Ok((k, a, g.k * (T::one() - a1f), g.k * (a1f - a)))
}

/// `kᵢⱼ − kᵢᵢ`, or the error of an element that would need an advance.
fn advance_free<T: Real>(kij: T, kii: T) -> Result<T, Error> {
    if kij < kii {
        return Err(Error::Unsupported(
            "decoupler: g_ij answers sooner than g_ii (θij < θii): the element would need an advance",
        ));
    }
    Ok(kij - kii)
}

/// The whole samples of [`fopdt_element`]'s delay line for these channels
/// (the room its `storage` needs), with its errors.
pub fn fopdt_element_samples<T: Real>(
    gij: &crate::model::Fopdt<T>,
    gii: &crate::model::Fopdt<T>,
    ts: T,
) -> Result<usize, Error> {
    let d = advance_free(sampled_fopdt(gij, ts)?.0, sampled_fopdt(gii, ts)?.0)?;
    d.to_usize().ok_or(Error::DelayTooLong("delay"))
}
