//! A run said in three parts: the [`Problem`] (a model, where it starts,
//! how long it runs), the [`Method`] that solves it, and the [`Limits`] it
//! runs under (an event budget, a wall-time budget or deadline, a stop flag). [`Options`]
//! holds all three at once for [`simulate`]; a problem builds it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

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

/// What may end a run besides reaching `t_end`, set from outside the
/// model: by a program, a scene's front end, or a tool that runs many.
#[derive(Debug, Clone, Default)]
pub struct Limits {
    /// The run fails once it would log more events than this; unset, the
    /// run's own budget ([`MAX_EVENTS`] for a problem, a scene's
    /// `max_events`). Where both are set the tighter holds.
    pub max_events: Option<u64>,
    /// The run fails after this much wall time (seconds), if set.
    pub max_wall_seconds: Option<f64>,
    /// When the whole work under these limits must end (a tool's
    /// `--wall`): each run gets what is left of it, and a tool that runs
    /// many begins none past it.
    pub deadline: Option<Instant>,
    /// Set from outside (a signal handler) to interrupt the run cleanly.
    pub stop: Option<Arc<AtomicBool>>,
    /// Go on past the horizon as a pseudo-orbit instead of stopping there
    /// ([`Options::past_horizon`]).
    pub past_horizon: bool,
}

/// A problem's event budget unless its limits set one.
pub const MAX_EVENTS: u64 = 1_000_000_000;

impl Limits {
    /// Whether the stop flag is set or the deadline has passed: a tool
    /// that runs many scenes stops between them.
    pub fn stopped(&self) -> bool {
        self.interrupted() || self.past_deadline()
    }

    /// Whether the stop flag is set.
    pub fn interrupted(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// Whether the deadline has passed.
    pub fn past_deadline(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }

    /// Why the work stopped, in words, once [`stopped`](Limits::stopped).
    pub fn stop_reason(&self) -> &'static str {
        if self.interrupted() {
            "interrupted: the stop flag was set"
        } else {
            "stopped: past the wall-clock budget (--wall)"
        }
    }

    /// The [`Options`] of a run to `t_end` by `method` (with `tolerances`
    /// where `Auto` takes Dormand-Prince) whose own event budget is
    /// `max_events`, under these limits: the tighter budget, and the wall
    /// time left before the deadline where that is sooner.
    pub fn options(
        &self,
        t_end: f64,
        max_events: u64,
        method: Method,
        tolerances: Tolerances,
    ) -> Options {
        Options {
            t_end,
            max_events: self
                .max_events
                .map_or(max_events, |own| own.min(max_events)),
            method,
            tolerances,
            stop: self.stop.clone(),
            max_wall_seconds: match (self.max_wall_seconds, self.deadline) {
                (own, None) => own,
                (own, Some(d)) => {
                    let left = d.saturating_duration_since(Instant::now()).as_secs_f64();
                    Some(own.map_or(left, |own| own.min(left)))
                }
            },
            past_horizon: self.past_horizon,
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
        // What `Auto` takes where a mode has only an ODE: the method's own
        // tolerances where it names them.
        let tolerances = match method {
            Method::Dopri5(t) | Method::Dop853(t) | Method::Taylor(t) => t,
            _ => Tolerances::default(),
        };
        limits.options(self.t_end, MAX_EVENTS, method, tolerances)
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
            max_events: Some(0),
            ..Limits::default()
        };
        let outcome = problem.solve(Method::Dopri5(tight), &none, &mut ());
        assert_eq!(outcome.status, crate::engine::Status::Failed);
    }

    #[test]
    fn the_tighter_budget_holds_and_a_deadline_leaves_what_is_left() {
        let options =
            |limits: &Limits| limits.options(1.0, 10, Method::Exact, Tolerances::default());
        assert_eq!(options(&Limits::default()).max_events, 10);
        let with = |n| Limits {
            max_events: Some(n),
            ..Limits::default()
        };
        assert_eq!(options(&with(5)).max_events, 5);
        assert_eq!(options(&with(50)).max_events, 10);
        // A deadline already past leaves no wall time, and stops a tool.
        let past = Limits {
            max_wall_seconds: Some(60.0),
            deadline: Some(Instant::now()),
            ..Limits::default()
        };
        assert_eq!(options(&past).max_wall_seconds, Some(0.0));
        assert!(past.stopped() && !past.interrupted());
        // A deadline later than the run's own budget leaves the budget.
        let later = Limits {
            max_wall_seconds: Some(1.0),
            deadline: Instant::now().checked_add(std::time::Duration::from_secs(3600)),
            ..Limits::default()
        };
        assert_eq!(options(&later).max_wall_seconds, Some(1.0));
        assert!(!later.stopped());
    }
}
