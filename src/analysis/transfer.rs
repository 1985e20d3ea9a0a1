//! The controller's and the loop's transfer functions as coefficient lists
//! (`msp tune --json`'s `transfer`, Python's `Controller.to_control()`).

use std::vec::Vec;

use crate::lti::zdomain::Rational;
use crate::poly::TransferFunction;
use crate::{controller::FrequencyResponse, error::Error};

/// A discrete transfer function `num(z)/den(z)`, descending powers of `z`
/// and both lists of one length, as MATLAB's `tf(num, den, Ts)` and
/// python-control's `TransferFunction(num, den, dt)` take them.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Coefficients {
    /// Numerator.
    pub num: Vec<f64>,
    /// Denominator.
    pub den: Vec<f64>,
}

impl From<&Rational> for Coefficients {
    fn from(r: &Rational) -> Self {
        let (num, den) = r.in_z();
        Coefficients { num, den }
    }
}

/// A controller's linear parts `u = Cr·r − Cy·y` and, with the plant
/// sampled exactly at `ts` (ZOH, its dead time as powers of `z^{−1}`, a
/// fraction of a sample by the modified z-transform), the loop
/// `L = Cy·P`, `S = 1/(1 + L)` and `T = L/(1 + L)`. Exact: the blocks'
/// own polynomials composed as the controller composes them; a factor
/// common to a numerator and a denominator cancels when it is the same
/// block's.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Transfer {
    /// The sample period (s).
    pub ts: f64,
    /// The set-point path `Cr`.
    pub cr: Coefficients,
    /// The feedback path `Cy`.
    pub cy: Coefficients,
    /// The sampled plant `P` (absent for a cascade, whose outer loop runs
    /// through the inner one).
    pub plant: Option<Coefficients>,
    /// The loop `L = Cy·P`.
    pub l: Option<Coefficients>,
    /// The sensitivity `S = 1/(1 + L)`.
    pub s: Option<Coefficients>,
    /// The complementary sensitivity `T = L/(1 + L)`.
    pub t: Option<Coefficients>,
}

/// The transfer functions of `controller` (at period `ts`) and of its loop
/// with `plant`; `None` for a controller that gives none.
pub fn transfer(
    controller: &dyn FrequencyResponse<f64>,
    plant: Option<&TransferFunction>,
    ts: f64,
) -> Result<Option<Transfer>, Error> {
    let Some((cr, cy)) = controller.transfer() else {
        return Ok(None);
    };
    let (mut p, mut l, mut s, mut t) = (None, None, None, None);
    if let Some(plant) = plant {
        let pd = super::DiscretePlant::new(plant, ts)?.transfer();
        let one = Rational::constant(1.0);
        let loop_ = cy.clone() * pd.clone();
        let den = one.clone() + loop_.clone();
        p = Some(Coefficients::from(&pd));
        s = Some(Coefficients::from(&(one / den.clone())));
        t = Some(Coefficients::from(&(loop_.clone() / den)));
        l = Some(Coefficients::from(&loop_));
    }
    Ok(Some(Transfer {
        ts,
        cr: Coefficients::from(&cr),
        cy: Coefficients::from(&cy),
        plant: p,
        l,
        s,
        t,
    }))
}
