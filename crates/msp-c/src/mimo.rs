//! Two-by-two plants from C: a Smith predictor on each diagonal channel,
//! decentralized or behind the inverted decoupler (`msp::mimo`), in the
//! caller's memory like every other controller.
//!
//! ```c
//! msp_mimo2_config cfg;
//! msp_model g[4] = {{MSP_FOPDT, 12.8f, 16.7f, 1.0f}, {MSP_FOPDT, -18.9f, 21.0f, 3.0f},
//!                   {MSP_FOPDT, 6.6f, 10.9f, 7.0f}, {MSP_FOPDT, -19.4f, 14.4f, 3.0f}};
//! msp_tune_mimo2(g, 1.0f, 1, &cfg);                 /* decoupled, λ = θ per loop */
//! size_t need = msp_mimo2_size(&cfg, &status);
//! msp_mimo2 *c; msp_mimo2_init(memory, sizeof memory, &cfg, &c);
//! float r[2] = {1, 0}, y[2], u[2];
//! msp_mimo2_update(c, r, y, u);                     /* once per sample */
//! ```

use core::mem::{align_of, size_of};

use msp_core::mimo::{
    fopdt_element, fopdt_element_samples, Decentralized, Decoupled, InvertedDecoupler,
    MultiController,
};
use msp_core::{Delay, Error, Fopdt, Real, SmithPredictor};

use crate::handle::{
    dead_time, msp_model_kind, msp_model_of, msp_pid_params_of, pid_config, read, Arena, Buf,
    Precision,
};
use crate::msp_status;

c_config! {
    /// A 2×2 plant's controller: the channels `g[0..4]` = `g11, g12, g21,
    /// g22` (first order plus dead time, `MSP_FOPDT`; `g_ij` from input `j`
    /// to output `i`), each loop's PI `pid[i]` inside its Smith predictor on
    /// `g_ii`, sampled every `ts` seconds; `decoupled` nonzero puts the
    /// inverted decoupler `d_ij = g_ij/g_ii` (the exact ratio of the sampled
    /// channels) between the predictors and the plant, which needs each
    /// `g_ij` to answer no sooner than `g_ii` (else `MSP_UNSUPPORTED`).
    msp_mimo2_config_of: msp_mimo2_config, msp_mimo2_config_f64 {
        ts: T,
        g: [msp_model_of<T>; 4],
        pid: [msp_pid_params_of<T>; 2],
        decoupled: u32,
    }
}

/// A 2×2 controller built by `msp_mimo2_init` (opaque).
pub struct msp_mimo2 {
    _opaque: [u8; 0],
}

/// A 2×2 controller built by `msp_mimo2_init_f64` (opaque).
pub struct msp_mimo2_f64 {
    _opaque: [u8; 0],
}

/// The handle types and their precisions.
pub(crate) trait MimoOpaque {
    type T: Precision + MimoTag;
}
impl MimoOpaque for msp_mimo2 {
    type T = f32;
}
impl MimoOpaque for msp_mimo2_f64 {
    type T = f64;
}

/// The 2×2 handle's tag, one per precision (not a single-loop handle's).
pub(crate) trait MimoTag {
    const MIMO_MAGIC: u32;
}
impl MimoTag for f32 {
    const MIMO_MAGIC: u32 = 0x4d4d_4d4d;
}
impl MimoTag for f64 {
    const MIMO_MAGIC: u32 = 0x3232_3232;
}

type Sp<T> = SmithPredictor<T, 1, Buf<T>>;

// the handle lives in the caller's buffer (sized by `msp_mimo2_size` for
// the scheme asked for): no heap to box a variant into
#[allow(clippy::large_enum_variant)]
enum Scheme2<T: Real> {
    Decentralized(Decentralized<Sp<T>, [Sp<T>; 2]>),
    Decoupled(Decoupled<T, Sp<T>, 2, 2, Buf<T>>),
}

#[repr(C)]
struct Handle2<T: Real> {
    magic: u32,
    scheme: Scheme2<T>,
}

/// The channels as models, each an FOPDT.
fn channels<T: Real>(c: &msp_mimo2_config_of<T>) -> Result<[Fopdt<T>; 4], Error> {
    let mut out = [Fopdt {
        k: T::one(),
        t: T::one(),
        l: T::zero(),
    }; 4];
    for (o, m) in out.iter_mut().zip(c.g.iter()) {
        if m.kind != msp_model_kind::MSP_FOPDT as u32 {
            return Err(Error::Unsupported(
                "a 2x2 controller's channels are first order plus dead time (MSP_FOPDT)",
            ));
        }
        dead_time(m, c.ts)?;
        *o = Fopdt::new(m.k, m.tau, m.theta)?;
    }
    Ok(out)
}

