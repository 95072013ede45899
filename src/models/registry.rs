//! The kinds of scene this crate ships, as a [`Registry`]: the mechanism,
//! the chain, the continuum, and automata defined in the file. It lives
//! with the models (above the scene layer, which knows no model).

use std::path::Path;

use serde_json::Value;

use crate::scene::{Kind, Registry, Scene, SceneError};

impl Registry {
    /// The models this crate ships: the mechanism, the chain, the
    /// continuum, and automata defined in the file.
    pub fn builtin() -> Self {
        let kind = |model, validate, schema| Kind {
            model,
            validate,
            schema,
        };
        Registry::of(vec![
            kind(
                "mechanism",
                crate::models::mechanism::scene::scene,
                include_str!("mechanism/scene.schema.json"),
            ),
            kind(
                "chain",
                crate::models::chain::scene::scene,
                include_str!("chain/scene.schema.json"),
            ),
            kind(
                "continuum",
                crate::models::continuum::scene::scene,
                include_str!("continuum/scene.schema.json"),
            ),
            kind(
                "automaton",
                crate::models::automaton::scene::scene,
                include_str!("automaton/scene.schema.json"),
            ),
        ])
    }
}

/// Read and validate the scene in `path`, of a model this crate ships.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    Registry::builtin().load(path)
}

/// Validate a scene given as JSON text, of a model this crate ships.
pub fn parse(text: &str) -> Result<Scene, SceneError> {
    Registry::builtin().parse(text)
}

/// Validate a scene given as a parsed JSON value, of a model this crate
/// ships.
pub fn from_value(value: &Value) -> Result<Scene, SceneError> {
    Registry::builtin().from_value(value)
}
