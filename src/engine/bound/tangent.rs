//! Linearisations of a model that carry a state error through a run: the
//! tangent map of a stretch of flow, and the saltation matrix of an event.
//!
//! They feed [`ErrorSet`]: an error is small, so what it becomes is what
//! the linearisation makes of it. Derivatives the model does not state are
//! differences (central, step `cbrt(eps)` of the component's size, errors
//! of about 1e-10 relative; forward for the right-hand side's Jacobian at
//! every step, about 1e-8), far below what a bound needs; a flow whose
//! Jacobian is constant (`x' = A x + b`, or `x' = A x + f(t)` driven by
//! the clock) gives it exactly, and its tangent is `exp(tau A)`.
//!
//! [`ErrorSet`]: crate::engine::bound::error_set::ErrorSet

use crate::engine::bound::error_set::{CARRIED, TRACKED};
use crate::engine::bound::saltation;
use crate::engine::model::{Flow, HybridModel, Mode};
use crate::numerics::central_difference::step_for;

/// Scratch for the linearisations of one run; matrices are row-major
/// `n x n`.
#[derive(Debug, Clone)]
pub struct Tangents {
    n: usize,
    /// The Jacobian of the last mode asked about, if it is constant (a
    /// linear flow, or one driven by a function of time).
    constant: Option<(Mode, Option<Vec<f64>>)>,
    /// The last two tangents of such a flow and their `tau`, the latest
    /// used first: a fixed-step method asks for the same one at every
    /// step, and an event between two steps for one of its own (which
    /// must not push the step's out).
    constant_tangents: [Option<(f64, Vec<f64>)>; 2],
    x: Vec<f64>,
    up: Vec<f64>,
    down: Vec<f64>,
    a: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
    e: Vec<f64>,
    /// The Jacobians at a piece's three Gauss points.
    nodes: [Vec<f64>; 3],
}

/// The flow at a stretch's start and at its end, where the step already
/// knows them (see `carry_the_flow`).
pub type Rates<'a> = Option<(&'a [f64], &'a [f64])>;

/// The largest `||tau J||` (row sums) of one piece of a nonlinear step's
/// tangent. The sixth-order Magnus generator's error falls as its seventh
/// power (a pendulum swinging to 1 rad: 2.5e-5 at 0.8, 1.2e-7 at 0.4); at
/// 1 a Taylor step of Henon-Heiles or of a pendulum is one piece, and the
/// bounds of the scenes measured are those of the exact tangent (pieces a
/// hundred times shorter) to within 30%.
const PIECE_SPREAD: f64 = 1.0;

/// The most pieces a step's tangent is cut into.
const MAX_PIECES: usize = 64;

/// The largest absolute row sum of a row-major `n x n` matrix.
fn row_norm(n: usize, a: &[f64]) -> f64 {
    if n == 0 {
        return 0.0;
    }
    // Each row summed from -0.0, in order, as `Sum` sums.
    a[..n * n].chunks_exact(n).fold(0.0, |largest, row| {
        largest.max(row.iter().fold(-0.0, |sum, x| sum + x.abs()))
    })
}

impl Tangents {
    /// Scratch for a model of `n` state components.
    pub fn new(n: usize) -> Self {
        Tangents {
            n,
            constant: None,
            constant_tangents: [None, None],
            x: vec![0.0; n],
            up: vec![0.0; n],
            down: vec![0.0; n],
            // Matrices only where errors are tracked (a long chain as an
            // ODE would hold gigabytes it never uses).
            a: vec![0.0; if n <= CARRIED { n * n } else { 0 }],
            c: vec![0.0; if n <= CARRIED { n * n } else { 0 }],
            d: vec![0.0; if n <= CARRIED { n * n } else { 0 }],
            e: vec![0.0; if n <= CARRIED { n * n } else { 0 }],
            nodes: std::array::from_fn(|_| vec![0.0; if n <= CARRIED { n * n } else { 0 }]),
        }
    }

    /// `A` if `mode`'s flow is `x' = A x + f(t)` (asked of the model once
    /// per change of mode).
    fn constant_part<M: HybridModel + ?Sized>(&mut self, model: &M, mode: Mode) -> Option<&[f64]> {
        let n = self.n;
        if self.constant.as_ref().is_none_or(|(m, _)| *m != mode) {
            let exact = model
                .constant_jacobian(mode)
                .map(|a| (0..n * n).map(|k| a[(k / n, k % n)]).collect());
            self.constant = Some((mode, exact));
            self.constant_tangents = [None, None];
        }
        self.constant.as_ref().and_then(|(_, a)| a.as_deref())
    }

