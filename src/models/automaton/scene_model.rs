//! The automaton scene as the command line and the tools see it
//! ([`SceneModel`]): its settings, its description, and what it runs,
//! samples, measures against and offers the tools, each handed to the
//! module that does it (`run.rs`, the family, the ensemble).

use crate::engine::Limits;
use crate::engine::bound::zeno;
use crate::engine::step::integrator::{methods_for, runs};
use crate::engine::{
    EventTimes, Family, HybridModel, Method, Observer, Status, Tolerances, step::taylor_method,
};
use crate::models::automaton::scene::AutomatonScene;
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest};
use crate::runner::{Report, Trajectory};
use crate::scene::Reference;
use crate::scene::solver::{SolverSpec, check_steps};
use crate::scene::{SceneError, SceneModel};

impl SceneModel for AutomatonScene {
    fn model(&self) -> &'static str {
        "automaton"
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
        let (method, tolerances) = spec.resolve()?;
        if method != Method::Auto {
            let modes = self.automaton.modes();
            runs(&*self.automaton, &modes, method).map_err(|why| {
                SceneError::field(
                    "solver.method",
                    format!("{why} (this automaton runs {})", self.methods().join(", ")),
                )
            })?;
        }
        check_steps(method, self.t_end)?;
        (self.method, self.tolerances, self.solver) = (method, tolerances, spec);
        Ok(())
    }

    fn methods(&self) -> Vec<&'static str> {
        methods_for(&*self.automaton, &self.automaton.modes())
    }

    /// The shortest period `2 pi / |lambda|` of the linear modes' flows, or
    /// a hundredth of `t_end` where no mode is linear.
    fn time_scale(&self) -> f64 {
        let model = &*self.automaton;
        let rates = self.automaton.modes().into_iter().filter_map(|m| {
            let (a, _) = model.linear(m)?;
            let rho = a
                .complex_eigenvalues()
                .iter()
                .map(|l| l.norm())
                .fold(0.0, f64::max);
            (rho > 0.0).then(|| std::f64::consts::TAU / rho)
        });
        rates
            .fold(None, |s: Option<f64>, p| Some(s.map_or(p, |s| s.min(p))))
            .unwrap_or(self.t_end / 100.0)
    }

    fn describe(&self) -> Vec<String> {
        let model = &*self.automaton;
        let d = &self.definition;
        let mut lines = vec![format!(
            "{} state(s) ({}){}, {} parameter(s), t_end {}",
            d.states.len(),
            d.states.join(", "),
            if model.has_clock() {
                " and the clock t"
            } else {
                ""
            },
            d.parameters.len(),
            self.t_end
        )];
        let traits_of = |m: crate::engine::Mode| {
            let mut traits = Vec::new();
            if model.is_linear(m) {
                traits.push("affine flow");
            } else if model.has_affine_flow(m) {
                // x' = A x + b + sines of t: the linear propagator's too.
                traits.push("affine flow driven by sines of t");
            } else if model.constant_jacobian(m).is_some() {
                // x' = A x + f(t): its errors move by exp(tau A).
                traits.push("affine flow driven by t");
            }
            if model.second_order(m) {
                traits.push("second order");
            }
            traits
        };
        for (i, mode) in d.modes.iter().enumerate() {
            let expanded = model.modes_of(i);
            let traits = if expanded.len() == 1 {
                traits_of(expanded[0])
            } else {
                Vec::new()
            };
            let transitions: Vec<String> = mode
                .transitions
                .iter()
                .map(|t| {
                    let to = &d.modes[t.to].name;
                    format!("`{}` -> {to}", t.name)
                })
                .collect();
            lines.push(format!(
                "mode {}{}{}: {}",
                mode.name,
                if i == d.initial_mode {
                    " (initial)"
                } else {
                    ""
                },
                if traits.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", traits.join(", "))
                },
                if transitions.is_empty() {
                    "no transitions".into()
                } else {
                    transitions.join(", ")
                }
            ));
            // A flow that reads sign(): its regions and sliding modes.
            if expanded.len() > 1 {
                let parts: Vec<String> = expanded
                    .iter()
                    .map(|&m| {
                        let traits = traits_of(m);
                        if traits.is_empty() {
                            model.mode_name(m).to_string()
                        } else {
                            format!("{} [{}]", model.mode_name(m), traits.join(", "))
                        }
                    })
                    .collect();
                lines.push(format!(
                    "  switches its flow by sign(): as Filippov's regions and sliding modes {}",
                    parts.join(", ")
                ));
            }
        }
        lines.push(format!("regime: {}", self.regime()));
        let (method, why) = self.resolved();
        lines.push(format!("method {}: {why}", method.name()));
        lines.push(format!(
            "methods that can run it: {}",
            self.methods().join(", ")
        ));
        lines
    }

    fn run(&self, limits: &Limits, observer: &mut dyn Observer) -> Result<Report, SceneError> {
        self.run_sampled(limits, &[], &mut |_| {}, observer)
    }

    fn family(&self) -> Result<Box<dyn Family>, SceneError> {
        Ok(Box::new(self.clone()))
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
        let names = self.automaton.state_names(0).to_vec();
        Some(Trajectory::record(names, |on_sample| {
            self.run_sampled(limits, times, on_sample, observer)
        }))
    }

    fn check_ensemble(&self, request: &EnsembleRequest) -> Result<(), SceneError> {
        super::ensemble::check(self, request)
    }

    fn ensemble(
        &self,
        request: &EnsembleRequest,
        limits: &Limits,
    ) -> Result<EnsembleReport, String> {
        super::ensemble::run(self, request, limits)
    }

    /// The exact linear propagator where every mode is affine, else
    /// Taylor's method at machine precision: the tightest run there is
    /// (its own stated bounds say how far to trust it, and come with it).
    /// A run that ends at a Zeno point has events without end, as a
    /// chattering orbit, and no final state to compare.
    fn reference(&self) -> Result<Reference, SceneError> {
        let tightest = Tolerances {
            rtol: taylor_method::DEFAULT_TOLERANCE,
            atol: taylor_method::DEFAULT_TOLERANCE,
        };
        let modes = self.automaton.modes();
        let (method, kind) = if self.automaton.all_linear() {
            (Method::Linear, "the exact linear propagator")
        } else if runs(&*self.automaton, &modes, Method::Taylor(tightest)).is_ok() {
            (
                Method::Taylor(tightest),
                "Taylor's method at machine precision",
            )
        } else {
            return Err(SceneError::field(
                "modes",
                format!(
                    "{} reads abs, min or max, where Taylor series do not hold: \
                     no reference to measure methods against",
                    self.automaton.rough().unwrap_or("an expression")
                ),
            ));
        };
        let mut exact = self.clone();
        exact.method = method;
        let mut times = EventTimes::default();
        let report = exact.run(&Limits::default(), &mut times)?;
        let o = report.outcome;
        // A run that stops at a Zeno point stops where it can no longer
        // resolve the events, which differs from method to method: it is
        // measured by its events, not by where it stopped.
        let (events, final_state) = match o.status {
            Status::Completed => (times.0.len() as u64, o.final_state),
            Status::Zeno => (u64::MAX, Vec::new()),
            Status::Failed | Status::Interrupted => {
                return Err(SceneError::field(
                    "solver",
                    format!(
                        "the reference run ({kind}) {} at t = {}: {}",
                        o.status.as_str(),
                        o.t_reached,
                        o.reason.unwrap_or_default()
                    ),
                )
                .untrusted());
            }
        };
        let times = match o.status {
            Status::Zeno => zeno::resolved(&times.0).to_vec(),
            _ => times.0,
        };
        let reference = Reference::new(kind, final_state, events, move |k| {
            usize::try_from(k)
                .ok()
                .and_then(|k| times.get(k).copied())
                .unwrap_or(f64::NAN)
        });
        let Some(error_bound) = o.error_bound else {
            return Err(SceneError::field(
                "states",
                format!(
                    "the reference run ({kind}) carries no error bound with {} state components, \
                     so it cannot stand for the truth",
                    self.automaton.dimension()
                ),
            ));
        };
        Ok(reference.with_bounds(error_bound, o.event_time_bound.unwrap_or(0.0)))
    }

    fn clone_box(&self) -> Box<dyn SceneModel> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
