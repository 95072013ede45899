//! Where methods fail: every stress scene run with every method its model
//! offers, each run either verified against the exact answer or failed with
//! its reason. A third outcome, a wrong answer given without complaint, is
//! what this exists to rule out (`tests/flicker/stress.rs` checks it).
//!
//! `flicker stress models/stress --markdown` prints the table that
//! `docs/stress.md` holds. Bundled automata with a closed form are measured
//! against it ([`closed_forms`]); the others against their tightest run.

use std::path::{Path, PathBuf};
use std::time::Instant;

pub mod closed_forms;

use crate::engine::step::method::{Setting, setting};
use crate::engine::{Limits, Status};
use crate::scene::solver::SolverSpec;
use crate::scene::{Registry, Scene, SceneError};

/// Dormand-Prince's tolerance in the suite.
pub const TOLERANCE: f64 = 1e-9;
/// Stormer-Verlet's step in the suite, as a fraction of the period.
pub const STEP_FRACTION: f64 = 1.0 / 200.0;

/// How one run of one method on one case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// The exact answer's events (or the same Zeno point), with the final
    /// state and every event time within the bounds the run stated.
    Passed,
    /// The run said it could not be trusted, and why.
    Failed {
        /// The run's own reason.
        reason: String,
    },
    /// The exact answer's events, but a final state or an event time
    /// further off than the run's own bound: the bound was wrong.
    Drifted {
        /// Which error exceeded which bound, by how much.
        why: String,
    },
    /// A different answer given without complaint.
    Wrong {
        /// How the answer differs: its event count against the exact one.
        why: String,
    },
}

/// One run measured against the exact answer: what [`classify`] judges.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// How the run ended.
    pub status: Status,
    /// Why the run is not plainly completed, if it is not.
    pub reason: Option<String>,
    /// Events logged (impacts).
    pub events: u64,
    /// The exact answer's count of events (`u64::MAX`: without end).
    pub reference_events: u64,
    /// Largest difference of a final state component from the exact one.
    pub final_error: f64,
    /// Largest difference of an event time from the exact one, over the
    /// events both have.
    pub time_error: Option<f64>,
    /// The bound the run stated on its final state's error
    /// ([`Outcome::error_bound`](crate::engine::Outcome::error_bound)),
    /// where it carries one.
    pub error_bound: Option<f64>,
    /// The bound it stated on its event times' errors, where it tracks
    /// them ([`Outcome::event_time_bound`](crate::engine::Outcome::event_time_bound)).
    pub event_time_bound: Option<f64>,
}

/// The verdict on a run: `passed` only if its errors are within the bounds
/// it stated itself, `failed` if it said it could not be trusted,
/// `drifted` if it kept the exact answer's events but not its own bounds,
/// `wrong` if it completed with other events.
pub fn classify(m: &Measured) -> Verdict {
    if matches!(m.status, Status::Failed | Status::Interrupted) {
        return Verdict::Failed {
            reason: m.reason.clone().unwrap_or_default(),
        };
    }
    // A Zeno run settles after the events it can resolve; the exact
    // answer counts them on (for chattering, without end).
    if m.status != Status::Zeno && m.events != m.reference_events {
        return Verdict::Wrong {
            why: format!(
                "{} events where the exact answer has {}",
                m.events, m.reference_events
            ),
        };
    }
    match m.error_bound {
        Some(bound) if !(m.final_error <= bound) => {
            return Verdict::Drifted {
                why: format!(
                    "final state {:.1e} off, beyond its stated bound {bound:.1e}",
                    m.final_error
                ),
            };
        }
        None => {
            return Verdict::Drifted {
                why: "the run states no bound on its final state".into(),
            };
        }
        Some(_) => {}
    }
    match (m.time_error, m.event_time_bound) {
        (Some(e), Some(bound)) if !(e <= bound) => Verdict::Drifted {
            why: format!("an event time {e:.1e} off, beyond its stated bound {bound:.1e}"),
        },
        (Some(_), None) => Verdict::Drifted {
            why: "the run states no bound on its event times".into(),
        },
        _ => Verdict::Passed,
    }
}

