//! An affine mode `x' = A x + b` solved once for the exact linear
//! propagator ([`crate::engine::step::linear`]), so that a step costs a
//! matrix-vector product instead of a Taylor series.
//!
//! With the augmented matrix `M = [[A, b], [0, 0]]` and `y = [x, 1]`, the
//! flow over `tau` is `exp(M tau) y`. Steps are at most `h = REACH / |M|_1`
//! long, over which the series of `exp(M h)` is summed to round-off by
//! [`ORDER`] + 1 terms. Where the mode is small enough (see
//! [`SOLVED_DIMENSION`]) this holds, once per mode:
//! - the propagator over a whole step, `exp(M h)` in double-double, so that
//!   a step rounds its result once, as the series it replaces does, and
//!   applying it many times adds no bias of its own; it is built once the
//!   mode has taken `m` whole steps by their series, `m` the augmented
//!   state's length (`n + 1`, two more per wave below; building it takes
//!   `m` series in double-double: microseconds for a few states, a
//!   millisecond at 16), so a run of a handful of steps never pays for it
//!   and any longer one wins it back;
//! - for each guard that is affine in the state, `g(x) = c . x + d`, the
//!   rows `[c, d] M^k / k!`: the guard's Taylor coefficients along any step
//!   are their products with `y`, with no series of the state in between;
//! - the same rows for each state component, `e_i M^k / k!`: the state's
//!   own series where a step needs it (an event's state), each coefficient
//!   one product, independent of the others.
//!
//! A mode driven by sines of the clock ([`AffineFlow`]'s waves) adds two
//! components per frequency, `sigma cos(w t)` and `sigma sin(w t)` (their
//! rows the rotation `C' = -w S`, `S' = w C`, their columns the forcing
//! over `sigma`, which keeps them from shortening the steps): `y = [x, 1,
//! sigma C, sigma S, ...]`, filled at each step's start from its exact
//! time ([`AffineMode::augment`]).
//!
//! [`AffineFlow`]: crate::engine::model::affine_flow::AffineFlow

use nalgebra::DMatrix;

use crate::engine::model::affine_flow::cos_sin;
use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::adaptive::StepFailure;
use crate::numerics::double_double::{DoubleDouble, dots};

/// The degree of a step's series: with `|M| h <= REACH`, the terms left
/// out sum to below `REACH^25 e^REACH / 25!` (7e-21) of the state.
pub const ORDER: usize = 24;

/// The longest step in units of `1 / |M|_1`. Over `|M| h = 1` the series
/// would be summed to 1e-25, far past round-off; over 1.5 to 7e-21, and
/// the double-double head of a state inside a step ([`FIRST`]) leaves
/// 3e-8 of an ulp. A longer step costs its series nothing, and every step
/// saved is a guard series, a root search and a map of the error set saved
/// (the forced passages: 11,459 steps to 7,641, 1.40x heyoka's time to
/// 1.12x). Past 1.5 the last terms of a guard's series (see
/// `Linear::fit_guards`) would cut the steps back.
pub const REACH: f64 = 1.5;

/// The largest state whose mode is solved once (with its waves, an
/// augmented state of `m <= SOLVED_DIMENSION + 1`): its propagator holds
/// `m^2` numbers and costs `m` series to build, and each affine guard
/// `(ORDER + 1) m` more, which a long chain (thousands of
/// states, one guard per unit) could not afford; larger modes are stepped
/// by their series.
pub const SOLVED_DIMENSION: usize = 32;

