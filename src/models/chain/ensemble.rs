//! The reproducibility horizon of a chain scene (docs/physics.md s.7): copies
//! of the run with each initial strain moved by up to `perturb` times the
//! scene's largest initial strain, run in parallel, compared at the
//! scene's sample times.
//!
//! The horizon is the first sample time at which some unit's strain
//! differs between two copies by more than [`HORIZON`]; the spread of a
//! field at a time is its largest difference between two copies there
//! (over units or windows). What every model's ensemble shares (the
//! request, the report, the seeding) is [`crate::runner::ensemble`]'s.

use rand::RngExt;
use rayon::prelude::*;
use serde_json::json;

use crate::engine::Limits;
use crate::engine::{Method, Options, Status, Tolerances, simulate_local};
use crate::models::chain::coarse::Coarse;
use crate::models::chain::scene::ChainScene;
use crate::models::chain::{Chain, TaylorChain};
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest, spread};
use crate::scene::SceneError;
use crate::time::Time;

/// Unit strains differing by more than this are no longer reproducible.
pub const HORIZON: f64 = 1e-3;

/// Most stored values (copies x samples x units x 4) an ensemble may hold.
const MAX_VALUES: usize = 100_000_000;

/// What the ensemble found.
#[derive(Debug, Clone, PartialEq)]
pub struct Ensemble {
    /// Number of perturbed copies run.
    pub copies: usize,
    /// Largest perturbation of a unit's initial strain, relative to the
    /// scene's largest initial strain.
    pub perturb: f64,
    /// Seed of the perturbations.
    pub seed: u64,
    /// First sample time at which unit strains of two copies differ by
    /// more than [`HORIZON`], if any before `t_end`.
    pub horizon: Option<f64>,
    /// Spacing of the sample times: the horizon's resolution.
    pub resolution: f64,
    /// The spread at each sample time.
    pub spread: Vec<Spread>,
}

/// The largest difference between copies at one sample time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// The sample time.
    pub t: f64,
    /// Largest difference of a unit's strain.
    pub unit_strain: f64,
    /// Largest difference of a window's coarse strain.
    pub window_strain: f64,
    /// Largest difference of a window's coarse velocity.
    pub window_velocity: f64,
    /// Largest difference of a window's hidden energy.
    pub hidden_energy: f64,
    /// Largest difference of the loaded end's displacement.
    pub right_end: f64,
    /// `None` while some copy has no front (docs/physics.md s.6) yet.
    pub front: Option<f64>,
}

/// One copy at one sample time.
struct Sample {
    strain: Vec<f64>,
    coarse: Coarse,
    right_end: f64,
    front: Option<f64>,
}

/// Whether `request` can run on `scene`: checked before anything runs, so
/// bad flags lose nothing.
pub fn check(scene: &ChainScene, request: &EnsembleRequest) -> Result<(), SceneError> {
    let refuse = |reason: String| SceneError::field("ensemble", reason);
    request
        .check()
        .map_err(|why| SceneError::field("ensemble", why))?;
    if !matches!(scene.method, Method::Auto | Method::Exact) {
        return Err(refuse(
            "runs a chain scene with its exact flow only; leave `--method` out".into(),
        ));
    }
    let copies = request.copies;
    let times = scene.sample_times();
    if times.len() < 2 {
        return Err(refuse(
            "needs at least 2 sample times (the scene's `samples`)".into(),
        ));
    }
    let stored = copies
        .saturating_mul(times.len())
        .saturating_mul(scene.units)
        .saturating_mul(4);
    if stored > MAX_VALUES {
        return Err(refuse(format!(
            "{copies} copies x {} samples x {} units is too much to hold; lower `samples` or the copies",
            times.len(),
            scene.units
        )));
    }
    Ok(())
}

/// Run the perturbed copies of `scene` (exact flow, no log) that
/// [`check`] accepted; an error says which copy stopped and why.
pub fn run_ensemble(
    scene: &ChainScene,
    request: &EnsembleRequest,
    limits: &Limits,
) -> Result<Ensemble, String> {
    check(scene, request).map_err(|e| e.reason)?;
    let times = scene.sample_times();
    let chain = scene.chain(scene.constraint);
    let options = limits.options(
        scene.t_end,
        scene.max_events,
        Method::Exact,
        Tolerances::default(),
    );
    let runs: Vec<Result<Vec<Sample>, String>> = (0..request.copies)
        .into_par_iter()
        .map(|copy| run_copy(scene, &chain, &options, &times, request, copy))
        .collect();
    let runs: Vec<Vec<Sample>> = runs.into_iter().collect::<Result<_, _>>()?;
    let spread: Vec<Spread> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| spread_at(t, runs.iter().map(|r| &r[i])))
        .collect();
    let horizon = spread.iter().find(|s| s.unit_strain > HORIZON).map(|s| s.t);
    Ok(Ensemble {
        copies: request.copies,
        perturb: request.perturb,
        seed: request.seed,
        horizon,
        resolution: times[1] - times[0],
        spread,
    })
}

