//! `flicker run --sensitivities eta,initial.strain` for automata: the
//! derivatives of the state and of every event time with respect to
//! parameters and initial values, forward through the flows (variational
//! equations on the compiled form: its exact Jacobian) and across each
//! event by its saltation matrix ([`crate::engine::variational`]).
//!
//! A parameter becomes a state that never changes
//! ([`Definition::with_parameters_as_states`]), its direction the unit
//! vector on it plus the derivative of the initial values it enters; an
//! initial value's direction is the unit vector on its state. The run is
//! the model with its derivatives, integrated as one: by the exact linear
//! propagator where every mode stays affine, else by DOP853 at 1e-13 or
//! the scene's `rtol`/`atol` (Taylor's method needs series the
//! derivatives do not have), or by the Runge-Kutta method the scene asks
//! for. Each logged event
//! carries `d{state}/d{direction}` and `dt/d{direction}` in its states.

use serde_json::{Map, Value, json};

use crate::engine::variational::Variational;
use crate::engine::{HybridModel, Method, Observer, Sample, Tolerances, simulate_sampled};
use crate::models::automaton::definition::Definition;
use crate::models::automaton::model::Automaton;
use crate::models::automaton::scene::AutomatonScene;
use crate::runner::{Control, Report};
use crate::scene::SceneError;

/// Tolerance of DOP853 where the scene names no method.
const TOLERANCE: f64 = 1e-13;

/// One direction of the derivatives.
#[derive(Debug, Clone, PartialEq)]
enum Direction {
    /// A parameter, by name.
    Parameter(String),
    /// The initial value of a state, by index.
    Initial(usize),
}

/// Check `names` against `scene` before anything runs: each a parameter
/// (`NAME` or `parameters.NAME`) or a state's initial value
/// (`initial.NAME`), each once, and the scene's method able to carry them.
pub fn check(scene: &AutomatonScene, names: &[String]) -> Result<(), SceneError> {
    let setup = Setup::new(&scene.definition, names)?;
    let variational = Variational::new(&setup.model, setup.model.modes().len(), &setup.labels);
    method(scene, &setup.model, &variational).map(|_| ())
}

/// The model with the derivatives' parameters as states, where the
/// derivatives start, and what they are called.
struct Setup {
    model: Automaton,
    /// Each direction's initial derivative of the whole state.
    s0: Vec<Vec<f64>>,
    /// Each direction as the summary names it.
    labels: Vec<String>,
}

impl Setup {
    fn new(definition: &Definition, names: &[String]) -> Result<Setup, SceneError> {
        let directions = directions(definition, names)?;
        let parameters: Vec<String> = directions
            .iter()
            .filter_map(|d| match d {
                Direction::Parameter(p) => Some(p.clone()),
                Direction::Initial(_) => None,
            })
            .collect();
        let (promoted, slopes) =
            definition.with_parameters_as_states(&parameters, "sensitivities")?;
        let model = Automaton::compile(&promoted)?;
        let states = definition.states.len();
        let n = model.dimension();
        let mut promoted_index = 0;
        let s0 = directions
            .iter()
            .map(|d| {
                let mut s = vec![0.0; n];
                match d {
                    Direction::Initial(i) => s[*i] = 1.0,
                    Direction::Parameter(_) => {
                        s[states + promoted_index] = 1.0;
                        s[..states].copy_from_slice(&slopes[promoted_index]);
                        promoted_index += 1;
                    }
                }
                s
            })
            .collect();
        let labels = directions
            .iter()
            .map(|d| match d {
                Direction::Parameter(p) => p.clone(),
                Direction::Initial(i) => format!("initial.{}", definition.states[*i]),
            })
            .collect();
        Ok(Setup { model, s0, labels })
    }
}

