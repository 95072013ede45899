//! The mechanism scene as the command line and the tools see it
//! ([`SceneModel`]): its settings, its description, and what it runs,
//! samples, measures against and offers the tools, each handed to the
//! module that does it (`run.rs`, the family).

use crate::engine::Limits;
use crate::engine::Name;
use crate::engine::Observer;
use crate::engine::step::integrator::methods_for;
use crate::models::mechanism::ExactOrbit;
use crate::models::mechanism::scene::{
    Formulation, MechanismScene, regime, resolve_solver, with_model,
};
use crate::runner::{Report, Trajectory};
use crate::scene::Reference;
use crate::scene::solver::{SolverSpec, check_steps};
use crate::scene::{SceneError, SceneModel};

impl SceneModel for MechanismScene {
    fn model(&self) -> &'static str {
        "mechanism"
    }

    fn t_end(&self) -> f64 {
        self.t_end
    }

    fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError> {
        check_steps(self.method, t_end)?;
        self.t_end = t_end;
        Ok(())
    }

    fn solver(&self) -> &SolverSpec {
        &self.solver
    }

    fn set_solver(&mut self, spec: SolverSpec) -> Result<(), SceneError> {
        (self.method, self.tolerances) = resolve_solver(&spec, self.formulation, self.mechanism)?;
        check_steps(self.method, self.t_end)?;
        self.solver = spec;
        Ok(())
    }

    fn methods(&self) -> Vec<&'static str> {
        with_model(self.formulation, self.mechanism, |model, modes| {
            methods_for(model, modes)
        })
    }

    fn time_scale(&self) -> f64 {
        std::f64::consts::TAU / self.mechanism.omega
    }

    fn describe(&self) -> Vec<String> {
        let (eps, rate) = self.initial_strain;
        let h0 = self.mechanism.energy(eps, rate);
        let formulation = match self.formulation {
            Formulation::Strain => "strain formulation",
            Formulation::Angle(_) => "angle formulation",
        };
        vec![
            format!("{formulation}, method {}", self.method.name()),
            format!(
                "eta {}, omega {}, t_end {}",
                self.mechanism.eta, self.mechanism.omega, self.t_end
            ),
            format!(
                "initial strain {eps:e}, strain rate {rate:e}, energy H0 = {h0:e}: {}",
                regime(self.mechanism, h0, self.t_end)
            ),
        ]
    }

    fn run(&self, limits: &Limits, observer: &mut dyn Observer) -> Result<Report, SceneError> {
        super::run::run(self, limits, observer)
    }

    fn family(&self) -> Result<Box<dyn crate::engine::Family>, SceneError> {
        Ok(Box::new(super::family::MechanismFamily::new(self)))
    }

    fn offers_samples(&self) -> bool {
        true
    }

    fn sampled(
        &self,
        limits: &Limits,
        times: &[f64],
        observer: &mut dyn Observer,
    ) -> Option<Result<Trajectory, SceneError>> {
        Some(Trajectory::record(
            vec![Name::new("strain"), Name::new("strain_rate")],
            |on_sample| super::run::run_sampled(self, limits, times, on_sample, observer),
        ))
    }

    /// The closed form (46) of the strain with impacts every `T_imp`,
    /// whatever the formulation (both describe the same `eps(t)`).
    fn reference(&self) -> Result<Reference, SceneError> {
        let (eps, rate) = self.initial_strain;
        let orbit = ExactOrbit::new(self.mechanism, eps, rate);
        let (e, r) = orbit.state_at(self.t_end);
        Ok(Reference::new(
            "closed form (46) of the strain, impacts every T_imp",
            vec![e, r],
            orbit.impacts_until(self.t_end),
            move |k| orbit.impact_time(k),
        ))
    }

    /// `T_imp` of an impacting orbit that impacts before `t_end`.
    fn period(&self) -> Option<f64> {
        let (eps, rate) = self.initial_strain;
        let h0 = self.mechanism.energy(eps, rate);
        let impacts = ExactOrbit::new(self.mechanism, eps, rate).impacts_until(self.t_end);
        (h0 > 0.0 && impacts > 0).then(|| self.mechanism.impact_period(h0))
    }

    fn clone_box(&self) -> Box<dyn SceneModel> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
