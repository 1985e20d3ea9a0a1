#![allow(dead_code, missing_docs)]

/// `|a − b| ≤ atol + rtol·|b|`.
pub fn close(a: f64, b: f64, rtol: f64, atol: f64) -> bool {
    (a - b).abs() <= atol + rtol * b.abs()
}

#[track_caller]
pub fn assert_close(a: f64, b: f64, rtol: f64, atol: f64) {
    assert!(
        close(a, b, rtol, atol),
        "{a} is not within rtol {rtol}, atol {atol} of {b}"
    );
}
