//! A load's onset in an [`Estimator`]'s data: found, passed over, and
//! taken as every model's state.

use super::*;

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// A load's onset, and its samples passing: at rest (no input move
    /// within the response's time, so no candidate's prediction can
    /// change) the chosen candidate's prediction error beyond [`ONSET`]
    /// times the measured noise is a load, not the model's error. Its
    /// first [`ONSET_SAMPLES`] samples teach nothing: an output load's
    /// step is a pulse there in the differences. At the last of them every
    /// simulation (the candidates', the reference's, the detector's) takes
    /// the measured difference as its state: an input load's response
    /// decays from there as the process's own free response, which each
    /// model then predicts with its own pole — the load is part of the
    /// model's initial state, not of its parameters. The output error
    /// model with its state re-estimated at a disturbance's onset
    /// (Ljung (1999) Sec. 4.3: a step disturbance is an initial state;
    /// Åström & Wittenmark (1995) Sec. 11.2: do not adapt on data that do
    /// not carry the process's response). Returns whether this sample is
    /// one of an onset's (not learnt from).
    pub(super) fn onset(&mut self, target: T) -> bool {
        let cfg = self.cfg;
        let Some(c) = self.bank.get(self.chosen) else {
            return false;
        };
        let d = cfg.d_min + self.chosen;
        let e = target - predict(c.theta, c.yhat, self.hist.pair(d), cfg.integrating);
        let floor = T::epsilon().sqrt() * (T::one() + self.last_y.abs());
        let threshold = at_least(T::of(ONSET) * self.onset_noise(), floor);
        if self.skip == 0 {
            // at rest (no input move within twice the response's time), and
            // the noise measured over as long (the change detector's)
            let rest = self.window.saturating_mul(2);
            let measured = usize::try_from(self.samples).map_or(true, |n| n > rest);
            if self.hist.quiet <= rest || !measured || e.abs() <= threshold {
                return false;
            }
            self.start_onset(d);
        } else if e.abs() > threshold && e.abs() > T::of(ONSET) * self.onset_error {
            // a load among an onset's samples (an error [`ONSET`] times the
            // last sample's): its samples start again, so that its step is
            // not taken as the state (measured: noise-free, a wrong model's
            // onsets follow each other at rest, and an output load's pulse
            // falling on the last of one's samples became every model's
            // state, an error decaying over the lag that hid the gain's)
            self.start_onset(d);
        }
        self.onset_error = e.abs();
        // the onset's first two samples are not state: an output load's
        // step is a pulse there (split over two when it falls inside a
        // block of means); from the third each simulation is corrected
        // towards the measurement by `1/n` of its error, the recursive
        // least-squares estimate of the state a model's own dynamics carry
        // (the Kalman filter without process noise, Åström & Wittenmark
        // (1997) Sec. 11.3): a single noisy difference taken as the state
        // would persist in every simulation for the lag's time, and the
        // noise-free response is taken exactly
        // every simulation takes its state from here
        self.wake();
        let (n, seen) = self.settled;
        let counted = seen >= 2;
        let n = if counted { n.saturating_add(1) } else { n };
        self.settled = (n, seen.saturating_add(1));
        self.skip -= 1;
        let anchor = self.skip == 0;
        if anchor {
            // the level test's response starts after the anchor
            self.levels_open(true);
        }
        let gain = if counted {
            T::one() / T::of(f64::from(n))
        } else if anchor {
            T::one()
        } else {
            T::zero()
        };
        let towards = |pred: T| pred + gain * (target - pred);
        let inputs = self.hist.from(cfg.d_min);
        let pairs = inputs.iter().zip(inputs.get(1..).unwrap_or_default());
        let [snap, _] = self.snap;
        let bank = self.bank.get_mut(..self.n).unwrap_or_default();
        for (c, (&u0, &u1)) in bank.iter_mut().zip(pairs) {
            c.yhat = towards(predict(c.theta, c.yhat, (u0, u1), cfg.integrating));
            c.scan = towards(predict(snap, c.scan, (u0, u1), cfg.integrating));
            c.psi = [T::zero(); 3];
        }
        if let Some(r) = self.reference.as_mut() {
            let (u0, u1) = self.hist.pair(r.d);
            for h in &mut self.hyp {
                h.yhat = towards(predict(h.coef, h.yhat, (u0, u1), cfg.integrating));
            }
            r.yhat = towards(predict(
                r.theta,
                r.yhat,
                self.hist.pair(r.d),
                cfg.integrating,
            ));
        }
        true
    }

    /// An onset's samples start: `d` the chosen dead time's samples.
    fn start_onset(&mut self, d: usize) {
        // the controller's answer to it reaches the output a dead time on
        self.skip = ONSET_SAMPLES.min(d).max(1);
        self.levels_end();
        self.onsets = self.onsets.saturating_add(1);
        self.settled = (0, 0);
    }

    /// Load onsets found so far: at rest (no input move within twice a
    /// response's time), a prediction error beyond [`ONSET`] times the
    /// measured noise, which no input move can explain; its first
    /// [`ONSET_SAMPLES`] samples teach nothing and every model's
    /// simulation takes the measurement as its state there.
    pub fn onsets(&self) -> u32 {
        self.onsets
    }
}
