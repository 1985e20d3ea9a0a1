//! How a transfer function is written: factored where its roots are real,
//! the polynomials in `s` otherwise (`Display`).

use super::*;

/// A polynomial as a product of factors in time-constant form, the way
/// engineers write plants: `gain · s^m · Π(τs ± 1)^k · Π(as² + bs + 1)^k`,
/// e.g. `[10000, 4000, 600, 40, 1]` → `(1, "(10s + 1)^4")`. The roots are
/// clustered (a root of multiplicity `k` is found only to `ε^{1/k}`), each
/// factor's coefficients rounded to 6 significant digits (a plant written
/// with such numbers), and the product accepted only if it gives back the
/// coefficients to `1e-12` relative; otherwise, and for fewer than two factors, `None`. The third
/// value counts the distinct factors (a single `(…)^k` needs no parentheses
/// around it after a `/`).
pub(super) fn factored(p: &[f64]) -> Option<(f64, String, usize)> {
    let p = trim(p);
    // roots at the origin are exact: the trailing zero coefficients
    let zeros = p.iter().rev().take_while(|c| **c == 0.0).count();
    let rest = p.get(..p.len().saturating_sub(zeros))?;
    let roots = if rest.len() > 1 {
        poly_roots(rest).ok()?
    } else {
        Vec::new()
    };
    let low = *rest.last()?;
    let tol = 1e-12 * p.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    for near in [5e-2, 0.0] {
        // (coefficients, power) of each factor: s^m, then (τs ± 1) by falling τ,
        // then (as² + bs + 1)
        let mut real: Vec<f64> = Vec::new();
        let mut quads: Vec<((f64, f64), usize)> = Vec::new();
        let mut pairs: Vec<(f64, f64)> = Vec::new();
        for &(re, im) in &roots {
            if im.abs() <= near * re.hypot(im) {
                real.push(re);
            } else if im > 0.0 {
                pairs.push((re, im));
            }
        }
        real.sort_by(|a, b| a.abs().total_cmp(&b.abs()).then(a.total_cmp(b)));
        let mut firsts: Vec<(f64, f64, usize)> = Vec::new(); // (sum, first, count)
        for &x in &real {
            match firsts.last_mut() {
                Some((sum, first, n)) if (x - *first).abs() <= near * first.abs() => {
                    *sum += x;
                    *n = n.saturating_add(1);
                }
                _ => firsts.push((x, x, 1)),
            }
        }
        pairs.sort_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)));
        for &(re, im) in &pairs {
            let m2 = re * re + im * im;
            let q = (1.0 / m2, -2.0 * re / m2);
            match quads.last_mut() {
                Some((c, n))
                    if (q.0 - c.0).abs() <= near * c.0
                        && (q.1 - c.1).abs() <= near * c.0.sqrt() =>
                {
                    *n = n.saturating_add(1);
                }
                _ => quads.push((q, 1)),
            }
        }
        let count = zeros
            + firsts.iter().map(|f| f.2).sum::<usize>()
            + quads.iter().map(|q| q.1).sum::<usize>();
        if count < 2 {
            return None;
        }
        {
            let digits = 6usize;
            let mut fs: Vec<(Vec<f64>, usize)> = Vec::new();
            if zeros > 0 {
                fs.push((vec![1.0, 0.0], zeros));
            }
            let mut sign = 1.0;
            for &(sum, _, n) in &firsts {
                // (s − r) ∝ (τs + 1) for r < 0, (τs − 1) for r > 0, τ = 1/|r|
                let r = sum / n as f64;
                let c = if r < 0.0 { 1.0 } else { -1.0 };
                if c < 0.0 && n % 2 == 1 {
                    sign = -sign;
                }
                fs.push((vec![round_sig(1.0 / r.abs(), digits), c], n));
            }
            for &((a, b), n) in &quads {
                fs.push((vec![round_sig(a, digits), round_sig(b, digits), 1.0], n));
            }
            let mut prod = vec![1.0];
            for (f, n) in &fs {
                for _ in 0..*n {
                    prod = mul(&prod, f);
                }
            }
            let gain = round_sig(low * sign, digits);
            let back = prod.iter().map(|c| c * gain);
            if prod.len() == p.len() && back.zip(&p).all(|(a, b)| (a - b).abs() <= tol) {
                let mut s = String::new();
                for (f, n) in &fs {
                    let (body, terms) = fmt_poly(f);
                    if terms > 1 {
                        s.push_str(&alloc::format!("({body})"));
                    } else {
                        s.push_str(&body);
                    }
                    if *n > 1 {
                        s.push_str(&alloc::format!("^{n}"));
                    }
                }
                return Some((gain, s, fs.len()));
            }
        }
    }
    None
}

