//! The step of a central difference: `eps^(1/3)` of the value's size (at
//! least 1), which balances the truncation (second order in the step)
//! against the rounding of the difference (an ulp over the step). Written
//! once as a constant: `f64::cbrt` is no `const fn`, and calling it for
//! every component of every difference was a measurable part of a run
//! with many events.

/// `f64::EPSILON.cbrt()`, checked equal to it bit for bit by a test.
pub const CBRT_EPSILON: f64 = 6.0554544523933395e-6;

/// The central-difference step for a component of size `x`.
#[inline]
pub fn step_for(x: f64) -> f64 {
    CBRT_EPSILON * x.abs().max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_constant_is_the_cube_root_of_epsilon() {
        assert_eq!(CBRT_EPSILON.to_bits(), f64::EPSILON.cbrt().to_bits());
        assert_eq!(step_for(-4.0), 4.0 * CBRT_EPSILON);
        assert_eq!(step_for(0.5), CBRT_EPSILON);
    }
}
