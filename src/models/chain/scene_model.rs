//! The chain scene as the command line and the tools see it
//! ([`SceneModel`]): its settings, its description, and what it runs,
//! samples, measures against and offers the tools, each handed to the
//! module that does it (`run.rs`, the family, the ensemble).

use crate::engine::Limits;
use crate::engine::Observer;
use crate::engine::step::integrator::methods_for;
use crate::models::chain::scene::{ChainScene, MAX_ODE_UNITS, resolve_solver};
use crate::runner::Report;
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest};
use crate::scene::Reference;
use crate::scene::extent;
use crate::scene::solver::{SolverSpec, check_steps};
use crate::scene::{SceneError, SceneModel};

impl SceneModel for ChainScene {
    fn model(&self) -> &'static str {
        "chain"
    }

    fn t_end(&self) -> f64 {
        self.t_end
    }

    /// A shortened run takes the snapshots it reaches.
    fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError> {
        check_steps(self.method, t_end)?;
        self.snapshots.retain(|&t| t <= t_end);
        self.t_end = t_end;
        Ok(())
    }

    fn solver(&self) -> &SolverSpec {
        &self.solver
    }

    fn set_solver(&mut self, spec: SolverSpec) -> Result<(), SceneError> {
        (self.method, self.tolerances) = resolve_solver(&spec, self.units)?;
        check_steps(self.method, self.t_end)?;
        self.solver = spec;
        Ok(())
    }

    /// The exact Taylor flow, and what the engine's rules let run the
    /// chain as an ODE up to [`MAX_ODE_UNITS`].
    fn methods(&self) -> Vec<&'static str> {
        let mut methods = vec!["exact"];
        if self.units <= MAX_ODE_UNITS {
            let ode = methods_for(&self.chain(self.constraint), &[0]);
            methods.extend(ode.into_iter().filter(|m| *m != "exact"));
        }
        methods
    }

    /// The time a wave at the bar speed takes to cross the chain.
    fn time_scale(&self) -> f64 {
        self.length / self.wave_speed
    }

    fn describe(&self) -> Vec<String> {
        vec![
            format!("{} units, method {}", self.units, self.method.name()),
            extent::describe_string(
                self.length,
                self.wave_speed,
                (self.load_before, self.load_after),
                self.constraint,
                self.t_end,
            ),
            format!(
                "{} snapshots, {} trace samples",
                self.snapshots.len(),
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
            "method comparisons measure against the mechanism's closed form; a chain scene has none \
             (its exact and ODE paths are checked against each other in tests/flicker/chain_exact.rs)"
                .into(),
        ))
    }

    fn family(&self) -> Result<Box<dyn crate::engine::Family>, SceneError> {
        Ok(Box::new(super::family::ChainFamily::new(self)))
    }

    fn check_ensemble(&self, request: &EnsembleRequest) -> Result<(), SceneError> {
        super::ensemble::check(self, request)
    }

    fn ensemble(
        &self,
        request: &EnsembleRequest,
        limits: &Limits,
    ) -> Result<EnsembleReport, String> {
        super::ensemble::run_ensemble(self, request, limits).map(|e| super::ensemble::report(&e))
    }

    fn clone_box(&self) -> Box<dyn SceneModel> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
