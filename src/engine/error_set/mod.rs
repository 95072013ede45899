//! The set of state errors a run may carry: what its stated error bound
//! is read from.
//!
//! Every numerical step leaves a local error (its embedded estimate, the
//! first term its series leaves out, and never less than its rounding: a
//! box of that half-width around the state). Later steps carry it along the
//! flow's tangent map, and every event carries it across the reset by the
//! saltation matrix: an error `d` moves the event by `d / closing speed`,
//! which the reset then turns into a jump of the state (see
//! [`tangent::saltation`]). Summing the local errors' sizes ignores all of
//! that, and near a slow impact understates the error by orders of
//! magnitude; multiplying norms overstates it just as badly (a shear
//! applied a thousand times grows linearly, its norm's power
//! exponentially).
//!
//! So the set is enclosed twice, and every question (the bound on a
//! component, the error along a guard's gradient) takes the smaller answer:
//! both hold the same errors, so both answers bound them.
//! - Lohner's parallelepiped (`parallelepiped.rs`) follows a rotating,
//!   shearing set of one degree of freedom closely, but re-boxing it at
//!   every step inflates it where the tangent turns several planes at once
//!   (the wrapping effect: Henon-Heiles's bound grew 1e8 times its error
//!   over 2000 time units).
//! - An ellipsoid (`ellipsoid.rs`) takes every map exactly, but adding a
//!   round local error to a long thin set swells its thin axes (the
//!   mechanism's phase error after 43,000 impacts: 1e3 times looser).
//!
//! A component the engine keeps exact (the clock) carries no error.
//! Dimensions above [`TRACKED`] are not tracked (the `n^3` cost per step
//! would dominate a large ODE): there the bound is the plain sum of the
//! local errors, without amplification, and no event-time bound is stated.
//!
//! [`tangent::saltation`]: crate::engine::tangent::Tangents::saltation

mod ellipsoid;
mod parallelepiped;

use ellipsoid::Ellipsoid;
use parallelepiped::Parallelepiped;

/// `body(n)`, with `n` a constant for the usual sizes (2, 3 and 4): each
/// gets its own copy of an inlined body, its loops of known length
/// unrolled. For the linear algebra a run does at every step.
#[inline(always)]
pub(crate) fn unrolled<R>(n: usize, body: impl FnOnce(usize) -> R) -> R {
    match n {
        2 => body(2),
        3 => body(3),
        4 => body(4),
        n => body(n),
    }
}

/// Largest state dimension whose errors are carried through flows and
/// events.
pub const TRACKED: usize = 8;

/// The errors a run may carry.
#[derive(Debug, Clone)]
pub struct ErrorSet {
    n: usize,
    /// The two enclosures, where the dimension is tracked.
    enclosures: Option<(Parallelepiped, Ellipsoid)>,
    /// Sum of the local errors added (the untracked bound), and of their
    /// squares (the untracked graze check's scale).
    sum: f64,
    squares: f64,
    /// Set once a non-finite error entered: every bound is then infinite.
    poisoned: bool,
    /// A component that carries no error (the clock, which the engine
    /// keeps equal to the run's time): the enclosures hold the others
    /// alone, and every map and gradient is read without its row and
    /// column.
    exact: Option<usize>,
}

impl ErrorSet {
    /// No error yet, in dimension `n`.
    pub fn new(n: usize) -> Self {
        ErrorSet {
            n,
            enclosures: (n <= TRACKED).then(|| (Parallelepiped::new(n), Ellipsoid::new(n))),
            sum: 0.0,
            squares: 0.0,
            poisoned: false,
            exact: None,
        }
    }

    /// The same, with component `exact` free of error: the clock, which
    /// the engine keeps equal to the run's time.
    pub fn with_exact(mut self, exact: Option<usize>) -> Self {
        self.exact = exact.filter(|&c| c < self.n);
        if let (Some(_), Some(enclosures)) = (self.exact, &mut self.enclosures) {
            let free = self.n - 1;
            *enclosures = (Parallelepiped::new(free), Ellipsoid::new(free));
        }
        self
    }