    /// The Jacobian of `mode`'s (nonlinear) right-hand side at `x`, into
    /// `jac`, by forward differences (step `sqrt(eps)` of the component's
    /// size: about 1e-8 relative, plenty for a bound, at `n + 1`
    /// evaluations of the right-hand side instead of central differences'
    /// `2 n`).
    fn jacobian<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        x: &[f64],
        jac: &mut [f64],
    ) {
        let n = self.n;
        if model.jacobian(mode, x, jac) {
            return;
        }
        model.rhs(mode, x, &mut self.down);
        self.x.copy_from_slice(x);
        for j in 0..n {
            let h = f64::EPSILON.sqrt() * x[j].abs().max(1.0);
            self.x[j] = x[j] + h;
            model.rhs(mode, &self.x, &mut self.up);
            self.x[j] = x[j];
            for i in 0..n {
                jac[i * n + j] = (self.up[i] - self.down[i]) / h;
            }
        }
    }

    /// The tangent map of `tau` of an ODE flow in `mode` along the states
    /// `at(s)` of a step (its dense output, `s` in `[0, tau]`): the
    /// exponential of Magnus' sixth-order generator (`magnus`) of each
    /// piece, the flow's direction then carried exactly (`carry_the_flow`,
    /// with the flow at the two ends, `rates`, where the step knows it).
    /// Exact where the Jacobian is constant.
    pub fn ode<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        (tau, rates): (f64, Rates<'_>),
        mut at: impl FnMut(f64, &mut [f64]),
        out: &mut [f64],
    ) {
        let n = self.n;
        let mut first = std::mem::take(&mut self.a);
        let mut x = std::mem::take(&mut self.c);
        if self.constant_part(model, mode).is_some() {
            // A constant Jacobian (a linear flow, or one driven by t): the
            // tangent is exp(tau A), no states needed.
            let hit = (self.constant_tangents.iter())
                .position(|cached| cached.as_ref().is_some_and(|(known, _)| *known == tau));
            if let Some(slot) = hit {
                self.constant_tangents.swap(0, slot);
                if let Some((_, tangent)) = &self.constant_tangents[0] {
                    out.copy_from_slice(tangent);
                }
                (self.a, self.c) = (first, x);
                return;
            }
            if let Some((_, Some(a))) = &self.constant {
                for (o, a) in x.iter_mut().zip(a) {
                    *o = tau * a;
                }
            }
            without_clock(n, model.clock(), &mut x);
            exp(n, &x, out);
            // The one used less lately gives way, and the new one goes first.
            self.constant_tangents.swap(0, 1);
            match &mut self.constant_tangents[0] {
                Some((known, tangent)) => {
                    *known = tau;
                    tangent.copy_from_slice(out);
                }
                empty => *empty = Some((tau, out.to_vec())),
            }
        } else {
            // Magnus' sixth-order generator from the Jacobians at the three
            // Gauss-Legendre points of each piece, where the midpoint's
            // exponential (second order) erred by 1e-4 over a Taylor step.
            // On a regular orbit the tangent over a period is a shear, and
            // an error in it splits the shear's double eigenvalue 1 into a
            // growing and a shrinking one: the bound then grows by a
            // factor per period (Henon-Heiles: to 391 by t = 20,000 with
            // the midpoint's, 8.9e-7 now). A long step (Taylor's method
            // takes a sizeable part of a period) is cut into pieces over
            // which the flow moves the state by at most PIECE_SPREAD of a
            // unit's linear growth.
            at(0.5 * tau, &mut x[..n]);
            self.jacobian(model, mode, &x[..n], &mut first);
            // The clock's column moves no error (the clock carries none):
            // it neither enters the tangent nor cuts the step into pieces.
            without_clock(n, model.clock(), &mut first);
            let spread = tau * row_norm(n, &first);
            let pieces = if spread.is_finite() {
                ((spread / PIECE_SPREAD).ceil() as usize).clamp(1, MAX_PIECES)
            } else {
                1
            };
            let mut piece = std::mem::take(&mut self.d);
            let mut product = std::mem::take(&mut self.e);
            let mut nodes = std::mem::take(&mut self.nodes);
            let h = tau / pieces as f64;
            let offset = GAUSS_OFFSET * h;
            for k in 0..pieces {
                let s = (k as f64 + 0.5) * h;
                for (node, at_s) in [(0, s - offset), (1, s), (2, s + offset)] {
                    // The middle node of the middle piece is where the
                    // step's Jacobian was taken (when its time rounds to
                    // the same): that one serves.
                    if node == 1 && at_s == 0.5 * tau {
                        nodes[1].copy_from_slice(&first);
                        continue;
                    }
                    at(at_s, &mut x[..n]);
                    self.jacobian(model, mode, &x[..n], &mut nodes[node]);
                    without_clock(n, model.clock(), &mut nodes[node]);
                }
                magnus(n, h, &nodes, &mut x);
                if k == 0 {
                    exp(n, &x, out);
                } else {
                    exp(n, &x, &mut piece);
                    // out = piece * out: the later piece acts last.
                    mat_mul(n, &piece, out, &mut product);
                    out.copy_from_slice(&product);
                }
            }
            self.d = piece;
            self.e = product;
            self.nodes = nodes;
            self.carry_the_flow(model, mode, (tau, rates), at, out);
        }
        self.a = first;
        self.c = x;
    }

    /// Make the tangent `out` of a stretch `tau` of an autonomous flow map
    /// the flow's direction where the exact one does: `out f(x(0)) =
    /// f(x(tau))` (a shift along the orbit stays one). On a periodic orbit
    /// the period's exact tangent then keeps its double eigenvalue 1; an
    /// approximate one off by 1e-7 splits it into a slow rotation, which
    /// turns the long, thin set of a shear (the phase error) across the
    /// parallelepiped's frame, and its bound grew 50 times past the exact
    /// tangent's over 10^4 periods (the pendulum against a wall). The
    /// rank-one change `(f1 - out f0) f0^T / |f0|^2` moves no direction
    /// across `f0`, and along `f0` gives the exact answer, so it leaves no
    /// direction less accurate. Only a correction already small (1e-6 of
    /// the rate) is made: near a rest point the rates say little. The
    /// rates are `known` where the step has them (Taylor's whole step: its
    /// series' first coefficients, and the flow its check took at the
    /// end), else taken at `at(0)` and `at(tau)`.
    fn carry_the_flow<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        (tau, known): (f64, Rates<'_>),
        mut at: impl FnMut(f64, &mut [f64]),
        out: &mut [f64],
    ) {
        // A forced flow's map of the state alone does not carry its rate.
        if model.clock().is_some() || !model.has_rhs(mode) {
            return;
        }
        let n = self.n;
        let (before, after): (&[f64], &[f64]) = match known {
            Some(rates) => rates,
            None => {
                at(0.0, &mut self.x);
                model.rhs(mode, &self.x, &mut self.up);
                at(tau, &mut self.x);
                model.rhs(mode, &self.x, &mut self.down);
                (&self.up, &self.down)
            }
        };
        let miss = &mut self.x;
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
        for (i, (m, row)) in miss.iter_mut().zip(out.chunks_exact(n)).enumerate() {
            *m = after[i]
                - row
                    .iter()
                    .zip(before.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
        }
        let scale = norm(before);
        if scale > 0.0 && norm(miss) <= 1e-12 * norm(after) {
            for (row, m) in out.chunks_exact_mut(n).zip(miss.iter()) {
                for (o, b) in row.iter_mut().zip(before.iter()) {
                    *o += m * b / scale;
                }
            }
        }
    }

    /// The tangent map of `tau` of `mode`'s exact flow from `x0`, by central
    /// differences of the flow map.
    pub fn exact<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        x0: &[f64],
        tau: f64,
        out: &mut [f64],
    ) {
        let n = self.n;
        self.x.copy_from_slice(x0);
        for j in 0..n {
            let h = step_for(x0[j]);
            self.x[j] = x0[j] + h;
            model.advance(mode, &self.x, tau, &mut self.up);
            self.x[j] = x0[j] - h;
            model.advance(mode, &self.x, tau, &mut self.down);
            self.x[j] = x0[j];
            for i in 0..n {
                out[i * n + j] = (self.up[i] - self.down[i]) / (2.0 * h);
            }
        }
    }

    /// The state's rate of change at `x` in `mode`: the right-hand side, or
    /// a forward difference of the exact flow, or zero if frozen.
    pub fn rate<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        x: &[f64],
        out: &mut [f64],
    ) {
        match model.flow(mode) {
            Flow::Frozen => out.fill(0.0),
            _ if model.has_rhs(mode) => model.rhs(mode, x, out),
            _ => {
                let h = f64::EPSILON.sqrt() * x.iter().fold(1.0, |m: f64, v| m.max(v.abs()));
                model.advance(mode, x, h, out);
                for (o, v) in out.iter_mut().zip(x) {
                    *o = (*o - v) / h;
                }
            }
        }
    }

    /// The gradient of `guard` in `mode` at `x` (see [`guard_gradient`]).
    pub fn gradient<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        guard: usize,
        x: &[f64],
        out: &mut [f64],
    ) {
        guard_gradient(model, mode, guard, x, out, &mut self.x);
    }

    /// The saltation matrix of `guard`'s event at `before` in `mode`, into
    /// `out` ([`saltation::matrix`]), the reset's Jacobian the model's or
    /// central differences (a passage's, see [`HybridModel::marks_only`],
    /// the identity without either): the closing speed and the largest
    /// jump of the rate.
    #[allow(clippy::too_many_arguments)]
    pub fn saltation<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        guard: usize,
        before: &[f64],
        gradient: &[f64],
        mode_after: Mode,
        after: &[f64],
        out: &mut [f64],
    ) -> (f64, f64) {
        let n = self.n;
        if mode_after == mode && after == before && model.marks_only(mode, guard) {
            // A passage: the same flow on both sides of a state it left as
            // it was. Its saltation is the identity; only its closing speed
            // is asked of the flow.
            let mut rate = std::mem::take(&mut self.up);
            self.rate(model, mode, before, &mut rate);
            for (k, o) in out[..n * n].iter_mut().enumerate() {
                *o = f64::from(k % (n + 1) == 0);
            }
            let closing = gradient.iter().zip(&rate).map(|(g, f)| g * f).sum();
            self.up = rate;
            return (closing, 0.0);
        }
        let mut reset = std::mem::take(&mut self.a);
        // The reset's Jacobian: the model's, else central differences.
        let exact = model.reset_jacobian(mode, guard, before, &mut reset[..n * n]);
        for j in (0..n).filter(|_| !exact) {
            let h = step_for(before[j]);
            self.up.copy_from_slice(before);
            self.up[j] += h;
            model.reset(mode, guard, &mut self.up);
            self.down.copy_from_slice(before);
            self.down[j] -= h;
            model.reset(mode, guard, &mut self.down);
            for i in 0..n {
                reset[i * n + j] = (self.up[i] - self.down[i]) / (2.0 * h);
            }
        }
        let mut rate_before = std::mem::take(&mut self.up);
        let mut rate_after = std::mem::take(&mut self.down);
        self.rate(model, mode, before, &mut rate_before);
        if mode_after == mode && after == before {
            // A marker: the same flow at the same state.
            rate_after.copy_from_slice(&rate_before);
        } else {
            self.rate(model, mode_after, after, &mut rate_after);
        }
        let (closing, largest_jump) =
            saltation::matrix(&reset, gradient, &rate_before, &rate_after, out);
        self.a = reset;
        self.up = rate_before;
        self.down = rate_after;
        (closing, largest_jump)
    }
}

