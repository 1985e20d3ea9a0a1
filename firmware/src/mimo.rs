// The 2×2 loops, written once for f32 (firmware) and f64 (host reference,
// included by build.rs): the Wood–Berry column (Wood & Berry 1973, minutes)
// sampled at 1 min, each channel an exact ZOH block with its dead time in a
// line, under decentralized Smith predictors and under the decoupled ones
// (an inverted decoupler, msp::mimo::fopdt_element).

use msp::mimo::{fopdt_element, Decentralized, Decoupled, InvertedDecoupler, MultiController};
use msp::{Delay, DelayLine, Fopdt, Lti, PidConfig, ProcessModel, Real, SmithPredictor};

pub const SAMPLES: usize = 2_000;
pub const CHECKS: usize = 20;
/// Delay lines' room (samples): the longest dead time is 7.
pub const ROOM: usize = 8;

/// `(K, τ, θ)` of `g11, g12, g21, g22`.
const WOOD_BERRY: [(f64, f64, f64); 4] = [
    (12.8, 16.7, 1.0),
    (-18.9, 21.0, 3.0),
    (6.6, 10.9, 7.0),
    (-19.4, 14.4, 3.0),
];

pub type Sp<T> = SmithPredictor<T, 1, [T; ROOM]>;
pub type DecentralizedSmith<T> = Decentralized<Sp<T>, [Sp<T>; 2]>;
pub type DecoupledSmith<T> = Decoupled<T, Sp<T>, 2, 2, [T; ROOM]>;

fn fail() -> ! {
    panic!("mimo model")
}

fn fopdt<T: Real>(i: usize) -> Fopdt<T> {
    let (k, t, l) = WOOD_BERRY[i];
    match Fopdt::new(T::of(k), T::of(t), T::of(l)) {
        Ok(f) => f,
        Err(_) => fail(),
    }
}

/// Loop `i`'s Smith predictor on `gᵢᵢ`, its PI for `λ = 2θᵢᵢ` (Kaya 2003:
/// `Kc = τ/(K·λ)`, `τI = τ`).
fn smith<T: Real>(i: usize) -> Sp<T> {
    let g = fopdt::<T>(i * 3);
    let lambda = T::of(2.0) * g.l;
    let pi = PidConfig::isa(g.t / (g.k * lambda), g.t, T::zero(), T::one());
    match SmithPredictor::from_model(pi, &ProcessModel::from(g), T::one()) {
        Ok(c) => c,
        Err(_) => fail(),
    }
}

pub fn decentralized<T: Real>() -> (DecentralizedSmith<T>, Plant<T>) {
    (Decentralized::new([smith(0), smith(1)]), Plant::new())
}

pub fn decoupled<T: Real>() -> (DecoupledSmith<T>, Plant<T>) {
    let el = |i: usize, j: usize| match fopdt_element(
        &fopdt::<T>(i * 2 + j),
        &fopdt::<T>(i * 3),
        T::one(),
        [T::zero(); ROOM],
    ) {
        Ok(e) => Some(e),
        Err(_) => fail(),
    };
    let d = match InvertedDecoupler::new([[None, el(0, 1)], [el(1, 0), None]]) {
        Ok(d) => d,
        Err(_) => fail(),
    };
    (Decoupled::new([smith(0), smith(1)], d), Plant::new())
}

/// The column: four channels, output `i` the sum of row `i`.
pub struct Plant<T: Real> {
    channels: [(Lti<T, 1>, DelayLine<T, ROOM>); 4],
}

impl<T: Real> Plant<T> {
    fn new() -> Self {
        let ch = |i: usize| {
            let m = ProcessModel::from(fopdt::<T>(i));
            let (block, d) = match m.discretize::<1>(T::one()) {
                Ok(x) => x,
                Err(_) => fail(),
            };
            match Delay::new(d) {
                Ok(line) => (block, line),
                Err(_) => fail(),
            }
        };
        Plant {
            channels: [ch(0), ch(1), ch(2), ch(3)],
        }
    }
    pub fn outputs(&self) -> [T; 2] {
        let y = |i: usize| self.channels[i].0.free_output();
        [y(0) + y(1), y(2) + y(3)]
    }
    pub fn advance(&mut self, u: [T; 2]) {
        for (i, (block, line)) in self.channels.iter_mut().enumerate() {
            block.step(line.process(u[i % 2]));
        }
    }
}

/// Runs the loop: loop 1's set point steps to 1 at 0 and loop 2's to 1 at
/// a third of the run, a load of −0.1 at input 1 from two thirds; `tick`
/// around each update. Returns `y1` then `y2` at `CHECKS/2` samples each.
pub fn run_mimo<T: Real, C>(
    c: &mut C,
    p: &mut Plant<T>,
    mut tick: impl FnMut(bool),
    mut update: impl FnMut(&mut C, &[T; 2], &[T; 2], &mut [T; 2]),
) -> [T; CHECKS] {
    let mut out = [T::zero(); CHECKS];
    let mut u = [T::zero(); 2];
    let every = SAMPLES / (CHECKS / 2);
    for k in 0..SAMPLES {
        let r = [
            T::one(),
            if k >= SAMPLES / 3 {
                T::one()
            } else {
                T::zero()
            },
        ];
        let y = p.outputs();
        tick(true);
        update(c, &r, &y, &mut u);
        tick(false);
        let load = if k >= 2 * SAMPLES / 3 {
            T::of(-0.1)
        } else {
            T::zero()
        };
        p.advance([u[0] + load, u[1]]);
        if (k + 1) % every == 0 {
            let at = (k + 1) / every - 1;
            out[at] = y[0];
            out[CHECKS / 2 + at] = y[1];
        }
    }
    out
}

/// [`run_mimo`] through the trait, for the host's reference.
#[allow(dead_code)] // build.rs runs it
pub fn run<T: Real, C: MultiController<T>>(c: &mut C, p: &mut Plant<T>) -> [T; CHECKS] {
    run_mimo(c, p, |_| {}, |c, r, y, u| c.update(r, y, u))
}
