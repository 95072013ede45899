//! What the adaptive Runge-Kutta pairs share: tolerances, why a step
//! fails, and the step-size control (starting step, acceptance, growth).
//! A pair supplies its stages, error estimate and dense output
//! ([`EmbeddedPair`]); the loop of trials, [`EmbeddedPair::step`], is the
//! same for every pair.

use crate::engine::model::{HybridModel, Mode};

/// Relative and absolute error tolerances of an adaptive step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance: the error allowed per unit of a component's size.
    pub rtol: f64,
    /// Absolute tolerance: the error allowed a component of size zero.
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
    Collapsed {
        /// The step size asked for.
        h: f64,
    },
    /// A guard's series converges over no step above `h_min` (Taylor's
    /// method): the guard turns steep here (a square root at zero).
    GuardCollapsed {
        /// The step size the guard allows.
        h: f64,
        /// The guard.
        guard: usize,
    },
    /// The right-hand side returned a non-finite value.
    NonFinite,
    /// The method cannot integrate this mode (said why).
    NotApplicable(String),
}

/// An embedded Runge-Kutta pair: its stages and trial steps; the step
/// loop, restarts and counts are shared.
pub trait EmbeddedPair {
    /// The step control, the stages (the first holds `f` at a step's
    /// start) and a scratch state.
    fn parts(&mut self) -> (&mut StepControl, &mut [Vec<f64>], &mut [f64]);

    /// The step control, to read.
    fn control(&self) -> &StepControl;

    /// The last accepted step's dense output at `tau` into it.
    fn dense_eval(&self, tau: f64, x: &mut [f64]);

    /// The last accepted step's size.
    fn dense_h(&self) -> f64;

    /// Where a trial step leaves its end state.
    fn trial_end(&mut self) -> &mut Vec<f64>;

    /// One trial step of size `h` from `y0`, and its error.
    fn attempt<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h: f64,
    ) -> TrialError;

    /// Keep the accepted trial of size `h`: its dense output, and `f` at
    /// its end for the next step.
    fn finish<M: HybridModel + ?Sized>(&mut self, model: &M, mode: Mode, y0: &[f64], h: f64);

    /// Take one accepted step from `y0`, no longer than `h_max`.
    fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
    ) -> Result<(), StepFailure> {
        let (control, stages, scratch) = self.parts();
        let mut h = control.begin(model, mode, y0, h_max, h_min, stages, scratch)?;
        loop {
            let error = self.attempt(model, mode, y0, h);
            match self.parts().0.judge(h, error, h_min)? {
                Some(next) => h = next,
                None => {
                    self.finish(model, mode, y0, h);
                    return Ok(());
                }
            }
        }
    }

    /// Forget the previous step: the next one starts from a state that was
    /// not this pair's last output (after a reset).
    fn restart(&mut self) {
        self.parts().0.fsal = false;
    }

    /// The error estimate of the last accepted step (largest component,
    /// absolute), doubled, as a bound on its local error: the estimate
    /// measures the pair's lower order, far above the propagated solution's
    /// error at tight tolerances, but at loose ones (long steps) the
    /// propagated solution and its dense output erred by up to 1.7 times it
    /// (a crest 1e-5 above a guard at rtol 1e-5, in
    /// `tests/flicker/event_location.rs`).
    fn local_error(&self) -> f64 {
        2.0 * self.control().local_error
    }

    /// Right-hand-side evaluations so far.
    fn evaluations(&self) -> u64 {
        self.control().evaluations
    }
}

/// The step-size memory and rules of an adaptive pair.
#[derive(Debug, Clone)]
pub struct StepControl {
    /// The tolerances trials are judged by.
    pub tol: Tolerances,
    /// Order of the pair's error estimate in the step size.
    order: i32,
    /// Largest factor a step grows by after an accepted trial, and smallest
    /// it shrinks by after a rejected one.
    growth: f64,
    shrinkage: f64,
    /// Whether the first stage holds `f` at the start of the next step
    /// (first same as last): false after a restart.
    pub fsal: bool,
    h_next: Option<f64>,
    /// Right-hand-side evaluations so far.
    pub evaluations: u64,
    /// Largest component of the error estimate of the last accepted step,
    /// over the first `bounded` components, or more where the estimate
    /// fell through (see [`StepControl::judge`]).
    pub local_error: f64,
    /// The last accepted step's error constant (its estimate over
    /// `h^order`) where that step was held to its tolerance (its scaled
    /// error at least [`MEANINGFUL`]), else zero.
    constant: f64,
    /// The components the local error is measured on (see
    /// [`HybridModel::bounded_dimension`]).
    pub bounded: usize,
}

/// The scaled error at which a step counts as held to its tolerance, so
/// that its estimate measures the method's error rather than rounding or
/// a step cut short by an event or `h_max`.
const MEANINGFUL: f64 = 1e-4;

