//! The design of `Fr` and `S` without allocation: model-sized polynomials in
//! fixed arrays, the dead-time-sized ones (`z^h·Dr`, `p`, the numerator of
//! `S`) in storage the caller's type provides ([`DelayStorage`]: a `Vec` on a
//! host, `[f64; C]` on a device, `C` at least `h` plus twice the model order
//! plus 8).

use super::{solve, MAX_CONDITIONS};
use crate::complex::Complex;
use crate::delay::DelayStorage;
use crate::lti::small::{model_tf, SmallPoly, SMALL};
use crate::{error::Error, lti::Lti};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// The shape of the robustness filter `Fr = Nr/Dr` whose free coefficients
/// Eq. 10 fixes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrSpec {
    /// Time constant `Tf` of the filter poles `γ = e^{−Ts/Tf}` (s).
    pub tf: f64,
    /// An optional phase lead `(z − ρ1)/(z − γ1)` given by its zero and pole
    /// time constants `(T_zero, T_pole)`: `ρ1 = e^{−Ts/T_zero}`,
    /// `γ1 = e^{−Ts/T_pole}` (García et al. (2010) Sec. 4, from the lead of `Gcd`).
    pub lead: Option<(f64, f64)>,
    /// `Nr` of the same degree as `Dr` (the biproper filters of García et al. (2010)
    /// Sec. 4: `Dr = (z − γ)^{m−1}`), or `Nr` one degree lower
    /// (`Dr = (z − γ)^m`, a strictly proper filter).
    pub biproper: bool,
}

/// The designed predictor: `ŷ = S(z)·u + Fr(z)·y`, `S = Gm(1 − z^{−h}Fr)`
/// realized without the model's unstable poles.
#[derive(Debug, Clone)]
pub struct FspDesign<S> {
    /// `Fr = Nr/Dr` (descending powers of z).
    pub nr: SmallPoly,
    /// Its denominator.
    pub dr: SmallPoly,
    /// The dead time `h` (samples).
    pub h: usize,
    /// How `S` is realized.
    pub s: Realization<S>,
}

/// The two realizations of the predictor's `S = Gm(1 − z^{−h}Fr)`.
///
/// A model with an unstable pole needs the direct form: `S` is stable only
/// once Eq. 10 has cancelled the pole, so its numerator is the long
/// polynomial `Nm(z − 1)p` (García et al. (2010) Eq. 10), as long as the dead
/// time, and each sample costs `O(h)`.
///
/// A stable model, or one with a single integrator, has no pole to cancel
/// but `z = 1`, and `S` splits into model-sized blocks around a line of the
/// last `h` inputs, `O(1)` per sample whatever the dead time:
/// - stable `Gm`: `S = A·(1 − z^{−h}B)` with `A = Gm`, `B = Fr`;
/// - `Gm = Nm/((z − 1)Dm⁻)`: `1 − z^{−h}Fr = (1 − z^{−h}) + z^{−h}(1 − Fr)`,
///   `(1 − z^{−h})/(z − 1) = Σ_{k=1}^{h} z^{−k}` (the sum of the last `h`
///   inputs) and `(1 − Fr)/(z − 1) = R/Dr` with `R = (Dr − Nr)/(z − 1)` (a
///   polynomial: `Fr(1) = 1`), so `S = A·(Σ_{k=1}^{h} z^{−k} + z^{−h}B)`
///   with `A = Nm/Dm⁻`, `B = R/Dr` — every block stable.
#[derive(Debug, Clone)]
// a design-time value, built once and read by the predictor's constructor:
// boxing the larger variant would need a heap a device does not have
#[allow(clippy::large_enum_variant)]
pub enum Realization<S> {
    /// `S = num/den` in powers of `z^{−1}`: the numerator (starting at
    /// `z^{−1}`) in the first `len` entries of `num`, the denominator monic.
    Direct {
        /// The numerator's storage.
        num: S,
        /// Its length.
        len: usize,
        /// The denominator `Dm⁻·Dr`.
        den: SmallPoly,
    },
    /// `S = A·(W + z^{−h}·s·B)` from the model's blocks (descending powers
    /// of z): `W = 1`, `s = −1` for a stable model, `W = Σ_{k=1}^{h} z^{−k}`,
    /// `s = 1` with `window` (a single integrator).
    Split {
        /// `A`'s numerator and denominator.
        a: (SmallPoly, SmallPoly),
        /// `B`'s numerator and denominator.
        b: (SmallPoly, SmallPoly),
        /// The model integrates: `W` is the sum of the last `h` inputs.
        window: bool,
    },
}

