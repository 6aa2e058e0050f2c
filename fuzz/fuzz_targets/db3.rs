#![no_main]
//! Fuzz target `db3`: the body is `gmwm_fuzz::db3` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::db3(data));
