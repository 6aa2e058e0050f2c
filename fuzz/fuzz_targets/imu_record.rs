#![no_main]
//! Fuzz target `imu_record`: the body is `gmwm_fuzz::imu_record` (src/lib.rs).

libfuzzer_sys::fuzz_target!(|data: &[u8]| gmwm_fuzz::imu_record(data));
