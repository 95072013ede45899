//! One release scene as the dense chain at several N and as each continuum,
//! compared by the reproducible quantities of docs/physics.md s.6-7: the loaded
//! end's displacement, the front, the coarse-grained strain, velocity and
//! hidden energy, and the energy, all measured against the densest chain
//! (the ground truth a continuum must converge to).
//!
//! Every model is sampled at the same times, and the coarse fields on the
//! same window centres ([`CENTRES`] of them from the wall to the loaded
//! end), so the comparison needs no interpolation: a chain whose N is a
//! multiple of `CENTRES - 1` has a node at every centre; others take the
//! nearest node.

pub mod chart;
pub mod files;
pub mod release;

pub use release::{Release, release};

use std::time::Instant;

use rayon::prelude::*;

use crate::engine::Limits;
use crate::engine::{LocalModel, Method, Options, Status, Tolerances, simulate_local};
use crate::models::chain::coarse::{Coarse, WINDOW_WIDTH};
use crate::models::chain::{Chain, TaylorChain};
use crate::models::continuum::scene::ContinuumScene;
use crate::models::continuum::{StringModel, Variant};
use crate::scene::SceneError;
use crate::time::Time;

/// Fewest windows behind the front for a plateau to be measured.
pub const PLATEAU_WINDOWS: usize = 10;

/// Cells of the homogenized string unless the caller says otherwise.
pub const DEFAULT_CELLS: usize = 200;

/// Window centres the coarse fields are compared at: every 0.02 on the
/// paper's string of length 2.
pub const CENTRES: usize = 101;

/// The strain the string starts at, against which the front is found.
fn undisturbed(release: &ContinuumScene) -> f64 {
    release.cells[0].strain
}

/// Why the homogenized string does not describe `release`, if it does
/// not: it keeps the rattling the constraint causes, from a stretched
/// string.
pub fn without_homogenized(release: &ContinuumScene) -> Option<String> {
    if !release.constraint {
        Some("the homogenized string is left out: it describes the constrained string (this one's constraint is off)".into())
    } else if undisturbed(release) <= 0.0 {
        Some(format!(
            "the homogenized string is left out: it starts from a stretched string (this one starts at strain {})",
            undisturbed(release)
        ))
    } else {
        None
    }
}

/// The window centres, from the wall to the loaded end.
fn centres(release: &ContinuumScene) -> Vec<f64> {
    (0..CENTRES)
        .map(|j| -0.5 * release.length + release.length * j as f64 / (CENTRES - 1) as f64)
        .collect()
}

/// One model's run, sampled.
#[derive(Debug, Clone)]
pub struct Track {
    /// `chain N=..` or `continuum (variant)`.
    pub label: String,
    /// Which model ran.
    pub model: Model,
    /// How the run ended.
    pub status: Status,
    /// Why the run is not plainly completed, if it is not.
    pub reason: Option<String>,
    /// Events the run took.
    pub events: u64,
    /// Wall time of the run, in seconds.
    pub wall_seconds: f64,
    /// Largest relative energy error the run saw, if the model has an energy.
    pub max_energy_error: Option<f64>,
    /// The model at the release's sample times.
    pub samples: Vec<Sample>,
    /// The model at the release's snapshot times.
    pub snapshots: Vec<Sample>,
}

impl Track {
    /// The chain's units, for a chain.
    pub fn units(&self) -> Option<usize> {
        match self.model {
            Model::Chain(n) => Some(n),
            Model::Continuum(_) => None,
        }
    }
}

/// A model at one time.
#[derive(Debug, Clone)]
pub struct Sample {
    /// The sample's time.
    pub t: f64,
    /// The loaded end's displacement.
    pub right_end: f64,
    /// The energy, with the scene's end load (NaN if the model gives none).
    pub energy: f64,
    /// Where the front is (the leftmost window centre behind it), once there
    /// is one.
    pub front: Option<f64>,
    /// The coarse fields at the comparison's [`CENTRES`] window centres.
    pub coarse: Coarse,
}

/// The chain of `units` on `release` (exact event-local flow, no log).
pub fn chain_track(
    release: &ContinuumScene,
    units: usize,
    limits: &Limits,
) -> Result<Track, String> {
    let chain = Chain::in_scene_units(
        units,
        release.length,
        release.wave_speed,
        release.load_after,
        release.constraint,
    );
    let gaps = vec![undisturbed(release) * chain.unit_length(); units];
    let mut model = TaylorChain::new(chain.clone(), &gaps, &vec![0.0; units])?;
    let centres = centres(release);
    let cell = release.length / units as f64;
    let sample = |m: &TaylorChain, t: f64| {
        let at = Time::new(t);
        let (gaps, velocities) = m.state_at(at);
        let all = Coarse::of(&chain, release.length, &gaps, &velocities);
        let pick = |values: &[f64]| -> Vec<f64> {
            centres
                .iter()
                .map(|x| values[(((x + 0.5 * release.length) / cell).round() as usize).min(units)])
                .collect()
        };
        let coarse = Coarse {
            x: centres.clone(),
            strain: pick(&all.strain),
            velocity: pick(&all.velocity),
            hidden_energy: pick(&all.hidden_energy),
        };
        Sample {
            t,
            right_end: gaps.iter().sum(),
            energy: m.energy(at).unwrap_or(f64::NAN),
            front: coarse.front(undisturbed(release)),
            coarse,
        }
    };
    track(
        format!("chain N={units}"),
        Model::Chain(units),
        &mut model,
        release,
        limits,
        sample,
    )
}

