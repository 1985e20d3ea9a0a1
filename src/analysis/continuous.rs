//! The stability verdict of a continuous loop `L(s) = k·N(s)/D(s)·e^{−θs}`
//! (the plant alone or behind a pure gain: `msp margins --continuous`),
//! from its characteristic equation with the exact delay.
//!
//! The Nyquist criterion on the contour up the imaginary axis, round the
//! poles of `L` at the origin on small semicircles to their right, and
//! back through the right half plane: with `P` the poles of `L` in the
//! open right half plane and `N` the counter-clockwise turns of `1 + L`
//! about the origin along it, `Z = P − N` closed-loop poles lie in the
//! right half plane. `1 + L(−jω)` is the conjugate of `1 + L(jω)`, so the
//! contour is twice the positive half: from `ω₀` (on the semicircle's end)
//! to `ω_e`, where `|L|` has fallen below `1` for good; a pole of order
//! `m` at the origin turns `L` by `−m·π` on the semicircle, and the return
//! through the right half plane, where `|e^{−θs}| ≤ 1` and `|L|` stays
//! below one, turns `1 + L` back to its mirror image by `−2·arg(1 + L(jω_e))`
//! without winding (Åström & Murray (2008) Sec. 9.2; with a delay,
//! Åström & Hägglund (2006) Sec. 4.6). A plant with direct feedthrough
//! and a delay is a neutral system: with `|k·D| > 1` it has infinitely
//! many closed-loop poles in the right half plane (Hale & Verduyn Lunel
//! (1993) Sec. 9.5), with `|k·D| < 1` the criterion holds as above.
//!
//! Along the axis `1 + L` is followed where `|L|` is between `0.4` and
//! `2.5`; where `|L|` is smaller, `1 + L` stays in the disc of radius `0.4`
//! about `1` and cannot wind; where it is larger, `arg(1 + L) = arg L +
//! arg(1 + 1/L)`, the first exact from the poles, zeros and delay, the
//! second within that disc again. So a long delay costs steps only near
//! the crossover.

use core::ops::{Add, Div, Sub};
use std::string::String;
use std::vec::Vec;

use super::stability::{follow, turn, Lost, Stability};
use crate::complex::Complex;
use crate::poly::{poly_roots, trim, TransferFunction};

/// The poles, zeros and gain of `k·G`, and how it is followed.
struct Loop {
    plant: TransferFunction,
    num: Vec<f64>,
    den: Vec<f64>,
    k: f64,
    delay: f64,
    zeros: Vec<(f64, f64)>,
    poles: Vec<(f64, f64)>,
}

impl Loop {
    /// `L(jω)`: the plant's own frequency response, times the gain.
    fn at(&self, w: f64) -> Complex<f64> {
        let (re, im) = self.plant.freq(w);
        Complex::new(re, im).scale(self.k)
    }

    /// The continuous phase of `L(jω)` for `ω > 0`: each pole's and zero's
    /// angle `arg(jω − p)` followed without a jump, the gain's sign, the
    /// delay's `−ωθ`.
    fn phase(&self, w: f64) -> f64 {
        let pi = core::f64::consts::PI;
        let angle = |(re, im): &(f64, f64)| {
            let y = w - im;
            if *re < 0.0 {
                (y / -re).atan()
            } else if *re > 0.0 {
                pi - (y / re).atan()
            } else {
                // on the axis: the origin's (a point elsewhere on it is
                // crossed only where `L` is 0 or refused)
                y.signum() * pi / 2.0
            }
        };
        let lead = self.k * self.num.first().copied().unwrap_or(1.0)
            / self.den.first().copied().unwrap_or(1.0);
        let sign = if lead < 0.0 { pi } else { 0.0 };
        self.zeros.iter().map(angle).sum::<f64>() - self.poles.iter().map(angle).sum::<f64>() + sign
            - w * self.delay
    }
}

