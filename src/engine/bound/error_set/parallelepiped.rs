//! Lohner's parallelepiped: one of the two enclosures of a run's errors
//! (see [`super`]).
//!
//! The set is `{ B u : |u_j| <= r_j }` with `B` orthogonal. A linear map
//! `M` takes it to `M B box(r)`, which is held again in the orthogonal
//! factor `Q` of `M B` (columns taken longest first): `Q box(|Q^T M B|
//! r)`. The frame follows the flow's rotation, so an oscillation does not
//! inflate the box at every step, and a shear grows it linearly, as it
//! grows the errors. A new local error box of half-width `l` is added as
//! `Q box(|Q^T| l)`. Where the map is neither (a quasi-periodic flow in
//! four dimensions, whose tangent turns several planes at once and shears
//! them), re-boxing in a new frame at every step inflates it by a factor
//! each time: the wrapping effect, which the ellipsoid beside it does not
//! have.

use super::storage::Storage;

/// The parallelepiped, its matrices kept in `S` (see [`Storage`]).
#[derive(Debug, Clone)]
pub(super) struct Parallelepiped<S: Storage> {
    n: usize,
    /// Orthonormal directions, column-major `n x n` (fixed arrays for the
    /// small sizes: the map below runs at every step, and small copies of
    /// slices of unknown length are calls).
    basis: S::Matrix,
    /// Half-widths along each direction.
    radii: S::Vector,
    order: S::Order,
}

impl<S: Storage> Parallelepiped<S> {
    /// No error, in dimension `n` (that `S` holds).
    pub(super) fn new(n: usize) -> Self {
        let mut basis = S::matrix(n);
        for i in 0..n {
            basis.as_mut()[i * n + i] = 1.0;
        }
        Parallelepiped {
            n,
            basis,
            radii: S::vector(n),
            order: S::order(n),
        }
    }

    /// Carry the set of `n` components through `m` (row-major), and add a
    /// local error box of half-width `local`. Inlined where `n` is known
    /// (see [`unrolled`](super::unrolled)).
    #[inline(always)]
    pub(super) fn map(&mut self, n: usize, m: &[f64], local: f64) {
        let mut product = S::matrix(n);
        let product = product.as_mut();
        let (basis, old_radii) = (self.basis.as_mut(), self.radii.as_ref());
        // product = m * basis, column-major.
        for j in 0..n {
            for i in 0..n {
                product[j * n + i] = (0..n).map(|k| m[i * n + k] * basis[j * n + k]).sum();
            }
        }
        // Longest error columns first: Q's first direction follows the
        // dominant error.
        let mut weight = S::vector(n);
        let weight = weight.as_mut();
        for (j, w) in weight[..n].iter_mut().enumerate() {
            let column = &product[j * n..(j + 1) * n];
            *w = column.iter().map(|x| x * x).sum::<f64>() * old_radii[j] * old_radii[j];
        }
        // The old basis is spent: the new one is written over it.
        if n == 2 {
            // The common case (one degree of freedom): the frame is the
            // heavier column's direction and its perpendicular.
            let first = usize::from(weight[1] > weight[0]);
            let (c, s) = direction(&product[2 * first..2 * first + 2])
                .or_else(|| direction(&product[2 - 2 * first..4 - 2 * first]))
                .unwrap_or((1.0, 0.0));
            basis[..4].copy_from_slice(&[c, s, -s, c]);
        } else {
            let order = &mut self.order.as_mut()[..n];
            order.sort_unstable_by(|&a, &b| weight[b].total_cmp(&weight[a]));
            orthonormalize::<S>(n, product, order, basis);
        }
        let q = &*basis;
        // New radii: |Q^T product| r + |Q^T| local.
        let mut radii = S::vector(n);
        for (a, r) in radii.as_mut()[..n].iter_mut().enumerate() {
            let qa = &q[a * n..(a + 1) * n];
            // Loops, not iterator sums, so that they unroll with the rest
            // (the same sums: f64's start from -0.0).
            let mut carried = -0.0;
            for j in 0..n {
                let mut dot = -0.0;
                for i in 0..n {
                    dot += qa[i] * product[j * n + i];
                }
                carried += dot.abs() * old_radii[j];
            }
            let spread: f64 = qa.iter().map(|x| x.abs()).sum();
            *r = carried + spread * local;
        }
        self.radii = radii;
    }

    /// How many components the set holds.
    pub(super) fn dimension(&self) -> usize {
        self.n
    }

    /// The sum of the half-widths along its directions: above the
    /// half-width along any component.
    pub(super) fn radii_sum(&self) -> f64 {
        self.radii.as_ref()[..self.n].iter().sum()
    }

    /// The half-width of the set along each component, the largest.
    pub(super) fn state_bound(&self) -> f64 {
        let (n, basis, radii) = (self.n, self.basis.as_ref(), self.radii.as_ref());
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| basis[j * n + i].abs() * radii[j])
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// The half-width of the set along `gradient`.
    pub(super) fn along(&self, gradient: &[f64]) -> f64 {
        let (n, basis, radii) = (self.n, self.basis.as_ref(), self.radii.as_ref());
        (0..n)
            .map(|j| {
                let dot: f64 = (0..n).map(|i| gradient[i] * basis[j * n + i]).sum();
                dot.abs() * radii[j]
            })
            .sum()
    }
}

/// The unit vector along a plane vector, if it has a direction.
#[inline(always)]
fn direction(v: &[f64]) -> Option<(f64, f64)> {
    // The plain root of the squares, correctly rounded enough for a frame
    // (any orthonormal one encloses the set), where no square overflows or
    // underflows to lose the length; `hypot` (a libm call) elsewhere.
    let squares = v[0] * v[0] + v[1] * v[1];
    let length = if squares.is_normal() && squares < 1e300 {
        squares.sqrt()
    } else {
        v[0].hypot(v[1])
    };
    (length > 0.0 && length.is_finite()).then(|| (v[0] / length, v[1] / length))
}

/// Orthonormal columns `q` (column-major) spanning the columns of `m` taken
/// in `order`, completed by unit vectors where `m` is rank-deficient (a
/// reset that collapses a direction). Gram-Schmidt twice over, which keeps
/// `q` orthogonal to round-off for the `n` carried.
#[inline(always)]
fn orthonormalize<S: Storage>(n: usize, m: &[f64], order: &[usize], q: &mut [f64]) {
    let mut filled = 0;
    let mut candidate = S::vector(n);
    let candidate = &mut candidate.as_mut()[..n];
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
