//! `flicker lyapunov`: a scene's Lyapunov spectrum through its events
//! (Benettin's method, saltation matrices at every event), written to
//! `DIR/lyapunov.json` with its convergence drawn in
//! `DIR/lyapunov.svg` and `.png`.

use std::path::{Path, PathBuf};

use crate::cli::exit::{Code, Failure};
use crate::cli::progress::WithProgress;
use crate::log::summary::write_atomically;
use crate::plot::draw::{Curve, Figure, Style};
use crate::session::{Observer, Registry, Spectrum, SpectrumRequest};

/// `flicker lyapunov`'s arguments.
#[derive(Debug, clap::Args)]
pub struct LyapunovArgs {
    /// The scene file (any model with a finite state).
    scene: PathBuf,
    /// How many exponents, the largest first (default: all).
    #[arg(long, value_name = "K")]
    exponents: Option<usize>,
    /// Run this long first, without tangents.
    #[arg(
        long,
        value_name = "T",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    transient: f64,
    /// Average over this long after the transient (default: the scene's
    /// t_end).
    #[arg(long = "t-end", value_name = "T", allow_negative_numbers = true)]
    t_end: Option<f64>,
    /// Time between re-orthonormalisations (default: the scene's time
    /// scale over 4).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    interval: Option<f64>,
    /// Stop, saying so, after this many seconds of wall time.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 600.0,
        allow_negative_numbers = true
    )]
    wall: f64,
    /// Do not draw progress.
    #[arg(long)]
    quiet: bool,
    // The `<scene name>` below is clap's placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>-lyapunov).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// The convergence of each exponent over the run.
fn draw(found: &Spectrum, scene: &Path, out: &Path) -> Result<Vec<PathBuf>, String> {
    let curves = (0..found.exponents.len())
        .map(|j| Curve {
            label: Some(format!("lambda_{}", j + 1)),
            points: found.history.iter().map(|(t, e)| (*t, e[j])).collect(),
            style: Style::Line(j % 6),
        })
        .collect();
    let figure = Figure {
        title: format!(
            "Lyapunov exponents of {}",
            scene.file_name().unwrap_or_default().to_string_lossy()
        ),
        x_label: "t".into(),
        y_label: "exponent".into(),
        curves,
        y_limit: None,
    };
    ["svg", "png"]
        .iter()
        .map(|ext| {
            let path = out.join(format!("lyapunov.{ext}"));
            figure.draw(&path).map(|_| path)
        })
        .collect()
}

/// Run `flicker lyapunov`: the spectrum, its file and its picture. A
/// spectrum that stopped short exits 3 (130 if interrupted), saying why.
pub fn lyapunov(args: LyapunovArgs, registry: &Registry) -> Result<Code, Failure> {
    let scene = registry.load(&args.scene).map_err(Failure::bad_input)?;
    let stop = crate::cli::setup::stop_flag();
    let asked = SpectrumRequest {
        exponents: args.exponents,
        transient: args.transient,
        t_end: args.t_end,
        interval: args.interval,
        wall: args.wall,
    };
    let prepared = asked
        .on(&scene, Some(stop.clone()))
        .map_err(|e| Failure::refused(&args.scene, e))?;
    let request = &prepared.request;
    let out = crate::cli::setup::out_dir(args.out.clone(), &args.scene, "lyapunov");
    crate::cli::setup::output_folder(&out)?;
    let mut bar = WithProgress::new((), request.span, args.quiet);
    let found = prepared.spectrum(&mut |t, events| bar.on_progress(t, events));
    bar.finish();
    let path = out.join("lyapunov.json");
    write_atomically(&path, &found.to_json(request, &args.scene))
        .map_err(|e| Failure::untrusted(format!("{}: cannot be written: {e}", path.display())))?;
    let drawn = if found.history.is_empty() {
        Vec::new()
    } else {
        draw(&found, &args.scene, &out).map_err(Failure::untrusted)?
    };
    say!(
        "Lyapunov exponents over t = {} ({} events, {}): {}",
        found.t_span,
        found.events,
        found.method,
        found
            .exponents
            .iter()
            .map(|l| format!("{l:.6e}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    say!("  sum {:.6e}", found.exponents.iter().sum::<f64>());
    let written: Vec<String> = std::iter::once(path)
        .chain(drawn)
        .map(|p| p.display().to_string())
        .collect();
    say!("  wrote {}", written.join(", "));
    if !found.completed() {
        say!("  stopped short: {}", found.status);
        eprintln!("flicker: the spectrum stopped short: {}", found.status);
        return Ok(Code::stopped(
            stop.load(std::sync::atomic::Ordering::Relaxed),
        ));
    }
    Ok(Code::Ok)
}
