#![no_main]
//! Fuzz target `wv_json`: the body is `gmwm_fuzz::wv_json` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::wv_json(data));