/// The gradient of `guard` in `mode` at `x` into `out`: the model's, where
/// it knows it exactly, else central differences (`probe` is scratch of the
/// state's length).
pub fn guard_gradient<M: HybridModel + ?Sized>(
    model: &M,
    mode: Mode,
    guard: usize,
    x: &[f64],
    out: &mut [f64],
    probe: &mut [f64],
) {
    if model.guard_gradient(mode, guard, x, out) {
        return;
    }
    probe.copy_from_slice(x);
    for j in 0..x.len() {
        let h = step_for(x[j]);
        probe[j] = x[j] + h;
        let up = model.guard(mode, guard, probe);
        probe[j] = x[j] - h;
        let down = model.guard(mode, guard, probe);
        probe[j] = x[j];
        out[j] = (up - down) / (2.0 * h);
    }
}

/// Clear the clock's column of the row-major `n x n` generator `a`. The
/// clock carries no error (its row of every map is cleared, see
/// `ErrorSet`), so what its column would feed into the state multiplies
/// nothing; without it a forced flow's clock decouples, and [`exp`] takes
/// the exponential of the state's block alone (a forced oscillator's is
/// then the 2 x 2 closed form).
fn without_clock(n: usize, clock: Option<usize>, a: &mut [f64]) {
    if let Some(c) = clock.filter(|&c| c < n) {
        for row in a[..n * n].chunks_exact_mut(n) {
            row[c] = 0.0;
        }
    }
}

