//! The stability verdict of a sampled loop, proven from its characteristic
//! equation and cross-checked by a simulation.
//!
//! The loop the simulator runs — the plant's exact ZOH equivalent with its
//! dead time as delay samples, the controller's blocks and delay lines — is a
//! finite-dimensional discrete system. Write the controller's feedback path
//! as `Cy = Nc/Dc` ([`crate::FrequencyResponse::feedback_parts`]: `Dc` is the
//! determinant of the controller's own loops) and the process as
//! `P = Np/Dp` (`Dp = 1` for a plant, the inner IMC loop's determinant for a
//! cascade). Then
//!
//! `χ(z) = Δ(z)·∏ᵢ Dᵢ(z)`,  `Δ = Dc·Dp + Nc·Np`,
//!
//! is the closed loop's characteristic polynomial, `Dᵢ` the denominators of
//! the blocks (each block's poles appear in `Δ` at most once, and `Δ(∞) ≠ 0`
//! since every loop passes through a delay of at least one sample). By the
//! argument principle on the unit circle — indented outwards around
//! `z = 1`, so integrators count as inside — the winding number of `Δ`
//! about the origin is `W = Z_in(χ) − Σ (deg Dᵢ − Pᵢ)`, `Pᵢ` the poles of
//! block `i` outside the circle. All `deg χ = Σ deg Dᵢ` roots of `χ` lie
//! inside exactly when
//!
//! `W = P_open = Σ Pᵢ`  (the plant's unstable poles plus the controller's),
//!
//! and `P_open − W` is the number of closed-loop poles outside (the discrete
//! Nyquist criterion; Åström & Wittenmark, Computer-Controlled Systems
//! (1997) Sec. 3.4, written for the return difference `1 + L = Δ/(Dc·Dp)`). An unstable mode
//! that cancels in `Cy` (a Smith predictor on an unstable plant) is not lost:
//! its block still counts in `P_open` while `Δ` no longer winds for it, so the
//! loop is declared unstable, as it is.
//!
//! `W` is found by following the phase of `Δ(e^{jθ})` from `θ₀ → 0⁺` to `π`
//! (the other half is its mirror image), in steps that never turn by more
//! than an eighth of a turn, refined where the phase moves fast; the order
//! `m` of the pole (or zero) of `Δ` at `z = 1` is read from the slope of
//! `ln|Δ|` as `θ → 0`, and the indentation adds `−m·π`. When a step cannot
//! be resolved (a closed-loop pole on the circle, to working precision) or
//! `W` is not an integer, the verdict is *unknown*, with the reason.

use core::ops::{Add, Mul};
use std::string::String;

use crate::complex::Complex;

/// The loop's stability verdict, what decided it, and the simulation's
/// cross-check. `msp run`, `tune`, `margins`, `compare`, `sweep`, `autotune`
/// and Python print it under these names.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Stability {
    /// `true`: every closed-loop pole is inside the unit circle (or at
    /// `z = 1`: the loop comes to rest, maybe off its set point); `false`:
    /// at least one is outside; `None`: it could not be decided (`reason`).
    pub stable: Option<bool>,
    /// Closed-loop poles outside the unit circle (the characteristic equation's count).
    pub unstable_poles: Option<usize>,
    /// Open-loop poles outside the unit circle: the plant's and the controller's blocks'.
    pub open_loop_unstable_poles: Option<usize>,
    /// The simulation's cross-check: `true` when the simulated loop stayed
    /// bounded and came to rest, `false` when it diverged or kept moving,
    /// `None` when no simulation was compared.
    pub simulation: Option<bool>,
    /// When the run changed the loop (s: a process drift, a retune, an
    /// adapted model): the verdict is the loop's as built, and the
    /// simulation is compared up to then; `None`: the loop the run ends
    /// with is the one analysed.
    pub as_built_until: Option<f64>,
    /// In words: how the verdict was reached, or why it is unknown, and any
    /// disagreement with the simulation.
    pub reason: String,
}

impl Stability {
    /// A verdict that could not be reached, with the reason.
    pub fn unknown(reason: impl Into<String>) -> Self {
        Stability {
            reason: reason.into(),
            ..Stability::default()
        }
    }

    /// The verdict cross-checked with a simulation that came to rest
    /// (`settled`) or not. When they disagree the mathematics decides and the
    /// reason says what the simulation showed; without a mathematical verdict
    /// the simulation's is reported as that and no more.
    pub fn with_simulation(mut self, settled: bool, span: f64) -> Self {
        self.simulation = Some(settled);
        let span = crate::poly::fmt_num(crate::poly::round_sig(span, 3));
        match self.stable {
            Some(s) if s != settled => {
                self.reason.push_str(&std::format!(
                    "; the simulation over {span} s disagrees ({}): {}",
                    if settled { "it stayed bounded and settled" } else { "it did not settle" },
                    if s {
                        "a slow or lightly damped loop, an actuator limit or an operator event can keep it moving; the characteristic equation decides stability"
                    } else {
                        "an unstable mode that grows slowly, or one the run did not excite, can stay hidden in a finite run; the characteristic equation decides stability"
                    }
                ));
            }
            Some(_) => self
                .reason
                .push_str(&std::format!("; the simulation over {span} s agrees")),
            None => self.reason.push_str(&std::format!(
                "; the simulation over {span} s {} (not a proof)",
                if settled {
                    "stayed bounded and settled"
                } else {
                    "did not settle"
                }
            )),
        }
        self
    }

