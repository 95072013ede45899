//! A chain scene (docs/physics.md s.4, scene units): its keys, read and
//! checked (what it offers the tools is `scene_model.rs`).
//!
//! ```json
//! {"model": "chain", "units": 200, "length": 2.0, "wave_speed": 1.0,
//!  "load": {"before": 1.1, "after": 0.0}, "constraint": true,
//!  "t_end": 3.0, "snapshots": [0.6667, 1.3333, 2.0], "samples": 300}
//! ```
//!
//! - `units`: N, a whole number from 1 to 10^6; `length` `L > 0`;
//!   `wave_speed` `c > 0` (so `F_cr = c^2`, node mass `L / N`, unit
//!   stiffness `F_cr N / L`).
//! - `load`: `{"before", "after"}`, the end load over `F_cr` before and after
//!   the release at `t = 0`. Every unit starts at strain `before - 1`, at
//!   rest, unless `initial` says otherwise; energies use `after`.
//! - `constraint`: `true` (default, units are unilateral: impacts) or
//!   `false` (the classical linear chain).
//! - `t_end > 0`; `snapshots`: times in `[0, t_end]` for `profiles.json`
//!   (default none); `samples`: how many rows `trace.csv` has, at
//!   `linspace(0, t_end, samples)` (default 101).
//! - optional: `initial` `{"strain": [N numbers], "velocity": [N numbers]}`
//!   (unit strains, `>= 0` with the constraint, and node velocities; either
//!   may be left out), `solver` (`exact`, the default, the event-local
//!   Taylor flow; `dopri5`, `dop853`, `verlet` or `linear` run the chain as an ODE, the
//!   independent path, for up to [`MAX_ODE_UNITS`] units), `max_events`,
//!   `description`.

use serde_json::Value;

use crate::engine::{Method, Tolerances};
use crate::models::chain::Chain;
use crate::scene::extent;
use crate::scene::fields::Fields;
use crate::scene::solver::{SolverSpec, check_steps};
use crate::scene::{Scene, SceneError};

/// Most units a scene may have.
pub const MAX_UNITS: u64 = 1_000_000;

/// Most units the ODE methods are offered for: every step costs O(N) and
/// scans N guards (the linear propagator a dense 2N x 2N exponential).
pub const MAX_ODE_UNITS: usize = 2000;

/// A validated chain scene: `units` equal units on a string, released
/// from one end load to another at `t = 0` (docs/physics.md s.4, scene
/// units).
#[derive(Debug, Clone, PartialEq)]
pub struct ChainScene {
    /// N, the number of units (1 to [`MAX_UNITS`]).
    pub units: usize,
    /// Length `L > 0` of the string.
    pub length: f64,
    /// Wave speed `c > 0`: `F_cr = c^2`, node mass `L / N`, unit stiffness
    /// `F_cr N / L`.
    pub wave_speed: f64,
    /// End load over `F_cr` before the release: the units start at strain
    /// `load_before - 1` unless `initial` says otherwise.
    pub load_before: f64,
    /// End load over `F_cr` after the release at `t = 0`; energies use it.
    pub load_after: f64,
    /// Whether the units are unilateral (`eps >= 0`, impacts); `false` is the
    /// classical linear chain.
    pub constraint: bool,
    /// Simulated time to run to, `> 0`.
    pub t_end: f64,
    /// Sorted times for `profiles.json`.
    pub snapshots: Vec<f64>,
    /// How many rows `trace.csv` has, at `linspace(0, t_end, samples)`.
    pub samples: usize,
    /// Initial unit strains, N of them (`>= 0` under the constraint).
    pub strain: Vec<f64>,
    /// Initial velocities of nodes 1 to N (node 0, the wall, does not move).
    pub velocity: Vec<f64>,
    /// The solver as written (the command line may override parts of it).
    pub solver: SolverSpec,
    /// The method `solver` resolves to ([`Method::Auto`]: the exact flow).
    pub method: Method,
    /// The tolerances `solver` resolves to.
    pub tolerances: Tolerances,
    /// Event budget: the run fails after this many events (default 10^9).
    pub max_events: u64,
    /// Free text about the scene, if given.
    pub description: Option<String>,
}

impl ChainScene {
    /// The scene's chain (docs/physics.md s.4 scene units, the load after the
    /// release), with the constraint on or off.
    pub fn chain(&self, constraint: bool) -> Chain {
        Chain::in_scene_units(
            self.units,
            self.length,
            self.wave_speed,
            self.load_after,
            constraint,
        )
    }

    /// The times `trace.csv` samples: `linspace(0, t_end, samples)`.
    pub fn sample_times(&self) -> Vec<f64> {
        extent::sample_times(self.t_end, self.samples)
    }

