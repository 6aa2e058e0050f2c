//! Run-time choice of the vector width of the hot loops (the Haar pyramid, the priming of its
//! rings, the lag recurrence of the split passes).
//!
//! The engine is built for the baseline x86-64 target (two-wide SSE2); the same loops compiled
//! for AVX2 or AVX-512 run up to twice as fast on the CPUs that have them. The loops are plain
//! Rust: the wider code performs the same IEEE operations in the same order (no fused
//! multiply-add, no reassociation), so every result is bit for bit the same on any CPU.

/// Defines `$name`, calling `$imp` (an `#[inline(always)]` function with the same arguments)
/// compiled for AVX-512F or AVX2 when the CPU has them (checked at run time), else as built.
macro_rules! multiversion {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? => $imp:path) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                unsafe fn avx512($($arg: $ty),*) $(-> $ret)? {
                    $imp($($arg),*)
                }
                #[target_feature(enable = "avx2")]
                unsafe fn avx2($($arg: $ty),*) $(-> $ret)? {
                    $imp($($arg),*)
                }
                if std::arch::is_x86_feature_detected!("avx512f") {
                    // SAFETY: the CPU has AVX-512F (checked just above), the only requirement
                    // of this `target_feature` function (unsafe for the MSRV, 1.80).
                    return unsafe { avx512($($arg),*) };
                }
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU has AVX2 (checked just above), the only requirement of
                    // this `target_feature` function (unsafe for the MSRV, 1.80).
                    return unsafe { avx2($($arg),*) };
                }
            }
            $imp($($arg),*)
        }
    };
}
pub(crate) use multiversion;
