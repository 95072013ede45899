//! `flicker basins`: a grid of starting values of two states, each named
//! by the attractor it reaches; writes `DIR/basins.csv` (the two states
//! and the attractor's id per point), `DIR/attractors.json` (each
//! attractor: its id, kind, a state on it, its period in section events)
//! and the picture `DIR/basins.svg` and `.png`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::cli::exit::{Code, Failure};
use crate::cli::progress::Points;
use crate::log::summary::write_atomically;
use crate::plot::draw::{Curve, Figure, Style};
use crate::session::{Basins, BasinsRequest, Registry};

/// `flicker basins`'s arguments.
#[derive(Debug, clap::Args)]
pub struct BasinsArgs {
    /// The scene file (any model with a finite state).
    scene: PathBuf,
    /// The grid: two states' starting values, `S1=A:B:N,S2=C:D:M` (the
    /// other states from the scene).
    #[arg(long, value_name = "S1=A:B:N,S2=C:D:M", value_delimiter = ',')]
    grid: Vec<String>,
    /// Time run before a point is read (default: the scene's t_end).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    transient: Option<f64>,
    /// The guard whose events are read for a periodic orbit.
    #[arg(long, value_name = "GUARD")]
    section: Option<String>,
    /// Section events read for a repeat.
    #[arg(long, value_name = "K", default_value_t = 64)]
    record: usize,
    /// How close two states must be to count as the same (relative to the
    /// larger of 1 and their size).
    #[arg(long, value_name = "D", default_value_t = 1e-6)]
    tolerance: f64,
    /// The forcing's period, for a model that reads the clock t: its
    /// periodic orbits are then refined (period, multipliers, stability).
    #[arg(
        long = "forcing-period",
        value_name = "T",
        allow_negative_numbers = true
    )]
    forcing_period: Option<f64>,
    /// Go on past each run's horizon as a pseudo-orbit: what tells a
    /// chaotic attractor, whose runs otherwise fail there.
    #[arg(long = "past-horizon")]
    past_horizon: bool,
    /// Run only the points I, I+N, I+2N, ... (0 <= I < N), for batch jobs.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// Stop, saying so, after this many seconds of wall time.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 3600.0,
        allow_negative_numbers = true
    )]
    wall: f64,
    /// Do not draw progress.
    #[arg(long)]
    quiet: bool,
    // This doc comment is clap's help text, printed as written: the
    // `<scene name>` in it is a placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>-basins).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Run `flicker basins`: check the request, run every point in parallel,
/// write the CSV, the attractors and the picture, and say what each
/// attractor is and how many points reach it.
pub fn basins(args: BasinsArgs, registry: &Registry) -> Result<Code, Failure> {
    let scene = registry.load(&args.scene).map_err(Failure::bad_input)?;
    let asked = BasinsRequest {
        grid: args.grid.clone(),
        transient: args.transient,
        section: args.section.clone(),
        record: args.record,
        tolerance: args.tolerance,
        forcing_period: args.forcing_period,
        past_horizon: args.past_horizon,
        shard: args.shard.clone(),
        wall: args.wall,
    };
    let prepared = asked
        .on(&scene)
        .map_err(|e| Failure::refused(&args.scene, e))?;
    let out = crate::cli::setup::out_dir(args.out.clone(), &args.scene, "basins");
    crate::cli::setup::output_folder(&out)?;
    let stop = crate::cli::setup::stop_flag();
    let started = Instant::now();
    let bar = Points::new(prepared.points(), args.quiet);
    let found = prepared.run(Some(stop.clone()), &|| bar.tick());
    bar.finish();
    let seconds = started.elapsed().as_secs_f64();
    let axes = &prepared.request().axes;
    let labels = [axes[0].state.as_str(), axes[1].state.as_str()];
    let untrusted = |path: &Path, e: String| Failure::untrusted(format!("{}: {e}", path.display()));
    let csv = out.join("basins.csv");
    write_csv(&found, labels, &csv).map_err(|e| untrusted(&csv, e.to_string()))?;
    let json = out.join("attractors.json");
    write_atomically(&json, &attractors(&found)).map_err(|e| untrusted(&json, e.to_string()))?;
    let mut written = vec![csv, json];
    written.extend(crate::cli::setup::draw_both(
        &picture(&found, labels),
        &out,
        "basins",
    )?);
    let run = found.attractor.iter().filter(|a| a.is_some()).count();
    say!(
        "{run} points of {} in {seconds:.3} s reach {} attractors:",
        found.attractor.len(),
        found.attractors.len()
    );
    for a in &found.attractors {
        let state: Vec<String> = found
            .names
            .iter()
            .zip(&a.state)
            .map(|(n, x)| format!("{n} = {x:.6e}"))
            .collect();
        say!(
            "  {}: {}{} ({} points) at {}{}",
            a.id,
            a.kind.as_str(),
            if a.cycle.is_empty() {
                String::new()
            } else {
                let events = match a.cycle.len() {
                    1 => " of one section event a period".to_string(),
                    k => format!(" of {k} section events a period"),
                };
                let refined = a.orbit.as_ref().map_or(String::new(), |o| {
                    let stable = if o.stable { "stable" } else { "unstable" };
                    format!(" ({:.6e} in time, {stable})", o.period)
                });
                events + &refined
            },
            a.points,
            state.join(", "),
            a.reason
                .as_deref()
                .map_or(String::new(), |why| format!(": {why}"))
        );
    }
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    say!("  wrote {}", names.join(", "));
    if run < prepared.points() {
        let interrupted = stop.load(std::sync::atomic::Ordering::Relaxed);
        eprintln!(
            "flicker: the grid stopped short ({}); the points not run have no attractor",
            if interrupted {
                "interrupted: the stop flag was set"
            } else {
                "stopped: past the wall-clock budget (--wall)"
            }
        );
        return Ok(Code::stopped(interrupted));
    }
    Ok(Code::Ok)
}

