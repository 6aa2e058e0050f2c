//! Numerical building blocks (docs/methods.md §12): compensated sums, 1-D minimisation and root
//! finding, special functions; the display of a number to so many significant digits.

pub(crate) mod brent;
pub(crate) mod elementary;
pub(crate) mod special;
pub(crate) mod sum;

/// The display of a value in the engine's tables and notes: `digits` significant digits
/// (clamped to 2..=17), in scientific notation outside [1e-3, 1e5).
pub(crate) fn significant(v: f64, digits: usize) -> String {
    let digits = digits.clamp(2, 17);
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        format!("{v}")
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.*e}", digits - 1)
    } else {
        let decimals = (digits as i32 - 1 - elementary::log10(a).floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    }
}
