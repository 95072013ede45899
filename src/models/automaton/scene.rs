//! An automaton scene: the file's keys, and what it offers the tools
//! ([`SceneModel`]). The format is in the [module doc](super).

use std::sync::Arc;

use crate::engine::bound::zeno;
use crate::engine::step::integrator::{methods_for, runs};
use crate::engine::step::method::cheapest;
use crate::engine::{
    EventTimes, Family, HybridModel, Method, Observer, Sample, Status, Tolerances,
    simulate_sampled, step::taylor_method,
};
use crate::models::automaton::definition::{Definition, Transition};
use crate::models::automaton::model::Automaton;
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest};
use crate::runner::{Control, Report, Trajectory};
use crate::scene::Reference;
use crate::scene::fields::Fields;
use crate::scene::solver::{SolverSpec, check_steps};
use crate::scene::{Scene, SceneError, SceneModel};

/// Default event budget of an automaton run.
const MAX_EVENTS: u64 = 1_000_000_000;

/// A validated automaton scene: the definition, compiled once.
#[derive(Debug, Clone)]
pub struct AutomatonScene {
    /// The model as the file defines it.
    pub definition: Definition,
    /// The compiled model.
    pub automaton: Arc<Automaton>,
    /// Simulated time to run to.
    pub t_end: f64,
    /// The solver as written.
    pub solver: SolverSpec,
    /// The method it resolves to (`Auto`: the cheapest exact one).
    pub method: Method,
    /// Tolerances of the adaptive methods.
    pub tolerances: Tolerances,
    /// Event budget.
    pub max_events: u64,
    /// Free text.
    pub description: Option<String>,
}

/// Validate the keys of an automaton scene.
pub fn scene(mut f: Fields) -> Result<Scene, SceneError> {
    let description = f.optional_string("description")?.map(str::to_string);
    let definition = Definition::read(&mut f)?;
    let automaton = Arc::new(Automaton::compile(&definition)?);
    let t_end = f.number_where("t_end", "> 0", |t| t > 0.0)?;
    let max_events = f.optional_count("max_events")?.unwrap_or(MAX_EVENTS);
    let mut scene = AutomatonScene {
        definition,
        automaton,
        t_end,
        solver: SolverSpec::default(),
        method: Method::Auto,
        tolerances: Tolerances::default(),
        max_events,
        description,
    };
    let solver = match f.optional("solver") {
        Some(value) => SolverSpec::from_json(value)?,
        None => SolverSpec::default(),
    };
    scene.set_solver(solver)?;
    f.finish()?;
    Ok(Scene::new(scene))
}

impl AutomatonScene {
    /// What kind of hybrid system the file describes, in a few words:
    /// forced or autonomous, its impacts, markers, mode changes and
    /// terminal transitions, its switching surfaces and resting modes, and
    /// whether every flow is affine.
    fn regime(&self) -> String {
        let d = &self.definition;
        let mut said = vec![if d.reads_clock() {
            "forced (reads the clock t)".to_string()
        } else {
            "autonomous".to_string()
        }];
        let named = |keep: &dyn Fn(&Transition, usize) -> bool| -> Vec<String> {
            let mut names: Vec<String> = (d.modes.iter().enumerate())
                .flat_map(|(i, m)| m.transitions.iter().map(move |t| (i, t)))
                .filter(|(i, t)| keep(t, *i))
                .map(|(_, t)| format!("`{}`", t.name))
                .collect();
            names.sort();
            names.dedup();
            names
        };
        for (what, names) in [
            ("impacting", named(&|t, _| t.barrier)),
            (
                "markers",
                named(&|t, i| !t.barrier && !t.terminal && t.to == i),
            ),
            ("mode changes", named(&|t, i| !t.barrier && t.to != i)),
            ("terminal", named(&|t, _| t.terminal)),
        ] {
            if !names.is_empty() {
                said.push(format!("{what} ({})", names.join(", ")));
            }
        }
        let switched = (0..d.modes.len())
            .filter(|&i| self.automaton.modes_of(i).len() > 1)
            .count();
        if switched > 0 {
            said.push(format!(
                "discontinuous (sign() in {switched} mode(s): Filippov sliding)"
            ));
        }
        if d.modes.iter().any(|m| m.rest.is_some()) {
            said.push("with resting modes".into());
        }
        said.push(if self.automaton.all_linear() {
            "every flow affine".into()
        } else {
            "nonlinear".into()
        });
        said.join(", ")
    }

    /// The method a run uses, and why: `Auto` resolves by
    /// [`cheapest`]: the exact linear propagator where every flow is
    /// affine, else Taylor's method at machine precision (unless told
    /// `rtol`/`atol`), else (a flow or guard with `abs`, `min` or `max`)
    /// Dormand-Prince.
    pub fn resolved(&self) -> (Method, String) {
        if self.method != Method::Auto {
            return (self.method, self.method.describe());
        }
        let taylor = Tolerances {
            rtol: self.solver.rtol.unwrap_or(taylor_method::DEFAULT_TOLERANCE),
            atol: self.solver.atol.unwrap_or(taylor_method::DEFAULT_TOLERANCE),
        };
        let modes = self.automaton.modes().len();
        let (method, why) = cheapest(&*self.automaton, modes, self.tolerances, taylor);
        let why = match method {
            Method::Dopri5(_) => format!(
                "a mode's flow is not affine, and {} reads abs, min or max (no Taylor series)",
                self.automaton.rough().unwrap_or("an expression")
            ),
            _ => why.to_string(),
        };
        (method, format!("{why}: {}", method.describe()))
    }
}

impl AutomatonScene {
    /// The run, with the state at
    /// each of `times` passed to `on_sample`.
    fn run_sampled(
        &self,
        control: &Control,
        times: &[f64],
        on_sample: &mut dyn FnMut(&Sample),
        observer: &mut dyn Observer,
    ) -> Result<Report, SceneError> {
        let (method, description) = self.resolved();
        let options = control.options(self.t_end, self.max_events, method, self.tolerances);
        let model = &*self.automaton;
        let outcome = simulate_sampled(
            model,
            model.initial_mode(),
            model.initial(),
            &options,
            times,
            on_sample,
            observer,
        );
        let final_state = outcome
            .final_state_names
            .iter()
            .cloned()
            .zip(outcome.final_state.iter().copied())
            .collect();
        Ok(Report {
            outcome,
            method,
            description,
            final_state,
            fields: None,
            sensitivities: None,
        })
    }
}

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

    fn run(&self, control: &Control, observer: &mut dyn Observer) -> Result<Report, SceneError> {
        self.run_sampled(control, &[], &mut |_| {}, observer)
    }

    fn family(&self) -> Result<Box<dyn Family>, SceneError> {
        Ok(Box::new(self.clone()))
    }

    fn offers_samples(&self) -> bool {
        true
    }

    fn sampled(
        &self,
        control: &Control,
        times: &[f64],
        observer: &mut dyn Observer,
    ) -> Option<Result<Trajectory, SceneError>> {
        let names = self.automaton.state_names(0).to_vec();
        Some(Trajectory::record(names, |on_sample| {
            self.run_sampled(control, times, on_sample, observer)
        }))
    }

    fn check_ensemble(&self, request: &EnsembleRequest) -> Result<(), SceneError> {
        super::ensemble::check(self, request)
    }

    fn ensemble(
        &self,
        request: &EnsembleRequest,
        control: &Control,
    ) -> Result<EnsembleReport, String> {
        super::ensemble::run(self, request, control)
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
        let report = exact.run(&Control::default(), &mut times)?;
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