    /// The verdict of the loop as built, for a run in which it changes at
    /// `at` s (`what`: a process drift, a retune, an adapted model): it
    /// says so, and the simulation cross-checks it up to then (`settled`:
    /// whether it had come to rest by `at`; `None`: too short a stretch to
    /// compare); the loop after the change is not covered.
    pub fn as_built(self, settled: Option<bool>, at: f64, what: &str) -> Self {
        let mut s = match settled {
            Some(settled) => self.with_simulation(settled, at),
            None => self,
        };
        s.as_built_until = Some(at);
        let at = crate::poly::fmt_num(crate::poly::round_sig(at, 3));
        s.reason.push_str(&std::format!(
            "; this is the loop as built: at {at} s {what}, and the verdict does not cover the loop after that"
        ));
        s
    }

    /// The verdict in a few words, for text output.
    pub fn summary(&self) -> &'static str {
        match self.stable {
            Some(true) => "stable",
            Some(false) => "UNSTABLE",
            None => "unknown",
        }
    }
}

/// The winding number of `f(e^{jθ})` (a real-coefficient rational function:
/// `f(e^{−jθ}) = conj f(e^{jθ})`) about the origin, on the unit circle
/// indented outwards around `z = 1`. `rate` bounds how fast the phase of
/// `f`'s terms turns (rad per rad of `θ`: the longest delay in samples,
/// plus the order), which sets the initial step.
fn winding(f: &dyn Fn(f64) -> Complex<f64>, rate: f64) -> Result<i64, String> {
    let rate = rate.max(1.0);
    let ln = |theta: f64| f(theta).abs().ln();
    // the order m of f's pole at z = 1 (negative: a zero): |f| ~ θ^{−m}
    let mut theta0 = (1e-3 / rate).min(1e-4);
    let mut order = None;
    for _ in 0..8 {
        let a = (ln(theta0 / 4.0) - ln(theta0)) / 4f64.ln();
        let b = (ln(theta0 / 16.0) - ln(theta0 / 4.0)) / 4f64.ln();
        if a.is_finite() && b.is_finite() && (a - b).abs() < 0.05 && (b - b.round()).abs() < 0.05 {
            #[allow(clippy::cast_possible_truncation)]
            let m = b.round() as i64;
            order = Some(m);
            break;
        }
        theta0 /= 16.0;
        if theta0 < 1e-14 {
            break;
        }
    }
    let m = order.ok_or_else(|| {
        String::from("the loop's behaviour at zero frequency could not be resolved")
    })?;
    let pi = core::f64::consts::PI;
    // a delay term of `rate` samples turns by half a radian per step (29°,
    // within the 45° that `follow` accepts without halving)
    let step = (0.5 / rate).min(0.05);
    let mut turned = 0.0;
    let mut a = theta0;
    let mut fa = f(a);
    if !(fa.re.is_finite() && fa.im.is_finite()) || fa.abs() == 0.0 {
        return Err(String::from(
            "the loop's response is not finite near zero frequency",
        ));
    }
    while a < pi {
        let b = (a * 1.05).min(a + step).min(pi);
        let fb = f(b);
        turned += follow(f, a, fa, b, fb, 0).map_err(|lost| match lost {
            Lost::NotFinite(b) => std::format!(
                "the characteristic equation is not finite at {b:.6e} rad/sample (a closed-loop pole on the unit circle)"
            ),
            Lost::Unresolved(b) => std::format!(
                "a closed-loop pole lies on the unit circle at {b:.6} rad/sample, to working precision: the loop is at the stability limit"
            ),
        })?;
        (a, fa) = (b, fb);
    }
    if fa.im.abs() > 1e-6 * fa.abs() {
        return Err(String::from(
            "the loop has a pole at the Nyquist frequency (z = −1)",
        ));
    }
    // the mirror half doubles the turn; the outward indentation around z = 1
    // turns by −m·π
    #[allow(clippy::cast_precision_loss)]
    let total = 2.0 * turned - m as f64 * pi;
    let w = total / (2.0 * pi);
    if (w - w.round()).abs() > 0.1 {
        return Err(std::format!(
            "the phase of the characteristic equation did not close ({w:.3} turns)"
        ));
    }
    #[allow(clippy::cast_possible_truncation)]
    Ok(w.round() as i64)
}