/// The outer Gauss-Legendre points of a piece of length `h` lie this far
/// times `h` on either side of its midpoint.
const GAUSS_OFFSET: f64 = 0.387_298_334_620_741_7; // sqrt(15) / 10

/// Magnus' sixth-order generator `omega` of a piece of length `h` (its
/// tangent is `exp(omega)`), from the row-major `n x n` Jacobians at the
/// piece's Gauss-Legendre points `nodes`, in time order (Blanes, Casas and
/// Ros, BIT 40, 2000; the review of Blanes, Casas, Oteo and Ros, Phys.
/// Rep. 470, 2009): with `a_i = h A_i`,
///
/// ```text
/// alpha1 = a_2, alpha2 = sqrt(15)/3 (a_3 - a_1), alpha3 = 10/3 (a_3 - 2 a_2 + a_1)
/// c1 = [alpha1, alpha2], c2 = -1/60 [alpha1, 2 alpha3 + c1]
/// omega = alpha1 + alpha3/12 + 1/240 [-20 alpha1 - alpha3 + c1, alpha2 + c2]
/// ```
///
/// Where the Jacobians commute (one state, or a constant Jacobian) this is
/// Gauss' quadrature of `h A`: `h (5 A_1 + 8 A_2 + 5 A_3) / 18`.
fn magnus(n: usize, h: f64, nodes: &[Vec<f64>; 3], out: &mut [f64]) {
    match n {
        0 => {}
        1 => out[0] = h * (5.0 * nodes[0][0] + 8.0 * nodes[1][0] + 5.0 * nodes[2][0]) / 18.0,
        2 => magnus_sized::<2>(h, nodes, out),
        3 => magnus_sized::<3>(h, nodes, out),
        4 => magnus_sized::<4>(h, nodes, out),
        5 => magnus_sized::<5>(h, nodes, out),
        6 => magnus_sized::<6>(h, nodes, out),
        7 => magnus_sized::<7>(h, nodes, out),
        8 => magnus_sized::<8>(h, nodes, out),
        n => magnus_dynamic(n, h, nodes, out),
    }
}

/// [`magnus_sized`] for the larger sizes, in nalgebra's matrices (built
/// from the row-major nodes, written back row-major).
fn magnus_dynamic(n: usize, h: f64, nodes: &[Vec<f64>; 3], out: &mut [f64]) {
    use nalgebra::DMatrix;
    let [a1, a2, a3] =
        std::array::from_fn(|k| DMatrix::from_row_slice(n, n, &nodes[k][..n * n]) * h);
    let commutator = |a: &DMatrix<f64>, b: &DMatrix<f64>| a * b - b * a;
    let alpha1 = a2.clone();
    let alpha2 = (&a3 - &a1) * (15f64.sqrt() / 3.0);
    let alpha3 = (&a3 - &a2 * 2.0 + &a1) * (10.0 / 3.0);
    let c1 = commutator(&alpha1, &alpha2);
    let c2 = commutator(&alpha1, &(&alpha3 * 2.0 + &c1));
    let left = &alpha1 * -20.0 - &alpha3 + &c1;
    let right = &alpha2 - &c2 / 60.0;
    let omega = &alpha1 + &alpha3 / 12.0 + commutator(&left, &right) / 240.0;
    for (i, row) in out.chunks_exact_mut(n).enumerate() {
        for (j, o) in row.iter_mut().enumerate() {
            *o = omega[(i, j)];
        }
    }
}

fn magnus_sized<const N: usize>(h: f64, nodes: &[Vec<f64>; 3], out: &mut [f64]) {
    let (a1, a2, a3) = (
        square::<N>(&nodes[0], h),
        square::<N>(&nodes[1], h),
        square::<N>(&nodes[2], h),
    );
    let root = 15f64.sqrt() / 3.0;
    let alpha1 = a2;
    let alpha2 = combine(&a3, &a1, |x, y| root * (x - y));
    let mut alpha3 = combine(&a3, &a2, |x, y| x - 2.0 * y);
    alpha3 = combine(&alpha3, &a1, |x, y| 10.0 / 3.0 * (x + y));
    let c1 = commutator(&alpha1, &alpha2);
    let twice_plus = combine(&alpha3, &c1, |x, y| 2.0 * x + y);
    let c2 = commutator(&alpha1, &twice_plus);
    let mut left = combine(&alpha1, &alpha3, |x, y| -20.0 * x - y);
    left = combine(&left, &c1, |x, y| x + y);
    let right = combine(&alpha2, &c2, |x, y| x - y / 60.0);
    let outer = commutator(&left, &right);
    let omega = combine(&alpha1, &alpha3, |x, y| x + y / 12.0);
    let omega = combine(&omega, &outer, |x, y| x + y / 240.0);
    for (o, row) in out.chunks_exact_mut(N).zip(&omega) {
        o.copy_from_slice(row);
    }
}

/// `f(a_ij, b_ij)` entry by entry.
#[inline(always)]
fn combine<const N: usize>(a: &Square<N>, b: &Square<N>, f: impl Fn(f64, f64) -> f64) -> Square<N> {
    let mut out = [[0.0; N]; N];
    for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
        for ((o, a), b) in o.iter_mut().zip(a).zip(b) {
            *o = f(*a, *b);
        }
    }
    out
}

