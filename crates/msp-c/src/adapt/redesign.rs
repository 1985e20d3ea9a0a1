//! How each adaptive scheme on the device is redesigned for a new model:
//! the Smith predictor's primary retuned, the Karan–Dey and the filtered
//! Smith predictors rebuilt in the dead-time line not in use.

use super::*;

/// The primary retuned by Kaya's IMC rule (Kaya (2003) Eqs. 20–21; the
/// tuning of `msp_tune_smith_fopdt`) at `lambda` (0: `λ = θ`, Eq. 26; NaN:
/// never).
#[derive(Debug, Clone, Copy)]
pub(super) struct Kaya<T> {
    pub(super) lambda: T,
}

impl<T: Real, C> Redesign<T, C> for Kaya<T> {
    fn gains(&mut self, k: T, tau: T, theta: T) -> Option<[T; 3]> {
        if self.lambda.is_nan() {
            return None;
        }
        let m: ProcessModel<T> = if tau.is_infinite() {
            Ipdt::new(k, theta).ok()?.into()
        } else {
            Fopdt::new(k, tau, theta).ok()?.into()
        };
        let lambda = if self.lambda == T::zero() {
            theta
        } else {
            self.lambda
        };
        let g = tuning::kaya(&m, lambda).ok()?;
        Some([g.kp, g.ti, g.td])
    }
}

/// A lot of the caller's memory a dead-time line is built in.
#[derive(Debug, Clone, Copy)]
pub(super) struct Lot {
    pub(super) at: *mut u8,
    pub(super) bytes: usize,
}

/// The two lots a redesigned scheme's lines alternate between: the one in
/// use holds one, its successor is built in the other.
#[derive(Debug, Clone, Copy)]
pub(super) struct Lots {
    pub(super) lots: (Lot, Lot),
    /// Whether the scheme in use holds the second lot.
    pub(super) second: bool,
}

impl Lots {
    /// An arena over the lot no scheme alive holds: the supervisor builds
    /// only while none it built before is warming up
    /// (`Redesign::rebuild`), so the one in use, on the other lot, is the
    /// only one.
    fn free(&self) -> Arena {
        let lot = if self.second {
            self.lots.0
        } else {
            self.lots.1
        };
        Arena::new(lot.at, lot.bytes)
    }

    /// The scheme built last took over (`Redesign::took_over`).
    fn swap(&mut self) {
        self.second = !self.second;
    }
}

/// The Karan–Dey predictor designed anew for a model: the thesis's tuning
/// (Bag (2022) Eqs. 4.30–4.44, `msp_tune_karan_dey_ipdt`) at `lambda` (0:
/// its default), the actuator's limits kept, its line in whichever of the
/// two lots the predictor in use does not hold.
pub(super) struct KaranDeyRedesign<T> {
    pub(super) ts: T,
    pub(super) lambda: T,
    pub(super) limits: (T, T),
    pub(super) lots: Lots,
}

impl<T: Real> Redesign<T, Kd<T>> for KaranDeyRedesign<T> {
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<Kd<T>> {
        if !tau.is_infinite() {
            return None;
        }
        let mut c = karan_dey_ipdt(k, theta, self.ts, self.lambda).ok()?;
        (c.u_min, c.u_max) = self.limits;
        karan_dey_in(&c, &mut self.lots.free()).ok()
    }

    fn took_over(&mut self) {
        self.lots.swap();
    }
}

/// The filtered Smith predictor designed anew for a model: its dead time
/// rounded to whole samples (the predictor realizes `z^{−h}`; the estimate
/// is not finer under noise), the primary by [`tuning::fsp_pi`] at
/// `lambda` (0: `λ = θ`), the filter's `tf` and the actuator's limits
/// kept; designed in `scratch`, its predictor in whichever of the two lots
/// the one in use does not hold.
pub(super) struct FspRedesign<T> {
    pub(super) ts: T,
    pub(super) lambda: T,
    pub(super) tf: T,
    pub(super) limits: (T, T),
    pub(super) lots: Lots,
    pub(super) scratch: Lot,
    /// The rounded dead time of the predictor built last (s).
    pub(super) built: Option<T>,
}

impl<T: Real> Redesign<T, Fsp<T>> for FspRedesign<T> {
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<Fsp<T>> {
        let ts = self.ts;
        let theta = (theta / ts).round().max(T::one()) * ts;
        self.built = Some(theta);
        let (m, model): (ProcessModel<T>, _) = if tau.is_infinite() {
            let m = (k, T::zero(), msp_model_kind::MSP_IPDT);
            (Ipdt::new(k, theta).ok()?.into(), m)
        } else {
            let m = (k, tau, msp_model_kind::MSP_FOPDT);
            (Fopdt::new(k, tau, theta).ok()?.into(), m)
        };
        let lambda = if self.lambda == T::zero() {
            theta
        } else {
            self.lambda
        };
        let g = tuning::fsp_pi(&m, lambda).ok()?;
        let c = msp_fsp_config_of {
            ts,
            model: msp_model_of {
                kind: model.2 as u32,
                k: model.0,
                tau: model.1,
                theta,
            },
            pid: msp_pid_params_of {
                kp: g.kp,
                ti: g.ti,
                td: T::zero(),
                u_min: self.limits.0,
                u_max: self.limits.1,
            },
            tf: self.tf,
        };
        // the scratch holds no scheme's state (the design is copied into
        // the predictor)
        let mut scratch = Arena::new(self.scratch.at, self.scratch.bytes);
        let (design, pid) = fsp_design(&c, |n| scratch.slice::<f64>(n)).ok()?;
        let mut a = self.lots.free();
        fsp_with(&design, pid, |n| a.slice::<T>(n)).ok()
    }

    fn took_over(&mut self) {
        self.lots.swap();
    }

    fn built_dead_time(&self) -> Option<T> {
        self.built
    }
}
