//! A continuum scene, the chain scene's string without its units
//! (docs/physics.md s.5, scene units): its keys, read and checked (what it
//! offers the tools is `scene_model.rs`).
//!
//! ```json
//! {"model": "continuum", "variant": "paper", "length": 2.0, "wave_speed": 1.0,
//!  "load": {"before": 1.1, "after": 1.0}, "constraint": true,
//!  "t_end": 3.0, "snapshots": [0.6667, 1.3333, 2.0], "samples": 300}
//! ```
//!
//! - `variant`: `paper` (the default; the wave equation with the
//!   constraint and energy kept across impacts, run exactly by front
//!   tracking, [`crate::models::continuum`]) or `homogenized` (the rattling
//!   kept as internal energy, by finite volumes,
//!   [`crate::models::continuum::homogenized`]).
//! - `length`, `wave_speed`, `load`, `constraint`, `t_end`, `snapshots`,
//!   `samples`: as in a chain scene ([`crate::models::chain::scene`]).
//! - `resolution`: how many equal cells the string is cut into (default
//!   400): the homogenized string's finite volumes, and the points at whose
//!   centres `profiles.json` samples either variant (front tracking itself
//!   needs none).
//! - optional: `initial` `{"strain": [..], "velocity": [..]}`, a constant
//!   state on each of as many equal cells as the arrays have entries
//!   (strains `>= 0` under the constraint); otherwise the string starts at
//!   strain `load.before - 1`, at rest. `max_events`, `description`.

use serde_json::Value;

use crate::models::continuum::{Continuum, Piece, Variant};
use crate::scene::extent;
use crate::scene::fields::{Fields, kind};
use crate::scene::solver::SolverSpec;
use crate::scene::{Scene, SceneError};

/// Most cells an `initial` profile may have, and most profile points.
pub const MAX_CELLS: u64 = 1_000_000;

/// Most finite volumes of the homogenized string (a step over them all is
/// one event, so this keeps an event to milliseconds).
pub const MAX_FINITE_VOLUMES: usize = 20_000;

/// A validated continuum scene: the chain scene's string without its
/// units, run as the continuum `variant` (docs/physics.md s.5, scene
/// units).
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuumScene {
    /// Which continuum: the paper's (front tracking) or the homogenized
    /// string (finite volumes).
    pub variant: Variant,
    /// Length `L > 0` of the string.
    pub length: f64,
    /// Wave speed `c > 0`: `F_cr = c^2`.
    pub wave_speed: f64,
    /// End load over `F_cr` before the release: the string starts at strain
    /// `load_before - 1` unless `initial` says otherwise.
    pub load_before: f64,
    /// End load over `F_cr` after the release at `t = 0`.
    pub load_after: f64,
    /// Whether `eps >= 0` is enforced; `false` is the classical string.
    pub constraint: bool,
    /// Simulated time to run to, `> 0`.
    pub t_end: f64,
    /// Sorted times for `profiles.json`.
    pub snapshots: Vec<f64>,
    /// How many rows `trace.csv` has, at `linspace(0, t_end, samples)`.
    pub samples: usize,
    /// Points along the string in `profiles.json`.
    pub resolution: usize,
    /// The initial state, one piece per equal cell.
    pub cells: Vec<Piece>,
    /// Event budget: the run fails after this many events (default 10^9).
    pub max_events: u64,
    /// Free text about the scene, if given.
    pub description: Option<String>,
}

impl ContinuumScene {
    /// The scene's string (the load after the release), with the
    /// constraint on or off.
    pub fn string(&self, constraint: bool) -> Continuum {
        Continuum {
            length: self.length,
            wave_speed: self.wave_speed,
            load: self.load_after,
            constraint,
        }
    }

    /// The times `trace.csv` samples: `linspace(0, t_end, samples)`.
    pub fn sample_times(&self) -> Vec<f64> {
        extent::sample_times(self.t_end, self.samples)
    }

    /// Every time the run samples (snapshots and trace rows).
    pub fn due_times(&self) -> Vec<f64> {
        extent::due_times(&self.snapshots, self.sample_times())
    }

    /// The centres of the `resolution` cells `profiles.json` samples.
    pub fn profile_points(&self) -> Vec<f64> {
        let cell = self.length / self.resolution as f64;
        (0..self.resolution)
            .map(|i| -0.5 * self.length + (i as f64 + 0.5) * cell)
            .collect()
    }
}

/// The registry's validator of continuum scenes.
pub(crate) fn scene(f: Fields) -> Result<Scene, SceneError> {
    validate(f).map(Scene::new)
}