/// `[a, b] = a b - b a`.
#[inline(always)]
fn commutator<const N: usize>(a: &Square<N>, b: &Square<N>) -> Square<N> {
    combine(&product(a, b), &product(b, a), |x, y| x - y)
}

/// `out = exp(a)` for a row-major `n x n` matrix: the Taylor polynomial
/// of degree 19 on `a / 2^s` with `|a / 2^s| <= 1.2`, then `s` squarings
/// (scaling and squaring, with the one degree a linearisation's pieces
/// need: seven products, and no squaring up to a piece's largest
/// spread).
fn exp(n: usize, a: &[f64], out: &mut [f64]) {
    if n == 2 {
        return exp2(a, out);
    }
    // Components that neither move nor move others (a frozen chart's
    // states) keep their errors: exp is the identity there, and the rest
    // is the exponential of the smaller block.
    let mut active = [0usize; TRACKED];
    let mut k = 0;
    for i in 0..n.min(TRACKED) {
        if (0..n).any(|j| a[i * n + j] != 0.0 || a[j * n + i] != 0.0) {
            active[k] = i;
            k += 1;
        }
    }
    if n <= TRACKED && k < n {
        let mut small = [0.0; TRACKED * TRACKED];
        for (r, &i) in active[..k].iter().enumerate() {
            for (c, &j) in active[..k].iter().enumerate() {
                small[r * k + c] = a[i * n + j];
            }
        }
        let mut result = [0.0; TRACKED * TRACKED];
        exp_dense(k, &small[..k * k], &mut result[..k * k]);
        out.fill(0.0);
        for i in 0..n {
            out[i * n + i] = 1.0;
        }
        for (r, &i) in active[..k].iter().enumerate() {
            for (c, &j) in active[..k].iter().enumerate() {
                out[i * n + j] = result[r * k + c];
            }
        }
        return;
    }
    exp_dense(n, a, out)
}

// `exp_dense` has an arm for each size up to TRACKED.
const _: () = assert!(TRACKED == 8);

/// [`exp`] without looking for decoupled components.
fn exp_dense(n: usize, a: &[f64], out: &mut [f64]) {
    match n {
        0 => {}
        1 => out[0] = a[0].exp(),
        2 => exp2(a, out),
        // A Taylor step takes several of these: each size its own code,
        // with loops of constant length on the stack.
        3 => exp_sized::<3>(a, out),
        4 => exp_sized::<4>(a, out),
        5 => exp_sized::<5>(a, out),
        6 => exp_sized::<6>(a, out),
        7 => exp_sized::<7>(a, out),
        8 => exp_sized::<8>(a, out),
        n => exp_dynamic(n, a, out),
    }
}

/// [`exp`] for the larger sizes: nalgebra's (Al-Mohy and Higham 2009: a
/// Pade approximant of degree 3 to 13 as the norm needs, with scaling and
/// squaring). The row-major `a` read
/// column-major is its transpose, whose exponential is the transpose of
/// `exp(a)`: written back column-major, `exp(a)` row-major.
fn exp_dynamic(n: usize, a: &[f64], out: &mut [f64]) {
    if !a[..n * n].iter().all(|x| x.is_finite()) {
        out.fill(f64::NAN);
        return;
    }
    let transposed = nalgebra::DMatrix::from_column_slice(n, n, &a[..n * n]).exp();
    out[..n * n].copy_from_slice(transposed.as_slice());
}

/// An `N x N` matrix.
type Square<const N: usize> = [[f64; N]; N];

/// The row-major `a` times `scale`, as a [`Square`].
///
/// The squares here are filled by loops, not `array::from_fn` or
/// `array::map`, whose closures the compiler leaves as calls.
#[inline(always)]
fn square<const N: usize>(a: &[f64], scale: f64) -> Square<N> {
    let mut out = [[0.0; N]; N];
    for (row, a) in out.iter_mut().zip(a.chunks_exact(N)) {
        for (x, a) in row.iter_mut().zip(a) {
            *x = scale * a;
        }
    }
    out
}

fn exp_sized<const N: usize>(a: &[f64], out: &mut [f64]) {
    let norm = row_norm(N, a);
    if !norm.is_finite() {
        // No exponential to take: the bound that uses it becomes infinite.
        out.fill(f64::NAN);
        return;
    }
    // Scaled to |a / 2^s| <= TAYLOR_19_REACH, where the Taylor polynomial
    // of degree 19 is exact to round-off: a piece's generator (its spread
    // at most PIECE_SPREAD) mostly needs no squaring. The halvings are
    // exact.
    let (mut squarings, mut scale) = (0, 1.0);
    while norm * scale > TAYLOR_19_REACH {
        (squarings, scale) = (squarings + 1, 0.5 * scale);
    }
    // Paterson and Stockmeyer: with y = x^4, the sum over j of
    // B_j(x) y^j, B_j = c_4j I + c_4j+1 x + c_4j+2 x^2 + c_4j+3 x^3, by
    // Horner's rule in y: seven products, and no solve (a Pade
    // approximant's solve is a chain of divisions that took half the
    // time).
    let x = square::<N>(a, scale);
    let x2 = product(&x, &x);
    let x3 = product(&x2, &x);
    let y = product(&x2, &x2);
    let block = |j: usize| {
        let c = |k: usize| INVERSE_FACTORIALS[4 * j + k];
        let mut b = [[0.0; N]; N];
        for (i, row) in b.iter_mut().enumerate() {
            for (l, v) in row.iter_mut().enumerate() {
                let sum = c(1) * x[i][l] + c(2) * x2[i][l] + c(3) * x3[i][l];
                *v = if i == l { sum + c(0) } else { sum };
            }
        }
        b
    };
    let mut e = block(4);
    for j in (0..4).rev() {
        e = product(&e, &y);
        let b = block(j);
        for (row, b) in e.iter_mut().zip(&b) {
            for (v, b) in row.iter_mut().zip(b) {
                *v += b;
            }
        }
    }
    for _ in 0..squarings {
        e = product(&e, &e);
    }
    for (o, row) in out.chunks_exact_mut(N).zip(&e) {
        o.copy_from_slice(row);
    }
}

