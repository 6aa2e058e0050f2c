//! Numerical building blocks (docs/methods.md §12): compensated sums, 1-D minimisation and root
//! finding, special functions.

pub(crate) mod brent;
pub(crate) mod special;
pub(crate) mod sum;
