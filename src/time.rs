//! Simulation time kept as an unevaluated sum of two `f64`s.
//!
//! A run of 10^7 impacts adds 10^7 flight times to a clock near 10^7: a plain
//! `f64` sum loses about one ulp per addition, which grows to microseconds and
//! spoils the state at the end. [`Time`] adds each flight time with an
//! error-free transformation (Knuth's two-sum, from
//! [`crate::numerics::double_double`]), so the clock stays exact to
//! about 1e-32 relative and a flow can always be evaluated at a small elapsed
//! time `tau` from its own origin.

use std::cmp::Ordering;

use crate::numerics::double_double::{quick_two_sum, two_sum};

/// A stretch of simulated time, `hi + lo` as [`Time`] holds a point: a
/// period rounded to a double and jumped over `k` times misses by `k` times
/// its rounding (the mechanism's period, 43,372 times: 8e-14).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Span {
    hi: f64,
    lo: f64,
}

impl Span {
    /// The nearest `f64`.
    pub fn value(self) -> f64 {
        self.hi
    }
}

impl From<f64> for Span {
    /// `tau` exactly.
    fn from(tau: f64) -> Self {
        Span { hi: tau, lo: 0.0 }
    }
}

/// A point in simulated time, `hi + lo` with `|lo| <= ulp(hi) / 2`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Time {
    hi: f64,
    lo: f64,
}

impl Time {
    /// The time `t`, exactly.
    pub fn new(t: f64) -> Self {
        Time { hi: t, lo: 0.0 }
    }

    /// The nearest `f64`.
    pub fn value(self) -> f64 {
        self.hi
    }

    /// What [`value`](Time::value) leaves out: `self - self.value()`.
    pub fn rounding(self) -> f64 {
        self.lo
    }

    /// `self + tau`, with the rounding error of the sum kept in `lo`.
    pub fn after(self, tau: f64) -> Self {
        let (s, e) = two_sum(self.hi, tau);
        let (hi, lo) = quick_two_sum(s, e + self.lo);
        Time { hi, lo }
    }

    /// `self + k tau`, the product kept exact (`k` below 2^53): jumping
    /// over `k` steps of `tau` lands where `k` additions of `tau` do, to
    /// the double-double's own rounding.
    pub fn after_multiple(self, k: u64, tau: Span) -> Self {
        let k = k as f64;
        let product = k * tau.hi;
        let rounding = k.mul_add(tau.hi, -product);
        self.after(product).after(rounding + k * tau.lo)
    }

    /// `self - earlier` to double-double, as a [`Span`]: a period measured
    /// between two events, which a run may multiply by millions.
    pub fn span_since(self, earlier: Time) -> Span {
        let (s, e) = two_sum(self.hi, -earlier.hi);
        let (hi, lo) = two_sum(s, e + (self.lo - earlier.lo));
        Span { hi, lo }
    }

    /// `self - earlier` as an `f64`, accurate to one rounding of the result.
    pub fn since(self, earlier: Time) -> f64 {
        let (s, e) = two_sum(self.hi, -earlier.hi);
        s + (e + (self.lo - earlier.lo))
    }

    /// `t - self` for a plain `f64` time `t`.
    pub fn until(self, t: f64) -> f64 {
        Time::new(t).since(self)
    }
}

impl PartialOrd for Time {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        match self.hi.partial_cmp(&other.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&other.lo),
            unequal => Some(unequal),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_addition_keeps_the_exact_sum() {
        // 0.1 is not representable; ten million additions of the same f64
        // must equal 1e7 times that f64, which a plain sum misses by ~1e-4.
        let step = 0.1_f64;
        let mut t = Time::new(0.0);
        let mut naive = 0.0_f64;
        for _ in 0..10_000_000 {
            t = t.after(step);
            naive += step;
        }
        // The f64 nearest 0.1 is 0.1000000000000000055511151231257827...,
        // so the exact sum exceeds 1e6 by 1e7 times that excess.
        let exact_excess = 5.551_115_123_125_783e-18 * 1e7;
        let got = t.since(Time::new(1e6));
        assert!(
            (got - exact_excess).abs() < 1e-20,
            "got {got}, want {exact_excess}"
        );
        assert!((naive - 1e6).abs() > 1e-6, "the naive sum should drift");
    }

    #[test]
    fn a_multiple_lands_where_repeated_additions_do() {
        let (start, step, k) = (Time::new(3.0).after(1e-20), 0.1_f64, 1_000_000);
        let mut added = start;
        for _ in 0..k {
            added = added.after(step);
        }
        let jumped = start.after_multiple(k, Span::from(step));
        assert!(jumped.since(added).abs() < 1e-24, "{}", jumped.since(added));
        // A rounded product misses by the rounding of 1e5: 5.6e-12.
        assert!(start.after(k as f64 * step).since(added).abs() > 1e-12);
    }

    #[test]
    fn a_span_keeps_what_a_double_period_loses() {
        // Two events 1/3 apart (as a double-double) at times near 1e4:
        // their span times a million lands where a million additions of
        // the span do; the span rounded to a double misses by about 1e-12.
        let third = 1.0 / 3.0;
        let residual = -3.0f64.mul_add(third, -1.0) / 3.0;
        let start = Time::new(1e4).after(1e-13);
        let later = start.after(third).after(residual);
        let span = later.span_since(start);
        assert_eq!(span.value(), third);
        let k = 1_000_000;
        let mut added = start;
        for _ in 0..k {
            added = added.after(third).after(residual);
        }
        let jumped = start.after_multiple(k, span);
        assert!(
            jumped.since(added).abs() < 1e-20,
            "{:e}",
            jumped.since(added)
        );
        let rounded = start.after_multiple(k, Span::from(span.value()));
        assert!(
            rounded.since(added).abs() > 1e-12,
            "{:e}",
            rounded.since(added)
        );
    }

    #[test]
    fn since_is_antisymmetric_and_ordered() {
        let a = Time::new(1e7).after(1e-9).after(3e-25);
        let b = Time::new(1e7);
        assert!(a > b);
        assert_eq!(a.since(b), -b.since(a));
        assert!((a.since(b) - 1e-9).abs() < 1e-24);
    }
}
