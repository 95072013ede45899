//! `flicker run --sensitivities eta,initial.strain` on any scene whose
//! model gives a [`Family`] (the mechanism in both formulations, the chain,
//! automata): the derivatives of the state and of every event time with
//! respect to parameters and initial values, forward through the flows
//! (variational equations, with the model's exact Jacobian where it gives
//! one, central differences otherwise) and across each event by its
//! saltation matrix ([`crate::engine::bound::variational`]).
//!
//! A parameter becomes a state that never changes ([`Family::promoted`]),
//! its direction the unit vector on it plus the derivative of the initial
//! values it enters; an initial value's direction is the unit vector on
//! its state. The run is the model with its derivatives, integrated as
//! one: by the exact linear propagator where every mode stays affine, else
//! by DOP853 at 1e-13 or the scene's `rtol`/`atol` (Taylor's method needs
//! series the derivatives do not have), or by the Runge-Kutta method the
//! scene asks for. Each logged event carries `d{state}/d{direction}` and
//! `dt/d{direction}` in its states.

use serde_json::{Map, Value, json};

use crate::engine::Limits;
use crate::engine::bound::variational::Variational;
use crate::engine::step::method::tightest;
use crate::engine::{
    Family, HybridModel, Method, Mode, Name, Observer, Sample, Tolerances, simulate_sampled,
};
use crate::runner::Report;
use crate::scene::{Scene, SceneError};

/// Tolerance of DOP853 where the scene names no method.
const TOLERANCE: f64 = 1e-13;

/// Event budget of a run with derivatives.
const MAX_EVENTS: u64 = 1_000_000_000;

/// One direction of the derivatives.
#[derive(Debug, Clone, PartialEq)]
enum Direction {
    /// A parameter, by name.
    Parameter(String),
    /// The initial value of a state, by index.
    Initial(usize),
}

/// The model the derivatives ride on, where it starts, and what they are
/// called.
struct Setup {
    family: Box<dyn Family>,
    /// The model with the parameters named held as states, if any were.
    promoted: Option<crate::engine::Promoted>,
    /// Each direction's initial derivative of the whole state.
    s0: Vec<Vec<f64>>,
    /// Each direction as the summary names it.
    labels: Vec<String>,
    /// The components that are parameters held as states.
    parameters: Vec<usize>,
}

impl Setup {
    fn new(scene: &Scene, names: &[String]) -> Result<Setup, SceneError> {
        let refuse = |reason: String| SceneError::field("sensitivities", reason);
        let family = scene
            .family()
            .map_err(|e| refuse(format!("{} (sensitivities need one)", e.reason)))?;
        let directions = directions(&*family, names)?;
        let parameters: Vec<String> = directions
            .iter()
            .filter_map(|d| match d {
                Direction::Parameter(p) => Some(p.clone()),
                Direction::Initial(_) => None,
            })
            .collect();
        let promoted = if parameters.is_empty() {
            None
        } else {
            Some(family.promoted(&parameters).map_err(refuse)?)
        };
        let n = match &promoted {
            Some(p) => p.model.dimension(),
            None => family.model().dimension(),
        };
        let mut next_parameter = 0;
        let s0 = directions
            .iter()
            .map(|d| match d {
                Direction::Initial(i) => {
                    let mut s = vec![0.0; n];
                    s[*i] = 1.0;
                    s
                }
                Direction::Parameter(_) => {
                    next_parameter += 1;
                    promoted
                        .as_ref()
                        .map_or_else(Vec::new, |p| p.slopes[next_parameter - 1].clone())
                }
            })
            .collect();
        let names = family.state_names();
        let labels = directions
            .iter()
            .map(|d| match d {
                Direction::Parameter(p) => p.clone(),
                Direction::Initial(i) => format!("initial.{}", names[*i]),
            })
            .collect();
        let parameters = promoted
            .as_ref()
            .map_or_else(Vec::new, |p| p.parameters.clone());
        Ok(Setup {
            family,
            promoted,
            s0,
            labels,
            parameters,
        })
    }

    /// The model the derivatives ride on, and where it starts.
    fn model(&self) -> (&(dyn HybridModel + Sync), Mode, Vec<f64>) {
        match &self.promoted {
            Some(p) => (&*p.model, p.mode, p.start.clone()),
            None => {
                let (mode, x0) = self.family.start();
                (self.family.model(), mode, x0)
            }
        }
    }
}

/// Check `names` against `scene` before anything runs: each a parameter
/// (`NAME` or `parameters.NAME`) or a state's initial value
/// (`initial.NAME`), each once, and the scene's method able to carry them.
pub fn check(scene: &Scene, names: &[String]) -> Result<(), SceneError> {
    let setup = Setup::new(scene, names)?;
    let (model, _, _) = setup.model();
    let variational = Variational::new(model, setup.family.modes(), &setup.labels);
    method(scene, setup.family.modes(), &variational).map(|_| ())
}