/// A mode's augmented matrix, its step bound and, where it is small, its
/// propagator and its affine guards' rows.
#[derive(Debug, Clone)]
pub struct AffineMode {
    /// `M`, row by row, `m^2` numbers (`m` the augmented state's length).
    pub rows: Vec<f64>,
    /// The longest step, `REACH / |M|_1` (infinite for `M = 0`).
    pub h_bound: f64,
    /// The clock, where sines of it drive the flow.
    clock: Option<usize>,
    /// Each wave's frequency and the scale its components are held at:
    /// `y = [x, 1, scale cos(w t), scale sin(w t), ...]`.
    waves: Vec<(f64, f64)>,
    /// `sum_k max_i (|c_ki| + |s_ki|)`: how strongly the waves drive the
    /// state, for the error their rounding leaves (see
    /// [`AffineMode::wave_error`]).
    drive: f64,
    /// `exp(M h_bound)` row by row in double-double (see
    /// [`crate::numerics::double_double::dot`]), once built.
    propagator: Option<Vec<DoubleDouble>>,
    /// Whole steps taken by the series so far.
    series_steps: u32,
    /// Per guard: the rows `[c, d] M^k / k!`, `k = 0..=ORDER`, one after
    /// another, for a guard affine in the state of a mode solved once.
    pub guard_rows: Vec<Option<Vec<f64>>>,
    /// Where the mode is small: each state component's rows `e_i M^k / k!`,
    /// `k = 0..=ORDER`, one component after another.
    pub state_rows: Option<Vec<f64>>,
    /// The same rows for `k <= FIRST`, in double-double.
    pub first_rows: Option<FirstRows>,
}

/// Each state component's rows `e_i M^k / k!`, `k = 0..=FIRST`, in
/// double-double, for [`state_series_in_two`]: by column (the `FIRST + 1`
/// rows' entries `j` together), their high and low parts apart, one
/// component after another; and the clock's component, which needs none
/// (its series is `t + tau`, exact).
#[derive(Debug, Clone)]
pub struct FirstRows {
    hi: Vec<f64>,
    lo: Vec<f64>,
    clock: Option<usize>,
}

/// The terms of a state's series summed in double-double where a step
/// evaluates it inside (an event's state, a step cut short), so that the
/// state and what its rounding left out are known to well below an ulp:
/// past them the terms are below `(|M| h)^13 / 13!` (3e-8) of the state,
/// and what their rounding adds is below that part of an ulp. A periodic
/// impact orbit repeats that error every period: with six terms (1e-3 of
/// an ulp) the mechanism's speed grew an ulp every 7,000 impacts.
pub const FIRST: usize = 12;

/// `out = a v` for a square matrix `a` laid out row by row.
pub fn mat_vec(a: &[f64], v: &[f64], out: &mut [f64]) {
    let m = v.len();
    for (o, row) in out[..m].iter_mut().zip(a.chunks_exact(m)) {
        *o = row.iter().zip(v).map(|(x, y)| x * y).sum();
    }
}

/// The series of `exp(M tau) y`, component by component: `series[i *
/// (ORDER + 1) + k]` is `(M^k y)_i / k!` for the first `series.len() /
/// (ORDER + 1)` components (the layout of [`HybridModel::flow_series`]),
/// by `ORDER` products with `M`: for a mode too large to be solved once
/// (a small one has [`AffineMode::state_rows`]). `term` and `next` are
/// scratch of `y`'s length.
pub fn state_series(
    rows: &[f64],
    y: &[f64],
    series: &mut [f64],
    term: &mut [f64],
    next: &mut [f64],
) {
    let w = ORDER + 1;
    let n = series.len() / w;
    term.copy_from_slice(y);
    for k in 0..w {
        for i in 0..n {
            series[i * w + k] = term[i];
        }
        if k < ORDER {
            mat_vec(rows, term, next);
            let scale = 1.0 / (k + 1) as f64;
            for (t, v) in term.iter_mut().zip(next.iter()) {
                *t = v * scale;
            }
        }
    }
}

