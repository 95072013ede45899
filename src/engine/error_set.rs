//! The set of state errors a run may carry: what its stated error bound
//! is read from.
//!
//! Every numerical step leaves a local error (its embedded estimate, a box
//! of that half-width around the state). Later steps carry it along the
//! flow's tangent map, and every event carries it across the reset by the
//! saltation matrix: an error `d` moves the event by `d / closing speed`,
//! which the reset then turns into a jump of the state (see
//! [`tangent::saltation`]). Summing the local errors' sizes ignores all of
//! that, and near a slow impact understates the error by orders of
//! magnitude; multiplying norms overstates it just as badly (a shear
//! applied a thousand times grows linearly, its norm's power
//! exponentially).
//!
//! So the set is kept as Lohner's parallelepiped: `{ B u : |u_j| <= r_j }`
//! with `B` orthogonal. A linear map `M` takes it to `M B box(r)`, which is
//! held again in the orthogonal factor `Q` of `M B` (columns taken
//! longest first): `Q box(|Q^T M B| r)`. The frame follows the flow's
//! rotation, so an oscillation does not inflate the box at every step
//! (the wrapping effect). A new local error box of half-width `l` is
//! added as `Q box(|Q^T| l)`.
//!
//! Dimensions above [`TRACKED`] are not tracked (the `n^3` cost per step
//! would dominate a large ODE): there the bound is the plain sum of the
//! local errors, without amplification, and no event-time bound is stated.
//!
//! [`tangent::saltation`]: crate::engine::tangent::Tangents::saltation

/// Largest state dimension whose errors are carried through flows and
/// events.
pub const TRACKED: usize = 8;

/// The errors a run may carry, for dimensions up to [`TRACKED`].
#[derive(Debug, Clone)]
pub struct ErrorSet {
    n: usize,
    /// Orthonormal directions, column-major `n x n` (fixed arrays: the
    /// map below runs at every step, and small copies of slices of
    /// unknown length are calls).
    basis: [f64; TRACKED * TRACKED],
    /// Half-widths along each direction.
    radii: [f64; TRACKED],
    /// Sum of the local errors added (the untracked bound), and of their
    /// squares (the untracked graze check's scale).
    sum: f64,
    squares: f64,
    /// Set once a non-finite error entered: every bound is then infinite.
    poisoned: bool,
    order: [usize; TRACKED],
}

impl ErrorSet {
    /// No error yet, in dimension `n`.
    pub fn new(n: usize) -> Self {
        let mut basis = [0.0; TRACKED * TRACKED];
        if n <= TRACKED {
            for i in 0..n {
                basis[i * n + i] = 1.0;
            }
        }
        ErrorSet {
            n,
            basis,
            radii: [0.0; TRACKED],
            sum: 0.0,
            squares: 0.0,
            poisoned: false,
            order: std::array::from_fn(|i| i),
        }
    }

    /// Whether errors are carried through flows and events in this
    /// dimension.
    pub fn tracked(&self) -> bool {
        self.n <= TRACKED
    }

    /// Whether no error has been added: an exact run's set stays empty, and
    /// the engine then skips every tangent it would otherwise compute.
    pub fn is_empty(&self) -> bool {
        self.sum == 0.0
    }

