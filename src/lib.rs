//! flicker: an event-driven engine for hybrid automata.
pub mod engine;
pub mod models;
pub mod time;
