//! `flicker advise`: whether a chain scene needs its chain, or a continuum
//! reproduces its coarse behaviour within a tolerance, and at what cost,
//! from measured runs.
//!
//! The chain is run at a probe size (the scene's N, at most
//! [`PROBE_UNITS`](crate::session::PROBE_UNITS)) and each continuum beside it; each continuum's
//! distance from the probe is measured (the loaded end's displacement
//! until the reflected wave is back and over the whole run, and the
//! front's speed). The
//! chain's cost at the scene's N is the probe's, scaled by `N^2`: the
//! number of impacts grows as `N^2` per unit time while the exact flow's
//! cost per impact does not grow (issue 4's measured figures), so this is
//! an estimate, said to be one.

use std::path::PathBuf;

use crate::session::{NotProbed, Registry, Status};

use crate::cli::exit::{Code, Failure};

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
    let probed = crate::session::probe(&scene, args.tolerance).map_err(|e| match e {
        NotProbed::NotAChain => Failure::bad_input(format!(
            "{}: advise weighs a chain scene against its continua; this is not a chain scene",
            args.scene.display()
        )),
        NotProbed::Refused(e) if e.field.as_deref() == Some("tolerance") => {
            Failure::bad_input(format!("--tolerance: {}", e.reason))
        }
        NotProbed::Refused(e) => Failure::bad_input(e.in_path(&args.scene)),
        NotProbed::Failed(why) => Failure::bad_input(why),
    })?;
    if let Some(why) = &probed.left_out {
        say!("{why}");
    }
    let (units, probe) = (probed.units, probed.probe);
    let tracks = &probed.measured.tracks;
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
    let distances = &probed.measured.distances;
    for (track, d) in tracks.iter().zip(distances).skip(1) {
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
            distances[0]
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
