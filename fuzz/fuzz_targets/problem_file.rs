//! Any bytes as a problem file: parsed or refused with an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = stamp_cli::run::Problem::parse(Path::new("fuzz.toml"), String::from_utf8_lossy(data).into_owned());
});
