//! Numbers carried as an unevaluated sum of two doubles, `hi + lo` with
//! `|lo| <= ulp(hi) / 2`: about 106 bits, from error-free transformations
//! (Knuth's two-sum, and the exact product a fused multiply-add gives).
//!
//! Only what a matrix used thousands of times needs: a step's propagator
//! rounded once to double carries a bias of up to half an ulp per entry,
//! which applying it step after step turns into a drift growing with the
//! number of steps (a rotation's phase). Built in double-double and applied
//! by [`dot`] to a state and the residual its last rounding left, a run of
//! steps rounds as if the state were carried to twice the precision.

use std::ops::{Add, Mul};

/// `hi + lo`, the two parts not overlapping.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DoubleDouble {
    /// The sum rounded to double.
    pub hi: f64,
    /// What rounding left out.
    pub lo: f64,
}

/// `a + b` exactly, as the rounded sum and its error (Knuth).
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let t = s - a;
    (s, (a - (s - t)) + (b - t))
}

/// `a + b` exactly for `|a| >= |b|` (or `a` zero), in three operations
/// instead of [`two_sum`]'s six (Dekker).
#[inline(always)]
pub fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// `a * b` exactly, as the rounded product and its error (one fused
/// multiply-add; a software one where the target has none).
#[inline(always)]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl DoubleDouble {
    /// `x` exactly.
    pub fn from(x: f64) -> Self {
        DoubleDouble { hi: x, lo: 0.0 }
    }

    /// Renormalised `hi + lo`.
    #[inline(always)]
    fn new(hi: f64, lo: f64) -> Self {
        let (hi, e) = two_sum(hi, lo);
        DoubleDouble { hi, lo: e }
    }

    /// `self / d` for a double `d`.
    pub fn divide(self, d: f64) -> Self {
        let q = self.hi / d;
        let (p, e) = two_prod(q, d);
        // The remainder, exact to the low part's rounding, over d.
        let r = ((self.hi - p) - e + self.lo) / d;
        DoubleDouble::new(q, r)
    }

    /// The nearest double.
    pub fn round(self) -> f64 {
        self.hi + self.lo
    }
}

impl Add for DoubleDouble {
    type Output = Self;

    #[inline(always)]
    fn add(self, other: Self) -> Self {
        let (s, e) = two_sum(self.hi, other.hi);
        DoubleDouble::new(s, e + self.lo + other.lo)
    }
}

impl Mul<f64> for DoubleDouble {
    type Output = Self;

    #[inline(always)]
    fn mul(self, x: f64) -> Self {
        let (p, e) = two_prod(self.hi, x);
        DoubleDouble::new(p, e + self.lo * x)
    }
}

/// To the product of the low parts, which is below the result's bits.
impl Mul for DoubleDouble {
    type Output = Self;

    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        self * other.hi + DoubleDouble::from(self.hi * other.lo)
    }
}

/// `sum_j a_j (y_j + r_j)` for double-double `a`, a double `y` and its
/// residual `r` (what rounding `y` left out), carried to about 106 bits
/// and normalised: `hi` is the sum rounded once, `lo` what that left out.
#[inline(always)]
pub fn dot(a: &[DoubleDouble], y: &[f64], r: &[f64]) -> DoubleDouble {
    let (mut hi, mut lo) = (0.0, 0.0);
    for ((a, &y), &r) in a.iter().zip(y).zip(r) {
        let (p, e) = two_prod(a.hi, y);
        let (s, f) = two_sum(hi, p);
        hi = s;
        lo += f + e + a.lo * y + a.hi * r;
    }
    DoubleDouble::new(hi, lo)
}

/// [`dot`] of each of `K` double-double rows with `y` and `r`, bit for
/// bit, the rows given by column (entry `k` of column `j` at `hi[j * K +
/// k]` and `lo[j * K + k]`) and summed in lockstep: one sum's chain of
/// exact additions waits on its last step, and the others fill the time,
/// four to an instruction where the target has AVX (an event's state on
/// the mechanism, 13 rows of 3).
#[inline(always)]
pub fn dots<const K: usize>(
    (hi_columns, lo_columns): (&[f64], &[f64]),
    y: &[f64],
    r: &[f64],
) -> [DoubleDouble; K] {
    let (mut hi, mut lo) = ([0.0; K], [0.0; K]);
    let columns = hi_columns.chunks_exact(K).zip(lo_columns.chunks_exact(K));
    for ((a_hi, a_lo), (&y, &r)) in columns.zip(y.iter().zip(r)) {
        for k in 0..K {
            let (p, e) = two_prod(a_hi[k], y);
            let (s, f) = two_sum(hi[k], p);
            hi[k] = s;
            lo[k] += f + e + a_lo[k] * y + a_hi[k] * r;
        }
    }
    std::array::from_fn(|k| DoubleDouble::new(hi[k], lo[k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_third_carries_twice_the_digits() {
        // 1/3 = hi + lo with lo the next 53 bits: 3 (hi + lo) - 1 is below
        // 1e-32, where a double third leaves 5.6e-17.
        let third = DoubleDouble::from(1.0).divide(3.0);
        let back = third * 3.0 + DoubleDouble::from(-1.0);
        assert!(back.round().abs() < 1e-32, "{back:?}");
        assert!(third.lo != 0.0);
    }

    #[test]
    fn a_dot_product_rounds_once() {
        // (1 + 2^-60) * 1 + (-1) * 1 = 2^-60: the low part survives the
        // cancellation, which a plain double sum loses entirely.
        let a = [
            DoubleDouble::new(1.0, 2f64.powi(-60)),
            DoubleDouble::from(-1.0),
        ];
        assert_eq!(dot(&a, &[1.0, 1.0], &[0.0, 0.0]).round(), 2f64.powi(-60));
        // A residual of y counts as well.
        let one = [DoubleDouble::from(1.0)];
        let sum = dot(&one, &[1.0], &[2f64.powi(-60)]);
        assert_eq!((sum.hi, sum.lo), (1.0, 2f64.powi(-60)));
        assert_eq!(1.0 + 2f64.powi(-60) - 1.0, 0.0);
    }
}