impl<S: AsRef<[f64]>> FspDesign<S> {
    /// The numerator of `S` in direct form (empty when split).
    pub fn s_num(&self) -> &[f64] {
        match &self.s {
            Realization::Direct { num, len, .. } => num.as_ref().get(..*len).unwrap_or(&[]),
            Realization::Split { .. } => &[],
        }
    }
}

/// `s` when it holds at least `len` values.
pub(crate) fn sized<T, S: AsRef<[T]>>(s: S, len: usize) -> Result<S, Error> {
    if s.as_ref().len() < len {
        return Err(Error::DelayTooLong("predictor storage"));
    }
    Ok(s)
}

/// Storage of at least `len` values.
pub(crate) fn buffer<T: crate::real::Real, S: DelayStorage<T>>(len: usize) -> Result<S, Error> {
    let n = u32::try_from(len).map_err(|_| Error::DelayTooLong("predictor storage"))?;
    let s = S::for_delay(T::of(f64::from(n)))?;
    if s.as_ref().len() < len {
        return Err(Error::DelayTooLong("predictor storage"));
    }
    Ok(s)
}

/// Designs the filter `Fr = Nr/(z − α)^m` (`α = e^{−Ts/Tf}`) and the stable predictor
/// `S` for the ZOH model `gm` with a dead time of `h` samples.
///
/// On a device, with arrays for the dead-time-sized buffers:
///
/// ```
/// use msp::dtc::fsp::{design, FilteredSmith};
/// use msp::Controller;
/// // 5 e^{-6s}/(100s - 1) at Ts = 0.06 s: h = 100 samples; buffers of 128
/// let (gm, _) = msp::ProcessModel::from(msp::Ufopdt::new(5.0, 100.0, 6.0)?).discretize::<1>(0.06)?;
/// let d = design::<[f64; 128], 1>(&gm, 100, 0.06, 3.0)?; // Fr with Tf = 3 s, S stable
/// let mut fsp: FilteredSmith<f32, [f32; 128]> =
///     FilteredSmith::new(msp::PidConfig::isa(6.87, 12.36, 0.0, 0.06), &d, Default::default())?;
/// assert!(fsp.update(1.0, 0.0) > 0.0);
/// # Ok::<(), msp::Error>(())
/// ```
pub fn design<S: DelayStorage<f64>, const N: usize>(
    gm: &Lti<f64, N>,
    h: usize,
    ts: f64,
    tf: f64,
) -> Result<FspDesign<S>, Error> {
    design_with(
        gm,
        h,
        ts,
        &FrSpec {
            tf,
            lead: None,
            biproper: false,
        },
    )
}

/// Designs `Fr` of the shape `spec` and the stable predictor `S` for the ZOH
/// model `gm` (strictly proper) with a dead time of `h` samples: FSPCC's
/// `Fr = kf (z − ρ1)(z − ρ2)/((z − γ1)(z − γ2))` is
/// `FrSpec { tf, lead: Some((T_zero, T_pole)), biproper: true }`.
pub fn design_with<S: DelayStorage<f64>, const N: usize>(
    gm: &Lti<f64, N>,
    h: usize,
    ts: f64,
    spec: &FrSpec,
) -> Result<FspDesign<S>, Error> {
    design_in(gm, h, ts, spec, buffer)
}

/// [`design_with`] with its two dead-time-sized buffers (a scratch of
/// `h + deg Dr + 1` values, then `S`'s numerator) taken from `storage`,
/// which returns storage of at least the length asked for (or an error):
/// for memory the caller owns, e.g. slices of one buffer given to the C API.
pub fn design_in<S: AsRef<[f64]> + AsMut<[f64]>, const N: usize>(
    gm: &Lti<f64, N>,
    h: usize,
    ts: f64,
    spec: &FrSpec,
    storage: impl FnMut(usize) -> Result<S, Error>,
) -> Result<FspDesign<S>, Error> {
    if gm.feedthrough() != 0.0 {
        return Err(Error::Unsupported(
            "fsp needs a strictly proper model (TransferFunction::to_model_lti gives one)",
        ));
    }
    let (nm, dm) = model_tf(gm);
    design_tf_in::<S, N>(&nm, &dm, h, ts, spec, storage)
}

/// [`design_in`] from the model's `z`-transfer function `Nm/Dm` (as
/// [`model_tf`] gives it; `D` bounds the degree of `Dm`, which keeps the
/// Schur decomposition out of low-order device builds): what a predictor
/// redesigned for another dead time starts from.
pub fn design_tf_in<S: AsRef<[f64]> + AsMut<[f64]>, const D: usize>(
    nm: &SmallPoly,
    dm: &SmallPoly,
    h: usize,
    ts: f64,
    spec: &FrSpec,
    storage: impl FnMut(usize) -> Result<S, Error>,
) -> Result<FspDesign<S>, Error> {
    design_form::<S, D>(nm, dm, h, ts, spec, storage, true)
}

