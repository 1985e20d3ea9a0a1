//! The cascade's designs: the secondary's IMC filter, the primary's model
//! seen through the closed secondary loop, and the primary's PID by
//! matching or by pole placement.

use super::*;

/// `Q(s) = a2(s)/(b2(s)·(λ2 s + 1)^r)` for `P2 = b2/a2`: the IMC controller
/// (numerator, denominator). `P2` must be stable and minimum phase.
#[cfg(feature = "alloc")]
pub fn imc_q(p2: &TransferFunction, lambda2: f64) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let lambda2 = crate::real::positive(lambda2, "lambda2")?;
    if p2.poles()?.iter().any(|(re, _)| *re >= 0.0) {
        return Err(Error::Unsupported(
            "the inner IMC loop needs a stable secondary process",
        ));
    }
    if p2.zeros()?.iter().any(|(re, _)| *re >= 0.0) {
        return Err(Error::Unsupported(
            "the inner IMC loop needs a minimum-phase secondary process",
        ));
    }
    let num = trim(&p2.num);
    let den = trim(&p2.den);
    let r = den.len().saturating_sub(num.len());
    let mut qd = num;
    for _ in 0..r {
        qd = mul(&qd, &[lambda2, 1.0]);
    }
    Ok((den, qd))
}

/// The overall delay-free model `Gm(s) = P1(s)/(λ2 s + 1)^r` and its dead time
/// `L1 + L2`: the primary loop's model `Pm = Mimc·P1` (Sec. 3.3).
#[cfg(feature = "alloc")]
pub fn primary_model(
    p1: &TransferFunction,
    p2: &TransferFunction,
    lambda2: f64,
) -> Result<TransferFunction, Error> {
    let lambda2 = crate::real::positive(lambda2, "lambda2")?;
    let r = trim(&p2.den).len().saturating_sub(trim(&p2.num).len());
    let mut den = p1.den.clone();
    for _ in 0..r {
        den = mul(&den, &[lambda2, 1.0]);
    }
    TransferFunction::new(&p1.num, &den, p1.delay + p2.delay)
}

/// The primary controller of Uma et al. (García et al. (2010) Sec. 4):
/// `Gcs = (kp + ki/s + kd·s)/(τ s + 1)` with the set-point weight `ε` on the
/// proportional term, as a [`PidConfig`]. The series filter is rewritten as a
/// parallel PID with the derivative filter `τ`:
///
/// `Gcs = P' + ki/s + kd'·s/(τ s + 1)`, `P' = kp − ki·τ`, `kd' = kd − P'·τ`,
///
/// and the set-point path `(ε·kp·s + ki)/(s(τ s + 1))` by the weights
/// `b = (ε·kp − ki·τ)/P'`, `c = −b·P'·τ/kd'` (derivative of the set point removed).
pub fn series_pid<T: Real>(
    kp: T,
    ki: T,
    kd: T,
    tau: T,
    epsilon: T,
    ts: T,
) -> Result<PidConfig<T>, Error> {
    let tau = crate::real::non_negative(tau, "tau")?;
    let p = kp - ki * tau;
    let kdp = kd - p * tau;
    // the gains share the sign of kp (negative for a reverse-acting loop)
    let sign = if kp < T::zero() { -T::one() } else { T::one() };
    if kdp * sign < -T::of(1e-12) * kd.abs().max(T::one()) {
        return Err(Error::OutOfRange(
            "kd (the series-filtered PID needs |kd| >= |kp - ki*tau|*tau, with the sign of kp)",
        ));
    }
    let kdp = if kdp * sign > T::zero() {
        kdp
    } else {
        T::zero()
    };
    let bp = epsilon * kp - ki * tau;
    let b = if p != T::zero() { bp / p } else { T::one() };
    let c = if kdp != T::zero() {
        -bp * tau / kdp
    } else {
        T::zero()
    };
    let mut cfg = PidConfig::parallel(p, ki, kdp, ts)
        .with_filter_time(tau)
        .with_weights(b, c)
        .with_anti_windup(AntiWindup::None);
    if kdp == T::zero() && tau > T::zero() {
        // a PI with a series lag: no derivative term can carry the lag
        return Err(Error::Unsupported(
            "tau without derivative action (set kd = (kp - ki*tau)*tau or tau = 0)",
        ));
    }
    if tau == T::zero() {
        cfg.tf = T::zero();
    }
    Ok(cfg)
}

/// FSPCC's and GPCC's primary controller (García et al. (2010) Sec. 4): Uma et al.'s
/// `Gcs = (kp + ki/s + kd s)/(τ s + 1)` with the set-point weight `ε`,
/// pole-zero matched at `ts` ([`Discretization::Matched`]) as `u = K(z)(F(z) r − y)` with
/// `K = Gcs` and the prefilter `F = (ε kp s + ki)/(kd s² + kp s + ki)`.
#[cfg(feature = "alloc")]
pub fn matched_primary<T: Real>(
    kp: f64,
    ki: f64,
    kd: f64,
    tau: f64,
    epsilon: f64,
    ts: f64,
) -> Result<crate::dtc::fsp::Matched2Dof<T>, Error> {
    let tau = crate::real::non_negative(tau, "tau")?;
    let matched = |n: &[f64], d: &[f64]| -> Result<Lti<T, 4>, Error> {
        Lti::from_tf_of(n, d, ts, Discretization::Matched)
    };
    let pid = [kd, kp, ki];
    let k = matched(&pid, &mul(&[1.0, 0.0], &[tau, 1.0]))?;
    let f = matched(&[epsilon * kp, ki], &pid)?;
    Ok(crate::dtc::fsp::Matched2Dof::new(f, k))
}

