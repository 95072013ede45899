//! The reproducibility horizon of an automaton (`flicker run --ensemble`):
//! copies whose initial states are each moved by up to `perturb` times the
//! state's scale, run in parallel with the scene's method and no log, and
//! compared at [`SAMPLES`] evenly spaced times.
//!
//! A state's scale is the largest magnitude it takes in any copy's samples
//! (1 where it stays zero). The horizon is the first sample time at which
//! two copies differ in some state by more than [`HORIZON`] of its scale.
//! The clock, where the state carries one, is not perturbed. A copy that
//! ends early at a Zeno point is compared up to its last sample.

use rand::RngExt;
use rayon::prelude::*;
use serde_json::{Value, json};

use crate::engine::Limits;
use crate::engine::{HybridModel, Name, Status, simulate_sampled};
use crate::models::automaton::scene::AutomatonScene;
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest, spread};
use crate::scene::SceneError;

/// Sample times at which the copies are compared, `t = 0` and `t_end`
/// included.
pub const SAMPLES: usize = 101;

/// Copies differing by more than this fraction of a state's scale are no
/// longer reproducible.
pub const HORIZON: f64 = 1e-3;

/// Most stored values (copies x samples x states) an ensemble may hold.
const MAX_VALUES: usize = 100_000_000;

/// Whether `request` can run on `scene`, checked before anything runs.
pub fn check(scene: &AutomatonScene, request: &EnsembleRequest) -> Result<(), SceneError> {
    request
        .check()
        .map_err(|why| SceneError::field("ensemble", why))?;
    let stored = request
        .copies
        .saturating_mul(SAMPLES)
        .saturating_mul(scene.automaton.dimension());
    if stored > MAX_VALUES {
        return Err(SceneError::field(
            "ensemble",
            format!(
                "{} copies x {SAMPLES} samples x {} states is too much to hold; run fewer copies",
                request.copies,
                scene.automaton.dimension()
            ),
        ));
    }
    Ok(())
}

/// Run the copies [`check`] accepted and report their spread.
pub fn run(
    scene: &AutomatonScene,
    request: &EnsembleRequest,
    limits: &Limits,
) -> Result<EnsembleReport, String> {
    check(scene, request).map_err(|e| e.reason)?;
    let times: Vec<f64> = (0..SAMPLES)
        .map(|i| scene.t_end * i as f64 / (SAMPLES - 1) as f64)
        .collect();
    let runs: Vec<Vec<Vec<f64>>> = (0..request.copies)
        .into_par_iter()
        .map(|copy| run_copy(scene, request, copy, &times, limits))
        .collect::<Result<_, _>>()?;
    let reached = runs.iter().map(Vec::len).min().unwrap_or(0);
    let names = scene.automaton.state_names(0);
    let mut scale = vec![0.0_f64; names.len()];
    for sample in runs.iter().flatten() {
        for (s, x) in scale.iter_mut().zip(sample) {
            *s = s.max(x.abs());
        }
    }
    let scale: Vec<f64> = scale
        .into_iter()
        .map(|s| if s > 0.0 { s } else { 1.0 })
        .collect();
    let spreads: Vec<Vec<f64>> = (0..reached)
        .map(|i| spread(runs.iter().map(|r| r[i].as_slice())))
        .collect();
    let horizon = spreads
        .iter()
        .position(|d| d.iter().zip(&scale).any(|(d, s)| *d > HORIZON * s))
        .map(|i| times[i]);
    Ok(report(request, names, &times, &spreads, &scale, horizon))
}

/// Copy `copy`'s state at each sample time it reached.
fn run_copy(
    scene: &AutomatonScene,
    request: &EnsembleRequest,
    copy: usize,
    times: &[f64],
    limits: &Limits,
) -> Result<Vec<Vec<f64>>, String> {
    let model = &*scene.automaton;
    let mut rng = request.stream(copy);
    let mut x = model.initial().to_vec();
    let perturbed = scene.definition.states.len();
    let largest = x[..perturbed].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for v in &mut x[..perturbed] {
        // Relative to the value, or to the largest where it starts at zero.
        let scale = if *v != 0.0 {
            v.abs()
        } else if largest > 0.0 {
            largest
        } else {
            1.0
        };
        *v += request.perturb * scale * rng.random_range(-1.0..=1.0);
    }
    let (method, _) = scene.resolved();
    let options = limits.options(scene.t_end, scene.max_events, method, scene.tolerances);
    let mut samples = Vec::with_capacity(times.len());
    let outcome = simulate_sampled(
        model,
        model.initial_mode(),
        &x,
        &options,
        times,
        &mut |s| samples.push(s.state.to_vec()),
        &mut (),
    );
    match outcome.status {
        Status::Completed | Status::Zeno => Ok(samples),
        _ => Err(format!(
            "copy {copy} stopped at t = {}: {}",
            outcome.t_reached,
            outcome.reason.unwrap_or_default()
        )),
    }
}

/// The ensemble as `flicker run` reports it: the summary's entry, one row
/// of `ensemble.csv` per sample time (each state's spread), what to print.
fn report(
    request: &EnsembleRequest,
    names: &[Name],
    times: &[f64],
    spreads: &[Vec<f64>],
    scale: &[f64],
    horizon: Option<f64>,
) -> EnsembleReport {
    let resolution = times[1] - times[0];
    let spread_json: Vec<Value> = spreads
        .iter()
        .zip(times)
        .map(|(d, t)| {
            let mut row = serde_json::Map::new();
            row.insert("t".into(), json!(t));
            for (name, d) in names.iter().zip(d) {
                row.insert(name.to_string(), json!(d));
            }
            Value::Object(row)
        })
        .collect();
    let scales: serde_json::Map<String, Value> = names
        .iter()
        .zip(scale)
        .map(|(n, s)| ((*n).to_string(), json!(s)))
        .collect();
    let summary = json!({
        "copies": request.copies,
        "perturb": request.perturb,
        "seed": request.seed,
        "horizon": horizon,
        "horizon_resolution": resolution,
        "scale": scales,
        "spread": spread_json,
    });
    let header = std::iter::once("t".to_string())
        .chain(names.iter().map(|n| n.to_string()))
        .collect();
    let rows = spreads
        .iter()
        .zip(times)
        .map(|(d, t)| {
            std::iter::once(t.to_string())
                .chain(d.iter().map(f64::to_string))
                .collect()
        })
        .collect();
    let mut said = vec![format!(
        "ensemble of {} copies (perturbation {:e}, seed {}): states part by more than {HORIZON:e} of their scale {}",
        request.copies,
        request.perturb,
        request.seed,
        horizon.map_or("nowhere before t_end".to_string(), |h| format!(
            "at t = {h} (to within {resolution:.3e}); results after that are not reproducible"
        ))
    )];
    if let Some(last) = spreads.last() {
        let parts: Vec<String> = names
            .iter()
            .zip(last)
            .map(|(n, d)| format!("{n} {d:.2e}"))
            .collect();
        said.push(format!(
            "spread at t = {}: {}",
            times[spreads.len() - 1],
            parts.join(", ")
        ));
    }
    EnsembleReport {
        summary,
        header,
        rows,
        said,
    }
}
