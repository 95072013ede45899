//! The native half of the Python package `flicker` (`flicker._flicker`):
//! scenes read and run by the engine, the events handed to NumPy as
//! arrays, and the tools `check`, `compare` and `sweep`. The Python half
//! (`python/flicker/__init__.py`) shapes what these return into the
//! package's `Run` and dicts of columns; the engine crate knows nothing of
//! Python.
//!
//! A run releases the GIL, so runs in several Python threads use several
//! cores. It goes on in a thread of its own while the calling thread, every
//! [`POLL`], takes the GIL back to look for a signal: Ctrl-C (in a terminal
//! or a notebook) sets the run's stop flag, and the run returns, status
//! `interrupted`, within a fraction of a second.

mod convert;
mod interrupt;
mod tools;

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use flicker::log::JsonlWriter;
use flicker::log::columns::EventColumns;
use flicker::log::size_notice::{FIRST_NOTICE, LogSize};
use flicker::log::summary::summary;
use flicker::session::{
    Ask, EventRecord, Observer, Registry, RunRequest, Samples, Scene,
    SceneError as EngineSceneError, SolverSpec, Status,
};

create_exception!(
    _flicker,
    SceneError,
    PyValueError,
    "A scene (or an override) that flicker refuses: the message is the command line's, `field` the dotted key at fault (or None), `reason` what is wrong."
);

/// How often the calling thread looks for a signal while a run goes on.
pub(crate) const POLL: Duration = Duration::from_millis(50);

/// The Python exception for an engine's refusal, with its parts.
fn scene_error(py: Python<'_>, e: &EngineSceneError) -> PyErr {
    let err = SceneError::new_err(format!("flicker: {e}"));
    let value = err.value(py);
    let _ = value.setattr("field", e.field.clone());
    let _ = value.setattr("reason", e.reason.clone());
    err
}

/// A word on standard error, as the command line gives it (a run holds
/// no GIL to warn through).
fn say(what: String) {
    eprintln!("flicker: {what}");
}

/// A refusal of an override (a keyword argument), as the command line
/// refuses its flag.
fn override_error(py: Python<'_>, field: &str, reason: String) -> PyErr {
    scene_error(py, &EngineSceneError::field(field, reason))
}

/// The scene given as JSON text or as a file, and the label its messages
/// and summary name it by.
fn load(py: Python<'_>, text: Option<&str>, path: Option<&str>) -> PyResult<(Scene, String)> {
    let registry = Registry::builtin();
    match (path, text) {
        (Some(path), _) => registry
            .load(Path::new(path))
            .map(|scene| (scene, path.to_string()))
            .map_err(|e| scene_error(py, &e)),
        (None, Some(text)) => registry
            .parse(text)
            .map(|scene| (scene, "<scene>".to_string()))
            .map_err(|e| scene_error(py, &e)),
        (None, None) => Err(override_error(
            py,
            "scene",
            "give a path, a JSON string or a dict".into(),
        )),
    }
}

/// The run's observers: the columns, and the log on disk where asked.
struct Keep {
    columns: Option<EventColumns>,
    log: Option<JsonlWriter<LogSize<BufWriter<File>, fn(String)>>>,
}

impl Observer for Keep {
    fn on_event(&mut self, event: &EventRecord) -> std::io::Result<()> {
        if let Some(columns) = &mut self.columns {
            columns.on_event(event)?;
        }
        if let Some(log) = &mut self.log {
            log.on_event(event)?;
        }
        Ok(())
    }

    fn wants_details(&self) -> bool {
        self.columns.is_some() || self.log.is_some()
    }
}

