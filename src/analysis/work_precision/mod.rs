//! `flicker compare`: one scene, every method over a range of tolerances or
//! steps, each run measured against the exact answer.
//!
//! A row per run: its cost (wall time, the median of a few repeats, and flow
//! evaluations) beside its errors (final state, event times and energy,
//! against the [`Reference`]) and the bounds the run stated on them. [`chart`] draws error against cost.

pub mod chart;

use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::engine::step::method::{NAMES, Setting, setting};
use crate::engine::{EachEvent, Status};
use crate::scene::Reference;
use crate::scene::solver::SolverSpec;
use crate::scene::{Scene, SceneError};

/// Default Dormand-Prince tolerances (`rtol = atol`).
pub const TOLERANCES: [f64; 9] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12];
/// Default Stormer-Verlet steps, as fractions of the period `2 pi / omega`.
pub const STEP_FRACTIONS: [f64; 6] = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4];

/// One run of one method at one setting.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Row {
    /// The method run, by the name `--method` takes.
    pub method: String,
    /// Its tolerance (`rtol = atol`), for the adaptive methods.
    pub tolerance: Option<f64>,
    /// Its fixed step, for Stormer-Verlet.
    pub step: Option<f64>,
    /// Wall time of one run, in seconds: the median of the repeats.
    pub wall_seconds: f64,
    /// Evaluations of the flow ([`Outcome::flow_evaluations`]).
    ///
    /// [`Outcome::flow_evaluations`]: crate::engine::Outcome::flow_evaluations
    pub flow_evals: u64,
    /// Events the run took.
    pub events: u64,
    /// Largest difference of a final state component from the reference's.
    pub final_error: f64,
    /// Largest difference of an event time from the reference's, over the
    /// events both have; `None` if either has none.
    pub max_event_time_error: Option<f64>,
    /// Largest relative energy error the run saw, for a model with an energy.
    pub energy_error: Option<f64>,
    /// The bound the run stated on its final state's error, where it
    /// carries one ([`Outcome::error_bound`]).
    ///
    /// [`Outcome::error_bound`]: crate::engine::Outcome::error_bound
    pub error_bound: Option<f64>,
    /// The bound it stated on its event times' errors, where it tracks them
    /// ([`Outcome::event_time_bound`]).
    ///
    /// [`Outcome::event_time_bound`]: crate::engine::Outcome::event_time_bound
    pub event_time_bound: Option<f64>,
    /// `completed`, `zeno`, `failed: <reason>` or `events differ: ...`.
    pub status: String,
}

/// Which settings to try for each method.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The methods to run, by name.
    pub methods: Vec<String>,
    /// Tolerances (`rtol = atol`) to run the adaptive methods at.
    pub tolerances: Vec<f64>,
    /// Fixed steps; `None` picks fractions of the scene's period.
    pub steps: Option<Vec<f64>>,
}

impl Plan {
    /// The plan made of `flicker compare`'s flags for `scene`: `methods`
    /// (default: every method its model can run), `tolerances` (default
    /// [`TOLERANCES`]), `steps` (default: fractions of its time scale);
    /// refused, naming `methods`, `tolerances` or `steps`, where a method is
    /// unknown or a value is not a finite number > 0.
    pub fn new(
        scene: &Scene,
        methods: Option<Vec<String>>,
        tolerances: Option<Vec<f64>>,
        steps: Option<Vec<f64>>,
    ) -> Result<Plan, SceneError> {
        let methods =
            methods.unwrap_or_else(|| scene.methods().into_iter().map(str::to_string).collect());
        if let Some(bad) = methods.iter().find(|m| !NAMES.contains(&m.as_str())) {
            return Err(SceneError::field(
                "methods",
                format!("unknown method {bad:?} (known: {})", NAMES.join(", ")),
            ));
        }
        for (key, values) in [("tolerances", &tolerances), ("steps", &steps)] {
            if values
                .iter()
                .flatten()
                .any(|x| !(x.is_finite() && *x > 0.0))
            {
                return Err(SceneError::field(
                    key,
                    "every value must be a finite number > 0".into(),
                ));
            }
        }
        Ok(Plan {
            methods,
            tolerances: tolerances.unwrap_or_else(|| TOLERANCES.to_vec()),
            steps,
        })
    }
}

