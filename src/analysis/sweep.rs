//! Parameter sweeps: one scene, a grid of values for some of its keys, one
//! CSV row per point, run in parallel; shards for batch schedulers.
//!
//! ```json
//! {"scene": "../mechanism_impacting.json",
//!  "grid": [{"key": "eta", "from": 0.5, "to": 1.5, "count": 100},
//!           {"key": "initial.energy", "values": [0.01, 0.1, 1.0]}],
//!  "description": "..."}
//! ```
//!
//! `scene` is a path (relative to the sweep file) or an inline scene object.
//! `"past_horizon": true` runs every point on past its horizon as a
//! pseudo-orbit (see `engine::horizon`), as `flicker run --past-horizon`
//! does: a sweep through a chaotic window then completes, and each row's
//! `horizon` says where its point's own answer ends.
//! Each grid entry names a key of the scene by its dotted path and gives its
//! values, as a list or as `from`, `to`, `count` (evenly spaced, or
//! geometrically with `"spacing": "log"`). Points are the Cartesian product,
//! the last key varying fastest, numbered from 0. A shard `i/n` runs the
//! points whose number is `i` modulo `n`; merging the shards gives the same
//! file, byte for byte, as one run of the whole sweep: rows are written in
//! point order and each row depends only on its point.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde_json::Value;

use crate::engine::Limits;
use crate::engine::{EventRecord, Observer, SETTLE, Status};
use crate::scene::fields::Fields;
use crate::scene::{Registry, SceneError};

/// The largest grid a sweep file may describe.
const MAX_POINTS: usize = 100_000_000;

/// One axis of the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The scene key the axis sets, as a dotted path (`initial.energy`).
    pub key: String,
    /// The values it takes, in order.
    pub values: Vec<f64>,
}

/// A validated sweep.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The scene every point starts from, as JSON.
    pub base: Value,
    /// The grid's axes, the last varying fastest.
    pub axes: Vec<Axis>,
    /// The scene models its points may be of.
    pub registry: Registry,
    /// Every point goes on past its horizon (`past_horizon`).
    pub past_horizon: bool,
}

/// Which points this process runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which shard this is, `0 <= index < count`.
    pub index: usize,
    /// How many shards the points are dealt among.
    pub count: usize,
}

impl Shard {
    /// Every point: the shard `0/1`.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Parse `I/N` with `0 <= I < N`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| format!("{text:?} is not of the form I/N"))?;
        let (index, count) = (i.trim().parse::<usize>(), n.trim().parse::<usize>());
        match (index, count) {
            (Ok(index), Ok(count)) if index < count => Ok(Shard { index, count }),
            _ => Err(format!(
                "{text:?} must be I/N with whole numbers 0 <= I < N"
            )),
        }
    }
}

/// One point's result.
#[derive(Debug, Clone)]
pub struct Row {
    /// The point's number, from 0 in grid order.
    pub point: usize,
    /// The grid values, in axis order.
    pub values: Vec<f64>,
    /// How the run ended: `completed`, another status with its reason
    /// (`zeno: ...`, `failed: ...`), or `invalid: ...` for a point whose
    /// scene is refused.
    pub status: String,
    /// Events the run took.
    pub events: u64,
    /// Time of the first event (settling aside), if any.
    pub first_impact: Option<f64>,
    /// Mean interval between consecutive impacts.
    pub impact_period: Option<f64>,
    /// The closed form's impact period, for the mechanism.
    pub exact_period: Option<f64>,
    /// `|impact_period - exact_period| / exact_period`, where both are known.
    pub period_error: Option<f64>,
    /// Largest relative energy error the run saw, for a model with an energy.
    pub energy_error: Option<f64>,
    /// Simulated time the run reached.
    pub t_reached: f64,
    /// The run's horizon (see [`crate::engine::Outcome::horizon`]).
    pub horizon: Option<f64>,
}

/// Whether `value` is a sweep (an object with `scene` and `grid`) rather
/// than a scene.
pub fn is_sweep(value: &Value) -> bool {
    value.get("grid").is_some() && value.get("scene").is_some()
}

/// Read and validate a sweep file, whose scenes are of the models
/// `registry` knows.
pub fn load(path: &Path, registry: &Registry) -> Result<Sweep, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: Some(path.to_path_buf()),
        field: None,
        reason: format!("cannot be read: {e}"),
        untrusted: false,
    })?;
    let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_text(&text, &folder, registry).map_err(|e| e.in_path(path))
}