/// A trial's error: the scaled norm step control uses (accepted at most 1,
/// non-finite when the trial blew up) and its largest component, absolute.
#[derive(Debug, Clone, Copy)]
pub struct TrialError {
    /// The scaled error norm: the trial is accepted if it is at most 1.
    pub norm: f64,
    /// The error's largest component, absolute.
    pub largest: f64,
    /// The largest error a component may have in a trial that is
    /// accepted: its tolerance, times the root of the dimension (the norm
    /// is a root mean square).
    pub allowed: f64,
}

impl StepControl {
    /// Step control for a pair whose error estimate is of order `order` in
    /// the step size: after an accepted trial a step grows by at most the
    /// factor `growth`, after a rejected one it shrinks by no factor smaller
    /// than `shrinkage`.
    pub fn new(tol: Tolerances, order: i32, growth: f64, shrinkage: f64) -> Self {
        StepControl {
            tol,
            order,
            growth,
            shrinkage,
            fsal: false,
            h_next: None,
            evaluations: 0,
            local_error: 0.0,
            constant: 0.0,
            bounded: usize::MAX,
        }
    }

    /// Start a step from `y0`: `f(y0)` into `stages[0]` unless the last
    /// step left it there, and the size of the first trial (the last
    /// step's successor, or Hairer's starting step after a restart).
    #[allow(clippy::too_many_arguments)]
    pub fn begin<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
        stages: &mut [Vec<f64>],
        scratch: &mut [f64],
    ) -> Result<f64, StepFailure> {
        if !self.fsal {
            model.rhs(mode, y0, &mut stages[0]);
            self.evaluations += 1;
            if stages[0].iter().any(|v| !v.is_finite()) {
                return Err(StepFailure::NonFinite);
            }
        }
        let h = match (self.fsal, self.h_next) {
            (true, Some(h)) => h,
            _ => {
                let (f0, rest) = stages.split_at_mut(1);
                self.evaluations += 1;
                self.initial_step(model, mode, y0, &f0[0], scratch, &mut rest[0], h_max)
            }
        };
        collapsed_below(h.min(h_max), h_min)
    }

    /// After a trial of size `h`: `None` if it is accepted (its error kept,
    /// the next step's size chosen), else the size to try instead.
    pub fn judge(
        &mut self,
        h: f64,
        error: TrialError,
        h_min: f64,
    ) -> Result<Option<f64>, StepFailure> {
        let err = error.norm;
        let next = if !err.is_finite() {
            0.1 * h
        } else if err <= 1.0 {
            let grow = (0.9 * self.shrink(err)).min(self.growth);
            self.h_next = Some(h * grow.max(1.0));
            // An estimate is a difference of two solutions, a few of the
            // flow's derivatives: where those pass through zero inside a
            // step (x' = sin t near t = pi/2, DOP853 at rtol 1e-7), it falls
            // far below the error, which the next derivative makes (3.5
            // times it there). The error constant of the step before,
            // where that step was held to its tolerance, stands in, up to
            // the most this step's tolerance allows: near a singular point
            // (the angle formulation's theta = 0) the constant of a short
            // step there, carried to a long one past it, is not this
            // step's error but thousands of times its tolerance.
            let scale = h.powi(self.order);
            let held = (self.constant * scale).min(error.allowed);
            self.local_error = error.largest.max(held);
            self.constant = if err >= MEANINGFUL && scale > 0.0 {
                error.largest / scale
            } else {
                0.0
            };
            return Ok(None);
        } else {
            h * (0.9 * self.shrink(err)).max(self.shrinkage)
        };
        collapsed_below(next, h_min).map(Some)
    }

    /// Hairer's starting step: the size at which an Euler step's change and
    /// its second-derivative estimate both stay within tolerance. `f0`
    /// holds `f(y0)`; `y` and `f1` are scratch.
    #[allow(clippy::too_many_arguments)]
    fn initial_step<M: HybridModel + ?Sized>(
        &self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        f0: &[f64],
        y: &mut [f64],
        f1: &mut [f64],
        h_max: f64,
    ) -> f64 {
        let tol = self.tol;
        let n = y0.len() as f64;
        let norm = |v: &dyn Fn(usize) -> f64| {
            ((0..y0.len()).map(|i| v(i).powi(2)).sum::<f64>() / n).sqrt()
        };
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
            (0.01 / d1.max(d2)).powf(1.0 / f64::from(self.order))
        };
        (100.0 * h0).min(h1).min(h_max)
    }

    /// `err^(-1/order)`, the step-size factor. Step control needs two
    /// digits, not sixteen: single precision halves its cost, which matters
    /// when the right-hand side is cheap.
    fn shrink(&self, err: f64) -> f64 {
        f64::from((err as f32).powf(-1.0 / self.order as f32))
    }
}

/// `h`, unless it is below `h_min`: the solution is (nearly) singular here.
fn collapsed_below(h: f64, h_min: f64) -> Result<f64, StepFailure> {
    if h < h_min {
        Err(StepFailure::Collapsed { h })
    } else {
        Ok(h)
    }
}
