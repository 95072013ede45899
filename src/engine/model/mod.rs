//! The model interface: what a hybrid model tells the engine (its state,
//! modes, flows, guards and resets: [`hybrid`]), the names and labels it
//! gives its parts and events, an affine flow it may declare for the
//! exact propagator, and what the tools ask of a model ([`family`], with
//! models built from parameter values, [`with_parameters`]).

pub mod affine_flow;
pub mod family;
pub mod hybrid;
pub mod labels;
pub mod names;
pub mod with_parameters;

pub use hybrid::*;
