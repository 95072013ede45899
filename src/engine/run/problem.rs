//! A run said in three parts: the [`Problem`] (a model, where it starts,
//! how long it runs), the [`Method`] that solves it, and the [`Limits`] it
//! runs under (an event budget, a wall-time budget, a stop flag). [`Options`]
//! holds all three at once for [`simulate`]; a problem builds it.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::engine::model::{HybridModel, Mode};
use crate::engine::run::observer::Observer;
use crate::engine::run::simulation::simulate;
use crate::engine::run::{Options, Outcome};
use crate::engine::step::adaptive::Tolerances;
use crate::engine::step::method::Method;

/// A model, the mode and state it starts in at `t = 0`, and the time it
/// runs to.
#[derive(Debug, Clone)]
pub struct Problem<'m, M: HybridModel + ?Sized> {
    /// The model.
    pub model: &'m M,
    /// The mode at `t = 0`.
    pub mode: Mode,
    /// The state at `t = 0`.
    pub state: Vec<f64>,
    /// The time the run ends at.
    pub t_end: f64,
}

/// What may end a run besides reaching `t_end`.
#[derive(Debug, Clone)]
pub struct Limits {
    /// The run fails once it would log more events than this.
    pub max_events: u64,
    /// The run fails after this much wall time (seconds), if set.
    pub max_wall_seconds: Option<f64>,
    /// Set from outside (a signal handler) to interrupt the run cleanly.
    pub stop: Option<Arc<AtomicBool>>,
    /// Go on past the horizon as a pseudo-orbit instead of stopping there
    /// ([`Options::past_horizon`]).
    pub past_horizon: bool,
}

impl Default for Limits {
    /// 10^9 events, no wall-time budget, no stop flag.
    fn default() -> Self {
        Limits {
            max_events: 1_000_000_000,
            max_wall_seconds: None,
            stop: None,
            past_horizon: false,
        }
    }
}

impl<'m, M: HybridModel + ?Sized> Problem<'m, M> {
    /// `model` from `state` in `mode` at `t = 0` to `t_end`.
    pub fn new(model: &'m M, mode: Mode, state: &[f64], t_end: f64) -> Self {
        Problem {
            model,
            mode,
            state: state.to_vec(),
            t_end,
        }
    }

    /// The [`Options`] of solving it by `method` under `limits`.
    pub fn options(&self, method: Method, limits: &Limits) -> Options {
        Options {
            t_end: self.t_end,
            max_events: limits.max_events,
            method,
            // What `Auto` takes where a mode has only an ODE: the method's
            // own tolerances where it names them.
            tolerances: match method {
                Method::Dopri5(t) | Method::Dop853(t) | Method::Taylor(t) => t,
                _ => Tolerances::default(),
            },
            stop: limits.stop.clone(),
            max_wall_seconds: limits.max_wall_seconds,
            past_horizon: limits.past_horizon,
        }
    }

    /// Solve it by `method` under `limits`, events to `observer`.
    pub fn solve<O: Observer + ?Sized>(
        &self,
        method: Method,
        limits: &Limits,
        observer: &mut O,
    ) -> Outcome {
        simulate(
            self.model,
            self.mode,
            &self.state,
            &self.options(method, limits),
            observer,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::model::names::Name;
    use crate::engine::model::{Direction, Flow, Guard, Jump};
    use crate::names;

    /// `x' = -x`, its closed form, and a marker where `x` falls through
    /// `1/2`.
    struct Decay;

    const HALF: &[Guard] = &[Guard::affine("half", Direction::Falling).as_crossing()];

    impl HybridModel for Decay {
        fn dimension(&self) -> usize {
            1
        }
        fn state_names(&self, _: Mode) -> &[Name] {
            names!["x"]
        }
        fn mode_name(&self, _: Mode) -> &str {
            "decay"
        }
        fn guards(&self, _: Mode) -> &[Guard] {
            HALF
        }
        fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
            x[0] - 0.5
        }
        fn flow(&self, _: Mode) -> Flow {
            Flow::Ode
        }
        fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
            dx[0] = -x[0];
        }
        fn reset(&self, mode: Mode, _: usize, _: &mut [f64]) -> Jump {
            Jump::to(mode)
        }
    }

    #[test]
    fn a_problem_is_solved_by_the_method_it_is_given() {
        let problem = Problem::new(&Decay, 0, &[1.0], 2.0);
        let tight = Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
        };
        for method in [Method::Dopri5(tight), Method::Dop853(tight)] {
            let outcome = problem.solve(method, &Limits::default(), &mut ());
            assert_eq!(outcome.events, 1);
            assert!((outcome.final_state[0] - (-2.0_f64).exp()).abs() < 1e-10);
        }
        // The limits are the run's: one event allowed, none.
        let none = Limits {
            max_events: 0,
            ..Limits::default()
        };
        let outcome = problem.solve(Method::Dopri5(tight), &none, &mut ());
        assert_eq!(outcome.status, crate::engine::Status::Failed);
    }
}
