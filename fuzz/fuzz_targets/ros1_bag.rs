#![no_main]
//! Fuzz target `ros1_bag`: the body is `gmwm_fuzz::ros1_bag` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::ros1_bag(data));
