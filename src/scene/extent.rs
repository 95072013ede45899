//! Keys shared by the scenes of models with extent along `x` (a chain, a
//! continuum): the load before and after the release, the constraint
//! switch, snapshot and sample times, and arrays of numbers.

use serde_json::Value;

use crate::scene::SceneError;
use crate::scene::fields::{Fields, kind};

/// Most rows of `trace.csv`.
const MAX_SAMPLES: u64 = 1_000_000;

/// `load`: `{"before", "after"}`, over `F_cr`.
pub fn load(value: &Value) -> Result<(f64, f64), SceneError> {
    let mut f = Fields::open(value, "load")?;
    let before = f.number("before")?;
    let after = f.number("after")?;
    f.finish()?;
    Ok((before, after))
}

/// `constraint`: `true` (the default) or `false`.
pub fn constraint(f: &mut Fields) -> Result<bool, SceneError> {
    match f.optional("constraint") {
        None => Ok(true),
        Some(Value::Bool(b)) => Ok(*b),
        Some(other) => Err(SceneError::field(
            "constraint",
            format!("must be true or false, found {}", kind(other)),
        )),
    }
}

/// `snapshots`: times in `[0, t_end]`, sorted, without repeats.
pub fn snapshots(f: &mut Fields, t_end: f64) -> Result<Vec<f64>, SceneError> {
    let mut snapshots = match f.optional("snapshots") {
        None => Vec::new(),
        Some(v) => numbers(v, "snapshots", None)?,
    };
    if let Some(t) = snapshots.iter().find(|t| !(0.0..=t_end).contains(*t)) {
        return Err(SceneError::field(
            "snapshots",
            format!("must lie in [0, t_end = {t_end}] (got {t})"),
        ));
    }
    snapshots.sort_by(f64::total_cmp);
    snapshots.dedup();
    Ok(snapshots)
}

/// `samples`: rows of `trace.csv` (default 101).
pub fn samples(f: &mut Fields) -> Result<usize, SceneError> {
    match f.optional("samples") {
        None => Ok(101),
        Some(v) => match v.as_u64() {
            Some(n) if n <= MAX_SAMPLES => Ok(n as usize),
            _ => Err(SceneError::field(
                "samples",
                format!(
                    "must be a whole number from 0 to {MAX_SAMPLES}, found {}",
                    kind(v)
                ),
            )),
        },
    }
}

/// The times `trace.csv` samples: `linspace(0, t_end, samples)`.
pub fn sample_times(t_end: f64, samples: usize) -> Vec<f64> {
    match samples {
        0 => Vec::new(),
        1 => vec![0.0],
        n => (0..n).map(|i| t_end * i as f64 / (n - 1) as f64).collect(),
    }
}

/// Every time a run samples: its snapshots and sample times merged, in
/// order, without repeats.
pub fn due_times(snapshots: &[f64], samples: Vec<f64>) -> Vec<f64> {
    let mut times = samples;
    times.extend(snapshots);
    times.sort_by(f64::total_cmp);
    times.dedup();
    times
}

/// An array of finite numbers at `path`, of length `len` (one per `what`)
/// if given.
pub fn numbers(
    value: &Value,
    path: &str,
    len: Option<(usize, &str)>,
) -> Result<Vec<f64>, SceneError> {
    let Value::Array(items) = value else {
        return Err(SceneError::field(
            path,
            format!("must be an array of numbers, found {}", kind(value)),
        ));
    };
    if let Some((n, what)) = len
        && items.len() != n
    {
        return Err(SceneError::field(
            path,
            format!(
                "must have one entry per {what} ({n}), found {}",
                items.len()
            ),
        ));
    }
    items
        .iter()
        .enumerate()
        .map(|(i, v)| match v.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(SceneError::field(
                &format!("{path}[{i}]"),
                format!("must be a finite number, found {}", kind(v)),
            )),
        })
        .collect()
}

/// The line `flicker check` gives of a chain's or a continuum's string.
pub fn describe_string(
    length: f64,
    wave_speed: f64,
    (before, after): (f64, f64),
    constraint: bool,
    t_end: f64,
) -> String {
    format!(
        "length {length}, wave speed {wave_speed}, load {before} -> {after} (F / F_cr), constraint {}, t_end {t_end}",
        if constraint { "on" } else { "off" }
    )
}
