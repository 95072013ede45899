//! Models built on the engine. Each is an ordinary [`HybridModel`]; the
//! engine knows nothing of them.
//!
//! [`HybridModel`]: crate::engine::HybridModel

pub mod chain;
pub mod mechanism;
