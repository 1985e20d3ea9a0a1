//! How a scheme is redesigned for a new model.

/// How a scheme `C` is redesigned for a model `(K, τ, θ)` (`τ` infinite:
/// integrating) by its own rule at the same λ policy.
///
/// A scheme whose model can change at run time ([`crate::Operate::set_model`]:
/// the Smith predictor) keeps its blocks and takes the primary's new gains
/// `[Kp, Ti, Td]` ([`Redesign::gains`]; `None` keeps them): any
/// `FnMut(K, τ, θ) -> Option<[T; 3]>` is one (a `fn` on a device, a
/// closure over the registry's tuning on a host), and `()` never retunes.
/// A scheme whose other blocks are designed from its model (the
/// compensator family, Karan–Dey, the filtered Smith predictor) is built
/// anew ([`Redesign::rebuild`], e.g. [`Rebuild`]): the new one runs beside
/// the old on the same measurements, tracking the output the plant
/// receives ([`crate::Operate::apply`]), until its model's dead time and four time
/// constants have passed (its lines and states hold the loop's history),
/// then takes over from that output (its integral where the tracking left
/// it; its own law from then on, as after a bumpless return to automatic).
pub trait Redesign<T, C> {
    /// The primary's gains for the model.
    fn gains(&mut self, k: T, tau: T, theta: T) -> Option<[T; 3]> {
        let _ = (k, tau, theta);
        None
    }

    /// The scheme designed for the model. It is asked for only while no
    /// scheme it built before is warming up: the one in use and the new one
    /// are the only two alive (a redesign that lends memory to the schemes
    /// it builds needs two lots, alternately).
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<C> {
        let _ = (k, tau, theta);
        None
    }

    /// The scheme it built last has taken over: the one it replaced is
    /// gone (its memory free for the next [`Redesign::rebuild`]).
    fn took_over(&mut self) {}

    /// The dead time (s) of the scheme it built last, where that scheme
    /// runs another than the one asked for and cannot say so itself
    /// ([`crate::Operate::dead_time`] is `None` for a scheme whose dead time is
    /// fixed when it is built): the model in use, its log and its verdict
    /// carry the dead time the loop runs.
    fn built_dead_time(&self) -> Option<T> {
        None
    }
}

impl<T, C, F: FnMut(T, T, T) -> Option<[T; 3]>> Redesign<T, C> for F {
    fn gains(&mut self, k: T, tau: T, theta: T) -> Option<[T; 3]> {
        self(k, tau, theta)
    }
}

impl<T, C> Redesign<T, C> for () {}

/// A redesign that builds the scheme anew: `F(K, τ, θ)` is the scheme
/// designed for the model ([`Redesign::rebuild`]).
#[derive(Debug, Clone, Copy)]
pub struct Rebuild<F>(pub F);

impl<T, C, F: FnMut(T, T, T) -> Option<C>> Redesign<T, C> for Rebuild<F> {
    fn rebuild(&mut self, k: T, tau: T, theta: T) -> Option<C> {
        (self.0)(k, tau, theta)
    }
}
