//! A flow the exact linear propagator runs: affine in the state, and
//! driven by sines of the clock,
//! `x' = A x + b + sum_k (c_k cos(w_k t) + s_k sin(w_k t))`.
//!
//! A sine of the clock is itself the state of a linear flow (`C = cos(w t)`,
//! `S = sin(w t)`: `C' = -w S`, `S' = w C`), so the whole is linear in the
//! augmented state `[x, 1, C_1, S_1, ...]`, and its propagator is one
//! matrix exponential (see [`crate::engine::step::affine_mode`]): a forced
//! oscillator is solved in closed form, not stepped by a series.

use nalgebra::{DMatrix, DVector};

/// A sine of the clock's share of the flow: `cos` and `sin` are the
/// coefficients, per state component, of `cos(frequency t)` and
/// `sin(frequency t)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Wave {
    /// `w > 0`.
    pub frequency: f64,
    /// `c`: the coefficients of `cos(w t)`.
    pub cos: DVector<f64>,
    /// `s`: the coefficients of `sin(w t)`.
    pub sin: DVector<f64>,
}

/// `x' = A x + b + sum_k (c_k cos(w_k t) + s_k sin(w_k t))`; with no waves,
/// a linear flow `x' = A x + b`.
#[derive(Debug, Clone, PartialEq)]
pub struct AffineFlow {
    /// `A`.
    pub a: DMatrix<f64>,
    /// `b`.
    pub b: DVector<f64>,
    /// The sines of the clock, distinct frequencies.
    pub waves: Vec<Wave>,
}

impl AffineFlow {
    /// `x' = A x + b`, driven by nothing.
    pub fn linear((a, b): (DMatrix<f64>, DVector<f64>)) -> Self {
        AffineFlow {
            a,
            b,
            waves: Vec::new(),
        }
    }
}

/// `(cos(w (t + t_lo)), sin(w (t + t_lo)))` to about an ulp for any `t`
/// (`t_lo` below an ulp of `t`): the product `w t` is split into its
/// rounded value and what rounding left out (an FMA gives it exactly),
/// whose turn, with `w t_lo`'s, is added to first order (below an ulp of
/// the angle, its square is far below the result's). Rounding `w t` alone
/// would err by half an ulp of the angle: 5e-13 at `t = 1e4`.
pub fn cos_sin(w: f64, t: f64, t_lo: f64) -> (f64, f64) {
    let angle = w * t;
    let left_out = w.mul_add(t, -angle) + w * t_lo;
    let (s, c) = angle.sin_cos();
    (c - s * left_out, s + c * left_out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cosine_and_sine_of_a_large_angle_keep_its_rounding() {
        // cos and sin of w t for the doubles w = 0.8, t = 1e4 and 9999.3,
        // by mpmath at 40 digits (the product taken exactly), to the nearest
        // double. Rounding w t to double first errs by 4.4e-13 and 2.1e-13.
        let cases = [
            (1e4, 0.06564512750987989, 0.997843032362411),
            (9999.3, 0.5856586162787791, 0.8105578234638328),
        ];
        for (t, cos, sin) in cases {
            let (c, s) = cos_sin(0.8, t, 0.0);
            assert!((c - cos).abs() < 2e-16, "{t}: {c} vs {cos}");
            assert!((s - sin).abs() < 2e-16, "{t}: {s} vs {sin}");
            assert!(
                ((0.8 * t).cos() - cos).abs() > 1e-13,
                "{t}: the plain one errs"
            );
        }
        // Where the product is exact, the plain cosine and sine.
        assert_eq!(cos_sin(0.5, 2.0, 0.0), (1.0_f64.cos(), 1.0_f64.sin()));
    }
}
