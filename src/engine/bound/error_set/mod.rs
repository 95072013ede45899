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
//!   mechanism's phase error after 43,000 impacts: 1e3 times looser); it
//!   is held as two, the recent errors apart from the old, which tempers
//!   that.
//!
//! Where one enclosure has grown a hundred times the other (the
//! parallelepiped wrapped on Henon-Heiles, the ellipsoid swollen on the
//! mechanism's phase error), it is dropped: the maps after carry both
//! alike, so it would stay the looser, at the cost of its map.
//!
//! A component the engine keeps exact (the clock) carries no error.
//! Up to [`TRACKED`] components the enclosures live in fixed arrays (the
//! common case, at every step), up to [`CARRIED`] in vectors (a chain of
//! impacting units written out: `n^3` a map, still a fraction of the
//! step's own tangent). Above that the set is not carried (the `n^3` cost
//! per step would dominate a large ODE): no bound is stated, and the sum
//! of the local errors, without amplification, is stated as an estimate
//! for what it is ([`ErrorSet::state_bound`] is `None`).
//!
//! [`tangent::saltation`]: crate::engine::bound::tangent::Tangents::saltation

mod ellipsoid;
mod parallelepiped;
mod storage;

use ellipsoid::Ellipsoid;
use parallelepiped::Parallelepiped;
use storage::{Fixed, Heap, Storage};

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

/// Round-off allowed per event, in ulps of the state's size (and of the
/// time's for event times).
pub const ROUNDOFF_ULPS: f64 = 16.0;

/// Largest state dimension whose errors are carried in fixed arrays.
pub const TRACKED: usize = 8;

/// Largest state dimension whose errors are carried through flows and
/// events at all: a chain of 32 impacting units written out as an
/// automaton. A map costs about `5 n^3` multiply-adds here (about 1 ms
/// at 64 components), besides the step's tangent; a chain of 30 units
/// written out (60 states) takes about 1.7 ms an impact in all.
pub const CARRIED: usize = 64;

/// The errors a run may carry.
#[derive(Debug, Clone)]
pub struct ErrorSet {
    n: usize,
    /// The two enclosures, where the dimension is carried.
    enclosures: Option<Enclosures>,
    /// Sum of the local errors added (the estimate where no set is
    /// carried), and of their squares (the uncarried graze check's scale).
    sum: f64,
    squares: f64,
    /// Set once a non-finite error entered: every bound is then infinite.
    poisoned: bool,
    /// The components the bound is about: the first `held` (the rest are
    /// derivatives a run carries beside the state, see
    /// [`HybridModel::bounded_dimension`]), but `exact`.
    ///
    /// [`HybridModel::bounded_dimension`]: crate::engine::HybridModel::bounded_dimension
    held: usize,
    /// A component that carries no error (the clock, which the engine
    /// keeps equal to the run's time): the enclosures hold the others
    /// alone, and every map and gradient is read without its row and
    /// column.
    exact: Option<usize>,
}

/// The two enclosures, in fixed arrays or in vectors.
// The fixed arrays are held inline on purpose: no indirection at every step.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
enum Enclosures {
    Fixed(Pair<Fixed>),
    Heap(Pair<Heap>),
}

/// Both enclosures of the same errors, in `k` components, while both are
/// worth their maps (see [`LOOSER`]).
#[derive(Debug, Clone)]
struct Pair<S: Storage> {
    box_: Parallelepiped<S>,
    ellipsoid: Ellipsoid<S>,
    /// The ones still carried; a dropped one is left as it was and never
    /// asked again.
    carried: Carried,
    /// Maps since the set was made, to compare the two every
    /// [`COMPARE_EVERY`].
    maps: u64,
}

/// Which enclosures a [`Pair`] carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Carried {
    Both,
    Box,
    Ellipsoid,
}

/// An enclosure whose largest half-width is this many times the other's
/// is dropped: every map after carries both alike, so the looser one's
/// excess (the parallelepiped's wrapping, the ellipsoid's swollen thin
/// axes) stays, and its map is spent for nothing. Henon-Heiles'
/// parallelepiped is 800 times its ellipsoid at t = 2000 and 9000 times
/// at 20,000, and its map is an eighth of the run; the mechanism's
/// ellipsoid ends 1000 times its parallelepiped.
const LOOSER: f64 = 100.0;

