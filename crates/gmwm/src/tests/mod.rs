//! The engine's tests against reference data, properties and Monte Carlo (STYLE §1), inside the
//! crate so that they reach the kernels the public API does not show.

// Parallel per-level arrays are compared by index throughout; iterator zips would obscure that.
#![allow(clippy::needless_range_loop)]

mod allan;
mod augmented;
mod calib;
mod canonical;
mod common;
mod contamination;
mod covariate;
mod coverage;
mod datasheet;
mod dynamics;
mod examples;
mod export;
mod fit_mc;
mod fit_ref;
mod fit_start;
mod flicker;
mod fuzz_props;
mod gaps;
mod horizon;
mod ieee;
mod inference;
mod maf;
mod methods_reference;
mod model;
mod monitor;
mod plan;
mod pooled;
mod process;
mod psd;
mod read;
mod robust;
mod ros;
mod scale;
mod selection;
mod shared;
mod sim;
mod streamed;
mod units;
mod wavelet;
mod wv;
