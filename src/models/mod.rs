//! Models built on the engine: the mechanism, the chain of N mechanisms,
//! and the continuum. Each is an ordinary [`HybridModel`] or
//! [`LocalModel`]; the engine knows nothing of them.
//!
//! [`HybridModel`]: crate::engine::HybridModel
//! [`LocalModel`]: crate::engine::LocalModel

pub mod automaton;
pub mod chain;
pub mod continuum;
pub mod mechanism;
