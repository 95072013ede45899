//! The exact propagator of a linear flow `x' = A x + b`.
//!
//! With the augmented matrix `M = [[A, b], [0, 0]]`, the flow from `y` is
//! `exp(M tau) y = sum_k M^k y tau^k / k!`. Steps are bounded so that
//! `|M| h <= 1`; over a step the series is then summed to round-off by its
//! first [`ORDER`] + 1 terms (the rest is below `1 / 25!` of the state), so
//! each step computes them once, `ORDER` matrix-vector products, and the
//! state anywhere in the step is that polynomial summed by compensated
//! Horner: exact to a few ulps, with no matrix exponential.
//!
//! Events are found on the same polynomials: where the model gives its
//! guards' Taylor series along a flow's ([`HybridModel::guard_series`]), by
//! the certified root search Taylor's method uses (no root in the step
//! missed); elsewhere (a chain's ODE) by the engine's scan of the state
//! along the step ([`locate`](crate::engine::locate)), each bracket refined
//! on the propagator itself.

use std::cell::Cell;

use nalgebra::{DMatrix, DVector};

use crate::engine::adaptive::StepFailure;
use crate::engine::locate::{Start, StepScan};
use crate::engine::model::{HybridModel, Mode};
use crate::numerics::polynomial::eval_compensated;

/// The degree of a step's series: with `|M| h <= 1`, the first term left
/// out is below `1 / 25!` (7e-26) of the state.
pub const ORDER: usize = 24;

/// The exact propagator's working state: the augmented matrix of the
/// current mode, and the current step's series.
#[derive(Debug, Clone)]
pub struct Linear {
    /// The mode whose `M` is cached.
    mode: Option<Mode>,
    augmented: DMatrix<f64>,
    /// The same, row by row, for the series' products.
    rows: Vec<f64>,
    h_bound: f64,
    h: f64,
    y0: DVector<f64>,
    /// The step's series, component by component: `series[i * (ORDER + 1)
    /// + k]` is `(M^k y0)_i / k!`, the layout of
    /// [`HybridModel::flow_series`].
    series: Vec<f64>,
    /// Scratch: one term of the augmented series and the next.
    term: Vec<f64>,
    next: Vec<f64>,
    /// Each guard's series along the step, one after another (where the
    /// model gives them).
    guards: Vec<f64>,
    /// A guard's series, scratch for its search.
    guard: Vec<f64>,
    y1: Vec<f64>,
    /// Propagator evaluations; a `Cell` because evaluation reads `&self`.
    evaluations: Cell<u64>,
}

/// `out = a v` for a square matrix `a` laid out row by row.
fn mat_vec(a: &[f64], v: &[f64], out: &mut [f64]) {
    let m = v.len();
    for (o, row) in out[..m].iter_mut().zip(a.chunks_exact(m)) {
        *o = row.iter().zip(v).map(|(x, y)| x * y).sum();
    }
}

impl Linear {
    /// A propagator for states of `dimension` components.
    pub fn new(dimension: usize) -> Self {
        Linear {
            mode: None,
            augmented: DMatrix::zeros(dimension + 1, dimension + 1),
            rows: vec![0.0; (dimension + 1) * (dimension + 1)],
            h_bound: f64::INFINITY,
            h: 0.0,
            y0: DVector::zeros(dimension + 1),
            series: vec![0.0; dimension * (ORDER + 1)],
            term: vec![0.0; dimension + 1],
            next: vec![0.0; dimension + 1],
            guards: Vec::new(),
            guard: vec![0.0; ORDER + 1],
            y1: vec![0.0; dimension],
            evaluations: Cell::new(0),
        }
    }

    /// Nothing to forget: a step does not depend on the one before.
    pub fn restart(&mut self) {}