/// The method the derivatives' run uses, and why (see the module doc).
fn method(
    scene: &AutomatonScene,
    model: &Automaton,
    variational: &Variational<'_, Automaton>,
) -> Result<(Method, String), SceneError> {
    let affine = model.modes().iter().all(|&m| variational.is_linear(m));
    match scene.method {
        Method::Auto | Method::Linear if affine => Ok((
            Method::Linear,
            "every mode's flow stays affine with its derivatives: exact linear propagator"
                .to_string(),
        )),
        Method::Auto => {
            let tol = Tolerances {
                rtol: scene.solver.rtol.unwrap_or(TOLERANCE),
                atol: scene.solver.atol.unwrap_or(TOLERANCE),
            };
            Ok((
                Method::Dop853(tol),
                format!(
                    "DOP853 (Dormand-Prince 8(5,3)), rtol {:e}, atol {:e}",
                    tol.rtol, tol.atol
                ),
            ))
        }
        Method::Linear => Err(SceneError::field(
            "solver.method",
            "the exact linear propagator needs every mode's flow to stay affine with its \
             derivatives, and one does not here (a parameter multiplies a state?): \
             use dopri5 or dop853"
                .into(),
        )),
        method @ (Method::Dopri5(_) | Method::Dop853(_)) => Ok((
            method,
            format!("{} at the scene's tolerances", method.name()),
        )),
        other => Err(SceneError::field(
            "solver.method",
            format!(
                "sensitivities are integrated with the model (variational equations): \
                 use linear (affine modes), dopri5 or dop853, not {}",
                other.name()
            ),
        )),
    }
}

fn directions(definition: &Definition, names: &[String]) -> Result<Vec<Direction>, SceneError> {
    let refuse = |reason: String| SceneError::field("sensitivities", reason);
    if names.is_empty() {
        return Err(refuse(
            "name at least one parameter or initial.STATE".into(),
        ));
    }
    let mut out = Vec::new();
    for name in names {
        let direction = if let Some(state) = name.strip_prefix("initial.") {
            let i = definition
                .states
                .iter()
                .position(|s| s == state)
                .ok_or_else(|| {
                    refuse(format!(
                        "no state is called `{state}` (states: {})",
                        definition.states.join(", ")
                    ))
                })?;
            Direction::Initial(i)
        } else {
            let p = name.strip_prefix("parameters.").unwrap_or(name);
            if !definition.parameters.iter().any(|(q, _)| q == p) {
                let known: Vec<&str> = definition
                    .parameters
                    .iter()
                    .map(|(q, _)| q.as_str())
                    .collect();
                return Err(refuse(format!(
                    "no parameter is called `{p}` (parameters: {}; an initial value is initial.STATE)",
                    known.join(", ")
                )));
            }
            Direction::Parameter(p.to_string())
        };
        if out.contains(&direction) {
            return Err(refuse(format!("`{name}` is named twice")));
        }
        out.push(direction);
    }
    Ok(out)
}

/// The run of `scene` from its initial state with the derivatives along
/// its `sensitivities`, by its method (`Auto`: see the module doc) under
/// `control`; samples and events as any run's.
pub fn run(
    scene: &AutomatonScene,
    control: &Control,
    times: &[f64],
    on_sample: &mut dyn FnMut(&Sample),
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let Setup { model, s0, labels } = Setup::new(&scene.definition, &scene.sensitivities)?;
    let states = scene.definition.states.len();
    let n = model.dimension();
    let variational = Variational::new(&model, model.modes().len(), &labels);
    let (method, description) = method(scene, &model, &variational)?;
    let options = control.options(scene.t_end, scene.max_events, method, scene.tolerances);
    let x0 = variational.initial(model.initial(), &s0);
    let outcome = simulate_sampled(
        &variational,
        model.initial_mode(),
        &x0,
        &options,
        times,
        on_sample,
        observer,
    );
    // The summary's final state is the file's states (and the clock).
    let names_n = variational.state_names(outcome.final_mode);
    let keep = |k: usize| k < states || (model.has_clock() && k == n - 1);
    let final_state = names_n[..n]
        .iter()
        .zip(&outcome.final_state[..n])
        .enumerate()
        .filter(|(k, _)| keep(*k))
        .map(|(_, (name, x))| (*name, *x))
        .collect();
    let mut sensitivities = Map::new();
    for (j, label) in labels.iter().enumerate() {
        let s = variational.sensitivity(&outcome.final_state, j);
        let by_name: Map<String, Value> = names_n[..n]
            .iter()
            .zip(s)
            .enumerate()
            .filter(|(k, _)| keep(*k))
            .map(|(_, (name, d))| (name.to_string(), json!(d)))
            .collect();
        sensitivities.insert(
            label.clone(),
            json!({
                "final_state": by_name,
                "last_event_time": variational.event_time_sensitivity(&outcome.final_state, j),
            }),
        );
    }
    Ok(Report {
        outcome,
        method: method.name(),
        description: format!(
            "{description}; with the derivatives along {} (variational equations, saltation matrices at events)",
            labels.join(", ")
        ),
        final_state,
        fields: None,
        sensitivities: Some(Value::Object(sensitivities)),
    })
}
