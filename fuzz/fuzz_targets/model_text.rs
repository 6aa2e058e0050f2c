#![no_main]
//! Fuzz target `model_text`: the body is `gmwm_fuzz::model_text` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::model_text(data));
