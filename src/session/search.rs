//! A periodic-orbit search, or a branch of them, or a brute-force diagram,
//! as `flicker orbit` and `flicker continue` (and Python's `orbit()` and
//! `continuation()`) ask it, resolved against the scene and run.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::analysis::orbit::continuation::Point;
use crate::analysis::orbit::diagram::Column;
use crate::analysis::orbit::{ContinuedBranch, Orbit, OrbitRequest, Watch};
use crate::scene::{Scene, SceneError};
use crate::session::Prepared;

/// A periodic-orbit search, or a branch of them, as asked (the flags of
/// `flicker orbit` and `flicker continue`, the keywords of Python's
/// `orbit()` and `continuation()`).
#[derive(Debug, Clone, PartialEq)]
pub struct SearchRequest {
    /// The guard whose events are the section.
    pub section: String,
    /// Section events per period.
    pub events: usize,
    /// Time run before the search starts from the next section event.
    pub settle: f64,
    /// The forcing's period, where the model reads the clock.
    pub forcing_period: Option<f64>,
    /// Seconds of wall time for the whole search or branch.
    pub wall: f64,
}

impl SearchRequest {
    /// The search's settings, stopped by `stop` where given; the error
    /// names `wall` (the section and the rest are checked by the search,
    /// which names them too).
    pub fn resolve(&self, stop: Option<Arc<AtomicBool>>) -> Result<OrbitRequest, SceneError> {
        Ok(OrbitRequest {
            guard: self.section.clone(),
            events: self.events,
            settle: self.settle,
            forcing_period: self.forcing_period,
            stop,
            deadline: super::deadline(self.wall)?,
        })
    }

    /// The search asked of `scene`, ready to run: its model's family
    /// (refused in one line, field `model`, for a scene without a finite
    /// state) and the search's settings.
    pub fn on(
        &self,
        scene: &Scene,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<Prepared<OrbitRequest>, SceneError> {
        Ok(Prepared {
            family: scene.family()?,
            request: self.resolve(stop)?,
            t_max: scene.t_end(),
        })
    }
}

impl Prepared<OrbitRequest> {
    /// The periodic orbit through the section (see [`crate::analysis::orbit::search`]).
    pub fn orbit(&self, watch: Watch<'_>) -> Result<Orbit, SceneError> {
        crate::analysis::orbit::search(&*self.family, &self.request, self.t_max, watch)
    }

    /// The branch of orbits followed in `parameter` to `to`, at most
    /// `points` orbits, no step longer than `max_step` of the way (see
    /// [`crate::analysis::orbit::follow`]); `on_point` hears of each orbit found.
    pub fn branch(
        &self,
        parameter: &str,
        to: f64,
        steps: (usize, f64),
        on_point: &mut dyn FnMut(&Point),
    ) -> Result<ContinuedBranch, SceneError> {
        crate::analysis::orbit::follow(
            &*self.family,
            &self.request,
            parameter,
            to,
            steps,
            self.t_max,
            on_point,
        )
    }

    /// The brute-force diagram at each of `values` of `parameter`: the
    /// section's states over `events` returns after half the scene's span
    /// (see [`crate::analysis::orbit::diagram::brute_force`]).
    pub fn brute_force(
        &self,
        parameter: &str,
        values: &[f64],
        events: usize,
    ) -> Result<Vec<Column>, SceneError> {
        crate::analysis::orbit::diagram::brute_force(
            &*self.family,
            parameter,
            values,
            &self.request.guard,
            (self.t_max / 2.0, events, self.t_max),
            (self.request.stop.as_ref(), self.request.deadline),
        )
    }
}
