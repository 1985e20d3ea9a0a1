//! Each scheme built from its C configuration in the caller's memory: the
//! model read and checked, the storage its lines need sized and placed.

use super::*;

pub(crate) fn model<T: Real>(m: &msp_model_of<T>) -> Result<ProcessModel<T>, Error> {
    Ok(match kind_of(m.kind).ok_or(Error::OutOfRange("kind"))? {
        msp_model_kind::MSP_FOPDT => Fopdt::new(m.k, m.tau, m.theta)?.into(),
        msp_model_kind::MSP_IPDT => Ipdt::new(m.k, m.theta)?.into(),
        msp_model_kind::MSP_UFOPDT => Ufopdt::new(m.k, m.tau, m.theta)?.into(),
    })
}

/// The model kind an integer names.
pub(super) fn kind_of(k: u32) -> Option<msp_model_kind> {
    [
        msp_model_kind::MSP_FOPDT,
        msp_model_kind::MSP_IPDT,
        msp_model_kind::MSP_UFOPDT,
    ]
    .into_iter()
    .find(|v| *v as u32 == k)
}

pub(crate) fn pid_config<T: Real>(p: &msp_pid_params_of<T>, ts: T) -> Result<PidConfig<T>, Error> {
    let c = PidConfig::try_isa(p.kp, p.ti, p.td, ts)?.with_limits(p.u_min, p.u_max);
    c.validate()?;
    Ok(c)
}

/// The model kinds a scheme takes (the registry's plant kinds): the classic
/// Smith predictor leaves an unstable model's pole in the loop, and the
/// Karan–Dey predictor is designed for integrating plants.
pub(super) fn takes(m: &msp_model_of<impl Real>, kinds: &[msp_model_kind]) -> Result<(), Error> {
    let Some(kind) = kind_of(m.kind) else {
        return Err(Error::OutOfRange("kind"));
    };
    if kinds.contains(&kind) {
        Ok(())
    } else {
        Err(Error::Unsupported("a model kind the scheme does not take"))
    }
}

/// The model's dead time in samples (checked) at the period `ts`.
pub(crate) fn dead_time<T: Real>(
    m: &msp_model_of<T>,
    ts: T,
) -> Result<(ProcessModel<T>, T), Error> {
    let pm = model(m)?;
    let ts = positive(ts, "ts")?;
    let d = msp_core::delay::samples(pm.delay(), ts)?;
    Ok((pm, d))
}

/// `v` when it is finite and greater than zero.
pub(super) fn positive<T: Real>(v: T, name: &'static str) -> Result<T, Error> {
    if !v.is_finite() {
        Err(Error::NonFinite(name))
    } else if v > T::zero() {
        Ok(v)
    } else {
        Err(Error::NotPositive(name))
    }
}

/// Whole samples of a delay of `d` samples, when it fits in 2³¹.
pub(crate) fn whole<T: Real>(d: T) -> Option<usize> {
    let c = d.ceil().to_f64()?;
    if c.is_finite() && (0.0..2_147_483_648.0).contains(&c) {
        // in range: checked just above
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        Some(c as usize)
    } else {
        None
    }
}

/// The values of `T` a scheme keeps beyond its handle, and the f64 scratch
/// its design needs, for a dead time of `samples` samples.
pub(super) fn storage_of(kind: Kind, samples: usize) -> Option<(usize, usize)> {
    const SMALL: usize = msp_core::dtc::fsp::SMALL;
    Some(match kind {
        Kind::Pid => (0, 0),
        Kind::Line => (samples.max(1), 0),
        // S's numerator and input history (h + order + 1 each); in f64 the
        // design's scratch and S's numerator, (h + SMALL) each
        Kind::Fsp => {
            let n = samples.checked_add(SMALL)?;
            (n.checked_mul(2)?, n.checked_mul(2)?)
        }
    })
}

#[derive(Clone, Copy)]
pub(crate) enum Kind {
    Pid,
    Line,
    Fsp,
}