    /// Every time the run samples (snapshots and trace rows).
    pub fn due_times(&self) -> Vec<f64> {
        extent::due_times(&self.snapshots, self.sample_times())
    }
}

/// The registry's validator of chain scenes.
pub(crate) fn scene(f: Fields) -> Result<Scene, SceneError> {
    validate(f).map(Scene::new)
}

pub(crate) fn validate(mut f: Fields) -> Result<ChainScene, SceneError> {
    let units = f
        .optional_count("units")?
        .ok_or_else(|| SceneError::field("units", "is missing".into()))?;
    if units > MAX_UNITS {
        return Err(SceneError::field(
            "units",
            format!("must be at most {MAX_UNITS} (got {units})"),
        ));
    }
    let units = units as usize;
    let length = f.number_where("length", "> 0", |x| x > 0.0)?;
    let wave_speed = f.number_where("wave_speed", "> 0", |x| x > 0.0)?;
    // The chain's own numbers must be finite and positive too.
    let critical_load = wave_speed * wave_speed;
    let (mass, stiffness) = (length / units as f64, critical_load * units as f64 / length);
    for (name, key, x) in [
        ("F_cr = wave_speed^2", "wave_speed", critical_load),
        ("the node mass length / units", "length", mass),
        (
            "the unit stiffness F_cr units / length",
            "length",
            stiffness,
        ),
        (
            "the frequency sqrt(stiffness / mass)",
            "wave_speed",
            (stiffness / mass).sqrt(),
        ),
    ] {
        if !(x.is_finite() && x > 0.0) {
            return Err(SceneError::field(
                key,
                format!(
                    "makes {name} = {x:e}, which is not a positive finite number; rescale the scene"
                ),
            ));
        }
    }
    let (load_before, load_after) = extent::load(f.required("load")?)?;
    let constraint = extent::constraint(&mut f)?;
    let t_end = f.number_where("t_end", "> 0", |t| t > 0.0)?;
    let snapshots = extent::snapshots(&mut f, t_end)?;
    let samples = extent::samples(&mut f)?;
    let at_rest = load_before - 1.0;
    let (strain, velocity) = match f.optional("initial") {
        None => (vec![at_rest; units], vec![0.0; units]),
        Some(v) => initial(v, units, at_rest)?,
    };
    if constraint && let Some(n) = strain.iter().position(|&e| e < 0.0) {
        let from = if f.has("initial") {
            format!("initial.strain[{n}] is {}", strain[n])
        } else {
            format!("load.before = {load_before} puts every unit at strain {at_rest}")
        };
        return Err(SceneError::field(
            if f.has("initial") {
                "initial.strain"
            } else {
                "load.before"
            },
            format!(
                "{from}, below zero, which the constraint forbids (use \"constraint\": false for the classical chain)"
            ),
        ));
    }
    let solver = f
        .optional("solver")
        .map(SolverSpec::from_json)
        .transpose()?
        .unwrap_or_default();
    let (method, tolerances) = resolve_solver(&solver, units)?;
    check_steps(method, t_end)?;
    let max_events = f.optional_count("max_events")?.unwrap_or(1_000_000_000);
    let description = f.optional_string("description")?.map(str::to_string);
    f.finish()?;
    Ok(ChainScene {
        units,
        length,
        wave_speed,
        load_before,
        load_after,
        constraint,
        t_end,
        snapshots,
        samples,
        strain,
        velocity,
        solver,
        method,
        tolerances,
        max_events,
        description,
    })
}

/// The method and tolerances of `spec` for a chain of `units`.
pub fn resolve_solver(spec: &SolverSpec, units: usize) -> Result<(Method, Tolerances), SceneError> {
    let (method, tolerances) = spec.resolve()?;
    let numerical = !matches!(method, Method::Auto | Method::Exact);
    if numerical && units > MAX_ODE_UNITS {
        return Err(SceneError::field(
            "solver.method",
            format!(
                "{} runs the chain as an ODE, for at most {MAX_ODE_UNITS} units (this one has {units}); use \"exact\"",
                method.name()
            ),
        ));
    }
    Ok((method, tolerances))
}

fn initial(value: &Value, units: usize, at_rest: f64) -> Result<(Vec<f64>, Vec<f64>), SceneError> {
    let mut f = Fields::open(value, "initial")?;
    let strain = f
        .optional("strain")
        .map(|v| extent::numbers(v, "initial.strain", Some((units, "unit"))))
        .transpose()?
        .unwrap_or_else(|| vec![at_rest; units]);
    let velocity = f
        .optional("velocity")
        .map(|v| extent::numbers(v, "initial.velocity", Some((units, "unit"))))
        .transpose()?
        .unwrap_or_else(|| vec![0.0; units]);
    f.finish()?;
    Ok((strain, velocity))
}
