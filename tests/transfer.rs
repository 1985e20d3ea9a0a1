//! Every scheme's transfer functions as coefficients (`FrequencyResponse::transfer`,
//! what `msp tune --json` prints and Python's `to_control()` builds) against the
//! controller itself: the difference equations of `Cr` and `Cy` driven by the
//! same set point and measurement give the controller's output sample by
//! sample. The time-domain run is independent of the composition that built
//! the coefficients.
use msp::poly::TransferFunction;
use msp::registry::{Build, SCHEMES};
use msp::{Complex, Controller};

/// `y = (num/den)·x` in powers of `z^{−1}` (`den[0] = 1`).
fn filter(num: &[f64], den: &[f64], x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; x.len()];
    for k in 0..x.len() {
        let mut v = 0.0;
        for (i, b) in num.iter().enumerate() {
            if i <= k {
                v += b * x[k - i];
            }
        }
        for (i, a) in den.iter().enumerate().skip(1) {
            if i <= k {
                v -= a * y[k - i];
            }
        }
        y[k] = v / den[0];
    }
    y
}

/// A deterministic excitation: a few incommensurate sinusoids and steps,
/// away from zero from the first sample on (a controller reset to rest
/// differences its first sample against zero, as the transfer function
/// from rest does: the derivative's kick included).
fn signal(n: usize, seed: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64;
            (0.31 * t + seed).sin()
                + 0.5 * (1.7 * t * seed).cos()
                + if k > n / 3 { 0.4 } else { 0.0 }
        })
        .collect()
}

/// `num(w)/den(w)` at `z = e^{jθ}` against `want`, within the rounding the
/// evaluation of the multiplied-out polynomials can carry: `n·ε` times each
/// polynomial's condition `Σ|p_i| / |p(w)|` (large near a cluster of roots).
fn agrees(p: &msp::lti::zdomain::Rational, theta: f64, want: Complex<f64>) -> Result<(), String> {
    let (num, den) = p.polynomials();
    let w = Complex::cis(-theta);
    let at = |p: &[f64]| {
        p.iter()
            .rev()
            .fold(Complex::default(), |a, c| a * w + Complex::real(*c))
    };
    let (n, d) = (at(&num), at(&den));
    let cond = |p: &[f64], v: Complex<f64>| p.iter().map(|c| c.abs()).sum::<f64>() / v.abs();
    let len = num.len().max(den.len()) as f64;
    let got = n / d;
    let tol =
        8.0 * len * f64::EPSILON * (cond(&num, n) + cond(&den, d) + 1.0) * want.abs() + 1e-300;
    if (got - want).abs() <= tol {
        Ok(())
    } else {
        Err(format!(
            "θ {theta}: {got:?} vs {want:?} (tolerance {tol:e})"
        ))
    }
}

/// A registry build at `ts` without limits.
fn unlimited(ts: f64) -> Build {
    Build::unlimited(ts)
}

/// The coefficients `cr`, `cy` of `c` are its frequency response (the one
/// the analysis uses) across the band.
fn is_the_response(
    name: &str,
    c: &dyn msp::FrequencyResponse<f64>,
    cr: &msp::lti::zdomain::Rational,
    cy: &msp::lti::zdomain::Rational,
) {
    for theta in [0.01, 0.4, 2.0] {
        let (fr, fy) = c.response(theta).unwrap();
        if let Err(e) = agrees(cr, theta, fr).and(agrees(cy, theta, fy)) {
            panic!("{name}: {e}");
        }
    }
}