/// A row per point run: the two states' starting values, the attractor.
fn write_csv(found: &Basins, labels: [&str; 2], path: &Path) -> std::io::Result<()> {
    let mut file = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(file, "{},{},attractor", labels[0], labels[1])?;
    let width = found.values[1].len();
    for (index, attractor) in found.attractor.iter().enumerate() {
        if let Some(id) = attractor {
            let (a, b) = (
                found.values[0][index / width],
                found.values[1][index % width],
            );
            writeln!(file, "{a:e},{b:e},{id}")?;
        }
    }
    file.flush()
}

/// `attractors.json`: a list of the attractors, each with its id, kind, a
/// state on it as a dict, its period in section events and its cycle
/// (periodic; its period in time, multipliers and stability where the
/// orbit finder refined it), how many points reach it, and why where
/// unresolved.
fn attractors(found: &Basins) -> serde_json::Value {
    let named = |x: &[f64]| -> serde_json::Map<String, serde_json::Value> {
        found
            .names
            .iter()
            .zip(x)
            .map(|(n, v)| (n.clone(), serde_json::json!(v)))
            .collect()
    };
    let list: Vec<serde_json::Value> = found
        .attractors
        .iter()
        .map(|a| {
            let mut one = serde_json::json!({
                "id": a.id,
                "kind": a.kind.as_str(),
                "state": named(&a.state),
                "points": a.points,
            });
            if !a.cycle.is_empty() {
                one["period"] = serde_json::json!(a.cycle.len());
                one["cycle"] = a.cycle.iter().map(|x| named(x)).collect();
            }
            if let Some(orbit) = &a.orbit {
                one["period_time"] = serde_json::json!(orbit.period);
                one["multipliers"] = orbit
                    .multipliers
                    .iter()
                    .map(|(re, im)| serde_json::json!([re, im]))
                    .collect();
                one["stable"] = serde_json::json!(orbit.stable);
            }
            if let Some(exponent) = a.exponent {
                one["exponent"] = serde_json::json!(exponent);
            }
            if let Some(why) = &a.reason {
                one["reason"] = serde_json::json!(why);
            }
            one
        })
        .collect();
    serde_json::Value::Array(list)
}

/// Each point run as a dot, coloured by its attractor (in the palette's
/// order of the ids, which the title lists).
fn picture(found: &Basins, labels: [&str; 2]) -> Figure {
    let width = found.values[1].len();
    let curves = found
        .attractors
        .iter()
        .map(|a| Curve {
            label: None,
            points: found
                .attractor
                .iter()
                .enumerate()
                .filter(|(_, id)| **id == Some(a.id))
                .map(|(index, _)| {
                    (
                        found.values[0][index / width],
                        found.values[1][index % width],
                    )
                })
                .collect(),
            style: Style::Dots(a.id),
        })
        .collect();
    let kinds: Vec<String> = found
        .attractors
        .iter()
        .map(|a| format!("{} {}", a.id, a.kind.as_str()))
        .collect();
    Figure {
        title: format!(
            "basins in ({}, {}), a colour per attractor: {}",
            labels[0],
            labels[1],
            kinds.join(", ")
        ),
        x_label: labels[0].to_string(),
        y_label: labels[1].to_string(),
        curves,
        y_limit: None,
    }
}
