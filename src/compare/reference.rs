//! The exact answer a comparison measures against.

use crate::models::mechanism::ExactOrbit;
use crate::scene::{Scene, SceneError};

/// The final state and event times of the exact solution.
#[derive(Debug, Clone)]
pub struct Reference {
    /// How the reference was obtained, for the output.
    pub kind: &'static str,
    pub final_state: Vec<f64>,
    /// Events up to the end (saturating for chattering orbits).
    pub events: u64,
    orbit: ExactOrbit,
}

impl Reference {
    /// The time of event number `k` (from 0).
    pub fn event_time(&self, k: u64) -> f64 {
        self.orbit.impact_time(k)
    }

    /// The largest difference between `times` and the reference's event
    /// times, over the events both have; `None` if either has none.
    pub fn largest_time_error(&self, times: &[f64]) -> Option<f64> {
        let common = (times.len() as u64).min(self.events);
        (common > 0).then(|| {
            (0..common)
                .map(|k| (times[k as usize] - self.event_time(k)).abs())
                .fold(0.0, f64::max)
        })
    }
}

impl Reference {
    /// The mechanism's closed form (46) with impacts every `T_imp`, whatever
    /// the formulation (both describe the same `eps(t)`).
    /// Chains have no closed form to measure against and are refused.
    pub fn of(scene: &Scene) -> Result<Self, SceneError> {
        match scene {
            Scene::Mechanism(m) => {
                let (eps, rate) = m.initial_strain;
                let orbit = ExactOrbit::new(m.mechanism, eps, rate);
                let (e, r) = orbit.state_at(m.t_end);
                Ok(Reference {
                    kind: "closed form (46) of the strain, impacts every T_imp",
                    final_state: vec![e, r],
                    events: orbit.impacts_until(m.t_end),
                    orbit,
                })
            }
            Scene::Chain(_) => Err(SceneError::field(
                "model",
                "method comparisons measure against the mechanism's closed form; a chain scene has none \
                 (its exact and ODE paths are checked against each other in tests/flicker/chain_exact.rs)"
                    .into(),
            )),
            Scene::Continuum(_) => Err(SceneError::field(
                "model",
                "method comparisons measure numerical methods against a closed form; a continuum runs by \
                 exact front tracking only (`flicker compare-models` compares it with the chain)"
                    .into(),
            )),
        }
    }
}