/// `msp_*_size`: the bytes for `kind` with a dead time of `samples`
/// (checked), or at least `max_samples`.
pub(super) fn size_for<T: Precision>(
    kind: Kind,
    samples: Result<T, Error>,
    max_samples: u32,
    status: *mut msp_status,
) -> usize {
    let samples = match samples {
        Ok(s) => s,
        Err(e) => {
            report(status, e.into());
            return 0;
        }
    };
    let need = whole(samples);
    let Some(need) = need else {
        report(status, msp_status::MSP_DEAD_TIME_TOO_LONG);
        return 0;
    };
    let n = need.max(max_samples as usize);
    match storage_of(kind, n).and_then(|(v, s)| bytes_for::<T>(v, s)) {
        Some(b) => {
            report(status, msp_status::MSP_OK);
            b
        }
        None => {
            report(status, msp_status::MSP_DEAD_TIME_TOO_LONG);
            0
        }
    }
}

/// Builds a handle in the caller's buffer with `make`, which takes its
/// storage from the arena after the handle.
///
/// # Safety
/// `buf` is null or points to `len` writable bytes; `out` is null or writable.
pub(super) unsafe fn init<T: Precision, H>(
    buf: *mut u8,
    len: usize,
    out: *mut *mut H,
    make: impl FnOnce(&mut Arena) -> Result<Scheme<T>, Error>,
) -> msp_status {
    if buf.is_null() || out.is_null() {
        return msp_status::MSP_NULL_POINTER;
    }
    let mut arena = Arena::new(buf, len);
    let Some(slot) = arena.place::<Handle<T>>() else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    let scheme = match make(&mut arena) {
        Ok(s) => s,
        Err(_) if arena.exhausted => return msp_status::MSP_BUFFER_TOO_SMALL,
        Err(e) => return e.into(),
    };
    // SAFETY: `slot` is aligned and inside the buffer (the arena checked)
    unsafe {
        slot.write(Handle {
            magic: T::MAGIC,
            update: update_of::<T, Pid<T>>,
            ctrl: core::ptr::null_mut(),
            held: T::zero(),
            auto_update: update_of::<T, Pid<T>>,
            auto_ctrl: core::ptr::null_mut(),
            scheme,
        });
        (*slot).bind();
        out.write(slot.cast());
    }
    msp_status::MSP_OK
}

pub(crate) fn make_pid<T: Real>(c: &msp_pid_config_of<T>) -> Result<Scheme<T>, Error> {
    Ok(Scheme::Pid(Pid::new(pid_config(&c.pid, c.ts)?)?))
}

/// A predictor's model (first order) and its dead-time line in the buffer.
pub(super) type ModelParts<T> = (msp_core::Lti<T, 1>, Delay<T, Buf<T>>);

/// The model ZOH-discretized at `ts`, and its dead-time line over the rest
/// of the arena.
pub(crate) fn model_in<T: Real>(
    m: &msp_model_of<T>,
    ts: T,
    a: &mut Arena,
) -> Result<ModelParts<T>, Error> {
    let (m, d) = dead_time(m, ts)?;
    let (block, _) = m.discretize::<1>(ts)?;
    Ok((block, Delay::with_storage(a.rest::<T>()?, d)?))
}

pub(crate) fn make_smith<T: Real>(
    c: &msp_smith_config_of<T>,
    a: &mut Arena,
) -> Result<Scheme<T>, Error> {
    smith_samples(c)?;
    let pid = pid_config(&c.pid, c.ts)?;
    let (block, line) = model_in(&c.model, c.ts, a)?;
    Ok(Scheme::Smith(SmithPredictor::new(pid, block, line)?))
}

pub(crate) fn make_karan_dey<T: Real>(
    c: &msp_karan_dey_config_of<T>,
    a: &mut Arena,
) -> Result<Scheme<T>, Error> {
    Ok(Scheme::KaranDey(karan_dey_in(c, a)?))
}

