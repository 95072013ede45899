//! One release scene as the dense chain at several N and as each continuum,
//! compared by the reproducible quantities of PHYSICS.md s.6-7: the loaded
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

use std::time::Instant;

use rayon::prelude::*;

use crate::engine::{LocalModel, Method, Options, Status, Tolerances, simulate_local};
use crate::models::chain::TaylorChain;
use crate::models::chain::coarse::{Coarse, WINDOW_WIDTH};
use crate::models::continuum::{
    Continuum, FrontTracking, Homogenized, Piece, StringModel, Variant,
};
use crate::runner::Control;
use crate::scene::{Scene, SceneError};
use crate::time::Time;

/// Fewest windows behind the front for a plateau to be measured.
pub const PLATEAU_WINDOWS: usize = 10;

/// Cells of the homogenized string unless the caller says otherwise.
pub const DEFAULT_CELLS: usize = 200;

/// Window centres the coarse fields are compared at: every 0.02 on the
/// paper's string of length 2.
pub const CENTRES: usize = 101;

/// The release a comparison runs: a uniform string at rest at strain
/// `load_before - 1`, its end load dropping to `load_after` at `t = 0`.
#[derive(Debug, Clone, PartialEq)]
pub struct Release {
    pub length: f64,
    pub wave_speed: f64,
    pub load_before: f64,
    pub load_after: f64,
    pub constraint: bool,
    pub t_end: f64,
    /// Times the coarse profiles are compared at.
    pub snapshots: Vec<f64>,
    pub max_events: u64,
    /// Cells of the homogenized string.
    pub cells: usize,
}

impl Release {
    /// The release a chain or continuum scene describes; scenes with an
    /// `initial` profile are refused (the models would not start alike).
    pub fn of(scene: &Scene) -> Result<Self, SceneError> {
        let uniform = |strains: &[f64], velocities: &[f64], rest: f64| {
            strains.iter().all(|e| *e == rest) && velocities.iter().all(|v| *v == 0.0)
        };
        let refuse = || {
            SceneError::field(
                "initial",
                "the models are compared from the release of a uniform string at rest; leave `initial` out".into(),
            )
        };
        match scene {
            Scene::Chain(c) => {
                if !uniform(&c.strain, &c.velocity, c.load_before - 1.0) {
                    return Err(refuse());
                }
                Ok(Release {
                    length: c.length,
                    wave_speed: c.wave_speed,
                    load_before: c.load_before,
                    load_after: c.load_after,
                    constraint: c.constraint,
                    t_end: c.t_end,
                    snapshots: c.snapshots.clone(),
                    max_events: c.max_events,
                    cells: DEFAULT_CELLS,
                })
            }
            Scene::Continuum(c) => {
                let strains: Vec<f64> = c.cells.iter().map(|p| p.strain).collect();
                let velocities: Vec<f64> = c.cells.iter().map(|p| p.velocity).collect();
                if !uniform(&strains, &velocities, c.load_before - 1.0) {
                    return Err(refuse());
                }
                Ok(Release {
                    length: c.length,
                    wave_speed: c.wave_speed,
                    load_before: c.load_before,
                    load_after: c.load_after,
                    constraint: c.constraint,
                    t_end: c.t_end,
                    snapshots: c.snapshots.clone(),
                    max_events: c.max_events,
                    cells: DEFAULT_CELLS,
                })
            }
            Scene::Mechanism(_) => Err(SceneError::field(
                "model",
                "compares a chain with its continuum: give a chain or continuum scene".into(),
            )),
        }
    }

    /// The strain the string starts at, against which the front is found.
    pub fn undisturbed(&self) -> f64 {
        self.load_before - 1.0
    }

    /// Why the homogenized string does not describe this release, if it
    /// does not: it keeps the rattling the constraint causes, from a
    /// stretched string.
    pub fn without_homogenized(&self) -> Option<String> {
        if !self.constraint {
            Some("the homogenized string is left out: it describes the constrained string (this one's constraint is off)".into())
        } else if self.undisturbed() <= 0.0 {
            Some(format!(
                "the homogenized string is left out: it starts from a stretched string (this one starts at strain {})",
                self.undisturbed()
            ))
        } else {
            None
        }
    }

    /// The window centres, from the wall to the loaded end.
    pub fn centres(&self) -> Vec<f64> {
        (0..CENTRES)
            .map(|j| -0.5 * self.length + self.length * j as f64 / (CENTRES - 1) as f64)
            .collect()
    }
}

/// One model's run, sampled.
#[derive(Debug, Clone)]
pub struct Track {
    /// `chain N=..` or `continuum (variant)`.
    pub label: String,
    pub units: Option<usize>,
    pub model: Model,
    pub status: Status,
    pub reason: Option<String>,
    pub events: u64,
    pub wall_seconds: f64,
    pub max_energy_error: Option<f64>,
    /// At the comparison's sample times, then at its snapshots.
    pub samples: Vec<Sample>,
    pub snapshots: Vec<Sample>,
}

