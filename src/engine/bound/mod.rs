//! Tangents, saltation and bounds: how a small change of the state is
//! carried through a stretch of flow ([`tangent`]) and across an event
//! ([`saltation`]), the derivatives a run carries beside its state
//! ([`variational`]), and the error bound a run states, kept as it goes
//! ([`tracker`], in the enclosures of [`error_set`]), with the rules that
//! decide where it can no longer be kept: events whose order is in doubt
//! (`commuting.rs`), events closer than the run resolves, the Zeno watch's
//! to judge ([`zeno`]), and the run's horizon ([`horizon`]). What the bound did
//! over a period is recorded for a jump over whole periods
//! ([`period_record`]).

mod commuting;
pub mod error_set;
pub mod horizon;
pub mod period_record;
pub mod saltation;
pub mod tangent;
pub mod tracker;
pub mod variational;
pub mod zeno;

pub use error_set::ROUNDOFF_ULPS;
pub(crate) use tracker::Bound;
pub use tracker::ErrorEstimate;
