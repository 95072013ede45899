//! The generic hybrid-systems engine, in four parts, each importing only
//! from those before it:
//! - [`model`]: what a model tells the engine (flows, guards, resets) and
//!   what the tools ask of it;
//! - [`bound`]: tangents, saltation and the error bound a run states;
//! - [`step`]: the integrators, which method a mode gets, and event
//!   location inside a step;
//! - [`run`]: the one run loop, driven by the whole state ([`simulate`]) or
//!   an event-local model ([`simulate_local`]), its books and watches, and
//!   the [`Outcome`] it returns.

pub mod bound;
pub mod model;
pub mod run;
pub mod step;

pub use bound::ErrorEstimate;
pub use model::family::{Family, Promoted};
pub use model::labels::{Label, Labels};
pub use model::names::Name;
pub use model::{Affects, Direction, Flow, Guard, HybridModel, Jump, Mode};
pub use run::local::{Accuracy, Fired, LocalModel, simulate_local};
pub use run::observer::{
    EachEvent, EventRecord, EventTimes, Observer, RecordedEvent, Recorder, SETTLE,
};
pub use run::problem::{Limits, MAX_EVENTS, Problem};
pub use run::simulation::{Sample, simulate, simulate_sampled};
pub use run::{FastForward, Options, Outcome, Status};
pub use step::adaptive::Tolerances;
pub use step::method::Method;
