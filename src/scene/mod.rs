//! JSON scene files: parsed into what was typed, then validated into models.
//!
//! A scene names its model (`"model": "mechanism"`) and gives that model's
//! keys; every error names the file, the key's path and the reason, e.g.
//! `models/x.json: field initial.strain: must be >= 0 (got -0.1)`. Unknown
//! keys are errors, so a typo never silently falls back to a default.
//! Each model's scene lives in the model's own folder, its keys documented
//! there ([`crate::models::mechanism::scene`],
//! [`crate::models::chain::scene`], [`crate::models::continuum::scene`]);
//! what every kind of scene offers the tools, and the registry of kinds,
//! in [`model`]; keys several kinds share in [`extent`] and [`solver`].

pub mod extent;
pub mod fields;
pub mod model;
pub mod reference;
pub mod solver;

use std::fmt;
use std::path::{Path, PathBuf};

pub use crate::scene::model::{Kind, Registry, Scene, SceneModel, Validator};
pub use crate::scene::reference::Reference;

/// Why a scene was refused: where, and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The scene file, once known ([`SceneError::in_path`]).
    pub file: Option<PathBuf>,
    /// Dotted path of the offending key, or `None` for the file as a whole.
    pub field: Option<String>,
    /// What is wrong, in one sentence.
    pub reason: String,
    /// Whether the input was fine but a run it needed could not be trusted
    /// (a reference run that failed): exit 3, not 2.
    pub untrusted: bool,
}

impl SceneError {
    /// An error in the key at the dotted path `path`, said of no file yet.
    pub fn field(path: &str, reason: String) -> Self {
        SceneError {
            file: None,
            field: Some(path.to_string()),
            reason,
            untrusted: false,
        }
    }

    /// The same error, said of a run that could not be trusted rather
    /// than of bad input.
    pub fn untrusted(mut self) -> Self {
        self.untrusted = true;
        self
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
