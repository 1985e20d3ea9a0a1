//! A controller sample of the adaptive controller: the estimator's
//! sample, the supervisor's at a block's end, the scheme's update, and the
//! rebuilt scheme warming beside it; the calls between a block's ends that
//! have nothing else to do take a path of their own (#48 item 7: host
//! cost).

use super::*;

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Adaptive<T, C, R, N, H, L>
{
    /// One sample with the input the plant really received over the last
    /// period (`None`: this controller's own output).
    pub fn update_applied(&mut self, r: T, y: T, u_applied: Option<T>) -> T {
        if let Some(u) = u_applied {
            if u.usable() && (u - self.last_u).abs() > T::epsilon() * (T::one() + u.abs()) {
                self.last_u = u;
                self.ok = false;
            }
        }
        self.step(r, y)
    }

    pub(super) fn step(&mut self, r: T, y: T) -> T {
        if self.calm > 0 {
            return self.calm_step(r, y);
        }
        // the estimator takes the last sample's measurement with the input
        // the plant then received (known only now: a limit or an operator
        // may have changed it after that update), one sample late
        let mut ended = false;
        let quiet = self.deferred.is_some() && self.est.idle();
        if self.refer {
            self.refer = false;
            self.reference();
        }
        if let Some(y_last) = self.pending.take() {
            let learn = self.ok && !self.frozen;
            ended = self.est.update(y_last, self.last_u, learn);
        }
        self.note(r, y);
        if quiet || ended {
            // (at a block's end only where no call between had been quiet)
            if let Some((m, kind)) = self.deferred.take() {
                self.take_now(m, kind);
            }
        }
        let logged = self.logged;
        if ended {
            // the supervisor runs at the estimator's period, on the
            // block's mean control error
            let mean = if self.err_n > 0 {
                self.err / T::of(f64::from(self.err_n))
            } else {
                T::zero()
            };
            (self.err, self.err_n) = (T::zero(), 0);
            self.blocks = self.blocks.saturating_add(1);
            self.since = self.since.saturating_add(1);
            self.supervise(mean);
        }
        let u = self.control(r, y);
        self.warm(r, y, u, self.logged != logged);
        // the calls up to the block's end that have nothing to do but add
        // their sample, where nothing waits (a change, the reference, a
        // rebuilt scheme)
        let waits = self.deferred.is_some() || self.refer || self.shadow.is_some();
        self.calm = if waits || self.pending.is_none() {
            0
        } else {
            self.est.calm_calls()
        };
        u
    }

    /// [`Adaptive::step`] in a call that has nothing to do but add its
    /// sample to the estimator's block (no learning part, level test or
    /// block's end in it; nothing waiting): the same arithmetic without
    /// the tests that find so. Any call from outside that may change that
    /// (a reset, a model or dead time set, a scheme built) ends the run.
    fn calm_step(&mut self, r: T, y: T) -> T {
        self.calm -= 1;
        if let Some(y_last) = self.pending {
            self.est.add(y_last, self.last_u, self.ok && !self.frozen);
        }
        self.note(r, y);
        self.control(r, y)
    }

    /// The sample's measurement for the next call, its count, the set
    /// point's move and the control error's sum.
    #[inline(always)]
    fn note(&mut self, r: T, y: T) {
        self.pending = Some(y);
        // (2⁶⁴ samples are not reached: no saturation to pay a sample)
        self.samples = self.samples.wrapping_add(1);
        if r != self.r_last {
            self.r_moved = true;
            self.r_last = r;
        }
        let e = r - y;
        if e.is_finite() {
            self.err = self.err + e;
            self.err_n = self.err_n.saturating_add(1);
        }
    }

    /// The scheme's update, and whether its output is one to learn from.
    #[inline(always)]
    fn control(&mut self, r: T, y: T) -> T {
        let scheme = &mut *self.inner;
        let u = scheme.update(r, y);
        self.last_u = u;
        self.ok = u.is_finite() && !scheme.fault();
        u
    }

    /// The rebuilt scheme's sample beside the one in use: it computes on
    /// the same measurement and follows the output the plant receives; when
    /// its time has come, it takes over (a sample later when this sample
    /// already logged a change: one change per sample, so that the
    /// recorded signals `adapt_changes` and `adapt_kind` name every one).
    fn warm(&mut self, r: T, y: T, u: T, logged: bool) {
        let Some(sh) = self.shadow.as_mut() else {
            return;
        };
        if let Some(spare) = self.inner.spare_mut() {
            spare.update(r, y);
            spare.apply(u, Tracking::Full);
        }
        sh.left = sh.left.saturating_sub(1);
        if sh.left > 0 {
            return;
        }
        if logged {
            sh.left = 1;
            return;
        }
        if let Some(sh) = self.shadow.take() {
            // (a flag: the scheme's lines are not copied)
            self.inner.swap();
            self.retune.took_over();
            self.use_model(sh.model);
            self.reference();
            self.record(sh.kind);
            self.changed(sh.kind);
        }
    }
}
