//! A run as a user asks it, from `flicker run`'s flags or `flicker.run`'s
//! keywords alike: the scene's overrides (its end, its solver) and what the
//! run carries besides its events (derivatives, samples, an ensemble),
//! checked in one order before anything runs or any file is touched
//! ([`RunRequest::prepare`]), then run ([`PreparedRun`]).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::engine::Limits;
use crate::engine::Observer;
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest};
use crate::runner::{Report, Trajectory};
use crate::scene::solver::SolverSpec;
use crate::scene::{Scene, SceneError};

/// The times a run is asked to sample its state at.
#[derive(Debug, Clone, PartialEq)]
pub enum Samples {
    /// This many, evenly spaced from 0 to `t_end` (`--samples`).
    Count(usize),
    /// At these times, each from 0 to `t_end` (`--at`, `t_eval`).
    At(Vec<f64>),
}

/// A run as asked: every field unset runs the scene as written.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunRequest {
    /// The time to run to instead of the scene's `t_end`.
    pub t_end: Option<f64>,
    /// Overrides of the scene's `solver` (`--method`, `--rtol`, ...).
    pub solver: SolverSpec,
    /// Directions of the derivatives to carry (`--sensitivities`).
    pub sensitivities: Option<Vec<String>>,
    /// Times to sample the state at.
    pub samples: Option<Samples>,
    /// Copies with perturbed starts, for the scene's horizon (`--ensemble`).
    pub ensemble: Option<EnsembleRequest>,
    /// Go on past the horizon as a pseudo-orbit (`--past-horizon`).
    pub past_horizon: bool,
}

/// Which part of a [`RunRequest`] was refused: each front end names it its
/// own way (a flag, a keyword).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ask {
    /// `t_end`.
    TEnd,
    /// The solver's overrides.
    Solver,
    /// `sensitivities`.
    Sensitivities,
    /// `ensemble`.
    Ensemble,
    /// `samples`.
    Samples,
}

/// A request the scene refused: which part, and the scene's error (its
/// field and reason).
#[derive(Debug, Clone)]
pub struct Refused {
    /// The part refused.
    pub ask: Ask,
    /// Why.
    pub error: SceneError,
}

impl RunRequest {
    /// `scene` with the request checked against it and its overrides made:
    /// the end first, then the solver (whether the method can carry
    /// derivatives depends on it), the derivatives, the ensemble and the
    /// samples (their times depend on the end).
    pub fn prepare(&self, mut scene: Scene) -> Result<PreparedRun, Refused> {
        let refused = |ask| move |error| Refused { ask, error };
        if let Some(t) = self.t_end {
            scene.set_t_end(t).map_err(refused(Ask::TEnd))?;
        }
        if self.solver != SolverSpec::default() {
            scene
                .override_solver(&self.solver)
                .map_err(refused(Ask::Solver))?;
        }
        if let Some(directions) = &self.sensitivities {
            crate::analysis::sensitivities::check(&scene, directions)
                .map_err(refused(Ask::Sensitivities))?;
        }
        if let Some(request) = &self.ensemble {
            scene
                .check_ensemble(request)
                .map_err(refused(Ask::Ensemble))?;
        }
        let times = match &self.samples {
            None => None,
            Some(samples) => {
                let (count, at) = match samples {
                    Samples::Count(n) => (Some(*n), None),
                    Samples::At(times) => (None, Some(times.as_slice())),
                };
                let times = crate::log::samples::times(count, at, scene.t_end())
                    .map_err(|why| refused(Ask::Samples)(SceneError::field("samples", why)))?;
                if !scene.offers_samples() {
                    return Err(refused(Ask::Samples)(no_samples(&scene)));
                }
                Some(times)
            }
        };
        Ok(PreparedRun {
            scene,
            sensitivities: self.sensitivities.clone(),
            times,
            ensemble: self.ensemble,
            past_horizon: self.past_horizon,
        })
    }
}

fn no_samples(scene: &Scene) -> SceneError {
    SceneError::field(
        "samples",
        format!("a {} scene offers no samples of its state", scene.model()),
    )
}

/// A run checked against its scene, ready to run.
#[derive(Debug)]
pub struct PreparedRun {
    scene: Scene,
    sensitivities: Option<Vec<String>>,
    times: Option<Vec<f64>>,
    ensemble: Option<EnsembleRequest>,
    past_horizon: bool,
}

impl PreparedRun {
    /// The scene, with the request's overrides made.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The limits the run goes under, stopped by `stop` where given.
    pub fn limits(&self, stop: Option<Arc<AtomicBool>>) -> Limits {
        Limits {
            stop,
            past_horizon: self.past_horizon,
            ..Limits::default()
        }
    }

    /// Run it under `limits`, events to `observer`: the report, and the
    /// samples where they were asked for.
    pub fn run(
        &self,
        limits: &Limits,
        observer: &mut dyn Observer,
    ) -> Result<(Report, Option<Trajectory>), SceneError> {
        let scene = &self.scene;
        let sampled = |trajectory: Trajectory| (trajectory.report.clone(), Some(trajectory));
        match (&self.sensitivities, &self.times) {
            (Some(directions), None) => crate::analysis::sensitivities::run(
                scene,
                directions,
                limits,
                &[],
                &mut |_| {},
                observer,
            )
            .map(|report| (report, None)),
            (Some(directions), Some(times)) => {
                crate::analysis::sensitivities::sampled(scene, directions, limits, times, observer)
                    .map(sampled)
            }
            (None, None) => scene.run(limits, observer).map(|report| (report, None)),
            (None, Some(times)) => match scene.sampled(limits, times, observer) {
                Some(ran) => ran.map(sampled),
                None => Err(no_samples(scene)),
            },
        }
    }

    /// The ensemble asked for, under `limits`, if one was: its report, or
    /// why it failed.
    pub fn ensemble(&self, limits: &Limits) -> Option<Result<EnsembleReport, String>> {
        let request = self.ensemble.as_ref()?;
        Some(self.scene.ensemble(request, limits))
    }
}
