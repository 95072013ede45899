//! An ellipsoid: the other enclosure of a run's errors (see [`super`]).
//!
//! The set is `{ x : x^T P^-1 x <= 1 }`, `P` symmetric positive
//! semidefinite. A linear map takes it exactly (`M P M^T`: no wrapping,
//! whatever the map turns or shears). A local error box of half-width `l`
//! in `m` components lies in the ball of radius `l sqrt(m)`, which is added
//! by the outer ellipsoid of the Minkowski sum of least trace,
//! `(1 + 1 / p) P + (1 + p) Q` with `p = sqrt(tr P / tr Q)` (exact for two
//! balls: the radii add). Where the set is long and thin (the phase error
//! of an orbit whose period depends on its energy), that sum swells the
//! thin axes, which the parallelepiped beside it does not.

use super::storage::Storage;

/// The ellipsoid, its matrix kept in `S` (see [`Storage`]).
#[derive(Debug, Clone)]
pub(super) struct Ellipsoid<S: Storage> {
    n: usize,
    /// `P`, row-major `n x n`.
    p: S::Matrix,
}

impl<S: Storage> Ellipsoid<S> {
    /// No error, in dimension `n` (that `S` holds).
    pub(super) fn new(n: usize) -> Self {
        Ellipsoid { n, p: S::matrix(n) }
    }

    /// Carry the set of `n` components through `m` (row-major), and add a
    /// local error box of half-width `local`. Inlined where `n` is known
    /// (see [`unrolled`](super::unrolled)).
    #[inline(always)]
    pub(super) fn map(&mut self, n: usize, m: &[f64], local: f64) {
        let mut mp = S::matrix(n);
        let (mp, p) = (mp.as_mut(), self.p.as_mut());
        for i in 0..n {
            for j in 0..n {
                mp[i * n + j] = (0..n).map(|k| m[i * n + k] * p[k * n + j]).sum();
            }
        }
        for i in 0..n {
            for j in i..n {
                let v: f64 = (0..n).map(|k| mp[i * n + k] * m[j * n + k]).sum();
                p[i * n + j] = v;
                p[j * n + i] = v;
            }
        }
        if local <= 0.0 {
            return;
        }
        let q = n as f64 * local * local;
        let trace_p: f64 = (0..n).map(|i| p[i * n + i]).sum();
        let (keep, add) = if trace_p > 0.0 {
            let ratio = (trace_p / (q * n as f64)).sqrt();
            (1.0 + 1.0 / ratio, 1.0 + ratio)
        } else {
            (0.0, 1.0)
        };
        for v in p[..n * n].iter_mut() {
            *v *= keep;
        }
        for i in 0..n {
            p[i * n + i] += add * q;
        }
    }

    /// The half-width of the set along each component, the largest.
    pub(super) fn state_bound(&self) -> f64 {
        let (n, p) = (self.n, self.p.as_ref());
        (0..n)
            .map(|i| p[i * n + i].max(0.0).sqrt())
            .fold(0.0, f64::max)
    }

    /// The half-width of the set along `gradient`.
    pub(super) fn along(&self, gradient: &[f64]) -> f64 {
        let (n, p) = (self.n, self.p.as_ref());
        let mut s = 0.0;
        for i in 0..n {
            let row: f64 = (0..n).map(|j| p[i * n + j] * gradient[j]).sum();
            s += gradient[i] * row;
        }
        s.max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::bound::error_set::storage::Fixed;

    #[test]
    fn a_map_is_carried_exactly_and_balls_add_their_radii() {
        // A unit ball stretched by 3 along x: its half-widths are 3 and 1.
        let mut e = Ellipsoid::<Fixed>::new(2);
        e.map(2, &[1.0, 0.0, 0.0, 1.0], 1.0 / 2f64.sqrt());
        e.map(2, &[3.0, 0.0, 0.0, 1.0], 0.0);
        assert!((e.along(&[1.0, 0.0]) - 3.0).abs() < 1e-12);
        assert!((e.along(&[0.0, 1.0]) - 1.0).abs() < 1e-12);
        // Two balls of radii 1 and 2: one of radius 3.
        let mut e = Ellipsoid::<Fixed>::new(2);
        e.map(2, &[1.0, 0.0, 0.0, 1.0], 1.0 / 2f64.sqrt());
        e.map(2, &[1.0, 0.0, 0.0, 1.0], 2.0 / 2f64.sqrt());
        assert!((e.state_bound() - 3.0).abs() < 1e-12, "{}", e.state_bound());
    }
}