/// A model at one time.
#[derive(Debug, Clone)]
pub struct Sample {
    pub t: f64,
    pub right_end: f64,
    pub energy: f64,
    pub front: Option<f64>,
    pub coarse: Coarse,
}

/// The chain of `units` on `release` (exact event-local flow, no log).
pub fn chain_track(
    release: &Release,
    units: usize,
    times: &[f64],
    control: &Control,
) -> Result<Track, String> {
    let chain = crate::models::chain::Chain::in_scene_units(
        units,
        release.length,
        release.wave_speed,
        release.load_after,
        release.constraint,
    );
    let gaps = vec![release.undisturbed() * chain.unit_length(); units];
    let mut model = TaylorChain::new(chain.clone(), &gaps, &vec![0.0; units])?;
    let centres = release.centres();
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
            front: coarse.front(release.undisturbed()),
            coarse,
        }
    };
    track(
        format!("chain N={units}"),
        Model::Chain(units),
        &mut model,
        release,
        times,
        control,
        sample,
    )
}

/// The continuum `variant` on `release`.
pub fn continuum_track(
    release: &Release,
    variant: Variant,
    times: &[f64],
    control: &Control,
) -> Result<Track, String> {
    let string = Continuum {
        length: release.length,
        wave_speed: release.wave_speed,
        load: release.load_after,
        constraint: release.constraint,
        variant,
    };
    let label = format!("continuum ({})", variant.name());
    // Energies are compared with the scene's load: where the paper's
    // continuum holds its end with more (F_cr), its own energy counts that
    // force's potential instead, which the scene's does not.
    let held = string.end_force() - string.load * string.critical_load();
    match variant {
        Variant::Paper => {
            let start = Piece {
                strain: release.undisturbed(),
                velocity: 0.0,
            };
            let mut model = FrontTracking::new(string, &[start])?;
            string_track(label, variant, held, &mut model, release, times, control)
        }
        Variant::Homogenized => {
            let mut checkpoints = times.to_vec();
            checkpoints.extend(&release.snapshots);
            checkpoints.push(release.t_end);
            let mut model =
                Homogenized::new(string, release.undisturbed(), release.cells, &checkpoints)?;
            string_track(label, variant, 0.0, &mut model, release, times, control)
        }
    }
}

/// `held`: the force the model's end carries beyond the scene's load.
fn string_track<M: StringModel>(
    label: String,
    variant: Variant,
    held: f64,
    model: &mut M,
    release: &Release,
    times: &[f64],
    control: &Control,
) -> Result<Track, String> {
    let centres = release.centres();
    let sample = |m: &M, t: f64| {
        let at = Time::new(t);
        let coarse = m.coarse(&centres, at);
        let right_end = m.right_end(at);
        Sample {
            t,
            right_end,
            energy: m.energy(at).map_or(f64::NAN, |e| e + held * right_end),
            front: coarse.front(release.undisturbed()),
            coarse,
        }
    };
    track(
        label,
        Model::Continuum(variant),
        model,
        release,
        times,
        control,
        sample,
    )
}

/// Run `model`, sampling at `times` and at the release's snapshots.
fn track<M: LocalModel>(
    label: String,
    kind: Model,
    model: &mut M,
    release: &Release,
    times: &[f64],
    control: &Control,
    sample: impl Fn(&M, f64) -> Sample,
) -> Result<Track, String> {
    let options: Options = control.options(
        release.t_end,
        release.max_events,
        Method::Exact,
        Tolerances::default(),
    );
    let mut all: Vec<f64> = times.iter().chain(&release.snapshots).copied().collect();
    all.sort_by(f64::total_cmp);
    all.dedup();
    let mut taken = Vec::new();
    let started = Instant::now();
    let outcome = simulate_local(
        model,
        &options,
        &all,
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
        units: match kind {
            Model::Chain(n) => Some(n),
            Model::Continuum(_) => None,
        },
        model: kind,
        status: outcome.status,
        reason: outcome.reason,
        events: outcome.events,
        wall_seconds,
        max_energy_error: outcome.max_energy_error,
        samples: pick(times),
        snapshots: pick(&release.snapshots),
    })
}

/// How far a track is from the reference (the densest chain).
#[derive(Debug, Clone, PartialEq)]
pub struct Distance {
    pub label: String,
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
    /// over the sample times while the front is on its way.
    pub plateau_strain: Option<f64>,
    pub plateau_velocity: Option<f64>,
    /// Largest difference of the coarse strain, velocity and hidden energy
    /// over the window centres and snapshot times.
    pub window_strain: f64,
    pub window_velocity: f64,
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
        label: track.label.clone(),
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
    Chain(usize),
    Continuum(Variant),
}

/// Run every model on `release`, in parallel, sampled at `samples` times.
pub fn run_all(
    release: &Release,
    models: &[Model],
    samples: usize,
    control: &Control,
) -> Result<Vec<Track>, String> {
    let times = crate::scene::extent::sample_times(release.t_end, samples);
    models
        .par_iter()
        .map(|&model| match model {
            Model::Chain(n) => chain_track(release, n, &times, control),
            Model::Continuum(v) => continuum_track(release, v, &times, control),
        })
        .collect()
}