    /// The components the enclosures hold, in order: all but `exact`.
    fn free(&self) -> impl Iterator<Item = usize> + Clone + use<> {
        let exact = self.exact;
        (0..self.n).filter(move |&i| Some(i) != exact)
    }

    /// Whether errors are carried through flows and events in this
    /// dimension.
    pub fn tracked(&self) -> bool {
        self.enclosures.is_some()
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
        if self.poisoned {
            return;
        }
        let (n, free) = (self.n, self.free());
        let Some((box_, ellipsoid)) = &mut self.enclosures else {
            return;
        };
        // The exact component's column multiplies no error, and its row
        // is no error: the map of the others is `m` without them.
        let mut reduced = [0.0; TRACKED * TRACKED];
        let k = box_.dimension();
        let m = if k == n {
            m
        } else {
            for (r, i) in free.clone().enumerate() {
                for (c, j) in free.clone().enumerate() {
                    reduced[r * k + c] = m[i * n + j];
                }
            }
            &reduced[..k * k]
        };
        // At every step: both maps copied for each size, their loops
        // unrolled.
        unrolled(
            k,
            #[inline(always)]
            |k| {
                box_.map(k, m, local);
                ellipsoid.map(k, m, local);
            },
        );
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
        match &self.enclosures {
            Some((box_, ellipsoid)) => box_.state_bound().min(ellipsoid.state_bound()),
            None => self.sum,
        }
    }

    /// Whether `limit > self.along(gradient) + spread`, asking the cheaper
    /// parallelepiped first: its answer bounds the smaller of the two, so
    /// where it settles the question the ellipsoid need not be asked.
    /// Inlined: a replayed period asks it at every step (see
    /// `Bound::replay`), where a call costs more than the question.
    #[inline(always)]
    pub fn within(&self, gradient: &[f64], spread: f64, limit: f64) -> bool {
        if let (Some((box_, _)), false) = (&self.enclosures, self.poisoned)
            && limit > box_.along(&self.reduced(gradient)) + spread
        {
            return true;
        }
        limit > self.along(gradient) + spread
    }

    /// The largest error of the linear function `gradient . x`. Where the
    /// set is not tracked, an optimistic scale instead: `sum |gradient_i|`
    /// times the root-sum-square of the local errors, as if independent.
    pub fn along(&self, gradient: &[f64]) -> f64 {
        if self.poisoned {
            return f64::INFINITY;
        }
        match &self.enclosures {
            Some((box_, ellipsoid)) => {
                let gradient = self.reduced(gradient);
                box_.along(&gradient).min(ellipsoid.along(&gradient))
            }
            None => gradient.iter().map(|g| g.abs()).sum::<f64>() * self.squares.sqrt(),
        }
    }