/// Validate a sweep given as JSON text; a `scene` path is read relative to
/// `folder`.
pub fn parse_text(text: &str, folder: &Path, registry: &Registry) -> Result<Sweep, SceneError> {
    let value: Value = serde_json::from_str(text).map_err(|e| SceneError {
        file: None,
        field: None,
        reason: format!("is not valid JSON: {e}"),
        untrusted: false,
    })?;
    parse(&value, folder, registry)
}

fn parse(value: &Value, folder: &Path, registry: &Registry) -> Result<Sweep, SceneError> {
    let mut f = Fields::open(value, "")?;
    let base = match f.required("scene")? {
        Value::String(relative) => {
            let path: PathBuf = folder.join(relative);
            let text = std::fs::read_to_string(&path).map_err(|e| {
                SceneError::field("scene", format!("{} cannot be read: {e}", path.display()))
            })?;
            serde_json::from_str(&text).map_err(|e| {
                SceneError::field(
                    "scene",
                    format!("{} is not valid JSON: {e}", path.display()),
                )
            })?
        }
        inline @ Value::Object(_) => inline.clone(),
        _ => {
            return Err(SceneError::field(
                "scene",
                "must be a path or a scene object".into(),
            ));
        }
    };
    let Some(entries) = f.required("grid")?.as_array() else {
        return Err(SceneError::field("grid", "must be an array of axes".into()));
    };
    let axes = entries
        .iter()
        .enumerate()
        .map(|(i, e)| axis(e, &format!("grid[{i}]")))
        .collect::<Result<Vec<_>, _>>()?;
    if axes.is_empty() {
        return Err(SceneError::field(
            "grid",
            "must hold at least one axis".into(),
        ));
    }
    f.optional_string("description")?;
    let past_horizon = match f.optional("past_horizon") {
        None => false,
        Some(Value::Bool(b)) => *b,
        Some(_) => {
            return Err(SceneError::field(
                "past_horizon",
                "must be true or false".into(),
            ));
        }
    };
    f.finish()?;
    let points = axes
        .iter()
        .try_fold(1usize, |n, a| n.checked_mul(a.values.len()));
    if points.is_none_or(|n| n > MAX_POINTS) {
        return Err(SceneError::field(
            "grid",
            format!("has more than {MAX_POINTS} points"),
        ));
    }
    // Every swept key must be in the scene, so a typo fails before any run.
    for (i, axis) in axes.iter().enumerate() {
        let found = axis
            .key
            .split('.')
            .try_fold(&base, |here, key| here.get(key));
        if found.is_none() {
            return Err(SceneError::field(
                &format!("grid[{i}].key"),
                format!("{:?} is not a key of the scene", axis.key),
            ));
        }
    }
    Ok(Sweep {
        base,
        axes,
        registry: registry.clone(),
        past_horizon,
    })
}

fn axis(value: &Value, path: &str) -> Result<Axis, SceneError> {
    let mut f = Fields::open(value, path)?;
    let key = f.string("key")?.to_string();
    let values = if f.has("values") {
        let list = f.required("values")?.as_array().ok_or_else(|| {
            SceneError::field(&f.path("values"), "must be an array of numbers".into())
        })?;
        list.iter()
            .map(|v| v.as_f64().filter(|x| x.is_finite()))
            .collect::<Option<Vec<f64>>>()
            .ok_or_else(|| {
                SceneError::field(&f.path("values"), "must hold finite numbers only".into())
            })?
    } else {
        let from = f.number("from")?;
        let to = f.number("to")?;
        let count = f
            .optional_count("count")?
            .ok_or_else(|| SceneError::field(&f.path("count"), "is missing".into()))?;
        // Checked before the values are made: a huge count must not allocate.
        if count > MAX_POINTS as u64 {
            return Err(SceneError::field(
                &f.path("count"),
                format!("must be at most {MAX_POINTS}"),
            ));
        }
        let log = match f.optional_string("spacing")? {
            None | Some("linear") => false,
            Some("log") if from > 0.0 && to > 0.0 => true,
            Some("log") => {
                return Err(SceneError::field(
                    &f.path("spacing"),
                    "\"log\" needs from > 0 and to > 0".into(),
                ));
            }
            Some(other) => {
                return Err(SceneError::field(
                    &f.path("spacing"),
                    format!("must be \"linear\" or \"log\" (got {other:?})"),
                ));
            }
        };
        spaced(from, to, count as usize, log)
    };
    if values.is_empty() {
        return Err(SceneError::field(
            &f.path("values"),
            "must not be empty".into(),
        ));
    }
    f.finish()?;
    Ok(Axis { key, values })
}

