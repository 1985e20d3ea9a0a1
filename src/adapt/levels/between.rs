//! The gain and the lag between the hypotheses, from the level test's fits.
//!
//! A gain hypothesis is the model in use with its input coefficients times
//! `g` (`[a, g·b0, g·b1]`, [`GAINS`]): from the response's start (state 0)
//! its simulation is `g` times the model's, `x_g = g·x`, and its residual
//! in levels `r_g = y − g·x` is affine in `g`. The load's least-squares fit
//! is a projection `P` that does not depend on `g` (its regressors `q`, the
//! constant and the drift's `p` share the model's pole `a`), so the
//! residual sum of squares `‖P(y − g·x)‖²` and the drift's share `z₃²/D₃`
//! (`z₃` linear in the residual's sums) are quadratics in `g`, exactly:
//! the model in use (`g = 1`) and the gain hypotheses are points on one
//! parabola, and three of them give it (Newton's divided differences), its
//! lowest point the least-squares gain of the response (the separable
//! least squares of Golub & Pereyra (1973): the linear parameter, here the
//! gain, eliminated in closed form). A change of the gain between two
//! hypotheses (0.6, between 0.5 and 0.7) is then fitted to the noise where
//! the nearer hypothesis leaves a misfit that no response takes as
//! evidence; summed over the responses taken as evidence (each divided by
//! the noise's variance, as the hypotheses' evidence is), the parabolas
//! give the gain the level test proposes with a gain hypothesis.
//!
//! The lag's residual is a parabola only near its lowest point: a lag
//! hypothesis moves the simulation's pole, `a^{1/l}`, not a multiple of it.
//! In the lag's logarithm, `ln l`, the hypotheses ([`LAGS`]: ½, ⅔, 4/3, 2)
//! lie symmetric about the model in use's 0, and a lag's step response
//! `1 − e^{−t/(lτ)}` moves alike for a like ratio either way (its
//! derivative in `ln l`, `−(t/lτ)·e^{−t/(lτ)}`, is one shape for every `l`),
//! so the parabola through the three nearest points (the interpolation of
//! Newton's divided differences, its error the third derivative's) is
//! fitted in `ln l`: measured on the bank, in `l` it put a doubled lag's
//! summed lowest point at 1.39 under 5 % noise and that model was applied
//! (the bank's lag ×2 at the coarse period 44 of 45 cases within 10 % of
//! the true model's IAE, one 1.33 times it), in `ln l` 45 of 45. Its
//! sum, its penalty and its streak are the gain's; a response counts in
//! the streak where the fit explains it better than the model in use by
//! more than the penalty (a loop that only loads move under 2 % noise has the model in use fit
//! most responses to the noise, and the gain's rule, a response the model
//! in use does not fit, never let a lag 1.6 times the model's be named
//! though its sum passed 150). Where a hypothesis is proposed too, the
//! factor is chosen over the nearest hypothesis when its summed parabolas
//! give it [`PENALTY`] over the hypothesis's own point (the factor is one
//! parameter over all the responses), over another hypothesis when its
//! sum is the larger. Measured on the bank (`docs/adapt-bank.md`): a lag
//! ×1.6 with loads only within 10 % of the true model's IAE in 81 of 90
//! cases, 68 before; with the set point moving at the coarse period 44 of
//! 45, 40 before.

use super::*;
use crate::real::arg_min;

/// A quadratic `c0 + c1·g + c2·g²`.
pub(super) type Quadratic<T> = [T; 3];

/// The gain between the hypotheses on one response: the residual sum of
/// squares and the drift's share at the parabola's lowest point (within the
/// hypotheses' range), and the residual's parabola.
#[derive(Debug, Clone, Copy)]
pub(super) struct Between<T> {
    pub(super) rss: T,
    pub(super) drift: T,
    pub(super) quad: Quadratic<T>,
}

/// The quadratic through three points `(g, v)` of distinct `g`.
fn through<T: Real>([(ga, va), (gb, vb), (gc, vc)]: [(T, T); 3]) -> Option<Quadratic<T>> {
    let fab = (vb - va) / (gb - ga);
    let fbc = (vc - vb) / (gc - gb);
    let c2 = (fbc - fab) / (gc - ga);
    let c1 = fab - c2 * (ga + gb);
    let c0 = va - fab * ga + c2 * ga * gb;
    let q = [c0, c1, c2];
    q.iter().all(|c| c.is_finite()).then_some(q)
}

/// `q` at `g`.
pub(super) fn at<T: Real>([c0, c1, c2]: Quadratic<T>, g: T) -> T {
    c0 + g * (c1 + g * c2)
}

/// The lowest point of `q` within `[lo, hi]` (`None`: not convex).
pub(super) fn lowest<T: Real>([_, c1, c2]: Quadratic<T>, lo: T, hi: T) -> Option<T> {
    (c2 > T::zero()).then(|| at_most(at_least(-c1 / (T::of(2.0) * c2), lo), hi))
}