pub(crate) fn validate(mut f: Fields) -> Result<ContinuumScene, SceneError> {
    let variant = match f.optional("variant") {
        None => Variant::Paper,
        Some(v) => match v.as_str() {
            Some("paper") => Variant::Paper,
            Some("homogenized") => Variant::Homogenized,
            Some(other) => {
                return Err(SceneError::field(
                    "variant",
                    format!("unknown variant {other:?} (known: \"paper\", \"homogenized\")"),
                ));
            }
            None => {
                return Err(SceneError::field(
                    "variant",
                    format!("must be a string, found {}", kind(v)),
                ));
            }
        },
    };
    let length = f.number_where("length", "> 0", |x| x > 0.0)?;
    let wave_speed = f.number_where("wave_speed", "> 0", |x| x > 0.0)?;
    if !(wave_speed * wave_speed).is_finite() {
        return Err(SceneError::field(
            "wave_speed",
            format!("makes F_cr = wave_speed^2 overflow (got {wave_speed:e}); rescale the scene"),
        ));
    }
    let (load_before, load_after) = extent::load(f.required("load")?)?;
    let constraint = extent::constraint(&mut f)?;
    if variant == Variant::Homogenized && !constraint {
        return Err(SceneError::field(
            "constraint",
            "the homogenized string keeps the rattling the constraint causes; without it use the paper variant (the classical string)".into(),
        ));
    }
    let t_end = f.number_where("t_end", "> 0", |t| t > 0.0)?;
    let snapshots = extent::snapshots(&mut f, t_end)?;
    let samples = extent::samples(&mut f)?;
    let resolution = match f.optional_count("resolution")? {
        None => 400,
        Some(n) if (1..=MAX_CELLS).contains(&n) => n as usize,
        Some(n) => {
            return Err(SceneError::field(
                "resolution",
                format!("must be a whole number from 1 to {MAX_CELLS} (got {n})"),
            ));
        }
    };
    let at_rest = Piece {
        strain: load_before - 1.0,
        velocity: 0.0,
    };
    let cells = match f.optional("initial") {
        None => vec![at_rest],
        Some(v) => initial(v, at_rest)?,
    };
    if constraint && let Some(n) = cells.iter().position(|p| p.strain < 0.0) {
        let (field, from) = if f.has("initial") {
            (
                "initial.strain",
                format!("initial.strain[{n}] is {}", cells[n].strain),
            )
        } else {
            (
                "load.before",
                format!(
                    "load.before = {load_before} puts the string at strain {}",
                    at_rest.strain
                ),
            )
        };
        return Err(SceneError::field(
            field,
            format!(
                "{from}, below zero, which the constraint forbids (use \"constraint\": false for the classical string)"
            ),
        ));
    }
    if variant == Variant::Homogenized && resolution > MAX_FINITE_VOLUMES {
        return Err(SceneError::field(
            "resolution",
            format!(
                "the homogenized string runs on at most {MAX_FINITE_VOLUMES} cells (got {resolution}); its cost grows as the square of the cells"
            ),
        ));
    }
    let max_events = f.optional_count("max_events")?.unwrap_or(1_000_000_000);
    let description = f.optional_string("description")?.map(str::to_string);
    f.finish()?;
    Ok(ContinuumScene {
        variant,
        length,
        wave_speed,
        load_before,
        load_after,
        constraint,
        t_end,
        snapshots,
        samples,
        resolution,
        cells,
        max_events,
        description,
    })
}

/// `initial`: strains and velocities of equal cells (either may be left
/// out, taking the state at rest; given both, they must agree in length).
fn initial(value: &Value, at_rest: Piece) -> Result<Vec<Piece>, SceneError> {
    let mut f = Fields::open(value, "initial")?;
    let strain = f.optional("strain");
    let velocity = f.optional("velocity");
    f.finish()?;
    let cells = match (strain, velocity) {
        (Some(Value::Array(a)), _) | (None, Some(Value::Array(a))) => a.len(),
        (Some(v), _) | (None, Some(v)) => {
            let path = if strain.is_some() {
                "initial.strain"
            } else {
                "initial.velocity"
            };
            return Err(SceneError::field(
                path,
                format!("must be an array of numbers, found {}", kind(v)),
            ));
        }
        (None, None) => return Ok(vec![at_rest]),
    };
    if cells == 0 || cells as u64 > MAX_CELLS {
        return Err(SceneError::field(
            "initial",
            format!("must give from 1 to {MAX_CELLS} cells (got {cells})"),
        ));
    }
    let read = |v: Option<&Value>, path: &str, rest: f64| {
        v.map(|v| extent::numbers(v, path, Some((cells, "cell"))))
            .transpose()
            .map(|x| x.unwrap_or_else(|| vec![rest; cells]))
    };
    let strain = read(strain, "initial.strain", at_rest.strain)?;
    let velocity = read(velocity, "initial.velocity", 0.0)?;
    Ok(strain
        .into_iter()
        .zip(velocity)
        .map(|(strain, velocity)| Piece { strain, velocity })
        .collect())
}

/// A continuum scene names no solver: it runs by its own method.
pub(super) const OWN_METHOD: SolverSpec = SolverSpec {
    method: None,
    rtol: None,
    atol: None,
    step: None,
};