/// The continuum `variant` on `release`, built as `flicker run` builds it.
pub fn continuum_track(
    release: &ContinuumScene,
    variant: Variant,
    limits: &Limits,
) -> Result<Track, String> {
    let label = format!("continuum ({})", variant.name());
    // Energies are compared with the scene's load: where the paper's
    // continuum holds its end with more (F_cr), its own energy counts that
    // force's potential instead, which the scene's does not.
    let string = release.string(release.constraint);
    let held = string.end_force() - string.load * string.critical_load();
    let refused = |e: SceneError| e.to_string();
    match variant {
        Variant::Paper => {
            let mut model =
                crate::models::continuum::run::front_tracking(release, release.constraint)
                    .map_err(refused)?;
            string_track(label, variant, held, &mut model, release, limits)
        }
        Variant::Homogenized => {
            let mut model = crate::models::continuum::run::homogenized(release).map_err(refused)?;
            string_track(label, variant, 0.0, &mut model, release, limits)
        }
    }
}

/// `held`: the force the model's end carries beyond the scene's load.
fn string_track<M: StringModel>(
    label: String,
    variant: Variant,
    held: f64,
    model: &mut M,
    release: &ContinuumScene,
    limits: &Limits,
) -> Result<Track, String> {
    let centres = centres(release);
    let sample = |m: &M, t: f64| {
        let at = Time::new(t);
        let coarse = m.coarse(&centres, at);
        let right_end = m.right_end(at);
        Sample {
            t,
            right_end,
            energy: m.energy(at).map_or(f64::NAN, |e| e + held * right_end),
            front: coarse.front(undisturbed(release)),
            coarse,
        }
    };
    track(
        label,
        Model::Continuum(variant),
        model,
        release,
        limits,
        sample,
    )
}

/// Run `model`, sampling at the release's sample and snapshot times.
fn track<M: LocalModel>(
    label: String,
    kind: Model,
    model: &mut M,
    release: &ContinuumScene,
    limits: &Limits,
    sample: impl Fn(&M, f64) -> Sample,
) -> Result<Track, String> {
    let options: Options = limits.options(
        release.t_end,
        release.max_events,
        Method::Exact,
        Tolerances::default(),
    );
    let times = release.sample_times();
    let mut taken = Vec::new();
    let started = Instant::now();
    let outcome = simulate_local(
        model,
        &options,
        &release.due_times(),
        &mut |m: &M, t| taken.push(sample(m, t)),
        &mut (),
    );
    let wall_seconds = started.elapsed().as_secs_f64();
    let pick = |wanted: &[f64]| -> Vec<Sample> {
        taken
            .iter()
            .filter(|s| wanted.contains(&s.t))
            .cloned()
            .collect()
    };
    Ok(Track {
        label,
        model: kind,
        status: outcome.status,
        reason: outcome.reason,
        events: outcome.events,
        wall_seconds,
        max_energy_error: outcome.max_energy_error,
        samples: pick(&times),
        snapshots: pick(&release.snapshots),
    })
}

/// How far a track is from the reference (the densest chain).
#[derive(Debug, Clone, PartialEq)]
pub struct Distance {
    /// Largest `|right_end - reference|` over the sample times.
    pub right_end: f64,
    /// The same until the wave reflected at the wall is back at the loaded
    /// end ([`Distance::returned`]).
    pub right_end_before_return: f64,
    /// When the reference's end first stops moving towards the wall (its
    /// first local minimum): the reflected wave is back.
    pub returned: Option<f64>,
    /// Largest `|front - reference|` while the reference's front is on
    /// its way to the wall (more than a window from it).
    pub front: Option<f64>,
    /// Mean speed of the front on its way to the wall (a least-squares
    /// line of position against time).
    pub front_speed: Option<f64>,
    /// Relative difference of the plateau's strain and velocity: the mean
    /// over the windows behind the reference's front (a window clear of
    /// the front and of the end; at least [`PLATEAU_WINDOWS`] of them) and
    /// over the sample times while the front is on its way. This is the
    /// strain's; `None` where no plateau was measured.
    pub plateau_strain: Option<f64>,
    /// The same for the plateau's velocity.
    pub plateau_velocity: Option<f64>,
    /// Largest difference of the coarse strain over the window centres and
    /// snapshot times.
    pub window_strain: f64,
    /// The same for the coarse velocity.
    pub window_velocity: f64,
    /// The same for the hidden energy.
    pub hidden_energy: f64,
    /// Largest `|energy - reference|` relative to the reference's initial
    /// energy.
    pub energy: f64,
}

