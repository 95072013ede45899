//! Grids of scenes, as `flicker sweep`, `flicker merge` and `flicker
//! check` (and Python's `sweep()` and `check()`) ask them: a file or text
//! read as a scene or a sweep, whichever it is; a sweep's points run in
//! parallel, whole or one shard; shards joined again.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::analysis::sweep::{self, Row, Shard, Sweep};
use crate::engine::Limits;
use crate::scene::{Registry, Scene, SceneError};

/// Where a scene or a sweep is read from.
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// A file; a sweep's `scene` path is read beside it.
    Path(&'a Path),
    /// JSON text; a sweep's `scene` path is read from the working folder.
    Text(&'a str),
}

/// A scene or a sweep (an object with `scene` and `grid`).
#[derive(Debug)]
pub enum Input {
    /// A scene.
    Scene(Scene),
    /// A sweep.
    Sweep(Sweep),
}

impl Input {
    /// What `flicker check` prints of it, a line each, naming it `label`.
    pub fn check_lines(&self, label: &str) -> Vec<String> {
        match self {
            Input::Scene(scene) => scene.check_lines(label),
            Input::Sweep(sweep) => sweep.check_lines(label),
        }
    }
}

/// Read and validate the scene or sweep at `source`, of models `registry`
/// knows. Text that is not JSON, or a file that cannot be read, is left to
/// the scene's own errors.
pub fn read(registry: &Registry, source: Source<'_>) -> Result<Input, SceneError> {
    let (text, folder) = match source {
        Source::Path(path) => match std::fs::read_to_string(path) {
            Ok(text) => (
                text,
                path.parent().map(Path::to_path_buf).unwrap_or_default(),
            ),
            Err(_) => return registry.load(path).map(Input::Scene),
        },
        Source::Text(text) => (text.to_string(), PathBuf::new()),
    };
    let a_sweep = serde_json::from_str::<Value>(&text).is_ok_and(|v| sweep::is_sweep(&v));
    match (a_sweep, source) {
        (true, Source::Path(path)) => sweep::load(path, registry).map(Input::Sweep),
        (true, Source::Text(_)) => sweep::parse_text(&text, &folder, registry).map(Input::Sweep),
        (false, Source::Path(path)) => registry.load(path).map(Input::Scene),
        (false, Source::Text(text)) => registry.parse(text).map(Input::Scene),
    }
}

/// The sweep at `path`, of models `registry` knows.
pub fn load(registry: &Registry, path: &Path) -> Result<Sweep, SceneError> {
    sweep::load(path, registry)
}

/// A sweep's points to run: all, or one shard, on a pool of threads.
pub struct SweepRun<'s> {
    sweep: &'s Sweep,
    shard: Shard,
    pool: rayon::ThreadPool,
}

impl<'s> SweepRun<'s> {
    /// `sweep`'s points in `shard` (`I/N`, or all), on `threads` threads
    /// (default: one per core); the error names `shard` or `threads`.
    pub fn new(
        sweep: &'s Sweep,
        shard: Option<&str>,
        threads: Option<usize>,
    ) -> Result<Self, SceneError> {
        let shard = super::shard(shard)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or(0))
            .build()
            .map_err(|e| SceneError::field("threads", e.to_string()))?;
        Ok(SweepRun { sweep, shard, pool })
    }

    /// The shard run.
    pub fn shard(&self) -> Shard {
        self.shard
    }

    /// The threads the points run on.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// How many points the shard holds.
    pub fn points(&self) -> usize {
        (self.shard.index..self.sweep.points())
            .step_by(self.shard.count)
            .count()
    }

    /// Run the shard's points under `limits` (its stop and deadline leave
    /// the points not begun as such), `done` told of each: a row per point.
    pub fn run(&self, limits: &Limits, done: &(dyn Fn() + Sync)) -> Vec<Row> {
        self.pool
            .install(|| self.sweep.run(self.shard, limits, done))
    }
}

/// The shard CSVs `shards` of `sweep` joined into the text of the CSV a
/// single run writes.
pub fn merge(sweep: &Sweep, shards: &[PathBuf]) -> Result<String, String> {
    sweep::merge(sweep, shards)
}
