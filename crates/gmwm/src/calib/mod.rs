//! Calibration: from a recording to navigation-filter parameters.
pub mod export;
pub mod ieee;