/// The verdict of the continuous loop `k·G(s)` in unit feedback.
pub fn continuous_verdict(plant: &TransferFunction, k: f64) -> Stability {
    let num = trim(&plant.num);
    let den = trim(&plant.den);
    if plant.delay > 0.0 && !num.is_empty() && num.len() == den.len() {
        let direct =
            (k * num.first().copied().unwrap_or(0.0) / den.first().copied().unwrap_or(1.0)).abs();
        if direct > 1.0 + 1e-12 {
            return Stability {
                stable: Some(false),
                reason: std::format!(
                    "the loop's direct feedthrough |k·D| = {direct:.4} behind a delay makes a neutral system with infinitely many closed-loop poles in the right half plane"
                ),
                ..Stability::default()
            };
        }
        if direct >= 1.0 - 1e-12 {
            return Stability::unknown(
                "the loop's direct feedthrough |k·D| = 1 behind a delay: a neutral system at its stability limit",
            );
        }
    }
    match count(plant, k) {
        Ok((z, p)) => Stability {
            stable: Some(z == 0),
            unstable_poles: Some(z),
            open_loop_unstable_poles: Some(p),
            simulation: None,
            as_built_until: None,
            reason: if z == 0 {
                std::format!(
                    "every closed-loop pole is in the left half plane (the continuous characteristic equation 1 + L(s) = 0 with the exact delay: {p} open-loop unstable pole{}, encircled as many times)",
                    if p == 1 { "" } else { "s" }
                )
            } else {
                std::format!(
                    "{z} closed-loop pole{} in the right half plane (the continuous characteristic equation with the exact delay)",
                    if z == 1 { " lies" } else { "s lie" }
                )
            },
        },
        Err(reason) => Stability::unknown(reason),
    }
}

