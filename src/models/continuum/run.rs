//! Running a continuum scene: the paper's string by exact front tracking,
//! or the homogenized string by finite volumes, with profiles at the
//! snapshot times, the trace at the sample times, and the classical string
//! (constraint off) beside it.

use crate::engine::Limits;
use crate::engine::{Method, Name, Observer, Outcome, Status, simulate_local};
use crate::models::continuum::scene::ContinuumScene;
use crate::models::continuum::{FrontTracking, Homogenized, StringModel, Variant};
use crate::runner::{Classical, FieldOutputs, Profile, Report, TraceRow};
use crate::scene::SceneError;
use crate::time::Time;

pub(crate) fn run(
    scene: &ContinuumScene,
    limits: &Limits,
    observer: &mut dyn Observer,
) -> Result<Report, SceneError> {
    let (outcome, mut fields) = match scene.variant {
        Variant::Paper => {
            let mut model = front_tracking(scene, scene.constraint)?;
            run_model(scene, &mut model, limits, observer)
        }
        Variant::Homogenized => {
            let mut model = homogenized(scene)?;
            run_model(scene, &mut model, limits, observer)
        }
    };
    if scene.constraint && outcome.status == Status::Completed {
        let mut classical = front_tracking(scene, false)?;
        let (companion, sampled) = sample(scene, &mut classical, limits, &mut ());
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
        method: match scene.variant {
            Variant::Paper => Method::Exact,
            Variant::Homogenized => Method::FiniteVolume,
        },
        description: describe(scene),
        final_state: vec![
            (Name::new("momentum"), fields.momentum),
            (Name::new("right_end"), fields.right_end),
        ],
        fields: Some(fields),
        sensitivities: None,
    })
}

/// The paper's string of `scene`, with the constraint on or off.
pub fn front_tracking(
    scene: &ContinuumScene,
    constraint: bool,
) -> Result<FrontTracking, SceneError> {
    FrontTracking::new(scene.string(constraint), &scene.cells)
        .map_err(|why| SceneError::field("initial", why))
}

/// The homogenized string of `scene`, its steps landing on every sample
/// and snapshot time.
pub fn homogenized(scene: &ContinuumScene) -> Result<Homogenized, SceneError> {
    let first = scene.cells[0];
    if scene.cells.iter().any(|&c| c != first) || first.velocity != 0.0 {
        return Err(SceneError::field(
            "initial",
            "the homogenized string starts from a uniform string at rest".into(),
        ));
    }
    let mut checkpoints = scene.due_times();
    checkpoints.push(scene.t_end);
    Homogenized::new(
        scene.string(scene.constraint),
        first.strain,
        scene.resolution,
        &checkpoints,
    )
    .map_err(|why| SceneError::field("load.before", why))
}

/// Run `model` and collect what the summary and the files need.
fn run_model<M: StringModel>(
    scene: &ContinuumScene,
    model: &mut M,
    limits: &Limits,
    observer: &mut dyn Observer,
) -> (Outcome, FieldOutputs) {
    let (outcome, sampled) = sample(scene, model, limits, observer);
    let end = Time::new(outcome.t_reached);
    let string = scene.string(scene.constraint);
    let momentum = model.momentum(end);
    let scale = momentum
        .abs()
        .max((string.end_force() * end.value()).abs())
        .max(string.length * string.wave_speed * f64::EPSILON);
    let fields = FieldOutputs {
        momentum,
        momentum_balance_error: Some((momentum - model.momentum_by_impulses(end)).abs() / scale),
        right_end: model.right_end(end),
        profiles: sampled.profiles,
        trace: sampled.trace,
        classical: None,
    };
    (outcome, fields)
}

/// What the summary says of the description used.
fn describe(scene: &ContinuumScene) -> String {
    let what = if scene.constraint {
        "incompressible"
    } else {
        "classical"
    };
    let mut text = match scene.variant {
        Variant::Paper => format!(
            "continuum (paper variant): the {what} string by exact front tracking (constant states between fronts at +-c; \
             crossings, reflections and impacts as events)"
        ),
        Variant::Homogenized => format!(
            "continuum (homogenized variant): mass, momentum and energy with the rattling kept, under the single mechanism's \
             equation of state, by finite volumes on {} cells (Rusanov fluxes, minmod slopes, Heun steps at CFL {})",
            scene.resolution,
            crate::models::continuum::homogenized::CFL
        ),
    };
    if scene.variant == Variant::Paper && scene.constraint && scene.load_after < 1.0 {
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

/// Run `model` to the scene's end, sampling as it goes.
fn sample<M: StringModel>(
    scene: &ContinuumScene,
    model: &mut M,
    limits: &Limits,
    observer: &mut dyn Observer,
) -> (Outcome, Sampled) {
    let options = limits.options(
        scene.t_end,
        scene.max_events,
        crate::engine::Method::Exact,
        Default::default(),
    );
    let mut snapshots = scene.snapshots.iter().copied().peekable();
    let mut samples = scene.sample_times().into_iter().peekable();
    let times = scene.due_times();
    let points = scene.profile_points();
    let mut sampled = Sampled {
        profiles: Vec::new(),
        trace: Vec::new(),
    };
    let outcome = simulate_local(
        model,
        &options,
        &times,
        &mut |m: &M, t| {
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
    (outcome, sampled)
}

/// The string at `points` (cell centres): strain, displacement and velocity
/// there.
fn profile<M: StringModel>(model: &M, points: &[f64], t: Time) -> Profile {
    let along = model.profile(points, t);
    Profile {
        t: t.value(),
        x: points.to_vec(),
        strain: along.iter().map(|(p, _)| p.strain).collect(),
        displacement: along.iter().map(|&(_, y)| y).collect(),
        velocity: along.iter().map(|(p, _)| p.velocity).collect(),
    }
}
