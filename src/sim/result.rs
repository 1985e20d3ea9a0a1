//! The recorded signals of a run and their CSV form.

use std::string::{String, ToString};
use std::vec::Vec;

/// Which load columns hold zeros in every row before the run writes them
/// (freshly allocated), so that a zero load need not be written.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Zeroed {
    pub(super) d: bool,
    pub(super) d_out: bool,
}

/// The signals of a run, one entry per sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimResult {
    /// Time (s).
    pub t: Vec<f64>,
    /// Set point.
    pub r: Vec<f64>,
    /// Plant output (with output disturbances, without noise).
    pub y: Vec<f64>,
    /// Actuator value after the limits.
    pub u: Vec<f64>,
    /// What the plant received when an actuator outside the controller
    /// limits it, or when operator events run ([`super::SimConfig::actuator`]);
    /// empty otherwise.
    pub u_applied: Vec<f64>,
    /// Input (load) disturbance.
    pub d: Vec<f64>,
    /// Output disturbance (all zero when there is none).
    pub d_out: Vec<f64>,
    /// Cascade plants: the secondary output `y2` as measured (empty otherwise).
    pub y2: Vec<f64>,
    /// Cascade plants: the disturbance `d0` at the secondary output (empty
    /// without one).
    pub d_inner: Vec<f64>,
    /// Internal signals of the controller, by name.
    pub signals: Vec<(String, Vec<f64>)>,
    /// Time at which the run was stopped because the output diverged.
    pub diverged_at: Option<f64>,
    /// Rows per controller period (the controller's samples are every `substeps` rows).
    pub substeps: usize,
    /// An adaptive controller's state at the end of the run
    /// ([`crate::Operate::adaptive_state`]; `None` for one that does not
    /// adapt).
    pub adaptive: Option<crate::operate::AdaptiveState<f64>>,
}

impl SimResult {
    /// Empties every column, keeping the allocations.
    pub(super) fn clear(&mut self) {
        self.truncate(0);
        self.diverged_at = None;
        self.adaptive = None;
    }

    /// Sizes the columns a run records to `rows` rows (the engine writes
    /// them in place and truncates them to the rows it ran), with one signal
    /// column per name (reused when the names are those of the last run);
    /// the others are left empty.
    pub(super) fn size(
        &mut self,
        names: &[&str],
        rows: usize,
        c: Columns,
    ) -> Result<Zeroed, crate::error::Error> {
        // a column without the room is allocated anew, zeroed, fallibly (a
        // column the process cannot have is an error, not an abort); a
        // reused one keeps its memory and its old rows, which the run
        // overwrites
        let fit = |v: &mut Vec<f64>| -> Result<bool, crate::error::Error> {
            if v.capacity() < rows {
                *v = super::plant::vec_zeros_for(rows, "recorded signals")?;
                Ok(true)
            } else {
                v.resize(rows, 0.0);
                Ok(false)
            }
        };
        let mut zeroed = Zeroed::default();
        let recorded = [
            (&mut self.t, true, None),
            (&mut self.y, true, None),
            (&mut self.u, true, None),
            (&mut self.u_applied, c.applied, None),
            (&mut self.y2, c.cascade, None),
            (&mut self.r, c.all, None),
            (&mut self.d, c.all, Some(&mut zeroed.d)),
            (&mut self.d_out, c.all, Some(&mut zeroed.d_out)),
            (&mut self.d_inner, c.all && c.cascade && c.d_inner, None),
        ];
        for (v, on, zero) in recorded {
            if on {
                let fresh = fit(v)?;
                if let Some(z) = zero {
                    *z = fresh;
                }
            } else {
                v.clear();
            }
        }
        self.diverged_at = None;
        if !c.all {
            self.signals.clear();
            return Ok(zeroed);
        }
        let same = self.signals.len() == names.len()
            && self.signals.iter().zip(names).all(|((a, _), b)| a == b);
        if !same {
            // other names: the old columns' buffers serve the new ones in turn
            let mut old = core::mem::take(&mut self.signals)
                .into_iter()
                .map(|(_, v)| v);
            self.signals = names
                .iter()
                .map(|s| (s.to_string(), old.next().unwrap_or_default()))
                .collect();
        }
        for (_, v) in &mut self.signals {
            fit(v)?;
        }
        Ok(zeroed)
    }

