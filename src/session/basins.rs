//! Basins of attraction as `flicker basins` asks them: the grid, the
//! transient, the section, checked against the scene before anything
//! runs, then run (see [`crate::analysis::basins`]).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::analysis::basins::{self, Axis, Basins, Request};
use crate::engine::{Family, Limits};
use crate::scene::{Scene, SceneError};

/// Basins as asked: unset settings follow the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct BasinsRequest {
    /// The grid: two axes, each `STATE=A:B:N`.
    pub grid: Vec<String>,
    /// Time run before a point is read (default: the scene's `t_end`).
    pub transient: Option<f64>,
    /// The guard whose events are read for a periodic orbit.
    pub section: Option<String>,
    /// Section events read for a repeat.
    pub record: usize,
    /// How close two states must be to count as the same.
    pub tolerance: f64,
    /// The forcing's period, for a model that reads the clock: periodic
    /// orbits are refined with it (multipliers, stability).
    pub forcing_period: Option<f64>,
    /// Runs go on past their horizon as pseudo-orbits (a chaotic
    /// attractor's points).
    pub past_horizon: bool,
    /// Only the points `I, I+N, ...` (`I/N`), for batch jobs.
    pub shard: Option<String>,
    /// Seconds of wall time for the whole grid.
    pub wall: f64,
}

/// Basins checked against their scene, ready to run.
pub struct PreparedBasins {
    family: Box<dyn Family>,
    request: Request,
    indices: Vec<usize>,
    past_horizon: bool,
    deadline: Option<std::time::Instant>,
}

impl BasinsRequest {
    /// The request checked against `scene`; the error names the field at
    /// fault (`grid`, `transient`, `section`, `record`, `tolerance`,
    /// `forcing_period`, `shard`, `wall`), or the scene's `model` where it has no finite
    /// state.
    pub fn on(&self, scene: &Scene) -> Result<PreparedBasins, SceneError> {
        let family = scene.family()?;
        let axes: Vec<Axis> = self
            .grid
            .iter()
            .map(|text| Axis::parse(text))
            .collect::<Result<_, _>>()
            .map_err(|why| SceneError::field("grid", why))?;
        let Ok(axes) = <[Axis; 2]>::try_from(axes) else {
            return Err(SceneError::field(
                "grid",
                "give two axes, STATE=A:B:N,STATE=C:D:M".into(),
            ));
        };
        let request = Request {
            axes,
            transient: self.transient.unwrap_or_else(|| scene.t_end()),
            section: self.section.clone(),
            record: self.record,
            tolerance: self.tolerance,
            forcing_period: self.forcing_period,
        };
        basins::check(&*family, &request).map_err(|(field, why)| SceneError::field(field, why))?;
        let shard = super::shard(self.shard.as_deref())?;
        let deadline = super::deadline(self.wall)?;
        let points = request.axes[0].count * request.axes[1].count;
        Ok(PreparedBasins {
            family,
            indices: (shard.index..points).step_by(shard.count).collect(),
            request,
            past_horizon: self.past_horizon,
            deadline,
        })
    }
}

impl PreparedBasins {
    /// How many points this grid (or its shard) runs.
    pub fn points(&self) -> usize {
        self.indices.len()
    }

    /// The settings, the scene's defaults filled in.
    pub fn request(&self) -> &Request {
        &self.request
    }

    /// Run it, stopped by `stop` where given and by the wall-time budget,
    /// `done` told of each point as it ends.
    pub fn run(&self, stop: Option<Arc<AtomicBool>>, done: &(dyn Fn() + Sync)) -> Basins {
        let limits = Limits {
            stop,
            deadline: self.deadline,
            past_horizon: self.past_horizon,
            ..Limits::default()
        };
        basins::run(&*self.family, &self.request, &self.indices, &limits, done)
    }
}
