//! A scheme's parameters as a type.
//!
//! Each scheme declares one struct with the crate's `param_struct!` macro: its field names are
//! the parameter names everywhere (reports, `--set`, Python's `params` dict),
//! because [`ParamSet::NAMES`] is generated from the fields and serde derives
//! its keys from the same fields. There is no second list of names to keep in
//! step. [`ParamList`] is the fixed-size, allocation-free copy a controller
//! keeps of its own parameters for [`crate::Introspect`]; it is built from a
//! typed struct only.

use crate::{error::Error, real::Real};

/// Most parameters one scheme has.
pub const MAX_PARAMS: usize = 16;

/// A scheme's typed parameter struct (implemented by the `param_struct!` macro).
pub trait ParamSet<T: Real>: Copy + Default + PartialEq + core::fmt::Debug {
    /// The field names, in declaration (report) order.
    const NAMES: &'static [&'static str];
    /// The value of field `i` of [`ParamSet::NAMES`] (NaN past the end).
    fn value(&self, i: usize) -> T;
    /// Sets field `i`; false past the end.
    fn set_value(&mut self, i: usize, v: T) -> bool;
    /// Checks every field against its declared range; the error names the field.
    fn validate(&self) -> Result<(), Error>;

    /// The value of the field called `name`.
    fn get(&self, name: &str) -> Option<T> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| self.value(i))
    }
    /// Sets the field called `name`; false if the type has no such field.
    fn set(&mut self, name: &str, v: T) -> bool {
        match Self::NAMES.iter().position(|n| *n == name) {
            Some(i) => self.set_value(i, v),
            None => false,
        }
    }
    /// `self` with the fields it shares with `other` (by name) taken from
    /// `other`: a scheme's struct filled from the PID or primary it extends.
    fn with_fields_of<U: Real, Q: ParamSet<U>>(mut self, other: &Q) -> Self {
        for (i, name) in Q::NAMES.iter().enumerate() {
            self.set(name, T::of(other.value(i).f64()));
        }
        self
    }
    /// Reads every field of `Self` by name from another parameter set (the
    /// fields `Self` shares with a larger struct, a cascade's primary PID for
    /// instance), converting the precision. The error names a missing field.
    fn from_list<U: Real>(list: &ParamList<U>) -> Result<Self, Error> {
        let mut p = Self::default();
        for (i, name) in Self::NAMES.iter().enumerate() {
            let v = list.get(name).ok_or(Error::Unsupported(name))?;
            p.set_value(i, T::of(v.f64()));
        }
        Ok(p)
    }
}

/// A check on one field of a `param_struct!`: `positive`, `non_negative`,
/// `finite`, or `any` (NaN allowed: a value that is reported, or left unset
/// for the user, and checked where it is used).
#[doc(hidden)]
#[inline]
pub fn check<T: Real>(kind: Check, x: T, field: &'static str) -> Result<(), Error> {
    match kind {
        Check::Positive => crate::real::positive(x, field).map(|_| ()),
        Check::NonNegative => crate::real::non_negative(x, field).map(|_| ()),
        Check::Finite => crate::real::finite(x, field).map(|_| ()),
        Check::Any => Ok(()),
    }
}

/// The range a field of a `param_struct!` must lie in.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Check {
    /// Finite and above zero.
    Positive,
    /// Finite and not below zero.
    NonNegative,
    /// Finite.
    Finite,
    /// Anything, NaN included.
    Any,
}

/// Declares a scheme's parameter struct, generic over the precision `T`
/// (default `f64`), with serde derived (feature `serde`, unknown keys refused)
/// and [`ParamSet`] implemented from the field list:
///
/// ```text
/// param_struct! {
///     /// Tuned parameters of …
///     pub struct HuangParams {
///         /// Proportional gain.
///         kp: Positive,
///         /// Gain of `B`.
///         kb: NonNegative,
///     }
/// }
/// ```
macro_rules! param_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$fmeta:meta])* $field:ident : $check:ident ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
        pub struct $name<T = f64> {
            $( $(#[$fmeta])* pub $field: T, )+
        }

        impl<T: $crate::Real> $crate::params::ParamSet<T> for $name<T> {
            const NAMES: &'static [&'static str] = &[$(stringify!($field)),+];
            #[allow(unused_assignments)]
            fn value(&self, i: usize) -> T {
                let mut k = 0usize;
                $(
                    if i == k {
                        return self.$field;
                    }
                    k = k.wrapping_add(1);
                )+
                T::nan()
            }
            #[allow(unused_assignments)]
            fn set_value(&mut self, i: usize, v: T) -> bool {
                let mut k = 0usize;
                $(
                    if i == k {
                        self.$field = v;
                        return true;
                    }
                    k = k.wrapping_add(1);
                )+
                false
            }
            fn validate(&self) -> Result<(), $crate::Error> {
                $(
                    $crate::params::check(
                        $crate::params::Check::$check,
                        self.$field,
                        stringify!($field),
                    )?;
                )+
                Ok(())
            }
        }

        impl<T: $crate::Real> $name<T> {
            /// The same parameters in precision `U`.
            pub fn cast<U: $crate::Real>(&self) -> $name<U> {
                $name { $( $field: U::of(self.$field.f64()), )+ }
            }
        }
    };
}
pub(crate) use param_struct;

