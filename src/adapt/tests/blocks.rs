//! The estimator's blocks: the input as the block means see it, and the
//! learning spread over the calls after a block.

use super::super::*;
use super::drive_dead_time_step;
use crate::test_util::ExpectOk;

/// A block's learning spread over the controller samples after the block
/// (two halves of the bank, then the detector and the choice) is the
/// learning of one call: an estimator decimating by 10 and one fed the
/// same block means one by one (with the block's input as the means see
/// it, `x_k = (Σ_p (p + 1)·u_{(k−1)10+p} + Σ_p (9 − p)·u_{10k+p})/100`, a
/// block older: [`Estimator::update`]) hold the same estimate (its dead
/// time a block shorter), costs and evidence bit for bit after every pass (the first when its last part ends, two
/// samples after the block), with a prior model and without, through a
/// dead-time step (the detector's restart) and under noise.
#[test]
fn spread_learning_is_the_learning_of_one_call() {
    for prior in [None, Some((1.5, 4.0, 1.2))] {
        let ts = 0.01;
        let mut fine = EstimatorConfig::new(ts, 2);
        fine.decimation = 10;
        let coarse = EstimatorConfig::new(ts * 10.0, 2);
        let mut spread: Estimator<f64, 16, 40> = Estimator::new(fine).expect_ok();
        let mut whole: Estimator<f64, 16, 40> = Estimator::new(coarse).expect_ok();
        if let Some((k, tau, theta)) = prior {
            spread.start_from(k, tau, theta).expect_ok();
            whole.start_from(k, tau, theta - fine.lag()).expect_ok();
        }
        // (`Σy`, `Σu`, `Σ_p Σ_{i<p} u_i` and the block before's rising side)
        let (mut sums, mut partial, mut before) = ((0.0f64, 0.0f64), 0.0f64, None);
        let mut passes = 0;
        drive_dead_time_step(7, |j, ym, u| {
            partial += sums.1;
            sums = (sums.0 + ym, sums.1 + u);
            if j % 10 == 9 {
                let inv = 1.0 / 10.0;
                let rising = 10.0 * sums.1 - partial;
                // (the first block has none before it: not learnt from)
                let (rising_before, ok) = before.map_or((rising, false), |r| (r, true));
                whole.update(sums.0 * inv, (rising_before + partial) * inv * inv, ok);
                before = Some(rising);
                (sums, partial) = ((0.0, 0.0), 0.0);
            }
            if spread.update(ym, u, true) {
                passes += 1;
                let (s, w) = (spread.estimate(), whole.estimate());
                assert_eq!(
                    s.map(|s| (s.k, s.tau, s.d, s.evidence.to_bits())),
                    w.map(|w| (w.k, w.tau, w.d, w.evidence.to_bits())),
                    "sample {j}"
                );
                let shorter = s.map(|s| s.theta - fine.lag());
                assert!(shorter
                    .zip(w)
                    .is_none_or(|(s, w)| (s - w.theta).abs() < 1e-12));
                assert!(spread.costs().eq(whole.costs()), "sample {j}");
                assert_eq!(spread.restarts(), whole.restarts());
            }
        });
        assert!(passes >= 3990, "{passes}");
        assert!(
            whole.restarts() >= 1,
            "the detector's restart is in the run"
        );
    }
}

