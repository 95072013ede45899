//! Where methods fail: every stress scene run with every method its model
//! offers, each run either verified against the exact answer or failed with
//! its reason. A third outcome, a wrong answer given without complaint, is
//! what this exists to rule out (`tests/flicker/stress.rs` checks it).
//!
//! `flicker stress models/stress --markdown` prints the table that
//! `docs/stress.md` holds.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::compare::Reference;
use crate::engine::{EventTimes, Status};
use crate::runner::{self, Control};
use crate::scene::solver::SolverSpec;
use crate::scene::{self, Formulation, Scene, SceneError};

/// Dormand-Prince's tolerance in the suite.
pub const TOLERANCE: f64 = 1e-9;
/// Stormer-Verlet's step in the suite, as a fraction of the period.
pub const STEP_FRACTION: f64 = 1.0 / 200.0;
/// A zeno run is verified if it settles this close to the exact state.
const SETTLED_TOLERANCE: f64 = 1e-6;

/// How one run of one method on one case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Same events as the exact answer (or the same Zeno point), with this
    /// final-state error.
    Passed { final_error: f64 },
    /// The run said it could not be trusted, and why.
    Failed { reason: String },
    /// A numerical run that completed with a different event count than the
    /// exact answer: accumulated integration error, which its summary states
    /// (`error_bound`). Only long runs may drift.
    Drifted { why: String },
    /// A different answer given without complaint.
    Wrong { why: String },
}

#[derive(Debug, Clone)]
pub struct Row {
    pub case: String,
    pub method: String,
    pub verdict: Verdict,
    pub events: u64,
    pub reference_events: u64,
    pub energy_error: Option<f64>,
    pub wall_seconds: f64,
}

/// The stress scenes in `dir`, sorted by name.
pub fn cases(dir: &Path) -> Result<Vec<(String, Scene)>, SceneError> {
    let entries = std::fs::read_dir(dir).map_err(|e| SceneError {
        file: Some(dir.to_path_buf()),
        field: None,
        reason: format!("cannot be read: {e}"),
    })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| {
            Ok((
                p.file_stem()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned(),
                scene::load(p)?,
            ))
        })
        .collect()
}

/// The suite's setting of each method the scene's model offers.
pub fn settings(scene: &Scene) -> Vec<SolverSpec> {
    let spec = |method: &str, tol: Option<f64>, step: Option<f64>| SolverSpec {
        method: Some(method.into()),
        rtol: tol,
        atol: tol,
        step,
    };
    match scene {
        Scene::Mechanism(m) if m.formulation == Formulation::Strain => {
            let period = std::f64::consts::TAU / m.mechanism.omega;
            vec![
                spec("exact", None, None),
                spec("linear", None, None),
                spec("dopri5", Some(TOLERANCE), None),
                spec("dop853", Some(TOLERANCE), None),
                spec("verlet", None, Some(period * STEP_FRACTION)),
            ]
        }
        Scene::Mechanism(_) => vec![
            spec("dopri5", Some(TOLERANCE), None),
            spec("dop853", Some(TOLERANCE), None),
        ],
        Scene::Chain(_) | Scene::Continuum(_) => Vec::new(),
    }
}

/// Run `scene` with `setting`, stopping it after `wall_seconds`, and judge it.
pub fn run_case(
    case: &str,
    scene: &Scene,
    setting: &SolverSpec,
    wall_seconds: f64,
) -> Result<Row, SceneError> {
    let mut scene = scene.clone();
    scene.set_solver(setting.clone())?;
    let reference = Reference::of(&scene)?;
    let mut times = EventTimes::default();
    let control = Control {
        stop: None,
        max_wall_seconds: Some(wall_seconds),
    };
    let start = Instant::now();
    let report = runner::run(&scene, &control, &mut times)?;
    let wall = start.elapsed().as_secs_f64();
    let o = &report.outcome;
    let final_error = report
        .final_state
        .iter()
        .zip(&reference.final_state)
        .map(|((_, a), b)| (a - b).abs())
        .fold(0.0, f64::max);
    let verdict = match (o.status, &o.reason) {
        (Status::Failed | Status::Interrupted, reason) => Verdict::Failed {
            reason: reason.clone().unwrap_or_default(),
        },
        (Status::Zeno, _) if final_error <= SETTLED_TOLERANCE => Verdict::Passed { final_error },
        (Status::Zeno, _) => Verdict::Wrong {
            why: format!("settled {final_error:.1e} away from the exact state"),
        },
        _ if times.0.len() as u64 != reference.events && o.error_bound > 0.0 => Verdict::Drifted {
            why: format!(
                "{} events where the exact answer has {}; the run's integration error bound is {:.1e}",
                times.0.len(),
                reference.events,
                o.error_bound
            ),
        },
        _ if times.0.len() as u64 != reference.events => Verdict::Wrong {
            why: format!(
                "{} events where the exact answer has {}",
                times.0.len(),
                reference.events
            ),
        },
        _ => Verdict::Passed { final_error },
    };
    Ok(Row {
        case: case.to_string(),
        method: report.method.to_string(),
        verdict,
        events: o.events,
        reference_events: reference.events,
        energy_error: o.max_energy_error,
        wall_seconds: wall,
    })
}

/// The table of outcomes, as Markdown.
pub fn markdown(rows: &[Row]) -> String {
    let mut text = String::from(
        "| case | method | outcome | final error | energy error | events (exact) | wall s |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let (outcome, error) = match &r.verdict {
            Verdict::Passed { final_error } => ("passed".to_string(), format!("{final_error:.1e}")),
            Verdict::Failed { reason } => {
                (format!("failed: {}", reason.replace('|', "/")), "-".into())
            }
            Verdict::Drifted { why } => (format!("drifted: {why}"), "-".into()),
            Verdict::Wrong { why } => (format!("WRONG: {why}"), "-".into()),
        };
        let energy = r.energy_error.map_or("-".into(), |e| format!("{e:.1e}"));
        text += &format!(
            "| {} | {} | {} | {} | {} | {} ({}) | {:.2} |\n",
            r.case, r.method, outcome, error, energy, r.events, r.reference_events, r.wall_seconds
        );
    }
    text
}
