//! The generic hybrid-systems engine: models declare flows, guards and
//! resets ([`model`]); the simulation owns the event queue, event location
//! and the loop ([`simulation`]).

pub mod adaptive;
pub mod bound;
pub mod dop853;
pub mod dopri5;
pub mod error_set;
pub mod integrator;
pub mod labels;
pub mod linear;
pub mod local;
pub mod locate;
pub mod model;
pub mod observer;
pub mod queue;
pub mod simulation;
pub mod tangent;
pub mod verlet;
pub mod zeno;

pub use adaptive::Tolerances;
pub use integrator::Method;
pub use labels::{Label, Labels};
pub use local::{Fired, LocalModel, simulate_local};
pub use model::{Affects, Direction, Flow, Guard, HybridModel, Jump, Mode};
pub use observer::{EventRecord, EventTimes, Observer, RecordedEvent, Recorder, SETTLE};
pub use simulation::{Options, Outcome, Sample, Status, simulate, simulate_sampled};
