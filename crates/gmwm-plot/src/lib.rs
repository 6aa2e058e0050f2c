//! Figures and the HTML calibration report of the gmwm platform.
//!
//! Every figure of docs/methods.md §11 (paper Figs. 1–4) and the IEEE Std 952 read-off, as SVG or
//! PNG, drawn with plotters on pure-Rust backends with an embedded DejaVu Sans, so that nothing
//! here needs a system font or a C library; and [`report::render`], one self-contained HTML page of
//! a calibration. This crate renders the engine's results and computes no statistic of its own:
//! what it shows is what `gmwm --json` gives.
//!
//! ```
//! use gmwm_plot::{wv_figure, Column, Layout};
//! let x: Vec<f64> = (0..4096).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
//! let wv = gmwm::wavelet_variance(&x, 100.0, &gmwm::WvOptions::default()).unwrap();
//! let figure = wv_figure(&[Column::new("gyro_x", "rad/s", &wv)], Layout::Grid);
//! let svg = figure.svg().unwrap();
//! assert!(svg.contains("gyro_x"));
//! ```
#![deny(missing_docs)]

mod chart;
mod figure;
mod figures;
pub mod report;
pub mod style;

pub use chart::{BarRow, Bars, Mark, Panel, PanelKind, Series};
pub use figure::{within_limits, Figure, ImageFormat, MAX_PIXELS, MAX_SIDE};
pub use figures::{
    allan_figure, compare_figure, covariate_figure, fit_figure, ieee_figure, plan_figure,
    pooled_figure, psd_figure, recordings_figure, selection_figure, shared_figure, wv_figure,
    Column, Layout, AV_SCALE, PSD_FREQUENCY, WIC_ROWS, WV_SCALE,
};

/// What can go wrong while drawing or writing a figure or a report.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// plotters failed to draw.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
    /// A figure file name without a known extension.
    #[error("{0}: a figure is written as .svg or .png (by the file name's extension)")]
    Format(String),
    /// A size too small for the panels' axes, or absurdly large.
    #[error("figure size {width}x{height} px: needs at least {min_width}x{min_height} px for its panels, at most 20000 px a side and 40 megapixels (fewer --columns make a smaller figure)")]
    Size {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// Smallest width for the grid.
        min_width: u32,
        /// Smallest height for the grid.
        min_height: u32,
    },
    /// Writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}
