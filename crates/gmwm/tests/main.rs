//! The engine's single integration-test binary (STYLE §1): reference data, properties, Monte Carlo.

mod allan;
mod common;
mod read;
mod robust;
mod wavelet;
mod wv;
