//! The plant parser never panics, and what it accepts prints back to itself.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(s) = std::str::from_utf8(data) else {
        return;
    };
    match msp::syntax::parse_plant(s) {
        Ok(tf) => {
            assert!(tf.num.iter().chain(&tf.den).all(|c| c.is_finite()));
            assert!(tf.delay >= 0.0 && tf.delay.is_finite());
            // the canonical form parses again
            let again = msp::syntax::parse_plant(&tf.to_string());
            assert!(again.is_ok(), "{} does not parse back", tf);
        }
        Err(e) => {
            assert!(!e.message.is_empty());
            assert!(e.column >= 1 && e.column <= s.chars().count() + 1);
        }
    }
});