/// One run of the table.
#[derive(Debug, Clone)]
pub struct Row {
    /// The case: the stress scene's file name without `.json`.
    pub case: String,
    /// The method run, by the name `--method` takes.
    pub method: String,
    /// How the run is judged.
    pub verdict: Verdict,
    /// What the verdict was judged from.
    pub measured: Measured,
    /// Largest relative energy error the run saw, for a model with an energy.
    pub energy_error: Option<f64>,
    /// Wall time of the run, in seconds.
    pub wall_seconds: f64,
}

/// The stress scenes in `dir` (of models `registry` knows), sorted by name.
pub fn cases(dir: &Path, registry: &Registry) -> Result<Vec<(String, Scene)>, SceneError> {
    let entries = std::fs::read_dir(dir).map_err(|e| SceneError {
        file: Some(dir.to_path_buf()),
        field: None,
        reason: format!("cannot be read: {e}"),
        untrusted: false,
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
                registry.load(p)?,
            ))
        })
        .collect()
}

/// The suite's setting of each method the scene's model offers.
pub fn settings(scene: &Scene) -> Vec<SolverSpec> {
    // Only a scene with an exact answer can be judged.
    if scene.reference().is_err() {
        return Vec::new();
    }
    let step = scene.time_scale() * STEP_FRACTION;
    scene
        .methods()
        .into_iter()
        .map(|method| {
            let (tol, step) = match setting(method) {
                // Taylor's method at its own default, machine precision:
                // the suite judges it where it is meant to run.
                Some(Setting::Tolerances) if method == "taylor" => (None, None),
                Some(Setting::Tolerances) => (Some(TOLERANCE), None),
                Some(Setting::Step) => (None, Some(step)),
                _ => (None, None),
            };
            SolverSpec {
                method: Some(method.into()),
                rtol: tol,
                atol: tol,
                step,
            }
        })
        .collect()
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
    let reference = closed_forms::reference(case, &scene).unwrap_or_else(|| scene.reference())?;
    let limits = Limits {
        stop: None,
        max_wall_seconds: Some(wall_seconds),
        ..Limits::default()
    };
    let start = Instant::now();
    let run = reference.measure(&scene, &limits)?;
    let wall = start.elapsed().as_secs_f64();
    let (report, o) = (&run.report, &run.report.outcome);
    let measured = Measured {
        status: o.status,
        reason: o.reason.clone(),
        events: run.times.len() as u64,
        reference_events: reference.events,
        final_error: run.final_error,
        time_error: run.time_error,
        // A reference that is itself a run is off by its own bound too.
        error_bound: o.error_bound.map(|b| b + reference.error_bound),
        event_time_bound: o.event_time_bound.map(|b| b + reference.event_time_bound),
    };
    Ok(Row {
        case: case.to_string(),
        method: report.method.to_string(),
        verdict: classify(&measured),
        measured,
        energy_error: o.max_energy_error,
        wall_seconds: wall,
    })
}

impl Measured {
    /// How many times its error the run's bound on its final state is
    /// (`None` where the error is zero: nothing to measure the bound by).
    pub fn state_ratio(&self) -> Option<f64> {
        self.error_bound
            .and_then(|bound| ratio(bound, Some(self.final_error)))
    }

    /// The same for its event times.
    pub fn time_ratio(&self) -> Option<f64> {
        self.event_time_bound
            .and_then(|bound| ratio(bound, self.time_error))
    }
}

fn ratio(bound: f64, error: Option<f64>) -> Option<f64> {
    error
        .filter(|e| *e > 0.0 && e.is_finite())
        .map(|e| bound / e)
}

