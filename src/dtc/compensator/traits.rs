//! The compensator as an operated controller with a frequency response:
//! `Operate` (modes, run-time dead time, retuning, a new model),
//! `Introspect` and `FrequencyResponse`.

use super::*;

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> crate::operate::Operate<T>
    for Compensator<T, N, S>
{
    /// With `u = u1 − u3`, an applied `u` means `u1 = u + u3`: the model (driven
    /// by `u1` when there is a disturbance controller, by `u` otherwise) and
    /// Watanabe–Ito's correction are amended to it, and `Gc1`, whose output
    /// is `u1 + Gc2·ym`, tracks `u1`'s change. `Gc2` and `Gd` see the model's
    /// output and error, which the amendment keeps right.
    fn apply(&mut self, applied: T, how: crate::operate::Tracking) {
        if !(applied.usable() && self.u.is_finite()) {
            return;
        }
        let u1_applied = applied + self.u3;
        let dm = if self.drives_model_with_u1() {
            u1_applied - self.u1
        } else {
            applied - self.u
        };
        self.model.amend_input(dm);
        if let Some(c) = &mut self.corr {
            c.amend_input(dm);
        }
        let g = self.gc1.output();
        self.gc1.apply(g + (u1_applied - self.u1), how);
        self.u1 = u1_applied;
        self.u = applied;
    }

    fn dead_time(&self) -> Option<T> {
        Some(self.model.line().delay())
    }

    /// The model's line, and with it Huang's filter's line, Åström–Hang–Lim's
    /// window (whole samples) and Watanabe–Ito's correction `m(s) = Kv·L/(1 + sL)`
    /// (redesigned, its output at the steady state of its input).
    fn set_dead_time(&mut self, samples: T) -> Result<(), Error> {
        // Watanabe–Ito's m(s) = Kv·L/(1 + sL) is redesigned for the new L,
        // its output rescaled by L'/L (its steady state for the same input)
        let corr = match (&self.corr, self.corr_integrating) {
            (None, _) => None,
            (Some(_), false) => {
                return Err(Error::Unsupported(
                    "the scheme's correction contains the dead time: rebuild it for another",
                ))
            }
            (Some(m), true) => {
                let ts = self.gc1.config().ts;
                let (l_old, l_new) = (self.model.line().delay() * ts, samples * ts);
                // m(0) = Kv·L
                let kv = m.dc_gain()? / l_old;
                let mut fresh = Self::integrating_correction(kv, l_new, ts)?;
                if l_old > T::zero() {
                    fresh.shift_output(m.free_output() * l_new / l_old);
                }
                Some(fresh)
            }
        };
        // Åström–Hang–Lim's M holds the dead time as a window: it moves with
        // the model (whole samples)
        self.model.line().check(samples)?;
        // Huang's F delays its output by the model's dead time too (its B
        // does not depend on it): both lines move together, or neither
        if let ErrorPath::Huang { line, .. } = &self.err {
            line.check(samples)?;
        }
        if let DisturbancePath::AstromHangLim(m) = &mut self.dist {
            m.set_delay(samples)?;
        }
        self.model.line_mut().set_delay(samples)?;
        if let ErrorPath::Huang { line, .. } = &mut self.err {
            line.set_delay(samples)?;
        }
        if corr.is_some() {
            self.corr = corr;
        }
        Ok(())
    }

    /// The model's line, and Huang's filter's with it, slide to `samples`.
    /// Watanabe–Ito's correction (redesigned for a dead time) and
    /// Åström–Hang–Lim's window (whole samples) do not slide: they take a
    /// new dead time at once ([`crate::Operate::set_dead_time`]).
    fn ramp_dead_time(&mut self, samples: T, per_sample: T) -> Result<(), Error> {
        if self.corr.is_some() || matches!(self.dist, DisturbancePath::AstromHangLim(_)) {
            return Err(Error::Unsupported(
                "this scheme's correction or window is designed for its dead time: give the new dead time at once",
            ));
        }
        let per_sample = crate::real::positive(per_sample, "slew")?;
        self.model.line().check(samples)?;
        if let ErrorPath::Huang { line, .. } = &self.err {
            line.check(samples)?;
        }
        let line = self.model.line_mut();
        line.set_slew(per_sample)?;
        line.ramp_delay(samples)?;
        if let ErrorPath::Huang { line, .. } = &mut self.err {
            line.set_slew(per_sample)?;
            line.ramp_delay(samples)?;
        }
        Ok(())
    }

    /// `Gc1`'s gains; `kp` only when no other path scales with it
    /// (Karan–Dey's `Gc2 = β·Kp` and `Gc3 = γ·Kp` share it).
    fn retune(&mut self, gain: crate::operate::Gain, value: T) -> Result<(), Error> {
        let shared =
            !matches!(self.gc2, InnerPath::Off) || !matches!(self.dist, DisturbancePath::Off);
        if gain == crate::operate::Gain::Kp && shared {
            return Err(Error::Unsupported(
                "kp is shared by this scheme's controllers: rebuild it with the new kp",
            ));
        }
        self.gc1.retune(gain, value)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> Introspect<T> for Compensator<T, N, S> {
    fn signal_names(&self) -> &'static [&'static str] {
        &["ym", "ym_delayed", "model_error", "u1", "u3"]
    }

    fn signal(&self, i: usize) -> T {
        let [ym, ym_delayed, eps] = self.model.signals();
        [ym, ym_delayed, eps, self.u1, self.u3]
            .get(i)
            .copied()
            .unwrap_or_else(T::nan)
    }

    fn param_names(&self) -> &'static [&'static str] {
        self.params.names()
    }

    fn param(&self, i: usize) -> T {
        self.params.value(i)
    }
}

