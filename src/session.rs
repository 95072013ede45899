//! What a user asks of a scene beyond the scene itself, resolved once for
//! the command line and the Python binding alike, so a request means the
//! same from either: a run with derivatives along some directions or
//! samples of the state at some times ([`RunRequest`]), a periodic-orbit
//! search or branch ([`SearchRequest`]), and a Lyapunov spectrum whose
//! unset settings follow the scene ([`SpectrumRequest`]).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::engine::{Family, Observer};
use crate::lyapunov;
use crate::orbit::OrbitRequest;
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

/// A Lyapunov spectrum as asked (`flicker lyapunov`'s flags, the keywords
/// of Python's `lyapunov()`): what is not given follows the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumRequest {
    /// How many exponents; all of them (the state's dimension) if unset.
    pub exponents: Option<usize>,
    /// Time run first, for a transient to die out.
    pub transient: f64,
    /// Time averaged over; the scene's `t_end` if unset.
    pub t_end: Option<f64>,
    /// Time between re-orthonormalisations; a quarter of the scene's time
    /// scale (at most the span) if unset.
    pub interval: Option<f64>,
    /// Seconds of wall time for the whole spectrum.
    pub wall: f64,
}

impl SpectrumRequest {
    /// The spectrum's settings for `scene`'s `family`, checked before
    /// anything runs, stopped by `stop` where given; the error names the
    /// field it is about (`exponents`, `interval`, `wall`...).
    pub fn resolve(
        &self,
        scene: &Scene,
        family: &dyn Family,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<lyapunov::Request, SceneError> {
        let span = self.t_end.unwrap_or_else(|| scene.t_end());
        let request = lyapunov::Request {
            exponents: self.exponents.unwrap_or_else(|| family.model().dimension()),
            transient: self.transient,
            span,
            interval: self
                .interval
                .unwrap_or_else(|| (scene.time_scale() / 4.0).min(span)),
            stop,
            deadline: crate::runner::deadline_in(self.wall)
                .map_err(|why| SceneError::field("wall", why))?,
        };
        lyapunov::check(family, &request).map_err(|(field, why)| SceneError::field(field, why))?;
        Ok(request)
    }
}

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
            deadline: crate::runner::deadline_in(self.wall)
                .map_err(|why| SceneError::field("wall", why))?,
        })
    }
}