/// `K e^{−θs}/s` (`integrating`) or `K e^{−θs}/(τs + 1)` sampled exactly
/// every `ts = 0.01` under a PI controller, the set point stepping between
/// 0 and 1 every `every` samples, without noise; the estimator decimating
/// by 10 from the true model: its largest relative error on the gain (and
/// lag) and absolute on the dead time (s) over the run's last half.
fn worst_error(integrating: bool, theta: f64, every: usize) -> (f64, f64) {
    let (ts, k, tau, m) = (0.01, 0.15, 2.0, 10usize);
    let d = (theta / ts).round() as usize;
    let mut cfg = EstimatorConfig::new(ts, 2);
    cfg.decimation = m;
    cfg.integrating = integrating;
    let mut est: Estimator<f64, 16, 40> = Estimator::new(cfg).expect_ok();
    let tau_model = if integrating { f64::INFINITY } else { tau };
    est.start_from(k, tau_model, theta).expect_ok();
    // (the PI of a fifth of the dead time's closed loop, its kick kp·Δr)
    let (kp, ti) = if integrating {
        (1.0 / (k * theta), 4.0 * theta)
    } else {
        (tau / (k * theta), tau)
    };
    let a = (-ts / tau).exp();
    let (mut y, mut integral, mut line) = (0.0f64, 0.0f64, vec![0.0f64; d]);
    let (mut gain, mut dead) = (0.0f64, 0.0f64);
    let n = 200 * every;
    for j in 0..n {
        let r = ((j / every) % 2) as f64;
        let e = r - y;
        integral += kp * ts / ti * e;
        let u = kp * e + integral;
        est.update(y, u, true);
        if j > n / 2 {
            let s = est.estimate().expect_ok();
            let lag = if integrating {
                0.0
            } else {
                (s.tau / tau - 1.0).abs()
            };
            gain = gain.max((s.k / k - 1.0).abs()).max(lag);
            dead = dead.max((s.theta - theta).abs());
        }
        let late = line[j % d];
        line[j % d] = u;
        y = if integrating {
            y + k * ts * late
        } else {
            a * y + k * (1.0 - a) * late
        };
    }
    (gain, dead)
}

/// The block's input as its means see it (`Estimator::update`): set-point
/// steps at every phase of a block (every 4 003 samples, blocks of 10), no
/// noise. An integrating process of a whole number of blocks of dead time
/// is learnt exactly (its gain to 10⁻⁶, its dead time to 10⁻⁶ s; with the
/// input's plain block means 11 to 27 % high, measured). Of a fraction of
/// a block more (a fifth, a half, four fifths) the two input coefficients
/// share the fraction by interpolation, which a step's triangle within a
/// block does not follow: the gain within 12 % at worst (6 to 11 %,
/// measured: what remains of the kick's bias), the dead time within a
/// twentieth of a block. A lag of twenty blocks: within 0.1 % and 2 %.
#[test]
fn the_block_means_obey_the_model_whatever_the_steps_phase() {
    let (gain, dead) = worst_error(true, 1.0, 4003);
    assert!(gain < 1e-6 && dead < 1e-6, "{gain} {dead}");
    for theta in [1.02, 1.05, 1.08] {
        let (gain, dead) = worst_error(true, theta, 4003);
        assert!(gain < 0.12 && dead < 0.005, "{theta}: {gain} {dead}");
    }
    let (gain, dead) = worst_error(false, 1.0, 4003);
    assert!(gain < 0.001 && dead < 0.001, "{gain} {dead}");
    let (gain, dead) = worst_error(false, 1.05, 4003);
    assert!(gain < 0.02 && dead < 0.005, "{gain} {dead}");
}

/// The decimation for a model's dead time (`EstimatorConfig::decimation_for`):
/// about a tenth of it, a whole number of blocks where the dead time is a
/// whole number of samples with a divisor giving 8 to 10 blocks (the
/// smallest such divisor), else `⌈dead/10⌉`.
#[test]
fn the_decimation_makes_the_dead_time_whole_blocks_where_it_can() {
    let m = EstimatorConfig::<f64>::decimation_for;
    assert_eq!((m(1000.0), m(954.0), m(10.0), m(7.0)), (100, 106, 1, 1));
    // (not a whole number of samples; 997 is prime)
    assert_eq!(
        (m(1050.66), m(997.0), m(f64::NAN), m(-3.0)),
        (106, 100, 1, 1)
    );
    for n in 10..3000usize {
        let d = m(n as f64);
        let divisor = (n.div_ceil(10)..=n / 8).find(|k| n % k == 0);
        match divisor {
            Some(k) => assert!(d == k && (8..=10).contains(&(n / d)), "{n}: {d}"),
            None => assert_eq!(d, n.div_ceil(10), "{n}"),
        }
    }
}