    /// Carry the set through the linear map `m` (row-major `n x n`) and add
    /// a local error box of half-width `local`.
    pub fn map(&mut self, m: &[f64], local: f64) {
        self.sum += local;
        self.squares += local * local;
        if !local.is_finite() || !m.iter().all(|x| x.is_finite()) {
            self.poisoned = true;
        }
        if !self.tracked() || self.poisoned {
            return;
        }
        let n = self.n;
        let mut product = [0.0; TRACKED * TRACKED];
        // product = m * basis, column-major.
        for j in 0..n {
            for i in 0..n {
                product[j * n + i] = (0..n).map(|k| m[i * n + k] * self.basis[j * n + k]).sum();
            }
        }
        // Longest error columns first: Q's first direction follows the
        // dominant error.
        let mut weight = [0.0; TRACKED];
        for (j, w) in weight[..n].iter_mut().enumerate() {
            let column = &product[j * n..(j + 1) * n];
            *w = column.iter().map(|x| x * x).sum::<f64>() * self.radii[j] * self.radii[j];
        }
        // The old basis is spent: the new one is written over it.
        if n == 2 {
            // The common case (one degree of freedom): the frame is the
            // heavier column's direction and its perpendicular.
            let first = usize::from(weight[1] > weight[0]);
            let (c, s) = direction(&product[2 * first..2 * first + 2])
                .or_else(|| direction(&product[2 - 2 * first..4 - 2 * first]))
                .unwrap_or((1.0, 0.0));
            self.basis[..4].copy_from_slice(&[c, s, -s, c]);
        } else {
            let order = &mut self.order[..n];
            order.sort_unstable_by(|&a, &b| weight[b].total_cmp(&weight[a]));
            orthonormalize(n, &product, order, &mut self.basis);
        }
        let q = &self.basis;
        // New radii: |Q^T product| r + |Q^T| local.
        let mut radii = [0.0; TRACKED];
        for (a, r) in radii[..n].iter_mut().enumerate() {
            let qa = &q[a * n..(a + 1) * n];
            let carried: f64 = (0..n)
                .map(|j| {
                    let dot: f64 = (0..n).map(|i| qa[i] * product[j * n + i]).sum();
                    dot.abs() * self.radii[j]
                })
                .sum();
            let added: f64 = qa.iter().map(|x| x.abs()).sum::<f64>() * local;
            *r = carried + added;
        }
        self.radii = radii;
    }

    /// Add an error box of half-width `local` where the state stands (a
    /// rare event: the identity is built each time).
    pub fn widen(&mut self, local: f64) {
        let n = self.n;
        if !self.tracked() {
            self.sum += local;
            return;
        }
        let identity: Vec<f64> = (0..n * n).map(|k| f64::from(k % (n + 1) == 0)).collect();
        self.map(&identity, local);
    }

    /// The largest error any state component may carry.
    pub fn state_bound(&self) -> f64 {
        if self.poisoned {
            return f64::INFINITY;
        }
        if !self.tracked() {
            return self.sum;
        }
        let n = self.n;
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| self.basis[j * n + i].abs() * self.radii[j])
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// The largest error of the linear function `gradient . x`. Where the
    /// set is not tracked, an optimistic scale instead: `sum |gradient_i|`
    /// times the root-sum-square of the local errors, as if independent.
    pub fn along(&self, gradient: &[f64]) -> f64 {
        let n = self.n;
        if self.poisoned {
            return f64::INFINITY;
        }
        if !self.tracked() {
            return gradient.iter().map(|g| g.abs()).sum::<f64>() * self.squares.sqrt();
        }
        (0..n)
            .map(|j| {
                let dot: f64 = (0..n).map(|i| gradient[i] * self.basis[j * n + i]).sum();
                dot.abs() * self.radii[j]
            })
            .sum()
    }
}

/// The unit vector along a plane vector, if it has a direction.
fn direction(v: &[f64]) -> Option<(f64, f64)> {
    let length = v[0].hypot(v[1]);
    (length > 0.0 && length.is_finite()).then(|| (v[0] / length, v[1] / length))
}

