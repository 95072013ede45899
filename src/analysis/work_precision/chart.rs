//! The work-precision chart: error against cost, log-log, one line per
//! method. Drawn as SVG (or PNG, by the file's extension) with a bundled
//! font, so a machine without system fonts draws text too.

use std::path::Path;

use plotters::prelude::*;

use crate::analysis::work_precision::Row;
use crate::plot::draw::PALETTE;

/// Errors below this are drawn at it (an exact method can hit zero).
const ERROR_FLOOR: f64 = 1e-17;

/// Draw `rows` (failed runs left out) to `path`, titled `title`.
pub fn draw(rows: &[Row], title: &str, path: &Path) -> Result<(), String> {
    crate::plot::register_fonts();
    let png = path.extension().is_some_and(|e| e == "png");
    if png {
        draw_on(
            BitMapBackend::new(path, (1000, 700)).into_drawing_area(),
            rows,
            title,
        )
    } else {
        draw_on(
            SVGBackend::new(path, (1000, 700)).into_drawing_area(),
            rows,
            title,
        )
    }
}

fn draw_on<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    rows: &[Row],
    title: &str,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let points: Vec<(&str, f64, f64)> = rows
        .iter()
        .filter(|r| {
            !r.status.starts_with("failed") && r.final_error.is_finite() && r.wall_seconds > 0.0
        })
        .map(|r| {
            (
                r.method.as_str(),
                r.final_error.max(ERROR_FLOOR),
                r.wall_seconds,
            )
        })
        .collect();
    if points.is_empty() {
        return Err("no run finished with a finite error: nothing to draw".into());
    }
    let span = |values: Vec<f64>| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo / 3.0)..(hi * 3.0)
    };
    let x_range = span(points.iter().map(|p| p.1).collect());
    let y_range = span(points.iter().map(|p| p.2).collect());
    area.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&area)
        .caption(title, ("sans-serif", 24))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("final error against the exact answer")
        .y_desc("wall time per run [s]")
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(err)?;
    let mut methods: Vec<&str> = points.iter().map(|p| p.0).collect();
    methods.dedup();
    for (i, method) in methods.iter().enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        // In the order of the runs, loosest setting first: sorting by cost
        // would zigzag wherever timing noise swaps two close runs.
        let line: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.0 == *method)
            .map(|p| (p.1, p.2))
            .collect();
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(err)?
            .label(*method)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(line.into_iter().map(|p| Circle::new(p, 4, colour.filled())))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerMiddle)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    area.present().map_err(err)
}
