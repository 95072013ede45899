//! Every method on one scene, measured against its exact answer, as
//! `flicker compare` and Python's `compare()` ask it.

use crate::analysis::work_precision::{self, Plan, Row};
use crate::engine::Limits;
use crate::scene::{Reference, Scene, SceneError};

/// A comparison as asked: each unset list takes its default.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CompareRequest {
    /// Methods by name (default: every method the model offers).
    pub methods: Option<Vec<String>>,
    /// Tolerances of the adaptive methods (`rtol = atol`).
    pub tolerances: Option<Vec<f64>>,
    /// Fixed steps (default: fractions of the scene's time scale).
    pub steps: Option<Vec<f64>>,
}

impl CompareRequest {
    /// The request checked against `scene`, before anything runs; the
    /// error names `methods`, `tolerances` or `steps`.
    pub fn on(&self, scene: Scene) -> Result<Comparison, SceneError> {
        let plan = Plan::new(
            &scene,
            self.methods.clone(),
            self.tolerances.clone(),
            self.steps.clone(),
        )?;
        Ok(Comparison { scene, plan })
    }
}

/// A comparison checked against its scene, ready to run.
#[derive(Debug)]
pub struct Comparison {
    scene: Scene,
    plan: Plan,
}

impl Comparison {
    /// Run every setting under `limits` (whose stop and deadline end it
    /// between runs), telling `progress` of each row: the reference
    /// measured against, and the rows.
    pub fn run(
        &self,
        limits: &Limits,
        progress: &mut dyn FnMut(&Row),
    ) -> Result<(Reference, Vec<Row>), SceneError> {
        work_precision::compare(&self.scene, &self.plan, limits, progress)
    }
}
