//! `a * b + c`, fused into one rounding where the target has FMA.
//!
//! Horner sums are chains of multiply-adds, each waiting on the last: a
//! fused one halves the chain's latency and rounds once instead of twice.
//! Rust never fuses on its own, and `f64::mul_add` on a target without the
//! instruction calls a slow software routine, so the choice is made here
//! at compile time.

/// `a * b + c`: fused if the build target has FMA (decided when compiling,
/// not by the CPU it runs on), two roundings otherwise.
#[inline(always)]
pub fn mul_add(a: f64, b: f64, c: f64) -> f64 {
    #[cfg(target_feature = "fma")]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(target_feature = "fma"))]
    {
        a * b + c
    }
}
