//! Variances of a series across scales: wavelet variance (classical and robust), Allan, modified
//! Allan and Hadamard variances, and their confidence intervals; beside them the power spectral
//! density by Welch's method (`psd`), the same variance spread over frequency.

pub(crate) mod allan;
pub(crate) mod ci;
pub(crate) mod cov;
pub(crate) mod cross;
mod file;
pub(crate) mod gaps;
pub(crate) mod growth;
pub(crate) mod haar;
pub(crate) mod haar_robust;
pub(crate) mod implied_cov;
pub(crate) mod pooled;
pub(crate) mod psd;
pub(crate) mod robust;
pub(crate) mod simd;
pub(crate) mod stream;
pub(crate) mod wv;

pub use file::{allan_from_wv, is_wv_json, read_wv_json, select_series};
pub use gaps::{gap_aware_wavelet_variance, GapAccount, GapLevel, GapPolicy};
pub use stream::{binary_columns_wv, binary_wavelet_variance, StreamedColumn};
pub use wv::default_levels;

use rayon::prelude::*;

/// Applies a per-series computation to several series in parallel (rayon), in order.
/// Results are independent of the thread count.
pub fn per_column<T: Send>(columns: &[&[f64]], f: impl Fn(&[f64]) -> T + Sync + Send) -> Vec<T> {
    columns.par_iter().map(|x| f(x)).collect()
}
