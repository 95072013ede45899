//! Pictures of a chain or continuum run, from the files `flicker run`
//! wrote: strain and displacement snapshots beside the classical string
//! (`profiles.json`), the loaded end's displacement and the energy ratio
//! `H(t) / H(0) - 1` over time (`trace.csv`; the paper's Figs. 12-14 for a
//! continuum release), and the space-time map of events, position against
//! time (`events.jsonl`: a chain's impacts by unit, a continuum's events by
//! `x`).

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::log::reader::for_each_event;
use crate::plot::draw::{Curve, Figure, Style};

/// Most points drawn from a log in an SVG; longer logs are thinned evenly
/// (and the title says so), so that a two-million-impact run stays a
/// picture of a few megabytes.
pub const MAX_POINTS: usize = 20_000;

/// The same for a PNG, whose size does not grow with the points.
const MAX_PIXEL_POINTS: usize = 2_000_000;

/// Draw the pictures the files in `dir` allow; returns the files written
/// (none if `dir` holds no `profiles.json`).
pub fn plot_fields(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let path = dir.join("profiles.json");
    if !path.exists() {
        return Ok(Vec::new());
    }
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let profiles: Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: not JSON: {e}", path.display()))?;
    let mut figures = Vec::new();
    for (key, name, label) in [
        ("strain", "snapshots", "strain"),
        ("displacement", "displacement", "displacement y"),
    ] {
        let mut curves = Vec::new();
        for (i, snapshot) in list(&profiles["snapshots"]).iter().enumerate() {
            let t = snapshot["t"].as_f64().unwrap_or(f64::NAN);
            curves.push(Curve {
                label: Some(format!("t = {t}")),
                points: pairs(&snapshot["x"], &snapshot[key]),
                style: Style::Line(i),
            });
        }
        for (i, snapshot) in list(&profiles["classical"]["snapshots"]).iter().enumerate() {
            curves.push(Curve {
                label: None,
                points: pairs(&snapshot["x"], &snapshot[key]),
                style: Style::Dashed(i),
            });
        }
        if !curves.is_empty() {
            figures.push((
                name,
                Figure {
                    title: format!("{label} along the string (dashed: the classical string)"),
                    x_label: "position x".into(),
                    y_label: label.into(),
                    curves,
                    y_limit: None,
                },
            ));
        }
    }
    let model = read_trace(dir)?;
    let classical_trace = list(&profiles["classical"]["trace"]);
    let classical = |key: &str| -> Vec<(f64, f64)> {
        classical_trace
            .iter()
            .filter_map(|r| Some((r["t"].as_f64()?, r[key].as_f64()?)))
            .collect()
    };
    for (name, title, y_label, ours, theirs) in [
        (
            "end_displacement",
            "the loaded end's displacement",
            "y at the loaded end",
            model.right_end,
            classical("right_end"),
        ),
        (
            "energy_ratio",
            "energy kept: H(t) / H(0) - 1 (the paper's Fig. 14)",
            "H(t) / H(0) - 1",
            ratio(model.energy),
            ratio(classical("energy")),
        ),
    ] {
        let mut curves = Vec::new();
        for (label, points, style) in [
            ("constrained", ours, Style::Line(0)),
            ("classical string", theirs, Style::Dashed(1)),
        ] {
            if !points.is_empty() {
                curves.push(Curve {
                    label: Some(label.into()),
                    points,
                    style,
                });
            }
        }
        if !curves.is_empty() {
            figures.push((
                name,
                Figure {
                    title: title.into(),
                    x_label: "time t".into(),
                    y_label: y_label.into(),
                    curves,
                    y_limit: None,
                },
            ));
        }
    }
    let centres: Vec<f64> = list(&profiles["snapshots"])
        .first()
        .map(|s| list(&s["x"]).iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default();
    let mut written = Vec::new();
    for (name, figure) in figures {
        for extension in ["svg", "png"] {
            let path = dir.join(format!("{name}.{extension}"));
            figure.draw(&path)?;
            written.push(path);
        }
    }
    for (extension, most) in [("svg", MAX_POINTS), ("png", MAX_PIXEL_POINTS)] {
        if let Some(map) = impact_map(dir, &centres, most)? {
            let path = dir.join(format!("impacts.{extension}"));
            map.draw(&path)?;
            written.push(path);
        }
    }
    Ok(written)
}

fn list(value: &Value) -> &[Value] {
    value.as_array().map_or(&[], Vec::as_slice)
}

fn pairs(x: &Value, y: &Value) -> Vec<(f64, f64)> {
    list(x)
        .iter()
        .zip(list(y))
        .filter_map(|(x, y)| Some((x.as_f64()?, y.as_f64()?)))
        .collect()
}

/// Energy and end displacement against time, from `trace.csv`.
#[derive(Default)]
struct Trace {
    energy: Vec<(f64, f64)>,
    right_end: Vec<(f64, f64)>,
}

/// `trace.csv` in `dir`, if there is one.
fn read_trace(dir: &Path) -> Result<Trace, String> {
    let path = dir.join("trace.csv");
    let mut trace = Trace::default();
    if !path.exists() {
        return Ok(trace);
    }
    let mut reader =
        csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    for record in reader.records() {
        let record = record.map_err(|e| format!("{}: {e}", path.display()))?;
        let field = |i: usize| record.get(i).and_then(|x| x.parse::<f64>().ok());
        if let Some(t) = field(0) {
            trace.energy.extend(field(1).map(|e| (t, e)));
            trace.right_end.extend(field(3).map(|y| (t, y)));
        }
    }
    Ok(trace)
}

/// `(t, E / E(first) - 1)`, or nothing if the first energy is zero: kept
/// to round-off, `E / E(first)` alone would be a flat line at 1.
fn ratio(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    match points.first() {
        Some(&(_, e0)) if e0 != 0.0 && e0.is_finite() => {
            points.into_iter().map(|(t, e)| (t, e / e0 - 1.0)).collect()
        }
        _ => Vec::new(),
    }
}

/// Each event as a dot at its place (a chain's unit centre, a continuum's
/// `x`) and its time (at most `most`).
fn impact_map(dir: &Path, centres: &[f64], most: usize) -> Result<Option<Figure>, String> {
    let log = dir.join("events.jsonl");
    if !log.exists() || centres.is_empty() {
        return Ok(None);
    }
    let mut points = Vec::new();
    for_each_event(&log, |e, _| {
        let unit = e
            .unit
            .and_then(|u| centres.get((u as usize).wrapping_sub(1)).copied());
        if let Some(x) = e.x.or(unit) {
            points.push((x, e.t));
        }
    })
    .map_err(|e| e.to_string())?;
    if points.is_empty() {
        return Ok(None);
    }
    let total = points.len();
    let stride = total.div_ceil(most);
    let shown: Vec<(f64, f64)> = points.into_iter().step_by(stride).collect();
    let title = if stride > 1 {
        format!("events in space and time (every {stride}th of {total})")
    } else {
        format!("events in space and time ({total})")
    };
    Ok(Some(Figure {
        title,
        x_label: "position x".into(),
        y_label: "time t".into(),
        curves: vec![Curve {
            label: None,
            points: shown,
            style: Style::Dots(0),
        }],
        y_limit: None,
    }))
}
