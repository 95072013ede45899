//! Running a continuum scene: the string by exact front tracking, with
//! profiles at the snapshot times, the trace at the sample times, and the
//! classical string (constraint off) beside it.

use crate::engine::{LocalModel, Observer, Outcome, Status, simulate_local};
use crate::models::continuum::{Continuum, FrontTracking};
use crate::runner::{Classical, Control, FieldOutputs, Profile, Report, TraceRow};
use crate::scene::{ContinuumScene, SceneError};
use crate::time::Time;

pub(super) fn run(
    scene: &ContinuumScene,
    control: &Control,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let string = scene.string(scene.constraint);
    let (outcome, model, sampled) = track(scene, string.clone(), control, observer)?;
    let end = Time::new(outcome.t_reached);
    let momentum = model.momentum(end);
    let expected = model.momentum_by_impulses(end);
    let scale = momentum
        .abs()
        .max((string.end_force() * end.value()).abs())
        .max(string.length * string.wave_speed * f64::EPSILON);
    let right_end = model.right_end(end);
    let mut fields = FieldOutputs {
        momentum,
        momentum_balance_error: Some((momentum - expected).abs() / scale),
        right_end,
        profiles: sampled.profiles,
        trace: sampled.trace,
        classical: None,
    };
    if scene.constraint && outcome.status == Status::Completed {
        let (companion, _, sampled) = track(scene, scene.string(false), control, &mut ())?;
        // A companion cut short (interrupted) is left out, not shown half.
        if companion.status == Status::Completed {
            fields.classical = Some(Classical {
                profiles: sampled.profiles,
                trace: sampled.trace,
            });
        }
    }
    Ok(Report {
        outcome,
        method: "exact",
        description: describe(scene),
        final_state: vec![("momentum", momentum), ("right_end", right_end)],
        fields: Some(fields),
    })
}

/// What the summary says of the description used.
fn describe(scene: &ContinuumScene) -> String {
    let mut text = format!(
        "continuum ({} variant): the {} string by exact front tracking (constant states between fronts at +-c; \
         crossings, reflections and impacts as events)",
        scene.variant.name(),
        if scene.constraint {
            "incompressible"
        } else {
            "classical"
        },
    );
    if scene.constraint && scene.load_after < 1.0 {
        text.push_str(&format!(
            "; the end load {} F_cr is below F_cr, so the constraint holds the end at strain 0 as the paper does: \
             the end carries F_cr, {} F_cr more than the scene's load",
            scene.load_after,
            1.0 - scene.load_after
        ));
    }
    text
}

/// Profiles and trace rows taken as the run passes their times.
struct Sampled {
    profiles: Vec<Profile>,
    trace: Vec<TraceRow>,
}

/// Run `string` from the scene's initial cells, sampling as it goes.
fn track(
    scene: &ContinuumScene,
    string: Continuum,
    control: &Control,
    observer: &mut dyn Observer,
) -> Result<(Outcome, FrontTracking, Sampled), SceneError> {
    let mut model = FrontTracking::new(string, &scene.cells)
        .map_err(|why| SceneError::field("initial", why))?;
    let options = control.options(
        scene.t_end,
        scene.max_events,
        crate::engine::Method::Exact,
        Default::default(),
    );
    let mut snapshots = scene.snapshots.iter().copied().peekable();
    let mut samples = scene.sample_times().into_iter().peekable();
    let mut times: Vec<f64> = scene.snapshots.clone();
    times.extend(scene.sample_times());
    times.sort_by(f64::total_cmp);
    times.dedup();
    let points = scene.profile_points();
    let mut sampled = Sampled {
        profiles: Vec::new(),
        trace: Vec::new(),
    };
    let outcome = simulate_local(
        &mut model,
        &options,
        &times,
        &mut |m: &FrontTracking, t| {
            let at = Time::new(t);
            if samples.next_if(|&s| s <= t).is_some() {
                sampled.trace.push(TraceRow {
                    t,
                    energy: m.energy(at).unwrap_or(f64::NAN),
                    momentum: m.momentum(at),
                    right_end: m.right_end(at),
                });
            }
            if snapshots.next_if(|&s| s <= t).is_some() {
                sampled.profiles.push(profile(m, &points, at));
            }
        },
        observer,
    );
    Ok((outcome, model, sampled))
}

/// The string at `points` (cell centres): strain, displacement and velocity
/// there.
fn profile(model: &FrontTracking, points: &[f64], t: Time) -> Profile {
    let pieces: Vec<_> = points.iter().map(|&x| model.piece_at(x, t)).collect();
    Profile {
        t: t.value(),
        x: points.to_vec(),
        strain: pieces.iter().map(|p| p.strain).collect(),
        displacement: points
            .iter()
            .map(|&x| model.displacement_at(x, t))
            .collect(),
        velocity: pieces.iter().map(|p| p.velocity).collect(),
    }
}