    /// The length of the last step taken.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// One step from `y0` in `mode`, as long as `h_max` and the bound
    /// `|M| h <= 1` allow; fails if the mode's flow is not linear or the
    /// state stops being finite.
    pub fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
    ) -> Result<(), StepFailure> {
        let n = y0.len();
        if self.mode != Some(mode) {
            let Some((a, b)) = model.linear(mode) else {
                return Err(StepFailure::NotApplicable(format!(
                    "mode `{}` is not a linear flow x' = A x + b",
                    model.mode_name(mode)
                )));
            };
            self.augmented.fill(0.0);
            self.augmented.view_mut((0, 0), (n, n)).copy_from(&a);
            self.augmented.view_mut((0, n), (n, 1)).copy_from(&b);
            if !self.augmented.iter().all(|x| x.is_finite()) {
                return Err(StepFailure::NonFinite);
            }
            let norm = self
                .augmented
                .column_iter()
                .map(|c| c.lp_norm(1))
                .fold(0.0, f64::max);
            self.h_bound = if norm > 0.0 {
                1.0 / norm
            } else {
                f64::INFINITY
            };
            let m = n + 1;
            for i in 0..m {
                for j in 0..m {
                    self.rows[i * m + j] = self.augmented[(i, j)];
                }
            }
            self.mode = Some(mode);
        }
        self.y0.rows_mut(0, n).copy_from_slice(y0);
        self.y0[n] = 1.0;
        self.h = self.h_bound.min(h_max);
        // The series: term k is M^k y0 / k!.
        let w = ORDER + 1;
        self.term.copy_from_slice(self.y0.as_slice());
        for k in 0..w {
            for i in 0..n {
                self.series[i * w + k] = self.term[i];
            }
            if k < ORDER {
                mat_vec(&self.rows, &self.term, &mut self.next);
                let scale = 1.0 / (k + 1) as f64;
                for (t, v) in self.term.iter_mut().zip(&self.next) {
                    *t = v * scale;
                }
            }
        }
        self.evaluations.set(self.evaluations.get() + 1);
        if model.has_series(mode) {
            let shortened_by = self.fit_guards(model, mode);
            if self.h < h_min {
                return Err(match shortened_by {
                    Some(guard) => StepFailure::GuardCollapsed { h: self.h, guard },
                    None => StepFailure::Collapsed { h: self.h },
                });
            }
        }
        let mut y1 = std::mem::take(&mut self.y1);
        self.eval(self.h, &mut y1);
        self.y1 = y1;
        if self.y1.iter().any(|x| !x.is_finite()) {
            return Err(StepFailure::NonFinite);
        }
        Ok(())
    }

    /// Each guard's series along the step (kept for [`Linear::locate`]),
    /// and the step shortened until every one of them is summed to
    /// round-off by its terms: the state's series converge over `|M| h <=
    /// 1`, but a guard may read the clock through a sine of any frequency.
    /// Returns the guard that shortened the step last, if one did: the one
    /// to blame where the step collapses (`sqrt(x)` near `x = 0`).
    fn fit_guards<M: HybridModel + ?Sized>(&mut self, model: &M, mode: Mode) -> Option<usize> {
        let w = ORDER + 1;
        let guards = model.guards(mode).len();
        self.guards.resize(guards * w, 0.0);
        // Measured as the state's own series are: against the state's size
        // (a guard's own coefficients, which a fast sine makes large, would
        // excuse any step).
        let scale = self.y0.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        let mut shortened_by = None;
        for g in 0..guards {
            let c = &mut self.guards[g * w..(g + 1) * w];
            model.guard_series(mode, g, &self.series, ORDER, c);
            // The last two terms at the step's length far below round-off
            // (1e-20 of the state's size: as far as the state's own, whose
            // last term is at most 1 / 24! of it).
            while self.h > 0.0
                && (c[ORDER - 1].abs() * self.h.powi(ORDER as i32 - 1)
                    + c[ORDER].abs() * self.h.powi(ORDER as i32))
                    > 1e-20 * scale
            {
                self.h *= 0.5;
                shortened_by = Some(g);
            }
        }
        shortened_by
    }

    /// The exact state `tau` after the step's start: the step's series
    /// inside it, an exponential of its own beyond.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        if tau <= self.h * (1.0 + 4.0 * f64::EPSILON) {
            for (xi, c) in x.iter_mut().zip(self.series.chunks_exact(ORDER + 1)) {
                *xi = eval_compensated(c, tau);
            }
            return;
        }
        let propagator = (&self.augmented * tau).exp();
        let y = propagator * &self.y0;
        x.copy_from_slice(&y.as_slice()[..x.len()]);
        self.evaluations.set(self.evaluations.get() + 1);
    }

    /// Where the model gives its guards' series: the first crossing of
    /// `guard` in the step on its series, as Taylor's method finds it (see
    /// [`crate::engine::taylor_method`]); `None` where the step is to be scanned.
    pub fn locate<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        guard: usize,
        start: Start,
        uncertainty: f64,
    ) -> Option<Result<StepScan, String>> {
        if !model.has_series(mode) {
            return None;
        }
        let w = ORDER + 1;
        self.guard
            .copy_from_slice(&self.guards[guard * w..(guard + 1) * w]);
        Some(crate::engine::taylor_method::locate_on_series(
            model,
            mode,
            guard,
            &mut self.guard,
            self.h,
            start,
            uncertainty,
        ))
    }

    /// Propagator evaluations so far: the series and exponentials taken.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.get()
    }

    /// The truncation of one propagation's series: below `1 / 25!` of the
    /// state, nothing beside the step's rounding (which the engine adds:
    /// see `STEP_ROUNDING_ULPS` in `src/engine/simulation.rs`).
    pub fn local_error(&self) -> f64 {
        0.0
    }

    /// The state at the end of the step.
    pub fn end(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.y1);
    }
}
