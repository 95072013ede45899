//! A mechanism scene: its keys, read and checked, and the helpers what it
//! offers the tools (`scene_model.rs`: its methods by the engine's rules,
//! its regime for `check`, the closed form as the exact reference, the
//! impact period) is made of.
//!
//! ```json
//! {"model": "mechanism", "formulation": "strain", "eta": 1.2, "omega": 1.0,
//!  "initial": {"strain": 0.05, "strain_rate": 0.0}, "t_end": 1000.0}
//! ```
//!
//! - `formulation`: `"strain"` (hybrid, exact flow) or `"angle"` (smooth
//!   equation (8), integrated with Dormand-Prince).
//! - `eta`: load ratio `F / F_cr`, any finite number; `omega > 0` (default 1).
//! - `initial`: one of `{"strain", "strain_rate"}` (`strain >= 0`),
//!   `{"energy", "phase"}` with phase `"impact"` (at `eps = 0`, opening) or
//!   `"apex"` (largest strain, at rest), or, for the angle formulation,
//!   `{"angle", "angle_rate"}` with `|angle| < pi/2`. A strain given to the
//!   angle formulation means `theta >= 0`.
//! - `t_end > 0`: simulated time.
//! - optional: `chart` (angle only: `"switch"`, the default, crosses
//!   `theta = 0` in the strain chart; `"none"` integrates (8) as it is and
//!   fails there), `solver` (see [`solver`](crate::scene::solver): the
//!   strain formulation takes `exact` (default), `linear`, `dopri5`,
//!   `dop853` and `verlet`; the angle formulation `dopri5`, the default, or
//!   `dop853`, with `rtol` and
//!   `atol` 1e-12 unless given), `max_events` (event budget, default 10^9),
//!   `description` (free text).

use std::f64::consts::FRAC_PI_2;

use crate::engine::bound::zeno;
use crate::engine::step::integrator::{methods_for, runs};
use crate::engine::{HybridModel, Mode};
use crate::engine::{Method, Tolerances};
use crate::models::mechanism::strain::{self, FLIGHT};
use crate::models::mechanism::{AngleMechanism, StrainMechanism, angle};
use crate::models::mechanism::{Charts, Mechanism, Phase};
use crate::scene::fields::{Fields, kind};
use crate::scene::solver::{SolverSpec, check_steps};
use crate::scene::{Scene, SceneError};

/// Which equations describe the mechanism.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Formulation {
    /// The strain formulation: a hybrid automaton whose flight has a
    /// closed form ([`StrainMechanism`]).
    Strain,
    /// The angle formulation: the smooth equation (8), integrated
    /// numerically, changing chart near `theta = 0` or not
    /// ([`AngleMechanism`]).
    Angle(Charts),
}

/// The initial state as the scene gave it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Initial {
    /// A strain and its rate.
    Strain {
        /// The strain `eps >= 0`.
        strain: f64,
        /// The strain rate `eps'`.
        rate: f64,
    },
    /// An energy and where on its orbit to start.
    Energy {
        /// The energy `H0`.
        energy: f64,
        /// Where on the orbit of that energy to start.
        phase: Phase,
    },
    /// An angle and its rate (the angle formulation only).
    Angle {
        /// The angle `theta`, `|theta| < pi/2`.
        angle: f64,
        /// The angle rate `theta'`.
        rate: f64,
    },
}

/// A validated mechanism scene: one bistable mechanism, its formulation,
/// its initial state and how to run it.
#[derive(Debug, Clone, PartialEq)]
pub struct MechanismScene {
    /// Strain or angle formulation.
    pub formulation: Formulation,
    /// The mechanism's load ratio `eta` and frequency `omega`.
    pub mechanism: Mechanism,
    /// The initial state as the scene gave it.
    pub initial: Initial,
    /// The initial `(eps, eps')`, resolved from `initial`.
    pub initial_strain: (f64, f64),
    /// Simulated time to run to, `> 0`.
    pub t_end: f64,
    /// The solver as written (the command line may override parts of it).
    pub solver: SolverSpec,
    /// The method `solver` resolves to ([`Method::Auto`]: the formulation's
    /// cheapest exact description).
    pub method: Method,
    /// The tolerances `solver` resolves to (`1e-12` unless given).
    pub tolerances: Tolerances,
    /// Event budget: the run fails after this many events (default 10^9).
    pub max_events: u64,
    /// Free text about the scene, if given.
    pub description: Option<String>,
}

/// The registry's validator of mechanism scenes.
pub(crate) fn scene(f: Fields) -> Result<Scene, SceneError> {
    validate(f).map(Scene::new)
}

pub(crate) fn validate(mut f: Fields) -> Result<MechanismScene, SceneError> {
    let formulation = f.string("formulation")?;
    let eta = f.number("eta")?;
    let omega = f.optional_number("omega")?.unwrap_or(1.0);
    let omega = f.check("omega", omega, "> 0", |w| w > 0.0)?;
    let mechanism = Mechanism { eta, omega };
    let t_end = f.number_where("t_end", "> 0", |t| t > 0.0)?;
    let max_events = f.optional_count("max_events")?.unwrap_or(1_000_000_000);
    let description = f.optional_string("description")?.map(str::to_string);
    let angle = formulation == "angle";
    let formulation = match formulation {
        "strain" => Formulation::Strain,
        "angle" => Formulation::Angle(charts(&mut f)?),
        other => {
            return Err(SceneError::field(
                "formulation",
                format!("must be \"strain\" or \"angle\" (got {other:?})"),
            ));
        }
    };
    let solver = f
        .optional("solver")
        .map(SolverSpec::from_json)
        .transpose()?
        .unwrap_or_default();
    let (method, tolerances) = resolve_solver(&solver, formulation, mechanism)?;
    check_steps(method, t_end)?;
    let (initial, initial_strain) = initial(f.required("initial")?, mechanism, angle)?;
    if !(initial_strain.0.is_finite() && initial_strain.1.is_finite()) {
        return Err(SceneError::field(
            "initial",
            format!(
                "gives a strain and rate {initial_strain:?} that overflow; scale the problem down"
            ),
        ));
    }
    if formulation == Formulation::Angle(Charts::Plain) && initial_strain.0 == 0.0 {
        return Err(SceneError::field(
            "initial",
            "puts theta = 0, where equation (8) is singular (theta' is infinite there); use \"chart\": \"switch\""
                .into(),
        ));
    }
    f.finish()?;
    Ok(MechanismScene {
        formulation,
        mechanism,
        initial,
        initial_strain,
        t_end,
        solver,
        method,
        tolerances,
        max_events,
        description,
    })
}

