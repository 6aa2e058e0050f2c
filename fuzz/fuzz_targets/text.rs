#![no_main]
//! Fuzz target `text`: the body is `gmwm_fuzz::text` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::text(data));
