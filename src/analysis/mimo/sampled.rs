//! The sampled multivariable loop: its stability verdict and its biggest
//! log modulus, from the exact sampled plant (each channel
//! [`DiscretePlant`]: ZOH with its own dead time) and the controllers' own
//! discrete responses.
//!
//! With loop `i`'s feedback path `cᵢ = Ncᵢ/Dcᵢ`
//! ([`crate::FrequencyResponse::feedback_parts`]) and an inverted decoupler
//! `D` (zero without one: `u = (I + D)⁻¹·v`, `vᵢ = −cᵢ·yᵢ`),
//!
//! `det(I + G·(I + D)⁻¹·C) = det(I + D + C·G)/det(I + D)`,
//!
//! and the characteristic function the generalized Nyquist criterion
//! counts is `Δ = det(diag(Dc)·(I + D) + diag(Nc)·G)` (row `i` multiplied
//! by `Dcᵢ`): its zeros outside the unit circle are the closed loop's
//! unstable poles, its poles there the blocks' (every channel's, every
//! element's, every controller's), so that the unstable closed-loop poles
//! number `P_open − W`, `W` the winding of `Δ(e^{jθ})` about the origin
//! (Maciejowski, *Multivariable Feedback Design* (1989) Sec. 2.9; the
//! single-loop equation of [`crate::analysis::stability`] is its `n = 1`).
//! The decoupler's own loop is stable when `det(I + D(e^{jθ}))` (its
//! elements stable) does not wind.
//!
//! The biggest log modulus is Luyben (1986)'s `Lcm = max 20·log10|W/(1 +
//! W)|`, `W = −1 + det(I + G·K)`, here over the sampled loop's frequencies
//! `0 < θ ≤ π`.

use core::ops::{Add, Div, Mul, Sub};
use std::vec::Vec;

use super::super::report::right_half_plane_poles;
use super::super::stability::from_characteristic;
use super::super::{DiscretePlant, Stability};
use super::{det, C64};
use crate::complex::Complex;
use crate::loop_controller::LoopController;
use crate::poly::TransferMatrix;

/// A decoupler's frequency response, as the analysis reads it.
pub trait Decoupling {
    /// `D(e^{jθ})`, row-major, zero on the diagonal.
    fn matrix(&self, theta: f64) -> Vec<C64>;
    /// How many of its elements' poles lie outside the unit circle.
    fn unstable(&self) -> usize;
    /// Its longest delay (samples) plus its order: how fast its phase turns.
    fn rate(&self) -> f64;
}

impl<const N: usize, const M: usize, S: AsRef<[f64]> + AsMut<[f64]>> Decoupling
    for crate::mimo::InvertedDecoupler<f64, N, M, S>
{
    fn matrix(&self, theta: f64) -> Vec<C64> {
        self.response(theta).into_iter().flatten().collect()
    }
    fn unstable(&self) -> usize {
        self.unstable_poles()
    }
    fn rate(&self) -> f64 {
        let mut r = 0.0f64;
        for i in 0..N {
            for j in 0..N {
                if let Some(e) = self.element(i, j) {
                    #[allow(clippy::cast_precision_loss)]
                    let o = e.order() as f64;
                    r = r.max(e.delay() + o);
                }
            }
        }
        r
    }
}

/// The decoupler's own loop `u = v − D·u` of an `n×n` plant: stable when
/// `det(I + D(e^{jθ}))` winds as many times as its elements have poles
/// outside the unit circle (none, as the design builds them).
pub fn decoupler_verdict(d: &dyn Decoupling, n: usize) -> Stability {
    let delta = |theta: f64| {
        let mut a = d.matrix(theta);
        for i in 0..n {
            if let Some(x) = a.get_mut(i * n + i) {
                *x = x.add(Complex::real(1.0));
            }
        }
        det(&a, n)
    };
    from_characteristic(&delta, d.unstable(), d.rate() + 16.0)
}

/// A multivariable loop as the analysis sees it: the plant sampled, each
/// loop's controller, and the decoupler if there is one.
pub struct SampledLoop<'a> {
    n: usize,
    plants: Vec<DiscretePlant>,
    loops: &'a [&'a dyn LoopController<f64>],
    decoupler: Option<&'a dyn Decoupling>,
    /// Open-loop poles outside the unit circle (`Err`: why they cannot be
    /// counted).
    open: Result<usize, std::string::String>,
    rate: f64,
}

