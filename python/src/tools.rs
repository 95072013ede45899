//! `check`, `compare` and `sweep` as the command line runs them, their
//! results as lists and NumPy columns instead of printed lines and CSV
//! files. Long ones release the GIL and stop on Ctrl-C ([`interruptible`]).

use std::path::Path;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use flicker::session::{
    BasinsRequest, CompareRequest, CompareRow, DiagramPoint, DiagramRequest, Input, Limits, Point,
    Registry, SearchRequest, Source, SpectrumRequest, Status, Sweep, SweepRow, SweepRun,
};

use crate::interrupt::interruptible;
use crate::{load, override_error, scene_error};

/// The scene or sweep given as JSON text or a file, and the label its
/// messages name it by.
fn read(py: Python<'_>, text: Option<&str>, path: Option<&str>) -> PyResult<(Input, String)> {
    let (source, label) = match (path, text) {
        (Some(path), _) => (Source::Path(Path::new(path)), path),
        (None, Some(text)) => (Source::Text(text), "<scene>"),
        (None, None) => {
            return Err(override_error(
                py,
                "scene",
                "give a path, a JSON string or a dict".into(),
            ));
        }
    };
    flicker::session::read(&Registry::builtin(), source)
        .map(|input| (input, label.to_string()))
        .map_err(|e| scene_error(py, &e))
}

/// What `flicker check` prints of a scene or a sweep, a line each.
#[pyfunction]
#[pyo3(signature = (text=None, path=None))]
pub fn check(py: Python<'_>, text: Option<&str>, path: Option<&str>) -> PyResult<Vec<String>> {
    let (input, label) = read(py, text, path)?;
    Ok(input.check_lines(&label))
}

/// `flicker compare`: each method of the plan against the exact answer.
/// Returns `{"reference": kind, "rows": {column: values}}`, the columns of
/// `compare.csv` (NaN where a value is missing; `method` and `status` as
/// lists of str).
#[pyfunction]
#[pyo3(signature = (text=None, path=None, methods=None, tolerances=None, steps=None))]
pub fn compare<'py>(
    py: Python<'py>,
    text: Option<&str>,
    path: Option<&str>,
    methods: Option<Vec<String>>,
    tolerances: Option<Vec<f64>>,
    steps: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, _) = load(py, text, path)?;
    let asked = CompareRequest {
        methods,
        tolerances,
        steps,
    };
    let comparison = asked
        .on(scene)
        .map_err(|e| override_error(py, e.field.as_deref().unwrap_or("methods"), e.reason))?;
    let compared = interruptible(py, |stop| {
        let limits = Limits {
            stop: Some(stop.clone()),
            ..Limits::default()
        };
        comparison.run(&limits, &mut |_| {})
    })?;
    let (reference, rows) = compared.map_err(|e| scene_error(py, &e))?;
    let out = PyDict::new(py);
    out.set_item("reference", reference.kind)?;
    let columns = PyDict::new(py);
    let nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
    columns.set_item(
        "method",
        PyList::new(py, rows.iter().map(|r| r.method.clone()))?,
    )?;
    columns.set_item(
        "status",
        PyList::new(py, rows.iter().map(|r| r.status.clone()))?,
    )?;
    let numbers: [(&str, fn(&CompareRow) -> Option<f64>); 10] = [
        ("tolerance", |r| r.tolerance),
        ("step", |r| r.step),
        ("wall_seconds", |r| Some(r.wall_seconds)),
        ("flow_evals", |r| Some(r.flow_evals as f64)),
        ("events", |r| Some(r.events as f64)),
        ("final_error", |r| Some(r.final_error)),
        ("max_event_time_error", |r| r.max_event_time_error),
        ("energy_error", |r| r.energy_error),
        ("error_bound", |r| r.error_bound),
        ("event_time_bound", |r| r.event_time_bound),
    ];
    for (key, value) in numbers {
        let column: Vec<f64> = rows.iter().map(|r| nan(value(r))).collect();
        columns.set_item(key, column.into_pyarray(py))?;
    }
    out.set_item("rows", columns)?;
    Ok(out)
}

