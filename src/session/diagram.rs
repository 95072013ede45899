//! A bifurcation diagram as `flicker diagram` asks it: the parameter's
//! values, the section, what is run and recorded at each value, checked
//! against the scene before anything runs, then run (see
//! [`crate::analysis::diagram`]).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::analysis::diagram::{self, Diagram, Request};
use crate::engine::{Family, Limits};
use crate::scene::{Scene, SceneError};

/// A diagram as asked: unset times follow the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagramRequest {
    /// The parameter varied.
    pub parameter: String,
    /// Its first value.
    pub from: f64,
    /// Its last value.
    pub to: f64,
    /// How many values, evenly spaced from `from` to `to`.
    pub points: usize,
    /// The guard whose events are recorded.
    pub section: String,
    /// Time run before recording (default: the scene's `t_end`).
    pub transient: Option<f64>,
    /// Section events recorded at each value.
    pub record: usize,
    /// The longest a value runs after its transient (default: the
    /// scene's `t_end`).
    pub span: Option<f64>,
    /// Start each value from where the one before ended.
    pub follow: bool,
    /// Runs go on past their horizon as pseudo-orbits.
    pub past_horizon: bool,
    /// Only the values `I, I+N, ...` (`I/N`), for batch jobs; not with
    /// `follow`.
    pub shard: Option<String>,
    /// Seconds of wall time for the whole diagram.
    pub wall: f64,
}

/// A diagram checked against its scene, ready to run.
pub struct PreparedDiagram {
    family: Box<dyn Family>,
    request: Request,
    indices: Vec<usize>,
    past_horizon: bool,
    deadline: Option<std::time::Instant>,
}

impl DiagramRequest {
    /// The request checked against `scene`; the error names the field at
    /// fault (`param`, `section`, `points`, `from`, `to`, `transient`,
    /// `record`, `span`, `shard`, `wall`), or the scene's `model` where it
    /// has no finite state.
    pub fn on(&self, scene: &Scene) -> Result<PreparedDiagram, SceneError> {
        let family = scene.family()?;
        for (field, x) in [("from", self.from), ("to", self.to)] {
            if !x.is_finite() {
                return Err(SceneError::field(field, "must be a finite number".into()));
            }
        }
        let n = self.points;
        let values = crate::analysis::spacing::evenly_spaced(self.from, self.to, n);
        let request = Request {
            parameter: self.parameter.clone(),
            values,
            section: self.section.clone(),
            transient: self.transient.unwrap_or_else(|| scene.t_end()),
            record: self.record,
            span: self.span.unwrap_or_else(|| scene.t_end()),
            follow: self.follow,
        };
        diagram::check(&*family, &request).map_err(|(field, why)| SceneError::field(field, why))?;
        if self.follow && self.shard.is_some() {
            return Err(SceneError::field(
                "shard",
                "a followed diagram runs its values in order, in one piece".into(),
            ));
        }
        let shard = super::shard(self.shard.as_deref())?;
        let deadline = super::deadline(self.wall)?;
        Ok(PreparedDiagram {
            family,
            indices: (shard.index..n).step_by(shard.count).collect(),
            request,
            past_horizon: self.past_horizon,
            deadline,
        })
    }
}

impl PreparedDiagram {
    /// How many values this diagram (or its shard) runs.
    pub fn points(&self) -> usize {
        self.indices.len()
    }

    /// The names of the states recorded, the parameter's aside.
    pub fn names(&self) -> Vec<String> {
        diagram::names(&*self.family, &self.request.parameter).unwrap_or_default()
    }

    /// The diagram's settings, the scene's defaults filled in.
    pub fn request(&self) -> &Request {
        &self.request
    }

    /// Run it, stopped by `stop` where given and by the wall-time budget,
    /// `done` told of each value as it ends.
    pub fn run(
        &self,
        stop: Option<Arc<AtomicBool>>,
        done: &(dyn Fn() + Sync),
    ) -> Result<Diagram, String> {
        let limits = Limits {
            stop,
            deadline: self.deadline,
            past_horizon: self.past_horizon,
            ..Limits::default()
        };
        diagram::run(&*self.family, &self.request, &self.indices, &limits, done)
    }
}
