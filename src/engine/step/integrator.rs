//! The numerical methods behind one interface, and which one a mode gets.
//!
//! The event loop asks an [`Integrator`] for one step and for states inside
//! it; it never asks which method is inside. [`Method`] is the user's choice
//! (`src/engine/step/method.rs`); [`Motion`] is what it means for one mode: the
//! model's exact flow, a frozen state, or steps of the chosen integrator.

use crate::engine::bound::tangent::Rates;
use crate::engine::model::{Flow, HybridModel, Mode};
use crate::engine::step::adaptive::{EmbeddedPair, StepFailure, Tolerances};
use crate::engine::step::crossing::{Crossing, Sharpened};
use crate::engine::step::dop853::Dop853;
use crate::engine::step::dopri5::Dopri5;
use crate::engine::step::linear::Linear;
use crate::engine::step::locate::{Interpolant, Start, StepScan};
use crate::engine::step::method::Method;
use crate::engine::step::sharpen::{dense_error, sharpen};
use crate::engine::step::taylor_method::Taylor;
use crate::engine::step::verlet::Verlet;

/// How one mode moves under a method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// The model's exact flow map and crossing times.
    Exact,
    /// The state does not move.
    Frozen,
    /// Steps of the run's integrator, events located on its dense output.
    Stepped,
}

/// Decide how `mode` moves under `method`, or say why it cannot.
pub fn motion<M: HybridModel + ?Sized>(
    model: &M,
    mode: Mode,
    method: Method,
) -> Result<Motion, String> {
    let name = model.mode_name(mode);
    match (model.flow(mode), method) {
        (_, Method::FiniteVolume) => Err(
            "finite volumes are the homogenized continuum's own solver; no other model runs by them"
                .into(),
        ),
        (Flow::Frozen, _) => Ok(Motion::Frozen),
        (Flow::Exact, Method::Auto | Method::Exact) => Ok(Motion::Exact),
        (Flow::Ode, Method::Auto) => Ok(Motion::Stepped),
        (Flow::Ode, Method::Exact) => Err(format!(
            "mode `{name}` has no exact flow; choose a numerical method"
        )),
        (_, Method::Linear) if !model.has_affine_flow(mode) => Err(format!(
            "mode `{name}` is not a linear flow x' = A x + b (plus sines of t), so the linear propagator cannot run it"
        )),
        (_, Method::Dopri5(_) | Method::Dop853(_) | Method::Verlet { .. })
            if !model.has_rhs(mode) =>
        {
            Err(format!(
                "mode `{name}` gives no right-hand side to integrate"
            ))
        }
        (_, Method::Taylor(_)) if !model.has_series(mode) => Err(format!(
            "mode `{name}` gives no Taylor series of its flow and guards (expressions compiled from a file do, \
             unless they use abs, min or max)"
        )),
        (_, Method::Verlet { .. }) if !model.second_order(mode) => Err(match model.clock() {
            Some(_) => format!(
                "mode `{name}` reads the time t (a forced flow), and Stormer-Verlet integrates only an autonomous q'' = a(q)"
            ),
            None => format!(
                "mode `{name}` is not of the form q'' = a(q), which Stormer-Verlet needs: positions q then \
                 velocities v, with q' = v and v' independent of v"
            ),
        }),
        _ => Ok(Motion::Stepped),
    }
}

/// Whether `method` can run every one of `modes` of `model`, by [`motion`]'s
/// rules; the first refusal's reason otherwise.
pub fn runs<M: HybridModel + ?Sized>(
    model: &M,
    modes: &[Mode],
    method: Method,
) -> Result<(), String> {
    modes
        .iter()
        .try_for_each(|&mode| motion(model, mode, method).map(|_| ()))
}