/// The gain between the hypotheses on a response: `factors` the gain
/// hypotheses' (ascending), `rss` and `drifts` their fits', `model` the
/// model in use's fit `(rss, drift)`. The parabola through the lowest of
/// the five points and its two neighbours (the nearest: the least
/// rounding), its lowest point within the hypotheses' range.
pub(super) fn between<T: Real, const G: usize>(
    factors: [T; G],
    origin: T,
    rss: &[T],
    drifts: &[T],
    (v_model, drift_model): (T, T),
) -> Option<Between<T>> {
    // the points in ascending `g`: the hypotheses below the model's
    // `origin`, the model, those above
    let mut points = [(origin, v_model, drift_model); 8];
    let mut n = 0;
    let mut model_in = false;
    for ((&g, &v), &d) in factors.iter().zip(rss).zip(drifts) {
        if !model_in && g > origin {
            *points.get_mut(n)? = (origin, v_model, drift_model);
            n += 1;
            model_in = true;
        }
        *points.get_mut(n)? = (g, v, d);
        n += 1;
    }
    if !model_in {
        *points.get_mut(n)? = (origin, v_model, drift_model);
        n += 1;
    }
    let points = points.get(..n)?;
    let (low, _) = arg_min(points.iter().map(|p| p.1))?;
    // (`max`/`min`, not `clamp`: three points at least, and no panic
    // where there are fewer)
    let mid = low.min(n.checked_sub(2)?).max(1);
    if mid + 1 >= n {
        return None;
    }
    let [a, b, c] = [points.get(mid - 1)?, points.get(mid)?, points.get(mid + 1)?];
    let quad = through([(a.0, a.1), (b.0, b.1), (c.0, c.1)])?;
    let drift = through([(a.0, a.2), (b.0, b.2), (c.0, c.2)])?;
    let (first, last) = (points.first()?.0, points.last()?.0);
    let g = lowest(quad, first, last)?;
    Some(Between {
        rss: at_least(at(quad, g), T::zero()),
        drift: at_least(at(drift, g), T::zero()),
        quad,
    })
}

/// The evidence a response's gain between must show beyond the model in
/// use's, in units of the noise's variance: the fitted gain is one more
/// parameter, and on a response the model in use explains its residual's
/// reduction is `χ²` with one degree of freedom (mean 1; beyond 4, two
/// standard deviations, 5 responses in 100). Page's sum of the excess
/// (Basseville & Nikiforov (1993) Sec. 2.2) then rests at zero while
/// nothing changed.
const PENALTY: f64 = 4.0;

/// What the level test measured on a response, for the gain between: its
/// samples, the noise's variance measured, the measurement's energy about
/// its mean, the model in use's residual and the other dead times' best,
/// whether the rounding is the noise.
#[derive(Debug, Clone, Copy)]
pub(super) struct Response<T> {
    pub(super) n: T,
    pub(super) measured: T,
    pub(super) energy: T,
    pub(super) v_ref: T,
    pub(super) v_dead: T,
    pub(super) rounded: bool,
}

/// The kinds of factor fitted between the hypotheses: the gain, the lag.
pub(super) const KINDS: usize = 2;

/// A factor the level test proposes between its hypotheses.
#[derive(Debug, Clone, Copy)]
pub(in crate::adapt) struct Proposed<T> {
    /// The nearest hypothesis.
    pub(in crate::adapt) i: usize,
    /// The factor from its gain or lag to the one proposed.
    pub(in crate::adapt) scale: T,
    /// The evidence for the factor proposed over the nearest hypothesis
    /// itself on the responses summed: their parabolas' sum at the
    /// hypothesis less at the lowest point.
    pub(in crate::adapt) beyond: T,
    /// The model in use's mismatch on the last response.
    pub(in crate::adapt) mismatch: Mismatch<T>,
}

/// The lag hypotheses' factors' logarithms (`ln` of [`LAGS`]): the lag's
/// coordinate, in which they are symmetric about the model in use's 0.
const LOG_LAGS: [f64; LAGS.len()] = [
    -core::f64::consts::LN_2,
    -0.405_465_108_108_164_4,
    0.287_682_072_451_780_9,
    core::f64::consts::LN_2,
];

