//! Stormer-Verlet (velocity form): the symplectic, second-order, fixed-step
//! method, with cubic Hermite dense output.
//!
//! The state is `[q; v]` with `q' = v` and `v' = a(q)` (declared by
//! [`HybridModel::second_order`]). One step costs one evaluation of `a`
//! (the last one is reused). Energy errors stay bounded instead of drifting,
//! which is what a symplectic method buys. Between the step's ends, `q` and
//! `v` are cubic Hermite interpolants of their values and rates, so affine
//! guards are cubics along the step and event location keeps its guarantee.
//!
//! [`HybridModel::second_order`]: crate::engine::HybridModel::second_order

use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::adaptive::StepFailure;

/// Stormer-Verlet's working state: the fixed step and the current step's
/// ends.
#[derive(Debug, Clone)]
pub struct Verlet {
    /// The fixed step; the last step before the end of the run is shorter.
    step: f64,
    /// The length of the last step taken.
    h: f64,
    y0: Vec<f64>,
    y1: Vec<f64>,
    /// `f` at the start and end of the step (`[v; a]`).
    f0: Vec<f64>,
    f1: Vec<f64>,
    fsal: bool,
    /// Right-hand-side evaluations so far.
    pub evaluations: u64,
}

impl Verlet {
    /// A method of fixed step `h` for states of length `dimension`.
    pub fn new(dimension: usize, h: f64) -> Self {
        let v = || vec![0.0; dimension];
        Verlet {
            step: h,
            h: 0.0,
            y0: v(),
            y1: v(),
            f0: v(),
            f1: v(),
            fsal: false,
            evaluations: 0,
        }
    }

    /// Forget the previous step: the next one starts from a state that was
    /// not this method's last output (after a reset).
    pub fn restart(&mut self) {
        self.fsal = false;
    }

    /// The length of the last step taken.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// One step from `y0` in `mode`: the fixed step, or `h_max` if that is
    /// shorter; fails if the fixed step is below `h_min` or the state stops
    /// being finite.
    pub fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
    ) -> Result<(), StepFailure> {
        let m = y0.len() / 2;
        if self.fsal {
            std::mem::swap(&mut self.f0, &mut self.f1);
        } else {
            model.rhs(mode, y0, &mut self.f0);
            self.evaluations += 1;
        }
        if self.step < h_min {
            return Err(StepFailure::Collapsed { h: self.step });
        }
        let h = self.step.min(h_max);
        self.y0.copy_from_slice(y0);
        for i in 0..m {
            let v_half = y0[m + i] + 0.5 * h * self.f0[m + i];
            self.y1[i] = y0[i] + h * v_half;
            self.y1[m + i] = v_half;
        }
        model.rhs(mode, &self.y1, &mut self.f1);
        self.evaluations += 1;
        for i in 0..m {
            self.y1[m + i] += 0.5 * h * self.f1[m + i];
            self.f1[i] = self.y1[m + i];
        }
        if self.y1.iter().chain(&self.f1).any(|x| !x.is_finite()) {
            return Err(StepFailure::NonFinite);
        }
        self.h = h;
        self.fsal = true;
        Ok(())
    }

    /// Cubic Hermite interpolation of each component from its values and
    /// rates at the step's ends.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        let h = self.h;
        let s = tau / h;
        // h00 = 1 - h01: written from y0 and the change over the step, a
        // component that does not move reads exactly its value.
        let (h10, h01, h11) = (
            s * (1.0 - s).powi(2),
            s * s * (3.0 - 2.0 * s),
            s * s * (s - 1.0),
        );
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = self.y0[i]
                + h01 * (self.y1[i] - self.y0[i])
                + h * (h10 * self.f0[i] + h11 * self.f1[i]);
        }
    }

    /// An estimate of the last step's local error, `h^2 |a1 - a0| / 3`:
    /// twice the method's leading term, `h^3 |a'| / 6` in the position
    /// (about `h^2 |a1 - a0| / 6`), since the run's error bound takes it as
    /// a bound; the embedded pairs' estimates have that margin built in
    /// (they measure their lower order).
    pub fn local_error(&self) -> f64 {
        let m = self.y0.len() / 2;
        let change = (m..2 * m)
            .map(|i| (self.f1[i] - self.f0[i]).abs())
            .fold(0.0, f64::max);
        self.h * self.h * change / 3.0
    }

    /// The state at the end of the step, exactly as the method computed it.
    pub fn end(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.y1);
    }
}