/// The table of outcomes, as Markdown: each run's errors beside the
/// bounds it stated, and how many times its errors the bounds are.
pub fn markdown(rows: &[Row]) -> String {
    let mut text = String::from(
        "| case | method | outcome | final error | error bound | bound / error | event-time error | event-time bound | bound / error | energy error | events (exact) | wall s |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let number = |x: Option<f64>| x.map_or("-".into(), |e| format!("{e:.1e}"));
    for r in rows {
        let m = &r.measured;
        let outcome = match &r.verdict {
            Verdict::Passed => "passed".to_string(),
            Verdict::Failed { reason } => format!("failed: {}", reason.replace('|', "/")),
            Verdict::Drifted { why } => format!("DRIFTED: {why}"),
            Verdict::Wrong { why } => format!("WRONG: {why}"),
        };
        let reference = match m.reference_events {
            u64::MAX => "unbounded".to_string(),
            n => n.to_string(),
        };
        let ratio = |x: Option<f64>| x.map_or("-".into(), |r| format!("{r:.1e}"));
        text += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} ({}) | {:.2} |\n",
            r.case,
            r.method,
            outcome,
            number(Some(m.final_error)),
            number(m.error_bound),
            ratio(m.state_ratio()),
            number(m.time_error),
            number(m.event_time_bound),
            ratio(m.time_ratio()),
            number(r.energy_error),
            m.events,
            reference,
            r.wall_seconds
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run that completed with the exact answer's 32 events, within its
    /// bounds: each test below breaks one thing.
    fn sound() -> Measured {
        Measured {
            status: Status::Completed,
            reason: None,
            events: 32,
            reference_events: 32,
            final_error: 1e-9,
            time_error: Some(1e-8),
            error_bound: Some(2e-9),
            event_time_bound: Some(2e-8),
        }
    }

    #[test]
    fn a_run_within_its_bounds_passes() {
        assert_eq!(classify(&sound()), Verdict::Passed);
    }

    #[test]
    fn a_final_state_beyond_its_bound_drifted() {
        let m = Measured {
            final_error: 1.7e-4,
            ..sound()
        };
        assert!(matches!(classify(&m), Verdict::Drifted { .. }));
        let m = Measured {
            final_error: f64::NAN,
            ..sound()
        };
        assert!(matches!(classify(&m), Verdict::Drifted { .. }));
        // A run that carries no bound has none to be within.
        let m = Measured {
            error_bound: None,
            ..sound()
        };
        assert!(matches!(classify(&m), Verdict::Drifted { .. }));
    }

    #[test]
    fn a_shifted_event_time_drifted() {
        let m = Measured {
            time_error: Some(9.6e-4),
            ..sound()
        };
        assert!(matches!(classify(&m), Verdict::Drifted { .. }));
        let m = Measured {
            event_time_bound: None,
            ..sound()
        };
        assert!(matches!(classify(&m), Verdict::Drifted { .. }));
    }

    #[test]
    fn a_dropped_or_extra_event_is_wrong_whatever_the_bounds() {
        for events in [31, 33] {
            let m = Measured {
                events,
                error_bound: Some(f64::INFINITY),
                event_time_bound: Some(f64::INFINITY),
                ..sound()
            };
            assert!(matches!(classify(&m), Verdict::Wrong { .. }), "{events}");
        }
    }

    #[test]
    fn a_run_that_says_it_failed_is_failed_with_its_reason() {
        let m = Measured {
            status: Status::Failed,
            reason: Some("grazes zero".into()),
            events: 3,
            final_error: 1.0,
            ..sound()
        };
        assert_eq!(
            classify(&m),
            Verdict::Failed {
                reason: "grazes zero".into()
            }
        );
    }

    #[test]
    fn a_settled_zeno_run_is_judged_by_its_state_not_its_count() {
        let settled = Measured {
            status: Status::Zeno,
            events: 10,
            reference_events: u64::MAX,
            ..sound()
        };
        assert_eq!(classify(&settled), Verdict::Passed);
        let elsewhere = Measured {
            final_error: 1e-3,
            ..settled
        };
        assert!(matches!(classify(&elsewhere), Verdict::Drifted { .. }));
    }
}