/// Declares a struct of figures (metrics, margins) whose report names are
/// its field names, as serde writes them, and `fields()`: each figure with
/// its name, in declaration order (the CSV columns, the text table,
/// Python's arrays). Every field is public, of one type, and ends with a
/// comma.
macro_rules! figures {
    (
        $(#[$meta:meta])*
        pub struct $name:ident $(<$t:ident>)? {
            $(#[$m0:meta])* pub $f0:ident: $ft:ty,
            $( $(#[$m:meta])* pub $field:ident: $ft_:ty, )*
        }
    ) => {
        $(#[$meta])*
        pub struct $name $(<$t>)? {
            $(#[$m0])* pub $f0: $ft,
            $( $(#[$m])* pub $field: $ft_, )*
        }

        impl $(<$t: Copy>)? $name $(<$t>)? {
            /// Every figure with its report name, in report order.
            pub fn fields(
                &self,
            ) -> [(&'static str, $ft); [stringify!($f0) $(, stringify!($field))*].len()] {
                [(stringify!($f0), self.$f0) $(, (stringify!($field), self.$field))*]
            }
        }
    };
}
pub(crate) use figures;

/// Declares a parameter struct (as [`param_struct!`]) whose fields others
/// begin with — the gains of a predictor's PID, a cascade's primary
/// controller — and the macro `$extend!` that declares those:
///
/// ```text
/// base_struct! { $ pid_params;
///     /// PID settings …
///     pub struct PidGains { kp: Finite, ti: Positive, td: NonNegative, }
/// }
/// pid_params! { /// Huang's … pub struct HuangParams { kb: Finite, tb: Positive, } }
/// ```
///
/// (`$` is passed in to write the inner macro's repetitions on stable Rust;
/// every base field ends with a comma.)
macro_rules! base_struct {
    (
        $d:tt $extend:ident;
        $(#[$meta:meta])* pub struct $name:ident { $($fields:tt)* }
    ) => {
        crate::params::param_struct! { $(#[$meta])* pub struct $name { $($fields)* } }

        macro_rules! $extend {
            ($d(#[$d m:meta])* pub struct $d n:ident { $d($d rest:tt)* }) => {
                crate::params::param_struct! {
                    $d(#[$d m])* pub struct $d n { $($fields)* $d($d rest)* }
                }
            };
        }
        #[allow(unused_imports)] // a family used only in its own module
        pub(crate) use $extend;
    };
}
pub(crate) use base_struct;

/// A scheme's design inputs: what its tuning rule reads besides the model
/// (implemented by the crate's `design_struct!` macro). Every scheme has the
/// closed-loop time constant `lambda` and its ratio to the dead time `alpha`;
/// the rest are the scheme's own (a filter's time constant, a case number…).
/// An absent input is `None`: the rule then uses its published default.
/// [`DesignSet::NAMES`] — generated from the fields — are the design keys
/// `--set` accepts before tuning.
pub trait DesignSet: Copy + Default + PartialEq + core::fmt::Debug {
    /// The field names, `lambda` and `alpha` first.
    const NAMES: &'static [&'static str];
    /// Sets the input called `name`; false if the type has no such field.
    fn set(&mut self, name: &str, v: f64) -> bool;
    /// The closed-loop time constant `λ` (s), if given.
    fn lambda(&self) -> Option<f64>;
    /// Gives the closed-loop time constant `λ` (s) (`--lambda`, which wins
    /// over `--set lambda=`).
    fn set_lambda(&mut self, lambda: f64);
    /// `λ/θ`, if given.
    fn alpha(&self) -> Option<f64>;
}

/// Declares a scheme's design-input struct: `lambda` and `alpha`, then the
/// listed fields, each an `Option<f64>` (serde with unknown keys refused):
///
/// ```text
/// design_struct! {
///     /// Design inputs of …
///     pub struct GpccTuning {
///         /// Time constant of `Fk` (s); default …
///         tk,
///     }
/// }
/// ```
macro_rules! design_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$fmeta:meta])* $field:ident ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
        pub struct $name {
            /// Closed-loop time constant `λ` (s); default `alpha·θ`.
            pub lambda: Option<f64>,
            /// `λ/θ` when `lambda` is not given (the scheme's default ratio otherwise).
            pub alpha: Option<f64>,
            $( $(#[$fmeta])* pub $field: Option<f64>, )*
        }

        impl $crate::params::DesignSet for $name {
            const NAMES: &'static [&'static str] = &["lambda", "alpha" $(, stringify!($field))*];
            fn set(&mut self, name: &str, v: f64) -> bool {
                let slot = match name {
                    "lambda" => &mut self.lambda,
                    "alpha" => &mut self.alpha,
                    $( stringify!($field) => &mut self.$field, )*
                    _ => return false,
                };
                *slot = Some(v);
                true
            }
            fn lambda(&self) -> Option<f64> {
                self.lambda
            }
            fn set_lambda(&mut self, lambda: f64) {
                self.lambda = Some(lambda);
            }
            fn alpha(&self) -> Option<f64> {
                self.alpha
            }
        }
    };
}
pub(crate) use design_struct;

/// Parameter names and values (up to [`MAX_PARAMS`]): the erased form of a
/// [`ParamSet`], which a controller keeps for [`crate::Introspect`] and the
/// registry hands between tuning, `--set` and construction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamList<T> {
    names: &'static [&'static str],
    values: [T; MAX_PARAMS],
}

impl<T: Real> Default for ParamList<T> {
    fn default() -> Self {
        ParamList {
            names: &[],
            values: [T::nan(); MAX_PARAMS],
        }
    }
}

impl<T: Real> ParamList<T> {
    /// The names and values of a typed parameter struct.
    pub fn of<P: ParamSet<T>>(p: &P) -> Self {
        let mut values = [T::nan(); MAX_PARAMS];
        for (i, v) in values.iter_mut().enumerate() {
            *v = p.value(i);
        }
        ParamList {
            names: P::NAMES,
            values,
        }
    }
    /// The same list in precision `U`.
    pub fn cast<U: Real>(&self) -> ParamList<U> {
        let mut values = [U::nan(); MAX_PARAMS];
        for (d, s) in values.iter_mut().zip(self.values.iter()) {
            *d = U::of(s.f64());
        }
        ParamList {
            names: self.names,
            values,
        }
    }
    /// The typed struct `P` (every field of `P` read by name).
    pub fn typed<P: ParamSet<T>>(&self) -> Result<P, Error> {
        P::from_list(self)
    }
    /// The names.
    pub fn names(&self) -> &'static [&'static str] {
        self.names
    }
    /// Value `i` (NaN if out of range).
    pub fn value(&self, i: usize) -> T {
        self.values.get(i).copied().unwrap_or(T::nan())
    }
    /// The value called `name`.
    pub fn get(&self, name: &str) -> Option<T> {
        self.names
            .iter()
            .position(|n| *n == name)
            .map(|i| self.value(i))
    }
    /// Sets the value called `name`; false if the list has no such name.
    pub fn set(&mut self, name: &str, v: T) -> bool {
        match self.names.iter().position(|n| *n == name) {
            Some(i) => match self.values.get_mut(i) {
                Some(slot) => {
                    *slot = v;
                    true
                }
                None => false,
            },
            None => false,
        }
    }
    /// `(name, value)` pairs in order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, T)> + '_ {
        self.names
            .iter()
            .enumerate()
            .map(|(i, n)| (*n, self.value(i)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    param_struct! {
        /// A test set.
        pub struct Two {
            /// First.
            kp: Positive,
            /// Second.
            td: NonNegative,
        }
    }

    #[test]
    fn names_come_from_the_fields() -> Result<(), Error> {
        assert_eq!(Two::<f64>::NAMES, &["kp", "td"]);
        let mut p = Two { kp: 2.0, td: 0.5 };
        assert_eq!(p.get("td"), Some(0.5));
        assert!(!p.set("ti", 1.0));
        assert!(p.set("kp", 3.0));
        assert_eq!(p.kp, 3.0);
        let l = ParamList::of(&p);
        assert_eq!(l.iter().collect::<Vec<_>>(), vec![("kp", 3.0), ("td", 0.5)]);
        let back: Two<f32> = l.typed()?;
        assert_eq!(
            back,
            Two {
                kp: 3.0f32,
                td: 0.5
            }
        );
        assert_eq!(back, p.cast::<f32>());
        assert_eq!(
            Two { kp: 0.0, td: 1.0 }.validate(),
            Err(Error::NotPositive("kp"))
        );
        assert_eq!(
            Two { kp: 1.0, td: -1.0 }.validate(),
            Err(Error::Negative("td"))
        );
        // a struct with a field the list lacks is refused by that field's name
        let short = ParamList::of(&Two { kp: 1.0, td: 0.0 });
        assert_eq!(
            short.typed::<crate::tuning::PidGains<f64>>(),
            Err(Error::Unsupported("ti"))
        );
        Ok(())
    }
}
