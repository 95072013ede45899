//! The pictures of a model comparison: the loaded end's displacement and
//! the front over time for every model, and the coarse strain, velocity and
//! hidden energy along the string at each snapshot (the densest chain
//! solid, the paper's continuum dashed, the homogenized string as circles; one
//! colour per model over time, per time along the string).

use std::path::{Path, PathBuf};

use crate::analysis::release_convergence::{Model, Track};
use crate::models::chain::coarse::Coarse;
use crate::models::continuum::Variant;
use crate::plot::draw::{Curve, Figure, Style};

/// Draw every picture into `dir` (SVG and PNG); `reference` is the index of
/// the densest chain in `tracks`. Returns the files written.
pub fn draw_all(tracks: &[Track], reference: usize, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let over_time =
        |value: fn(&crate::analysis::release_convergence::Sample) -> Option<f64>| -> Vec<Curve> {
            tracks
                .iter()
                .enumerate()
                .map(|(i, track)| Curve {
                    label: Some(track.label.clone()),
                    points: track
                        .samples
                        .iter()
                        .filter_map(|s| Some((s.t, value(s)?)))
                        .collect(),
                    style: style(track.model, i),
                })
                .filter(|c| !c.points.is_empty())
                .collect()
        };
    let mut figures = vec![
        (
            "right_end".to_string(),
            Figure {
                title:
                    "the loaded end: chains (solid), paper's continuum (dashed), homogenized (circles)"
                        .into(),
                x_label: "time t".into(),
                y_label: "y at the loaded end".into(),
                curves: over_time(|s| Some(s.right_end)),
                y_limit: None,
            },
        ),
        (
            "front".to_string(),
            Figure {
                title: "the front: leftmost window strain 0.008 below the undisturbed".into(),
                x_label: "time t".into(),
                y_label: "front position x".into(),
                curves: over_time(|s| s.front),
                y_limit: None,
            },
        ),
    ];
    let fields: [(&str, &str, fn(&Coarse) -> &[f64]); 3] = [
        ("window_strain", "window strain", |c| &c.strain),
        ("window_velocity", "window velocity", |c| &c.velocity),
        ("hidden_energy", "hidden energy per unit length", |c| {
            &c.hidden_energy
        }),
    ];
    for (name, label, field) in fields {
        let mut curves = Vec::new();
        for (k, track) in tracks.iter().enumerate() {
            let dense = k == reference;
            if !(dense || track.units().is_none()) {
                continue;
            }
            for (i, s) in track.snapshots.iter().enumerate() {
                curves.push(Curve {
                    label: dense.then(|| format!("t = {}", s.t)),
                    points: s
                        .coarse
                        .x
                        .iter()
                        .copied()
                        .zip(field(&s.coarse).iter().copied())
                        .collect(),
                    style: style(track.model, i),
                });
            }
        }
        if !curves.is_empty() {
            figures.push((
                name.to_string(),
                Figure {
                    title: format!(
                        "{label}: {} (solid), paper's continuum (dashed), homogenized (circles)",
                        tracks[reference].label
                    ),
                    x_label: "position x".into(),
                    y_label: label.into(),
                    curves,
                    y_limit: None,
                },
            ));
        }
    }
    let mut written = Vec::new();
    for (name, figure) in figures {
        if figure.curves.is_empty() {
            continue;
        }
        for extension in ["svg", "png"] {
            let path = dir.join(format!("{name}.{extension}"));
            figure.draw(&path)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// Chains solid, the paper's continuum dashed, the homogenized string as
/// circles, in palette colour `i`.
fn style(model: Model, i: usize) -> Style {
    match model {
        Model::Chain(_) => Style::Line(i),
        Model::Continuum(Variant::Paper) => Style::Dashed(i),
        Model::Continuum(Variant::Homogenized) => Style::Circles(i),
    }
}
