//! One module per subcommand.

pub mod avar;
pub mod batch;
pub mod calibrate;
pub mod demo;
pub mod fit;
pub mod implied;
pub mod monitor;
pub mod plot;
pub mod report;
pub mod same_model;
pub mod select;
pub mod shared;
pub mod simulate;
pub mod topics;
pub mod wv;