/// A Karan–Dey predictor, its dead-time line over the rest of the arena.
pub(crate) fn karan_dey_in<T: Real>(
    c: &msp_karan_dey_config_of<T>,
    a: &mut Arena,
) -> Result<KaranDey<T, 1, Buf<T>>, Error> {
    karan_dey_samples(c)?;
    let p = KaranDeyParams {
        kp: c.kp,
        ti: c.ti,
        beta: c.beta,
        gamma: c.gamma,
        td: c.td,
        n: c.n,
    };
    let (block, line) = model_in(&c.model, c.ts, a)?;
    compensator::build(&p, c.ts, block, line)?.with_limits(c.u_min, c.u_max)
}

pub(crate) fn make_fsp<T: Real>(
    c: &msp_fsp_config_of<T>,
    a: &mut Arena,
) -> Result<Scheme<T>, Error> {
    // the design's two f64 buffers come first; the predictor's after them
    let (design, pid) = fsp_design(c, |n| a.slice::<f64>(n))?;
    Ok(Scheme::Fsp(fsp_with(&design, pid, |n| a.slice::<T>(n))?))
}

/// The filtered Smith predictor in the caller's memory.
pub(crate) type Fsp<T> = FilteredSmith<T, Buf<T>, 2>;

/// The filtered Smith predictor's design (García et al. (2010) Sec. 3: `Fr`
/// and `S`, in f64 whatever `T` is, as on the host) in `scratch`, and its
/// primary.
pub(crate) fn fsp_design<T: Real>(
    c: &msp_fsp_config_of<T>,
    scratch: impl FnMut(usize) -> Result<&'static mut [f64], Error>,
) -> Result<(FspDesign<&'static mut [f64]>, PidConfig<T>), Error> {
    let (_, d) = dead_time(&c.model, c.ts)?;
    let pid = pid_config(&c.pid, c.ts)?;
    let tf = positive(c.tf, "tf")?.to_f64().unwrap_or(f64::NAN);
    let ts = c.ts.to_f64().unwrap_or(f64::NAN);
    let wide = |v: T| v.to_f64().unwrap_or(f64::NAN);
    let m64 = model(&msp_model_of {
        kind: c.model.kind,
        k: wide(c.model.k),
        tau: wide(c.model.tau),
        theta: wide(c.model.theta),
    })?;
    let (gm, _) = m64.discretize::<1>(ts)?;
    // the nearest whole number, to a relative 10⁻⁶: a dead time of whole
    // samples may come out ulps above it (f32: 0.3 s at 0.06 s is
    // 5.0000005 samples, 1.08 s 18.000002)
    let h = whole(d.round()).ok_or(Error::DelayTooLong("theta"))?;
    if (d.to_f64().unwrap_or(f64::NAN) - h as f64).abs() > 1e-6 * (h.max(1) as f64) {
        return Err(Error::Unsupported(
            "the filtered Smith predictor needs a dead time of whole samples",
        ));
    }
    let spec = FrSpec {
        tf,
        lead: None,
        biproper: false,
    };
    Ok((design_in(&gm, h, ts, &spec, scratch)?, pid))
}

/// The filtered Smith predictor of a design, its predictor in `storage`.
pub(crate) fn fsp_with<T: Real>(
    design: &FspDesign<&'static mut [f64]>,
    pid: PidConfig<T>,
    storage: impl FnMut(usize) -> Result<&'static mut [T], Error>,
) -> Result<Fsp<T>, Error> {
    let pred = FspPredictor::new_in(design, storage)?;
    FilteredSmith::with_predictor(pid, pred, ParamList::default())
}

/// The values of `T` and the f64 scratch a filtered Smith predictor of
/// `samples` samples of dead time needs.
pub(crate) fn fsp_storage(samples: usize) -> Option<(usize, usize)> {
    storage_of(Kind::Fsp, samples)
}
