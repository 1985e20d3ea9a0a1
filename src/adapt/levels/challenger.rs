//! The level test's challenger: a model the supervisor has it weigh
//! against the model in use (the bank's settled estimate, where the
//! differences cannot yet tell it from the model in use).

use super::*;

/// A model the supervisor has the level test weigh against the model in
/// use: its model `(K, τ, θ)`, coefficients and dead time; Page's sum of its
/// evidence over the model in use and the responses in a row it explained
/// better; whether its fit began with the response under way (one set
/// during a response weighs the responses after it).
#[derive(Debug, Clone, Copy)]
pub(super) struct Challenger<T> {
    pub(super) model: (T, T, T),
    pub(super) coef: [T; 3],
    pub(super) d: usize,
    pub(super) sum: T,
    pub(super) streak: u8,
    pub(super) whole: bool,
}

impl<T: Real, const N: usize, const H: usize> Estimator<T, N, H> {
    /// The model `(K, τ, θ)` for the level test to weigh against the model
    /// in use over the responses to come, as it weighs a hypothesis (its
    /// own Page's sum; [`Estimator::challenger`]). A model within `tol`
    /// (relative, the same dead time) of the challenger already weighed
    /// keeps it and its evidence; one the estimator cannot weigh (a dead
    /// time beyond the history) is none.
    pub(crate) fn challenge(&mut self, (k, tau, theta): (T, T, T), tol: T) {
        let Ok((d, coef)) = self.coefficients(k, tau, theta) else {
            self.levels.challenger = None;
            return;
        };
        let kept = self.levels.challenger.is_some_and(|c| {
            let (ck, ctau, _) = c.model;
            c.d == d && near(ck, k, tol) && near(ctau, tau, tol)
        });
        if !kept {
            self.levels.challenger = Some(Challenger {
                model: (k, tau, theta),
                coef,
                d,
                sum: T::zero(),
                streak: 0,
                whole: false,
            });
        }
    }

    /// The challenger ([`Estimator::challenge`]) once the level test has
    /// the evidence for it over the model in use that it asks of a
    /// hypothesis ([`LEVEL_EVIDENCE`], and it explained the last two
    /// responses to the noise better than the model in use).
    pub(crate) fn challenger(&self) -> Option<(T, T, T)> {
        if self.levels.ramping() {
            return None;
        }
        self.levels
            .challenger
            .filter(|c| c.sum >= T::of(LEVEL_EVIDENCE) && c.streak >= 2)
            .map(|c| c.model)
    }
}
