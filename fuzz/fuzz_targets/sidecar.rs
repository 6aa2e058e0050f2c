#![no_main]
//! Fuzz target `sidecar`: the body is `gmwm_fuzz::sidecar` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::sidecar(data));
