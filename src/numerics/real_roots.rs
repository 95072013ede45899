//! Real roots of polynomials and brackets, for the event scan of a step's
//! dense output (`src/engine/step/locate.rs`): the polynomial through equally
//! spaced samples, every real root of a low-degree polynomial on `(0, 1)`
//! (by recursion on its derivative's), and the refinement of a bracket. The
//! certified first crossing of a Taylor series is
//! [`first_crossing`](crate::numerics::first_crossing)'s.

use crate::numerics::polynomial::eval_plain;

/// The highest degree of dense output the scan takes.
pub const MAX_DEGREE: usize = 7;

/// Illinois iteration on a bracket `g(a) * g(b) <= 0`. Returns the end on
/// the side of `g(b)`, so the state there has just crossed.
pub fn refine(
    mut a: f64,
    mut fa: f64,
    mut b: f64,
    mut fb: f64,
    g: &mut impl FnMut(f64) -> f64,
    fallback: &dyn Fn(f64) -> f64,
) -> f64 {
    if fb == 0.0 {
        return b;
    }
    // Rounding can make the guard itself disagree with the polynomial that
    // found the bracket; the polynomial then decides.
    if fa.signum() == fb.signum() {
        return refine_polynomial(a, b, fallback);
    }
    let mut side = 0;
    for _ in 0..200 {
        if b - a <= 4.0 * f64::EPSILON * b.abs().max(f64::MIN_POSITIVE) {
            break;
        }
        let mut m = (a * fb - b * fa) / (fb - fa);
        if !(m > a && m < b) {
            m = 0.5 * (a + b);
        }
        let fm = g(m);
        if fm == 0.0 {
            return m;
        }
        if fm.signum() == fa.signum() {
            (a, fa) = (m, fm);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = (m, fm);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    b
}

fn refine_polynomial(mut a: f64, mut b: f64, p: &dyn Fn(f64) -> f64) -> f64 {
    let fa = p(a);
    if fa.is_nan() || fa.signum() == p(b).signum() {
        return b;
    }
    while b - a > 4.0 * f64::EPSILON * b.abs() {
        let m = 0.5 * (a + b);
        if p(m).signum() == fa.signum() {
            a = m;
        } else {
            b = m;
        }
    }
    b
}

/// Monomial coefficients (lowest first) of the polynomial of degree
/// `N - 1` through values `v` at equispaced `s` from 0 to 1.
pub fn polynomial_through<const N: usize>(v: &[f64; N]) -> [f64; N] {
    // Newton divided differences on the equispaced nodes, then expanded.
    let node = |i: usize| i as f64 / (N - 1) as f64;
    let mut d = *v;
    for level in 1..N {
        for i in (level..N).rev() {
            d[i] = (d[i] - d[i - 1]) / (node(i) - node(i - level));
        }
    }
    let mut poly = [0.0; N];
    for i in (0..N).rev() {
        // poly = poly * (s - node(i)) + d[i]
        let mut next = [0.0; N];
        for k in 0..N - 1 {
            next[k + 1] += poly[k];
            next[k] -= node(i) * poly[k];
        }
        next[0] += d[i];
        poly = next;
    }
    poly
}

/// The coefficients of `poly'` (one fewer than `poly`'s, zero-padded).
pub fn derivative(poly: &[f64]) -> [f64; MAX_DEGREE] {
    let mut d = [0.0; MAX_DEGREE];
    for k in 1..poly.len().min(MAX_DEGREE + 1) {
        d[k - 1] = k as f64 * poly[k];
    }
    d
}

/// At most seven sorted values in `(0, 1)`: the roots or turning points of
/// a polynomial of degree seven or less, kept without allocating.
#[derive(Debug, Clone, Copy, Default)]
pub struct Points {
    len: usize,
    values: [f64; MAX_DEGREE],
}

impl Points {
    fn push(&mut self, x: f64) {
        self.values[self.len] = x;
        self.len += 1;
    }

    /// The values, in increasing order.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len]
    }

    /// How many there are.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The values, in increasing order.
    pub fn iter(&self) -> std::slice::Iter<'_, f64> {
        self.as_slice().iter()
    }
}

/// The real roots of `poly'` in `(0, 1)`, sorted.
pub fn critical_points(poly: &[f64]) -> Points {
    let d = derivative(poly);
    roots_in_unit_interval(&d[..poly.len().saturating_sub(1).min(MAX_DEGREE)])
}

/// Every real root of `poly` in `(0, 1)`, sorted, by recursion on the
/// derivative: the critical points split `[0, 1]` into monotone pieces.
pub fn roots_in_unit_interval(poly: &[f64]) -> Points {
    let mut roots = Points::default();
    let Some(degree) = poly.iter().rposition(|c| *c != 0.0).filter(|d| *d > 0) else {
        return roots;
    };
    let p = &poly[..=degree];
    let turning = if degree == 1 {
        Points::default()
    } else {
        critical_points(p)
    };
    let (mut left, mut f_left) = (0.0, p[0]);
    for &right in turning.iter().chain(std::iter::once(&1.0)) {
        let f_right = eval_plain(p, right);
        if f_left * f_right < 0.0 {
            // Illinois rather than bisection: a septic's roots take a few
            // iterations each, not fifty.
            let at = |s: f64| eval_plain(p, s);
            roots.push(refine(left, f_left, right, f_right, &mut { at }, &at));
        } else if f_right == 0.0 && right < 1.0 {
            roots.push(right);
        }
        (left, f_left) = (right, f_right);
    }
    roots
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_root_in_the_unit_interval_is_found_in_order() {
        // (s - 0.2)(s - 0.5)(s - 0.9)(s - 1.5): three roots inside, one out.
        let roots = [0.2, 0.5, 0.9, 1.5];
        let mut poly = vec![1.0];
        for r in roots {
            let mut next = vec![0.0; poly.len() + 1];
            for (k, c) in poly.iter().enumerate() {
                next[k + 1] += c;
                next[k] -= r * c;
            }
            poly = next;
        }
        let found = roots_in_unit_interval(&poly);
        assert_eq!(found.len(), 3);
        for (got, want) in found.iter().zip(&roots[..3]) {
            assert!((got - want).abs() < 1e-14, "{got} against {want}");
        }
    }

    #[test]
    fn the_polynomial_through_samples_of_a_cubic_is_that_cubic() {
        let cubic = [0.3, -1.0, 2.0, 0.5];
        let samples: [f64; 4] = std::array::from_fn(|i| eval_plain(&cubic, i as f64 / 3.0));
        let fitted = polynomial_through(&samples);
        for (a, b) in fitted.iter().zip(&cubic) {
            assert!((a - b).abs() < 1e-13, "{fitted:?}");
        }
    }
}