/// [`design_tf_in`], in direct form unless `allow_split` (the direct form of
/// a stable model is what the split one is checked against).
pub(crate) fn design_form<S: AsRef<[f64]> + AsMut<[f64]>, const D: usize>(
    nm: &SmallPoly,
    dm: &SmallPoly,
    h: usize,
    ts: f64,
    spec: &FrSpec,
    mut storage: impl FnMut(usize) -> Result<S, Error>,
    allow_split: bool,
) -> Result<FspDesign<S>, Error> {
    let deg = dm.len().saturating_sub(1);
    let mut rts = [Complex::<f64>::default(); SMALL];
    crate::lti::roots_upto::<D, f64>(dm.as_slice(), &mut rts)?;
    let (mut dplus, mut dminus) = (SmallPoly::new(&[1.0])?, SmallPoly::new(&[1.0])?);
    // the roots of Dm⁺(z)(z − 1) with multiplicities (clustered within 1e-6)
    let mut cond = [(0.0f64, 0usize); MAX_CONDITIONS];
    let mut count = 0usize;
    let mut add = |x: f64, cond: &mut [(f64, usize); MAX_CONDITIONS]| -> Result<(), Error> {
        if let Some(c) = cond
            .iter_mut()
            .take(count)
            .find(|(r, _)| (*r - x).abs() < 1e-6)
        {
            c.1 = c.1.saturating_add(1);
            return Ok(());
        }
        let slot = cond.get_mut(count).ok_or(Error::OutOfRange("roots"))?;
        *slot = (x, 1);
        count = count.saturating_add(1);
        Ok(())
    };
    add(1.0, &mut cond)?;
    for r in rts.iter().take(deg) {
        let (re, im) = (r.re, r.im);
        if re.hypot(im) >= 1.0 - 1e-9 {
            if im.abs() > 1e-9 {
                return Err(Error::Unsupported(
                    "complex unstable poles in the filtered Smith predictor",
                ));
            }
            add(re, &mut cond)?;
            dplus = dplus.mul(&[1.0, -re])?;
        } else if im.abs() <= 1e-12 {
            dminus = dminus.mul(&[1.0, -re])?;
        } else if im > 0.0 {
            dminus = dminus.mul(&[1.0, -2.0 * re, re * re + im * im])?;
        }
    }
    let cond = cond.get(..count).unwrap_or(&[]);
    let m: usize = cond.iter().map(|c| c.1).sum();
    let pole = |t: f64| -> Result<f64, Error> { Ok((-ts / crate::real::positive(t, "tf")?).exp()) };
    let alpha = pole(spec.tf)?;
    let mut dr = SmallPoly::new(&[1.0])?;
    for _ in 0..(if spec.biproper {
        m.saturating_sub(1)
    } else {
        m
    }) {
        dr = dr.mul(&[1.0, -alpha])?;
    }
    let q = match spec.lead {
        Some((t_zero, t_pole)) => {
            dr = dr.mul(&[1.0, -pole(t_pole)?])?;
            SmallPoly::new(&[1.0, -pole(t_zero)?])?
        }
        None => SmallPoly::new(&[1.0])?,
    };
    let (c, k) = solve(h, dr.as_slice(), q.as_slice(), cond)?;
    let nr = q.mul(c.get(..k).unwrap_or(&[]))?;
    if allow_split {
        if let Some(s) = split(nm, dm, (&dplus, &dminus), &nr, &dr)? {
            return Ok(FspDesign { nr, dr, h, s });
        }
    }
    // diff = z^h·Dr − Nr, then p = diff/(Dm⁺(z − 1)) in place (quotient in front)
    let dlen = h.saturating_add(dr.len());
    let mut diff: S = sized(storage(dlen)?, dlen)?;
    {
        let d = diff.as_mut();
        d.iter_mut().for_each(|v| *v = 0.0);
        for (x, v) in d.iter_mut().zip(dr.as_slice()) {
            *x = *v;
        }
        let off = dlen.saturating_sub(nr.len());
        for (i, v) in nr.as_slice().iter().enumerate() {
            if let Some(x) = d.get_mut(off.saturating_add(i)) {
                *x -= v;
            }
        }
    }
    let divisor = dplus.mul(&[1.0, -1.0])?;
    let scale = {
        let d = diff.as_ref();
        d.iter().take(dlen).fold(1.0f64, |m, v| m.max(v.abs()))
    };
    let qlen = {
        let d = diff.as_mut().get_mut(..dlen).unwrap_or(&mut []);
        let qlen = crate::lti::divide_in_place(d, divisor.as_slice());
        if d.iter()
            .take(dlen)
            .skip(qlen)
            .any(|r| r.abs() > 1e-6 * scale)
        {
            return Err(Error::Numerical("robustness filter (Eq. 10 not satisfied)"));
        }
        qlen
    };
    // S = Nm(z − 1)p / (Dm⁻·Dr·z^h), in powers of z^{−1}
    let nm1 = SmallPoly::new(nm.as_slice())?.mul(&[1.0, -1.0])?;
    let a = dminus.mul(dr.as_slice())?;
    let a_lead = a.lead();
    let da = a.len().saturating_sub(1).saturating_add(h);
    let blen = qlen.saturating_add(nm1.len()).saturating_sub(1);
    let db = blen.saturating_sub(1);
    let s_len = da.saturating_add(1);
    let off = da.saturating_sub(db);
    let mut s_num: S = sized(storage(s_len)?, s_len)?;
    {
        let p = diff.as_ref();
        let out = s_num.as_mut();
        out.iter_mut().for_each(|v| *v = 0.0);
        for (i, ni) in nm1.as_slice().iter().enumerate() {
            for (j, pj) in p.iter().take(qlen).enumerate() {
                if let Some(x) = out.get_mut(off.saturating_add(i).saturating_add(j)) {
                    *x += ni * pj / a_lead;
                }
            }
        }
    }
    let mut s_den = [0.0; SMALL];
    for (d, v) in s_den.iter_mut().zip(a.as_slice()) {
        *d = v / a_lead;
    }
    Ok(FspDesign {
        nr,
        dr,
        h,
        s: Realization::Direct {
            num: s_num,
            len: s_len,
            den: SmallPoly::new(s_den.get(..a.len()).unwrap_or(&[1.0]))?,
        },
    })
}

