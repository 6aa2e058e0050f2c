#![no_main]
//! Fuzz target `raw_binary`: the body is `gmwm_fuzz::raw_binary` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::raw_binary(data));