/// Orthonormal columns `q` (column-major) spanning the columns of `m` taken
/// in `order`, completed by unit vectors where `m` is rank-deficient (a
/// reset that collapses a direction). Gram-Schmidt twice over, which keeps
/// `q` orthogonal to round-off for the small `n` tracked.
fn orthonormalize(n: usize, m: &[f64], order: &[usize], q: &mut [f64]) {
    let mut filled = 0;
    let mut candidate = [0.0; TRACKED];
    let candidate = &mut candidate[..n];
    for pick in order
        .iter()
        .map(|&j| Some(j))
        .chain((0..n).map(|_| None))
        .enumerate()
    {
        if filled == n {
            break;
        }
        match pick {
            (_, Some(j)) => candidate.copy_from_slice(&m[j * n..(j + 1) * n]),
            (k, None) => {
                candidate.fill(0.0);
                candidate[k - order.len()] = 1.0;
            }
        }
        let norm0 = candidate.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm0 == 0.0 || !norm0.is_finite() {
            continue;
        }
        for _ in 0..2 {
            for k in 0..filled {
                let qk = &q[k * n..(k + 1) * n];
                let dot: f64 = qk.iter().zip(candidate.iter()).map(|(a, b)| a * b).sum();
                for (c, a) in candidate.iter_mut().zip(qk) {
                    *c -= dot * a;
                }
            }
        }
        let norm = candidate.iter().map(|x| x * x).sum::<f64>().sqrt();
        // A column (nearly) inside the span so far adds no direction.
        if norm <= 1e-10 * norm0 {
            continue;
        }
        for (slot, c) in q[filled * n..(filled + 1) * n]
            .iter_mut()
            .zip(candidate.iter())
        {
            *slot = c / norm;
        }
        filled += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact half-width along `e_i` of the zonotope with generators
    /// `columns` (each a vector): the sum of their `|i`-th components|.
    fn hull(columns: &[Vec<f64>], i: usize) -> f64 {
        columns.iter().map(|c| c[i].abs()).sum()
    }

    #[test]
    fn a_rotation_applied_many_times_does_not_inflate_the_set() {
        // One local error, then 10^4 rotations by 0.1: the set is the same
        // box rotated, whose half-width along each axis is at most
        // sqrt(2) times the box's. A box re-wrapped at each step would grow
        // by (|cos| + |sin|)^10^4.
        let mut set = ErrorSet::new(2);
        set.map(&[1.0, 0.0, 0.0, 1.0], 1e-9);
        let (c, s) = (0.1f64.cos(), 0.1f64.sin());
        for _ in 0..10_000 {
            set.map(&[c, -s, s, c], 0.0);
        }
        let bound = set.state_bound();
        assert!(bound <= 2f64.sqrt() * 1e-9 * (1.0 + 1e-9), "{bound}");
        assert!(bound >= 1e-9 * (1.0 - 1e-9), "{bound}");
    }

    #[test]
    fn a_shear_grows_linearly_and_matches_the_exact_set() {
        // Local errors l at each of k steps of the shear [[1, 1], [0, 1]]:
        // the exact set is the sum of the boxes sheared 0..k times, whose
        // generators are written out here.
        let (k, l) = (1000usize, 1e-12);
        let mut set = ErrorSet::new(2);
        let mut columns = Vec::new();
        for _ in 0..k {
            set.map(&[1.0, 1.0, 0.0, 1.0], l);
            for c in &mut columns {
                let c: &mut Vec<f64> = c;
                c[0] += c[1];
            }
            columns.push(vec![l, 0.0]);
            columns.push(vec![0.0, l]);
        }
        let exact = hull(&columns, 0).max(hull(&columns, 1));
        let bound = set.state_bound();
        assert!(
            bound >= exact * (1.0 - 1e-9),
            "{bound} below the exact {exact}"
        );
        assert!(bound <= 3.0 * exact, "{bound} far above the exact {exact}");
    }

    #[test]
    fn a_collapsing_map_keeps_an_orthonormal_frame() {
        let mut set = ErrorSet::new(2);
        set.map(&[1.0, 0.0, 0.0, 1.0], 1.0);
        // Projects onto the first axis: the second direction is gone.
        set.map(&[1.0, 0.0, 0.0, 0.0], 0.0);
        assert!((set.state_bound() - 1.0).abs() < 1e-15);
        assert_eq!(set.along(&[0.0, 1.0]), 0.0);
        set.map(&[0.0, 1.0, 1.0, 0.0], 0.5);
        assert!((set.along(&[0.0, 1.0]) - 1.5).abs() < 1e-15);
        assert!((set.along(&[1.0, 0.0]) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn above_the_tracked_dimension_the_bound_is_the_plain_sum() {
        let n = TRACKED + 1;
        let mut set = ErrorSet::new(n);
        let identity: Vec<f64> = (0..n * n).map(|k| f64::from(k % (n + 1) == 0)).collect();
        set.map(&identity, 1e-9);
        set.map(&identity, 2e-9);
        assert!((set.state_bound() - 3e-9).abs() < 1e-24);
        // sqrt(1 + 4) 1e-9 per unit of gradient, over n components.
        assert!((set.along(&vec![1.0; n]) - n as f64 * 5f64.sqrt() * 1e-9).abs() < 1e-20);
    }
}