/// `flicker sweep`: every point of the sweep, on `threads` threads
/// (default: one per core). Returns a dict of columns: `point` and each
/// axis, then `status` (a list of str) and the results (NaN where a value
/// is missing), as `flicker sweep` writes them.
#[pyfunction]
#[pyo3(signature = (text=None, path=None, threads=None))]
pub fn sweep<'py>(
    py: Python<'py>,
    text: Option<&str>,
    path: Option<&str>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec: Sweep = match read(py, text, path)?.0 {
        Input::Sweep(spec) => spec,
        Input::Scene(_) => {
            return Err(override_error(
                py,
                "grid",
                "a sweep is an object with `scene` and `grid`; this is a scene".into(),
            ));
        }
    };
    let points = SweepRun::new(&spec, None, threads)
        .map_err(|e| override_error(py, e.field.as_deref().unwrap_or("threads"), e.reason))?;
    let rows = interruptible(py, |stop| {
        let limits = Limits {
            stop: Some(stop.clone()),
            ..Limits::default()
        };
        points.run(&limits, &|| {})
    })?;
    let out = PyDict::new(py);
    let header = spec.header();
    let axes = &header[1..1 + spec.axes.len()];
    out.set_item(
        "point",
        rows.iter()
            .map(|r| r.point as u64)
            .collect::<Vec<u64>>()
            .into_pyarray(py),
    )?;
    for (k, key) in axes.iter().enumerate() {
        let column: Vec<f64> = rows.iter().map(|r| r.values[k]).collect();
        out.set_item(key, column.into_pyarray(py))?;
    }
    out.set_item(
        "status",
        PyList::new(py, rows.iter().map(|r| r.status.clone()))?,
    )?;
    out.set_item(
        "events",
        rows.iter()
            .map(|r| r.events)
            .collect::<Vec<u64>>()
            .into_pyarray(py),
    )?;
    let nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
    let numbers: [(&str, fn(&SweepRow) -> Option<f64>); 7] = [
        ("first_impact", |r| r.first_impact),
        ("impact_period", |r| r.impact_period),
        ("exact_period", |r| r.exact_period),
        ("period_error", |r| r.period_error),
        ("energy_error", |r| r.energy_error),
        ("t_reached", |r| Some(r.t_reached)),
        ("horizon", |r| r.horizon),
    ];
    for (key, value) in numbers {
        let column: Vec<f64> = rows.iter().map(|r| nan(value(r))).collect();
        out.set_item(key, column.into_pyarray(py))?;
    }
    Ok(out)
}

/// The search as asked (see [`SearchRequest`]).
fn asked(
    section: String,
    (events, settle, forcing_period): (usize, f64, Option<f64>),
    wall: f64,
) -> SearchRequest {
    SearchRequest {
        section,
        events,
        settle,
        forcing_period,
        wall,
    }
}

/// `flicker orbit`: the JSON text of `orbit.json` for the orbit found (or
/// why none was).
#[pyfunction]
#[pyo3(signature = (text=None, path=None, section=String::new(), events=1, settle=0.0, forcing_period=None, wall=600.0))]
#[allow(clippy::too_many_arguments)]
pub fn orbit(
    py: Python<'_>,
    text: Option<&str>,
    path: Option<&str>,
    section: String,
    events: usize,
    settle: f64,
    forcing_period: Option<f64>,
    wall: f64,
) -> PyResult<String> {
    let (scene, label) = load(py, text, path)?;
    let asked = asked(section.clone(), (events, settle, forcing_period), wall);
    let started = std::time::Instant::now();
    let found = interruptible(py, |stop| {
        asked
            .on(&scene, Some(stop.clone()))
            .and_then(|search| search.orbit(Default::default()))
    })?
    .map_err(|e| scene_error(py, &e))?;
    let json = found.to_json(Path::new(&label), &section, started.elapsed().as_secs_f64());
    Ok(json.to_string())
}