/// The norm up to which the Taylor polynomial of degree 19 gives `exp` to
/// round-off: its first term left out, `|x|^20 / 20!`, is 1.6e-17 at 1.2.
const TAYLOR_19_REACH: f64 = 1.2;

/// `1 / k!` for `k` from 0 to 19, each rounded once (`k!` is exact in
/// `f64` up to 22!).
const INVERSE_FACTORIALS: [f64; 20] = {
    let (mut c, mut factorial, mut k) = ([1.0; 20], 1.0, 1);
    while k < 20 {
        factorial *= k as f64;
        c[k] = 1.0 / factorial;
        k += 1;
    }
    c
};

/// `a b`, each entry summed over `l` in increasing order.
fn product<const N: usize>(a: &Square<N>, b: &Square<N>) -> Square<N> {
    // Row by row (a vector instruction per few entries), each entry's sum
    // in the same order.
    let mut out = [[0.0; N]; N];
    for (row, a) in out.iter_mut().zip(a) {
        *row = b[0];
        for x in row.iter_mut() {
            *x *= a[0];
        }
        for (a, b) in a.iter().zip(b).skip(1) {
            for (x, y) in row.iter_mut().zip(b) {
                *x += a * y;
            }
        }
    }
    out
}

/// `out = a b` of row-major `n x n` matrices, each entry summed over `l`
/// in increasing order. The tangents of a Taylor step take dozens of
/// these: sizes up to four get loops the compiler unrolls and checks no
/// bounds in.
fn mat_mul(n: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    match n {
        3 => mat_mul_fixed::<3>(a, b, out),
        4 => mat_mul_fixed::<4>(a, b, out),
        _ => {
            for (row, o) in a.chunks_exact(n).zip(out.chunks_exact_mut(n)) {
                for (j, o) in o.iter_mut().enumerate() {
                    *o = row.iter().enumerate().map(|(l, x)| x * b[l * n + j]).sum();
                }
            }
        }
    }
}

fn mat_mul_fixed<const N: usize>(a: &[f64], b: &[f64], out: &mut [f64]) {
    let p = product::<N>(&square(a, 1.0), &square(b, 1.0));
    for (o, row) in out.chunks_exact_mut(N).zip(&p) {
        o.copy_from_slice(row);
    }
}

