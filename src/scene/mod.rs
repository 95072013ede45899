//! JSON scene files: parsed into what was typed, then validated into models.
//!
//! A scene names its model (`"model": "mechanism"`) and gives that model's
//! keys; every error names the file, the key's path and the reason, e.g.
//! `models/x.json: field initial.strain: must be >= 0 (got -0.1)`. Unknown
//! keys are errors, so a typo never silently falls back to a default.
//! The keys of each model are documented in its module ([`mechanism`],
//! [`chain`], [`continuum`]).

pub mod chain;
pub mod continuum;
pub mod extent;
pub mod fields;
pub mod mechanism;
pub mod solver;

use std::fmt;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::engine::Method;
pub use crate::scene::chain::ChainScene;
pub use crate::scene::continuum::ContinuumScene;
use crate::scene::fields::{Fields, kind};
pub use crate::scene::mechanism::{Formulation, Initial, MechanismScene};

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub enum Scene {
    Mechanism(MechanismScene),
    Chain(ChainScene),
    Continuum(ContinuumScene),
}

impl Scene {
    /// Simulated time to run to.
    pub fn t_end(&self) -> f64 {
        match self {
            Scene::Mechanism(m) => m.t_end,
            Scene::Chain(c) => c.t_end,
            Scene::Continuum(c) => c.t_end,
        }
    }

    /// Override the solver with what the command line gave (the fields it
    /// sets replace the scene's), checking it.
    pub fn override_solver(&mut self, flags: &solver::SolverSpec) -> Result<(), SceneError> {
        let spec = match self {
            Scene::Mechanism(m) => m.solver.overridden_by(flags),
            Scene::Chain(c) => c.solver.overridden_by(flags),
            Scene::Continuum(_) => flags.clone(),
        };
        self.set_solver(spec)
    }

    /// Replace the solver, checking it against the model.
    pub fn set_solver(&mut self, spec: solver::SolverSpec) -> Result<(), SceneError> {
        match self {
            Scene::Mechanism(m) => {
                (m.method, m.tolerances) = mechanism::resolve_solver(&spec, m.formulation)?;
                mechanism::check_steps(m.method, m.t_end)?;
                m.solver = spec;
            }
            Scene::Chain(c) => {
                (c.method, c.tolerances) = chain::resolve_solver(&spec, c.units)?;
                mechanism::check_steps(c.method, c.t_end)?;
                c.solver = spec;
            }
            Scene::Continuum(_) => {
                // Front tracking is exact and the only method offered.
                let (method, _) = spec.resolve()?;
                if !matches!(method, Method::Auto | Method::Exact) {
                    return Err(SceneError::field(
                        "solver.method",
                        format!(
                            "a continuum runs by its own method only (exact front tracking, or finite volumes for the homogenized string), not {}",
                            method.name()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Replace `t_end` (from the command line), checking it; a chain scene
    /// keeps only the snapshots up to it.
    pub fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError> {
        if !(t_end.is_finite() && t_end > 0.0) {
            return Err(SceneError::field(
                "t_end",
                format!("must be a finite number > 0 (got {t_end})"),
            ));
        }
        match self {
            Scene::Mechanism(m) => {
                mechanism::check_steps(m.method, t_end)?;
                m.t_end = t_end;
            }
            Scene::Chain(c) => {
                mechanism::check_steps(c.method, t_end)?;
                // A shortened run takes the snapshots it reaches.
                c.snapshots.retain(|&t| t <= t_end);
                c.t_end = t_end;
            }
            Scene::Continuum(c) => {
                c.snapshots.retain(|&t| t <= t_end);
                c.t_end = t_end;
            }
        }
        Ok(())
    }
}

/// Why a scene was refused: where, and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    pub file: Option<PathBuf>,
    /// Dotted path of the offending key, or `None` for the file as a whole.
    pub field: Option<String>,
    pub reason: String,
}

impl SceneError {
    pub fn field(path: &str, reason: String) -> Self {
        SceneError {
            file: None,
            field: Some(path.to_string()),
            reason,
        }
    }

    /// The same error, said of the file `file`.
    pub fn in_path(mut self, file: &Path) -> Self {
        self.file = Some(file.to_path_buf());
        self
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(file) = &self.file {
            write!(f, "{}: ", file.display())?;
        }
        if let Some(field) = &self.field {
            write!(f, "field {field}: ")?;
        }
        f.write_str(&self.reason)
    }
}

impl std::error::Error for SceneError {}

/// Read and validate the scene in `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: Some(path.to_path_buf()),
        field: None,
        reason: format!("cannot be read: {e}"),
    })?;
    parse(&text).map_err(|e| e.in_path(path))
}

/// Validate a scene given as JSON text.
pub fn parse(text: &str) -> Result<Scene, SceneError> {
    let value: Value = serde_json::from_str(text).map_err(|e| SceneError {
        file: None,
        field: None,
        reason: format!("is not valid JSON: {e}"),
    })?;
    from_value(&value)
}

/// Validate a scene given as a parsed JSON value.
pub fn from_value(value: &Value) -> Result<Scene, SceneError> {
    let mut fields = Fields::open(value, "")?;
    let model = fields.required("model")?;
    match model.as_str() {
        Some("mechanism") => mechanism::validate(fields).map(Scene::Mechanism),
        Some("chain") => chain::validate(fields).map(Scene::Chain),
        Some("continuum") => continuum::validate(fields).map(Scene::Continuum),
        Some(other) => Err(SceneError::field(
            "model",
            format!("unknown model {other:?} (known: \"mechanism\", \"chain\", \"continuum\")"),
        )),
        None => Err(SceneError::field(
            "model",
            format!("must be a string, found {}", kind(model)),
        )),
    }
}
