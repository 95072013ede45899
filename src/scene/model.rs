//! What a kind of scene offers the tools, and the registry that finds it
//! by the scene's `"model"`.
//!
//! Every command (`run`, `check`, `compare`, `stress`, `sweep`...) asks a
//! [`SceneModel`] what it needs: its time span and solver, the methods it
//! can run, what to say of it in `check`, the run itself, and where the
//! model has them an exact reference and a period. No command matches on
//! the kind of model, so a new kind is its validator, this one impl and
//! its JSON Schema: registered in a [`Registry`], every tool takes it, and
//! the scene schema (`flicker schema`, `schemas/scene.schema.json`) is the
//! registry's.

use std::any::Any;
use std::fmt;

use serde_json::Value;

use crate::engine::Limits;
use crate::engine::{Family, Observer};
use crate::runner::ensemble::{EnsembleReport, EnsembleRequest};
use crate::runner::{Report, Trajectory};
use crate::scene::Reference;
use crate::scene::SceneError;
use crate::scene::fields::{Fields, kind};
use crate::scene::solver::SolverSpec;

/// A validated scene of one kind of model.
pub trait SceneModel: fmt::Debug + Send + Sync + 'static {
    /// The scene's `"model"`, as the registry knows it.
    fn model(&self) -> &'static str;

    /// Simulated time to run to.
    fn t_end(&self) -> f64;

    /// Replace `t_end` (already checked finite and positive), checking it
    /// against the rest of the scene.
    fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError>;

    /// The solver as the scene wrote it.
    fn solver(&self) -> &SolverSpec;

    /// Replace the solver, checking it against the model.
    fn set_solver(&mut self, spec: SolverSpec) -> Result<(), SceneError>;

    /// The methods this scene can run, in the names of `solver.method`,
    /// cheapest exact description first.
    fn methods(&self) -> Vec<&'static str>;

    /// The natural time scale of the scene (a period of its linear flow, a
    /// wave's crossing time): what fixed steps are fractions of.
    fn time_scale(&self) -> f64;

    /// Lines describing the scene for `flicker check` (after the line that
    /// names the file and the model).
    fn describe(&self) -> Vec<String>;

    /// Run the scene under `limits`, reporting events to `observer`.
    fn run(&self, limits: &Limits, observer: &mut dyn Observer) -> Result<Report, SceneError>;

    /// The scene's model as the tools see it: the hybrid model, where the
    /// scene starts, and its parameters. Periodic orbits, continuation,
    /// bifurcation diagrams and sensitivities run on it, whatever the
    /// kind. A kind with no finite state says why.
    fn family(&self) -> Result<Box<dyn Family>, SceneError> {
        Err(SceneError::field(
            "model",
            format!(
                "a {} scene has no finite state for a tool to follow",
                self.model()
            ),
        ))
    }

    /// The exact answer numerical methods are measured against
    /// (`flicker compare`, `flicker stress`), where the model has one.
    fn reference(&self) -> Result<Reference, SceneError> {
        Err(SceneError::field(
            "model",
            format!(
                "a {} scene has no exact reference to measure methods against",
                self.model()
            ),
        ))
    }

    /// The closed-form period of the orbit the scene starts on, where the
    /// model knows one and the orbit has one (a sweep's `exact_period`).
    fn period(&self) -> Option<f64> {
        None
    }

    /// The run with its state sampled at `times` (increasing, up to
    /// `t_end`), events reported to `observer` with their states: what
    /// `flicker plot phase SCENE` draws any two states from. `None` where
    /// the model offers no samples of its state.
    fn sampled(
        &self,
        limits: &Limits,
        times: &[f64],
        observer: &mut dyn Observer,
    ) -> Option<Result<Trajectory, SceneError>> {
        let _ = (limits, times, observer);
        None
    }

    /// Whether [`sampled`](SceneModel::sampled) gives samples, asked
    /// before anything runs.
    fn offers_samples(&self) -> bool {
        false
    }

    /// Whether `flicker run --ensemble` can run this scene as `request`
    /// asks, checked before anything runs.
    fn check_ensemble(&self, request: &EnsembleRequest) -> Result<(), SceneError> {
        let _ = request;
        Err(SceneError::field(
            "ensemble",
            format!(
                "a {} scene has no ensemble of perturbed copies",
                self.model()
            ),
        ))
    }

    /// Run the perturbed copies of this scene that [`check_ensemble`]
    /// accepted, and say how far apart they drift; an error says which copy
    /// stopped and why.
    ///
    /// [`check_ensemble`]: SceneModel::check_ensemble
    fn ensemble(
        &self,
        request: &EnsembleRequest,
        limits: &Limits,
    ) -> Result<EnsembleReport, String> {
        self.check_ensemble(request).map_err(|e| e.reason)?;
        let _ = limits;
        Err(format!("a {} scene has no ensemble", self.model()))
    }

    /// A copy behind a new box (scenes are cloned per sweep point and per
    /// method compared).
    fn clone_box(&self) -> Box<dyn SceneModel>;

    /// The scene as `Any`, for a program's own tools made for one kind of
    /// model.
    fn as_any(&self) -> &dyn Any;
}

