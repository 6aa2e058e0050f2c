//! One module per subcommand.

pub mod avar;
pub mod demo;
pub mod wv;
