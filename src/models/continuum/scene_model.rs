//! The continuum scene as the command line and the tools see it
//! ([`SceneModel`]): its settings, its description, and what it runs,
//! samples, measures against and offers the tools, each handed to the
//! module that does it (`run.rs`, the family).

use crate::engine::Limits;
use crate::engine::{Method, Observer};
use crate::models::continuum::Variant;
use crate::models::continuum::scene::{ContinuumScene, OWN_METHOD};
use crate::runner::Report;
use crate::scene::Reference;
use crate::scene::extent;
use crate::scene::solver::SolverSpec;
use crate::scene::{SceneError, SceneModel};

impl SceneModel for ContinuumScene {
    fn model(&self) -> &'static str {
        "continuum"
    }

    fn t_end(&self) -> f64 {
        self.t_end
    }

    fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError> {
        self.snapshots.retain(|&t| t <= t_end);
        self.t_end = t_end;
        Ok(())
    }

    fn solver(&self) -> &SolverSpec {
        &OWN_METHOD
    }

    /// Front tracking is exact and the only method offered.
    fn set_solver(&mut self, spec: SolverSpec) -> Result<(), SceneError> {
        let (method, _) = spec.resolve()?;
        if !matches!(method, Method::Auto | Method::Exact) {
            return Err(SceneError::field(
                "solver.method",
                format!(
                    "a continuum runs by its own method only (exact front tracking, or finite volumes for the homogenized string), not {}",
                    method.name()
                ),
            ));
        }
        Ok(())
    }

    fn methods(&self) -> Vec<&'static str> {
        vec!["exact"]
    }

    /// The time a wave at the bar speed takes to cross the string.
    fn time_scale(&self) -> f64 {
        self.length / self.wave_speed
    }

    fn describe(&self) -> Vec<String> {
        let method = match self.variant {
            Variant::Paper => "exact front tracking".to_string(),
            Variant::Homogenized => format!("finite volumes on {} cells", self.resolution),
        };
        vec![
            format!(
                "{} variant, {} initial cells, {method}",
                self.variant.name(),
                self.cells.len()
            ),
            extent::describe_string(
                self.length,
                self.wave_speed,
                (self.load_before, self.load_after),
                self.constraint,
                self.t_end,
            ),
            format!(
                "{} snapshots of {} points, {} trace samples",
                self.snapshots.len(),
                self.resolution,
                self.samples
            ),
        ]
    }

    fn run(&self, limits: &Limits, observer: &mut dyn Observer) -> Result<Report, SceneError> {
        super::run::run(self, limits, observer)
    }

    fn reference(&self) -> Result<Reference, SceneError> {
        Err(SceneError::field(
            "model",
            "method comparisons measure numerical methods against a closed form; a continuum runs by \
             exact front tracking only (`flicker compare-models` compares it with the chain)"
                .into(),
        ))
    }

    fn family(&self) -> Result<Box<dyn crate::engine::Family>, SceneError> {
        Err(SceneError::field(
            "model",
            "a continuum scene is a field with no finite state: orbits, sensitivities and \
             spectra need a finite one; write the chain it is the limit of (\"model\": \"chain\")"
                .into(),
        ))
    }

    fn clone_box(&self) -> Box<dyn SceneModel> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