/// Run every method of `plan` on `scene` and measure it against the
/// reference; `limits`'s stop flag ends the comparison between runs and
/// interrupts the one under way.
pub fn compare(
    scene: &Scene,
    plan: &Plan,
    limits: &crate::engine::Limits,
    progress: &mut dyn FnMut(&Row),
) -> Result<(Reference, Vec<Row>), SceneError> {
    let reference = scene.reference()?;
    let mut rows = Vec::new();
    for method in &plan.methods {
        let settings: Vec<SolverSpec> = match setting(method) {
            Some(Setting::Tolerances) => plan
                .tolerances
                .iter()
                .map(|&tol| spec(method, Some(tol), None))
                .collect(),
            Some(Setting::Step) => plan
                .steps
                .clone()
                .unwrap_or_else(|| {
                    STEP_FRACTIONS
                        .iter()
                        .map(|f| f * scene.time_scale())
                        .collect()
                })
                .into_iter()
                .map(|h| spec(method, None, Some(h)))
                .collect(),
            _ => vec![spec(method, None, None)],
        };
        for setting in settings {
            if limits.stopped() {
                return Err(SceneError {
                    file: None,
                    field: None,
                    reason: limits.stop_reason().into(),
                    untrusted: true,
                });
            }
            let mut run_scene = scene.clone();
            run_scene.set_solver(setting.clone())?;
            let row = measure(&run_scene, &setting, &reference, limits)?;
            progress(&row);
            rows.push(row);
        }
    }
    Ok((reference, rows))
}

/// Read rows back from a `compare.csv`.
pub fn read_csv(path: &Path) -> Result<Vec<Row>, csv::Error> {
    csv::Reader::from_path(path)?.deserialize().collect()
}

/// Write `rows` as CSV to `path`.
pub fn write_csv(rows: &[Row], path: &Path) -> Result<(), csv::Error> {
    let mut writer = csv::Writer::from_path(path)?;
    for row in rows {
        writer.serialize(row)?;
    }
    writer.flush()?;
    Ok(())
}

fn spec(method: &str, tolerance: Option<f64>, step: Option<f64>) -> SolverSpec {
    SolverSpec {
        method: Some(method.to_string()),
        rtol: tolerance,
        atol: tolerance,
        step,
    }
}

/// Repeats of a run for its timing: at least 3, and until 50 ms have passed.
fn measure(
    scene: &Scene,
    setting: &SolverSpec,
    reference: &Reference,
    limits: &crate::engine::Limits,
) -> Result<Row, SceneError> {
    let start = Instant::now();
    let run = reference.measure(scene, limits)?;
    let mut walls = vec![start.elapsed().as_secs_f64()];
    while !limits.stopped()
        && (walls.len() < 3 || (walls.iter().sum::<f64>() < 0.05 && walls.len() < 1000))
    {
        let start = Instant::now();
        // Every event fired, as in the measured run: a run that looks at
        // none would jump over a periodic orbit's periods.
        scene.run(limits, &mut EachEvent)?;
        walls.push(start.elapsed().as_secs_f64());
    }
    walls.sort_by(f64::total_cmp);
    let (report, times) = (&run.report, &run.times);
    let o = &report.outcome;
    let (final_error, max_event_time_error) = (run.final_error, run.time_error);
    let status = match (o.status, &o.reason) {
        (Status::Failed, Some(reason)) => format!("failed: {reason}"),
        // The run stopped at the accumulation it could no longer resolve;
        // the exact answer counts on without end.
        (Status::Zeno, _) if reference.events == u64::MAX => "zeno".into(),
        _ if times.len() as u64 != reference.events => format!(
            "events differ: {} against {} in the reference",
            times.len(),
            reference.events
        ),
        (status, _) => status.as_str().to_string(),
    };
    Ok(Row {
        method: report.method.to_string(),
        tolerance: setting.rtol,
        step: setting.step,
        wall_seconds: walls[walls.len() / 2],
        flow_evals: o.flow_evaluations,
        events: o.events,
        final_error,
        max_event_time_error,
        energy_error: o.max_energy_error,
        error_bound: o.error_bound,
        event_time_bound: o.event_time_bound,
        status,
    })
}
