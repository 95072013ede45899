//! Running a validated scene: build its model, pick its method, run it, and
//! describe the result in the scene's own terms.

pub mod ensemble;
mod fields;

use crate::engine::{Method, Name, Outcome};

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

/// The instant `seconds` (a wall-clock budget, `--wall`) from now, or
/// why `seconds` is not a budget.
pub fn deadline_in(seconds: f64) -> Result<Option<std::time::Instant>, String> {
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(format!("a time > 0 (got {seconds})"));
    }
    Ok(std::time::Instant::now().checked_add(std::time::Duration::from_secs_f64(seconds.min(1e9))))
}