/// `count` values from `from` to `to`, evenly or geometrically spaced.
fn spaced(from: f64, to: f64, count: usize, log: bool) -> Vec<f64> {
    if count == 1 {
        return vec![from];
    }
    (0..count)
        .map(|i| match i {
            0 => from,
            _ if i == count - 1 => to,
            _ => {
                let u = i as f64 / (count - 1) as f64;
                if log {
                    from * (to / from).powf(u)
                } else {
                    from + u * (to - from)
                }
            }
        })
        .collect()
}

impl Sweep {
    /// The number of points in the grid.
    pub fn points(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// The grid values of point `index`, the last axis varying fastest.
    pub fn values_at(&self, mut index: usize) -> Vec<f64> {
        let mut values = vec![0.0; self.axes.len()];
        for (slot, axis) in values.iter_mut().zip(&self.axes).rev() {
            *slot = axis.values[index % axis.values.len()];
            index /= axis.values.len();
        }
        values
    }

    /// The scene JSON of point `index`.
    pub fn scene_at(&self, index: usize) -> Result<Value, SceneError> {
        let mut scene = self.base.clone();
        for (axis, value) in self.axes.iter().zip(self.values_at(index)) {
            set(&mut scene, &axis.key, value)
                .map_err(|reason| SceneError::field(&axis.key, reason))?;
        }
        Ok(scene)
    }

    /// Run the points of `shard`, in parallel, in point order, under
    /// `limits`: once its stop flag is set or its deadline passed, the
    /// runs under way end and the points not begun are marked so.
    /// `done` hears of each point as it finishes.
    pub fn run(&self, shard: Shard, limits: &Limits, done: &(dyn Fn() + Sync)) -> Vec<Row> {
        let points: Vec<usize> = (shard.index..self.points()).step_by(shard.count).collect();
        // Points differ in cost by orders of magnitude (chattering orbits
        // make thousands of impacts): small pieces keep both cores busy.
        points
            .par_iter()
            .with_max_len(4)
            .map(|&point| {
                let row = self.run_point(point, limits);
                done();
                row
            })
            .collect()
    }

    fn run_point(&self, point: usize, limits: &Limits) -> Row {
        let values = self.values_at(point);
        let failed = |reason: String| Row {
            point,
            values: values.clone(),
            status: reason,
            events: 0,
            first_impact: None,
            impact_period: None,
            exact_period: None,
            period_error: None,
            energy_error: None,
            t_reached: 0.0,
            horizon: None,
        };
        let scene = match self
            .scene_at(point)
            .and_then(|v| self.registry.from_value(&v))
        {
            Ok(scene) => scene,
            Err(e) => return failed(format!("invalid: {e}")),
        };
        if limits.stopped() {
            return failed(format!("{}; not begun", limits.stop_reason()));
        }
        let limits = &Limits {
            past_horizon: self.past_horizon,
            ..limits.clone()
        };
        let mut times = FirstAndLast::default();
        let report = match scene.run(limits, &mut times) {
            Ok(report) => report,
            Err(e) => return failed(format!("invalid: {e}")),
        };
        let o = &report.outcome;
        let impact_period = match times.span {
            Some((first, last)) if times.count > 1 => {
                Some((last - first) / (times.count - 1) as f64)
            }
            _ => None,
        };
        let exact_period = scene.period();
        let status = match (o.status, &o.reason) {
            (Status::Completed, _) | (_, None) => o.status.as_str().to_string(),
            (status, Some(reason)) => format!("{}: {reason}", status.as_str()),
        };
        Row {
            point,
            values,
            status,
            events: o.events,
            first_impact: times.span.map(|(first, _)| first),
            impact_period,
            exact_period,
            period_error: impact_period
                .zip(exact_period)
                .map(|(a, b)| ((a - b) / b).abs()),
            energy_error: o.max_energy_error,
            t_reached: o.t_reached,
            horizon: o.horizon,
        }
    }

    /// What `flicker check` says of the sweep, a line each: `label` (the
    /// file), how many scenes of which model, then each axis.
    pub fn check_lines(&self, label: &str) -> Vec<String> {
        let model = self
            .base
            .get("model")
            .and_then(|m| m.as_str())
            .unwrap_or("?");
        let mut said = vec![format!(
            "{label}: a valid sweep of {} {model} scenes (run it with `flicker sweep`)",
            self.points()
        )];
        for axis in &self.axes {
            let (first, last) = (axis.values.first(), axis.values.last());
            said.push(format!(
                "  {}: {} values from {} to {}",
                axis.key,
                axis.values.len(),
                first.map_or("-".into(), |v| v.to_string()),
                last.map_or("-".into(), |v| v.to_string())
            ));
        }
        said
    }

    /// The CSV header: `point`, the axis keys, then the results.
    pub fn header(&self) -> Vec<String> {
        let mut header = vec!["point".to_string()];
        header.extend(self.axes.iter().map(|a| a.key.clone()));
        header.extend(
            [
                "status",
                "events",
                "first_impact",
                "impact_period",
                "exact_period",
                "period_error",
                "energy_error",
                "t_reached",
                "horizon",
            ]
            .map(str::to_string),
        );
        header
    }
}

/// The first and last event times and the count: all a row needs, without
/// keeping every time.
#[derive(Debug, Default)]
struct FirstAndLast {
    span: Option<(f64, f64)>,
    count: u64,
}

impl Observer for FirstAndLast {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        if e.guard != SETTLE {
            self.span = Some(self.span.map_or((e.t, e.t), |(first, _)| (first, e.t)));
            self.count += 1;
        }
        Ok(())
    }
}

