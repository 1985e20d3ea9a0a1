//! `update` of every controller allocates nothing (a counting global allocator).
#![allow(unsafe_code)] // a global allocator is unsafe by nature; test-only
mod common;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use msp::poly::TransferFunction;
use msp::registry::{Build, SCHEMES};
use msp::Controller;

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // only this test's thread counts: the harness's own threads may allocate meanwhile
    static COUNTING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if COUNTING.with(|c| c.get()) {
            ALLOCS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

const BUILD: Build = Build {
    ts: 0.1,
    u_min: -10.0,
    u_max: 10.0,
    max_dead_time: 0.0,
};

/// Allocations made by this thread while `f` runs.
fn allocations(f: impl FnOnce()) -> usize {
    COUNTING.with(|c| c.set(true));
    let before = ALLOCS.load(Ordering::SeqCst);
    f();
    let after = ALLOCS.load(Ordering::SeqCst);
    COUNTING.with(|c| c.set(false));
    after - before
}

#[test]
fn update_allocates_nothing() {
    let plants = ["0.2/s*e^-7.4s", "5.6*e^-93.9s/(40.2s+1)"];
    for scheme in SCHEMES {
        for p in plants {
            let plant: TransferFunction = p.parse().unwrap();
            let Ok(params) = scheme.tune_with(&plant, None, &[]) else {
                continue;
            };
            let mut c = scheme.build_with(&params, &plant, &BUILD).unwrap();
            let n = allocations(|| {
                let mut y = 0.0;
                for k in 0..10_000 {
                    y = 0.999 * y + 0.001 * c.update(1.0, y);
                    if k == 5000 {
                        y = f64::NAN;
                    }
                    if !y.is_finite() {
                        y = 0.0;
                    }
                }
                c.reset();
            });
            assert_eq!(n, 0, "{} allocated during update", scheme.name);
        }
    }
}

#[test]
fn cascade_update_allocates_nothing() {
    // García et al.'s Example 2 (integrating primary)
    let p1: TransferFunction = common::EXAMPLE2.0.parse().unwrap();
    let p2: TransferFunction = common::EXAMPLE2.1.parse().unwrap();
    let mut checked = 0;
    for scheme in SCHEMES.iter().filter(|s| s.is_cascade()) {
        let params = scheme
            .tune_process(
                &p1,
                Some(&p2),
                None,
                None,
                &common::required_settings(scheme.name),
            )
            .unwrap();
        let mut c = scheme
            .build_process(&params, &p1, Some(&p2), &BUILD)
            .unwrap();
        let n = allocations(|| {
            let (mut y, mut y2) = (0.0, 0.0);
            for _ in 0..10_000 {
                let u = c.update_cascade(1.0, y, y2);
                y2 = 0.9 * y2 + 0.1 * u;
                y += 0.01 * y2;
            }
            c.reset();
        });
        assert_eq!(n, 0, "{} allocated during update", scheme.name);
        checked += 1;
    }
    assert_eq!(checked, 4);
}
