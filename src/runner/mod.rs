//! Running a validated scene: build its model, pick its method, run it, and
//! describe the result in the scene's own terms.

pub mod ensemble;
mod fields;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::engine::{Method, Name, Options, Outcome, Tolerances};

pub use fields::{CLASSICAL_MAX_UNITS, Classical, FieldOutputs, Profile, TraceRow};

/// A finished run and what the summary needs to say about it.
#[derive(Debug, Clone)]
pub struct Report {
    /// What the engine reported: how the run ended, its events, its errors.
    pub outcome: Outcome,
    /// The method used (its [`Method::name`] is the summary's `method`).
    pub method: Method,
    /// A sentence saying which description of the model was used and why.
    pub description: String,
    /// The final state in the scene's physical variables.
    pub final_state: Vec<(Name, f64)>,
    /// What a model with extent adds: momentum, profiles, the trace.
    pub fields: Option<FieldOutputs>,
    /// The derivatives of the final state and of the last event's time
    /// along each direction asked for (`flicker run --sensitivities`), as
    /// the summary's `sensitivities` entry.
    pub sensitivities: Option<serde_json::Value>,
}

/// A run with its state sampled along the way: what pictures of any two
/// states are drawn from ([`SceneModel::sampled`]).
///
/// [`SceneModel::sampled`]: crate::scene::SceneModel::sampled
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// The names of the state's components.
    pub names: Vec<Name>,
    /// `(t, state)` at each sample time the run reached (the state before
    /// an event at the same time).
    pub samples: Vec<(f64, Vec<f64>)>,
    /// Each sample's error bound (see [`Sample::bound`]).
    ///
    /// [`Sample::bound`]: crate::engine::Sample::bound
    pub bounds: Vec<f64>,
    /// The run itself.
    pub report: Report,
}

impl Trajectory {
    /// The trajectory of a run `run` makes, handing each sample it takes
    /// to the callback it is given; `names` head the state's components.
    pub fn record<E>(
        names: Vec<Name>,
        run: impl FnOnce(&mut dyn FnMut(&crate::engine::Sample)) -> Result<Report, E>,
    ) -> Result<Trajectory, E> {
        let (mut samples, mut bounds) = (Vec::new(), Vec::new());
        let report = run(&mut |s| {
            samples.push((s.t, s.state.to_vec()));
            bounds.push(s.bound);
        })?;
        Ok(Trajectory {
            names,
            samples,
            bounds,
            report,
        })
    }
}

/// What may stop a run from outside the scene.
#[derive(Debug, Clone, Default)]
pub struct Control {
    /// Interrupts the run cleanly when set (a signal handler sets it).
    pub stop: Option<Arc<AtomicBool>>,
    /// Fails the run after this much wall time.
    pub max_wall_seconds: Option<f64>,
    /// When the whole work under this control must end (a tool's
    /// `--wall`): each run gets what is left of it, and a tool that runs
    /// many begins none past it.
    pub deadline: Option<std::time::Instant>,
    /// Runs go on past their horizon as pseudo-orbits (`--past-horizon`).
    pub past_horizon: bool,
}

/// The instant `seconds` (a wall-clock budget, `--wall`) from now, or
/// why `seconds` is not a budget.
pub fn deadline_in(seconds: f64) -> Result<Option<std::time::Instant>, String> {
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(format!("a time > 0 (got {seconds})"));
    }
    Ok(std::time::Instant::now().checked_add(std::time::Duration::from_secs_f64(seconds.min(1e9))))
}

impl Control {
    /// Whether the stop flag is set: a tool that runs many scenes stops
    /// between them.
    pub fn stopped(&self) -> bool {
        self.interrupted() || self.past_deadline()
    }

    /// Whether the stop flag is set.
    pub fn interrupted(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// Whether the deadline has passed.
    pub fn past_deadline(&self) -> bool {
        self.deadline
            .is_some_and(|d| std::time::Instant::now() >= d)
    }

    /// Why the work stopped, in words, once [`stopped`](Control::stopped).
    pub fn stop_reason(&self) -> &'static str {
        if self.interrupted() {
            "interrupted: the stop flag was set"
        } else {
            "stopped: past the wall-clock budget (--wall)"
        }
    }

    /// The engine's options for a scene's run under this control.
    pub fn options(
        &self,
        t_end: f64,
        max_events: u64,
        method: Method,
        tolerances: Tolerances,
    ) -> Options {
        Options {
            t_end,
            max_events,
            method,
            tolerances,
            stop: self.stop.clone(),
            max_wall_seconds: match (self.max_wall_seconds, self.deadline) {
                (own, None) => own,
                (own, Some(d)) => {
                    let left = d
                        .saturating_duration_since(std::time::Instant::now())
                        .as_secs_f64();
                    Some(own.map_or(left, |own| own.min(left)))
                }
            },
            past_horizon: self.past_horizon,
        }
    }
}
