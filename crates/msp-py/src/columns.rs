//! A run's columns lent to numpy, and taken back when numpy frees them.
//!
//! `msp.run` hands the simulator's buffers to numpy without a copy. A
//! buffer freed to the allocator goes back to the system when it is large,
//! and the next run's fresh buffer costs a page fault per 4 KiB on its first
//! touch (on a virtual machine more than simulating the samples it holds).
//! Here a freed array's buffer goes to a small pool instead, and the next run
//! on any thread writes into it ([`msp::study::recycle`]): memory that is
//! already mapped. The pool holds at most [`MAX_BUFFERS`] buffers and
//! [`MAX_BYTES`] bytes; beyond that a buffer is freed as before.

use std::sync::Mutex;

use msp::sim::SimResult;
use numpy::ndarray::ArrayView1;
use numpy::PyArray1;
use pyo3::prelude::*;

/// The most buffers the pool keeps.
const MAX_BUFFERS: usize = 32;
/// The most bytes the pool keeps (64 MiB).
const MAX_BYTES: usize = 64 << 20;

static POOL: Mutex<Vec<Vec<f64>>> = Mutex::new(Vec::new());

/// Keeps `v`'s memory for a later run when the pool has room.
pub(crate) fn give(v: Vec<f64>) {
    if v.capacity() == 0 {
        return;
    }
    if let Ok(mut pool) = POOL.lock() {
        let held: usize = pool.iter().map(Vec::capacity).sum();
        if pool.len() < MAX_BUFFERS && (held + v.capacity()) * 8 <= MAX_BYTES {
            pool.push(v);
        }
    }
}

/// Every pooled buffer, as the columns of a result the next run on this
/// thread writes into: the largest for `t`, `y`, `u`, `r`, `d`, `d_out`, the
/// rest for the controller's signals.
pub(crate) fn lend() {
    let mut all = match POOL.lock() {
        Ok(mut pool) => std::mem::take(&mut *pool),
        Err(_) => return,
    };
    if all.is_empty() {
        return;
    }
    all.sort_by_key(|v| std::cmp::Reverse(v.capacity()));
    let mut it = all.into_iter();
    let mut next = || it.next().unwrap_or_default();
    let (t, y, u, r, d, d_out) = (next(), next(), next(), next(), next(), next());
    let signals = std::iter::from_fn(|| {
        let v = next();
        (v.capacity() > 0).then(|| (String::new(), v))
    })
    .collect();
    msp::study::recycle(SimResult {
        t,
        y,
        u,
        r,
        d,
        d_out,
        signals,
        ..SimResult::default()
    });
}

/// The owner of an array's memory: its buffer goes back to the pool when
/// numpy drops the array.
#[pyclass(module = "msp._msp", frozen)]
pub(crate) struct Column(Vec<f64>);

impl Drop for Column {
    fn drop(&mut self) {
        give(std::mem::take(&mut self.0));
    }
}

/// `v` as a numpy array over the same memory (no copy), given back to the
/// pool when the array is freed. The crate's one `unsafe`: numpy's only way
/// to give an array an owner of ours.
#[allow(unsafe_code)]
pub(crate) fn array(py: Python<'_>, v: Vec<f64>) -> PyResult<Bound<'_, PyArray1<f64>>> {
    let owner = Bound::new(py, Column(v))?;
    let (ptr, len) = (owner.get().0.as_ptr(), owner.get().0.len());
    // SAFETY: `ptr` and `len` describe the initialized elements of the
    // vector `owner` holds; `owner` is frozen (its vector is never changed
    // or reallocated) and becomes the array's base object, so the memory
    // lives as long as the array.
    let view = unsafe { ArrayView1::from_shape_ptr(len, ptr) };
    // SAFETY: as above: the view's memory belongs to `owner`, which the
    // returned array keeps alive.
    Ok(unsafe { PyArray1::borrow_from_array(&view, owner.into_any()) })
}
