//! The one door into flicker for its front ends, the command line
//! (`src/cli`) and the Python binding (`python/src`): each thing a user
//! asks is a request here, checked against its scene before anything runs
//! or any file is touched, and run here, so it means the same from either.
//! The front ends only convert values in (flags, keywords) and out
//! (printed lines, files, NumPy columns).
//!
//! | asked by | door |
//! |---|---|
//! | `run`, `flicker.run` | [`RunRequest`] → [`PreparedRun`] |
//! | `check`, `flicker.check` | [`read`] → [`Input::check_lines`] |
//! | `compare`, `flicker.compare` | [`CompareRequest`] → [`Comparison`] |
//! | `sweep`, `merge`, `flicker.sweep` | [`load`], [`read`] → [`SweepRun`], [`merge`] |
//! | `diagram` | [`DiagramRequest`] → [`PreparedDiagram`] |
//! | `basins` | [`BasinsRequest`] → [`PreparedBasins`] |
//! | `stress` | [`stress()`] |
//! | `compare-models` | [`ModelsRequest`] → [`ModelsCompared`] |
//! | `advise` | [`probe`] |
//! | `orbit`, `continue`, `flicker.orbit`, `flicker.continuation` | [`SearchRequest`] → [`Prepared`] |
//! | `lyapunov`, `flicker.lyapunov` | [`SpectrumRequest`] → [`Prepared`] |
//! | `plot phase` | [`mechanism_portrait`], [`state_plane`] |
//! | `schema`, `events`, `plot DIR` | read or write files only: [`Registry::schema`], `log`, `plot` |
//!
//! Besides its doors, this face names what the front ends read and write
//! of the layers below (reports, statuses, rows); they name nothing else
//! of the library but the log and picture files (`log`, `plot`), which
//! `tests/flicker/one_door.rs` checks.

mod basins;
mod compare;
mod diagram;
mod portraits;
mod releases;
mod run;
mod search;
mod spectrum;
mod stress;
mod sweeps;

pub use basins::{BasinsRequest, PreparedBasins};
pub use compare::{CompareRequest, Comparison};
pub use diagram::{DiagramRequest, PreparedDiagram};
pub use portraits::{mechanism_portrait, state_plane};
pub use releases::{Measured, ModelsCompared, ModelsRequest, NotProbed, PROBE_UNITS, Probe, probe};
pub use run::{Ask, PreparedRun, Refused, RunRequest, Samples};
pub use search::SearchRequest;
pub use spectrum::SpectrumRequest;
pub use stress::stress;
pub use sweeps::{Input, Source, SweepRun, load, merge, read};

// What the front ends read and write of the layers below.
pub use crate::analysis::basins::{
    Attractor, Basins, Kind as AttractorKind, Request as BasinsSettings,
};
pub use crate::analysis::diagram::{Diagram, DiagramPoint, Request as DiagramSettings};
pub use crate::analysis::lyapunov::Spectrum;
pub use crate::analysis::orbit::continuation::{Branch, Point};
pub use crate::analysis::orbit::diagram::Column;
pub use crate::analysis::orbit::{Orbit, Watch};
pub use crate::analysis::release_convergence::{DEFAULT_CELLS, Track};
pub use crate::analysis::release_convergence::{chart as release_chart, files as release_files};
pub use crate::analysis::stress::{Row as StressRow, Verdict, markdown as stress_markdown};
pub use crate::analysis::sweep::{Row as SweepRow, Shard, Sweep, write_csv as write_sweep_csv};
pub use crate::analysis::work_precision::{Row as CompareRow, chart as compare_chart};
pub use crate::analysis::work_precision::{
    read_csv as read_compare_csv, write_csv as write_compare_csv,
};
pub use crate::engine::step::method::NAMES as METHODS;
pub use crate::engine::{EventRecord, Limits, Name, Observer, Status};
pub use crate::runner::ensemble::EnsembleRequest;
pub use crate::runner::{FieldOutputs, Profile, Report, TraceRow, Trajectory, deadline_in};
pub use crate::scene::solver::SolverSpec;
pub use crate::scene::{Registry, Scene, SceneError};

use crate::engine::Family;

/// A tool's request resolved against its scene: the scene's model as the
/// tools see it and the settings they run with. The command line and
/// Python both run it; they only convert what goes in and what comes out.
pub struct Prepared<R> {
    /// The scene's model as the tools see it.
    pub family: Box<dyn Family>,
    /// The tool's settings.
    pub request: R,
    /// The scene's `t_end`: the latest any return may come.
    t_max: f64,
}

/// The instant `wall` seconds from now (a tool's `--wall`), refused as
/// field `wall` where it is not a time > 0.
fn deadline(wall: f64) -> Result<Option<std::time::Instant>, SceneError> {
    crate::runner::deadline_in(wall).map_err(|why| SceneError::field("wall", why))
}

/// The shard `I/N` asked for, or the whole, refused as field `shard`.
fn shard(asked: Option<&str>) -> Result<Shard, SceneError> {
    asked.map_or(Ok(Shard::WHOLE), |text| {
        Shard::parse(text).map_err(|e| SceneError::field("shard", e))
    })
}
