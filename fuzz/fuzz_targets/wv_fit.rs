#![no_main]
//! Fuzz target `wv_fit`: the body is `gmwm_fuzz::wv_fit` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::wv_fit(data));
