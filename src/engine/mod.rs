//! The generic hybrid-systems engine: models declare flows, guards and
//! resets ([`model`]); one run loop (`run_loop.rs`) drives either source
//! of segments, the whole state ([`simulation`]) or an event-local model
//! ([`local`]), and returns the [`Outcome`] of a run ([`run`]).

pub mod adaptive;
pub mod affine_flow;
pub mod affine_mode;
pub mod bound;
mod commuting;
pub mod dop853;
pub mod dopri5;
pub mod error_set;
pub mod family;
pub mod horizon;
pub mod integrator;
pub mod labels;
mod ledger;
pub mod linear;
pub mod local;
pub mod locate;
pub mod method;
pub mod model;
pub mod names;
pub mod observer;
pub mod period_record;
pub mod periodic;
pub mod problem;
pub mod queue;
pub mod run;
mod run_loop;
pub mod saltation;
mod sharpen;
pub mod simulation;
pub mod tangent;
pub mod taylor_method;
pub mod variational;
pub mod verlet;
pub mod with_parameters;
pub mod zeno;

pub use adaptive::Tolerances;
pub use family::{Family, Promoted};
pub use labels::{Label, Labels};
pub use local::{Accuracy, Fired, LocalModel, simulate_local};
pub use method::Method;
pub use model::{Affects, Direction, Flow, Guard, HybridModel, Jump, Mode};
pub use names::Name;
pub use observer::{EachEvent, EventRecord, EventTimes, Observer, RecordedEvent, Recorder, SETTLE};
pub use problem::{Limits, Problem};
pub use run::{ErrorEstimate, FastForward, Options, Outcome, Status};
pub use simulation::{Sample, simulate, simulate_sampled};