fn run_copy(
    scene: &ChainScene,
    chain: &Chain,
    options: &Options,
    times: &[f64],
    request: &EnsembleRequest,
    copy: usize,
) -> Result<Vec<Sample>, String> {
    let (perturb, mut rng) = (request.perturb, request.stream(copy));
    let unit_length = chain.unit_length();
    // Relative to the scene's strain scale, so that units starting shut are
    // perturbed too.
    let scale = scene.strain.iter().fold(0.0, |m: f64, e| m.max(e.abs()));
    let scale = if scale > 0.0 { scale } else { 1.0 };
    let gaps: Vec<f64> = scene
        .strain
        .iter()
        .map(|e| {
            let r: f64 = rng.random_range(-1.0..=1.0);
            let moved = e + perturb * scale * r;
            // The constraint holds strains at zero from below.
            let moved = if scene.constraint {
                moved.max(0.0)
            } else {
                moved
            };
            moved * unit_length
        })
        .collect();
    let mut model = TaylorChain::new(chain.clone(), &gaps, &scene.velocity)?;
    let undisturbed = scene.load_before - 1.0;
    let mut samples = Vec::with_capacity(times.len());
    let outcome = simulate_local(
        &mut model,
        options,
        times,
        &mut |m: &TaylorChain, t| {
            let (gaps, velocities) = m.state_at(Time::new(t));
            let coarse = Coarse::of(chain, scene.length, &gaps, &velocities);
            samples.push(Sample {
                strain: gaps.iter().map(|d| d / unit_length).collect(),
                right_end: gaps.iter().sum(),
                front: coarse.front(undisturbed),
                coarse,
            });
        },
        &mut (),
    );
    match outcome.status {
        Status::Completed => Ok(samples),
        _ => Err(format!(
            "copy {copy} stopped at t = {}: {}",
            outcome.t_reached,
            outcome.reason.unwrap_or_default()
        )),
    }
}

/// The largest pairwise differences between `copies` at one time.
fn spread_at<'s>(t: f64, copies: impl Iterator<Item = &'s Sample> + Clone) -> Spread {
    let range = |values: &dyn Fn(&'s Sample) -> &'s [f64]| -> f64 {
        spread(copies.clone().map(values))
            .into_iter()
            .fold(0.0, f64::max)
    };
    let scalar = |value: &dyn Fn(&Sample) -> Option<f64>| -> Option<f64> {
        let values: Option<Vec<f64>> = copies.clone().map(value).collect();
        values.map(|v| {
            spread(v.iter().map(std::slice::from_ref))
                .first()
                .copied()
                .unwrap_or(0.0)
        })
    };
    Spread {
        t,
        unit_strain: range(&|s| &s.strain),
        window_strain: range(&|s| &s.coarse.strain),
        window_velocity: range(&|s| &s.coarse.velocity),
        hidden_energy: range(&|s| &s.coarse.hidden_energy),
        right_end: scalar(&|s| Some(s.right_end)).unwrap_or(0.0),
        front: scalar(&|s| s.front),
    }
}

/// The ensemble as `flicker run` reports it: the summary's entry (copies,
/// perturbation, seed, the horizon and its resolution, the spread of each
/// field over time), `ensemble.csv` (those spreads, one row per sample
/// time, an empty `front` while some copy has none), and what to print.
pub fn report(e: &Ensemble) -> EnsembleReport {
    let spread: Vec<serde_json::Value> = e
        .spread
        .iter()
        .map(|s| {
            json!({
                "t": s.t,
                "unit_strain": s.unit_strain,
                "window_strain": s.window_strain,
                "window_velocity": s.window_velocity,
                "hidden_energy": s.hidden_energy,
                "right_end": s.right_end,
                "front": s.front,
            })
        })
        .collect();
    let summary = json!({
        "copies": e.copies,
        "perturb": e.perturb,
        "seed": e.seed,
        "horizon": e.horizon,
        "horizon_resolution": e.resolution,
        "spread": spread,
    });
    let header = [
        "t",
        "unit_strain",
        "window_strain",
        "window_velocity",
        "hidden_energy",
        "right_end",
        "front",
    ];
    let rows = e
        .spread
        .iter()
        .map(|s| {
            vec![
                s.t.to_string(),
                s.unit_strain.to_string(),
                s.window_strain.to_string(),
                s.window_velocity.to_string(),
                s.hidden_energy.to_string(),
                s.right_end.to_string(),
                s.front.map_or(String::new(), |f| f.to_string()),
            ]
        })
        .collect();
    let mut said = vec![format!(
        "ensemble of {} copies (perturbation {:e}, seed {}): unit strains part by more than 1e-3 {}",
        e.copies,
        e.perturb,
        e.seed,
        e.horizon
            .map_or("nowhere before t_end".to_string(), |h| format!(
                "at t = {h} (to within {:.3e}); unit-level results after that are not reproducible",
                e.resolution
            ))
    )];
    if let Some(s) = e.spread.last() {
        said.push(format!(
            "spread at the end: window strain {:.2e}, window velocity {:.2e}, hidden energy {:.2e}, right end {:.2e}",
            s.window_strain, s.window_velocity, s.hidden_energy, s.right_end
        ));
    }
    EnsembleReport {
        summary,
        header: header.map(String::from).to_vec(),
        rows,
        said,
    }
}