/// Run a scene; see `flicker.run` for what the arguments mean. Returns a
/// dict: `summary` (the JSON text of `summary.json`, with the derivatives
/// along `sensitivities` where asked), `events` (columns,
/// see `convert::events`), `fields` (a chain's or continuum's trace and
/// profiles, or None).
#[pyfunction]
#[pyo3(signature = (text=None, path=None, t_end=None, method=None, rtol=None, atol=None, step=None, log=None, events=true, sensitivities=None, t_eval=None, past_horizon=false))]
#[allow(clippy::too_many_arguments)]
fn run<'py>(
    py: Python<'py>,
    text: Option<&str>,
    path: Option<&str>,
    t_end: Option<f64>,
    method: Option<String>,
    rtol: Option<f64>,
    atol: Option<f64>,
    step: Option<f64>,
    log: Option<&str>,
    events: bool,
    sensitivities: Option<Vec<String>>,
    t_eval: Option<Vec<f64>>,
    past_horizon: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, label) = load(py, text, path)?;
    let request = RunRequest {
        t_end,
        solver: SolverSpec {
            method,
            rtol,
            atol,
            step,
        },
        sensitivities,
        samples: t_eval.map(Samples::At),
        ensemble: None,
        past_horizon,
    };
    let run = request
        .prepare(scene)
        .map_err(|refused| match refused.ask {
            Ask::Solver => override_error(py, "method/rtol/atol/step", refused.error.to_string()),
            ask => {
                let keyword = match ask {
                    Ask::TEnd => "t_end",
                    Ask::Sensitivities => "sensitivities",
                    Ask::Ensemble => "ensemble",
                    Ask::Samples | Ask::Solver => "t_eval",
                };
                override_error(py, keyword, refused.error.reason)
            }
        })?;
    let writer = match log {
        None => None,
        Some(file) => Some(JsonlWriter::new(LogSize::new(
            BufWriter::new(File::create(file).map_err(|e| {
                override_error(py, "log", format!("{file}: cannot be created: {e}"))
            })?),
            FIRST_NOTICE,
            say as fn(String),
        ))),
    };
    let mut keep = Keep {
        columns: events.then(EventColumns::default),
        log: writer,
    };
    let stop = Arc::new(AtomicBool::new(false));
    let limits = run.limits(Some(stop.clone()));
    let done = AtomicBool::new(false);
    let report = py.detach(|| {
        std::thread::scope(|s| {
            // The worker says it is done and wakes the caller (a wake-up
            // given before the caller waits is kept for it).
            let caller = std::thread::current();
            let (run, limits, keep, finished) = (&run, &limits, &mut keep, &done);
            let worker = s.spawn(move || {
                let report = run.run(limits, keep);
                finished.store(true, Ordering::Release);
                caller.unpark();
                report
            });
            // A worker that panicked never says it is done, but is finished.
            while !done.load(Ordering::Acquire) && !worker.is_finished() {
                std::thread::park_timeout(POLL);
                // A pending Ctrl-C raises here: it becomes the run's stop.
                if Python::attach(|py| py.check_signals()).is_err() {
                    stop.store(true, Ordering::Relaxed);
                }
            }
            worker.join()
        })
    });
    let report = match report {
        Ok(result) => result.map_err(|e| scene_error(py, &e))?,
        Err(_) => {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "flicker: the run panicked (a bug: please report the scene)",
            ));
        }
    };
    let (mut report, trajectory) = report;
    if let Some(writer) = &mut keep.log
        && let Err(e) = writer.flush()
    {
        report.outcome.status = Status::Failed;
        report.outcome.reason = Some(format!("could not write the event log: {e}"));
    }
    let summary = summary(
        &report,
        run.scene().model(),
        Path::new(&label),
        log.map(Path::new),
    );
    let out = PyDict::new(py);
    out.set_item("summary", summary.to_string())?;
    match keep.columns {
        Some(mut columns) => out.set_item("events", convert::events(py, &mut columns)?)?,
        None => out.set_item("events", py.None())?,
    }
    match &report.fields {
        Some(fields) => out.set_item("fields", convert::fields(py, fields)?)?,
        None => out.set_item("fields", py.None())?,
    }
    match trajectory {
        Some(trajectory) => out.set_item("samples", convert::samples(py, trajectory)?)?,
        None => out.set_item("samples", py.None())?,
    }
    Ok(out)
}

/// The native module.
#[pymodule]
fn _flicker(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(tools::check, m)?)?;
    m.add_function(wrap_pyfunction!(tools::compare, m)?)?;
    m.add_function(wrap_pyfunction!(tools::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(tools::orbit, m)?)?;
    m.add_function(wrap_pyfunction!(tools::lyapunov, m)?)?;
    m.add_function(wrap_pyfunction!(tools::continuation, m)?)?;
    m.add_function(wrap_pyfunction!(tools::diagram, m)?)?;
    m.add_function(wrap_pyfunction!(tools::basins, m)?)?;
    Ok(())
}
