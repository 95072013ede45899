//! `a * b + c`, fused into one rounding where the target has FMA.
//!
//! Horner sums are chains of multiply-adds, each waiting on the last: a
//! fused one halves the chain's latency and rounds once instead of twice.
//! Rust never fuses on its own, and `f64::mul_add` on a target without the
//! instruction calls a slow software routine, so the choice is made here
//! at compile time. Every 64-bit ARM core has the instruction, though
//! Rust's aarch64 targets name no `fma` feature: there it is fused too, so
//! an aarch64 build rounds as an x86-64-v3 one does (and as `wide`'s
//! vectors, which fuse on both).

/// Whether [`mul_add`] rounds once on this build's target.
pub const FUSED: bool = cfg!(any(target_feature = "fma", target_arch = "aarch64"));

/// `a * b + c`: fused if the build target has FMA (decided when compiling,
/// not by the CPU it runs on), two roundings otherwise.
#[inline(always)]
pub fn mul_add(a: f64, b: f64, c: f64) -> f64 {
    #[cfg(any(target_feature = "fma", target_arch = "aarch64"))]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(any(target_feature = "fma", target_arch = "aarch64")))]
    {
        a * b + c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wide::f64x4;

    #[test]
    fn fused_where_the_target_has_fma_and_as_wide_s_vectors_are() {
        // (1 + 2^-30)(1 - 2^-30) = 1 - 2^-60: rounded first, the product
        // is 1 and the sum 0; fused, the sum is exact.
        let (a, b) = (1.0 + 2f64.powi(-30), 1.0 - 2f64.powi(-30));
        let once = mul_add(a, b, -1.0);
        assert_eq!(once, if FUSED { -(2f64.powi(-60)) } else { 0.0 });
        // The chain's vectors (`window_series.rs`) and its scalar Horner
        // sums must round alike, or a chain's results move with the
        // column count.
        let lanes = f64x4::splat(a).mul_add(f64x4::splat(b), f64x4::splat(-1.0));
        assert_eq!(lanes.to_array(), [once; 4]);
        // x86-64 builds here target x86-64-v3 (`.cargo/config.toml`), and
        // every aarch64 core fuses: the golden outputs assume it.
        if cfg!(any(target_arch = "x86_64", target_arch = "aarch64")) {
            assert!(FUSED, "this build does not fuse: see .cargo/config.toml");
        }
    }
}
