//! One bistable mechanism (paper s.2-3): the closed form, and the two
//! hybrid models built on it, strain (exact, with impacts) and angle
//! (smooth, integrated numerically).

pub mod angle;
pub mod closed_form;
pub mod family;
pub(crate) mod run;
pub mod scene;
mod scene_model;
pub mod strain;

pub use angle::{AngleMechanism, Charts};
pub use closed_form::{ExactOrbit, Mechanism, Phase};
pub use strain::StrainMechanism;
