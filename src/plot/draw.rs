//! Drawing a figure of curves: SVG, or PNG by the file's extension.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How a curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A level set of a first integral.
    Level,
    /// The separatrix.
    Separatrix,
    /// A jump of the state (the flipped strain rate), dashed.
    Jump,
    /// A trajectory simulated by the engine, as dots.
    Simulated,
    /// The edge of the admissible region.
    Constraint,
    /// One of several series: a solid line in palette colour `i`.
    Line(usize),
    /// The same, dashed (a reference drawn beside a series).
    Dashed(usize),
    /// The same, as dots.
    Dots(usize),
    /// The same, as larger open circles (a third series beside a solid
    /// and a dashed one).
    Circles(usize),
}

/// Colours of [`Style::Line`], [`Style::Dashed`], [`Style::Dots`] and
/// [`Style::Circles`].
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// One curve, with its label (if any).
#[derive(Debug, Clone)]
pub struct Curve {
    /// The label, drawn at the curve's upper-right end.
    pub label: Option<String>,
    /// The points `(x, y)`, in the order they are joined; points that are
    /// not finite are left out.
    pub points: Vec<(f64, f64)>,
    /// How the curve is drawn.
    pub style: Style,
}

/// A whole figure.
#[derive(Debug, Clone)]
pub struct Figure {
    /// The title above the plot.
    pub title: String,
    /// The horizontal axis's label.
    pub x_label: String,
    /// The vertical axis's label.
    pub y_label: String,
    /// The curves, drawn in this order.
    pub curves: Vec<Curve>,
    /// Points with `|y|` above this are left out (rates that diverge).
    pub y_limit: Option<f64>,
}

impl Figure {
    /// Draw to `path`: PNG if it ends in `.png`, SVG otherwise.
    pub fn draw(&self, path: &Path) -> Result<(), String> {
        crate::plot::register_fonts();
        if path.extension().is_some_and(|e| e == "png") {
            self.draw_on(BitMapBackend::new(path, (1000, 760)).into_drawing_area())
        } else {
            self.draw_on(SVGBackend::new(path, (1000, 760)).into_drawing_area())
        }
    }

    fn draw_on<DB: DrawingBackend>(
        &self,
        area: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let limit = self.y_limit.unwrap_or(f64::INFINITY);
        let shown = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && y.abs() <= limit;
        let all = self
            .curves
            .iter()
            .flat_map(|c| c.points.iter())
            .filter(|p| shown(p));
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in all {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        if !(x0 <= x1 && y0 <= y1) {
            return Err(format!("{}: nothing to draw", self.title));
        }
        // A single point or a flat curve still gets axes around it.
        let widen = |lo: &mut f64, hi: &mut f64| {
            if lo == hi {
                let pad = (lo.abs() * 0.1).max(1e-3);
                (*lo, *hi) = (*lo - pad, *hi + pad);
            }
        };
        widen(&mut x0, &mut x1);
        widen(&mut y0, &mut y1);
        let (dx, dy) = (0.05 * (x1 - x0), 0.05 * (y1 - y0));
        area.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&area)
            .caption(&self.title, ("sans-serif", 24))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d((x0 - dx)..(x1 + dx), (y0 - dy)..(y1 + dy))
            .map_err(err)?;
        let x_format = tick_format(x0.abs().max(x1.abs()));
        let y_format = tick_format(y0.abs().max(y1.abs()));
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_label_formatter(&x_format)
            .y_label_formatter(&y_format)
            .label_style(("sans-serif", 15))
            .light_line_style(WHITE)
            .draw()
            .map_err(err)?;
        let blue = RGBColor(31, 119, 180);
        let red = RGBColor(214, 39, 40);
        let grey = RGBColor(120, 120, 120);
        let orange = RGBColor(255, 127, 14);
        for curve in &self.curves {
            let points: Vec<(f64, f64)> = curve.points.iter().copied().filter(shown).collect();
            match curve.style {
                Style::Level => {
                    chart
                        .draw_series(LineSeries::new(points.clone(), blue.stroke_width(1)))
                        .map_err(err)?;
                }
                Style::Separatrix => {
                    chart
                        .draw_series(LineSeries::new(points.clone(), red.stroke_width(2)))
                        .map_err(err)?;
                }
                Style::Constraint => {
                    chart
                        .draw_series(LineSeries::new(points.clone(), grey.stroke_width(1)))
                        .map_err(err)?;
                }
                Style::Jump => {
                    chart
                        .draw_series(DashedLineSeries::new(
                            points.clone(),
                            6,
                            4,
                            blue.stroke_width(1),
                        ))
                        .map_err(err)?;
                }
                Style::Simulated => {
                    chart
                        .draw_series(points.iter().map(|p| Circle::new(*p, 2, orange.filled())))
                        .map_err(err)?;
                }
                Style::Line(i) => {
                    let colour = PALETTE[i % PALETTE.len()];
                    chart
                        .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                        .map_err(err)?;
                }
                Style::Dashed(i) => {
                    let colour = PALETTE[i % PALETTE.len()];
                    chart
                        .draw_series(DashedLineSeries::new(
                            points.clone(),
                            6,
                            4,
                            colour.stroke_width(1),
                        ))
                        .map_err(err)?;
                }
                Style::Dots(i) => {
                    let colour = PALETTE[i % PALETTE.len()];
                    chart
                        .draw_series(points.iter().map(|p| Circle::new(*p, 1, colour.filled())))
                        .map_err(err)?;
                }
                Style::Circles(i) => {
                    let colour = PALETTE[i % PALETTE.len()];
                    chart
                        .draw_series(
                            points
                                .iter()
                                .map(|p| Circle::new(*p, 3, colour.stroke_width(1))),
                        )
                        .map_err(err)?;
                }
            }
            // Labels sit at the upper-right end of their curve, where nested
            // level sets are furthest apart.
            let reach = |p: &(f64, f64)| (p.0 - x0) / (x1 - x0) + (p.1 - y0) / (y1 - y0);
            let corner = points
                .iter()
                .copied()
                .max_by(|a, b| reach(a).total_cmp(&reach(b)));
            if let (Some(label), Some(corner)) = (&curve.label, corner) {
                let at = (corner.0, corner.1 + 0.01 * (y1 - y0));
                // Text ends at a corner in the right half, so that it stays
                // inside the plot.
                let across = if (corner.0 - x0) / (x1 - x0) > 0.5 {
                    HPos::Right
                } else {
                    HPos::Left
                };
                let style = TextStyle::from(("sans-serif", 13).into_font())
                    .pos(Pos::new(across, VPos::Bottom));
                chart
                    .draw_series(std::iter::once(Text::new(label.clone(), at, style)))
                    .map_err(err)?;
            }
        }
        area.present().map_err(err)
    }
}

/// Tick labels: plain decimals for ordinary magnitudes, exponents for tiny
/// or huge ones (energy errors of 1e-10 must not all read 0.0).
fn tick_format(largest: f64) -> impl Fn(&f64) -> String {
    let scientific = largest != 0.0 && !(1e-2..1e4).contains(&largest);
    move |v: &f64| {
        if scientific {
            format!("{v:.1e}")
        } else {
            let text = format!("{v:.3}");
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        }
    }
}
