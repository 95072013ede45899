//! `flicker compare-models`: a release scene as the dense chain at several
//! N and as each continuum, measured against the densest chain.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use crate::log::summary::write_atomically;
use crate::session::{
    Limits, ModelsRequest, Registry, Status, release_chart as chart, release_files as files,
};

use crate::cli::exit::{Code, Failure};

/// `flicker compare-models`'s arguments.
#[derive(Debug, clap::Args)]
pub struct CompareModelsArgs {
    /// A chain or continuum scene (a uniform string at rest, released).
    scene: PathBuf,
    /// Chain sizes, comma-separated; the largest is the reference.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "N,N,..",
        default_value = "100,200,400,800,1600"
    )]
    units: Vec<usize>,
    /// Cells of the homogenized continuum.
    #[arg(long, default_value_t = crate::session::DEFAULT_CELLS, value_name = "M")]
    cells: usize,
    /// Sample times over [0, t_end] for the trace and the front.
    #[arg(long, default_value_t = 121, value_name = "S")]
    samples: usize,
    // This doc comment is clap's help text, printed as written: the
    // `<scene name>` in it is a placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>-models).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Run `flicker compare-models`: run the release scene as the chain at each
/// of the sizes asked for and as each continuum, print each model's
/// distance from the largest chain, and write the CSVs, the JSON summary
/// and the pictures.
pub fn compare_models(args: CompareModelsArgs, registry: &Registry) -> Result<Code, Failure> {
    let CompareModelsArgs {
        scene: path,
        units,
        cells,
        samples,
        out,
    } = args;
    let scene = registry.load(&path).map_err(Failure::bad_input)?;
    let asked = ModelsRequest {
        units,
        cells,
        samples,
    };
    let models = asked.on(&scene).map_err(|e| match e.field.as_deref() {
        Some("cells") => Failure::bad_input(format!("--cells: {}", e.reason)),
        Some("units") => Failure::bad_input(format!("--units: {}", e.reason)),
        Some("samples") => Failure::bad_input(format!("--samples: {}", e.reason)),
        _ => Failure::bad_input(e.in_path(&path)),
    })?;
    let units = &models.units;
    let out = crate::cli::setup::out_dir(out, &path, "models");
    crate::cli::setup::output_folder(&out)?;
    let stop = crate::cli::setup::stop_flag();
    let limits = Limits {
        stop: Some(stop.clone()),
        max_wall_seconds: None,
        ..Limits::default()
    };
    if let Some(why) = &models.left_out {
        say!("{why}");
    }
    eprintln!(
        "running {} chains (N = {}) and the continua to t = {}",
        units.len(),
        units
            .iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        models.t_end()
    );
    let measured = models.run(&limits).map_err(Failure::bad_input)?;
    let (tracks, reference, distances) =
        (&measured.tracks, measured.reference, &measured.distances);
    if let Some(t) = tracks.iter().find(|t| t.status != Status::Completed) {
        let code = Code::stopped(stop.load(Ordering::Relaxed));
        say!(
            "{} stopped: {}",
            t.label,
            t.reason.clone().unwrap_or_default()
        );
        return Ok(code);
    }
    let untrusted = |e: String| Failure::untrusted(format!("{}: {e}", out.display()));
    files::write_csvs(tracks, &out).map_err(|e| untrusted(e.to_string()))?;
    let summary_path = out.join("compare_models.json");
    write_atomically(
        &summary_path,
        &files::summary(tracks, &tracks[reference], distances),
    )
    .map_err(|e| untrusted(e.to_string()))?;
    let pictures = chart::draw_all(tracks, reference, &out).map_err(untrusted)?;
    let returned = distances[reference]
        .returned
        .map_or("the end".to_string(), |t| format!("t = {t:.3}"));
    say!(
        "against {} (largest differences; plateau: relative, behind the front on its way; \
         end to {returned}, when the reflected wave is back, and to t_end):",
        tracks[reference].label
    );
    say!(
        "{:<24} {:>8} {:>10} {:>7} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "model",
        "seconds",
        "events",
        "speed",
        "plateau",
        "plat. v",
        "end<ret",
        "end",
        "strain",
        "hidden"
    );
    for (t, d) in tracks.iter().zip(distances) {
        let opt = |x: Option<f64>, p: usize| x.map_or("-".into(), |x| format!("{x:.p$}"));
        say!(
            "{:<24} {:>8.3} {:>10} {:>7} {:>8} {:>8} {:>8.4} {:>8.4} {:>8.4} {:>8.1e}",
            t.label,
            t.wall_seconds,
            t.events,
            opt(d.front_speed, 3),
            opt(d.plateau_strain.map(|x| 100.0 * x), 1) + "%",
            opt(d.plateau_velocity.map(|x| 100.0 * x), 1) + "%",
            d.right_end_before_return,
            d.right_end,
            d.window_strain,
            d.hidden_energy
        );
    }
    let names: Vec<String> = [
        out.join("compare_models.csv"),
        out.join("coarse.csv"),
        summary_path,
    ]
    .into_iter()
    .chain(pictures)
    .map(|p| p.display().to_string())
    .collect();
    say!("wrote {}", names.join(", "));
    Ok(Code::Ok)
}
