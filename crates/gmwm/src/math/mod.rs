//! Numerical building blocks (METHODS §12): compensated sums, 1-D minimisation and root finding.

pub mod brent;
pub mod sum;
