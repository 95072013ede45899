//! The exact answer a scene offers to measure runs against, and the one
//! measurement of a run against it (`flicker compare`, `flicker stress`).

use std::fmt;
use std::sync::Arc;

use crate::engine::Limits;
use crate::engine::{EventTimes, Status, bound::zeno};
use crate::runner::Report;
use crate::scene::{Scene, SceneError};

/// A run measured against a [`Reference`] ([`Reference::measure`]).
#[derive(Debug, Clone)]
pub struct Against {
    /// The run.
    pub report: Report,
    /// Its event times, Zeno settlings left out.
    pub times: Vec<f64>,
    /// The largest error of its final state, component by component.
    pub final_error: f64,
    /// The largest error of its event times, over the events both have (a
    /// run that stopped at a Zeno point without its last, unresolvable
    /// ones); `None` if either has none.
    pub time_error: Option<f64>,
}

/// The final state and event times of the exact solution, as a scene's
/// model gives them ([`SceneModel::reference`]).
///
/// [`SceneModel::reference`]: crate::scene::SceneModel::reference
#[derive(Clone)]
pub struct Reference {
    /// How the reference was obtained, for the output.
    pub kind: &'static str,
    /// The exact state at the end, component by component as the run's.
    pub final_state: Vec<f64>,
    /// Events up to the end (saturating for chattering orbits).
    pub events: u64,
    /// How far the reference's own final state may be from the truth (0
    /// for a closed form; a run's stated bound where the reference is the
    /// tightest run there is).
    pub error_bound: f64,
    /// The same for its event times.
    pub event_time_bound: f64,
    /// The time of event number `k` (from 0).
    event_time: Arc<dyn Fn(u64) -> f64 + Send + Sync>,
}

impl Reference {
    /// A reference with these final state and event count, whose `k`-th
    /// event (from 0) happens at `event_time(k)`.
    pub fn new(
        kind: &'static str,
        final_state: Vec<f64>,
        events: u64,
        event_time: impl Fn(u64) -> f64 + Send + Sync + 'static,
    ) -> Self {
        Reference {
            kind,
            final_state,
            events,
            error_bound: 0.0,
            event_time_bound: 0.0,
            event_time: Arc::new(event_time),
        }
    }

    /// The reference with the bounds its own run stated on its final state
    /// and its event times.
    pub fn with_bounds(mut self, error_bound: f64, event_time_bound: f64) -> Self {
        self.error_bound = error_bound;
        self.event_time_bound = event_time_bound;
        self
    }

    /// The time of event number `k` (from 0).
    pub fn event_time(&self, k: u64) -> f64 {
        (self.event_time)(k)
    }

    /// Run `scene` under `limits` and measure it against this reference.
    pub fn measure(&self, scene: &Scene, limits: &Limits) -> Result<Against, SceneError> {
        let mut times = EventTimes::default();
        let report = scene.run(limits, &mut times)?;
        let final_error = report
            .final_state
            .iter()
            .zip(&self.final_state)
            .map(|((_, a), b)| (a - b).abs())
            .fold(0.0, f64::max);
        let time_error = self.largest_time_error(match report.outcome.status {
            Status::Zeno => zeno::resolved(&times.0),
            _ => &times.0,
        });
        Ok(Against {
            report,
            times: times.0,
            final_error,
            time_error,
        })
    }

    /// The largest difference between `times` and the reference's event
    /// times, over the events both have; `None` if either has none.
    pub fn largest_time_error(&self, times: &[f64]) -> Option<f64> {
        let common = (times.len() as u64).min(self.events);
        (common > 0).then(|| {
            (0..common)
                .map(|k| (times[k as usize] - self.event_time(k)).abs())
                .fold(0.0, f64::max)
        })
    }
}

impl fmt::Debug for Reference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Reference")
            .field("kind", &self.kind)
            .field("final_state", &self.final_state)
            .field("events", &self.events)
            .field("error_bound", &self.error_bound)
            .field("event_time_bound", &self.event_time_bound)
            .finish_non_exhaustive()
    }
}
