//! What most programs need, in one import: `use flicker::prelude::*;`.
//!
//! - writing a model: [`HybridModel`] and what it returns ([`Flow`],
//!   [`Guard`], [`Direction`], [`Jump`], [`Mode`]);
//! - running it: [`simulate`] (or [`simulate_sampled`]) under [`Options`]
//!   with a [`Method`] and [`Tolerances`], giving an [`Outcome`] whose
//!   [`Status`] says how it ended; events to an [`Observer`] (a
//!   [`Recorder`] keeps them, each an [`EventRecord`]);
//! - scenes: [`Registry`] (the crate's own kinds:
//!   [`Registry::builtin`]), [`Scene`], run under a [`Control`] as a
//!   [`RunRequest`] asks;
//! - tools on any model: its [`Family`].

pub use crate::engine::{
    Direction, EventRecord, Family, Flow, Guard, HybridModel, Jump, Method, Mode, Observer,
    Options, Outcome, Recorder, Status, Tolerances, simulate, simulate_sampled,
};
pub use crate::runner::Control;
pub use crate::scene::{Registry, Scene};
pub use crate::session::RunRequest;
