//! Process models with dead time, and their conversion to discrete blocks.
//!
//! The parameter names (`k`, `t`, `t1`, `t2`, `l`) are the ones reports, the
//! CLI and Python use. Forms (Bag (2022) Eq. 4.1,
//! Kaya (2003) Sec. 3):
//!
//! | model | transfer function |
//! | --- | --- |
//! | FOPDT | `K e^{−Ls}/(T s + 1)` |
//! | SOPDT | `K e^{−Ls}/((T1 s + 1)(T2 s + 1))` |
//! | IPDT | `K e^{−Ls}/s` |
//! | FOIPDT | `K e^{−Ls}/(s (T s + 1))` |
//! | UFOPDT | `K e^{−Ls}/(T s − 1)` |

use crate::real::{finite, non_negative, positive};
use crate::{error::Error, lti::Discretization, lti::Lti, real::Real};

/// A model's struct, and its constructor checking each parameter with the
/// function written after its name (`nonzero`, `positive`, `non_negative`).
macro_rules! model_struct {
    ($(#[$m:meta])* $name:ident { $($(#[$fm:meta])* $f:ident: $check:ident),* $(,)? }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        pub struct $name<T> {
            $($(#[$fm])* pub $f: T,)*
        }

        impl<T: Real> $name<T> {
            /// The model from its parameters, each checked: finite, the gain
            /// not zero, the time constants positive, the dead time not
            /// negative.
            pub fn new($($f: T),*) -> Result<Self, Error> {
                Ok($name {
                    $($f: $check($f, stringify!($f))?,)*
                })
            }
        }
    };
}

model_struct! {
    /// First order plus dead time `K e^{−Ls}/(T s + 1)`.
    Fopdt {
        /// Static gain `K`.
        k: nonzero,
        /// Time constant `T` (s).
        t: positive,
        /// Dead time `L` (s).
        l: non_negative,
    }
}
model_struct! {
    /// Second order plus dead time `K e^{−Ls}/((T1 s + 1)(T2 s + 1))`.
    Sopdt {
        /// Static gain `K`.
        k: nonzero,
        /// First time constant `T1` (s).
        t1: positive,
        /// Second time constant `T2` (s).
        t2: positive,
        /// Dead time `L` (s).
        l: non_negative,
    }
}
model_struct! {
    /// Integrator plus dead time `K e^{−Ls}/s`.
    Ipdt {
        /// Velocity gain `K` (1/s).
        k: nonzero,
        /// Dead time `L` (s).
        l: non_negative,
    }
}
model_struct! {
    /// First-order integrator plus dead time `K e^{−Ls}/(s (T s + 1))`.
    Foipdt {
        /// Velocity gain `K`.
        k: nonzero,
        /// Time constant `T` (s).
        t: positive,
        /// Dead time `L` (s).
        l: non_negative,
    }
}
model_struct! {
    /// Unstable first order plus dead time `K e^{−Ls}/(T s − 1)`.
    Ufopdt {
        /// Gain `K` (the static gain is `−K`).
        k: nonzero,
        /// Time constant `T` of the unstable pole `+1/T` (s).
        t: positive,
        /// Dead time `L` (s).
        l: non_negative,
    }
}

fn nonzero<T: Real>(k: T, field: &'static str) -> Result<T, Error> {
    (finite(k, field)? != T::zero())
        .then_some(k)
        .ok_or(Error::OutOfRange(field))
}

/// Any of the low-order process models.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum ProcessModel<T> {
    /// First order plus dead time.
    Fopdt(Fopdt<T>),
    /// Second order plus dead time.
    Sopdt(Sopdt<T>),
    /// Integrator plus dead time.
    Ipdt(Ipdt<T>),
    /// First-order integrator plus dead time.
    Foipdt(Foipdt<T>),
    /// Unstable first order plus dead time.
    Ufopdt(Ufopdt<T>),
}

macro_rules! from_model {
    ($($v:ident),*) => {$(
        impl<T> From<$v<T>> for ProcessModel<T> {
            fn from(m: $v<T>) -> Self {
                ProcessModel::$v(m)
            }
        }
    )*};
}
from_model!(Fopdt, Sopdt, Ipdt, Foipdt, Ufopdt);

impl<T: Real> ProcessModel<T> {
    /// The dead time `L` (s).
    pub fn delay(&self) -> T {
        match self {
            ProcessModel::Fopdt(m) => m.l,
            ProcessModel::Sopdt(m) => m.l,
            ProcessModel::Ipdt(m) => m.l,
            ProcessModel::Foipdt(m) => m.l,
            ProcessModel::Ufopdt(m) => m.l,
        }
    }

    /// The short name: `fopdt`, `sopdt`, `ipdt`, `foipdt` or `ufopdt`.
    pub fn kind(&self) -> &'static str {
        match self {
            ProcessModel::Fopdt(_) => "fopdt",
            ProcessModel::Sopdt(_) => "sopdt",
            ProcessModel::Ipdt(_) => "ipdt",
            ProcessModel::Foipdt(_) => "foipdt",
            ProcessModel::Ufopdt(_) => "ufopdt",
        }
    }

    /// The largest time constant of the delay-free part (0 for an IPDT model).
    pub fn largest_lag(&self) -> T {
        match *self {
            ProcessModel::Fopdt(m) => m.t,
            ProcessModel::Sopdt(m) => m.t1.max(m.t2),
            ProcessModel::Ipdt(_) => T::zero(),
            ProcessModel::Foipdt(m) => m.t,
            ProcessModel::Ufopdt(m) => m.t,
        }
    }

    /// True for a pole at the origin.
    pub fn is_integrating(&self) -> bool {
        matches!(self, ProcessModel::Ipdt(_) | ProcessModel::Foipdt(_))
    }

    /// True for a pole in the right half plane.
    pub fn is_unstable(&self) -> bool {
        matches!(self, ProcessModel::Ufopdt(_))
    }

    /// The delay-free part as `(num, den)` coefficients in descending powers of `s`,
    /// padded to degree 2 (leading zeros).
    pub fn rational(&self) -> ([T; 3], [T; 3]) {
        let z = T::zero();
        let o = T::one();
        match *self {
            ProcessModel::Fopdt(m) => ([z, z, m.k], [z, m.t, o]),
            ProcessModel::Sopdt(m) => ([z, z, m.k], [m.t1 * m.t2, m.t1 + m.t2, o]),
            ProcessModel::Ipdt(m) => ([z, z, m.k], [z, o, z]),
            ProcessModel::Foipdt(m) => ([z, z, m.k], [m.t, o, z]),
            ProcessModel::Ufopdt(m) => ([z, z, m.k], [z, m.t, -o]),
        }
    }

    /// The gain `|G(jω)|` and the unwrapped phase `arg G(jω)` (radians,
    /// from 0 at `ω = 0` for a positive gain: `−ωL − atan(ωT)` for a FOPDT,
    /// `−π/2 − ωL` for an IPDT, `−π + atan(ωT) − ωL` for `K/(Ts − 1)`), of
    /// the model with its gain's magnitude; the sign of `K` is the caller's
    /// (a reverse-acting process).
    pub fn frequency_response(&self, w: T) -> (T, T) {
        let lag = |t: T| ((T::one() + (w * t) * (w * t)).sqrt(), (w * t).atan());
        let half_pi = T::of(core::f64::consts::FRAC_PI_2);
        let (k, mag, phase) = match *self {
            ProcessModel::Fopdt(m) => {
                let (a, p) = lag(m.t);
                (m.k, a, -p)
            }
            ProcessModel::Sopdt(m) => {
                let ((a1, p1), (a2, p2)) = (lag(m.t1), lag(m.t2));
                (m.k, a1 * a2, -p1 - p2)
            }
            ProcessModel::Ipdt(m) => (m.k, w, -half_pi),
            ProcessModel::Foipdt(m) => {
                let (a, p) = lag(m.t);
                (m.k, w * a, -half_pi - p)
            }
            ProcessModel::Ufopdt(m) => {
                let (a, p) = lag(m.t);
                (m.k, a, -half_pi - half_pi + p)
            }
        };
        (k.abs() / mag, phase - w * self.delay())
    }

    /// The name and value of each parameter, in the order of the model's formula.
    pub fn params(&self) -> ([(&'static str, T); 4], usize) {
        let z = ("", T::zero());
        match *self {
            ProcessModel::Fopdt(m) => ([("k", m.k), ("t", m.t), ("l", m.l), z], 3),
            ProcessModel::Sopdt(m) => ([("k", m.k), ("t1", m.t1), ("t2", m.t2), ("l", m.l)], 4),
            ProcessModel::Ipdt(m) => ([("k", m.k), ("l", m.l), z, z], 2),
            ProcessModel::Foipdt(m) => ([("k", m.k), ("t", m.t), ("l", m.l), z], 3),
            ProcessModel::Ufopdt(m) => ([("k", m.k), ("t", m.t), ("l", m.l), z], 3),
        }
    }

    /// The delay-free part ZOH-discretized at `ts`, and the dead time in
    /// samples; a first-order lag and an integrator in closed form
    /// ([`Lti::first_order`], [`Lti::integrator`]).
    pub fn discretize<const N: usize>(&self, ts: T) -> Result<(Lti<T, N>, T), Error> {
        let block = match *self {
            ProcessModel::Fopdt(m) => Lti::first_order(m.k, m.t, ts)?,
            ProcessModel::Ipdt(m) => Lti::integrator(m.k, ts)?,
            _ => {
                let (num, den) = self.rational();
                Lti::from_tf(&num, &den, ts, Discretization::Zoh)?
            }
        };
        Ok((block, crate::delay::samples(self.delay(), ts)?))
    }
}
