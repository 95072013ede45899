//! Polynomials `p(s) = sum c[k] s^k` (coefficients from the constant term
//! up): one Horner evaluator, with the multiply-add step as a parameter.
//!
//! Event location on a Runge-Kutta dense output rounds each step twice
//! ([`eval_plain`]), as it always has; the chain's Taylor series fuse each
//! step into one rounding where the target can ([`eval`]). The two differ
//! in the last bits only, and each keeps the results it was tested with.

use crate::numerics::fused::mul_add;

/// `p(s)` by Horner's rule, each step `step(acc, s, c[k])`.
#[inline(always)]
fn horner(c: &[f64], s: f64, step: impl Fn(f64, f64, f64) -> f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| step(acc, s, ck))
}

/// `p(s)`, each step fused where the target has FMA.
pub fn eval(c: &[f64], s: f64) -> f64 {
    horner(c, s, mul_add)
}

/// `p(s)`, each step `acc * s + c` with two roundings.
pub fn eval_plain(c: &[f64], s: f64) -> f64 {
    horner(c, s, |acc, s, ck| acc * s + ck)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_evaluate_a_polynomial_written_out() {
        // 2 - 3 s + s^3 at s = 1.5: 2 - 4.5 + 3.375 = 0.875, exact in binary.
        let c = [2.0, -3.0, 0.0, 1.0];
        assert_eq!(eval(&c, 1.5), 0.875);
        assert_eq!(eval_plain(&c, 1.5), 0.875);
        assert_eq!(eval(&[], 3.0), 0.0);
    }
}
