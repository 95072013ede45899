//! An automaton scene: the file's keys, read and checked (what it offers
//! the tools is `scene_model.rs`). The format is in the [module
//! doc](super).

use std::sync::Arc;

use crate::engine::Limits;
use crate::engine::step::method::cheapest;
use crate::engine::{Method, Observer, Sample, Tolerances, simulate_sampled, step::taylor_method};
use crate::models::automaton::definition::{Definition, Transition};
use crate::models::automaton::model::Automaton;
use crate::runner::Report;
use crate::scene::fields::Fields;
use crate::scene::solver::SolverSpec;
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
    pub(super) fn regime(&self) -> String {
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
    pub(super) fn run_sampled(
        &self,
        limits: &Limits,
        times: &[f64],
        on_sample: &mut dyn FnMut(&Sample),
        observer: &mut dyn Observer,
    ) -> Result<Report, SceneError> {
        let (method, description) = self.resolved();
        let options = limits.options(self.t_end, self.max_events, method, self.tolerances);
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