/// The gain and the lag between the hypotheses on a response (`None`
/// where there are too few points: an integrating model has no lag), from
/// the gain hypotheses' fits (`factors` theirs) and the lag hypotheses'
/// (the rest of `rss`, `drifts`; [`LAGS`]), `model` the model in use's fit;
/// the lag's in its logarithm ([`LOG_LAGS`]: see the module documentation).
pub(super) fn betweens<'a, T: Real>(
    factors: [T; GAINS.len()],
    rss: &'a [T],
    drifts: &'a [T],
    model: (T, T),
) -> [Option<Between<T>>; KINDS] {
    let part = |x: &'a [T]| x.split_at_checked(GAINS.len()).unwrap_or((x, &[]));
    let ((g_rss, l_rss), (g_drifts, l_drifts)) = (part(rss), part(drifts));
    let gain = between(factors, T::one(), g_rss, g_drifts, model);
    let lag = between(LOG_LAGS.map(T::of), T::zero(), l_rss, l_drifts, model);
    [gain, lag]
}

/// A response's gain and lag between the hypotheses, to be weighed in a
/// call of their own ([`Levels::weigh_betweens`]): what it measured, and
/// the gain hypotheses' factors.
#[derive(Debug, Clone, Copy)]
pub(super) struct Weigh<T> {
    pub(super) betweens: [Option<Between<T>>; KINDS],
    pub(super) response: Response<T>,
    pub(super) factors: [T; GAINS.len()],
}

impl<T: Real> Levels<T> {
    /// The gain and the lag between the hypotheses ([`betweens`]) weighed
    /// on a response ([`Levels::weigh_between`]), each by its own sum.
    pub(super) fn weigh_betweens(&mut self, w: Weigh<T>) {
        let Weigh {
            betweens,
            response: r,
            factors,
        } = w;
        let lags = LOG_LAGS.map(T::of);
        let kinds: [(&[T], usize); KINDS] = [(&factors, 0), (&lags, GAINS.len())];
        for (k, (b, (coords, first))) in betweens.into_iter().zip(kinds).enumerate() {
            if let Some(b) = b {
                self.weigh_between(k, b, &r, coords, first);
            }
        }
    }

    /// The factor between the hypotheses proposed, where it explains the
    /// data better than the hypothesis proposed: the nearest one's own
    /// with [`PENALTY`] of evidence beyond it (the factor is one parameter
    /// more over the responses summed; a lag twice the model's is that
    /// hypothesis, not a factor a little off it), another one's with more
    /// evidence (the factor's net of its penalty per response).
    pub(super) fn between_choice(&self) -> Option<Proposed<T>> {
        // (of the gain's and the lag's, the one with the more evidence)
        let p = match self.between_proposed {
            [Some(g), Some(l)] if l.mismatch.evidence > g.mismatch.evidence => l,
            [Some(g), _] => g,
            [None, l] => l?,
        };
        let chosen = match self.proposal {
            Some((h, _)) if h == p.i => p.beyond >= T::of(PENALTY),
            Some((_, m)) => p.mismatch.evidence > m.evidence,
            None => true,
        };
        chosen.then_some(p)
    }

