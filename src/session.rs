//! What a user asks of a scene beyond the scene itself, resolved once for
//! the command line and the Python binding alike, so a request means the
//! same from either: a run with derivatives along some directions or
//! samples of the state at some times ([`RunRequest`]), a periodic-orbit
//! search or branch ([`SearchRequest`]), and a Lyapunov spectrum whose
//! unset settings follow the scene ([`SpectrumRequest`]). A tool's request
//! resolved against its scene is a [`Prepared`] tool, which both run.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::analysis::lyapunov::{self, Spectrum};
use crate::analysis::orbit::continuation::Point;
use crate::analysis::orbit::diagram::Column;
use crate::analysis::orbit::{ContinuedBranch, Orbit, OrbitRequest, Watch};
use crate::engine::{Family, Observer};
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
            crate::analysis::sensitivities::check(scene, directions)?;
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
            (Some(directions), None) => crate::analysis::sensitivities::run(
                scene,
                directions,
                control,
                &[],
                &mut |_| {},
                observer,
            )
            .map(|report| (report, None)),
            (Some(directions), Some(times)) => {
                crate::analysis::sensitivities::sampled(scene, directions, control, times, observer)
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

    /// The spectrum asked of `scene`, ready to run: its model's family
    /// (refused in one line, field `model`, for a scene without a finite
    /// state) and the settings resolved against it.
    pub fn on(
        &self,
        scene: &Scene,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<Prepared<lyapunov::Request>, SceneError> {
        let family = scene.family()?;
        let request = self.resolve(scene, &*family, stop)?;
        Ok(Prepared {
            family,
            request,
            t_max: scene.t_end(),
        })
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

/// A tool's request resolved against its scene: the scene's model as the
/// tools see it and the settings they run with. The command line and
/// Python both run it; they only convert what goes in and what comes out.
pub struct Prepared<R> {
    /// The scene's model as the tools see it.
    pub family: Box<dyn Family>,
    /// The tool's settings.
    pub request: R,
    /// The scene's `t_end`: the latest any return may come.
    t_max: f64,
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

impl Prepared<lyapunov::Request> {
    /// The spectrum (see [`crate::analysis::lyapunov::spectrum`]); `progress` hears
    /// of the time reached and the events so far.
    pub fn spectrum(&self, progress: &mut dyn FnMut(f64, u64)) -> Spectrum {
        lyapunov::spectrum(&*self.family, &self.request, progress)
    }
}