pub(super) fn fmt_poly(p: &[f64]) -> (String, usize) {
    let deg = p.len().saturating_sub(1);
    let mut out = String::new();
    let mut terms = 0usize;
    for (i, c) in p.iter().enumerate() {
        if *c == 0.0 {
            continue;
        }
        let pow = deg.saturating_sub(i);
        let mag = c.abs();
        if out.is_empty() {
            if *c < 0.0 {
                out.push('-');
            }
        } else {
            out.push_str(if *c < 0.0 { " - " } else { " + " });
        }
        let coef = if mag == 1.0 && pow > 0 {
            String::new()
        } else {
            fmt_num(mag)
        };
        out.push_str(&coef);
        match pow {
            0 => {}
            1 => out.push('s'),
            _ => out.push_str(&alloc::format!("s^{pow}")),
        }
        terms = terms.saturating_add(1);
    }
    if out.is_empty() {
        out.push('0');
    }
    (out, terms)
}

impl fmt::Display for TransferFunction {
    /// Canonical form: denominator scaled so its lowest non-zero coefficient has
    /// magnitude 1 (time-constant form), e.g. `5.6*e^(-93.9s)/(40.2s + 1)`. It
    /// parses back to the same transfer function.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (den_scale, den_text) = match factored(&self.den) {
            Some((g, text, groups)) => {
                let wrapped = if groups > 1 {
                    alloc::format!("({text})")
                } else {
                    text
                };
                (g, Some(wrapped))
            }
            None => (
                self.den
                    .iter()
                    .rev()
                    .find(|v| **v != 0.0)
                    .map_or(1.0, |v| v.abs()),
                None,
            ),
        };
        let num: Vec<f64> = self.num.iter().map(|v| v / den_scale).collect();
        let den: Vec<f64> = self.den.iter().map(|v| v / den_scale).collect();
        let (ns, nt) = match factored(&num) {
            Some((1.0, text, _)) => (text, 1),
            Some((-1.0, text, _)) => (alloc::format!("-{text}"), 1),
            Some((g, text, _)) => (alloc::format!("{}*{text}", fmt_num(g)), 1),
            None => fmt_poly(&num),
        };
        let (ds, dt) = match &den_text {
            Some(text) => (text.clone(), 1),
            None => fmt_poly(&den),
        };
        let unit_num = ns == "1" && self.delay > 0.0;
        if nt > 1 {
            write!(f, "({ns})")?;
        } else if !unit_num {
            f.write_str(&ns)?;
        }
        if self.delay > 0.0 {
            if !unit_num {
                f.write_str("*")?;
            }
            if self.delay == 1.0 {
                f.write_str("e^(-s)")?;
            } else {
                write!(f, "e^(-{}s)", fmt_num(self.delay))?;
            }
        }
        if den_text.is_some() {
            write!(f, "/{ds}")?;
        } else if ds != "1" {
            if dt > 1
                || ds.starts_with('-')
                || (ds.contains('s') && ds.len() > 1 && !ds.starts_with('s'))
                || ds.contains('^')
            {
                write!(f, "/({ds})")?;
            } else {
                write!(f, "/{ds}")?;
            }
        }
        Ok(())
    }
}