/// The method the derivatives' run uses, and why (see the module doc).
fn method<M: HybridModel + ?Sized>(
    scene: &Scene,
    modes: usize,
    variational: &Variational<'_, M>,
) -> Result<(Method, String), SceneError> {
    // Derivatives ride as an ODE: linear where the propagator runs them.
    let affine = tightest(variational, modes, TOLERANCE) == Method::Linear;
    let spec = scene.solver();
    let (asked, tolerances) = spec.resolve()?;
    match asked {
        Method::Auto | Method::Exact | Method::Linear if affine => Ok((
            Method::Linear,
            "every mode's flow stays affine with its derivatives: exact linear propagator"
                .to_string(),
        )),
        Method::Auto | Method::Exact => {
            let tol = Tolerances {
                rtol: spec.rtol.unwrap_or(TOLERANCE),
                atol: spec.atol.unwrap_or(TOLERANCE),
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
        Method::Dopri5(_) | Method::Dop853(_) => {
            let method = match asked {
                Method::Dopri5(_) => Method::Dopri5(tolerances),
                _ => Method::Dop853(tolerances),
            };
            Ok((
                method,
                format!("{} at the scene's tolerances", method.name()),
            ))
        }
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

fn directions(family: &dyn Family, names: &[String]) -> Result<Vec<Direction>, SceneError> {
    let refuse = |reason: String| SceneError::field("sensitivities", reason);
    if names.is_empty() {
        return Err(refuse(
            "name at least one parameter or initial.STATE".into(),
        ));
    }
    let states = family.state_names();
    let clock = family.model().clock();
    let parameters = family.parameters();
    let mut out = Vec::new();
    for name in names {
        let direction = if let Some(state) = name.strip_prefix("initial.") {
            let i = states
                .iter()
                .enumerate()
                .position(|(i, s)| s == state && Some(i) != clock)
                .ok_or_else(|| {
                    let known: Vec<&str> = states
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| Some(*i) != clock)
                        .map(|(_, s)| s.as_str())
                        .collect();
                    refuse(format!(
                        "no state is called `{state}` (states: {})",
                        known.join(", ")
                    ))
                })?;
            Direction::Initial(i)
        } else {
            let p = name.strip_prefix("parameters.").unwrap_or(name);
            if !parameters.iter().any(|q| q == p) {
                return Err(refuse(format!(
                    "no parameter is called `{p}` (parameters: {}; an initial value is initial.STATE)",
                    parameters.join(", ")
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

/// The run of `scene` from its start with the derivatives along `names`,
/// by its method (`Auto`: see the module doc) under `limits`; samples and
/// events as any run's.
pub fn run(
    scene: &Scene,
    names: &[String],
    limits: &Limits,
    times: &[f64],
    on_sample: &mut dyn FnMut(&Sample),
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let setup = Setup::new(scene, names)?;
    let (model, mode, start) = setup.model();
    let n = model.dimension();
    let modes = setup.family.modes();
    let variational = Variational::new(model, modes, &setup.labels);
    let (method, description) = method(scene, modes, &variational)?;
    let tolerances = match method {
        Method::Dopri5(t) | Method::Dop853(t) => t,
        _ => Tolerances::default(),
    };
    let options = limits.options(scene.t_end(), MAX_EVENTS, method, tolerances);
    let x0 = variational.initial(&start, &setup.s0);
    let outcome = simulate_sampled(
        &variational,
        mode,
        &x0,
        &options,
        times,
        on_sample,
        observer,
    );
    // The summary's final state is the model's own (and the clock), not
    // the parameters held as states.
    let own = setup.family.state_names();
    let names: Vec<String> = {
        let listed = model.state_names(outcome.final_mode);
        if listed.len() == n {
            listed.iter().map(|s| s.to_string()).collect()
        } else {
            let mut all = own.clone();
            all.extend(setup.parameters.iter().map(|i| format!("x{i}")));
            all
        }
    };
    let keep = |k: usize| !setup.parameters.contains(&k);
    let final_state = names
        .iter()
        .zip(&outcome.final_state[..n])
        .enumerate()
        .filter(|(k, _)| keep(*k))
        .map(|(_, (name, x))| (Name::from(name.as_str()), *x))
        .collect();
    let mut sensitivities = Map::new();
    for (j, label) in setup.labels.iter().enumerate() {
        let s = variational.sensitivity(&outcome.final_state, j);
        let by_name: Map<String, Value> = names
            .iter()
            .zip(s)
            .enumerate()
            .filter(|(k, _)| keep(*k))
            .map(|(_, (name, d))| (name.clone(), json!(d)))
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
        method,
        description: format!(
            "{description}; with the derivatives along {} (variational equations, saltation matrices at events)",
            setup.labels.join(", ")
        ),
        final_state,
        fields: None,
        sensitivities: Some(Value::Object(sensitivities)),
    })
}

/// [`run`] with the state sampled at `times`: the model's own components,
/// named as [`Family::state_names`] names them, then the derivatives.
pub fn sampled(
    scene: &Scene,
    names: &[String],
    limits: &Limits,
    times: &[f64],
    observer: &mut dyn Observer,
) -> Result<crate::runner::Trajectory, SceneError> {
    let family = scene.family()?;
    let own = family.state_names().into_iter().map(Name::from).collect();
    crate::runner::Trajectory::record(own, |on_sample| {
        run(scene, names, limits, times, on_sample, observer)
    })
}
