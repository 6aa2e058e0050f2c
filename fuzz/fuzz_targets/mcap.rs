#![no_main]
//! Fuzz target `mcap`: the body is `gmwm_fuzz::mcap` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::mcap(data));