/// How many maps apart the two enclosures are compared (two state bounds,
/// a fraction of one map's cost spread over this many).
const COMPARE_EVERY: u64 = 64;

impl<S: Storage> Pair<S> {
    fn new(k: usize) -> Self {
        Pair {
            box_: Parallelepiped::new(k),
            ellipsoid: Ellipsoid::new(k),
            carried: Carried::Both,
            maps: 0,
        }
    }

    /// Carry both through `m` (row-major over the run's `n` components,
    /// of which the set holds `free`) and add a box of half-width `local`.
    #[inline(always)]
    fn map(
        &mut self,
        (n, free): (usize, impl Iterator<Item = usize> + Clone),
        m: &[f64],
        local: f64,
    ) {
        // The exact component's column multiplies no error, and its row
        // is no error: the map of the others is `m` without them.
        let k = self.box_.dimension();
        let mut reduced;
        let m = if k == n {
            m
        } else {
            reduced = S::matrix(k);
            let r = reduced.as_mut();
            for (row, i) in free.clone().enumerate() {
                for (column, j) in free.clone().enumerate() {
                    r[row * k + column] = m[i * n + j];
                }
            }
            &reduced.as_ref()[..k * k]
        };
        // At every step: both maps copied for each size, their loops
        // unrolled.
        let Pair {
            box_,
            ellipsoid,
            carried,
            ..
        } = self;
        unrolled(
            k,
            #[inline(always)]
            |k| {
                if *carried != Carried::Ellipsoid {
                    box_.map(k, m, local);
                }
                if *carried != Carried::Box {
                    ellipsoid.map(k, m, local);
                }
            },
        );
        self.maps += 1;
        if self.carried == Carried::Both && self.maps % COMPARE_EVERY == 0 {
            let (boxed, round) = (self.box_.state_bound(), self.ellipsoid.state_bound());
            if boxed > LOOSER * round {
                self.carried = Carried::Ellipsoid;
            } else if round > LOOSER * boxed {
                self.carried = Carried::Box;
            }
        }
    }

    fn state_bound(&self) -> f64 {
        match self.carried {
            Carried::Both => self.box_.state_bound().min(self.ellipsoid.state_bound()),
            Carried::Box => self.box_.state_bound(),
            Carried::Ellipsoid => self.ellipsoid.state_bound(),
        }
    }

    /// Whether some component's error may exceed `limit`: no component's
    /// half-width in the parallelepiped exceeds the sum of its radii (its
    /// frame is orthonormal), which settles most questions at once.
    fn exceeds(&self, limit: f64) -> bool {
        let settled = self.carried != Carried::Ellipsoid && self.box_.radii_sum() <= limit;
        !settled && !(self.state_bound() <= limit)
    }

    fn along(&self, gradient: &[f64]) -> f64 {
        match self.carried {
            Carried::Both => self
                .box_
                .along(gradient)
                .min(self.ellipsoid.along(gradient)),
            Carried::Box => self.box_.along(gradient),
            Carried::Ellipsoid => self.ellipsoid.along(gradient),
        }
    }

    /// Whether the parallelepiped alone says `limit > along(gradient) +
    /// spread` (its answer bounds the smaller of the two).
    #[inline(always)]
    fn box_settles(&self, gradient: &[f64], spread: f64, limit: f64) -> bool {
        self.carried != Carried::Ellipsoid && limit > self.box_.along(gradient) + spread
    }
}

impl ErrorSet {
    /// No error yet, in dimension `n`.
    pub fn new(n: usize) -> Self {
        ErrorSet {
            n,
            enclosures: Self::enclosures(n),
            sum: 0.0,
            squares: 0.0,
            poisoned: false,
            held: n,
            exact: None,
        }
    }

