//! The saltation matrix of an event: how a small change of the state just
//! before an event becomes a change just after it, the event's shift in
//! time included (docs/physics.md's impacts, and any reset).
//!
//! `S = R + (f+ - R f-) grad(g)^T / (grad(g) . f-)`, with `R` the reset's
//! Jacobian, `g` the guard, `f-` and `f+` the rates just before and after.
//! A change `d` before the event moves it by `-grad(g) . d / (grad(g) .
//! f-)` in time and leaves `S d` after it. The error bounds carry errors
//! through events by it ([`crate::engine::bound::tangent`]), and sensitivities,
//! orbits and Lyapunov spectra carry derivatives by it
//! ([`crate::engine::bound::variational`]).

/// `S` into `out` (row-major `n x n`) from `reset` (`R`, row-major),
/// `gradient`, and the rates `before` and `after`. Returns the closing
/// speed `grad(g) . f-` (zero at a graze, where `S` is not defined) and
/// the largest component of `f+ - R f-`: what firing the event a time
/// `dt` late leaves in the state, per unit of `dt`.
pub fn matrix(
    reset: &[f64],
    gradient: &[f64],
    before: &[f64],
    after: &[f64],
    out: &mut [f64],
) -> (f64, f64) {
    let n = gradient.len();
    let closing: f64 = gradient.iter().zip(before).map(|(g, f)| g * f).sum();
    let mut largest_jump: f64 = 0.0;
    for i in 0..n {
        let pushed: f64 = (0..n).map(|k| reset[i * n + k] * before[k]).sum();
        largest_jump = largest_jump.max((after[i] - pushed).abs());
        let jump = (after[i] - pushed) / closing;
        for j in 0..n {
            out[i * n + j] = reset[i * n + j] + jump * gradient[j];
        }
    }
    (closing, largest_jump)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ball falling at speed 2 onto a floor (guard `y`), restitution
    /// `r = 1/2`: `R = diag(1, -r)`, `f- = (-2, -g)`, `f+ = (1, -g)`. By
    /// hand, `S = [[1 - 3/2, 0], [(1 + r) g / 2, -r]]`, and its
    /// determinant is `r^2`: the phase volume a restitution takes.
    #[test]
    fn a_bounce_s_saltation_matrix_is_the_closed_form() {
        let (r, g) = (0.5, 9.81);
        let reset = [1.0, 0.0, 0.0, -r];
        let mut s = [0.0; 4];
        let (closing, jump) = matrix(&reset, &[1.0, 0.0], &[-2.0, -g], &[1.0, -g], &mut s);
        assert_eq!(closing, -2.0);
        // f+ - R f- = (1 + 2, -g - r g).
        assert_eq!(jump, (1.0 + r) * g);
        let expected = [1.0 - 1.5, 0.0, (1.0 + r) * g / 2.0, -r];
        for (got, want) in s.iter().zip(expected) {
            assert!((got - want).abs() < 1e-15, "{s:?}");
        }
        let det = s[0] * s[3] - s[1] * s[2];
        assert!((det - r * r).abs() < 1e-15, "{det}");
    }
}