/// The split realization of `S` ([`Realization::Split`]) when the model's
/// poles on or outside the unit circle (`Dm⁺`) are none or a single `z = 1`;
/// `None` for any other model (the direct form).
fn split<S>(
    nm: &SmallPoly,
    dm: &SmallPoly,
    (dplus, dminus): (&SmallPoly, &SmallPoly),
    nr: &SmallPoly,
    dr: &SmallPoly,
) -> Result<Option<Realization<S>>, Error> {
    let integrator = match dplus.as_slice() {
        [_] => false,
        [_, r] if (r + 1.0).abs() < 1e-6 => true,
        _ => return Ok(None),
    };
    if !integrator {
        return Ok(Some(Realization::Split {
            a: (*nm, *dm),
            b: (*nr, *dr),
            window: false,
        }));
    }
    // A = Nm/Dm⁻ (Dm = lead·(z − 1)·Dm⁻ with Dm⁻ monic)
    let lead = dm.lead();
    let mut an = [0.0; SMALL];
    for (x, v) in an.iter_mut().zip(nm.as_slice()) {
        *x = v / lead;
    }
    let a = (SmallPoly::new(an.get(..nm.len()).unwrap_or(&[]))?, *dminus);
    // R = (Dr − Nr)/(z − 1): Horner's synthetic division by z − 1
    let (d, n) = (dr.as_slice(), nr.as_slice());
    let off = d.len().saturating_sub(n.len());
    let mut diff = [0.0; SMALL];
    for (i, x) in diff.iter_mut().enumerate().take(d.len()) {
        let ni = i
            .checked_sub(off)
            .and_then(|j| n.get(j))
            .copied()
            .unwrap_or(0.0);
        *x = d.get(i).copied().unwrap_or(0.0) - ni;
    }
    let len = d.len();
    let mut acc = 0.0;
    let scale = diff.iter().take(len).fold(1.0f64, |m, v| m.max(v.abs()));
    for x in diff.iter_mut().take(len) {
        acc += *x;
        *x = acc;
    }
    // the last running sum is Dr(1) − Nr(1): zero when Fr(1) = 1
    if acc.abs() > 1e-9 * scale {
        return Err(Error::Numerical("robustness filter (Fr(1) is not 1)"));
    }
    let r = SmallPoly::new(diff.get(..len.saturating_sub(1)).unwrap_or(&[]))?;
    Ok(Some(Realization::Split {
        a,
        b: (r, *dr),
        window: true,
    }))
}
