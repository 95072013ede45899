//! How to run a model and what a run did: the [`Options`] every run loop
//! takes and the [`Outcome`] it returns, whichever source of segments
//! (whole-state or event-local) drove it.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::engine::bound::ErrorEstimate;
use crate::engine::model::Mode;
use crate::engine::model::names::Name;
use crate::engine::step::adaptive::Tolerances;
use crate::engine::step::method::Method;

/// How to run a model.
#[derive(Debug, Clone)]
pub struct Options {
    /// Simulated time to stop at (the run starts at 0).
    pub t_end: f64,
    /// Stop with `failed` after this many events (guards against runs that
    /// would take forever without being Zeno).
    pub max_events: u64,
    /// How to advance the flows ([`Method::Auto`]: each mode's cheapest
    /// exact description).
    pub method: Method,
    /// Tolerances of Dormand-Prince where [`Method::Auto`] needs it (modes
    /// whose only flow is an ODE).
    pub tolerances: Tolerances,
    /// Set from outside (a signal handler) to stop the run cleanly.
    pub stop: Option<Arc<AtomicBool>>,
    /// Stop with `failed` after this much wall time (seconds), if set.
    pub max_wall_seconds: Option<f64>,
    /// Go on past the run's horizon as a pseudo-orbit, carrying no bound
    /// from there and flagging its events `shadow`, instead of stopping
    /// where the bound can no longer decide what happens (see
    /// [`horizon`](crate::engine::bound::horizon)).
    pub past_horizon: bool,
}

impl Options {
    /// Run to `t_end` with a budget of 10^9 events and default tolerances.
    pub fn until(t_end: f64) -> Self {
        Options {
            t_end,
            max_events: 1_000_000_000,
            method: Method::Auto,
            tolerances: Tolerances::default(),
            stop: None,
            max_wall_seconds: None,
            past_horizon: false,
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Reached `t_end`.
    Completed,
    /// A Zeno accumulation was recognised (see [`Outcome::reason`]); the run
    /// either settled into resting contact and went on, or stopped there.
    Zeno,
    /// A method failed; the result cannot be trusted past `t_reached`.
    Failed,
    /// Stopped from outside.
    Interrupted,
}

impl Status {
    /// The status as the summary writes it: `completed`, `zeno`, `failed` or
    /// `interrupted`.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Completed => "completed",
            Status::Zeno => "zeno",
            Status::Failed => "failed",
            Status::Interrupted => "interrupted",
        }
    }
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// How the run ended.
    pub status: Status,
    /// Why the run is not plainly `completed` (or, for a run a terminal
    /// transition ended before `t_end`, which one).
    pub reason: Option<String>,
    /// The simulated time the run was asked to reach.
    pub t_end: f64,
    /// The simulated time it reached: `t_end` unless it stopped early.
    pub t_reached: f64,
    /// Non-internal events (impacts and other resets).
    pub events: u64,
    /// Events per guard name; Zeno settlings under
    /// [`SETTLE`](crate::engine::run::observer::SETTLE).
    pub events_by_guard: BTreeMap<Name, u64>,
    /// Whether a Zeno accumulation was recognised, whether the run then
    /// settled and went on or stopped there.
    pub zeno: bool,
    /// The model's energy at the start, if it has one.
    pub energy_initial: Option<f64>,
    /// The model's energy at the end, if it has one.
    pub energy_final: Option<f64>,
    /// Largest `|E - E(0)| / scale` seen at any event and at the end
    /// (`E(0)` moved by each reset's change where resets may change the
    /// energy).
    pub max_energy_error: Option<f64>,
    /// The mode the run ended in.
    pub final_mode: Mode,
    /// That mode's name.
    pub final_mode_name: Name,
    /// Names of the components of `final_state`.
    pub final_state_names: Vec<Name>,
    /// The state at `t_reached`.
    pub final_state: Vec<f64>,
    /// Evaluations of the flow: right-hand sides and propagators of
    /// numerical methods, flow maps and crossing times of exact ones.
    pub flow_evaluations: u64,
    /// The largest error any state component may carry at the end: the
    /// numerical steps' local errors carried through the flow and across
    /// every event (see [`bound`](crate::engine::bound)), plus a round-off allowance of
    /// [`ROUNDOFF_ULPS`](crate::engine::bound::ROUNDOFF_ULPS) ulps of the state's size (or the model's rounding scale) per event.
    /// `None` where no bound is carried (above
    /// [`CARRIED`](crate::engine::bound::error_set::CARRIED) state components):
    /// [`Outcome::error_estimate`] says what is known instead.
    pub error_bound: Option<f64>,
    /// Where no bound is carried, what stands in for it and how it was
    /// made; `None` where `error_bound` is stated.
    pub error_estimate: Option<ErrorEstimate>,
    /// The largest error any event time may carry: each event's share of
    /// the state error divided by its closing speed, plus a round-off
    /// allowance of [`ROUNDOFF_ULPS`](crate::engine::bound::ROUNDOFF_ULPS) ulps of the time reached; `None`
    /// where the errors are not tracked.
    pub event_time_bound: Option<f64>,
    /// Where the run's own error first reached 1e-3 of its state's scale,
    /// or its bound could no longer decide what happens, whichever came
    /// first (see [`horizon`](crate::engine::bound::horizon)); `None` if neither
    /// happened.
    pub horizon: Option<f64>,
    /// Events logged past the horizon by a run that went on past it
    /// ([`Options::past_horizon`], or an event-local model that always
    /// does), each flagged `shadow`.
    pub shadow_events: u64,
    /// Whole periods of an exactly periodic orbit the run jumped over
    /// instead of firing their events (see
    /// [`periodic`](crate::engine::run::periodic)); `None` where it fired
    /// every event.
    pub fast_forward: Option<FastForward>,
    /// Wall time the run took, in seconds.
    pub wall_seconds: f64,
}

/// The periods a run jumped over, summed over its jumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FastForward {
    /// Whole periods jumped over (their events counted as if fired).
    pub periods: u64,
    /// The events each period of the last jump held.
    pub events_per_period: u64,
    /// The period of the last jump.
    pub period: f64,
    /// Where the first jump started and the last ended.
    pub from: f64,
    /// See `from`.
    pub to: f64,
}
