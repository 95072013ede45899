//! Models built on the engine: the mechanism, the chain of N mechanisms,
//! and the continuum, and automata read from a file. Each is an ordinary
//! [`HybridModel`] or [`LocalModel`]; the engine knows nothing of them.
//! Each kind's scene (its JSON keys, and what it offers the tools) lives
//! in its folder; [`load`] and [`parse`] read a scene of any kind the
//! crate ships ([`crate::scene::Registry::builtin`]).
//!
//! [`HybridModel`]: crate::engine::HybridModel
//! [`LocalModel`]: crate::engine::LocalModel

pub mod automaton;
pub mod chain;
pub mod continuum;
pub mod mechanism;
mod registry;

pub use chain::scene::ChainScene;
pub use continuum::scene::ContinuumScene;
pub use mechanism::scene::{Formulation, Initial, MechanismScene};
pub use registry::{from_value, load, parse};
