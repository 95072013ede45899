//! Pictures of what a run wrote, as SVG and PNG: the energy audit and the
//! intervals between events, from `events.jsonl`; the work-precision chart,
//! from `compare.csv` (`flicker plot DIR`, and `flicker run --plot`).

use std::path::{Path, PathBuf};

use crate::log::reader::for_each_event;
use crate::plot::draw::{Curve, Figure, Style};

/// Draw every picture the files in `dir` allow; returns the files written.
pub fn plot_run(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut written = Vec::new();
    let log = dir.join("events.jsonl");
    if log.exists() {
        let (mut energy, mut intervals) = (Vec::new(), Vec::new());
        let mut first_energy = None;
        let mut last_t: Option<f64> = None;
        for_each_event(&log, |e, _| {
            if let (Some(before), Some(after)) = (e.energy_before, e.energy_after) {
                let e0 = *first_energy.get_or_insert(before);
                let scale = e0.abs().max(f64::MIN_POSITIVE);
                energy.push((e.t, (after - e0) / scale));
            }
            if let Some(last) = last_t {
                intervals.push((e.t, e.t - last));
            }
            last_t = Some(e.t);
        })
        .map_err(|e| e.to_string())?;
        let pictures = [
            (
                "energy",
                "energy across events",
                "relative change of energy since the first event",
                energy,
            ),
            (
                "intervals",
                "time between events",
                "interval to the previous event",
                intervals,
            ),
        ];
        for (name, title, y_label, points) in pictures {
            if points.is_empty() {
                continue;
            }
            // A long log is thinned evenly to a picture's worth of points.
            let stride = points.len().div_ceil(crate::plot::fields::MAX_POINTS);
            let points: Vec<(f64, f64)> = points.into_iter().step_by(stride).collect();
            let figure = Figure {
                title: title.into(),
                x_label: "time t".into(),
                y_label: y_label.into(),
                curves: vec![Curve {
                    label: None,
                    points,
                    style: Style::Simulated,
                }],
                y_limit: None,
            };
            for extension in ["svg", "png"] {
                let path = dir.join(format!("{name}.{extension}"));
                figure.draw(&path)?;
                written.push(path);
            }
        }
    }
    let compare = dir.join("compare.csv");
    if compare.exists() {
        let rows = crate::session::read_compare_csv(&compare)
            .map_err(|e| format!("{}: {e}", compare.display()))?;
        for name in ["compare.svg", "compare.png"] {
            let path = dir.join(name);
            crate::session::compare_chart::draw(&rows, "work-precision", &path)?;
            written.push(path);
        }
    }
    written.extend(crate::plot::fields::plot_fields(dir)?);
    if written.is_empty() {
        return Err(format!(
            "{}: holds neither events.jsonl nor compare.csv",
            dir.display()
        ));
    }
    Ok(written)
}
