//! A scheme rebuilt for a model ([`Redesign::rebuild`]): built in the
//! call that applies the model, or, with
//! [`AdaptiveConfig::background_design`], in [`Adaptive::design`], called
//! outside the control loop's sample (a device's background task: a
//! design can take far more than a sample's budget, the filtered Smith
//! predictor's f64 design about 195 000 instructions on a Cortex-M4F,
//! where an update takes a few hundred; #48 item 7).

use super::*;

impl<T: Real, C: Operate<T>, R: Redesign<T, C>, const N: usize, const H: usize, const L: usize>
    Adaptive<T, C, R, N, H, L>
{
    /// Builds the scheme the model in waiting needs
    /// ([`AdaptiveConfig::background_design`]): it warms up beside the one
    /// in use over the following updates and takes over as the change
    /// logged. Returns whether one was built; where the redesign cannot
    /// build it, adaptation freezes, logged as refused (the scheme in use
    /// is untouched). Nothing waits without `background_design`: the
    /// update that applies a model builds its scheme.
    pub fn design(&mut self) -> bool {
        // (the next call warms what this builds: not a calm one)
        self.calm = 0;
        let Some((m, kind)) = self.waiting.take() else {
            return false;
        };
        if self
            .rebuild(m, kind, "the redesign could not build the scheme")
            .is_ok()
        {
            return true;
        }
        self.frozen = true;
        self.record(ChangeKind::Refused);
        false
    }

    /// A model waits for [`Adaptive::design`] to build its scheme.
    pub fn is_designing(&self) -> bool {
        self.waiting.is_some()
    }

    /// The scheme designed for `m` warming up to take over, logged as
    /// `kind` when it does (`Error::Unsupported(why)`: the redesign built
    /// none).
    pub(super) fn rebuild(
        &mut self,
        m: Model<T>,
        kind: ChangeKind,
        why: &'static str,
    ) -> Result<(), Error> {
        let ts = self.cfg.estimator.ts;
        // (the one replaced last goes before its successor is built)
        self.inner.clear_spare();
        let scheme = self
            .retune
            .rebuild(m.k, m.tau, m.theta)
            .ok_or(Error::Unsupported(why))?;
        // the model in use is the one built: its dead time as the scheme
        // runs it (a filtered Smith predictor's is rounded to a sample; one
        // without a run-time dead time says so through its redesign)
        let m = Model {
            theta: scheme
                .dead_time()
                .map(|d| d * ts)
                .or_else(|| self.retune.built_dead_time())
                .unwrap_or(m.theta),
            ..m
        };
        // its dead time and four time constants (an integrating model's:
        // four dead times) fill its lines and settle it
        let span = if m.tau.is_finite() { m.tau } else { m.theta };
        let samples = ((m.theta + T::of(4.0) * span) / ts).ceil();
        let left = num_traits::ToPrimitive::to_u32(&samples)
            .unwrap_or(u32::MAX)
            .clamp(1, 100_000);
        self.inner.set_spare(scheme);
        self.shadow = Some(Shadow {
            model: m,
            left,
            kind,
        });
        Ok(())
    }
}