#[test]
fn coefficients_reproduce_every_controller() {
    // stable, integrating and unstable plants, dead times of 8-12 samples
    let cases = [
        ("e^-2s/(2s+1)", 0.25),
        ("0.2/s*e^-7.4s", 0.74),
        ("e^-1s/(5s-1)", 0.1),
        ("e^-0.5s/((2s+1)(20s-1))", 0.05),
    ];
    let n = 400;
    let (r, y) = (signal(n, 0.7), signal(n, 1.9));
    let mut checked = Vec::new();
    for scheme in SCHEMES {
        for (plant, ts) in cases {
            let tf: TransferFunction = plant.parse().unwrap();
            let Ok(params) = scheme.tune_with(&tf, None, &[]) else {
                continue;
            };
            let build = unlimited(ts);
            let Ok(mut c) = scheme.build_with(&params, &tf, &build) else {
                continue;
            };
            let (cr, cy) = c
                .transfer()
                .unwrap_or_else(|| panic!("{} gives no transfer function", scheme.name));
            let ((nr, dr), (ny, dy)) = (cr.polynomials(), cy.polynomials());
            assert!(
                [&nr, &dr, &ny, &dy]
                    .iter()
                    .all(|p| p.iter().all(|c| c.is_finite())),
                "{} on {plant}: {nr:?}/{dr:?}, {ny:?}/{dy:?}",
                scheme.name
            );
            let (ur, uy) = (filter(&nr, &dr, &r), filter(&ny, &dy, &y));
            // how much the recursion itself moves when its denominators'
            // coefficients move by a few roundings (clustered poles near
            // z = 1 make the expanded form sensitive): the tolerance
            let nudge = |p: &[f64]| -> Vec<f64> {
                p.iter()
                    .enumerate()
                    .map(|(i, c)| {
                        c * (1.0 + 4.0 * f64::EPSILON * if i % 2 == 0 { 1.0 } else { -1.0 })
                    })
                    .collect()
            };
            let (ur2, uy2) = (filter(&nr, &nudge(&dr), &r), filter(&ny, &nudge(&dy), &y));
            let sensitivity = ur
                .iter()
                .zip(&ur2)
                .chain(uy.iter().zip(&uy2))
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            c.reset_to_rest();
            let mut scale = 1.0f64;
            let mut worst = 0.0f64;
            for k in 0..n {
                let u = c.update(r[k], y[k]);
                let want = ur[k] - uy[k];
                scale = scale.max(ur[k].abs()).max(uy[k].abs());
                let err = (u - want).abs();
                worst = if err.is_nan() {
                    f64::INFINITY
                } else {
                    worst.max(err)
                };
            }
            // the sums of a few hundred terms of this scale, each rounded
            eprintln!(
                "{} on {plant}: {:e} sens {:e}",
                scheme.name,
                worst / scale,
                sensitivity / scale
            );
            assert!(
                worst <= 1e-12 * scale + 10.0 * sensitivity,
                "{} on {plant}: worst {worst:e} of {scale:e} (Cr {nr:?}/{dr:?})",
                scheme.name
            );
            // and the coefficients are the response the analysis uses
            is_the_response(scheme.name, &*c, &cr, &cy);
            checked.push((scheme.name, plant));
        }
    }
    // the cascades: the outer controller's parts (with the inner set point as
    // its actuator), against the response the analysis uses; the outer
    // controllers' blocks are those checked in the time domain above
    let uma: Vec<(String, f64)> = [
        ("kpd", 3.119),
        ("kid", 0.0921),
        ("kdd", 6.6156),
        ("lead", 3.0),
        ("lag", 0.144),
    ]
    .iter()
    .map(|(k, v)| (k.to_string(), *v))
    .collect();
    let examples = [
        ("e^-4s/(20s-1)", "2e^-2s/(20s+1)", 0.2),
        ("2e^-2s/s", "4e^-2s/(s+1)", 0.1),
    ];
    for scheme in SCHEMES.iter().filter(|s| s.is_cascade()) {
        for (p1, p2, ts) in examples {
            let (p1, p2): (TransferFunction, TransferFunction) =
                (p1.parse().unwrap(), p2.parse().unwrap());
            let set = if scheme.name == "uma" { &uma[..] } else { &[] };
            let Ok(params) = scheme.tune_process(&p1, Some(&p2), None, None, set) else {
                continue;
            };
            let build = unlimited(ts);
            let c = scheme
                .build_process(&params, &p1, Some(&p2), &build)
                .unwrap();
            let (cr, cy) = c.transfer().unwrap();
            let (nr, dr) = cr.polynomials();
            assert!(
                nr.iter().chain(&dr).all(|c| c.is_finite()),
                "{}",
                scheme.name
            );
            is_the_response(scheme.name, &*c, &cr, &cy);
            checked.push((scheme.name, "cascade"));
        }
    }
    // every scheme on some plant
    for scheme in SCHEMES {
        assert!(
            checked.iter().any(|(s, _)| *s == scheme.name),
            "{} not checked",
            scheme.name
        );
    }
}

/// The Smith predictor's `Cy = G1y/(1 + G1y·Gm(1 − z^{−d}))` by hand for a P
/// controller on a first-order model: `Gm = b w/(1 − a w)`, so
/// `Cy = k(1 − a w)/(1 − a w + k b w(1 − w^d))`.
#[test]
fn smith_predictor_by_hand() {
    use msp::FrequencyResponse;
    use msp::{DelayLine, Discretization, Lti, PidConfig, SmithPredictor};
    let (k, ts, tau, d) = (0.8, 0.1, 1.0, 5usize);
    let model = Lti::<f64, 2>::from_tf(&[1.0], &[tau, 1.0], ts, Discretization::Zoh).unwrap();
    let pid = PidConfig::isa(k, f64::INFINITY, 0.0, ts);
    let line = DelayLine::<f64, 16>::new(d as f64).unwrap();
    let sp = SmithPredictor::new(pid, model, line).unwrap();
    let (_, cy) = sp.transfer().unwrap();
    let (num, den) = cy.polynomials();
    let a = (-ts / tau).exp();
    let b = 1.0 - a;
    let mut want_den = vec![0.0; d + 2];
    want_den[0] = 1.0;
    want_den[1] = -a + k * b;
    want_den[d + 1] = -k * b;
    let want_num = [k, -k * a];
    assert_eq!(num.len(), 2, "{num:?}");
    assert_eq!(den.len(), d + 2, "{den:?}");
    for (g, w) in num.iter().zip(want_num) {
        assert!((g - w).abs() < 1e-14, "{num:?}");
    }
    for (g, w) in den.iter().zip(want_den) {
        assert!((g - w).abs() < 1e-14, "{den:?}");
    }
}
