//! The exact answer a comparison measures against.

use crate::models::mechanism::ExactOrbit;
use crate::scene::Scene;

/// The final state and event times of the exact solution.
#[derive(Debug, Clone)]
pub struct Reference {
    /// How the reference was obtained, for the output.
    pub kind: &'static str,
    pub final_state: Vec<f64>,
    pub event_times: Vec<f64>,
}

impl Reference {
    /// The mechanism's closed form (46) with impacts every `T_imp`, whatever
    /// the formulation (both describe the same `eps(t)`).
    pub fn of(scene: &Scene) -> Self {
        match scene {
            Scene::Mechanism(m) => {
                let (eps, rate) = m.initial_strain;
                let orbit = ExactOrbit::new(m.mechanism, eps, rate);
                let (e, r) = orbit.state_at(m.t_end);
                Reference {
                    kind: "closed form (46) of the strain, impacts every T_imp",
                    final_state: vec![e, r],
                    event_times: orbit.impact_times_until(m.t_end),
                }
            }
        }
    }
}
