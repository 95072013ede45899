//! One run of a scene as a user asks for it, beyond the scene itself:
//! derivatives along some directions, samples of the state at some times.
//! The command line and the Python binding both run scenes through here,
//! so a request means the same from either.

use crate::engine::Observer;
use crate::runner::{Control, Report, Trajectory};
use crate::scene::{Scene, SceneError};

/// What a run carries besides its events and summary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunRequest {
    /// Directions of the derivatives to carry (`--sensitivities`).
    pub sensitivities: Option<Vec<String>>,
    /// Times to sample the state at (`--samples`, `--at`, `t_eval`).
    pub times: Option<Vec<f64>>,
}

impl RunRequest {
    /// Check the request against `scene` before anything runs or any file
    /// is touched; the error names the field it is about
    /// (`sensitivities`, `samples`).
    pub fn check(&self, scene: &Scene) -> Result<(), SceneError> {
        if let Some(directions) = &self.sensitivities {
            crate::sensitivities::check(scene, directions)?;
        }
        if self.times.is_some() && !scene.offers_samples() {
            return Err(SceneError::field(
                "samples",
                format!("a {} scene offers no samples of its state", scene.model()),
            ));
        }
        Ok(())
    }

    /// Run `scene` as asked, under `control`, events to `observer`: the
    /// report, and the samples where times were asked for.
    pub fn run(
        &self,
        scene: &Scene,
        control: &Control,
        observer: &mut dyn Observer,
    ) -> Result<(Report, Option<Trajectory>), SceneError> {
        let sampled = |trajectory: Trajectory| (trajectory.report.clone(), Some(trajectory));
        match (&self.sensitivities, &self.times) {
            (Some(directions), None) => {
                crate::sensitivities::run(scene, directions, control, &[], &mut |_| {}, observer)
                    .map(|report| (report, None))
            }
            (Some(directions), Some(times)) => {
                crate::sensitivities::sampled(scene, directions, control, times, observer)
                    .map(sampled)
            }
            (None, None) => scene.run(control, observer).map(|report| (report, None)),
            (None, Some(times)) => match scene.sampled(control, times, observer) {
                Some(ran) => ran.map(sampled),
                None => Err(SceneError::field(
                    "samples",
                    format!("a {} scene offers no samples of its state", scene.model()),
                )),
            },
        }
    }
}
