//! Pictures of a chain run, from the files `flicker run` wrote: strain and
//! displacement snapshots beside the classical string (`profiles.json`),
//! the loaded end's displacement over time (`trace.csv`), and the
//! space-time map of impacts, unit position against time (`events.jsonl`).

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

/// Draw the chain pictures the files in `dir` allow; returns the files
/// written (none if `dir` holds no `profiles.json`).
pub fn plot_chain(dir: &Path) -> Result<Vec<PathBuf>, String> {
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
                    title: format!("{label} along the chain (dashed: the classical string)"),
                    x_label: "position x".into(),
                    y_label: label.into(),
                    curves,
                    y_limit: None,
                },
            ));
        }
    }
    let mut end = end_displacement(dir)?;
    end.retain(|c| !c.points.is_empty());
    let classical: Vec<(f64, f64)> = list(&profiles["classical"]["trace"])
        .iter()
        .filter_map(|r| Some((r["t"].as_f64()?, r["right_end"].as_f64()?)))
        .collect();
    if !classical.is_empty() {
        end.push(Curve {
            label: Some("classical string".into()),
            points: classical,
            style: Style::Dashed(1),
        });
    }
    if !end.is_empty() {
        figures.push((
            "end_displacement",
            Figure {
                title: "the loaded end's displacement y_N".into(),
                x_label: "time t".into(),
                y_label: "y_N".into(),
                curves: end,
                y_limit: None,
            },
        ));
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

/// `right_end` against `t` from `trace.csv`, if there is one.
fn end_displacement(dir: &Path) -> Result<Vec<Curve>, String> {
    let path = dir.join("trace.csv");
    if !path.exists() {
        return Ok(Vec::new());
    }
    let mut reader =
        csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut points = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| format!("{}: {e}", path.display()))?;
        let field = |i: usize| record.get(i).and_then(|x| x.parse::<f64>().ok());
        if let (Some(t), Some(y)) = (field(0), field(3)) {
            points.push((t, y));
        }
    }
    Ok(vec![Curve {
        label: Some("chain".into()),
        points,
        style: Style::Line(0),
    }])
}

/// Each impact as a dot at its unit's centre and its time (at most `most`).
fn impact_map(dir: &Path, centres: &[f64], most: usize) -> Result<Option<Figure>, String> {
    let log = dir.join("events.jsonl");
    if !log.exists() || centres.is_empty() {
        return Ok(None);
    }
    let mut points = Vec::new();
    for_each_event(&log, |e, _| {
        if let Some(x) = e
            .unit
            .and_then(|u| centres.get((u as usize).wrapping_sub(1)))
        {
            points.push((*x, e.t));
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
        format!("impacts in space and time (every {stride}th of {total})")
    } else {
        format!("impacts in space and time ({total})")
    };
    Ok(Some(Figure {
        title,
        x_label: "position x of the unit".into(),
        y_label: "time t".into(),
        curves: vec![Curve {
            label: None,
            points: shown,
            style: Style::Dots(0),
        }],
        y_limit: None,
    }))
}