/// The names of the methods a user can choose that run every one of
/// `modes` of `model` ([`runs`]), in the order exact, linear, taylor,
/// dopri5, dop853, verlet: the one place that says which methods a model
/// takes.
pub fn methods_for<M: HybridModel + ?Sized>(model: &M, modes: &[Mode]) -> Vec<&'static str> {
    // Tolerances and steps never decide whether a method applies.
    let tol = Tolerances::default();
    [
        Method::Exact,
        Method::Linear,
        Method::Taylor(tol),
        Method::Dopri5(tol),
        Method::Dop853(tol),
        Method::Verlet { step: 1.0 },
    ]
    .into_iter()
    .filter(|&method| runs(model, modes, method).is_ok())
    .map(|method| method.name())
    .collect()
}

/// One numerical method's working state. One lives per run, so the size of
/// the largest variant does not matter.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum Integrator {
    /// Dormand-Prince 5(4).
    Dopri5(Dopri5),
    /// Dormand and Prince's DOP853.
    Dop853(Dop853),
    /// Stormer-Verlet.
    Verlet(Verlet),
    /// The exact propagator of linear flows.
    Linear(Linear),
    /// Taylor's method.
    Taylor(Taylor),
}

impl Integrator {
    /// The integrator `method` steps with (Dormand-Prince for `Auto` and
    /// `Exact`, whose non-exact modes need one).
    pub fn for_method(method: Method, dimension: usize, tolerances: Tolerances) -> Self {
        match method {
            Method::Verlet { step } => Integrator::Verlet(Verlet::new(dimension, step)),
            Method::Linear => Integrator::Linear(Linear::new(dimension)),
            Method::Dopri5(tol) => Integrator::Dopri5(Dopri5::new(dimension, tol)),
            Method::Dop853(tol) => Integrator::Dop853(Dop853::new(dimension, tol)),
            Method::Taylor(tol) => Integrator::Taylor(Taylor::new(dimension, tol)),
            Method::Auto | Method::Exact | Method::FiniteVolume => {
                Integrator::Dopri5(Dopri5::new(dimension, tolerances))
            }
        }
    }

    /// Measure the local error on the first `bounded` components only
    /// ([`HybridModel::bounded_dimension`]).
    pub fn bound_first(&mut self, bounded: usize) {
        match self {
            Integrator::Dopri5(m) => m.parts().0.bounded = bounded,
            Integrator::Dop853(m) => m.parts().0.bounded = bounded,
            Integrator::Linear(_) | Integrator::Verlet(_) | Integrator::Taylor(_) => {}
        }
    }

