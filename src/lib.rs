//! flicker: an event-driven engine for hybrid automata.
pub mod engine;
pub mod log;
pub mod models;
pub mod runner;
pub mod scene;
pub mod time;
