//! Any text given to the expression parser of `shape = "expression"`: a tree that evaluates (finite
//! or not) without a panic, or an error whose column lies in the text (or just past its end) and
//! whose message is short; never a panic, a stack overflow or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match stamp_contact::expression_parser::parse(text) {
        Ok(_) => {
            let e = stamp_contact::Expression::new(text, 1.0).expect("parsed once, parses again");
            for x in [[0.0, 0.0, 0.0], [1.5, -2.0, 40.0], [-1e300, 1e-300, 0.5]] {
                let _ = e.jet(&nalgebra::Vector3::from(x));
            }
        }
        Err(e) => {
            assert!(e.column >= 1 && e.column <= text.chars().count() + 1, "column {} of a text of {} characters", e.column, text.chars().count());
            assert!(!e.message.is_empty() && e.message.len() <= 400, "message of {} bytes: {}", e.message.len(), e.message);
        }
    }
});
