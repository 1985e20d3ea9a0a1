//! The gain between the hypotheses, from the level test's fits.
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
    rss: &[T],
    drifts: &[T],
    (v_model, drift_model): (T, T),
) -> Option<Between<T>> {
    // the points in ascending `g`: the hypotheses below 1, the model, those
    // above
    let mut points = [(T::one(), v_model, drift_model); 8];
    let mut n = 0;
    let mut model_in = false;
    for ((&g, &v), &d) in factors.iter().zip(rss).zip(drifts) {
        if !model_in && g > T::one() {
            *points.get_mut(n)? = (T::one(), v_model, drift_model);
            n += 1;
            model_in = true;
        }
        *points.get_mut(n)? = (g, v, d);
        n += 1;
    }
    if !model_in {
        *points.get_mut(n)? = (T::one(), v_model, drift_model);
        n += 1;
    }
    let points = points.get(..n)?;
    let (low, _) = arg_min(points.iter().map(|p| p.1))?;
    let mid = low.clamp(1, n.checked_sub(2)?);
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
pub(super) struct Response<T> {
    pub(super) n: T,
    pub(super) measured: T,
    pub(super) energy: T,
    pub(super) v_ref: T,
    pub(super) v_dead: T,
    pub(super) rounded: bool,
}

impl<T: Real> Levels<T> {
    /// The gain between the hypotheses `b` on a response, weighed as a
    /// hypothesis is (`Estimator::levels_compare`: it explains the response
    /// to the noise, the response stands out of it, no drift, no other dead
    /// time explains it better, a misfit beyond the rounding), with one
    /// degree of freedom less and [`PENALTY`] for the gain it fits; its
    /// parabolas summed while its evidence is; proposed, with the gain at
    /// their lowest point within the hypotheses' range (`factors`), when
    /// its sum reaches [`LEVEL_EVIDENCE`], not on one response alone
    /// ([`REPLICATED`], as a hypothesis's: `enough`), and it explained the
    /// last two responses better than the model in use.
    pub(super) fn weigh_between<const G: usize>(
        &mut self,
        b: Between<T>,
        r: Response<T>,
        factors: [T; G],
    ) {
        // (three parameters: the load's two and the gain)
        let noise = Noise::new(r.n, T::of(3.0), r.measured, b.rss, r.energy);
        let sigma2 = noise.sigma2;
        let fits_ref = noise.fits(r.v_ref);
        let explains = noise.explains(b.rss, r.v_ref);
        let counts = (explains || fits_ref)
            && noise.seen(r.energy)
            && noise.steady(b.drift)
            && (b.rss < r.v_dead || fits_ref)
            && !(r.rounded && fits_ref)
            && sigma2 > T::zero();
        if !counts {
            return;
        }
        let (sum, streak) = self.between;
        let sum = page(sum, (r.v_ref - b.rss) / sigma2 - T::of(PENALTY));
        if sum.0 > T::zero() {
            for (g, &c) in self.gain.iter_mut().zip(&b.quad) {
                *g = *g + c / sigma2;
            }
        } else {
            self.gain = [T::zero(); 3];
        }
        let better = explains && !fits_ref;
        let streak = if better { streak.saturating_add(1) } else { 0 };
        self.between = (sum, streak);
        let proposed = enough(sum) && streak >= 2;
        let range = factors.first().zip(factors.last());
        let g = range
            .filter(|_| proposed)
            .and_then(|(&lo, &hi)| lowest(self.gain, lo, hi));
        // proposed as the nearest gain hypothesis, scaled
        let nearest = g.and_then(|g| {
            let (i, _) = arg_min(factors.iter().map(|&f| (f - g).abs()))?;
            Some((i, g / *factors.get(i)?))
        });
        self.gain_proposed = nearest.map(|(i, scale)| {
            let error = (at_least(r.v_ref - b.rss, T::zero()) / r.energy).sqrt();
            let evidence = sum.0;
            (i, scale, Mismatch { error, evidence })
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
        let b = between(factors, &rss, &drifts, (v(1.0), d(1.0))).expect_ok();
        let g = lowest(b.quad, 0.5, 2.0).expect_ok();
        assert!((g - 0.6).abs() < 1e-12, "{b:?}");
        assert!((b.rss - 0.2).abs() < 1e-12, "{b:?}");
        assert!((b.drift - d(0.6)).abs() < 1e-12, "{b:?}");
        // the sum of two responses' parabolas: their weighted lowest point
        let w = |g: f64| (g - 0.8) * (g - 0.8);
        let other = between(factors, &factors.map(w), &drifts, (w(1.0), d(1.0))).expect_ok();
        let sum = [0, 1, 2].map(|i| b.quad[i] + other.quad[i]);
        let g = lowest(sum, 0.5, 2.0).expect_ok();
        // 3(g − 0.6) + (g − 0.8) = 0
        assert!((g - 0.65).abs() < 1e-12, "{g}");
        // beyond the range: its end
        let far = |g: f64| (g - 3.0) * (g - 3.0);
        let end = between(factors, &factors.map(far), &drifts, (far(1.0), 0.0)).expect_ok();
        assert_eq!(end.rss, far(2.0));
        // not convex: none
        let cap = |g: f64| -g * g;
        assert!(between(factors, &factors.map(cap), &drifts, (cap(1.0), 0.0)).is_none());
    }
}