/// `flicker continue`: the branch as columns (`parameter`, `period`, each
/// state at the section, `largest_multiplier`, `stable`, `label`), and
/// `ended`, why it ended.
#[pyfunction]
#[pyo3(signature = (text=None, path=None, section=String::new(), param=String::new(), to=0.0, events=1, settle=0.0, forcing_period=None, points=200, max_step=0.05, wall=600.0))]
#[allow(clippy::too_many_arguments)]
pub fn continuation<'py>(
    py: Python<'py>,
    text: Option<&str>,
    path: Option<&str>,
    section: String,
    param: String,
    to: f64,
    events: usize,
    settle: f64,
    forcing_period: Option<f64>,
    points: usize,
    max_step: f64,
    wall: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, _) = load(py, text, path)?;
    let asked = asked(section, (events, settle, forcing_period), wall);
    let (branch, names, p) = interruptible(py, |stop| {
        asked
            .on(&scene, Some(stop.clone()))
            .and_then(|search| search.branch(&param, to, (points, max_step), &mut |_| {}))
    })?
    .map_err(|e| scene_error(py, &e))?;
    let out = PyDict::new(py);
    let column = |f: &dyn Fn(&Point) -> f64| -> Vec<f64> { branch.points.iter().map(f).collect() };
    out.set_item("parameter", column(&|q| q.parameter).into_pyarray(py))?;
    out.set_item("period", column(&|q| q.period).into_pyarray(py))?;
    for (i, name) in names.iter().enumerate().filter(|(i, _)| *i != p) {
        out.set_item(name.as_str(), column(&|q| q.state[i]).into_pyarray(py))?;
    }
    out.set_item(
        "largest_multiplier",
        column(&|q| {
            q.multipliers
                .iter()
                .skip(1)
                .map(|z| z.0.hypot(z.1))
                .fold(0.0, f64::max)
        })
        .into_pyarray(py),
    )?;
    out.set_item(
        "stable",
        PyList::new(py, branch.points.iter().map(|q| q.stable))?,
    )?;
    out.set_item(
        "label",
        PyList::new(py, branch.points.iter().map(|q| q.label.clone()))?,
    )?;
    out.set_item("ended", branch.ended.clone())?;
    Ok(out)
}

/// `flicker lyapunov`: the JSON text of `lyapunov.json` (the spectrum, or
/// as far as it got and why it stopped).
#[pyfunction]
#[pyo3(signature = (text=None, path=None, exponents=None, transient=0.0, t_end=None, interval=None, wall=600.0))]
#[allow(clippy::too_many_arguments)]
pub fn lyapunov(
    py: Python<'_>,
    text: Option<&str>,
    path: Option<&str>,
    exponents: Option<usize>,
    transient: f64,
    t_end: Option<f64>,
    interval: Option<f64>,
    wall: f64,
) -> PyResult<String> {
    let (scene, label) = load(py, text, path)?;
    let asked = SpectrumRequest {
        exponents,
        transient,
        t_end,
        interval,
        wall,
    };
    let found = interruptible(py, |stop| {
        asked
            .on(&scene, Some(stop.clone()))
            .map(|spectrum| (spectrum.spectrum(&mut |_, _| {}), spectrum.request))
    })?;
    let (found, request) = found.map_err(|e| scene_error(py, &e))?;
    Ok(found.to_json(&request, Path::new(&label)).to_string())
}

/// `flicker diagram`: the state after each section event recorded at each
/// value of the parameter. Returns a dict: `param`, `t` and each state
/// (float64, a row per record), and `ended_short`, a list of dicts
/// (`param`, `status`, `reason`, `records`) for each value that did not
/// complete.
#[pyfunction]
#[pyo3(signature = (text=None, path=None, param=String::new(), start=0.0, stop=0.0, points=100, section=String::new(), transient=None, record=50, span=None, follow=false, past_horizon=false, wall=3600.0))]
#[allow(clippy::too_many_arguments)]
pub fn diagram<'py>(
    py: Python<'py>,
    text: Option<&str>,
    path: Option<&str>,
    param: String,
    start: f64,
    stop: f64,
    points: usize,
    section: String,
    transient: Option<f64>,
    record: usize,
    span: Option<f64>,
    follow: bool,
    past_horizon: bool,
    wall: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, _) = load(py, text, path)?;
    let asked = DiagramRequest {
        parameter: param,
        from: start,
        to: stop,
        points,
        section,
        transient,
        record,
        span,
        follow,
        past_horizon,
        shard: None,
        wall,
    };
    let prepared = asked.on(&scene).map_err(|e| scene_error(py, &e))?;
    let found = interruptible(py, |flag| prepared.run(Some(flag.clone()), &|| {}))?
        .map_err(|why| override_error(py, "param", why))?;
    let out = PyDict::new(py);
    let rows = || {
        found
            .points
            .iter()
            .flat_map(|p| p.records.iter().map(move |r| (p, r)))
    };
    let column = |f: &dyn Fn((&DiagramPoint, &(f64, Vec<f64>))) -> f64| {
        rows().map(f).collect::<Vec<f64>>().into_pyarray(py)
    };
    out.set_item("param", column(&|(p, _)| p.parameter))?;
    out.set_item("t", column(&|(_, r)| r.0))?;
    for (i, name) in found.names.iter().enumerate() {
        out.set_item(name.as_str(), column(&|(_, r)| r.1[i]))?;
    }
    let short = PyList::empty(py);
    for p in found
        .points
        .iter()
        .filter(|p| p.status != Status::Completed)
    {
        let one = PyDict::new(py);
        one.set_item("param", p.parameter)?;
        one.set_item("status", p.status.as_str())?;
        one.set_item("reason", p.reason.clone())?;
        one.set_item("records", p.records.len())?;
        short.append(one)?;
    }
    out.set_item("ended_short", short)?;
    Ok(out)
}

