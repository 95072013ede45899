//! `flicker advise`: whether a chain scene needs its chain, or a continuum
//! reproduces its coarse behaviour within a tolerance, and at what cost,
//! from measured runs.
//!
//! The chain is run at a probe size (the scene's N, at most
//! [`PROBE_UNITS`]) and each continuum beside it; each continuum's
//! distance from the probe is measured (the loaded end's displacement
//! until the reflected wave is back and over the whole run, and the
//! front's speed). The
//! chain's cost at the scene's N is the probe's, scaled by `N^2`: the
//! number of impacts grows as `N^2` per unit time while the exact flow's
//! cost per impact does not grow (issue 4's measured figures), so this is
//! an estimate, said to be one.

use std::path::PathBuf;

use crate::analysis::release_convergence::Release;
use crate::analysis::release_convergence::{
    Track, chain_track, continuum_track, distance, release, without_homogenized,
};
use crate::engine::Status;
use crate::models::continuum::Variant;
use crate::runner::Control;
use crate::scene::Registry;

use crate::cli::exit::{Code, Failure};

/// Largest chain run to probe a scene.
pub const PROBE_UNITS: usize = 400;

/// Times the models are compared at.
const SAMPLES: usize = 121;

/// `flicker advise`'s arguments.
#[derive(Debug, clap::Args)]
pub struct AdviseArgs {
    /// A chain scene (a uniform string at rest, released).
    scene: PathBuf,
    /// Largest difference of the loaded end's displacement from the chain
    /// that still counts as reproduced, in the scene's length units.
    #[arg(long, default_value_t = 0.01, value_name = "D")]
    tolerance: f64,
}

/// Run `flicker advise`: probe the chain scene and each continuum, print
/// how far each continuum is from the chain and what it costs, and advise
/// which to run. Returns [`Code::Untrusted`] if a run stopped early.
pub fn advise(args: AdviseArgs, registry: &Registry) -> Result<Code, Failure> {
    let scene = registry.load(&args.scene).map_err(Failure::bad_input)?;
    let not_a_chain = || {
        Failure::bad_input(format!(
            "{}: advise weighs a chain scene against its continua; this is not a chain scene",
            args.scene.display()
        ))
    };
    let units = match crate::analysis::release_convergence::release::described(&scene) {
        Some(Release {
            units: Some(units), ..
        }) => units,
        _ => return Err(not_a_chain()),
    };
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        return Err(Failure::bad_input("--tolerance: a number > 0"));
    }
    let mut release = release(&scene)
        .map_err(|e| Failure::bad_input(e.in_path(&args.scene)))?
        .string;
    release.samples = SAMPLES;
    let probe = units.min(PROBE_UNITS);
    // One after another, so that each is timed alone.
    let control = Control::default();
    let mut runs = vec![
        chain_track(&release, probe, &control),
        continuum_track(&release, Variant::Paper, &control),
    ];
    match without_homogenized(&release) {
        None => runs.push(continuum_track(&release, Variant::Homogenized, &control)),
        Some(why) => say!("{why}"),
    }
    let tracks: Vec<Track> = runs
        .into_iter()
        .collect::<Result<_, _>>()
        .map_err(Failure::bad_input)?;
    if let Some(t) = tracks.iter().find(|t| t.status != Status::Completed) {
        say!(
            "{} stopped: {}",
            t.label,
            t.reason.clone().unwrap_or_default()
        );
        return Ok(Code::Untrusted);
    }
    let reference = &tracks[0];
    let scale = (units as f64 / probe as f64).powi(2);
    let chain_seconds = reference.wall_seconds * scale;
    say!(
        "{}: chain of {} units; probed with the chain at N = {probe} ({:.3} s, {} impacts){}",
        args.scene.display(),
        units,
        reference.wall_seconds,
        reference.events,
        if scale > 1.0 {
            format!(
                "; at N = {} it would take about {chain_seconds:.1} s (x N^2)",
                units
            )
        } else {
            String::new()
        }
    );
    let mut best: Option<(&str, f64)> = None;
    for track in &tracks[1..] {
        let d = distance(track, reference);
        let within = d.right_end <= args.tolerance;
        let ratio = chain_seconds / track.wall_seconds.max(1e-6);
        say!(
            "  {}: loaded end within {:.4} of the chain until the reflected wave is back ({}), {:.4} over the run \
             ({} the tolerance {}); front speed {} against {}; {}",
            track.label,
            d.right_end_before_return,
            d.returned.map_or("-".into(), |t| format!("t = {t:.3}")),
            d.right_end,
            if within { "within" } else { "outside" },
            args.tolerance,
            d.front_speed.map_or("-".into(), |s| format!("{s:.3}")),
            distance(reference, reference)
                .front_speed
                .map_or("-".into(), |s| format!("{s:.3}")),
            if ratio >= 1.0 {
                format!("{ratio:.1}x cheaper")
            } else {
                format!("{:.1}x dearer", 1.0 / ratio)
            }
        );
        if within && best.is_none_or(|(_, r)| ratio > r) {
            best = Some((track.label.as_str(), ratio));
        }
    }
    match best {
        Some((label, ratio)) => say!(
            "advice: {label} reproduces this scene's loaded end within {}, {}; run it for coarse results (the chain for unit-level ones)",
            args.tolerance,
            if ratio >= 1.0 {
                format!("at {ratio:.1}x less cost")
            } else {
                format!(
                    "though at {:.1}x the cost: at this N the chain is cheaper",
                    1.0 / ratio
                )
            }
        ),
        None => say!(
            "advice: no continuum reproduces this scene within {}; run the chain",
            args.tolerance
        ),
    }
    Ok(Code::Ok)
}
