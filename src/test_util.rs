//! Helpers shared by the unit tests in `src/`.

/// Unwraps in test helpers: a failure aborts the test with the error's text.
pub(crate) trait ExpectOk<T> {
    fn expect_ok(self) -> T;
}

impl<T, E: core::fmt::Debug> ExpectOk<T> for Result<T, E> {
    #[track_caller]
    fn expect_ok(self) -> T {
        match self {
            Ok(v) => v,
            Err(e) => std::panic::panic_any(std::format!("{e:?}")),
        }
    }
}

impl<T> ExpectOk<T> for Option<T> {
    #[track_caller]
    fn expect_ok(self) -> T {
        match self {
            Some(v) => v,
            None => std::panic::panic_any(std::string::String::from("None")),
        }
    }
}