fn charts(f: &mut Fields) -> Result<Charts, SceneError> {
    match f.optional_string("chart")? {
        None | Some("switch") => Ok(Charts::Switch),
        Some("none") => Ok(Charts::Plain),
        Some(other) => Err(SceneError::field(
            "chart",
            format!("must be \"switch\" or \"none\" (got {other:?})"),
        )),
    }
}

/// The method and tolerances of `spec`, checked by the engine's rules
/// against the formulation's model.
pub fn resolve_solver(
    spec: &SolverSpec,
    formulation: Formulation,
    mechanism: Mechanism,
) -> Result<(Method, Tolerances), SceneError> {
    let (method, tolerances) = spec.resolve()?;
    if method == Method::Auto {
        return Ok((method, tolerances));
    }
    with_model(formulation, mechanism, |model, modes| {
        runs(model, modes, method).map_err(|why| {
            SceneError::field(
                "solver.method",
                format!(
                    "{why} (this formulation runs {})",
                    methods_for(model, modes).join(", ")
                ),
            )
        })
    })?;
    Ok((method, tolerances))
}

/// `f` of the formulation's model and the modes a run of it may enter:
/// what the engine's rules judge methods against.
pub(super) fn with_model<R>(
    formulation: Formulation,
    mechanism: Mechanism,
    f: impl FnOnce(&dyn HybridModel, &[Mode]) -> R,
) -> R {
    match formulation {
        Formulation::Strain => f(&StrainMechanism { mechanism }, &[FLIGHT, strain::RESTING]),
        Formulation::Angle(charts) => f(
            &AngleMechanism { mechanism, charts },
            &[
                angle::ANGLE_POSITIVE,
                angle::ANGLE_NEGATIVE,
                angle::STRAIN_POSITIVE,
                angle::STRAIN_NEGATIVE,
                angle::PLAIN,
                angle::RESTING,
            ],
        ),
    }
}

fn initial(
    value: &serde_json::Value,
    mechanism: Mechanism,
    angle: bool,
) -> Result<(Initial, (f64, f64)), SceneError> {
    let mut f = Fields::open(value, "initial")?;
    let initial = if f.has("strain") {
        let strain = f.number_where(
            "strain",
            ">= 0 (the strain is a unilateral constraint)",
            |e| e >= 0.0,
        )?;
        let rate = f.number("strain_rate")?;
        (Initial::Strain { strain, rate }, (strain, rate))
    } else if f.has("energy") {
        let energy = f.number("energy")?;
        let phase = match f.string("phase")? {
            "impact" => Phase::Impact,
            "apex" => Phase::Apex,
            other => {
                return Err(SceneError::field(
                    "initial.phase",
                    format!("must be \"impact\" or \"apex\" (got {other:?})"),
                ));
            }
        };
        let state = mechanism
            .state_with_energy(energy, phase)
            .map_err(|reason| SceneError::field("initial.energy", reason))?;
        (Initial::Energy { energy, phase }, state)
    } else if f.has("angle") {
        if !angle {
            return Err(SceneError::field(
                "initial.angle",
                "is for the angle formulation; give the strain formulation {\"strain\", \"strain_rate\"}".into(),
            ));
        }
        let theta = f.number_where("angle", "inside (-pi/2, pi/2)", |a| a.abs() < FRAC_PI_2)?;
        let rate = f.number("angle_rate")?;
        let state = crate::models::mechanism::angle::strain_of_angle(theta, rate);
        (Initial::Angle { angle: theta, rate }, state)
    } else {
        return Err(SceneError::field(
            "initial",
            format!(
                "must hold {{\"strain\", \"strain_rate\"}}, {{\"energy\", \"phase\"}}{}; found {}",
                if angle {
                    " or {\"angle\", \"angle_rate\"}"
                } else {
                    ""
                },
                kind(value)
            ),
        ));
    };
    f.finish()?;
    Ok(initial)
}

/// Which regime of docs/physics.md s.2 an orbit of energy `h0` is in.
pub(super) fn regime(m: Mechanism, h0: f64, t_end: f64) -> String {
    let c = m.centre();
    let resolution = zeno::resolution(0.0, t_end);
    if h0 > 0.0 && m.impact_period(h0) <= resolution {
        format!(
            "chattering towards resting contact: an impact every {:e}, faster than the run can resolve (expect zeno)",
            m.impact_period(h0)
        )
    } else if h0 > 0.0 {
        format!("impacting, an impact every {:e}", m.impact_period(h0))
    } else if h0 == 0.0 && c > 0.0 {
        "the grazing separatrix: touches eps = 0 at zero speed, no impact".into()
    } else if h0 == 0.0 && c < 0.0 {
        "resting contact at the trivial state".into()
    } else if h0 == 0.0 {
        "at rest at the critical load".into()
    } else {
        "a loose oscillation about the buckled strain, no impact".into()
    }
}
