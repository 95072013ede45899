//! Running a validated scene: build its model, pick its method, run it, and
//! describe the result in the scene's own terms.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::engine::{Method, Observer, Options, Outcome, simulate};
use crate::models::mechanism::strain::FLIGHT;
use crate::models::mechanism::{AngleMechanism, Charts, StrainMechanism};
use crate::scene::{Formulation, Initial, MechanismScene, Scene, SceneError};

/// A finished run and what the summary needs to say about it.
#[derive(Debug, Clone)]
pub struct Report {
    pub outcome: Outcome,
    /// The method used, in the names `flicker compare` uses (`exact`, `dopri5`).
    pub method: &'static str,
    /// A sentence saying which description of the model was used and why.
    pub description: String,
    /// The final state in the scene's physical variables.
    pub final_state: Vec<(&'static str, f64)>,
}

/// What may stop a run from outside the scene.
#[derive(Debug, Clone, Default)]
pub struct Control {
    /// Interrupts the run cleanly when set (a signal handler sets it).
    pub stop: Option<Arc<AtomicBool>>,
    /// Fails the run after this much wall time.
    pub max_wall_seconds: Option<f64>,
}

/// Run `scene` under `control`.
pub fn run(
    scene: &Scene,
    control: &Control,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    match scene {
        Scene::Mechanism(m) => run_mechanism(m, control, observer),
    }
}

fn run_mechanism(
    scene: &MechanismScene,
    control: &Control,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let options = Options {
        t_end: scene.t_end,
        max_events: scene.max_events,
        method: scene.method,
        tolerances: scene.tolerances,
        stop: control.stop.clone(),
        max_wall_seconds: control.max_wall_seconds,
    };
    let (eps, rate) = scene.initial_strain;
    let strain_names = ["strain", "strain_rate"];
    match scene.formulation {
        Formulation::Strain => {
            let model = StrainMechanism {
                mechanism: scene.mechanism,
            };
            let outcome = simulate(&model, FLIGHT, &[eps, rate], &options, observer);
            let final_state = strain_names
                .into_iter()
                .zip(outcome.final_state.iter().copied())
                .collect();
            let (method, description) = match scene.method {
                Method::Auto | Method::Exact => (
                    "exact",
                    "strain formulation: closed-form flow (46) between impacts, impact times in closed form".to_string(),
                ),
                Method::Linear => (
                    "linear",
                    "strain formulation: exact linear propagator (matrix exponential), impacts located on it".into(),
                ),
                Method::Dopri5(tol) => (
                    "dopri5",
                    format!("strain formulation: Dormand-Prince 5(4), rtol {:e}, atol {:e}", tol.rtol, tol.atol),
                ),
                Method::Verlet { step } => ("verlet", format!("strain formulation: Stormer-Verlet, step {step:e}")),
            };
            Ok(Report {
                outcome,
                method,
                description,
                final_state,
            })
        }
        Formulation::Angle(charts) => {
            let model = AngleMechanism {
                mechanism: scene.mechanism,
                charts,
            };
            let (mode, x0) = match scene.initial {
                Initial::Angle { angle, rate } => model.start_from_angle(angle, rate),
                _ => model
                    .start_from_strain(eps, rate)
                    .map_err(|reason| SceneError::field("initial", reason))?,
            };
            let outcome = simulate(&model, mode, &x0, &options, observer);
            let (e, r) = model.strain(outcome.final_mode, &outcome.final_state);
            let description = match charts {
                Charts::Switch => {
                    "angle formulation: equation (8) by Dormand-Prince 5(4), switching to the strain chart near theta = 0"
                }
                Charts::Plain => {
                    "angle formulation: equation (8) by Dormand-Prince 5(4), no chart switching"
                }
            };
            Ok(Report {
                outcome,
                method: "dopri5",
                description: description.into(),
                final_state: vec![("strain", e), ("strain_rate", r)],
            })
        }
    }
}
