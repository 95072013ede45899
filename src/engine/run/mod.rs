//! The run loop and its books: a run said as a [`problem`], the one event
//! loop every run goes through (`run_loop.rs`), driven by the whole state
//! ([`simulation`]) or by an event-local model ([`local`]); the queue of
//! predicted events ([`queue`]), the books a run keeps (`ledger.rs`),
//! whole periods jumped ([`periodic`]), the
//! observers that receive the events ([`observer`]) and what a run
//! returns ([`outcome`]).

mod ledger;
pub mod local;
pub mod observer;
pub mod outcome;
pub mod periodic;
pub mod problem;
pub mod queue;
mod run_loop;
pub mod simulation;

pub use outcome::*;