/// `exp(a)` of a 2 x 2 matrix in closed form (the common case: one degree
/// of freedom): with `a = h I + b`, `b` traceless, `b^2 = d I`, so
/// `exp(a) = e^h (C I + S b)` with `C, S = cosh w, sinh w / w` for
/// `d = w^2 > 0` and `cos w, sin w / w` for `d = -w^2 < 0`.
fn exp2(a: &[f64], out: &mut [f64]) {
    let (p, q, r, s) = (a[0], a[1], a[2], a[3]);
    let h = 0.5 * (p + s);
    let d = 0.25 * (p - s) * (p - s) + q * r;
    let w = d.abs().sqrt();
    let (c, sinc) = match d {
        _ if w == 0.0 => (1.0, 1.0),
        _ if d > 0.0 => (w.cosh(), w.sinh() / w),
        _ => (w.cos(), w.sin() / w),
    };
    let e = h.exp();
    out[0] = e * (c + sinc * (p - h));
    out[1] = e * sinc * q;
    out[2] = e * sinc * r;
    out[3] = e * (c + sinc * (s - h));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{Direction, Guard, Jump, Name};
    use crate::names;
    use nalgebra::DMatrix;

    /// `theta'' = -sin(theta)`: a Jacobian that turns along the orbit, so
    /// that its values at two times do not commute.
    struct Pendulum;

    const NO_GUARD: &[Guard] = &[Guard::affine("never", Direction::Rising)];

    #[rustfmt::skip]
    impl HybridModel for Pendulum {
        fn dimension(&self) -> usize { 2 }
        fn state_names(&self, _: Mode) -> &[Name] { names!["theta", "omega"] }
        fn mode_name(&self, _: Mode) -> &str { "swing" }
        fn guards(&self, _: Mode) -> &[Guard] { NO_GUARD }
        fn guard(&self, _: Mode, _: usize, _: &[f64]) -> f64 { -1.0 }
        fn flow(&self, _: Mode) -> Flow { Flow::Ode }
        fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) { dx[0] = x[1]; dx[1] = -x[0].sin() }
        fn reset(&self, _: Mode, _: usize, _: &mut [f64]) -> Jump { Jump::to(0) }
        fn jacobian(&self, _: Mode, x: &[f64], jac: &mut [f64]) -> bool {
            jac.copy_from_slice(&[0.0, 1.0, -x[0].cos(), 0.0]);
            true
        }
    }

    /// The pendulum's state and its tangent (row-major) `s` from `theta =
    /// 1, omega = 0`, by classical Runge-Kutta in steps of at most 1e-4 on
    /// the state and its variational equation together (errors about
    /// 1e-16): a reference independent of the Magnus generator.
    fn pendulum_at(s: f64) -> ([f64; 2], [f64; 4]) {
        let rate = |y: &[f64; 6]| {
            let (c, sn) = (y[0].cos(), y[0].sin());
            // phi' = J phi, J = [[0, 1], [-cos, 0]].
            [y[1], -sn, y[4], y[5], -c * y[2], -c * y[3]]
        };
        let steps = (s / 1e-4).ceil().max(1.0) as usize;
        let h = s / steps as f64;
        let mut y = [1.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let add = |y: &[f64; 6], k: &[f64; 6], c: f64| std::array::from_fn(|i| y[i] + c * k[i]);
        for _ in 0..steps {
            let k1 = rate(&y);
            let k2 = rate(&add(&y, &k1, h / 2.0));
            let k3 = rate(&add(&y, &k2, h / 2.0));
            let k4 = rate(&add(&y, &k3, h));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        ([y[0], y[1]], [y[2], y[3], y[4], y[5]])
    }

    /// The largest entry of `a - b`.
    fn farthest(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
    }

    #[test]
    fn a_long_step_is_cut_into_pieces_each_of_the_generators_error() {
        // tau |J| = 2.5: three pieces of 0.83, the middle one's middle node
        // the step's midpoint (taken once), each piece about 3e-5 off.
        let mut tangents = Tangents::new(2);
        let mut out = [0.0; 4];
        let at = |s: f64, x: &mut [f64]| x.copy_from_slice(&pendulum_at(s).0);
        tangents.ode(&Pendulum, 0, (2.5, None), at, &mut out);
        let exact = pendulum_at(2.5).1;
        assert!(farthest(&out, &exact) < 2e-4, "{out:?} against {exact:?}");
    }

    #[test]
    fn the_magnus_generator_is_of_sixth_order() {
        // One piece of `tau`, its Jacobians at its Gauss points: the local
        // error falls as tau^7 (the midpoint's exponential: tau^3).
        let error = |tau: f64| {
            let nodes = [0.5 - GAUSS_OFFSET, 0.5, 0.5 + GAUSS_OFFSET].map(|c| {
                let ([theta, _], _) = pendulum_at(c * tau);
                vec![0.0, 1.0, -theta.cos(), 0.0]
            });
            let (mut omega, mut tangent) = ([0.0; 4], [0.0; 4]);
            magnus(2, tau, &nodes, &mut omega);
            exp(2, &omega, &mut tangent);
            farthest(&tangent, &pendulum_at(tau).1)
        };
        // (Measured: 2.5e-5, 1.2e-7, 9.9e-10, 7.8e-12 over 0.8, 0.4, 0.2,
        // 0.1: 128 times less for each halving, once past 0.4.)
        let (long, short) = (error(0.4), error(0.2));
        assert!(long < 1e-6, "error {long:e} over 0.4");
        assert!(
            short * 60.0 < long,
            "halving the piece: {long:e} -> {short:e}"
        );
    }

    #[test]
    fn a_step_tangent_is_within_its_generator_error_and_carries_the_flow() {
        let mut tangents = Tangents::new(2);
        let tau = 0.5;
        let mut out = [0.0; 4];
        let at = |s: f64, x: &mut [f64]| x.copy_from_slice(&pendulum_at(s).0);
        tangents.ode(&Pendulum, 0, (tau, None), at, &mut out);
        let (end, exact) = pendulum_at(tau);
        // One piece (tau |J| = 0.5), of Magnus' error (about 5e-7 here:
        // see above).
        assert!(farthest(&out, &exact) < 2e-6, "{out:?} against {exact:?}");
        // The rate at the start maps to the rate at the end.
        let (mut f0, mut f1) = ([0.0; 2], [0.0; 2]);
        Pendulum.rhs(0, &[1.0, 0.0], &mut f0);
        Pendulum.rhs(0, &end, &mut f1);
        let mapped = [
            out[0] * f0[0] + out[1] * f0[1],
            out[2] * f0[0] + out[3] * f0[1],
        ];
        assert!(farthest(&mapped, &f1) < 1e-15, "{mapped:?} against {f1:?}");
    }

    /// `x'' = -x`: a constant Jacobian, whose tangent over `tau` is the
    /// rotation by `tau`.
    struct Oscillator;

    #[rustfmt::skip]
    impl HybridModel for Oscillator {
        fn dimension(&self) -> usize { 2 }
        fn state_names(&self, _: Mode) -> &[Name] { names!["x", "v"] }
        fn mode_name(&self, _: Mode) -> &str { "swing" }
        fn guards(&self, _: Mode) -> &[Guard] { NO_GUARD }
        fn guard(&self, _: Mode, _: usize, _: &[f64]) -> f64 { -1.0 }
        fn flow(&self, _: Mode) -> Flow { Flow::Ode }
        fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) { dx[0] = x[1]; dx[1] = -x[0] }
        fn reset(&self, _: Mode, _: usize, _: &mut [f64]) -> Jump { Jump::to(0) }
        fn constant_jacobian(&self, _: Mode) -> Option<DMatrix<f64>> {
            Some(DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0]))
        }
    }

    #[test]
    fn a_constant_flow_s_tangents_are_each_their_own_stretch_s() {
        // Whole steps with an event's stretch between them, in every order
        // the two cached tangents can be asked for: each is the rotation
        // by its own stretch, never the other's.
        let mut tangents = Tangents::new(2);
        let at = |_: f64, _: &mut [f64]| panic!("a constant flow needs no states");
        for tau in [1.3, 0.4, 1.3, 0.7, 1.3, 1.3, 0.4, 0.7, 2.0, 1.3] {
            let mut out = [0.0; 4];
            tangents.ode(&Oscillator, 0, (tau, None), at, &mut out);
            let (c, s) = (f64::cos(tau), f64::sin(tau));
            assert!(farthest(&out, &[c, s, -s, c]) < 1e-15, "tau {tau}: {out:?}");
        }
    }

    #[test]
    fn the_closed_form_2x2_exp_agrees_with_the_series() {
        // Rotation, growth, shear, and a general matrix; the series path is
        // taken by embedding each in a 3 x 3 block matrix.
        for a in [
            [0.0, -2.0, 2.0, 0.0],
            [0.3, 1.2, 0.7, -0.1],
            [0.0, 1.0, 0.0, 0.0],
            [-1.0, 0.5, -4.0, 0.2],
        ] {
            let mut closed = [0.0; 4];
            exp2(&a, &mut closed);
            let big = [a[0], a[1], 0.0, a[2], a[3], 0.0, 0.0, 0.0, 0.0];
            let mut series = [0.0; 9];
            exp(3, &big, &mut series);
            for (c, s) in closed
                .iter()
                .zip([series[0], series[1], series[3], series[4]])
            {
                assert!(
                    (c - s).abs() < 1e-13 * s.abs().max(1.0),
                    "{a:?}: {closed:?} vs {series:?}"
                );
            }
        }
    }

    /// A 4 x 4 generator in two blocks, a rotation by `w` and a shear
    /// with growth: `exp` of the rotation block is `[[c, -s], [s, c]]`,
    /// of `[[g, 1], [0, g]]` it is `e^g [[1, 1], [0, 1]]`. From small
    /// norms (no squaring) to large (many).
    #[test]
    fn exp_of_a_4x4_rotation_and_shear_is_its_closed_form() {
        for (w, g) in [(0.1, 0.05), (0.2, -0.1), (2.0, 0.3), (40.0, -1.5)] {
            #[rustfmt::skip]
            let a = [
                0.0, -w, 0.0, 0.0,
                w, 0.0, 0.0, 0.0,
                0.0, 0.0, g, 1.0,
                0.0, 0.0, 0.0, g,
            ];
            let mut out = [0.0; 16];
            exp(4, &a, &mut out);
            let (c, s, e) = (w.cos(), w.sin(), f64::exp(g));
            #[rustfmt::skip]
            let want = [
                c, -s, 0.0, 0.0,
                s, c, 0.0, 0.0,
                0.0, 0.0, e, e,
                0.0, 0.0, 0.0, e,
            ];
            for (k, (got, want)) in out.iter().zip(want).enumerate() {
                // Each squaring doubles the relative error: about 6 ulps per
                // unit of the angle.
                assert!(
                    (got - want).abs() < 2e-15 * w.max(1.0) * want.abs().max(1.0),
                    "w {w}, g {g}, entry {k}: {got} vs {want}"
                );
            }
        }
    }

    /// The largest absolute row sum, whatever the entries' signs.
    #[test]
    fn the_row_norm_is_the_largest_absolute_row_sum() {
        #[rustfmt::skip]
        let a = [
            1.0, -2.0, 0.5,
            -4.0, 0.0, -0.25,
            0.0, 3.0, -1.0,
        ];
        assert_eq!(row_norm(3, &a), 4.25);
        assert_eq!(row_norm(1, &[-0.5]), 0.5);
        assert_eq!(row_norm(0, &[]), 0.0);
    }

    /// Every size up to TRACKED, and past it (nalgebra's exponential): a
    /// rotation by `w` beside a Jordan block `g I + S` (`S` the shift),
    /// whose exponential is `e^g / (j - i)!` above the diagonal.
    #[test]
    fn exp_of_a_rotation_beside_a_jordan_block_is_its_closed_form_at_every_size() {
        let (w, g) = (0.7, 0.1);
        for n in 3..=TRACKED + 4 {
            let mut a = vec![0.0; n * n];
            (a[1], a[n]) = (-w, w);
            for i in 2..n {
                a[i * n + i] = g;
                if i + 1 < n {
                    a[i * n + i + 1] = 1.0;
                }
            }
            let mut out = vec![0.0; n * n];
            exp(n, &a, &mut out);
            let factorial = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
            for i in 0..n {
                for j in 0..n {
                    let want = match (i, j) {
                        (0, 0) | (1, 1) => w.cos(),
                        (0, 1) => -w.sin(),
                        (1, 0) => w.sin(),
                        _ if i >= 2 && j >= i => g.exp() / factorial(j - i),
                        _ => 0.0,
                    };
                    let got = out[i * n + j];
                    assert!(
                        (got - want).abs() < 1e-14,
                        "n {n}, entry ({i}, {j}): {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn magnus_past_the_fixed_sizes_is_the_same_generator() {
        // Three Jacobians that do not commute: nalgebra's generator is the
        // fixed size's to rounding.
        let n = TRACKED;
        let node = |k: usize| -> Vec<f64> {
            (0..n * n)
                .map(|e| ((e * 7 + k * 13) % 11) as f64 / 11.0 - 0.5)
                .collect()
        };
        let nodes = [node(0), node(1), node(2)];
        let (mut fixed, mut dynamic) = (vec![0.0; n * n], vec![0.0; n * n]);
        magnus_sized::<TRACKED>(0.3, &nodes, &mut fixed);
        magnus_dynamic(n, 0.3, &nodes, &mut dynamic);
        let beyond_the_midpoint = farthest(
            &fixed,
            &nodes[1].iter().map(|a| 0.3 * a).collect::<Vec<_>>(),
        );
        assert!(beyond_the_midpoint > 1e-3, "{beyond_the_midpoint}");
        assert!(
            farthest(&fixed, &dynamic) < 1e-15,
            "{fixed:?} vs {dynamic:?}"
        );
    }

    #[test]
    fn exp_of_a_rotation_generator_is_the_rotation() {
        for angle in [0.0, 0.3, 2.0, 40.0] {
            let mut out = [0.0; 4];
            exp(2, &[0.0, -angle, angle, 0.0], &mut out);
            let (c, s) = (f64::cos(angle), f64::sin(angle));
            for (got, want) in out.iter().zip([c, -s, s, c]) {
                assert!(
                    (got - want).abs() < 1e-12 * angle.max(1.0),
                    "{angle}: {out:?}"
                );
            }
        }
    }
}
