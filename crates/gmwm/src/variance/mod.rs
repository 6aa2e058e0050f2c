//! Variances of a series across scales: wavelet variance (classical and robust), Allan, modified
//! Allan and Hadamard variances, and their confidence intervals.

pub mod allan;
pub mod ci;
pub mod robust;
pub mod wv;