/// Pole placement of the series-filtered PID `(kp + ki/s + kd s)/(τ s + 1)` on
/// a delay-free model `Gm = n/d` of order 1 or 2: every closed-loop pole at
/// `−1/λ`. The characteristic polynomial `s(τ s + 1)d + (kd s² + kp s + ki)n`
/// is linear in `(τ, kd, kp, ki)`; matching it to `τ·d0·(s + 1/λ)^N`
/// (`N = deg d + 2`) gives as many equations as unknowns (first order: no
/// `kd`). Uma et al.'s Example 1 controller of García et al. (2010) is exactly this design
/// with `λ = 5 s` (`(s + 0.2)^4`), for an overall dead time of 6 s.
/// When no causal filter achieves that (a slow `λ` against a fast model pole
/// `−p`, e.g. `2/(s(0.5 s + 1))` with `λ > 2 s`), one closed-loop pole is
/// placed at `−p` instead. Returns `(kp, ki, kd, tau)`.
#[cfg(feature = "alloc")]
pub fn pole_placement(gm: &TransferFunction, lambda: f64) -> Result<[f64; 4], Error> {
    let lambda = crate::real::positive(lambda, "lambda")?;
    match place(gm, 1.0 / lambda, None) {
        Err(Error::Numerical(_)) => {
            let fastest = gm
                .poles()?
                .iter()
                .filter(|(re, _)| *re < 0.0)
                .map(|(re, im)| re.hypot(*im))
                .fold(1.0 / lambda, f64::max);
            place(gm, 1.0 / lambda, Some(fastest))
        }
        other => other,
    }
}

/// Places the closed-loop poles at `−a` (one at `−b` when given).
#[cfg(feature = "alloc")]
pub(super) fn place(gm: &TransferFunction, a: f64, b: Option<f64>) -> Result<[f64; 4], Error> {
    let d = trim(&gm.den);
    let n = trim(&gm.num);
    let deg = d.len().saturating_sub(1);
    if !(1..=2).contains(&deg) || n.len() >= d.len() {
        return Err(Error::Unsupported(
            "pole placement of the primary PID needs a strictly proper model of order 1 or 2",
        ));
    }
    let big_n = deg.saturating_add(2);
    // target (s + a)^N or (s + a)^{N−1}(s + b), ascending coefficients
    let mut target = alloc::vec![1.0];
    for i in 0..big_n {
        let root = match b {
            Some(b) if i == 0 => b,
            _ => a,
        };
        target = mul(&target, &[1.0, root]);
    }
    let asc = |p: &[f64]| -> Vec<f64> { p.iter().rev().copied().collect() };
    let coef = |p: &[f64], k: usize| p.get(k).copied().unwrap_or(0.0);
    let (da, na, ta) = (asc(&d), asc(&n), asc(&target));
    let d0 = coef(&d, 0);
    // columns: τ, kp, ki, (kd); rows: powers 0..N−1
    let unknowns = if deg == 2 { 4 } else { 3 };
    let mut m = [[0.0f64; 5]; 4];
    for (k, row) in m.iter_mut().enumerate().take(unknowns) {
        // τ: s²·d − d0·target; constant part s·d
        let tau_col = if k >= 2 { coef(&da, k - 2) } else { 0.0 } - d0 * coef(&ta, k);
        let kp_col = if k >= 1 { coef(&na, k - 1) } else { 0.0 };
        let ki_col = coef(&na, k);
        let kd_col = if k >= 2 { coef(&na, k - 2) } else { 0.0 };
        let rhs = -(if k >= 1 { coef(&da, k - 1) } else { 0.0 });
        *row = [tau_col, kp_col, ki_col, kd_col, rhs];
        if unknowns == 3 {
            row[3] = rhs;
        }
    }
    let x = solve_small(&m, unknowns)?;
    let (tau, kp, ki) = (x[0], x[1], x[2]);
    let kd = if unknowns == 4 { x[3] } else { 0.0 };
    if !(tau >= 0.0) {
        return Err(Error::Numerical(
            "pole placement gives a negative filter time constant (choose a larger lambda)",
        ));
    }
    Ok([kp, ki, kd, tau])
}

/// Solves the `n×(n+1)` augmented system `m` (`n ≤ 4`) by LU with partial
/// pivoting (nalgebra).
#[cfg(feature = "alloc")]
pub(super) fn solve_small(m: &[[f64; 5]; 4], n: usize) -> Result<[f64; 4], Error> {
    let at = |i: usize, j: usize| m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0);
    let a = nalgebra::DMatrix::from_fn(n, n, at);
    let b = nalgebra::DVector::from_fn(n, |i, _| at(i, n));
    let x = a
        .lu()
        .solve(&b)
        .filter(|x| x.iter().all(|v| v.is_finite()))
        .ok_or(Error::Numerical("pole placement (singular equations)"))?;
    let mut out = [0.0; 4];
    for (o, v) in out.iter_mut().zip(x.iter()) {
        *o = *v;
    }
    Ok(out)
}