    /// `gradient`'s components along the enclosures' (the exact one
    /// dropped), the rest zero.
    fn reduced(&self, gradient: &[f64]) -> [f64; TRACKED] {
        let mut out = [0.0; TRACKED];
        for (o, i) in out.iter_mut().zip(self.free()) {
            *o = gradient[i];
        }
        out
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
    fn within_gives_the_verdict_of_the_smaller_enclosure() {
        // A sheared set, where the box and the ellipsoid answer differently
        // along different directions: `within` must say exactly what
        // comparing with `along` says, on either side of it.
        let mut set = ErrorSet::new(2);
        for _ in 0..50 {
            set.map(&[1.0, 0.3, -0.2, 1.0], 1e-12);
        }
        for gradient in [[1.0, 0.0], [0.0, 1.0], [0.6, -0.8], [3.0, 1.0]] {
            let along = set.along(&gradient);
            assert!(along > 0.0);
            for limit in [0.5, 0.99, 1.0, 1.01, 2.0].map(|f| f * (along + 1e-13)) {
                assert_eq!(
                    set.within(&gradient, 1e-13, limit),
                    limit > along + 1e-13,
                    "{gradient:?} at {limit:e} (along {along:e})"
                );
            }
        }
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
    fn a_map_turning_two_planes_does_not_wrap() {
        // Two planes turned at different rates, the first sheared by the
        // second (the tangent of a quasi-periodic orbit), with a local error
        // at every one of k steps: the exact set's half-widths are summed
        // from its generators, mapped one by one.
        let (k, l) = (3000usize, 1e-12);
        let (c1, s1) = (0.1f64.cos(), 0.1f64.sin());
        let (c2, s2) = (0.13f64.cos(), 0.13f64.sin());
        let e = 0.01;
        #[rustfmt::skip]
        let m = [
            c1, -s1, e, 0.0,
            s1, c1, 0.0, e,
            0.0, 0.0, c2, -s2,
            0.0, 0.0, s2, c2,
        ];
        let mut set = ErrorSet::new(4);
        let mut boxed = Parallelepiped::new(4);
        let mut columns: Vec<[f64; 4]> = Vec::new();
        for _ in 0..k {
            set.map(&m, l);
            boxed.map(4, &m, l);
            for c in &mut columns {
                *c = std::array::from_fn(|i| (0..4).map(|j| m[i * 4 + j] * c[j]).sum());
            }
            for i in 0..4 {
                let mut c = [0.0; 4];
                c[i] = l;
                columns.push(c);
            }
        }
        let exact = (0..4)
            .map(|i| columns.iter().map(|c| c[i].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let bound = set.state_bound();
        assert!(
            bound >= exact * (1.0 - 1e-9),
            "{bound} below the exact {exact}"
        );
        assert!(bound <= 3.0 * exact, "{bound} far above the exact {exact}");
        // The parallelepiped alone wraps.
        assert!(
            boxed.state_bound() > 10.0 * exact,
            "{} against {exact}",
            boxed.state_bound()
        );
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
    fn an_exact_component_carries_no_error() {
        // A clock beside a state: the map feeds the clock's error into the
        // state (a forcing), but the clock has none, so the state keeps
        // only its own local errors.
        let mut set = ErrorSet::new(2).with_exact(Some(1));
        for _ in 0..100 {
            set.map(&[1.0, 5.0, 0.0, 1.0], 1e-12);
        }
        assert_eq!(set.along(&[0.0, 1.0]), 0.0);
        let bound = set.state_bound();
        assert!((bound - 1e-10).abs() < 1e-22, "{bound}");
        // Without it the clock's errors, sheared into the state, dominate.
        let mut plain = ErrorSet::new(2);
        for _ in 0..100 {
            plain.map(&[1.0, 5.0, 0.0, 1.0], 1e-12);
        }
        assert!(plain.state_bound() > 100.0 * bound);
    }

    #[test]
    fn a_set_with_an_exact_component_is_the_set_of_the_others() {
        // The clock in the middle of three components: the set carries
        // the first and third through the map without the clock's row and
        // column, bit for bit as a set of two would.
        let m = [0.9, 0.3, -0.4, 2.0, 1.0, 7.0, 0.2, -0.5, 1.1];
        let mut set = ErrorSet::new(3).with_exact(Some(1));
        let mut two = ErrorSet::new(2);
        for k in 0..50 {
            let local = 1e-12 * (1 + k % 3) as f64;
            set.map(&m, local);
            two.map(&[0.9, -0.4, 0.2, 1.1], local);
        }
        assert_eq!(set.state_bound().to_bits(), two.state_bound().to_bits());
        let along = set.along(&[0.3, 100.0, -1.2]);
        assert_eq!(along.to_bits(), two.along(&[0.3, -1.2]).to_bits());
        assert!(along > 0.0);
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
