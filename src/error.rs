//! The typed construction error.

use core::fmt;

/// Why a block, controller or model could not be built.
///
/// Every variant names the offending field (the same name the parameter has in
/// reports, the CLI's `--set` and Python), so a message can point at it.
/// `Copy`, allocation-free and usable on bare metal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Error {
    /// The value is NaN or infinite.
    NonFinite(&'static str),
    /// The value must be strictly positive (a period, a time constant, a gain...).
    NotPositive(&'static str),
    /// The value must not be negative (a delay, a hysteresis...).
    Negative(&'static str),
    /// The value lies outside its documented range.
    OutOfRange(&'static str),
    /// A lower limit is above its upper limit.
    InvalidLimits(&'static str),
    /// A delay longer than the delay line's capacity.
    DelayTooLong(&'static str),
    /// A model order larger than the block's capacity.
    OrderTooHigh(&'static str),
    /// The transfer function is improper (numerator degree above denominator degree),
    /// or its leading denominator coefficient is zero.
    Improper(&'static str),
    /// The model or plant is of a kind this scheme or rule cannot handle.
    Unsupported(&'static str),
    /// A numerical design step failed (singular matrix, non-converging iteration).
    Numerical(&'static str),
    /// A column of data is not finite at a row (0-based).
    NonFiniteAt(&'static str, usize),
    /// A column of data does not increase at a row (0-based): a time that is
    /// not after the one before.
    NotIncreasing(&'static str, usize),
    /// The memory for this could not be allocated (the system refused it).
    OutOfMemory(&'static str),
}

impl Error {
    /// The name of the field or step the error refers to.
    pub fn field(&self) -> &'static str {
        match *self {
            Error::NonFinite(f)
            | Error::NotPositive(f)
            | Error::Negative(f)
            | Error::OutOfRange(f)
            | Error::InvalidLimits(f)
            | Error::DelayTooLong(f)
            | Error::OrderTooHigh(f)
            | Error::Improper(f)
            | Error::Unsupported(f)
            | Error::Numerical(f)
            | Error::NonFiniteAt(f, _)
            | Error::NotIncreasing(f, _)
            | Error::OutOfMemory(f) => f,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::NonFinite(n) => write!(f, "`{n}` must be a finite number"),
            Error::NotPositive(n) => write!(f, "`{n}` must be greater than zero"),
            Error::Negative(n) => write!(f, "`{n}` must not be negative"),
            Error::OutOfRange(n) => write!(f, "`{n}` is outside its allowed range"),
            Error::InvalidLimits(n) => write!(f, "`{n}`: the lower limit is above the upper limit"),
            Error::DelayTooLong(n) => {
                write!(f, "`{n}`: the delay is longer than the delay line's capacity")
            }
            Error::OrderTooHigh(n) => {
                write!(f, "`{n}`: the model order exceeds the block's capacity")
            }
            Error::Improper(n) => write!(
                f,
                "`{n}`: improper transfer function (numerator degree above denominator degree, or zero leading coefficient)"
            ),
            Error::Unsupported(n) => write!(f, "not supported: {n}"),
            Error::OutOfMemory(n) => write!(
                f,
                "`{n}`: the system could not provide the memory it needs"
            ),
            Error::Numerical(n) => write!(f, "numerical failure in {n}"),
            Error::NonFiniteAt(n, row) => {
                write!(f, "`{n}` is not a finite number at data row {}", row.saturating_add(1))
            }
            Error::NotIncreasing(n, row) => write!(
                f,
                "`{n}` must increase: data row {} is not after the row before",
                row.saturating_add(1)
            ),
        }
    }
}

impl core::error::Error for Error {}
