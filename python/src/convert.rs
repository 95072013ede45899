//! The engine's columns as NumPy arrays: each vector moves into its array
//! without a copy and without a Python object per element.

use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use flicker::log::columns::EventColumns;
use flicker::session::{FieldOutputs, Profile, TraceRow, Trajectory};

/// The events as a dict: `seq` (uint64), `t`, `energy_before`,
/// `energy_after` (float64), `guard`, `mode_before`, `mode_after` (uint32
/// indices into `names`, a list of str), `state_names` (list of str),
/// `before` and `after` (float64, events x states), `labels` (a list of
/// `(name, float64 array, whole numbers?)`).
pub fn events<'py>(py: Python<'py>, columns: &mut EventColumns) -> PyResult<Bound<'py, PyDict>> {
    let n = columns.len();
    let table = columns.states();
    let width = table.names.len();
    let out = PyDict::new(py);
    out.set_item("seq", std::mem::take(&mut columns.seq).into_pyarray(py))?;
    out.set_item("t", std::mem::take(&mut columns.t).into_pyarray(py))?;
    for (key, values) in [
        ("guard", std::mem::take(&mut columns.guard)),
        ("mode_before", std::mem::take(&mut columns.mode_before)),
        ("mode_after", std::mem::take(&mut columns.mode_after)),
    ] {
        out.set_item(key, values.into_pyarray(py))?;
    }
    out.set_item(
        "names",
        PyList::new(py, columns.names.iter().map(|n| n.as_str()))?,
    )?;
    for (key, values) in [
        ("energy_before", std::mem::take(&mut columns.energy_before)),
        ("energy_after", std::mem::take(&mut columns.energy_after)),
    ] {
        out.set_item(key, values.into_pyarray(py))?;
    }
    out.set_item(
        "state_names",
        PyList::new(py, table.names.iter().map(|n| n.as_str()))?,
    )?;
    for (key, values) in [("before", table.before), ("after", table.after)] {
        out.set_item(key, values.into_pyarray(py).reshape([n, width])?)?;
    }
    out.set_item(
        "shadow",
        std::mem::take(&mut columns.shadow).into_pyarray(py),
    )?;
    let labels = PyList::empty(py);
    for label in std::mem::take(&mut columns.labels) {
        labels.append((label.name, label.values.into_pyarray(py), label.counts))?;
    }
    out.set_item("labels", labels)?;
    Ok(out)
}

/// A trajectory's samples as a dict of float64 arrays: `t`, one per state
/// (a model's clock, `t` itself, once), and `bound`, each sample's error
/// bound.
pub fn samples<'py>(py: Python<'py>, trajectory: Trajectory) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let column = |k: usize| -> Vec<f64> { trajectory.samples.iter().map(|(_, x)| x[k]).collect() };
    let times: Vec<f64> = trajectory.samples.iter().map(|(t, _)| *t).collect();
    out.set_item("t", times.into_pyarray(py))?;
    for (k, name) in trajectory.names.iter().enumerate() {
        if *name != "t" {
            out.set_item(name.as_str(), column(k).into_pyarray(py))?;
        }
    }
    out.set_item("bound", trajectory.bounds.into_pyarray(py))?;
    Ok(out)
}

/// A trace as a dict of float64 arrays: `t`, `energy`, `momentum`,
/// `right_end`.
fn trace<'py>(py: Python<'py>, rows: &[TraceRow]) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let column = |f: fn(&TraceRow) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    out.set_item("t", column(|r| r.t).into_pyarray(py))?;
    out.set_item("energy", column(|r| r.energy).into_pyarray(py))?;
    out.set_item("momentum", column(|r| r.momentum).into_pyarray(py))?;
    out.set_item("right_end", column(|r| r.right_end).into_pyarray(py))?;
    Ok(out)
}

/// Profiles as a list of dicts: `t` (float) and float64 arrays `x`,
/// `strain`, `displacement`, `velocity`.
fn profiles<'py>(py: Python<'py>, profiles: &[Profile]) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for p in profiles {
        let d = PyDict::new(py);
        d.set_item("t", p.t)?;
        d.set_item("x", p.x.clone().into_pyarray(py))?;
        d.set_item("strain", p.strain.clone().into_pyarray(py))?;
        d.set_item("displacement", p.displacement.clone().into_pyarray(py))?;
        d.set_item("velocity", p.velocity.clone().into_pyarray(py))?;
        out.append(d)?;
    }
    Ok(out)
}

/// A chain's or continuum's fields: `trace`, `profiles`, `classical` (the
/// same two for the string without its constraint, or None), `momentum`,
/// `momentum_balance_error`, `right_end`.
pub fn fields<'py>(py: Python<'py>, f: &FieldOutputs) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("trace", trace(py, &f.trace)?)?;
    out.set_item("profiles", profiles(py, &f.profiles)?)?;
    match &f.classical {
        Some(c) => {
            let d = PyDict::new(py);
            d.set_item("trace", trace(py, &c.trace)?)?;
            d.set_item("profiles", profiles(py, &c.profiles)?)?;
            out.set_item("classical", d)?;
        }
        None => out.set_item("classical", py.None())?,
    }
    out.set_item("momentum", f.momentum)?;
    out.set_item("momentum_balance_error", f.momentum_balance_error)?;
    out.set_item("right_end", f.right_end)?;
    Ok(out)
}
