//! What the adaptive Runge-Kutta pairs share: tolerances, why a step
//! fails, the starting step and the step-size factor.

use crate::engine::model::{HybridModel, Mode};

/// Relative and absolute error tolerances of an adaptive step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
}

impl Default for Tolerances {
    /// Tight enough that the angle formulation agrees with the exact strain
    /// flow to about 1e-9 over a hundred impacts.
    fn default() -> Self {
        Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
        }
    }
}

impl Tolerances {
    /// The error a component of size `y` may carry.
    pub fn scale(&self, y: f64) -> f64 {
        self.atol + self.rtol * y.abs()
    }
}

/// Why a step could not be taken.
#[derive(Debug, Clone, PartialEq)]
pub enum StepFailure {
    /// The error control asked for a step below `h_min`: the solution is
    /// (nearly) singular here.
    Collapsed { h: f64 },
    /// The right-hand side returned a non-finite value.
    NonFinite,
    /// The method cannot integrate this mode (said why).
    NotApplicable(String),
}

/// Hairer's starting step for a pair whose error estimate is of order
/// `order` in the step size (5 for Dormand-Prince, 8 for DOP853): the size at which
/// an Euler step's change and its second-derivative estimate both stay
/// within tolerance. `f0` holds `f(y0)`; `y` and `f1` are scratch.
#[allow(clippy::too_many_arguments)]
pub fn initial_step<M: HybridModel + ?Sized>(
    model: &M,
    mode: Mode,
    tol: Tolerances,
    order: i32,
    y0: &[f64],
    f0: &[f64],
    y: &mut [f64],
    f1: &mut [f64],
    h_max: f64,
) -> f64 {
    let n = y0.len() as f64;
    let norm =
        |v: &dyn Fn(usize) -> f64| ((0..y0.len()).map(|i| v(i).powi(2)).sum::<f64>() / n).sqrt();
    let d0 = norm(&|i| y0[i] / tol.scale(y0[i]));
    let d1 = norm(&|i| f0[i] / tol.scale(y0[i]));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    }
    .min(h_max);
    for i in 0..y0.len() {
        y[i] = y0[i] + h0 * f0[i];
    }
    model.rhs(mode, y, f1);
    let d2 = norm(&|i| (f1[i] - f0[i]) / tol.scale(y0[i])) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / f64::from(order))
    };
    (100.0 * h0).min(h1).min(h_max)
}

/// `err^(-1/order)`, the step-size factor for an error estimate of that order.
/// Step control needs two digits, not sixteen: single precision halves its
/// cost, which matters when the right-hand side is cheap.
pub fn shrink(err: f64, order: i32) -> f64 {
    f64::from((err as f32).powf(-1.0 / order as f32))
}
