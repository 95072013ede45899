//! An ellipsoid: the other enclosure of a run's errors (see [`super`]).
//!
//! An ellipsoid `{ x : x^T P^-1 x <= 1 }`, `P` symmetric positive
//! semidefinite, takes a linear map exactly (`M P M^T`: no wrapping,
//! whatever the map turns or shears). A local error box of half-width `l`
//! in `m` components lies in the ball of radius `l sqrt(m)`, which is added
//! by the outer ellipsoid of the Minkowski sum of least trace,
//! `(1 + 1 / p) P + (1 + p) Q` with `p = sqrt(tr P / tr Q)` (exact for two
//! balls, or any two ellipsoids of one shape: the radii add).
//!
//! Where the set is long and thin (the phase error of an orbit whose
//! period depends on its energy), that sum swells the thin axes by about
//! the root of the long one times the ball's: no ellipsoid holds a thin
//! set beside a round one closely. So the errors are held as a sum of two
//! ellipsoids, the young and the old, whose half-widths add: each step's
//! ball joins the young, which the flow has not yet drawn out, and the
//! young join the old after 64, 128, 256, ... local errors, when the flow
//! has drawn both alike. Henon-Heiles' bound at t = 2e3, 2e4 and 2e5 came 2.9,
//! 20 and 144 times an exact enclosure of the same errors and tangents
//! (one ellipsoid: 5.3, 50 and 393 times).

use super::storage::Storage;

/// The young ellipsoid first joins the old after this many local errors,
/// then after twice as many as the time before.
const FIRST_MERGE: u64 = 64;

/// The two ellipsoids, their matrices kept in `S` (see [`Storage`]).
#[derive(Debug, Clone)]
pub(super) struct Ellipsoid<S: Storage> {
    n: usize,
    /// The old ellipsoid's `P`, row-major `n x n`.
    old: S::Matrix,
    /// The young one's.
    young: S::Matrix,
    /// Local errors added, and the count at which the young next join the
    /// old.
    added: u64,
    merge_at: u64,
}

impl<S: Storage> Ellipsoid<S> {
    /// No error, in dimension `n` (that `S` holds).
    pub(super) fn new(n: usize) -> Self {
        Ellipsoid {
            n,
            old: S::matrix(n),
            young: S::matrix(n),
            added: 0,
            merge_at: FIRST_MERGE,
        }
    }

    /// Carry the set of `n` components through `m` (row-major), and add a
    /// local error box of half-width `local`. Inlined where `n` is known
    /// (see [`unrolled`](super::unrolled)).
    #[inline(always)]
    pub(super) fn map(&mut self, n: usize, m: &[f64], local: f64) {
        map_one::<S>(n, m, self.old.as_mut());
        map_one::<S>(n, m, self.young.as_mut());
        let q = n as f64 * local * local;
        // (An error whose square underflows adds nothing a bound could
        // tell.)
        if !(q > 0.0) {
            return;
        }
        let young = self.young.as_mut();
        let (keep, add) = least_trace(trace(n, young), q * n as f64);
        for v in young[..n * n].iter_mut() {
            *v *= keep;
        }
        for i in 0..n {
            young[i * n + i] += add * q;
        }
        self.added += 1;
        if self.added == self.merge_at {
            self.merge_at = self.merge_at.saturating_mul(2);
            let (old, young) = (self.old.as_mut(), self.young.as_mut());
            let (keep, add) = least_trace(trace(n, old), trace(n, young));
            for (o, y) in old[..n * n].iter_mut().zip(young[..n * n].iter_mut()) {
                *o = keep * *o + add * *y;
                *y = 0.0;
            }
        }
    }

    /// The half-width of the set along each component, the largest.
    pub(super) fn state_bound(&self) -> f64 {
        let (n, old, young) = (self.n, self.old.as_ref(), self.young.as_ref());
        (0..n)
            .map(|i| old[i * n + i].max(0.0).sqrt() + young[i * n + i].max(0.0).sqrt())
            .fold(0.0, f64::max)
    }

    /// The half-width of the set along `gradient`.
    pub(super) fn along(&self, gradient: &[f64]) -> f64 {
        let n = self.n;
        let along = |p: &[f64]| {
            let mut s = 0.0;
            for i in 0..n {
                let row: f64 = (0..n).map(|j| p[i * n + j] * gradient[j]).sum();
                s += gradient[i] * row;
            }
            s.max(0.0).sqrt()
        };
        along(self.old.as_ref()) + along(self.young.as_ref())
    }
}

/// The trace of a row-major `n x n` `p`.
fn trace(n: usize, p: &[f64]) -> f64 {
    (0..n).map(|i| p[i * n + i]).sum()
}

/// The weights `(1 + 1 / r, 1 + r)`, `r = sqrt(tr P / tr Q)`, of `P` and
/// `Q` in the outer ellipsoid of least trace of their Minkowski sum; `Q`
/// alone where `P` is empty.
fn least_trace(trace_p: f64, trace_q: f64) -> (f64, f64) {
    if trace_p > 0.0 {
        let ratio = (trace_p / trace_q).sqrt();
        (1.0 + 1.0 / ratio, 1.0 + ratio)
    } else {
        (0.0, 1.0)
    }
}

/// `p = m p m^T` for a row-major `n x n` `p`, symmetric.
#[inline(always)]
fn map_one<S: Storage>(n: usize, m: &[f64], p: &mut [f64]) {
    let mut mp = S::matrix(n);
    let mp = mp.as_mut();
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::bound::error_set::storage::Fixed;

    #[test]
    fn a_thin_set_beside_round_errors_is_held_as_two() {
        // A shear with a round local error at each of k steps: the exact
        // set's half-width along the sheared component is the sum over
        // the steps of `(1 + j) l` (the errors sheared `j` times). One
        // ellipsoid takes in every ball beside the long, thin set and
        // comes out 67 times that; the young and the old, 27 times.
        let (k, l) = (2000, 1e-12);
        let mut e = Ellipsoid::<Fixed>::new(2);
        for _ in 0..k {
            e.map(2, &[1.0, 1.0, 0.0, 1.0], l);
        }
        let exact: f64 = (0..k).map(|j| (1 + j) as f64 * l).sum();
        let bound = e.state_bound();
        assert!(bound >= exact, "{bound:e} below the exact {exact:e}");
        assert!(bound < 35.0 * exact, "{bound:e} against {exact:e}");
        // Along the unsheared component, the sum of the errors, k l.
        let thin = e.along(&[0.0, 1.0]);
        assert!(thin >= k as f64 * l, "{thin:e}");
    }

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