/// Set the number at dotted `path` in a JSON object, creating nothing but
/// the last key.
fn set(value: &mut Value, path: &str, x: f64) -> Result<(), String> {
    let mut keys = path.split('.').peekable();
    let mut here = value;
    while let Some(key) = keys.next() {
        let object = here
            .as_object_mut()
            .ok_or_else(|| format!("cannot be set: the scene has no object at {key:?}"))?;
        if keys.peek().is_none() {
            object.insert(key.to_string(), Value::from(x));
            return Ok(());
        }
        here = object
            .get_mut(key)
            .ok_or_else(|| format!("cannot be set: the scene has no key {key:?}"))?;
    }
    Err("is empty".into())
}

/// Write rows (in point order) as CSV.
pub fn write_csv(
    sweep: &Sweep,
    rows: &[Row],
    out: &mut impl std::io::Write,
) -> Result<(), csv::Error> {
    let mut writer = csv::Writer::from_writer(out);
    writer.write_record(sweep.header())?;
    let number =
        |x: Option<f64>| x.map_or(String::new(), |x| ryu::Buffer::new().format(x).to_string());
    for r in rows {
        let mut record = vec![r.point.to_string()];
        record.extend(r.values.iter().map(|v| number(Some(*v))));
        record.extend([
            r.status.clone(),
            r.events.to_string(),
            number(r.first_impact),
            number(r.impact_period),
            number(r.exact_period),
            number(r.period_error),
            number(r.energy_error),
            number(Some(r.t_reached)),
            number(r.horizon),
        ]);
        writer.write_record(&record)?;
    }
    writer.flush()?;
    Ok(())
}

/// Join the shard files of `sweep` into the CSV one run of the whole sweep
/// writes; every point must be in exactly one shard.
pub fn merge(sweep: &Sweep, shards: &[PathBuf]) -> Result<String, String> {
    let mut expected = Vec::new();
    write_csv(sweep, &[], &mut expected).map_err(|e| e.to_string())?;
    let expected = String::from_utf8_lossy(&expected).trim_end().to_string();
    let mut rows: Vec<(usize, String)> = Vec::new();
    for path in shards {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot be read: {e}", path.display()))?;
        let mut lines = text.lines();
        let first = lines
            .next()
            .ok_or_else(|| format!("{}: is empty", path.display()))?;
        if first != expected {
            return Err(format!(
                "{}: its header is not this sweep's ({expected})",
                path.display()
            ));
        }
        for (n, line) in lines.enumerate() {
            let point = line
                .split(',')
                .next()
                .and_then(|p| p.parse::<usize>().ok())
                .ok_or_else(|| format!("{}: line {}: no point number", path.display(), n + 2))?;
            rows.push((point, line.to_string()));
        }
    }
    rows.sort_by_key(|(p, _)| *p);
    let total = sweep.points();
    for (i, (point, _)) in rows.iter().enumerate() {
        if *point >= total {
            return Err(format!(
                "point {point} is not in the sweep, which has {total} points"
            ));
        } else if *point < i {
            return Err(format!("point {point} is in two shards"));
        } else if *point > i {
            return Err(format!("point {i} is missing"));
        }
    }
    if rows.len() < total {
        return Err(format!(
            "points {}.. are missing: the sweep has {total}",
            rows.len()
        ));
    }
    let mut text = expected;
    text.push('\n');
    for (_, line) in rows {
        text.push_str(&line);
        text.push('\n');
    }
    Ok(text)
}