/// `(Z, P)`: closed-loop poles in the right half plane, open-loop ones.
fn count(plant: &TransferFunction, k: f64) -> Result<(usize, usize), String> {
    let num = trim(&plant.num);
    let den = trim(&plant.den);
    if !k.is_finite() || k == 0.0 || num.iter().all(|c| *c == 0.0) {
        return Err(String::from("the loop gain is zero or not finite"));
    }
    if num.len() > den.len() {
        return Err(String::from(
            "the loop is improper (more zeros than poles): it has no continuous verdict",
        ));
    }
    let lost =
        |e: crate::error::Error| std::format!("the loop's poles and zeros could not be found: {e}");
    let l = Loop {
        plant: plant.clone(),
        zeros: poly_roots(&num).map_err(lost)?,
        poles: poly_roots(&den).map_err(lost)?,
        num,
        den,
        k,
        delay: plant.delay,
    };
    // poles: in the open right half plane; at the origin (the order of the
    // indentation, less the zeros there); elsewhere on the axis: refused
    let mut open = 0usize;
    let mut origin = 0i64;
    for (re, im) in &l.poles {
        let size = re.hypot(*im);
        if size == 0.0 {
            origin += 1;
        } else if *re > 1e-9 * size {
            open += 1;
        } else if re.abs() <= 1e-9 * size {
            return Err(String::from(
                "the plant has undamped poles on the imaginary axis: no verdict is given",
            ));
        }
    }
    let at_origin = l
        .zeros
        .iter()
        .filter(|(re, im)| *re == 0.0 && *im == 0.0)
        .count();
    let m = (origin - i64::try_from(at_origin).unwrap_or(0)).max(0);
    // a direct feedthrough: |k·D| below one (checked by the caller)
    let lead = l.num.first().copied().unwrap_or(0.0) / l.den.first().copied().unwrap_or(1.0);
    let direct = if l.num.len() == l.den.len() {
        (k * lead).abs()
    } else {
        0.0
    };
    if direct > 0.0 && l.delay == 0.0 && (1.0 + k * lead).abs() < 1e-12 {
        return Err(String::from("1 + L(∞) = 0: the closed loop is improper"));
    }
    let roots = l.zeros.iter().chain(&l.poles).map(|(re, im)| re.hypot(*im));
    let biggest = roots.clone().fold(0.0f64, f64::max);
    let smallest = roots.filter(|r| *r > 0.0).fold(f64::INFINITY, f64::min);
    let smallest = if smallest.is_finite() { smallest } else { 1.0 };
    let smallest = if l.delay > 0.0 {
        smallest.min(1.0 / l.delay)
    } else {
        smallest
    };
    let w0 = 1e-6 * smallest;
    // the high-frequency end: ten times beyond every pole and zero each
    // factor of |L| is within 1 % of its asymptote, and L tends to its
    // direct term `c = k·D` from there, |L − c| falling; the end is where
    // 1 + L can wind no more — behind a delay where |L| is below halfway
    // from |c| to one (1 + L in a disc about 1 that leaves out 0), without
    // one where |L − c| is below half of |1 + c| (a disc about 1 + c) — and
    // ten times on
    let c = if direct > 0.0 { k * lead } else { 0.0 };
    let settled = |w: f64| {
        let lw = l.at(w);
        if l.delay > 0.0 {
            lw.abs() <= 0.5 * (1.0 + direct)
        } else {
            lw.sub(Complex::real(c)).abs() <= 0.5 * (1.0 + c).abs()
        }
    };
    let end = {
        let mut w = 10.0 * biggest.max(smallest);
        while !settled(w) && w < 1e300 {
            w *= 2.0;
        }
        10.0 * w
    };
    if m == 0 {
        // 1 + L(0) = 0: a closed-loop pole at the origin
        let l0 = l.at(0.0).re;
        if (1.0 + l0).abs() <= 1e-12 * (1.0 + l0.abs()) {
            return Err(String::from(
                "1 + L(0) = 0: a closed-loop pole at s = 0, the loop at its stability limit",
            ));
        }
    }
    let f = |w: f64| Complex::real(1.0).add(l.at(w));
    let inv = |c: Complex<f64>| Complex::real(1.0).div(c);
    let lost = |e: Lost| {
        match e {
        Lost::NotFinite(w) | Lost::Unresolved(w) => std::format!(
            "a closed-loop pole lies on the imaginary axis at {w:.6} rad/s, to working precision: the loop is at the stability limit"
        ),
    }
    };
    // the phase of 1 + L from ω₀ to the end, interval by interval of a
    // logarithmic grid
    let mut turned = 0.0;
    let mut a = w0;
    let mut la = l.at(a);
    let linear = if l.delay > 0.0 {
        0.5 / l.delay
    } else {
        f64::INFINITY
    };
    while a < end {
        let b = (a * 1.01).min(end);
        let lb = l.at(b);
        let (ma, mb) = (la.abs(), lb.abs());
        if !(ma.is_finite() && mb.is_finite()) {
            return Err(String::from(
                "the loop's response is not finite on the axis",
            ));
        }
        turned += if ma < 0.4 && mb < 0.4 {
            turn(Complex::real(1.0).add(la), Complex::real(1.0).add(lb))
        } else if ma > 2.5 && mb > 2.5 {
            l.phase(b) - l.phase(a)
                + turn(
                    Complex::real(1.0).add(inv(la)),
                    Complex::real(1.0).add(inv(lb)),
                )
        } else {
            // near the crossover: in steps the delay turns by half a radian
            let mut t = 0.0;
            let mut x = a;
            let mut fx = Complex::real(1.0).add(la);
            while x < b {
                let y = (x + linear).min(b);
                let fy = if y == b {
                    Complex::real(1.0).add(lb)
                } else {
                    f(y)
                };
                t += follow(&f, x, fx, y, fy, 0).map_err(lost)?;
                (x, fx) = (y, fy);
            }
            t
        };
        (a, la) = (b, lb);
    }
    let pi = core::f64::consts::PI;
    #[allow(clippy::cast_precision_loss)]
    let fe = Complex::real(1.0).add(la);
    let total = 2.0 * turned - m as f64 * pi + turn(fe, fe.conj());
    let n = total / (2.0 * pi);
    if (n - n.round()).abs() > 0.1 {
        return Err(std::format!(
            "the phase of 1 + L did not close ({n:.3} turns)"
        ));
    }
    #[allow(clippy::cast_possible_truncation)]
    let z = i64::try_from(open).unwrap_or(i64::MAX) - n.round() as i64;
    usize::try_from(z)
        .map(|z| (z, open))
        .map_err(|_| std::format!("1 + L winds {n:.0} times for {open} open-loop unstable poles: the count is inconsistent"))
}
