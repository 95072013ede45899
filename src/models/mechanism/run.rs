//! Running a mechanism scene in the formulation and method it asks for.

use crate::engine::Limits;
use crate::engine::{Method, Name, Observer, Sample, simulate_sampled};
use crate::models::mechanism::scene::{Formulation, Initial, MechanismScene};
use crate::models::mechanism::strain::FLIGHT;
use crate::models::mechanism::{AngleMechanism, Charts, StrainMechanism};
use crate::runner::Report;
use crate::scene::SceneError;

pub(crate) fn run(
    scene: &MechanismScene,
    limits: &Limits,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    run_sampled(scene, limits, &[], &mut |_| {}, observer)
}

/// [`run`], the state at each of `times` passed to `on_sample`: the strain
/// and its rate, whichever formulation runs (the angle's charts are
/// mapped back to them).
pub(crate) fn run_sampled(
    scene: &MechanismScene,
    limits: &Limits,
    times: &[f64],
    on_sample: &mut dyn FnMut(&Sample),
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let options = limits.options(
        scene.t_end,
        scene.max_events,
        scene.method,
        scene.tolerances,
    );
    let (eps, rate) = scene.initial_strain;
    let strain_names = [Name::new("strain"), Name::new("strain_rate")];
    match scene.formulation {
        Formulation::Strain => {
            let model = StrainMechanism {
                mechanism: scene.mechanism,
            };
            let outcome = simulate_sampled(
                &model,
                FLIGHT,
                &[eps, rate],
                &options,
                times,
                on_sample,
                observer,
            );
            let final_state = strain_names
                .into_iter()
                .zip(outcome.final_state.iter().copied())
                .collect();
            let (method, description) = match scene.method {
                Method::Auto | Method::Exact => (
                    Method::Exact,
                    "strain formulation: closed-form flow (46) between impacts, impact times in closed form".to_string(),
                ),
                numerical => (numerical, format!("strain formulation: {}", numerical.describe())),
            };
            Ok(Report {
                outcome,
                method,
                description,
                final_state,
                fields: None,
                sensitivities: None,
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
            let mut in_strain = |s: &Sample| {
                let (e, r) = model.strain(s.mode, s.state);
                on_sample(&Sample {
                    state: &[e, r],
                    ..*s
                });
            };
            let outcome =
                simulate_sampled(&model, mode, &x0, &options, times, &mut in_strain, observer);
            let (e, r) = model.strain(outcome.final_mode, &outcome.final_state);
            let (method, integrator) = match scene.method {
                Method::Dop853(t) => (Method::Dop853(t), "DOP853"),
                _ => (Method::Dopri5(scene.tolerances), "Dormand-Prince 5(4)"),
            };
            let description = match charts {
                Charts::Switch => format!(
                    "angle formulation: equation (8) by {integrator}, switching to the strain chart near theta = 0"
                ),
                Charts::Plain => {
                    format!("angle formulation: equation (8) by {integrator}, no chart switching")
                }
            };
            Ok(Report {
                outcome,
                method,
                description,
                final_state: vec![(Name::new("strain"), e), (Name::new("strain_rate"), r)],
                fields: None,
                sensitivities: None,
            })
        }
    }
}
