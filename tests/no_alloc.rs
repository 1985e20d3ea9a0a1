//! `update` of every controller allocates nothing (a counting global allocator).
#![allow(unsafe_code)] // a global allocator is unsafe by nature; test-only
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

#[test]
fn update_allocates_nothing() {
    let plants = ["0.2/s*e^-7.4s", "5.6*e^-93.9s/(40.2s+1)"];
    for scheme in SCHEMES {
        for p in plants {
            let plant: TransferFunction = p.parse().unwrap();
            let Ok(params) = scheme.tune_with(&plant, None, &[]) else {
                continue;
            };
            let mut c = scheme
                .build_with(
                    &params,
                    &plant,
                    &Build {
                        ts: 0.1,
                        u_min: -10.0,
                        u_max: 10.0,
                    },
                )
                .unwrap();
            COUNTING.with(|c| c.set(true));
            let before = ALLOCS.load(Ordering::SeqCst);
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
            let after = ALLOCS.load(Ordering::SeqCst);
            COUNTING.with(|c| c.set(false));
            assert_eq!(after, before, "{} allocated during update", scheme.name);
        }
    }
}