    /// The method's name, for messages.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Dopri5(_) => "Dormand-Prince",
            Integrator::Dop853(_) => "DOP853",
            Integrator::Verlet(_) => "Stormer-Verlet",
            Integrator::Linear(_) => "linear propagator",
            Integrator::Taylor(_) => "Taylor's method",
        }
    }

    /// Whether each step depends only on the state it starts from (and the
    /// run's settings), unless the run's end cuts it short: Taylor's method
    /// chooses its step from the series there, and the linear propagator
    /// steps a fixed length. The adaptive
    /// pairs carry their step size over from the step before, and
    /// Stormer-Verlet's dense output is scanned without the margins a
    /// replayed bound checks (see [`crate::engine::run::periodic`]).
    pub fn memoryless(&self) -> bool {
        matches!(self, Integrator::Linear(_) | Integrator::Taylor(_))
    }

    /// Forget the last step (the next starts from a reset state).
    pub fn restart(&mut self) {
        match self {
            Integrator::Dopri5(m) => m.restart(),
            Integrator::Dop853(m) => m.restart(),
            Integrator::Verlet(m) => m.restart(),
            Integrator::Linear(m) => m.restart(),
            Integrator::Taylor(m) => m.restart(),
        }
    }

    /// Take one step from `y0`, at most `h_max` long.
    pub fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
    ) -> Result<(), StepFailure> {
        match self {
            Integrator::Dopri5(m) => m.step(model, mode, y0, h_max, h_min),
            Integrator::Dop853(m) => m.step(model, mode, y0, h_max, h_min),
            Integrator::Verlet(m) => m.step(model, mode, y0, h_max, h_min),
            Integrator::Linear(m) => m.step(model, mode, y0, h_max, h_min),
            Integrator::Taylor(m) => m.step(model, mode, y0, h_max, h_min),
        }
    }

    /// The next step starts where the clock (component `clock`) reads the
    /// run's time less `rounding`: the linear propagator starts from the
    /// exact time (see [`Linear::clock_at`]); the others read the clock as
    /// it is.
    pub fn clock_at(&mut self, clock: usize, rounding: f64) {
        if let Integrator::Linear(m) = self {
            m.clock_at(clock, rounding);
        }
    }

    /// Length of the last step.
    pub fn h(&self) -> f64 {
        match self {
            Integrator::Dopri5(m) => m.dense().h,
            Integrator::Dop853(m) => m.dense().h,
            Integrator::Verlet(m) => m.h(),
            Integrator::Linear(m) => m.h(),
            Integrator::Taylor(m) => m.h(),
        }
    }

    /// The state `tau` into the last step.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        match self {
            Integrator::Dopri5(m) => m.dense().eval(tau, x),
            Integrator::Dop853(m) => m.dense().eval(tau, x),
            Integrator::Verlet(m) => m.eval(tau, x),
            Integrator::Linear(m) => m.eval(tau, x),
            Integrator::Taylor(m) => m.eval(tau, x),
        }
    }

    /// The state at `tau` into the last step, to working precision: what
    /// a linearisation of the step samples (Taylor's series summed without
    /// compensation; the other methods' dense output as [`Integrator::eval`]).
    pub fn sample(&self, tau: f64, x: &mut [f64]) {
        match self {
            Integrator::Taylor(m) => m.sample(tau, x),
            _ => self.eval(tau, x),
        }
    }

    /// The flow at the start and at the end of a stretch `tau` from
    /// `offset` into the last step, where the method knows both without
    /// evaluating it: a whole step (Taylor's, checked against the flow at
    /// its end; a Dormand-Prince pair's first and last stages).
    pub fn rates(&self, offset: f64, tau: f64) -> Rates<'_> {
        let whole = offset == 0.0 && tau == self.h();
        match self {
            Integrator::Taylor(m) => m.rates(offset, tau),
            Integrator::Dopri5(m) => whole.then(|| m.rates()),
            Integrator::Dop853(m) => whole.then(|| m.rates()),
            _ => None,
        }
    }

    /// The state at the end of the last step.
    pub fn end(&self, x: &mut [f64]) {
        match self {
            Integrator::Dopri5(m) => m.dense().end(x),
            Integrator::Dop853(m) => m.dense().end(x),
            Integrator::Verlet(m) => m.end(x),
            Integrator::Linear(m) => m.end(x),
            Integrator::Taylor(m) => m.end(x),
        }
    }

    /// What kind of function of the step time the dense output is.
    pub fn interpolant(&self) -> Interpolant {
        match self {
            Integrator::Dopri5(_) => Interpolant::Polynomial { degree: 4 },
            Integrator::Dop853(_) => Interpolant::Polynomial { degree: 7 },
            Integrator::Verlet(_) => Interpolant::Polynomial { degree: 3 },
            Integrator::Linear(_) | Integrator::Taylor(_) => Interpolant::Other,
        }
    }

    /// Where the method locates a guard's crossing itself, on its own
    /// series (Taylor's method, see [`Taylor::locate`]; the linear
    /// propagator where the model gives its guards' series): the scan of
    /// the last step for `guard`, from `offset` into it (a marker that let
    /// the step go on: Taylor's method only); `None` where the dense output
    /// is to be scanned, or the step cannot be searched from inside.
    pub fn locate<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        guard: usize,
        start: Start,
        uncertainty: f64,
        offset: f64,
    ) -> Option<Result<StepScan, String>> {
        match self {
            Integrator::Taylor(m) => Some(m.locate(model, mode, guard, start, uncertainty, offset)),
            Integrator::Linear(m) if offset == 0.0 => {
                m.locate(model, mode, guard, start, uncertainty)
            }
            _ => None,
        }
    }

    /// Whether [`Integrator::locate`] can search the last step from inside
    /// it (Taylor's method: a marker that fired there lets the step go on).
    pub fn locates_inside(&self) -> bool {
        matches!(self, Integrator::Taylor(_))
    }

    /// The correction to a crossing at `tau` into the last step where the
    /// method's dense output is less accurate than its steps (the
    /// Runge-Kutta pairs, see `src/engine/step/sharpen.rs`), or where the method knows the state at the
    /// crossing to well below an ulp (the linear propagator: an affine
    /// guard's zero to double-double, see [`Linear::sharpen`]); `None` for
    /// the others and where sharpening declines, leaving the crossing as
    /// it was.
    pub fn sharpen<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        crossing: &Crossing,
        x: &mut [f64],
    ) -> Sharpened {
        match self {
            Integrator::Dopri5(m) => sharpen(m, model, mode, y0, crossing, x),
            Integrator::Dop853(m) => sharpen(m, model, mode, y0, crossing, x),
            Integrator::Linear(m) => m
                .sharpen(crossing, x)
                .map_or(Sharpened::Kept(0.0), Sharpened::Moved),
            _ => Sharpened::Kept(0.0),
        }
    }

    /// How far the dense output `tau` into the last step (from `y0`, its
    /// start) may be from the solution, where it is not the step itself:
    /// for the Runge-Kutta pairs, measured by re-taking the step to `tau`
    /// on `spare` (a copy of this integrator, made here when first needed,
    /// whose working state it spends; see `src/engine/step/sharpen.rs`); `None` for the methods whose dense
    /// output is their step (a Taylor series, the propagator) or has no
    /// such check (Stormer-Verlet).
    pub fn dense_error<M: HybridModel + ?Sized>(
        &self,
        spare: &mut Option<Box<Integrator>>,
        model: &M,
        mode: Mode,
        at: (&[f64], f64),
        x: &mut [f64],
    ) -> Option<f64> {
        if !matches!(self, Integrator::Dopri5(_) | Integrator::Dop853(_)) {
            return None;
        }
        let spare = spare.get_or_insert_with(|| Box::new(self.clone()));
        match (self, &mut **spare) {
            (Integrator::Dopri5(m), Integrator::Dopri5(s)) => {
                Some(dense_error(m, s, model, mode, at, x))
            }
            (Integrator::Dop853(m), Integrator::Dop853(s)) => {
                Some(dense_error(m, s, model, mode, at, x))
            }
            _ => None,
        }
    }

    /// Where a step of `h` reads the clock at the run's exact time (the
    /// linear propagator: see [`Linear::clock_at`]), so that a forcing
    /// read through it is not shifted by the clock's rounding: what the
    /// forcing's values' own rounding leaves instead. `None` for the
    /// others, whose forcing sees the clock's reading.
    pub fn exact_clock_error(&self, h: f64) -> Option<f64> {
        match self {
            Integrator::Linear(m) => Some(m.forcing_error(h)),
            _ => None,
        }
    }

    /// An estimate of the last step's local error (largest component).
    pub fn local_error(&self) -> f64 {
        match self {
            Integrator::Dopri5(m) => m.local_error(),
            Integrator::Dop853(m) => m.local_error(),
            Integrator::Verlet(m) => m.local_error(),
            Integrator::Linear(m) => m.local_error(),
            Integrator::Taylor(m) => m.local_error(),
        }
    }

    /// Right-hand-side or propagator evaluations so far.
    pub fn evaluations(&self) -> u64 {
        match self {
            Integrator::Dopri5(m) => m.evaluations(),
            Integrator::Dop853(m) => m.evaluations(),
            Integrator::Verlet(m) => m.evaluations,
            Integrator::Linear(m) => m.evaluations(),
            Integrator::Taylor(m) => m.evaluations(),
        }
    }
}