/// [`state_series`] for a mode solved once, from `y` and the residual
/// `y_lo` of its rounding: each component's first `FIRST + 1` terms from
/// its double-double rows ([`FirstRows`]), each rounded once and what that
/// left out pushed onto `lo` (`FIRST + 1` per component); the terms past
/// them, each at most `3e-8` of the state, one product of a cached row of
/// [`AffineMode::state_rows`] with `y`. The products are independent of
/// each other (a chain of `ORDER` products with `M` waits on each in turn).
pub fn state_series_in_two(
    state_rows: &[f64],
    first: &FirstRows,
    y: &[f64],
    y_lo: &[f64],
    series: &mut [f64],
    lo: &mut Vec<f64>,
) {
    const ZEROS: [f64; SOLVED_DIMENSION + 1] = [0.0; SOLVED_DIMENSION + 1];
    let (w, m) = (ORDER + 1, y.len());
    let head_len = (FIRST + 1) * m;
    let components = (state_rows.chunks_exact(w * m)).zip(
        first
            .hi
            .chunks_exact(head_len)
            .zip(first.lo.chunks_exact(head_len)),
    );
    for (i, ((rows, columns), out)) in components.zip(series.chunks_exact_mut(w)).enumerate() {
        if Some(i) == first.clock {
            // `t + tau`: its terms exact in double (past the first two,
            // zero), the start's residual the only one left out.
            let (head, rest) = out.split_at_mut(2);
            guard_series(&rows[..2 * m], y, &ZEROS[..m], head);
            rest.fill(0.0);
            lo.push(y_lo[i]);
            lo.extend([0.0; FIRST]);
            continue;
        }
        let (head, tail) = out.split_at_mut(FIRST + 1);
        for (o, term) in head.iter_mut().zip(dots::<{ FIRST + 1 }>(columns, y, y_lo)) {
            *o = term.hi;
            lo.push(term.lo);
        }
        guard_series(&rows[(FIRST + 1) * m..], y, &ZEROS[..m], tail);
    }
}

/// An affine guard's series along a step that starts from `y` (and the
/// residual `y_lo` of its rounding): `out[k] = row_k . y + row_k . y_lo`
/// for the rows of [`AffineMode::guard_rows`]. Small states take a loop
/// unrolled for their size.
pub fn guard_series(rows: &[f64], y: &[f64], y_lo: &[f64], out: &mut [f64]) {
    match y.len() {
        2 => guard_series_of::<2>(rows, y, y_lo, out),
        3 => guard_series_of::<3>(rows, y, y_lo, out),
        4 => guard_series_of::<4>(rows, y, y_lo, out),
        5 => guard_series_of::<5>(rows, y, y_lo, out),
        // A forced oscillator: two states, the clock, one wave.
        6 => guard_series_of::<6>(rows, y, y_lo, out),
        7 => guard_series_of::<7>(rows, y, y_lo, out),
        m => {
            let product =
                |row: &[f64], y: &[f64]| -> f64 { row.iter().zip(y).map(|(a, b)| a * b).sum() };
            for (o, row) in out.iter_mut().zip(rows.chunks_exact(m)) {
                *o = product(row, y) + product(row, y_lo);
            }
        }
    }
}

/// [`guard_series`] for an augmented state of `M` components.
fn guard_series_of<const M: usize>(rows: &[f64], y: &[f64], y_lo: &[f64], out: &mut [f64]) {
    let mut start = [0.0; M];
    start.copy_from_slice(y);
    let mut lo = [0.0; M];
    lo.copy_from_slice(y_lo);
    // Most steps start from a state that was not a whole step's end.
    let carried = lo.iter().any(|l| *l != 0.0);
    for (o, row) in out.iter_mut().zip(rows.chunks_exact(M)) {
        let mut sum = 0.0;
        for (a, b) in row.iter().zip(&start) {
            sum += a * b;
        }
        if carried {
            let mut residual = 0.0;
            for (a, b) in row.iter().zip(&lo) {
                residual += a * b;
            }
            sum += residual;
        }
        *o = sum;
    }
}