impl<T: Real, const N: usize, S: AsRef<[T]> + AsMut<[T]>> FrequencyResponse<T>
    for Compensator<T, N, S>
{
    /// From the structure (module documentation), with `D = z^{−d}`:
    /// `den = 1 + G1y(Gm − F·D·Gm − Mc) + G2·Gm`, `u1 = (G1r·r − G1y·F·y)/den`,
    /// `u = u1(1 + Gd·D·Gm) − Gd·y` (model driven by `u1`; without `Gd`, `u = u1`).
    fn response(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        Some(self.response_at(&Frequency::new(theta)))
    }

    #[cfg(feature = "alloc")]
    fn transfer(&self) -> Option<(crate::lti::zdomain::Rational, crate::lti::zdomain::Rational)> {
        Some(self.response_at(&crate::lti::zdomain::Symbolic))
    }

    fn inner_response(&self, theta: T) -> Option<Complex<T>> {
        let g1y = self.gc1.response(theta).1;
        let g2 = self.gc2.response(theta);
        Some(g1y.add(g2).mul(self.model.response(theta).0))
    }

    /// [`Compensator::response`]'s `Cy` over one determinant, with
    /// `F = Fn/Fd` (Huang's `Fd = 1 + B·z^{−d}`) and `Gd = Mn/Md`
    /// (Åström–Hang–Lim's `M` with its own loop):
    /// `Dc = Md·(Fd(1 + G1y(Gm − Mc) + G2·Gm) − G1y·Fn·D·Gm)`,
    /// `Nc = G1y·Fn·(Md + Mn·D·Gm) + Mn·Dc/Md`.
    fn feedback_parts(&self, theta: T) -> Option<(Complex<T>, Complex<T>)> {
        let one = Complex::real(T::one());
        let zero = Complex::default();
        let at = Frequency::new(theta);
        let (_, g1y) = self.gc1.response_at(&at);
        let g2 = self.gc2.response_at(&at);
        let (gm, d) = self.model.response_at(&at);
        let (f_num, f_den) = match &self.err {
            ErrorPath::Direct => (one, one),
            ErrorPath::Blocked => (zero, one),
            ErrorPath::Filter(f) => (at.lti(f), one),
            ErrorPath::Huang { b, line } => {
                let bb = at.lti(b);
                let dl = at.delay(line.delay());
                (one.add(bb), one.add(bb.mul(dl)))
            }
        };
        let (m_num, m_den) = match &self.dist {
            DisturbancePath::Off => (zero, one),
            DisturbancePath::Block(b) => (at.lti(b), one),
            DisturbancePath::AstromHangLim(m) => m.parts_at(&at),
        };
        let mc = self.corr.as_ref().map_or(zero, |c| at.lti(c));
        let den = f_den
            .mul(one.add(g1y.mul(gm.sub(mc))).add(g2.mul(gm)))
            .sub(g1y.mul(f_num).mul(d).mul(gm));
        let nc = g1y
            .mul(f_num)
            .mul(m_den.add(m_num.mul(d).mul(gm)))
            .add(m_num.mul(den));
        Some((nc, m_den.mul(den)))
    }

    /// The model's unstable poles and those of the filters (none, as designed).
    fn unstable_poles(&self) -> usize {
        let filter = match &self.err {
            ErrorPath::Filter(f) => f.unstable_poles(),
            ErrorPath::Huang { b, .. } => b.unstable_poles(),
            ErrorPath::Direct | ErrorPath::Blocked => 0,
        };
        let dist = match &self.dist {
            DisturbancePath::Block(b) => b.unstable_poles(),
            DisturbancePath::Off | DisturbancePath::AstromHangLim(_) => 0,
        };
        self.model.unstable_poles() + filter + dist
    }
}