impl<'a> SampledLoop<'a> {
    /// The loop of `loops` (loop `i` on output and input `i`) behind
    /// `decoupler` on `m` sampled at `ts`.
    pub fn new(
        m: &TransferMatrix,
        ts: f64,
        loops: &'a [&'a dyn LoopController<f64>],
        decoupler: Option<&'a dyn Decoupling>,
    ) -> Result<Self, crate::error::Error> {
        let n = m.size();
        if loops.len() != n {
            return Err(crate::error::Error::OutOfRange("one controller per loop"));
        }
        let mut plants = Vec::with_capacity(n * n);
        let mut open: Result<usize, std::string::String> = Ok(0);
        let mut rate = 16.0f64;
        for i in 0..n {
            for j in 0..n {
                let g = m
                    .get(i, j)
                    .ok_or(crate::error::Error::OutOfRange("the matrix's size"))?;
                plants.push(DiscretePlant::new(g, ts)?);
                open = open.and_then(|o| Ok(o + right_half_plane_poles(g)?));
                #[allow(clippy::cast_precision_loss)]
                let r = g.delay_samples(ts).unwrap_or(0.0) + g.order() as f64;
                rate = rate.max(r + 16.0);
            }
        }
        for c in loops {
            open = open.map(|o| o + c.unstable_poles());
            rate = rate.max(2.0 * c.dead_time().unwrap_or(0.0) + rate);
        }
        if let Some(d) = decoupler {
            open = open.map(|o| o + d.unstable());
            rate += d.rate();
        }
        Ok(SampledLoop {
            n,
            plants,
            loops,
            decoupler,
            open,
            rate,
        })
    }

    /// `G(e^{jθ})`, row-major.
    fn g(&self, theta: f64) -> Vec<C64> {
        self.plants.iter().map(|p| p.response(theta)).collect()
    }

    /// Each loop's `(Nc, Dc)` at `θ` (`None`: a controller without a response).
    fn parts(&self, theta: f64) -> Option<Vec<(C64, C64)>> {
        self.loops.iter().map(|c| c.feedback_parts(theta)).collect()
    }

    /// `I + D(e^{jθ})`, row-major.
    fn i_plus_d(&self, theta: f64) -> Vec<C64> {
        let n = self.n;
        let mut a = match self.decoupler {
            Some(d) => d.matrix(theta),
            None => std::vec![Complex::real(0.0); n * n],
        };
        for i in 0..n {
            if let Some(x) = a.get_mut(i * n + i) {
                *x = x.add(Complex::real(1.0));
            }
        }
        a
    }

    /// `Δ(e^{jθ}) = det(diag(Dc)·(I + D) + diag(Nc)·G)`.
    fn delta(&self, theta: f64) -> C64 {
        let n = self.n;
        let Some(parts) = self.parts(theta) else {
            return Complex::new(f64::NAN, f64::NAN);
        };
        let (g, id) = (self.g(theta), self.i_plus_d(theta));
        let mut m = Vec::with_capacity(n * n);
        for (i, (nc, dc)) in parts.iter().enumerate() {
            for j in 0..n {
                let at = i * n + j;
                let x = dc.mul(id.get(at).copied().unwrap_or_default());
                m.push(x.add(nc.mul(g.get(at).copied().unwrap_or_default())));
            }
        }
        det(&m, n)
    }

    /// The closed loop's stability verdict (the generalized Nyquist
    /// criterion on `Δ`; see the module documentation).
    pub fn verdict(&self) -> Stability {
        if self.parts(0.1).is_none() {
            return Stability::unknown("a loop's controller has no frequency response");
        }
        match &self.open {
            Ok(open) => from_characteristic(&|t| self.delta(t), *open, self.rate),
            Err(e) => Stability::unknown(e.clone()),
        }
    }

    /// The decoupler's own loop ([`decoupler_verdict`]); `None` without a
    /// decoupler.
    pub fn decoupler_verdict(&self) -> Option<Stability> {
        Some(decoupler_verdict(self.decoupler?, self.n))
    }

    /// `W(e^{jθ}) = −1 + det(I + G·K)`, `K = (I + D)⁻¹·C`.
    fn w(&self, theta: f64) -> C64 {
        let n = self.n;
        let Some(parts) = self.parts(theta) else {
            return Complex::new(f64::NAN, f64::NAN);
        };
        let (g, id) = (self.g(theta), self.i_plus_d(theta));
        let mut m = id.clone();
        for (i, (nc, dc)) in parts.iter().enumerate() {
            let c = nc.div(*dc);
            for j in 0..n {
                let at = i * n + j;
                if let (Some(x), Some(gij)) = (m.get_mut(at), g.get(at)) {
                    *x = x.add(c.mul(*gij));
                }
            }
        }
        det(&m, n).div(det(&id, n)).sub(Complex::real(1.0))
    }

    /// The biggest log modulus (dB) over `0 < θ ≤ π`: a grid fine enough
    /// for the fastest-turning term, the peak refined by golden section.
    pub fn lcm(&self) -> f64 {
        let lc = |theta: f64| {
            let w = self.w(theta);
            20.0 * w.div(w.add(Complex::real(1.0))).abs().log10()
        };
        super::peak(&lc, (1e-4f64).ln(), core::f64::consts::PI.ln())
    }
}