    /// The factor of kind `k` (0 the gain, 1 the lag) between the
    /// hypotheses `factors` (ascending; the first of them the hypothesis
    /// `first`) on a response, weighed as a hypothesis is
    /// (`Estimator::levels_compare`: it explains the response to the
    /// noise, the response stands out of it, no drift, no other dead time
    /// explains it better, a misfit beyond the rounding), with one degree of
    /// freedom less and [`PENALTY`] for the factor it fits; its parabolas
    /// summed while its evidence is; proposed, with the factor at their
    /// lowest point within the hypotheses' range, when its sum reaches
    /// [`LEVEL_EVIDENCE`], not on one response alone ([`REPLICATED`], as a
    /// hypothesis's: `enough`), and it explained the last two responses
    /// better than the model in use, by more than the penalty.
    fn weigh_between(
        &mut self,
        k: usize,
        b: Between<T>,
        r: &Response<T>,
        coords: &[T],
        first: usize,
    ) {
        // (three parameters: the load's two and the factor)
        let noise = Noise::new(r.n, T::of(3.0), r.measured, b.rss, r.energy).undithered(r.rounded);
        let sigma2 = noise.sigma2;
        let fits_ref = noise.fits(r.v_ref);
        let explains = noise.explains(b.rss, r.v_ref);
        let counts = (explains || fits_ref)
            && noise.seen(r.energy)
            && noise.steady(b.drift)
            && (b.rss < r.v_dead || fits_ref)
            && !(r.rounded && fits_ref)
            && sigma2 > T::zero();
        let (Some(state), Some(quad), Some(proposed)) = (
            self.between.get_mut(k),
            self.quads.get_mut(k),
            self.between_proposed.get_mut(k),
        ) else {
            return;
        };
        if !counts {
            return;
        }
        let (sum, streak) = *state;
        let sum = page(sum, (r.v_ref - b.rss) / sigma2 - T::of(PENALTY));
        if sum.0 > T::zero() {
            for (g, &c) in quad.iter_mut().zip(&b.quad) {
                *g = *g + c / sigma2;
            }
        } else {
            *quad = [T::zero(); 3];
        }
        // (to the noise and by more than the penalty: the parabola's lowest
        // point is hardly ever above the model in use's own)
        let better = noise.better(b.rss, r.v_ref) && r.v_ref - b.rss > T::of(PENALTY) * sigma2;
        let streak = if better { streak.saturating_add(1) } else { 0 };
        *state = (sum, streak);
        let range = coords.first().zip(coords.last());
        let x = range
            .filter(|_| enough(sum) && streak >= 2)
            .and_then(|(&lo, &hi)| lowest(*quad, lo, hi));
        // proposed as the nearest hypothesis, scaled (the gain's factor its
        // coordinate, the lag's the coordinate's exponential)
        let nearest = x.and_then(|x| {
            let (i, _) = arg_min(coords.iter().map(|&c| (c - x).abs()))?;
            let c = *coords.get(i)?;
            let scale = if k == 0 { x / c } else { (x - c).exp() };
            Some((first + i, scale, at(*quad, c) - at(*quad, x)))
        });
        *proposed = nearest.map(|(i, scale, beyond)| {
            let error = (at_least(r.v_ref - b.rss, T::zero()) / r.energy).sqrt();
            let evidence = sum.0;
            let mismatch = Mismatch { error, evidence };
            Proposed {
                i,
                scale,
                beyond,
                mismatch,
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::ExpectOk;

    /// Points of `v(g) = 3·(g − 0.6)² + 0.2`, `drift(g) = (g − 0.9)²`: the
    /// lowest point 0.6 and its values, from whichever three are nearest.
    #[test]
    fn a_parabola_through_the_hypotheses_has_its_lowest_point_between_them() {
        let v = |g: f64| 3.0 * (g - 0.6) * (g - 0.6) + 0.2;
        let d = |g: f64| (g - 0.9) * (g - 0.9);
        let factors = GAINS;
        let rss = factors.map(v);
        let drifts = factors.map(d);
        let b = between(factors, 1.0, &rss, &drifts, (v(1.0), d(1.0))).expect_ok();
        let g = lowest(b.quad, 0.5, 2.0).expect_ok();
        assert!((g - 0.6).abs() < 1e-12, "{b:?}");
        assert!((b.rss - 0.2).abs() < 1e-12, "{b:?}");
        assert!((b.drift - d(0.6)).abs() < 1e-12, "{b:?}");
        // the sum of two responses' parabolas: their weighted lowest point
        let w = |g: f64| (g - 0.8) * (g - 0.8);
        let other = between(factors, 1.0, &factors.map(w), &drifts, (w(1.0), d(1.0))).expect_ok();
        let sum = [0, 1, 2].map(|i| b.quad[i] + other.quad[i]);
        let g = lowest(sum, 0.5, 2.0).expect_ok();
        // 3(g − 0.6) + (g − 0.8) = 0
        assert!((g - 0.65).abs() < 1e-12, "{g}");
        // beyond the range: its end
        let far = |g: f64| (g - 3.0) * (g - 3.0);
        let end = between(factors, 1.0, &factors.map(far), &drifts, (far(1.0), 0.0)).expect_ok();
        assert_eq!(end.rss, far(2.0));
        // not convex: none
        let cap = |g: f64| -g * g;
        assert!(between(factors, 1.0, &factors.map(cap), &drifts, (cap(1.0), 0.0)).is_none());
    }

    /// The lag's residual as a parabola in `ln l` with its lowest point at
    /// a lag 1.6 times the model's (between the hypotheses 4/3 and 2): the
    /// gain's points beside it (lowest at 0.6) do not move it, and the lag
    /// read back from the log coordinate is 1.6; an integrating model's
    /// (no lag hypotheses) has none.
    #[test]
    fn the_lag_between_is_fitted_in_its_logarithm() {
        let v = |x: f64| 2.0 * (x - 1.6f64.ln()).powi(2) + 0.1;
        let g = |g: f64| 3.0 * (g - 0.6) * (g - 0.6) + 0.2;
        let rss: Vec<f64> = GAINS.map(g).into_iter().chain(LOG_LAGS.map(v)).collect();
        let drifts = [0.0; HYPOTHESES];
        // (the model in use's point: one fit, at each coordinate's origin)
        let [gain, lag] = betweens(GAINS, &rss, &drifts, (v(0.0), 0.0));
        let lag = lag.expect_ok();
        let x = lowest(lag.quad, LOG_LAGS[0], LOG_LAGS[3]).expect_ok();
        assert!((x.exp() - 1.6).abs() < 1e-12, "{x}");
        assert!((lag.rss - 0.1).abs() < 1e-12, "{lag:?}");
        assert!(gain.is_some());
        let [_, none] = betweens(
            GAINS,
            &rss[..GAINS.len()],
            &drifts[..GAINS.len()],
            (0.0, 0.0),
        );
        assert!(none.is_none());
    }
}
