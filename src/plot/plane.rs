//! Any two states of a run against each other (`flicker plot phase SCENE
//! --x A --y B`): the flow between events as lines through the state
//! sampled along the way, each reset as a dashed jump from the state before
//! it to the state after, and the stretches a discontinuous flow slides
//! along a switching surface (from its `slide:h` event to its `leave:h`)
//! in red. A run with more than [`MAX_JUMPS`] events is drawn as dots at
//! the samples, without its jumps.

use crate::engine::Limits;
use crate::engine::Recorder;
use crate::plot::draw::{Curve, Figure, Style};
use crate::runner::Report;
use crate::scene::Scene;

/// Sample times of a picture unless told otherwise.
pub const DEFAULT_SAMPLES: usize = 4000;

/// Most events whose jumps are drawn.
pub const MAX_JUMPS: usize = 2000;

/// The picture of states `x` and `y` of `scene`'s run, sampled at
/// `samples` evenly spaced times, and the run's report.
pub fn state_plane(
    scene: &Scene,
    x: &str,
    y: &str,
    samples: usize,
    limits: &Limits,
) -> Result<(Figure, Report), String> {
    if samples < 2 {
        return Err(format!("--samples: at least 2 (got {samples})"));
    }
    let t_end = scene.t_end();
    let times: Vec<f64> = (0..samples)
        .map(|i| t_end * i as f64 / (samples - 1) as f64)
        .collect();
    let mut events = Recorder::default();
    let trajectory = scene
        .sampled(limits, &times, &mut events)
        .ok_or_else(|| {
            format!(
                "a {} scene offers no samples of its state to draw",
                scene.model()
            )
        })?
        .map_err(|e| e.to_string())?;
    let index = |name: &str, flag: &str| {
        trajectory
            .names
            .iter()
            .position(|n| *n == name)
            .ok_or_else(|| {
                format!(
                    "--{flag}: the scene has no state `{name}` (its states: {})",
                    trajectory.names.join(", ")
                )
            })
    };
    let (i, j) = (index(x, "x")?, index(y, "y")?);
    let point = |state: &[f64]| (state[i], state[j]);
    let mut curves = Vec::new();
    let title;
    if events.events.len() <= MAX_JUMPS {
        let slides = events.events.iter().any(|e| sliding_after(&e.guard));
        title = if slides {
            format!("{y} against {x} (dashed: resets; red: sliding)")
        } else {
            format!("{y} against {x} (dashed: resets)")
        };
        let mut flight = Vec::new();
        let mut sliding = false;
        let mut pending = events.events.iter().peekable();
        let jump = |flight: &mut Vec<(f64, f64)>,
                    sliding: &mut bool,
                    curves: &mut Vec<Curve>,
                    e: &crate::engine::RecordedEvent| {
            // An event-local model's events carry no states.
            if e.before.len() <= i.max(j) || e.after.len() <= i.max(j) {
                return;
            }
            flight.push(point(&e.before));
            curves.push(Curve {
                label: None,
                points: std::mem::take(flight),
                style: flight_style(*sliding),
            });
            // A switching surface's events move nothing: no jump to draw.
            if point(&e.before) != point(&e.after) {
                curves.push(Curve {
                    label: None,
                    points: vec![point(&e.before), point(&e.after)],
                    style: Style::Jump,
                });
            }
            *sliding = sliding_after(&e.guard);
            flight.push(point(&e.after));
        };
        for (t, state) in &trajectory.samples {
            // A sample at an event's time holds the state before it.
            while let Some(e) = pending.next_if(|e| e.t < *t) {
                jump(&mut flight, &mut sliding, &mut curves, e);
            }
            flight.push(point(state));
        }
        for e in pending {
            jump(&mut flight, &mut sliding, &mut curves, e);
        }
        curves.push(Curve {
            label: None,
            points: flight,
            style: flight_style(sliding),
        });
    } else {
        title = format!(
            "{y} against {x} at {} sample times ({} resets, not drawn)",
            trajectory.samples.len(),
            events.events.len()
        );
        curves.push(Curve {
            label: None,
            points: trajectory.samples.iter().map(|(_, s)| point(s)).collect(),
            style: Style::Simulated,
        });
    }
    let figure = Figure {
        title,
        x_label: x.to_string(),
        y_label: y.to_string(),
        curves,
        y_limit: None,
    };
    Ok((figure, trajectory.report))
}

/// Whether the run slides after an event of `guard`: a discontinuous
/// flow's `slide:h` starts a slide, and any other event ends it (its
/// `leave:h`, or a reset, which picks the region afresh).
fn sliding_after(guard: &str) -> bool {
    guard.starts_with("slide:")
}

/// How a stretch of flow between events is drawn.
fn flight_style(sliding: bool) -> Style {
    Style::Line(if sliding { 1 } else { 0 })
}
