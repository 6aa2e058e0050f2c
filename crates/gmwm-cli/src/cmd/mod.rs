//! One module per subcommand.

pub mod avar;
pub mod demo;
pub mod fit;
pub mod implied;
pub mod simulate;
pub mod wv;