/// The distance of `track` from `reference`.
pub fn distance(track: &Track, reference: &Track) -> Distance {
    let largest = |pairs: &mut dyn Iterator<Item = f64>| pairs.fold(0.0, f64::max);
    let paired = || track.samples.iter().zip(&reference.samples);
    let fields = |field: fn(&Coarse) -> &[f64]| {
        largest(
            &mut track
                .snapshots
                .iter()
                .zip(&reference.snapshots)
                .flat_map(|(a, b)| {
                    field(&a.coarse)
                        .iter()
                        .zip(field(&b.coarse))
                        .map(|(x, y)| (x - y).abs())
                        .collect::<Vec<_>>()
                }),
        )
    };
    let on_its_way = |s: &Sample| s.front.filter(|&x| x > s.coarse.x[0] + WINDOW_WIDTH);
    // From the release until the reference's front first comes within a
    // window of the wall (after that a "front" is some later dip).
    let travelling = || {
        paired()
            .skip_while(|(_, r)| r.front.is_none())
            .take_while(|(_, r)| on_its_way(r).is_some())
    };
    let fronts: Vec<f64> = travelling()
        .filter_map(|(a, b)| Some((a.front? - b.front?).abs()))
        .collect();
    let returned = reference
        .samples
        .windows(2)
        .find(|w| w[1].right_end > w[0].right_end)
        .map(|w| w[0].t);
    let before_return = paired()
        .filter(|(a, _)| returned.is_none_or(|r| a.t <= r))
        .map(|(a, b)| (a.right_end - b.right_end).abs());
    let plateau = |field: fn(&Coarse) -> &[f64]| -> Option<f64> {
        let (mut mine, mut theirs, mut times) = (0.0, 0.0, 0);
        for (a, b) in travelling() {
            let (Some(front), Some(&end)) = (on_its_way(b), b.coarse.x.last()) else {
                continue;
            };
            let behind = |c: &Coarse| -> Vec<f64> {
                c.x.iter()
                    .zip(field(c))
                    .filter(|(x, _)| **x > front + WINDOW_WIDTH && **x < end - WINDOW_WIDTH)
                    .map(|(_, y)| *y)
                    .collect()
            };
            let (m, r) = (behind(&a.coarse), behind(&b.coarse));
            if r.len() >= PLATEAU_WINDOWS {
                mine += m.iter().sum::<f64>() / m.len() as f64;
                theirs += r.iter().sum::<f64>() / r.len() as f64;
                times += 1;
            }
        }
        (times > 0).then(|| (mine - theirs).abs() / theirs.abs().max(f64::MIN_POSITIVE))
    };
    let e0 = reference
        .samples
        .first()
        .map_or(1.0, |s| s.energy.abs().max(f64::MIN_POSITIVE));
    Distance {
        right_end: largest(&mut paired().map(|(a, b)| (a.right_end - b.right_end).abs())),
        right_end_before_return: largest(&mut before_return.into_iter()),
        returned,
        front: (!fronts.is_empty()).then(|| largest(&mut fronts.into_iter())),
        front_speed: front_speed(track),
        plateau_strain: plateau(|c| &c.strain),
        plateau_velocity: plateau(|c| &c.velocity),
        window_strain: fields(|c| &c.strain),
        window_velocity: fields(|c| &c.velocity),
        hidden_energy: fields(|c| &c.hidden_energy),
        energy: largest(&mut paired().map(|(a, b)| (a.energy - b.energy).abs() / e0)),
    }
}

/// The front's mean speed towards the wall: the slope of a least-squares
/// line through its positions while it is seen (before it reaches the
/// wall's window), if seen at three times at least.
pub fn front_speed(track: &Track) -> Option<f64> {
    let seen: Vec<(f64, f64)> = track
        .samples
        .iter()
        .filter_map(|s| Some((s.t, s.front?)))
        .take_while(|&(_, x)| x > track.samples[0].coarse.x[0] + WINDOW_WIDTH)
        .collect();
    if seen.len() < 3 {
        return None;
    }
    let n = seen.len() as f64;
    let (mt, mx) = seen
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, x)| (a + t / n, b + x / n));
    let (sxy, sxx) = seen.iter().fold((0.0, 0.0), |(a, b), (t, x)| {
        (a + (t - mt) * (x - mx), b + (t - mt) * (t - mt))
    });
    Some(-sxy / sxx)
}

/// One model of a comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    /// The chain of this many units.
    Chain(usize),
    /// The continuum of this variant.
    Continuum(Variant),
}

/// Run every model on `release`, in parallel, sampled at its sample and
/// snapshot times.
pub fn run_all(
    release: &ContinuumScene,
    models: &[Model],
    limits: &Limits,
) -> Result<Vec<Track>, String> {
    models
        .par_iter()
        .map(|&model| match model {
            Model::Chain(n) => chain_track(release, n, limits),
            Model::Continuum(v) => continuum_track(release, v, limits),
        })
        .collect()
}