/// Each line's length (values of `T`): the predictors' dead times, then
/// the decoupler's delay differences.
fn lines<T: Real>(c: &msp_mimo2_config_of<T>) -> Result<[usize; 4], Error> {
    let [g11, g12, g21, g22] = channels(c)?;
    let whole = |d: T| -> Result<usize, Error> {
        crate::handle::whole(d).ok_or(Error::DelayTooLong("delay"))
    };
    let d = |g: &Fopdt<T>| msp_core::delay::samples(g.l, c.ts);
    let (d11, d22) = (d(&g11)?, d(&g22)?);
    let (e12, e21) = if c.decoupled != 0 {
        (
            fopdt_element_samples(&g12, &g11, c.ts)?,
            fopdt_element_samples(&g21, &g22, c.ts)?,
        )
    } else {
        (0, 0)
    };
    for p in &c.pid {
        pid_config(p, c.ts)?;
    }
    Ok([whole(d11)?, whole(d22)?, e12, e21])
}

/// The bytes a 2×2 controller needs, with the alignment slack of any buffer.
fn size_of_config<T: Precision>(c: &msp_mimo2_config_of<T>) -> Result<usize, Error> {
    let values: usize = lines(c)?.iter().sum();
    values
        .checked_mul(size_of::<T>())
        .and_then(|b| b.checked_add(size_of::<Handle2<T>>()))
        .and_then(|b| b.checked_add(align_of::<Handle2<T>>() + 4 * align_of::<T>()))
        .ok_or(Error::DelayTooLong("delay"))
}

fn build<T: Precision>(c: &msp_mimo2_config_of<T>, a: &mut Arena) -> Result<Scheme2<T>, Error> {
    let [n1, n2, n12, n21] = lines(c)?;
    let [g11, g12, g21, g22] = channels(c)?;
    let [p1, p2] = c.pid;
    let sp =
        |g: Fopdt<T>, p: &msp_pid_params_of<T>, n: usize, a: &mut Arena| -> Result<Sp<T>, Error> {
            let (block, d) = msp_core::ProcessModel::from(g).discretize::<1>(c.ts)?;
            let line = Delay::with_storage(a.slice::<T>(n)?, d)?;
            SmithPredictor::new(pid_config(p, c.ts)?, block, line)
        };
    let loops = [sp(g11, &p1, n1, a)?, sp(g22, &p2, n2, a)?];
    if c.decoupled == 0 {
        return Ok(Scheme2::Decentralized(Decentralized::new(loops)));
    }
    let d12 = fopdt_element(&g12, &g11, c.ts, a.slice::<T>(n12)?)?;
    let d21 = fopdt_element(&g21, &g22, c.ts, a.slice::<T>(n21)?)?;
    let dec = InvertedDecoupler::new([[None, Some(d12)], [Some(d21), None]])?;
    Ok(Scheme2::Decoupled(Decoupled::new(loops, dec)))
}

/// Builds the controller of `c` in the `len` bytes at `buf` (both checked
/// non-null by the caller) and writes its handle to `ctrl`.
///
/// # Safety
/// `buf` points to `len` writable bytes that stay in place while the
/// controller is used; `ctrl` is writable.
unsafe fn init2<T: Precision + MimoTag, H>(
    buf: *mut u8,
    len: usize,
    c: &msp_mimo2_config_of<T>,
    ctrl: *mut *mut H,
) -> msp_status {
    let mut arena = Arena::new(buf, len);
    let Some(slot) = arena.place::<Handle2<T>>() else {
        return msp_status::MSP_BUFFER_TOO_SMALL;
    };
    let scheme = match build(c, &mut arena) {
        Ok(s) => s,
        Err(_) if arena.exhausted => return msp_status::MSP_BUFFER_TOO_SMALL,
        Err(e) => return e.into(),
    };
    // SAFETY: `slot` is aligned and inside the buffer (the arena checked)
    unsafe {
        slot.write(Handle2 {
            magic: T::MIMO_MAGIC,
            scheme,
        });
        ctrl.write(slot.cast());
    }
    msp_status::MSP_OK
}

/// The handle behind a pointer, when it is a 2×2 one of its precision.
///
/// # Safety
/// `ctrl` is null or was given by an `msp_mimo2_init` call of this precision.
unsafe fn handle2<'a, H: MimoOpaque>(ctrl: *mut H) -> Option<&'a mut Handle2<H::T>> {
    let p = ctrl.cast::<Handle2<H::T>>();
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null; the caller's memory holds at least the tag
    let magic = unsafe { core::ptr::addr_of!((*p).magic).read_unaligned() };
    if magic != <H::T as MimoTag>::MIMO_MAGIC {
        return None;
    }
    // SAFETY: a tagged handle was written by `init2`
    unsafe { p.as_mut() }
}

