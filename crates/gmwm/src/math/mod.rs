//! Numerical building blocks (METHODS §12): compensated sums, 1-D minimisation and root finding,
//! special functions.

pub mod brent;
pub mod special;
pub mod sum;
