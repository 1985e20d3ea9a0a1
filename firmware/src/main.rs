//! The Karan–Dey MSP, the classic Smith predictor and the filtered Smith
//! predictor for an unstable plant (its `Fr` and `S` designed on the device)
//! in f32 on a Cortex-M4F, each against a simulated plant for 10 000 samples,
//! checked against the host's f64 run (relative difference below 1e-4, 1e-3
//! for the unstable plant and the adaptive predictor), with the instructions per update counted by
//! SysTick (QEMU `-icount shift=0`: one instruction per nanosecond, so one
//! 25 MHz tick per 40 instructions), read around every call. `scripts/firmware`
//! checks these figures against an exact count: each update single-stepped
//! under QEMU's gdb stub (`count.py`).
#![no_std]
#![no_main]

mod adaptive;
mod loops;
mod mimo;

mod reference {
    include!(concat!(env!("OUT_DIR"), "/reference.rs"));
}

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};

macro_rules! nops4 {
    () => {
        cortex_m::asm::nop();
        cortex_m::asm::nop();
        cortex_m::asm::nop();
        cortex_m::asm::nop();
    };
}
macro_rules! nops64 {
    () => {
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
        nops4!();
    };
}

/// Instructions per SysTick tick: QEMU's SysTick runs at the board clock
/// (25 MHz) while `-icount shift=0` executes one instruction per nanosecond, so
/// a tick is about 40 instructions; measured on 4096 straight-line `nop`s.
fn instructions_per_tick() -> f64 {
    let t0 = cortex_m::peripheral::SYST::get_current();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    nops64!();
    let t1 = cortex_m::peripheral::SYST::get_current();
    let ticks = t0.wrapping_sub(t1) & 0x00FF_FFFF;
    4096.0 / f64::from(ticks.max(1))
}

fn check(name: &str, got: &[f32], want: &[f64], tol: f64, instructions: f64, ram: usize) -> bool {
    let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
    let worst = got
        .iter()
        .zip(want)
        .fold(0.0f64, |m, (g, w)| m.max((f64::from(*g) - w).abs() / scale));
    let ok = worst < tol;
    hprintln!(
        "{}: max relative difference to the host's f64 run {:e} ({}); {:.0} instructions per update; controller RAM {} bytes",
        name,
        worst,
        if ok { "ok" } else { "FAIL" },
        instructions,
        ram
    );
    ok
}

/// An update that does nothing, for the measurement's overhead.
#[inline(never)]
fn empty_update(_c: &mut msp::SmithPredictor<f32, 1, [f32; loops::CAP]>, r: f32, _y: f32) -> f32 {
    // an empty barrier: the call stays a call
    // SAFETY: no instructions, no operands
    unsafe { core::arch::asm!("", options(nomem, nostack, preserves_flags)) };
    r
}

/// 64 instructions of work, to check the measurement.
#[inline(never)]
fn nop_update(_c: &mut msp::SmithPredictor<f32, 1, [f32; loops::CAP]>, r: f32, _y: f32) -> f32 {
    nops64!();
    r * 0.0
}

macro_rules! fma8 {
    ($x:ident, $a:ident, $b:ident) => {
        $x = $x * $a + $b;
        $x = $x * $a + $b;
        $x = $x * $a + $b;
        $x = $x * $a + $b;
        $x = $x * $a + $b;
        $x = $x * $a + $b;
        $x = $x * $a + $b;
        $x = $x * $a + $b;
    };
}

/// 64 dependent floating-point multiply-adds, to check how VFP code is counted.
#[inline(never)]
fn fma_update(_c: &mut msp::SmithPredictor<f32, 1, [f32; loops::CAP]>, r: f32, y: f32) -> f32 {
    let (a, b) = (
        core::hint::black_box(0.999f32),
        core::hint::black_box(0.001f32),
    );
    let mut x = y;
    fma8!(x, a, b);
    fma8!(x, a, b);
    fma8!(x, a, b);
    fma8!(x, a, b);
    fma8!(x, a, b);
    fma8!(x, a, b);
    fma8!(x, a, b);
    fma8!(x, a, b);
    x * 0.0 + r * 0.0
}