    /// Empty enclosures of `k` components, where they are carried.
    fn enclosures(k: usize) -> Option<Enclosures> {
        match k {
            k if k <= TRACKED => Some(Enclosures::Fixed(Pair::new(k))),
            k if k <= CARRIED => Some(Enclosures::Heap(Pair::new(k))),
            _ => None,
        }
    }

    /// The same, holding the errors of the first `held` components alone
    /// (the state a bound is about; the components after it must not
    /// feed it, as a state's derivatives do not), with component `exact`
    /// free of error: the clock, which the engine keeps equal to the
    /// run's time. Each map and gradient is read without the rows and
    /// columns of the others. The maps are of the whole state, so none is
    /// carried above [`CARRIED`] components in all.
    pub fn holding(mut self, held: usize, exact: Option<usize>) -> Self {
        self.held = held.min(self.n);
        self.exact = exact.filter(|&c| c < self.held);
        if self.enclosures.is_some() {
            self.enclosures = Self::enclosures(self.free().count());
        }
        self
    }

    /// The components the enclosures hold, in order.
    fn free(&self) -> impl Iterator<Item = usize> + Clone + use<> {
        let exact = self.exact;
        (0..self.held).filter(move |&i| Some(i) != exact)
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
        let dimensions = (self.n, self.free());
        match &mut self.enclosures {
            Some(Enclosures::Fixed(pair)) => pair.map(dimensions, m, local),
            Some(Enclosures::Heap(pair)) => pair.map(dimensions, m, local),
            None => {}
        }
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

    /// The largest error any state component may carry; `None` where the
    /// set is not carried (see [`ErrorSet::estimate`]).
    pub fn state_bound(&self) -> Option<f64> {
        if self.poisoned && self.tracked() {
            return Some(f64::INFINITY);
        }
        match &self.enclosures {
            Some(Enclosures::Fixed(pair)) => Some(pair.state_bound()),
            Some(Enclosures::Heap(pair)) => Some(pair.state_bound()),
            None => None,
        }
    }

    /// Whether the largest error of some component may exceed `limit` (the
    /// estimate's, where the set is not carried). Asked at every step.
    #[inline]
    pub fn exceeds(&self, limit: f64) -> bool {
        match &self.enclosures {
            _ if self.poisoned => true,
            Some(Enclosures::Fixed(pair)) => pair.exceeds(limit),
            Some(Enclosures::Heap(pair)) => pair.exceeds(limit),
            None => !(self.sum <= limit),
        }
    }

    /// The sum of the local errors added, without amplification: what
    /// stands in for a bound where the set is not carried.
    pub fn estimate(&self) -> f64 {
        if self.poisoned {
            f64::INFINITY
        } else {
            self.sum
        }
    }

    /// Whether `limit > self.along(gradient) + spread`, asking the cheaper
    /// parallelepiped first: its answer bounds the smaller of the two, so
    /// where it settles the question the ellipsoid need not be asked.
    /// Inlined: a replayed period asks it at every step (see
    /// `Bound::replay`), where a call costs more than the question.
    #[inline(always)]
    pub fn within(&self, gradient: &[f64], spread: f64, limit: f64) -> bool {
        if !self.poisoned {
            let settled = match &self.enclosures {
                Some(Enclosures::Fixed(pair)) => {
                    pair.box_settles(self.reduced::<Fixed>(gradient).as_ref(), spread, limit)
                }
                Some(Enclosures::Heap(pair)) => {
                    pair.box_settles(self.reduced::<Heap>(gradient).as_ref(), spread, limit)
                }
                None => false,
            };
            if settled {
                return true;
            }
        }
        limit > self.along(gradient) + spread
    }

    /// The largest error of the linear function `gradient . x`. Where the
    /// set is not carried, an optimistic scale instead: `sum |gradient_i|`
    /// times the root-sum-square of the local errors, as if independent.
    pub fn along(&self, gradient: &[f64]) -> f64 {
        if self.poisoned {
            return f64::INFINITY;
        }
        match &self.enclosures {
            Some(Enclosures::Fixed(pair)) => pair.along(self.reduced::<Fixed>(gradient).as_ref()),
            Some(Enclosures::Heap(pair)) => pair.along(self.reduced::<Heap>(gradient).as_ref()),
            None => gradient.iter().map(|g| g.abs()).sum::<f64>() * self.squares.sqrt(),
        }
    }

    /// `gradient`'s components along the enclosures' (the exact one
    /// dropped), the rest zero.
    #[inline(always)]
    fn reduced<S: Storage>(&self, gradient: &[f64]) -> S::Vector {
        let mut out = S::vector(self.n);
        for (o, i) in out.as_mut().iter_mut().zip(self.free()) {
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
        let bound = set.state_bound().unwrap();
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
        let bound = set.state_bound().unwrap();
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
        let m = turning_planes(0.1, 0.13, 0.01);
        let mut set = ErrorSet::new(4);
        let mut boxed = Parallelepiped::<Fixed>::new(4);
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
        let bound = set.state_bound().unwrap();
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

    /// Two planes turned by `a1` and `a2` a map, the first sheared by the
    /// second by `e` (the tangent of a quasi-periodic orbit), row-major.
    fn turning_planes(a1: f64, a2: f64, e: f64) -> [f64; 16] {
        let (c1, s1) = (a1.cos(), a1.sin());
        let (c2, s2) = (a2.cos(), a2.sin());
        #[rustfmt::skip]
        let m = [
            c1, -s1, e, 0.0,
            s1, c1, 0.0, e,
            0.0, 0.0, c2, -s2,
            0.0, 0.0, s2, c2,
        ];
        m
    }

    /// Maps `m` (of `N` components) with a local error `steps` times, then
    /// doubles the set a dozen times, beside the two enclosures carried
    /// alone, and checks that the set answers
    /// as the smaller of them until it drops the other from `kept`, at a
    /// comparison where that one was LOOSER times it (and at none before),
    /// and then as `kept` alone, bit for bit. The step it dropped at.
    fn dropped_for<const N: usize>(m: &[f64], steps: u64, kept: Carried) -> Option<u64> {
        let l = 1e-12;
        let mut set = ErrorSet::new(N);
        let mut boxed = Parallelepiped::<Fixed>::new(N);
        let mut round = Ellipsoid::<Fixed>::new(N);
        let gradient: Vec<f64> = (0..N).map(|i| [0.3, -1.0, 0.2, 2.0][i % 4]).collect();
        let mut dropped_at = None;
        // Then the set doubled a dozen times: a dropped enclosure, left as
        // it was, falls far inside the set, and must not be asked.
        let mut doubling = [0.0; TRACKED * TRACKED];
        for i in 0..N {
            doubling[i * N + i] = 2.0;
        }
        let maps = std::iter::repeat_n(m, steps as usize)
            .chain(std::iter::repeat_n(&doubling[..N * N], 12));
        for (step, m) in (1..).zip(maps) {
            set.map(m, l);
            boxed.map(N, m, l);
            round.map(N, m, l);
            let Some(Enclosures::Fixed(pair)) = &set.enclosures else {
                panic!("small sets are kept in fixed arrays")
            };
            let (b, e) = (boxed.state_bound(), round.state_bound());
            let (kept_bound, dropped_bound, kept_along) = match kept {
                Carried::Ellipsoid => (e, b, round.along(&gradient)),
                _ => (b, e, boxed.along(&gradient)),
            };
            let bound = set.state_bound().unwrap();
            assert!(set.exceeds(0.99 * bound) && !set.exceeds(1.01 * bound));
            if pair.carried == Carried::Both {
                assert_eq!(bound, b.min(e), "step {step}");
                if step % COMPARE_EVERY == 0 {
                    assert!(dropped_bound <= LOOSER * kept_bound, "step {step}");
                }
                continue;
            }
            assert_eq!(pair.carried, kept, "step {step}");
            let at = *dropped_at.get_or_insert(step);
            assert_eq!(at % COMPARE_EVERY, 0);
            if step == at {
                assert!(dropped_bound > LOOSER * kept_bound, "step {step}");
            }
            assert_eq!(bound, kept_bound, "step {step}");
            assert_eq!(set.along(&gradient), kept_along, "step {step}");
            assert!(set.within(&gradient, 0.0, 1.01 * kept_along));
            assert!(!set.within(&gradient, 0.0, 0.99 * kept_along));
        }
        dropped_at
    }

    #[test]
    fn an_enclosure_far_looser_than_the_other_is_dropped_keeping_the_bound() {
        // Two planes turned fast (a Henon-Heiles step's spread) wrap the
        // parallelepiped: the ellipsoid is kept.
        let fast = turning_planes(0.6, 0.83, 0.2);
        assert!(dropped_for::<4>(&fast, 3000, Carried::Ellipsoid).is_some());
        // A shear with round local errors swells the ellipsoid's thin
        // axis (the phase error of a periodic orbit): the parallelepiped
        // is kept.
        let shear = [1.0, 1.0, 0.0, 1.0];
        assert!(dropped_for::<2>(&shear, 40_000, Carried::Box).is_some());
    }

    #[test]
    fn both_enclosures_are_carried_while_neither_is_far_looser() {
        // A rotation, and two planes turned slowly: both stay within a few
        // times of each other, and both are kept.
        let rotation = [0.1f64.cos(), -0.1f64.sin(), 0.1f64.sin(), 0.1f64.cos()];
        assert_eq!(dropped_for::<2>(&rotation, 3000, Carried::Both), None);
        let slow = turning_planes(0.1, 0.13, 0.01);
        assert_eq!(dropped_for::<4>(&slow, 1000, Carried::Both), None);
    }

    #[test]
    fn a_collapsing_map_keeps_an_orthonormal_frame() {
        let mut set = ErrorSet::new(2);
        set.map(&[1.0, 0.0, 0.0, 1.0], 1.0);
        // Projects onto the first axis: the second direction is gone.
        set.map(&[1.0, 0.0, 0.0, 0.0], 0.0);
        assert!((set.state_bound().unwrap() - 1.0).abs() < 1e-15);
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
        let mut set = ErrorSet::new(2).holding(2, Some(1));
        for _ in 0..100 {
            set.map(&[1.0, 5.0, 0.0, 1.0], 1e-12);
        }
        assert_eq!(set.along(&[0.0, 1.0]), 0.0);
        let bound = set.state_bound().unwrap();
        assert!((bound - 1e-10).abs() < 1e-22, "{bound}");
        // Without it the clock's errors, sheared into the state, dominate.
        let mut plain = ErrorSet::new(2);
        for _ in 0..100 {
            plain.map(&[1.0, 5.0, 0.0, 1.0], 1e-12);
        }
        assert!(plain.state_bound().unwrap() > 100.0 * bound);
    }

    #[test]
    fn a_set_with_an_exact_component_is_the_set_of_the_others() {
        // The clock in the middle of three components: the set carries
        // the first and third through the map without the clock's row and
        // column, bit for bit as a set of two would.
        let m = [0.9, 0.3, -0.4, 2.0, 1.0, 7.0, 0.2, -0.5, 1.1];
        let mut set = ErrorSet::new(3).holding(3, Some(1));
        let mut two = ErrorSet::new(2);
        for k in 0..50 {
            let local = 1e-12 * (1 + k % 3) as f64;
            set.map(&m, local);
            two.map(&[0.9, -0.4, 0.2, 1.1], local);
        }
        assert_eq!(
            set.state_bound().map(f64::to_bits),
            two.state_bound().map(f64::to_bits)
        );
        let along = set.along(&[0.3, 100.0, -1.2]);
        assert_eq!(along.to_bits(), two.along(&[0.3, -1.2]).to_bits());
        assert!(along > 0.0);
    }

    #[test]
    fn above_the_carried_dimension_no_bound_is_stated_only_an_estimate() {
        let n = CARRIED + 1;
        let mut set = ErrorSet::new(n);
        assert!(!set.tracked());
        let identity: Vec<f64> = (0..n * n).map(|k| f64::from(k % (n + 1) == 0)).collect();
        set.map(&identity, 1e-9);
        set.map(&identity, 2e-9);
        assert_eq!(set.state_bound(), None);
        assert!((set.estimate() - 3e-9).abs() < 1e-24);
        // Nor is one stated once an error is not finite.
        let mut poisoned = set.clone();
        poisoned.map(&identity, f64::NAN);
        assert_eq!(poisoned.state_bound(), None);
        assert_eq!(poisoned.estimate(), f64::INFINITY);
        // sqrt(1 + 4) 1e-9 per unit of gradient, over n components.
        assert!((set.along(&vec![1.0; n]) - n as f64 * 5f64.sqrt() * 1e-9).abs() < 1e-18);
    }

    /// A chain of `units` oscillators coupled to their neighbours, with a
    /// wall: `x' = v, v' = -L x` (`L` the path Laplacian plus the wall),
    /// its tangent over `tau` to second order, `[q; v]` row-major.
    fn coupled_step(units: usize, tau: f64) -> Vec<f64> {
        let n = 2 * units;
        let laplacian = |i: usize, j: usize| -> f64 {
            match i.abs_diff(j) {
                0 => 2.0,
                1 => -1.0,
                _ => 0.0,
            }
        };
        let mut m = vec![0.0; n * n];
        for i in 0..units {
            m[i * n + i] = 1.0;
            m[i * n + units + i] = tau;
            m[(units + i) * n + units + i] = 1.0;
            for j in 0..units {
                m[(units + i) * n + j] = -tau * laplacian(i, j);
                m[i * n + j] -= 0.5 * tau * tau * laplacian(i, j);
            }
        }
        m
    }

    #[test]
    fn a_large_set_encloses_the_exact_zonotope_as_tightly_as_a_small_one() {
        // Twelve coupled units (24 components, kept in vectors): local
        // errors at each of k steps of a map that couples every unit to
        // its neighbours. The exact set's half-widths come from its
        // generators, mapped one by one.
        for units in [2, 12] {
            let n = 2 * units;
            let (k, l) = (300usize, 1e-12);
            let m = coupled_step(units, 0.05);
            let mut set = ErrorSet::new(n);
            let mut columns: Vec<Vec<f64>> = Vec::new();
            for _ in 0..k {
                set.map(&m, l);
                for c in &mut columns {
                    *c = (0..n)
                        .map(|i| (0..n).map(|j| m[i * n + j] * c[j]).sum())
                        .collect();
                }
                for i in 0..n {
                    let mut c = vec![0.0; n];
                    c[i] = l;
                    columns.push(c);
                }
            }
            let exact = (0..n).map(|i| hull(&columns, i)).fold(0.0, f64::max);
            let bound = set.state_bound().unwrap();
            assert!(
                bound >= exact * (1.0 - 1e-9),
                "{units}: {bound} below the exact {exact}"
            );
            assert!(
                bound <= 3.0 * exact,
                "{units}: {bound} far above the exact {exact}"
            );
            // The gradient of one unit's elongation, both ways.
            let mut gradient = vec![0.0; n];
            (gradient[1], gradient[0]) = (1.0, -1.0);
            let along = set.along(&gradient);
            let exact_along: f64 = columns.iter().map(|c| (c[1] - c[0]).abs()).sum();
            assert!(
                along >= exact_along * (1.0 - 1e-9),
                "{units}: {along} < {exact_along}"
            );
            assert!(
                along <= 3.0 * exact_along,
                "{units}: {along} >> {exact_along}"
            );
        }
    }

    #[test]
    fn vectors_hold_the_same_arithmetic_as_fixed_arrays() {
        // The same four-component map in both storages: the same bits.
        let m = coupled_step(2, 0.1);
        let mut fixed = Pair::<Fixed>::new(4);
        let mut heap = Pair::<Heap>::new(4);
        for step in 0..200 {
            let local = 1e-12 * (1 + step % 5) as f64;
            fixed.map((4, 0..4), &m, local);
            heap.map((4, 0..4), &m, local);
        }
        assert_eq!(fixed.state_bound().to_bits(), heap.state_bound().to_bits());
        let gradient = [0.3, -1.0, 0.2, 2.0];
        assert_eq!(
            fixed.along(&gradient).to_bits(),
            heap.along(&gradient).to_bits()
        );
        assert!(fixed.state_bound() > 0.0);
    }
}
