//! The elementary functions of the engine's computations, the same on every target where the
//! platforms' libraries differ by algorithm.
//!
//! The standard library calls the platform's C library: glibc on Linux, wasi-libc (musl) in the
//! WebAssembly build of the browser page. For `expm1`, `log1p`, `sin`, `cos`, `tanh`, `atanh`,
//! `sinh`, `hypot`, `log10` and `exp2` the two use different algorithms, whose last bits differ,
//! and a fit carries a last bit to about 1e-9 of a parameter along a flat direction of its
//! objective (the page's bias instability of adis_16405_imu1 gyro_z differed from the command's
//! by 1.4e-9): these come from the `libm` crate, a pure-Rust port of musl's, on every target.
//! `exp`, `ln` and `powf` stay the platform's: glibc and musl share their algorithms (ARM's
//! optimized routines; glibc's FMA variants round differently only rarely), and `libm`'s `pow`
//! (fdlibm's) would double a calibration's time. With this split the page's N, B, K of the
//! shared ADIS recordings equal the command's to 1.5e-10, 1e-13, 2.9e-8, 0, 3.1e-8 and 0
//! (before: 1.4e-9, a different model on imu2 with N, B, K 45% apart, 1.7e-8, 1.1e-9, 7.6e-5,
//! 3.1e-8), for 2% of the command's time. Taking `exp` and `ln` from `libm` too does not help
//! (imu3 2.5e-7, imu5 7.6e-5): what remains comes from `powf`, `exp`, `ln` and the libraries
//! the engine calls (statrs, rustfft), and a near-tie of two candidate models can amplify it.

#[inline]
pub(crate) fn exp(x: f64) -> f64 {
    // the platform's (see the module's documentation)
    x.exp()
}
#[inline]
pub(crate) fn log(x: f64) -> f64 {
    // the platform's
    x.ln()
}
#[inline]
pub(crate) fn expm1(x: f64) -> f64 {
    libm::expm1(x)
}
#[inline]
pub(crate) fn log1p(x: f64) -> f64 {
    libm::log1p(x)
}
#[inline]
pub(crate) fn pow(x: f64, y: f64) -> f64 {
    // the platform's
    x.powf(y)
}
#[inline]
pub(crate) fn exp2(x: f64) -> f64 {
    libm::exp2(x)
}
#[inline]
pub(crate) fn log10(x: f64) -> f64 {
    libm::log10(x)
}
#[inline]
pub(crate) fn sin(x: f64) -> f64 {
    libm::sin(x)
}
#[inline]
pub(crate) fn cos(x: f64) -> f64 {
    libm::cos(x)
}
/// `(sin x, cos x)`.
#[inline]
pub(crate) fn sincos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}
#[inline]
pub(crate) fn sinh(x: f64) -> f64 {
    libm::sinh(x)
}
#[inline]
pub(crate) fn tanh(x: f64) -> f64 {
    libm::tanh(x)
}
#[inline]
pub(crate) fn atanh(x: f64) -> f64 {
    libm::atanh(x)
}
#[inline]
pub(crate) fn hypot(x: f64, y: f64) -> f64 {
    libm::hypot(x, y)
}
