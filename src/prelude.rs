//! What most programs need, in one import: `use flicker::prelude::*;`.
//!
//! - writing a model: [`HybridModel`] and what it returns ([`Flow`],
//!   [`Guard`], [`Direction`], [`Jump`], [`Mode`], a [`Name`] and the
//!   [`names!`](crate::names) of its states);
//! - running it: a [`Problem`] (the model, its start, its end) solved by
//!   a [`Method`] (with its [`Tolerances`]) under [`Limits`], or
//!   [`simulate`] (and [`simulate_sampled`]) under [`Options`], which hold
//!   all three; either gives an [`Outcome`] whose [`Status`] says how it
//!   ended; events to an [`Observer`] (a [`Recorder`] keeps them, each an
//!   [`EventRecord`]);
//! - scenes: [`Registry`] (the crate's own kinds:
//!   [`Registry::builtin`]), [`Scene`], run under a [`Limits`] as a
//!   [`RunRequest`] asks;
//! - tools on any model: its [`Family`].

pub use crate::engine::{
    Direction, EventRecord, Family, Flow, Guard, HybridModel, Jump, Limits, Method, Mode, Name,
    Observer, Options, Outcome, Problem, Recorder, Status, Tolerances, simulate, simulate_sampled,
};
pub use crate::names;
pub use crate::scene::{Registry, Scene};
pub use crate::session::RunRequest;