/// The Smith predictor's PID alone, for the cost breakdown.
#[inline(never)]
fn pid_update(c: &mut msp::SmithPredictor<f32, 1, [f32; loops::CAP]>, r: f32, y: f32) -> f32 {
    c.pid_mut().update(r, y)
}

/// A 2×2 update that does nothing, for the multivariable harness's overhead.
#[inline(never)]
fn mimo_empty(_c: &mut mimo::DecoupledSmith<f32>, r: &[f32; 2], _y: &[f32; 2], u: &mut [f32; 2]) {
    // SAFETY: no instructions, no operands
    unsafe { core::arch::asm!("", options(nomem, nostack, preserves_flags)) };
    *u = *r;
}

/// One update of the decentralized Smith predictors (2×2, Wood–Berry).
#[inline(never)]
fn decentralized_update(
    c: &mut mimo::DecentralizedSmith<f32>,
    r: &[f32; 2],
    y: &[f32; 2],
    u: &mut [f32; 2],
) {
    use msp::mimo::MultiController;
    c.update(r, y, u);
}

/// One update of the decoupled Smith predictors (2×2, Wood–Berry).
#[inline(never)]
fn decoupled_update(
    c: &mut mimo::DecoupledSmith<f32>,
    r: &[f32; 2],
    y: &[f32; 2],
    u: &mut [f32; 2],
) {
    use msp::mimo::MultiController;
    c.update(r, y, u);
}

/// A 2×2 loop of [`mimo`] run with SysTick around each update: its RAM, its
/// outputs at the checkpoints and the mean ticks per call.
fn measured_mimo<C>(
    (mut c, mut plant): (C, mimo::Plant<f32>),
    update: impl FnMut(&mut C, &[f32; 2], &[f32; 2], &mut [f32; 2]),
) -> (usize, [f32; mimo::CHECKS], f64) {
    let ram = core::mem::size_of_val(&c);
    let mut ticks = Ticks::default();
    let y = mimo::run_mimo(&mut c, &mut plant, |b| ticks.tick(b), update);
    (ram, y, ticks.mean(mimo::SAMPLES))
}

