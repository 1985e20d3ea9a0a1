//! The scheme in use and a rebuilt one warming up beside it, in two places
//! that trade roles by a flag: a scheme's takeover does not copy it (on a
//! Cortex-M4F a predictor with its line inline is hundreds of bytes, whose
//! copy alone went past a sample's budget of 3 000 instructions; #48
//! item 7).

use core::ops::{Deref, DerefMut};

/// Two places for a scheme: the one in use (read through `Deref`) and the
/// spare (none until a scheme is first rebuilt).
#[derive(Debug, Clone)]
#[repr(C)]
pub(super) struct Slots<C> {
    /// The second place holds the scheme in use (first: what every
    /// sample reads, then the place it reads).
    in_second: bool,
    first: C,
    second: Option<C>,
}

impl<C> Slots<C> {
    pub(super) fn new(c: C) -> Self {
        Slots {
            in_second: false,
            first: c,
            second: None,
        }
    }

    /// The scheme in the spare place, if any (it may be one replaced
    /// before: only the supervisor's shadow says it is warming up).
    pub(super) fn spare_mut(&mut self) -> Option<&mut C> {
        if self.in_second {
            Some(&mut self.first)
        } else {
            self.second.as_mut()
        }
    }

    /// Only the scheme in use stays, in the first place (moved there where
    /// it was in the second: a rebuild's call can afford the move, an
    /// update, which only swaps, makes none), the spare dropped: a
    /// redesign that lends memory to its schemes has the one in use alone
    /// alive when it builds the next ([`super::Redesign::rebuild`]).
    pub(super) fn clear_spare(&mut self) {
        if self.in_second {
            if let Some(c) = self.second.take() {
                self.first = c;
            }
            self.in_second = false;
        } else {
            self.second = None;
        }
    }

    /// `c` into the spare place.
    pub(super) fn set_spare(&mut self, c: C) {
        if self.in_second {
            self.first = c;
        } else {
            self.second = Some(c);
        }
    }

    /// The spare takes over (where there is one).
    pub(super) fn swap(&mut self) {
        if self.second.is_some() {
            self.in_second = !self.in_second;
        }
    }
}

impl<C> Deref for Slots<C> {
    type Target = C;

    fn deref(&self) -> &C {
        match (&self.second, self.in_second) {
            (Some(c), true) => c,
            _ => &self.first,
        }
    }
}

impl<C> DerefMut for Slots<C> {
    /// The place in use, chosen once: inlined freely into the scheme's
    /// update, the choice was made again at each of the scheme's field
    /// accesses (on x86 a load from both places and a `cmov` each), so the
    /// place passes through `black_box` (the optimizer sees one pointer,
    /// whatever it is) and the update reads one place. Measured (callgrind,
    /// the bench's loop): 530 → 452 instructions a sample in a call of its
    /// own, 8 fewer inline behind `black_box`.
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut C {
        let c = match (&mut self.second, self.in_second) {
            (Some(c), true) => c,
            _ => &mut self.first,
        };
        core::hint::black_box(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The places trade roles: the scheme set spare is the one in use
    /// after a swap, the one before it the spare, and so on alternately;
    /// without a spare a swap changes nothing.
    #[test]
    fn the_spare_takes_over_and_the_places_alternate() {
        let mut s = Slots::new(1);
        s.swap();
        assert_eq!((*s, s.spare_mut().copied()), (1, None));
        s.set_spare(2);
        assert_eq!((*s, s.spare_mut().copied()), (1, Some(2)));
        s.swap();
        assert_eq!((*s, s.spare_mut().copied()), (2, Some(1)));
        s.set_spare(3);
        *s += 10;
        assert_eq!((*s, s.spare_mut().copied()), (12, Some(3)));
        s.swap();
        assert_eq!((*s, s.spare_mut().copied()), (3, Some(12)));
        // the one in use alone, whichever place it was in
        s.clear_spare();
        assert_eq!((*s, s.spare_mut().copied()), (3, None));
        s.set_spare(4);
        s.swap();
        s.clear_spare();
        assert_eq!((*s, s.spare_mut().copied()), (4, None));
        s.clear_spare();
        assert_eq!((*s, s.spare_mut().copied()), (4, None));
    }
}