twins! {
    /// Fills `*config` for the 2×2 plant `g` (`g11, g12, g21, g22`, each
    /// `MSP_FOPDT`) at the period `ts`: each loop's PI inside its Smith
    /// predictor by Kaya (2003), `kp = τ/(K·λ)`, `ti = τ`, with `λ = θ` of its
    /// channel when `decoupled` (the loops do not see each other) and
    /// `λ = 2θ` when not (the coupling is the loops' disturbance: `msp tune
    /// --plant "[…]" -c smith` detunes them on the host to a biggest log
    /// modulus of 4 dB, whose `loops` can be copied into `pid`).
    ///
    /// # Safety
    /// `g` is null or points to four models; `config` is null or writable.
    fn msp_tune_mimo2, msp_tune_mimo2_f64(
        g: *const crate::handle::msp_model | *const crate::handle::msp_model_f64,
        ts: f32 | f64,
        decoupled: u32,
        config: *mut msp_mimo2_config | *mut msp_mimo2_config_f64,
    ) -> msp_status {
        if g.is_null() || config.is_null() {
            return msp_status::MSP_NULL_POINTER;
        }
        // SAFETY: non-null, four models by the contract
        let models = unsafe { [*g, *g.add(1), *g.add(2), *g.add(3)] };
        let tuned = (|| {
            let mut c = msp_mimo2_config_of {
                ts,
                g: models,
                pid: [crate::handle::msp_pid_params_of {
                    kp: 1.0,
                    ti: 1.0,
                    td: 0.0,
                    u_min: -1.0 / 0.0,
                    u_max: 1.0 / 0.0,
                }; 2],
                decoupled,
            };
            let [g11, _, _, g22] = channels(&c)?;
            let factor = if decoupled != 0 { 1.0 } else { 2.0 };
            for (p, m) in c.pid.iter_mut().zip([g11, g22]) {
                let lambda = factor * m.l;
                if lambda <= 0.0 {
                    return Err(Error::Unsupported("a diagonal channel without dead time"));
                }
                p.kp = m.t / (m.k * lambda);
                p.ti = m.t;
            }
            lines(&c)?;
            Ok(c)
        })();
        // SAFETY: forwarded
        unsafe { crate::relay::tuned(config, tuned) }
    }

    /// The bytes a 2×2 controller needs (its delay lines included); 0 on an
    /// error, with the reason in `*status` (`status` may be null).
    ///
    /// # Safety
    /// `config` and `status` are null or valid pointers.
    fn msp_mimo2_size, msp_mimo2_size_f64(
        config: *const msp_mimo2_config | *const msp_mimo2_config_f64,
        status: *mut msp_status,
    ) -> usize {
        // SAFETY: forwarded
        crate::reported_size(unsafe { read(config) }, status, size_of_config)
    }

    /// Builds a 2×2 controller in `buf` (`len` bytes, any alignment); `*ctrl`
    /// is its handle.
    ///
    /// # Safety
    /// `buf` is null or points to `len` writable bytes that stay in place
    /// while the controller is used; `config` and `ctrl` are null or valid.
    fn msp_mimo2_init, msp_mimo2_init_f64(
        buf: *mut core::ffi::c_void,
        len: usize,
        config: *const msp_mimo2_config | *const msp_mimo2_config_f64,
        ctrl: *mut *mut msp_mimo2 | *mut *mut msp_mimo2_f64,
    ) -> msp_status {
        // SAFETY: forwarded
        let Some(c) = (unsafe { read(config) }) else {
            return msp_status::MSP_NULL_POINTER;
        };
        if buf.is_null() || ctrl.is_null() {
            return msp_status::MSP_NULL_POINTER;
        }
        // SAFETY: forwarded
        unsafe { init2(buf.cast(), len, &c, ctrl) }
    }

    /// One sample: the set points `r[2]` and measurements `y[2]` in, the
    /// plant's inputs `u[2]` out. A handle that is not a 2×2 one of this
    /// precision gives `MSP_BAD_HANDLE` (`MSP_NULL_POINTER` for null) and
    /// leaves `u` alone.
    ///
    /// # Safety
    /// `ctrl` is null or from `msp_mimo2_init`; `r`, `y` are null or point
    /// to two readable values, `u` to two writable ones.
    fn msp_mimo2_update, msp_mimo2_update_f64(
        ctrl: *mut msp_mimo2 | *mut msp_mimo2_f64,
        r: *const f32 | *const f64,
        y: *const f32 | *const f64,
        u: *mut f32 | *mut f64,
    ) -> msp_status {
        if r.is_null() || y.is_null() || u.is_null() {
            return msp_status::MSP_NULL_POINTER;
        }
        // SAFETY: forwarded
        let Some(h) = (unsafe { handle2(ctrl) }) else {
            return crate::handle::bad(ctrl);
        };
        // SAFETY: two values each, by the contract
        let (rv, yv) = unsafe { ([*r, *r.add(1)], [*y, *y.add(1)]) };
        let mut out = [0.0; 2];
        match &mut h.scheme {
            Scheme2::Decentralized(c) => c.update(&rv, &yv, &mut out),
            Scheme2::Decoupled(c) => c.update(&rv, &yv, &mut out),
        }
        // SAFETY: two writable values
        unsafe {
            u.write(out[0]);
            u.add(1).write(out[1]);
        }
        msp_status::MSP_OK
    }
}
