//! The reproducibility horizon of a chain scene (docs/physics.md s.7): copies
//! of the run with each initial strain moved by up to `perturb` times the
//! scene's largest initial strain, run in parallel, compared at the
//! scene's sample times.
//!
//! Copy `i` draws its perturbation from its own xorshift stream seeded by
//! `(seed, i)`, so the ensemble is the same for a given seed whatever the
//! number of threads. The horizon is the first sample time at which some
//! unit's strain differs between two copies by more than [`HORIZON`]; the
//! spread of a field at a time is its largest difference between two
//! copies there (over units or windows).

use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;
use rayon::prelude::*;

use crate::engine::{Method, Options, Status, Tolerances, simulate_local};
use crate::models::chain::coarse::Coarse;
use crate::models::chain::{Chain, TaylorChain};
use crate::runner::Control;
use crate::scene::{ChainScene, SceneError};
use crate::time::Time;

/// Unit strains differing by more than this are no longer reproducible.
pub const HORIZON: f64 = 1e-3;

/// Most stored values (copies x samples x units x 4) an ensemble may hold.
const MAX_VALUES: usize = 100_000_000;

/// What the ensemble found.
#[derive(Debug, Clone, PartialEq)]
pub struct Ensemble {
    /// Number of perturbed copies run.
    pub copies: usize,
    /// Largest perturbation of a unit's initial strain, relative to the
    /// scene's largest initial strain.
    pub perturb: f64,
    /// Seed of the perturbations.
    pub seed: u64,
    /// First sample time at which unit strains of two copies differ by
    /// more than [`HORIZON`], if any before `t_end`.
    pub horizon: Option<f64>,
    /// Spacing of the sample times: the horizon's resolution.
    pub resolution: f64,
    /// The spread at each sample time.
    pub spread: Vec<Spread>,
}

/// The largest difference between copies at one sample time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// The sample time.
    pub t: f64,
    /// Largest difference of a unit's strain.
    pub unit_strain: f64,
    /// Largest difference of a window's coarse strain.
    pub window_strain: f64,
    /// Largest difference of a window's coarse velocity.
    pub window_velocity: f64,
    /// Largest difference of a window's hidden energy.
    pub hidden_energy: f64,
    /// Largest difference of the loaded end's displacement.
    pub right_end: f64,
    /// `None` while some copy has no front (docs/physics.md s.6) yet.
    pub front: Option<f64>,
}

/// One copy at one sample time.
struct Sample {
    strain: Vec<f64>,
    coarse: Coarse,
    right_end: f64,
    front: Option<f64>,
}

/// Whether an ensemble of `copies` at `perturb` can run on `scene`: checked
/// before anything runs, so bad flags lose nothing.
pub fn check(scene: &ChainScene, copies: usize, perturb: f64) -> Result<(), SceneError> {
    let refuse = |reason: String| SceneError::field("ensemble", reason);
    if copies < 2 {
        return Err(refuse(format!(
            "needs at least 2 copies to compare (got {copies})"
        )));
    }
    if !(perturb.is_finite() && perturb > 0.0 && perturb < 1.0) {
        return Err(refuse(format!(
            "the perturbation must be in (0, 1) (got {perturb})"
        )));
    }
    let times = scene.sample_times();
    if times.len() < 2 {
        return Err(refuse(
            "needs at least 2 sample times (the scene's `samples`)".into(),
        ));
    }
    let stored = copies
        .saturating_mul(times.len())
        .saturating_mul(scene.units)
        .saturating_mul(4);
    if stored > MAX_VALUES {
        return Err(refuse(format!(
            "{copies} copies x {} samples x {} units is too much to hold; lower `samples` or the copies",
            times.len(),
            scene.units
        )));
    }
    Ok(())
}