/// A validated scene of any registered kind.
#[derive(Debug)]
pub struct Scene(Box<dyn SceneModel>);

impl Scene {
    /// Wrap a validated scene.
    pub fn new(model: impl SceneModel) -> Self {
        Scene(Box::new(model))
    }

    /// The scene as its concrete kind, if it is of kind `T`.
    pub fn downcast_ref<T: SceneModel>(&self) -> Option<&T> {
        self.0.as_any().downcast_ref()
    }

    /// Replace `t_end` (from the command line), checking it.
    pub fn set_t_end(&mut self, t_end: f64) -> Result<(), SceneError> {
        if !(t_end.is_finite() && t_end > 0.0) {
            return Err(SceneError::field(
                "t_end",
                format!("must be a finite number > 0 (got {t_end})"),
            ));
        }
        self.0.set_t_end(t_end)
    }

    /// What `flicker check` says of the scene, a line each: `label` (the
    /// file), that it is valid and of which model, then what its model
    /// describes.
    pub fn check_lines(&self, label: &str) -> Vec<String> {
        let mut lines = self.describe().into_iter();
        let mut said = vec![format!(
            "{label}: a valid {} scene ({})",
            self.model(),
            lines.next().unwrap_or_default()
        )];
        said.extend(lines.map(|line| format!("  {line}")));
        said
    }

    /// Override the solver with what the command line gave (the fields it
    /// sets replace the scene's), checking it.
    pub fn override_solver(&mut self, flags: &SolverSpec) -> Result<(), SceneError> {
        let spec = self.0.solver().overridden_by(flags);
        self.0.set_solver(spec)
    }
}

impl Clone for Scene {
    fn clone(&self) -> Self {
        Scene(self.0.clone_box())
    }
}

impl std::ops::Deref for Scene {
    type Target = dyn SceneModel;

    fn deref(&self) -> &Self::Target {
        &*self.0
    }
}

impl std::ops::DerefMut for Scene {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut *self.0
    }
}

/// The largest scene file read: 64 MiB (a chain of 10^6 units with its
/// initial strains and velocities takes about 40 MB).
pub const MAX_SCENE_BYTES: u64 = 64 << 20;

/// Validates the keys of one kind of scene (all but `"model"`).
pub type Validator = fn(Fields) -> Result<Scene, SceneError>;

/// One kind of scene: its `"model"`, its validator, and its JSON Schema
/// (the definition of one scene object, as JSON text; it may refer to the
/// shared `#/$defs/positive`).
#[derive(Debug, Clone, Copy)]
pub struct Kind {
    /// The scene's `"model"`.
    pub model: &'static str,
    /// Validates the scene's other keys.
    pub validate: Validator,
    /// The JSON Schema of the scene, as text.
    pub schema: &'static str,
}

/// The kinds of scene a program knows, by their `"model"`.
#[derive(Debug, Clone)]
pub struct Registry {
    kinds: Vec<Kind>,
}

