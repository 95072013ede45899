//! Phase planes, as `flicker plot phase` asks them: the mechanism's
//! portrait (level sets beside simulated trajectories), or any two states
//! of a scene's run.

use crate::engine::Limits;
use crate::models::mechanism::Mechanism;
use crate::plot::draw::Figure;
use crate::plot::phase::{Plane, Portrait};
use crate::runner::Report;
use crate::scene::Scene;

/// The mechanism's portrait at load ratio `eta` and frequency `omega`
/// (checked by the caller: `omega > 0`, both finite) in `plane`.
pub fn mechanism_portrait(eta: f64, omega: f64, plane: Plane) -> Portrait {
    Portrait::new(Mechanism { eta, omega }, plane)
}

/// States `x` and `y` of `scene`'s run against each other, sampled at
/// `samples` evenly spaced times, under `limits`: the picture and the
/// run's report, or why it cannot be drawn.
pub fn state_plane(
    scene: &Scene,
    (x, y): (&str, &str),
    samples: usize,
    limits: &Limits,
) -> Result<(Figure, Report), String> {
    crate::plot::plane::state_plane(scene, x, y, samples, limits)
}