    /// Cuts every column to its first `rows` rows.
    pub(super) fn truncate(&mut self, rows: usize) {
        for v in [
            &mut self.t,
            &mut self.y,
            &mut self.u,
            &mut self.u_applied,
            &mut self.y2,
            &mut self.r,
            &mut self.d,
            &mut self.d_out,
            &mut self.d_inner,
        ] {
            v.truncate(rows);
        }
        for (_, v) in &mut self.signals {
            v.truncate(rows);
        }
    }
}

/// Which columns a run records besides `t`, `y` and `u`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Columns {
    /// `y2` (a cascade process).
    pub(super) cascade: bool,
    /// `r`, `d`, `d_out`, the controller's signals (and `d_inner` with it).
    pub(super) all: bool,
    /// `u_applied`.
    pub(super) applied: bool,
    /// `d_inner` (a disturbance at the secondary output).
    pub(super) d_inner: bool,
}

impl SimResult {
    /// Writes the signals as CSV: `t,r,y,u,d` (`t,r,y,u,u_applied,d` when
    /// the plant received something else than the controller gave), then `d_out` when there is an
    /// output disturbance, `y2` for a cascade process, `d_inner` when it has a
    /// `d0` disturbance, then the controller's signals (shortest round-trip
    /// number formatting).
    pub fn write_csv<W: std::io::Write + ?Sized>(&self, w: &mut W) -> std::io::Result<()> {
        let with_dout = self.d_out.iter().any(|v| *v != 0.0);
        let with_y2 = !self.y2.is_empty();
        let with_dinner = !self.d_inner.is_empty();
        let with_applied = !self.u_applied.is_empty();
        let mut head = std::string::String::from(if with_applied {
            "t,r,y,u,u_applied,d"
        } else {
            "t,r,y,u,d"
        });
        if with_dout {
            head.push_str(",d_out");
        }
        if with_y2 {
            head.push_str(",y2");
        }
        if with_dinner {
            head.push_str(",d_inner");
        }
        for (n, _) in &self.signals {
            head.push(',');
            head.push_str(n);
        }
        head.push('\n');
        w.write_all(head.as_bytes())?;
        let mut buf = ryu::Buffer::new();
        let mut line: Vec<u8> = Vec::with_capacity(256);
        let mut num = |line: &mut Vec<u8>, v: f64| {
            if v == 0.0 && v.is_sign_positive() {
                // the common value of disturbance columns, without formatting
                line.push(b'0');
            } else if v.is_finite() {
                let s = buf.format_finite(v);
                // ryu writes integers as "1.0"; keep them as "1" like `{}` does
                line.extend_from_slice(s.strip_suffix(".0").unwrap_or(s).as_bytes());
            } else {
                line.extend_from_slice(std::format!("{v}").as_bytes());
            }
        };
        for i in 0..self.t.len() {
            line.clear();
            let get = |v: &Vec<f64>| v.get(i).copied().unwrap_or(f64::NAN);
            num(&mut line, get(&self.t));
            for v in [&self.r, &self.y, &self.u] {
                line.push(b',');
                num(&mut line, get(v));
            }
            if with_applied {
                line.push(b',');
                num(&mut line, get(&self.u_applied));
            }
            line.push(b',');
            num(&mut line, get(&self.d));
            if with_dout {
                line.push(b',');
                num(&mut line, get(&self.d_out));
            }
            if with_y2 {
                line.push(b',');
                num(&mut line, get(&self.y2));
            }
            if with_dinner {
                line.push(b',');
                num(&mut line, get(&self.d_inner));
            }
            for (_, v) in &self.signals {
                line.push(b',');
                num(&mut line, get(v));
            }
            line.push(b'\n');
            w.write_all(&line)?;
        }
        Ok(())
    }
}
