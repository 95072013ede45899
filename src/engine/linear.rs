//! The exact propagator of a linear flow `x' = A x + b`.
//!
//! With the augmented matrix `M = [[A, b], [0, 0]]`, `exp(M tau)` holds both
//! `exp(A tau)` and `(integral of exp(A s) ds) b`, so one matrix exponential
//! (nalgebra's scaled Pade) gives the state at any `tau` to round-off.
//! Steps are bounded so that `|M| h <= 1/2`: within a step the guard is
//! smooth enough for the polynomial root isolation of
//! [`locate`](crate::engine::locate) to bracket every crossing, and each
//! bracket is refined on the exact propagator itself.

use std::cell::Cell;

use nalgebra::{DMatrix, DVector};

use crate::engine::adaptive::StepFailure;
use crate::engine::model::{HybridModel, Mode};

/// The exact propagator's working state: the augmented matrix of the
/// current mode, and the current step.
#[derive(Debug, Clone)]
pub struct Linear {
    /// The mode whose `M` is cached.
    mode: Option<Mode>,
    augmented: DMatrix<f64>,
    h_bound: f64,
    h: f64,
    y0: DVector<f64>,
    y1: Vec<f64>,
    /// `exp(M h / GRID)` for the step length `h` it was made for: event
    /// location samples the step at multiples of `h / GRID`, so the states
    /// there come from powers of it, without a matrix exponential each.
    /// With it, `exp(M h)` itself, which takes the step to its end in one
    /// product (no rounding piled up over `GRID` products).
    grid_propagator: Option<(f64, DMatrix<f64>, DMatrix<f64>)>,
    /// The states at `k h / GRID`, `k = 0..=GRID`, of the current step.
    grid: Vec<DVector<f64>>,
    /// Propagator evaluations; a `Cell` because evaluation reads `&self`.
    evaluations: Cell<u64>,
}

/// Points per step whose states are kept (see `Linear::grid`).
const GRID: usize = 8;

impl Linear {
    /// A propagator for states of `dimension` components.
    pub fn new(dimension: usize) -> Self {
        Linear {
            mode: None,
            augmented: DMatrix::zeros(dimension + 1, dimension + 1),
            h_bound: f64::INFINITY,
            h: 0.0,
            y0: DVector::zeros(dimension + 1),
            y1: vec![0.0; dimension],
            grid_propagator: None,
            grid: Vec::new(),
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
    /// `|M| h <= 1/2` allow; fails if the mode's flow is not linear or the
    /// state stops being finite.
    pub fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        _h_min: f64,
    ) -> Result<(), StepFailure> {
        if self.mode != Some(mode) {
            let Some((a, b)) = model.linear(mode) else {
                return Err(StepFailure::NotApplicable(format!(
                    "mode `{}` is not a linear flow x' = A x + b",
                    model.mode_name(mode)
                )));
            };
            let n = y0.len();
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
                0.5 / norm
            } else {
                f64::INFINITY
            };
            self.mode = Some(mode);
            self.grid_propagator = None;
        }
        self.y0.rows_mut(0, y0.len()).copy_from_slice(y0);
        self.y0[y0.len()] = 1.0;
        self.h = self.h_bound.min(h_max);
        if self
            .grid_propagator
            .as_ref()
            .is_none_or(|(h, _, _)| *h != self.h)
        {
            let part = (&self.augmented * (self.h / GRID as f64)).exp();
            let whole = (&self.augmented * self.h).exp();
            self.evaluations.set(self.evaluations.get() + 2);
            self.grid_propagator = Some((self.h, part, whole));
        }
        if let Some((_, part, whole)) = &self.grid_propagator {
            self.grid.clear();
            self.grid.push(self.y0.clone());
            for k in 1..GRID {
                let next = part * &self.grid[k - 1];
                self.grid.push(next);
            }
            self.grid.push(whole * &self.y0);
        }
        let n = y0.len();
        self.y1.copy_from_slice(&self.grid[GRID].as_slice()[..n]);
        if self.y1.iter().any(|x| !x.is_finite()) {
            return Err(StepFailure::NonFinite);
        }
        Ok(())
    }

    /// The exact state `tau` after the step's start.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        let k = (tau / self.h * GRID as f64).round();
        if (0.0..=GRID as f64).contains(&k)
            && (tau - k * self.h / GRID as f64).abs() <= 4.0 * f64::EPSILON * self.h
        {
            x.copy_from_slice(&self.grid[k as usize].as_slice()[..x.len()]);
            return;
        }
        let propagator = (&self.augmented * tau).exp();
        let y = propagator * &self.y0;
        x.copy_from_slice(&y.as_slice()[..x.len()]);
        self.evaluations.set(self.evaluations.get() + 1);
    }

    /// Propagator evaluations so far: the matrix exponentials taken.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.get()
    }

    /// Round-off of one propagation: a few ulps of the state.
    pub fn local_error(&self) -> f64 {
        8.0 * f64::EPSILON * self.y1.iter().fold(1.0, |m: f64, x| m.max(x.abs()))
    }

    /// The state at the end of the step.
    pub fn end(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.y1);
    }
}