/// One Smith-predictor update, kept out of line so its size is its own symbol.
#[inline(never)]
fn smith_update(c: &mut msp::SmithPredictor<f32, 1, [f32; loops::CAP]>, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

/// One Karan–Dey MSP update, kept out of line so its size is its own symbol.
#[inline(never)]
fn karan_dey_update(c: &mut msp::KaranDey<f32, 1, [f32; loops::CAP]>, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

/// One filtered-Smith-predictor update, kept out of line so its size is its own symbol.
#[inline(never)]
fn fsp_update(c: &mut msp::dtc::fsp::FilteredSmith<f32, [f32; loops::CAP]>, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

/// One update of the adaptive Smith predictor (a bank of 16 candidate dead
/// times). Not named `*_update`: its cost varies from sample to sample (it
/// learns while the input moves), so its mean is not compared with the
/// single-stepped count of one call, which scripts/firmware takes as the
/// learning path's.
#[inline(never)]
fn adaptive_step(c: &mut loops::AdaptiveSmith<f32>, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

/// Mean SysTick ticks per update over a run: the counter is read right before
/// and right after each call (the counter counts down from 2^24 − 1). A tick is
/// about 40 instructions, so before each call a spin of 0–40 `nop` iterations
/// (3 instructions each, coprime to 40) moves the phase of the reads across the
/// tick: the quantization then averages out instead of biasing every call alike.
fn per_call<C>(
    c: &mut C,
    plant: &mut loops::Plant<f32>,
    update: impl FnMut(&mut C, f32, f32) -> f32,
) -> ([f32; loops::CHECKS], f64, (u32, usize)) {
    let mut ticks = Ticks::default();
    let y = loops::run_with(c, plant, |before| ticks.tick(before), update);
    (y, ticks.mean(loops::SAMPLES), (ticks.max, ticks.max_at))
}

/// A loop built by `loops` run through [`per_call`]: the controller's RAM,
/// its outputs at the checkpoints and the mean SysTick per call.
fn measured<C>(
    (c, plant): (C, loops::Plant<f32>),
    update: impl FnMut(&mut C, f32, f32) -> f32,
) -> (usize, [f32; loops::CHECKS], f64) {
    let (ram, y, t, _) = measured_max((c, plant), update);
    (ram, y, t)
}

/// [`measured`] with the most ticks one call took and the call's number.
fn measured_max<C>(
    (mut c, mut plant): (C, loops::Plant<f32>),
    update: impl FnMut(&mut C, f32, f32) -> f32,
) -> (usize, [f32; loops::CHECKS], f64, (u32, usize)) {
    let ram = core::mem::size_of_val(&c);
    let (y, t, max) = per_call(&mut c, &mut plant, update);
    (ram, y, t, max)
}

/// SysTick read around calls (see [`per_call`]).
#[derive(Default)]
struct Ticks {
    t0: u32,
    sum: u64,
    spin: u32,
    /// The most ticks one call took, and the call's number.
    max: u32,
    max_at: usize,
    calls: usize,
}

impl Ticks {
    /// Before (`true`) or after a call.
    fn tick(&mut self, before: bool) {
        use core::sync::atomic::{compiler_fence, Ordering::SeqCst};
        if before {
            self.spin = (self.spin + 1) % 41;
            for _ in 0..core::hint::black_box(self.spin) {
                cortex_m::asm::nop();
            }
            compiler_fence(SeqCst);
            self.t0 = cortex_m::peripheral::SYST::get_current();
            compiler_fence(SeqCst);
        } else {
            compiler_fence(SeqCst);
            let t1 = cortex_m::peripheral::SYST::get_current();
            compiler_fence(SeqCst);
            let t = self.t0.wrapping_sub(t1) & 0x00FF_FFFF;
            self.sum += u64::from(t);
            if t > self.max {
                (self.max, self.max_at) = (t, self.calls);
            }
            self.calls += 1;
        }
    }

    /// Mean ticks per call over `calls`.
    fn mean(&self, calls: usize) -> f64 {
        self.sum as f64 / calls as f64
    }
}

/// One update of the Smith predictor operated as in a plant (`msp::Operated`:
/// modes, external reset, run-time dead time around the same predictor).
#[inline(never)]
fn operated_update(c: &mut loops::OperatedSmith<f32>, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

/// The switch from manual back to automatic.
#[inline(never)]
fn switch_to_auto(c: &mut loops::OperatedSmith<f32>) {
    c.auto();
}

/// A new dead time for the predictor's model (samples).
#[inline(never)]
fn change_dead_time(c: &mut loops::OperatedSmith<f32>, samples: f32) -> bool {
    c.set_dead_time(samples).is_ok()
}

/// The adaptive Smith predictor on a process whose gain is half its
/// model's ([`adaptive::applying`]): it learns, applies a model (sample
/// 10 000 on the host) and its line is rescaled over the following
/// updates. The most ticks one call took and the call's number, and how
/// many models it applied.
fn adaptive_applying() -> (u32, usize, usize) {
    let (mut c, _) = loops::smith_adaptive::<f32>();
    let m: msp::ProcessModel<f32> = match msp::Fopdt::new(5.6 * 0.5, 40.2, 93.9) {
        Ok(f) => f.into(),
        Err(_) => fail(),
    };
    let mut plant = loops::Plant::new(&m, 0.939);
    let (max, at, applied, _) = adaptive::applying(&mut c, &mut plant, adaptive_step, |_| false);
    (max, at, applied)
}

/// The MathWorks example's Smith predictor at a tenth of its period: 1 000
/// samples of dead time in a line of 1 024.
type LongSmith = msp::SmithPredictor<f32, 1, [f32; 1024]>;

fn long_smith() -> LongSmith {
    let ts = 0.0939;
    let m: msp::ProcessModel<f32> = match msp::Fopdt::new(5.6, 40.2, 93.9) {
        Ok(f) => f.into(),
        Err(_) => fail(),
    };
    let pi = msp::PidConfig::isa(40.2 / (5.6 * 93.9), 40.2, 0.0, ts);
    match msp::SmithPredictor::from_model(pi, &m, ts) {
        Ok(c) => c,
        Err(_) => fail(),
    }
}

/// A new gain for the long line's model (`Operate::set_model`, as an
/// adaptive controller applies one): its line is rescaled over the
/// following updates, not in this call.
#[inline(never)]
fn change_model(c: &mut LongSmith, gain: f32) -> bool {
    use msp::Operate;
    c.set_model(gain, 40.2).is_ok()
}

/// An update of the long line's predictor while its line is rescaled.
#[inline(never)]
fn rescaling_step(c: &mut LongSmith, r: f32, y: f32) -> f32 {
    use msp::Controller;
    c.update(r, y)
}

#[entry]
fn main() -> ! {
    let Some(mut p) = cortex_m::Peripherals::take() else {
        fail()
    };
    p.SYST.set_clock_source(SystClkSource::Core);
    p.SYST.set_reload(0x00FF_FFFF);
    p.SYST.clear_current();
    p.SYST.enable_counter();
    let ipt = instructions_per_tick();
    hprintln!("SysTick: {:.2} instructions per tick", ipt);

    // the loop's own cost (plant, set point, bookkeeping): the same run with an empty update
    let (_, _, base) = measured(loops::smith::<f32>(), empty_update);
    let (ram_sp, y_sp, t_sp) = measured(loops::smith::<f32>(), smith_update);
    let (ram_kd, y_kd, t_kd) = measured(loops::karan_dey::<f32>(), karan_dey_update);
    let (ram_fs, y_fs, t_fs) = measured(loops::fsp::<f32>(), fsp_update);
    let (ram_ad, y_ad, t_ad, (max_ad, max_at)) =
        measured_max(loops::smith_adaptive::<f32>(), adaptive_step);

    // the same loop with an operator: manual, back to auto, a dead-time change
    let (mut op, mut plant) = loops::smith_operated::<f32>();
    let ram_op = core::mem::size_of_val(&op);
    let mut ticks = Ticks::default();
    let y_op = loops::run_operated(&mut op, &mut plant, |b| ticks.tick(b), operated_update);
    let t_op = ticks.mean(loops::SAMPLES);
    // the one-off calls, 100 times each in the same harness
    let (mut to_auto, mut new_delay) = (Ticks::default(), Ticks::default());
    for i in 0..100 {
        if op.manual(0.1).is_err() {
            fail()
        }
        to_auto.tick(true);
        switch_to_auto(&mut op);
        to_auto.tick(false);
        new_delay.tick(true);
        let ok = change_dead_time(&mut op, if i % 2 == 0 { 100.0 } else { 110.0 });
        new_delay.tick(false);
        if !ok {
            fail()
        }
    }
    // a new model's gain on a line of 1 024 samples, 100 times, each
    // followed by the 40 updates over which its line is rescaled (32
    // samples in each: the line's 1 024 in 33 updates)
    let mut long = long_smith();
    for _ in 0..1100 {
        use msp::Controller;
        long.update(1.0, 0.5);
    }
    for i in 0..100 {
        if !change_model(&mut long, if i % 2 == 0 { 4.0 } else { 5.6 }) {
            fail()
        }
        for _ in 0..40 {
            rescaling_step(&mut long, 1.0, 0.5);
        }
    }
    // their exact counts come from single-stepping (scripts/firmware); the
    // SysTick means here are printed for reference only
    hprintln!(
        "one-off calls (SysTick, about): switch_to_auto {:.0}, change_dead_time {:.0} instructions",
        (to_auto.mean(100) - base) * ipt + 3.0,
        (new_delay.mean(100) - base) * ipt + 3.0
    );

    // instructions from a function's entry to its return, inclusive: the empty
    // update's own body (push, mov, pop) is 3
    let per = |t: f64| (t - base) * ipt + 3.0;
    // known costs through the same harness (64 nops; 64 dependent VFP
    // multiply-adds), and the PID alone for the Smith predictor's breakdown
    let (_, _, t_nop) = measured(loops::smith::<f32>(), nop_update);
    let (_, _, t_pid) = measured(loops::smith::<f32>(), pid_update);
    let (_, _, t_fma) = measured(loops::smith::<f32>(), fma_update);
    // one line per function, read by scripts/firmware to compare with the
    // single-stepped count
    for (name, t) in [
        ("nop_update", t_nop),
        ("fma_update", t_fma),
        ("pid_update", t_pid),
        ("smith_update", t_sp),
        ("karan_dey_update", t_kd),
        ("fsp_update", t_fs),
        ("operated_update", t_op),
    ] {
        hprintln!("instructions: {} {:.1}", name, per(t));
    }
    // the 2×2 loops (Wood–Berry), through their own harness's overhead
    let (_, _, base2) = measured_mimo(mimo::decoupled::<f32>(), mimo_empty);
    let (ram_dc, y_dc, t_dc) = measured_mimo(mimo::decentralized::<f32>(), decentralized_update);
    let (ram_dd, y_dd, t_dd) = measured_mimo(mimo::decoupled::<f32>(), decoupled_update);
    let per2 = |t: f64| (t - base2) * ipt + 3.0;
    for (name, t) in [("decentralized_update", t_dc), ("decoupled_update", t_dd)] {
        hprintln!("instructions: {} {:.1}", name, per2(t));
    }
    let mimo_ok = check(
        "2x2 decentralized smith (wood-berry)",
        &y_dc,
        &reference::DECENTRALIZED,
        1e-4,
        per2(t_dc),
        ram_dc,
    ) & check(
        "2x2 decoupled smith (wood-berry)",
        &y_dd,
        &reference::DECOUPLED,
        1e-4,
        per2(t_dd),
        ram_dd,
    );
    // the unstable plant amplifies f32 rounding (its own and the predictor's sum of
    // h = 100 products per sample): a tenth of a percent there
    let ok = mimo_ok
        & check("smith", &y_sp, &reference::SMITH, 1e-4, per(t_sp), ram_sp)
        & check(
            "karan-dey",
            &y_kd,
            &reference::KARAN_DEY,
            1e-4,
            per(t_kd),
            ram_kd,
        )
        & check(
            "fsp (unstable plant)",
            &y_fs,
            &reference::FSP,
            1e-3,
            per(t_fs),
            ram_fs,
        );
    hprintln!(
        "adaptive smith (16 candidate dead times, f32): mean {:.0} instructions per update over the run; the longest call {} (about {:.0} instructions)",
        per(t_ad),
        max_at,
        f64::from(max_ad) * ipt
    );
    let (max_ap, ap_at, applied) = adaptive_applying();
    hprintln!(
        "adaptive smith applying a model ({} applied, f32): the longest call {} (about {:.0} instructions)",
        applied,
        ap_at,
        f64::from(max_ap) * ipt
    );
    let ok = ok & (applied > 0);
    let ((max_kd, kd_at, kd_applied, kd_design), kd_ram) = adaptive::karan_dey_applying();
    hprintln!(
        "adaptive karan-dey applying a model ({} applied, f32, designed in the background): the longest call {} (about {:.0} instructions); controller RAM {} bytes",
        kd_applied,
        kd_at,
        f64::from(max_kd) * ipt,
        kd_ram
    );
    hprintln!(
        "designs in the background (about): karan-dey {:.0} instructions, filtered smith (f64) {:.0}",
        f64::from(kd_design) * ipt,
        f64::from(adaptive::fsp_design_ticks()) * ipt
    );
    let ok = ok & (kd_applied > 0);
    // 1e-3 as for the design on the device: the model the loop runs on is
    // estimated in f32, by recursive least squares whose covariance spans
    // four decades (its rounding, ~1e-7 times that, reaches the estimates at
    // ~1e-3 and the output through the applied model)
    let ok =
        ok & check(
            "smith adaptive (16 candidate dead times)",
            &y_ad,
            &reference::ADAPTIVE,
            1e-3,
            per(t_ad),
            ram_ad,
        ) & check(
            "smith operated (manual, auto, dead time 100 -> 110 samples)",
            &y_op,
            &reference::OPERATED,
            1e-4,
            per(t_op),
            ram_op,
        );
    // the Smith predictor's f32 output at the check points, which the C
    // example's run (examples/c/smith.c) is compared with by scripts/c
    for (i, y) in y_sp.iter().enumerate() {
        hprintln!(
            "y smith {} {:e}",
            (i + 1) * (loops::SAMPLES / loops::CHECKS),
            y
        );
    }
    hprintln!("verdict: {}", if ok { "PASS" } else { "FAIL" });
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

fn fail() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    fail()
}