/// The schema of the scene file, less the kinds' own definitions.
const SCENE_SCHEMA_TITLE: &str = "flicker scene";
const SCENE_SCHEMA_DESCRIPTION: &str = "A scene file for `flicker run`. The schema states the shape; `flicker check SCENE.json` also checks what a schema cannot (an energy no state has, an initial angle given to the strain formulation, ...).";

impl Registry {
    /// A registry of these kinds, in this order (the order of the scene
    /// schema's `oneOf`). [`Registry::builtin`] is the crate's own.
    pub fn of(kinds: Vec<Kind>) -> Self {
        Registry { kinds }
    }

    /// The same registry, knowing one more kind (or another definition of
    /// a kind it knew).
    pub fn with(mut self, kind: Kind) -> Self {
        self.kinds.retain(|known| known.model != kind.model);
        self.kinds.push(kind);
        self
    }

    /// The JSON Schema of a scene file of any kind this registry knows:
    /// one of the kinds' definitions. Fails, naming the kind, if a
    /// definition is not JSON.
    pub fn schema(&self) -> Result<Value, String> {
        let mut defs = serde_json::Map::new();
        defs.insert(
            "positive".into(),
            serde_json::json!({"type": "number", "exclusiveMinimum": 0}),
        );
        let mut one_of = Vec::new();
        for kind in &self.kinds {
            let schema: Value = serde_json::from_str(kind.schema)
                .map_err(|e| format!("the schema of model {:?} is not JSON: {e}", kind.model))?;
            defs.insert(kind.model.into(), schema);
            one_of.push(serde_json::json!({"$ref": format!("#/$defs/{}", kind.model)}));
        }
        Ok(serde_json::json!({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": SCENE_SCHEMA_TITLE,
            "description": SCENE_SCHEMA_DESCRIPTION,
            "oneOf": one_of,
            "$defs": defs,
        }))
    }

    /// Validate a scene given as a parsed JSON value.
    pub fn from_value(&self, value: &Value) -> Result<Scene, SceneError> {
        let mut fields = Fields::open(value, "")?;
        let model = fields.required("model")?;
        let Some(name) = model.as_str() else {
            return Err(SceneError::field(
                "model",
                format!("must be a string, found {}", kind(model)),
            ));
        };
        match self.kinds.iter().find(|kind| kind.model == name) {
            Some(kind) => (kind.validate)(fields),
            None => {
                let known: Vec<String> = self
                    .kinds
                    .iter()
                    .map(|kind| format!("{:?}", kind.model))
                    .collect();
                Err(SceneError::field(
                    "model",
                    format!("unknown model {name:?} (known: {})", known.join(", ")),
                ))
            }
        }
    }

    /// Validate a scene given as JSON text.
    pub fn parse(&self, text: &str) -> Result<Scene, SceneError> {
        let value: Value = serde_json::from_str(text).map_err(|e| SceneError {
            file: None,
            field: None,
            reason: format!("is not valid JSON: {e}"),
            untrusted: false,
        })?;
        self.from_value(&value)
    }

    /// Read and validate the scene in `path` (at most [`MAX_SCENE_BYTES`]).
    pub fn load(&self, path: &std::path::Path) -> Result<Scene, SceneError> {
        use std::io::Read;
        let refuse = |reason: String| SceneError {
            file: Some(path.to_path_buf()),
            field: None,
            reason,
            untrusted: false,
        };
        let file = std::fs::File::open(path).map_err(|e| refuse(format!("cannot be read: {e}")))?;
        // Read one byte past the limit to tell a file at the limit from a larger one.
        let mut text = String::new();
        file.take(MAX_SCENE_BYTES + 1)
            .read_to_string(&mut text)
            .map_err(|e| refuse(format!("cannot be read: {e}")))?;
        if text.len() as u64 > MAX_SCENE_BYTES {
            return Err(refuse(format!(
                "is larger than {MAX_SCENE_BYTES} bytes: too large for a scene"
            )));
        }
        self.parse(&text).map_err(|e| e.in_path(path))
    }
}
