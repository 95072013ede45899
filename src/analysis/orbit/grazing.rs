//! Grazing along a branch: where an impacting orbit's impact speed falls
//! to zero as the parameter moves, the orbit touches its guard
//! tangentially and the branch of impacting orbits ends.
//!
//! The impact speed is watched as the guard's rate just after the section
//! event, `q = grad g . f`, on every orbit of the branch. Where the line
//! through the last two orbits' `q` meets zero within the next step, the
//! zero is solved for directly: impacting orbits corrected at three
//! parameters on the impacting side, `q` fitted by a quadratic through
//! them and its zero taken, again with the three twice as close, until
//! the zero stands still or the orbits come too near the graze for the
//! section map (whose Jacobian grows as `1 / q`) to correct them.

use crate::analysis::orbit::section::Section;

/// The guard's rate at `x` just after a section event in `mode`, by
/// central differences along the flow (exact for an affine guard).
pub fn impact_speed(section: &Section, mode: usize, x: &[f64]) -> Option<f64> {
    let model = section.model;
    let guard = model
        .guards(mode)
        .iter()
        .position(|g| g.name == section.guard)?;
    let mut f = vec![0.0; x.len()];
    model.rhs(mode, x, &mut f);
    let size = x.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    let h = 1e-6 * size / f.iter().fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    let along = |s: f64| -> Vec<f64> { x.iter().zip(&f).map(|(x, f)| x + s * f).collect() };
    let q =
        (model.guard(mode, guard, &along(h)) - model.guard(mode, guard, &along(-h))) / (2.0 * h);
    q.is_finite().then_some(q)
}

/// Where the line through `(p0, q0)` and `(p1, q1)` meets `q = 0`.
pub fn predicted((p0, q0): (f64, f64), (p1, q1): (f64, f64)) -> Option<f64> {
    let slope = (q1 - q0) / (p1 - p0);
    let zero = p1 - q1 / slope;
    (zero.is_finite() && slope != 0.0).then_some(zero)
}

/// The zero of the quadratic through three points `(p, q)`, the one
/// nearest `guess`.
pub fn quadratic_zero(points: &[(f64, f64); 3], guess: f64) -> Option<f64> {
    // Newton's divided differences about the guess, then the root of
    // a + b u + c u^2 (u = p - guess) nearest u = 0.
    let [(x0, y0), (x1, y1), (x2, y2)] = *points;
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let c = (d12 - d01) / (x2 - x0);
    let b = d01 + c * ((guess - x0) + (guess - x1));
    let a = y0 + d01 * (guess - x0) + c * (guess - x0) * (guess - x1);
    let u = if c == 0.0 {
        -a / b
    } else {
        let disc = b * b - 4.0 * a * c;
        // No real zero: the fit does not meet zero (its vertex is no root).
        if disc < 0.0 {
            return None;
        }
        let disc = disc.sqrt();
        // The root of smaller size, computed without cancellation.
        let big = -(b + b.signum() * disc) / 2.0;
        let (r1, r2) = (big / c, a / big);
        if r1.abs() < r2.abs() { r1 } else { r2 }
    };
    let zero = guess + u;
    zero.is_finite().then_some(zero)
}

/// Where the impact speeds of a branch's last orbits (`speeds`, parameter
/// and speed, in the branch's order) fall to zero, and how sure that is:
/// the zero of the quadratic through the last three, and its distance
/// from the line's through the last two (the quadratic's own error is
/// smaller still). `None` unless the three fall towards zero on one side,
/// the zero lies ahead of the last and within the branch's `range` (its
/// start's parameter and where it is to go: past a fold a branch travels
/// away from its end).
pub fn extrapolated(speeds: &[(f64, f64)], range: (f64, f64)) -> Option<(f64, f64)> {
    let &[a, b, c] = speeds.last_chunk::<3>()?;
    let falling = a.1.signum() == b.1.signum()
        && b.1.signum() == c.1.signum()
        && c.1.abs() < b.1.abs()
        && b.1.abs() < a.1.abs();
    let line = predicted(b, c)?;
    let zero = quadratic_zero(&[a, b, c], line)?;
    let step = c.0 - b.0;
    let ahead = (zero - c.0) * step.signum() >= 0.0;
    (falling && ahead && within(zero, range)).then_some((zero, (zero - line).abs()))
}

/// Whether `p` lies between the two ends of `range`, in either order.
pub fn within(p: f64, (a, b): (f64, f64)) -> bool {
    a.min(b) <= p && p <= a.max(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_falling_to_zero_put_the_graze_ahead_and_say_how_surely() {
        // q = (3 - p)(1 + p/10), approached from below.
        let q = |p: f64| (3.0 - p) * (1.0 + p / 10.0);
        let speeds: Vec<(f64, f64)> = [2.9, 2.95, 2.99].iter().map(|&p| (p, q(p))).collect();
        let (zero, accuracy) = extrapolated(&speeds, (2.0, 4.0)).unwrap();
        assert!((zero - 3.0).abs() < 1e-12, "{zero}");
        assert!(accuracy > 0.0 && accuracy < 1e-3, "{accuracy}");
        // Past a fold, going away from the end: still found in range.
        assert!(extrapolated(&speeds, (4.0, 2.0)).is_some());
        // Out of range, rising, or two points only: nothing.
        assert_eq!(extrapolated(&speeds, (2.0, 2.995)), None);
        let rising: Vec<(f64, f64)> = speeds.iter().rev().copied().collect();
        assert_eq!(extrapolated(&rising, (0.0, 4.0)), None);
        assert_eq!(extrapolated(&speeds[1..], (2.0, 4.0)), None);
    }

    #[test]
    fn a_line_and_a_quadratic_meet_zero_where_they_should() {
        assert_eq!(predicted((0.0, 2.0), (1.0, 1.0)), Some(2.0));
        // q = (3 - p)(1 + p/10): zero at 3.
        let q = |p: f64| (3.0 - p) * (1.0 + p / 10.0);
        let points = [(2.9, q(2.9)), (2.95, q(2.95)), (2.99, q(2.99))];
        let zero = quadratic_zero(&points, 3.01).unwrap();
        assert!((zero - 3.0).abs() < 1e-14, "{zero}");
    }
}
