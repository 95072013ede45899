//! A released string as chains and continua, as `flicker compare-models`
//! and `flicker advise` ask it: the request checked against the scene,
//! the models run, and each measured against the densest chain.

use crate::analysis::release_convergence::{
    DEFAULT_CELLS, Distance, Model, Track, chain_track, continuum_track, distance, release,
    run_all, without_homogenized,
};
use crate::engine::Limits;
use crate::models::continuum::Variant;
use crate::models::continuum::scene::{ContinuumScene, MAX_FINITE_VOLUMES};
use crate::scene::{Scene, SceneError};

/// The models a release is run as (`flicker compare-models`).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelsRequest {
    /// Chain sizes; the largest is the reference.
    pub units: Vec<usize>,
    /// Cells of the homogenized continuum.
    pub cells: usize,
    /// Sample times over `[0, t_end]`.
    pub samples: usize,
}

impl Default for ModelsRequest {
    /// Chains of 100 to 1600 units, the default cells, 121 samples.
    fn default() -> Self {
        ModelsRequest {
            units: vec![100, 200, 400, 800, 1600],
            cells: DEFAULT_CELLS,
            samples: 121,
        }
    }
}

/// A release's models, checked, ready to run.
#[derive(Debug)]
pub struct ModelsCompared {
    release: ContinuumScene,
    models: Vec<Model>,
    /// The chain sizes, sorted, each once.
    pub units: Vec<usize>,
    /// Why the homogenized string is left out, where it is.
    pub left_out: Option<String>,
}

/// The tracks of a release's models and each one's distance from the
/// reference (the densest chain).
#[derive(Debug)]
pub struct Measured {
    /// Each model's run.
    pub tracks: Vec<Track>,
    /// The reference's index in `tracks`.
    pub reference: usize,
    /// Each track's distance from the reference.
    pub distances: Vec<Distance>,
}

impl ModelsRequest {
    /// The request checked against `scene` (a release); the error names
    /// `cells`, `units` or `samples`, or is the scene's own.
    pub fn on(&self, scene: &Scene) -> Result<ModelsCompared, SceneError> {
        let mut release = release(scene)?.string;
        if !(2..=MAX_FINITE_VOLUMES).contains(&self.cells) {
            return Err(SceneError::field(
                "cells",
                format!("from 2 to {MAX_FINITE_VOLUMES}"),
            ));
        }
        release.resolution = self.cells;
        let mut units = self.units.clone();
        units.sort_unstable();
        units.dedup();
        if units.is_empty() || units[0] == 0 || units[units.len() - 1] > 100_000 {
            return Err(SceneError::field(
                "units",
                "give chain sizes from 1 to 100000".into(),
            ));
        }
        if !(3..=100_000).contains(&self.samples) {
            return Err(SceneError::field("samples", "from 3 to 100000".into()));
        }
        release.samples = self.samples;
        let mut models: Vec<Model> = units.iter().map(|&n| Model::Chain(n)).collect();
        models.push(Model::Continuum(Variant::Paper));
        let left_out = without_homogenized(&release);
        if left_out.is_none() {
            models.push(Model::Continuum(Variant::Homogenized));
        }
        Ok(ModelsCompared {
            release,
            models,
            units,
            left_out,
        })
    }
}

impl ModelsCompared {
    /// The release's end time.
    pub fn t_end(&self) -> f64 {
        self.release.t_end
    }

    /// Run every model in parallel under `limits`, and measure each
    /// against the densest chain.
    pub fn run(&self, limits: &Limits) -> Result<Measured, String> {
        let tracks = run_all(&self.release, &self.models, limits)?;
        let reference = self.units.len() - 1;
        Ok(measured(tracks, reference))
    }
}

fn measured(tracks: Vec<Track>, reference: usize) -> Measured {
    let distances = tracks
        .iter()
        .map(|t| distance(t, &tracks[reference]))
        .collect();
    Measured {
        tracks,
        reference,
        distances,
    }
}

/// Largest chain run to probe a scene (`flicker advise`).
pub const PROBE_UNITS: usize = 400;

/// Times the models are compared at when probing.
const PROBE_SAMPLES: usize = 121;

/// A chain scene probed (`flicker advise`): the chain at a probe size
/// beside each continuum.
#[derive(Debug)]
pub struct Probe {
    /// The scene's chain size.
    pub units: usize,
    /// The chain size run.
    pub probe: usize,
    /// Why the homogenized string is left out, where it is.
    pub left_out: Option<String>,
    /// The probe chain first, then each continuum, measured against it.
    pub measured: Measured,
}

/// Why a scene cannot be probed.
#[derive(Debug)]
pub enum NotProbed {
    /// It is not a chain scene.
    NotAChain,
    /// The request or the scene was refused (a field and why).
    Refused(SceneError),
    /// A model could not be run.
    Failed(String),
}

/// Probe the chain scene `scene` with the chain at its own size (at most
/// [`PROBE_UNITS`]) and each continuum beside it, one after another so
/// that each is timed alone; `tolerance` (a number > 0) is checked here
/// for the advice that follows.
pub fn probe(scene: &Scene, tolerance: f64) -> Result<Probe, NotProbed> {
    let units = match crate::analysis::release_convergence::release::described(scene) {
        Some(crate::analysis::release_convergence::Release {
            units: Some(units), ..
        }) => units,
        _ => return Err(NotProbed::NotAChain),
    };
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(NotProbed::Refused(SceneError::field(
            "tolerance",
            "a number > 0".into(),
        )));
    }
    let mut release = release(scene).map_err(NotProbed::Refused)?.string;
    release.samples = PROBE_SAMPLES;
    let probe = units.min(PROBE_UNITS);
    let limits = Limits::default();
    let mut runs = vec![
        chain_track(&release, probe, &limits),
        continuum_track(&release, Variant::Paper, &limits),
    ];
    let left_out = without_homogenized(&release);
    if left_out.is_none() {
        runs.push(continuum_track(&release, Variant::Homogenized, &limits));
    }
    let tracks: Vec<Track> = runs
        .into_iter()
        .collect::<Result<_, _>>()
        .map_err(NotProbed::Failed)?;
    Ok(Probe {
        units,
        probe,
        left_out,
        measured: measured(tracks, 0),
    })
}