/// `flicker basins`: each point of a grid of two states' starting values
/// named by the attractor it reaches. Returns a dict: the two states'
/// values (float64, a row per point run), `attractor` (int64 ids), and
/// `attractors`, a list of dicts (`id`, `kind`, `state` as a dict,
/// `points`; `period` and `cycle` for a periodic orbit, with
/// `period_time`, `multipliers` (`(re, im)` pairs) and `stable` where
/// refined;
/// `exponent` where measured, `reason` where unresolved).
#[pyfunction]
#[pyo3(signature = (text=None, path=None, grid=Vec::new(), transient=None, section=None, record=64, tolerance=1e-6, forcing_period=None, past_horizon=false, wall=3600.0))]
#[allow(clippy::too_many_arguments)]
pub fn basins<'py>(
    py: Python<'py>,
    text: Option<&str>,
    path: Option<&str>,
    grid: Vec<String>,
    transient: Option<f64>,
    section: Option<String>,
    record: usize,
    tolerance: f64,
    forcing_period: Option<f64>,
    past_horizon: bool,
    wall: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, _) = load(py, text, path)?;
    let asked = BasinsRequest {
        grid,
        transient,
        section,
        record,
        tolerance,
        forcing_period,
        past_horizon,
        shard: None,
        wall,
    };
    let prepared = asked.on(&scene).map_err(|e| scene_error(py, &e))?;
    let found = interruptible(py, |flag| prepared.run(Some(flag.clone()), &|| {}))?;
    let axes = &prepared.request().axes;
    let width = found.values[1].len();
    let run: Vec<(usize, usize)> = found
        .attractor
        .iter()
        .enumerate()
        .filter_map(|(index, id)| id.map(|id| (index, id)))
        .collect();
    let out = PyDict::new(py);
    let first: Vec<f64> = run
        .iter()
        .map(|(i, _)| found.values[0][i / width])
        .collect();
    let second: Vec<f64> = run
        .iter()
        .map(|(i, _)| found.values[1][i % width])
        .collect();
    out.set_item(axes[0].state.as_str(), first.into_pyarray(py))?;
    out.set_item(axes[1].state.as_str(), second.into_pyarray(py))?;
    let ids: Vec<i64> = run.iter().map(|(_, id)| *id as i64).collect();
    out.set_item("attractor", ids.into_pyarray(py))?;
    let named = |x: &[f64]| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (n, v) in found.names.iter().zip(x) {
            d.set_item(n.as_str(), *v)?;
        }
        Ok(d)
    };
    let list = PyList::empty(py);
    for a in &found.attractors {
        let one = PyDict::new(py);
        one.set_item("id", a.id)?;
        one.set_item("kind", a.kind.as_str())?;
        one.set_item("state", named(&a.state)?)?;
        one.set_item("points", a.points)?;
        if !a.cycle.is_empty() {
            one.set_item("period", a.cycle.len())?;
            let cycle = PyList::empty(py);
            for x in &a.cycle {
                cycle.append(named(x)?)?;
            }
            one.set_item("cycle", cycle)?;
        }
        if let Some(orbit) = &a.orbit {
            one.set_item("period_time", orbit.period)?;
            one.set_item("multipliers", orbit.multipliers.clone())?;
            one.set_item("stable", orbit.stable)?;
        }
        if let Some(exponent) = a.exponent {
            one.set_item("exponent", exponent)?;
        }
        if let Some(why) = &a.reason {
            one.set_item("reason", why.as_str())?;
        }
        list.append(one)?;
    }
    out.set_item("attractors", list)?;
    Ok(out)
}