/// Where [`follow`] could not follow the phase: `f` not finite (or zero)
/// at this point, or a turn not resolved there to working precision (a
/// root of `f` on the path).
#[derive(Debug, Clone, Copy)]
pub(super) enum Lost {
    NotFinite(f64),
    Unresolved(f64),
}

/// The phase turned by `f` from `a` to `b`, halving the step where it turns
/// by more than an eighth of a turn.
pub(super) fn follow(
    f: &dyn Fn(f64) -> Complex<f64>,
    a: f64,
    fa: Complex<f64>,
    b: f64,
    fb: Complex<f64>,
    depth: u32,
) -> Result<f64, Lost> {
    if !(fb.re.is_finite() && fb.im.is_finite()) || fb.abs() == 0.0 {
        return Err(Lost::NotFinite(b));
    }
    // the angle from fa to fb: arg(fb·conj(fa)), scaled to unit length
    // first only where the product would leave the floating-point range
    let d = turn(fa, fb);
    if d.abs() <= core::f64::consts::FRAC_PI_4 {
        return Ok(d);
    }
    if depth >= 40 || b - a <= 4.0 * f64::EPSILON * b {
        return Err(Lost::Unresolved(b));
    }
    let c = 0.5 * (a + b);
    let fc = f(c);
    Ok(follow(f, a, fa, c, fc, depth + 1)? + follow(f, c, fc, b, fb, depth + 1)?)
}

/// The angle from `fa` to `fb`, in `(−π, π]`.
pub(super) fn turn(fa: Complex<f64>, fb: Complex<f64>) -> f64 {
    let product = fb.mul(fa.conj());
    if product.re.is_finite() && product.im.is_finite() && product.abs() > 1e-280 {
        product.arg()
    } else {
        let unit = |c: Complex<f64>| c.scale(1.0 / c.abs());
        unit(fb).mul(unit(fa).conj()).arg()
    }
}

/// The verdict for a controller whose feedback path is `Cy = Nc/Dc`
/// (`parts(θ) = (Nc, Dc)`, `None` where it has no response) on a process
/// `P = Np/Dp` (`process(θ) = (Np, Dp)`) at `z = e^{jθ}`: `open` is the
/// number of block poles outside the unit circle (the plant's and the
/// controller's), `rate` the longest delay in samples of the loop plus its
/// order.
pub fn verdict(
    parts: &dyn Fn(f64) -> Option<(Complex<f64>, Complex<f64>)>,
    process: &dyn Fn(f64) -> (Complex<f64>, Complex<f64>),
    open: usize,
    rate: f64,
) -> Stability {
    let delta = |theta: f64| match parts(theta) {
        Some((nc, dc)) => {
            let (np, dp) = process(theta);
            dc.mul(dp).add(nc.mul(np))
        }
        None => Complex::new(f64::NAN, f64::NAN),
    };
    if parts(0.1).is_none() {
        return Stability::unknown("this controller has no frequency response");
    }
    from_characteristic(&delta, open, rate)
}

/// The verdict from the characteristic function `delta(θ)` at `z = e^{jθ}`
/// (the return difference times the controller's determinants: its zeros
/// outside the unit circle are the closed loop's unstable poles, its poles
/// there the `open` unstable poles of the blocks), `rate` as in
/// [`verdict`]: the single-loop equation, or a multivariable loop's
/// determinant ([`crate::analysis::mimo`]).
pub(crate) fn from_characteristic(
    delta: &dyn Fn(f64) -> Complex<f64>,
    open: usize,
    rate: f64,
) -> Stability {
    match winding(delta, rate) {
        Ok(turns) => {
            let open_i = i64::try_from(open).unwrap_or(i64::MAX);
            let outside = open_i - turns;
            if outside < 0 {
                return Stability {
                    open_loop_unstable_poles: Some(open),
                    ..Stability::unknown(std::format!(
                        "the characteristic equation winds {turns} times for {open} open-loop unstable poles: the count is inconsistent"
                    ))
                };
            }
            let n = usize::try_from(outside).unwrap_or(usize::MAX);
            Stability {
                stable: Some(n == 0),
                unstable_poles: Some(n),
                open_loop_unstable_poles: Some(open),
                simulation: None,
                as_built_until: None,
                reason: if n == 0 {
                    std::format!(
                        "every closed-loop pole is inside the unit circle (characteristic equation: {open} open-loop unstable pole{}, encircled as many times)",
                        if open == 1 { "" } else { "s" }
                    )
                } else {
                    std::format!(
                        "{n} closed-loop pole{} outside the unit circle (characteristic equation)",
                        if n == 1 { " lies" } else { "s lie" }
                    )
                },
            }
        }
        Err(reason) => Stability {
            open_loop_unstable_poles: Some(open),
            ..Stability::unknown(reason)
        },
    }
}