impl AffineMode {
    /// `mode` of `model` solved once, or why it cannot be: its flow is not
    /// affine, or its matrix not finite.
    pub fn new<M: HybridModel + ?Sized>(
        model: &M,
        mode: Mode,
        n: usize,
    ) -> Result<Self, StepFailure> {
        let Some(flow) = model.affine_flow(mode) else {
            return Err(StepFailure::NotApplicable(format!(
                "mode `{}` is not a linear flow x' = A x + b (plus sines of t)",
                model.mode_name(mode)
            )));
        };
        let clock = match (flow.waves.is_empty(), model.clock()) {
            (true, _) => None,
            (false, Some(clock)) => Some(clock),
            (false, None) => {
                return Err(StepFailure::NotApplicable(format!(
                    "mode `{}` is driven by sines of t but the model has no clock",
                    model.mode_name(mode)
                )));
            }
        };
        let m = n + 1 + 2 * flow.waves.len();
        let mut augmented = DMatrix::zeros(m, m);
        augmented.view_mut((0, 0), (n, n)).copy_from(&flow.a);
        augmented.view_mut((0, n), (n, 1)).copy_from(&flow.b);
        let column_norm = |a: &DMatrix<f64>, j: usize| a.column(j).lp_norm(1);
        let undriven = (0..=n)
            .map(|j| column_norm(&augmented, j))
            .fold(0.0, f64::max);
        let mut waves = Vec::with_capacity(flow.waves.len());
        let mut drive = 0.0;
        for (k, wave) in flow.waves.iter().enumerate() {
            let (c, s) = (n + 1 + 2 * k, n + 2 + 2 * k);
            // The wave's components held scaled, `sigma (cos, sin)`, so
            // that its columns (`|c_k| / sigma + w`) do not shorten the
            // steps below what `A` and `b` allow where they need not.
            let size = wave.cos.lp_norm(1).max(wave.sin.lp_norm(1));
            let room = (undriven - wave.frequency).max(0.25 * wave.frequency);
            // A power of two: the coefficients over it, and the values
            // times it, are exact.
            let scale = if size > 0.0 {
                (size / room).log2().ceil().exp2()
            } else {
                1.0
            };
            augmented
                .view_mut((0, c), (n, 1))
                .copy_from(&(&wave.cos / scale));
            augmented
                .view_mut((0, s), (n, 1))
                .copy_from(&(&wave.sin / scale));
            augmented[(c, s)] = -wave.frequency;
            augmented[(s, c)] = wave.frequency;
            waves.push((wave.frequency, scale));
            drive += (0..n)
                .map(|i| wave.cos[i].abs() + wave.sin[i].abs())
                .fold(0.0, f64::max);
        }
        if !augmented.iter().all(|x| x.is_finite()) || !waves.iter().all(|(_, s)| s.is_finite()) {
            return Err(StepFailure::NonFinite);
        }
        let norm = (0..m)
            .map(|j| column_norm(&augmented, j))
            .fold(0.0, f64::max);
        let h_bound = if norm > 0.0 {
            REACH / norm
        } else {
            f64::INFINITY
        };
        let mut rows = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                rows[i * m + j] = augmented[(i, j)];
            }
        }
        let mut solved = AffineMode {
            rows,
            h_bound,
            clock,
            waves,
            drive,
            propagator: None,
            series_steps: 0,
            guard_rows: vec![None; model.guards(mode).len()],
            state_rows: None,
            first_rows: None,
        };
        if m <= SOLVED_DIMENSION + 1 {
            solved.state_rows = Some(solved.component_rows(n));
            // The clock's series is `t + tau` where its row of `M` says
            // `t' = 1`, as an automaton's does.
            let clock = model.clock().filter(|&c| {
                c < n && (0..m).all(|j| solved.rows[c * m + j] == if j == n { 1.0 } else { 0.0 })
            });
            solved.first_rows = Some(solved.first_component_rows(n, clock));
            for g in 0..solved.guard_rows.len() {
                solved.guard_rows[g] = solved.affine_guard_rows(model, mode, g, n);
            }
        }
        Ok(solved)
    }

    /// The propagator over a whole step (`h_bound`), for one more whole
    /// step: `None` while the mode is too large, its bound infinite, or it
    /// has taken no more than its augmented size (`m`) by the series.
    pub fn whole_step(&mut self) -> Option<&[DoubleDouble]> {
        if self.propagator.is_none() {
            let m = self.augmented_len();
            if m > SOLVED_DIMENSION + 1 || !self.h_bound.is_finite() {
                return None;
            }
            self.series_steps += 1;
            if self.series_steps <= m as u32 {
                return None;
            }
            self.propagator = Some(self.propagator_over(self.h_bound, m));
        }
        self.propagator.as_deref()
    }

    /// The augmented state at the start of a step from `x` (`n`
    /// components): `[x, 1, scale cos(w t), scale sin(w t), ...]`, `t` the
    /// clock's value and what its rounding left out in `x_lo` (the run's
    /// exact time: the time rounded would shift the forcing against the
    /// state by half an ulp of `t` at every step).
    pub fn augment(&self, x: &[f64], x_lo: &[f64], y: &mut [f64]) {
        let n = x.len();
        y[..n].copy_from_slice(x);
        y[n] = 1.0;
        if let Some(clock) = self.clock {
            for (k, &(w, scale)) in self.waves.iter().enumerate() {
                let (c, s) = cos_sin(w, x[clock], x_lo[clock]);
                y[n + 1 + 2 * k] = scale * c;
                y[n + 2 + 2 * k] = scale * s;
            }
        }
    }

    /// What the waves' rounding may leave in the state over a step of
    /// `h`: each wave starts within `3 eps` of its value ([`cos_sin`]: the
    /// library's sine and cosine within an ulp, the first-order turn's
    /// product and sum within one each; the scale a power of two, exact),
    /// and drives the state by at most `drive` through a propagator of
    /// norm at most `e^REACH` (`|M| h <= REACH`). Zero where no wave
    /// drives the flow.
    pub fn wave_error(&self, h: f64) -> f64 {
        REACH.exp() * 3.0 * f64::EPSILON * self.drive * h
    }

    /// `n + 1` (and two per wave), the augmented state's length.
    pub fn augmented_len(&self) -> usize {
        (self.rows.len() as f64).sqrt().round() as usize
    }

    /// `exp(M h)` row by row, to double-double rounding and the series'
    /// truncation (below 7e-21 of the state, see [`ORDER`]): the series
    /// `sum_k (M h)^k / k!` in double-double.
    fn propagator_over(&self, h: f64, m: usize) -> Vec<DoubleDouble> {
        let mut term: Vec<DoubleDouble> = (0..m * m)
            .map(|i| DoubleDouble::from(if i % (m + 1) == 0 { 1.0 } else { 0.0 }))
            .collect();
        let mut sum = term.clone();
        let mut next = vec![DoubleDouble::default(); m * m];
        let mut power = DoubleDouble::from(1.0);
        for k in 1..=ORDER {
            // term = M term / k; the sum gains term h^k.
            for i in 0..m {
                for j in 0..m {
                    next[i * m + j] = (0..m).fold(DoubleDouble::default(), |acc, l| {
                        acc + term[l * m + j] * self.rows[i * m + l]
                    });
                }
            }
            power = power * h;
            for ((t, n), s) in term.iter_mut().zip(&next).zip(sum.iter_mut()) {
                *t = n.divide(k as f64);
                *s = *s + *t * power;
            }
        }
        sum
    }

    /// The rows `[c, d] M^k / k!` of guard `g`, if the model says it is
    /// affine and gives its gradient `c` (then constant; `d` is the guard
    /// at the zero state).
    fn affine_guard_rows<M: HybridModel + ?Sized>(
        &self,
        model: &M,
        mode: Mode,
        g: usize,
        n: usize,
    ) -> Option<Vec<f64>> {
        if !model.guards(mode)[g].affine {
            return None;
        }
        let m = self.augmented_len();
        let zero = vec![0.0; n];
        let mut row = vec![0.0; m];
        if !model.guard_gradient(mode, g, &zero, &mut row[..n]) {
            return None;
        }
        row[n] = model.guard(mode, g, &zero);
        if !row.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(self.powers(&row))
    }

    /// Each state component's rows `e_i M^k / k!`, `k = 0..=ORDER`, one
    /// component after another: its Taylor coefficients along any step are
    /// their products with `y`, each rounded once.
    fn component_rows(&self, n: usize) -> Vec<f64> {
        let m = self.augmented_len();
        let mut all = Vec::with_capacity(n * (ORDER + 1) * m);
        for i in 0..n {
            let mut unit = vec![0.0; m];
            unit[i] = 1.0;
            all.extend(self.powers(&unit));
        }
        all
    }

    /// The state components' [`FirstRows`].
    fn first_component_rows(&self, n: usize, clock: Option<usize>) -> FirstRows {
        let m = self.augmented_len();
        let (mut hi, mut lo) = (Vec::with_capacity(n * (FIRST + 1) * m), Vec::new());
        let mut rows = vec![DoubleDouble::default(); (FIRST + 1) * m];
        for i in 0..n {
            rows.fill(DoubleDouble::default());
            if Some(i) == clock {
                // Its series is summed in double (see
                // `state_series_in_two`): its rows stay zero.
                hi.resize(hi.len() + (FIRST + 1) * m, 0.0);
                lo.resize(lo.len() + (FIRST + 1) * m, 0.0);
                continue;
            }
            rows[i] = DoubleDouble::from(1.0);
            for k in 1..=FIRST {
                // row_k = row_{k-1} M / k.
                for j in 0..m {
                    let sum = (0..m).fold(DoubleDouble::default(), |acc, l| {
                        acc + rows[(k - 1) * m + l] * self.rows[l * m + j]
                    });
                    rows[k * m + j] = sum.divide(k as f64);
                }
            }
            for j in 0..m {
                for k in 0..=FIRST {
                    hi.push(rows[k * m + j].hi);
                    lo.push(rows[k * m + j].lo);
                }
            }
        }
        FirstRows { hi, lo, clock }
    }

    /// `row M^k / k!` for `k = 0..=ORDER`, one after another.
    fn powers(&self, row: &[f64]) -> Vec<f64> {
        let m = row.len();
        let mut out = vec![0.0; (ORDER + 1) * m];
        out[..m].copy_from_slice(row);
        for k in 1..=ORDER {
            // row_k = row_{k-1} M / k.
            let (done, rest) = out.split_at_mut(k * m);
            let previous = &done[(k - 1) * m..];
            let scale = 1.0 / k as f64;
            for (j, o) in rest[..m].iter_mut().enumerate() {
                *o = previous
                    .iter()
                    .enumerate()
                    .map(|(i, p)| p * self.rows[i * m + j])
                    .sum::<f64>()
                    * scale;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two states' series of the 3 x 3 augmented matrix `rows` from
    /// `y` and `y_lo` ([`state_series_in_two`]), and their first terms'
    /// residuals.
    fn two_series(
        rows: Vec<f64>,
        clock: Option<usize>,
        y: [f64; 3],
        y_lo: [f64; 3],
    ) -> (Vec<f64>, Vec<f64>) {
        let mode = of_rows(rows);
        let (mut series, mut lo) = (vec![f64::NAN; 2 * (ORDER + 1)], Vec::new());
        let first = mode.first_component_rows(2, clock);
        state_series_in_two(
            &mode.component_rows(2),
            &first,
            &y,
            &y_lo,
            &mut series,
            &mut lo,
        );
        (series, lo)
    }

    /// A mode of the augmented matrix `rows` alone, for what reads only it.
    fn of_rows(rows: Vec<f64>) -> AffineMode {
        AffineMode {
            rows,
            h_bound: 1.0,
            clock: None,
            waves: Vec::new(),
            drive: 0.0,
            propagator: None,
            series_steps: 0,
            guard_rows: Vec::new(),
            state_rows: None,
            first_rows: None,
        }
    }

    #[test]
    fn a_rotation_step_is_its_cosine_and_sine() {
        // x' = y, y' = -x: M h with h = 1 (|M|_1 = 1).
        let rows = vec![0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mode = of_rows(rows);
        let p = mode.propagator_over(1.0, 3);
        let (c, s) = (1.0_f64.cos(), 1.0_f64.sin());
        let expected = [c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0];
        for (got, want) in p.iter().zip(expected) {
            assert!(
                (got.round() - want).abs() <= f64::EPSILON,
                "{got:?} vs {want}"
            );
        }
        // Beyond double: cos^2 + sin^2 - 1 in double-double is down at the
        // series' truncation (its first term left out, 1 / 25! = 6.4e-26),
        // where a propagator rounded to double leaves about 1e-16.
        let norm = p[0] * p[0] + p[1] * p[1] + DoubleDouble::from(-1.0);
        assert!(
            norm.round().abs() < 4.0 / 15511210043330985984000000.0,
            "{norm:?}"
        );
    }

    #[test]
    fn the_clock_s_series_is_its_time_and_its_rate() {
        // x' = t, t' = 1 from (0.5, 3 + 2e-16 unrounded): x = 0.5 + 3 s +
        // s^2 / 2, t = 3 + s; the clock's residual is its own first term's
        // and x's slope's.
        let rows = vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let w = ORDER + 1;
        let (series, lo) = two_series(rows, Some(1), [0.5, 3.0, 1.0], [0.0, 2e-16, 0.0]);
        let mut x = vec![0.0; w];
        x[..3].copy_from_slice(&[0.5, 3.0, 0.5]);
        let mut t = vec![0.0; w];
        t[..2].copy_from_slice(&[3.0, 1.0]);
        assert_eq!(&series[..w], &x[..]);
        assert_eq!(&series[w..], &t[..]);
        let mut x_lo = [0.0; FIRST + 1];
        x_lo[1] = 2e-16;
        let mut t_lo = [0.0; FIRST + 1];
        t_lo[0] = 2e-16;
        assert_eq!(&lo[..FIRST + 1], &x_lo[..]);
        assert_eq!(&lo[FIRST + 1..], &t_lo[..]);
    }

    #[test]
    fn state_rows_give_the_cosine_and_sine_series() {
        // x' = y + 1, y' = -x from (0, 0) (the augmented 1 last): x = sin t,
        // y = cos t - 1.
        let rows = vec![0.0, 1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let w = ORDER + 1;
        let (series, lo) = two_series(rows, None, [0.0, 0.0, 1.0], [0.0; 3]);
        let mut factorial = DoubleDouble::from(1.0);
        for k in 0..w {
            if k > 0 {
                factorial = factorial * k as f64;
            }
            let sign = if k % 4 < 2 { 1.0 } else { -1.0 };
            // sin t at odd k, cos t - 1 at even k > 0: +-1 / k!.
            let (x, y) = match k {
                0 => (0.0, 0.0),
                k if k % 2 == 0 => (0.0, sign / factorial.hi),
                _ => (sign / factorial.hi, 0.0),
            };
            for (got, want) in [(series[k], x), (series[w + k], y)] {
                assert!(
                    (got - want).abs() <= 4.0 * f64::EPSILON * want.abs(),
                    "{k}: {got} vs {want}"
                );
            }
            // The first terms to double-double: `(hi + lo) k!` is +-1 to
            // far below an ulp.
            if k <= FIRST {
                for (i, want) in [(0, x), (1, y)] {
                    let term = DoubleDouble::from(series[i * w + k])
                        + DoubleDouble::from(lo[i * (FIRST + 1) + k]);
                    let one = if want == 0.0 { 0.0 } else { want.signum() };
                    let off = (term * factorial + DoubleDouble::from(-one)).round();
                    assert!(off.abs() < 1e-30, "{k}, component {i}: {off:e}");
                }
            }
        }
    }
}