/// Run `copies` perturbed copies of `scene` (exact flow, no log), which
/// [`check`] accepted; an error says which copy stopped and why.
pub fn run_ensemble(
    scene: &ChainScene,
    copies: usize,
    perturb: f64,
    seed: u64,
    control: &Control,
) -> Result<Ensemble, String> {
    check(scene, copies, perturb).map_err(|e| e.reason)?;
    let times = scene.sample_times();
    let chain = scene.chain(scene.constraint);
    let options = control.options(
        scene.t_end,
        scene.max_events,
        Method::Exact,
        Tolerances::default(),
    );
    let runs: Vec<Result<Vec<Sample>, String>> = (0..copies)
        .into_par_iter()
        .map(|copy| run_copy(scene, &chain, &options, &times, perturb, seed, copy))
        .collect();
    let runs: Vec<Vec<Sample>> = runs.into_iter().collect::<Result<_, _>>()?;
    let spread: Vec<Spread> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| spread_at(t, runs.iter().map(|r| &r[i])))
        .collect();
    let horizon = spread.iter().find(|s| s.unit_strain > HORIZON).map(|s| s.t);
    Ok(Ensemble {
        copies,
        perturb,
        seed,
        horizon,
        resolution: times[1] - times[0],
        spread,
    })
}

fn run_copy(
    scene: &ChainScene,
    chain: &Chain,
    options: &Options,
    times: &[f64],
    perturb: f64,
    seed: u64,
    copy: usize,
) -> Result<Vec<Sample>, String> {
    let mut rng =
        XorShiftRng::seed_from_u64(seed ^ (copy as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let unit_length = chain.unit_length();
    // Relative to the scene's strain scale, so that units starting shut are
    // perturbed too.
    let scale = scene.strain.iter().fold(0.0, |m: f64, e| m.max(e.abs()));
    let scale = if scale > 0.0 { scale } else { 1.0 };
    let gaps: Vec<f64> = scene
        .strain
        .iter()
        .map(|e| {
            let r: f64 = rng.random_range(-1.0..=1.0);
            let moved = e + perturb * scale * r;
            // The constraint holds strains at zero from below.
            let moved = if scene.constraint {
                moved.max(0.0)
            } else {
                moved
            };
            moved * unit_length
        })
        .collect();
    let mut model = TaylorChain::new(chain.clone(), &gaps, &scene.velocity)?;
    let undisturbed = scene.load_before - 1.0;
    let mut samples = Vec::with_capacity(times.len());
    let outcome = simulate_local(
        &mut model,
        options,
        times,
        &mut |m: &TaylorChain, t| {
            let (gaps, velocities) = m.state_at(Time::new(t));
            let coarse = Coarse::of(chain, scene.length, &gaps, &velocities);
            samples.push(Sample {
                strain: gaps.iter().map(|d| d / unit_length).collect(),
                right_end: gaps.iter().sum(),
                front: coarse.front(undisturbed),
                coarse,
            });
        },
        &mut (),
    );
    match outcome.status {
        Status::Completed => Ok(samples),
        _ => Err(format!(
            "copy {copy} stopped at t = {}: {}",
            outcome.t_reached,
            outcome.reason.unwrap_or_default()
        )),
    }
}

/// The largest pairwise differences between `copies` at one time.
fn spread_at<'s>(t: f64, copies: impl Iterator<Item = &'s Sample> + Clone) -> Spread {
    let range = |values: &dyn Fn(&Sample) -> &[f64]| -> f64 {
        let first = values(copies.clone().next().expect("at least two copies"));
        let mut low = first.to_vec();
        let mut high = first.to_vec();
        for s in copies.clone() {
            for ((lo, hi), x) in low.iter_mut().zip(high.iter_mut()).zip(values(s)) {
                *lo = lo.min(*x);
                *hi = hi.max(*x);
            }
        }
        low.iter()
            .zip(&high)
            .map(|(lo, hi)| hi - lo)
            .fold(0.0, f64::max)
    };
    let scalar = |value: &dyn Fn(&Sample) -> Option<f64>| -> Option<f64> {
        let values: Option<Vec<f64>> = copies.clone().map(value).collect();
        values.map(|v| {
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(*x), hi.max(*x))
                });
            hi - lo
        })
    };
    Spread {
        t,
        unit_strain: range(&|s| &s.strain),
        window_strain: range(&|s| &s.coarse.strain),
        window_velocity: range(&|s| &s.coarse.velocity),
        hidden_energy: range(&|s| &s.coarse.hidden_energy),
        right_end: scalar(&|s| Some(s.right_end)).unwrap_or(0.0),
        front: scalar(&|s| s.front),
    }
}
