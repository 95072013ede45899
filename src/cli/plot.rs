//! `flicker plot`: phase portraits of the mechanism (level sets and
//! simulated trajectories together), any two states of a scene's run, and
//! the pictures of what a run wrote.

use std::path::{Path, PathBuf};

use crate::plot::phase::Plane;
use crate::plot::plane::DEFAULT_SAMPLES;
use crate::session::{Limits, Registry};

use crate::cli::exit::{Code, Failure};

/// `flicker plot`'s pictures.
#[derive(Debug, clap::Subcommand)]
pub enum PlotCommand {
    /// A phase plane: with a scene, any two of its states against each
    /// other along its run (`--x`, `--y`); with `--eta`, the mechanism's
    /// portrait (the paper's Figs. 3-9).
    Phase {
        /// A scene to run and draw (an automaton: any two of its states).
        scene: Option<PathBuf>,
        /// The state on the horizontal axis (with a scene).
        #[arg(long, requires = "scene")]
        x: Option<String>,
        /// The state on the vertical axis (with a scene).
        #[arg(long, requires = "scene")]
        y: Option<String>,
        /// Sample times along the run (with a scene).
        #[arg(long, default_value_t = DEFAULT_SAMPLES, requires = "scene")]
        samples: usize,
        /// Run the scene to this time instead of its own t_end.
        #[arg(
            long,
            value_name = "T",
            allow_negative_numbers = true,
            requires = "scene"
        )]
        t_end: Option<f64>,
        /// Load ratio F / F_cr.
        #[arg(long, allow_negative_numbers = true, conflicts_with = "scene")]
        eta: Option<f64>,
        /// sqrt(k / m).
        #[arg(long, default_value_t = 1.0)]
        omega: f64,
        /// strain (eps, eps'), canonical (theta, p0), theta (theta, theta')
        /// or linear (theta1, theta1'), which needs --f1.
        #[arg(long, default_value = "strain")]
        plane: String,
        /// The linearised load parameter, eta = 1 + e^2 f1 (plane linear).
        #[arg(long, allow_negative_numbers = true)]
        f1: Option<f64>,
        /// The picture: .svg, or .png.
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
}

/// `flicker plot DIR`: the pictures of what a run wrote.
pub fn plot_dir(dir: &Path) -> Result<Code, Failure> {
    let written = crate::cli::plot_run::plot_run(dir).map_err(Failure::bad_input)?;
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    say!("wrote {}", names.join(", "));
    Ok(Code::Ok)
}

/// Run `flicker plot phase`: check the parameters, draw the phase plane
/// into its file, and say what it shows.
pub fn plot(command: PlotCommand, registry: &Registry) -> Result<Code, Failure> {
    let PlotCommand::Phase {
        scene,
        x,
        y,
        samples,
        t_end,
        eta,
        omega,
        plane,
        f1,
        out,
    } = command;
    if let Some(scene) = scene {
        return scene_plane(registry, &scene, (x, y), samples, t_end, &out);
    }
    let finite = |name: &str, x: f64| {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(Failure::bad_input(format!(
                "--{name}: must be a finite number"
            )))
        }
    };
    if !(omega.is_finite() && omega > 0.0) {
        return Err(Failure::bad_input("--omega: must be a number > 0"));
    }
    let plane = match (plane.as_str(), f1) {
        ("linear", Some(f1)) if finite("f1", f1)? != 0.0 => Plane::Linear { f1 },
        ("linear", _) => {
            return Err(Failure::bad_input(
                "--plane linear needs --f1, a non-zero number",
            ));
        }
        ("strain", _) => Plane::Strain,
        ("canonical", _) => Plane::Canonical,
        ("theta", _) => Plane::Theta,
        (other, _) => {
            return Err(Failure::bad_input(format!(
                "--plane: {other:?} is not one of strain, canonical, theta, linear"
            )));
        }
    };
    let eta = match (eta, plane) {
        (Some(eta), _) => finite("eta", eta)?,
        (None, Plane::Linear { .. }) => 1.0,
        (None, _) => return Err(Failure::bad_input("--eta: needed for this plane")),
    };
    let portrait = crate::session::mechanism_portrait(eta, omega, plane);
    portrait
        .figure
        .draw(&out)
        .map_err(|e| Failure::untrusted(format!("{}: {e}", out.display())))?;
    say!(
        "wrote {} (level sets and simulated trajectories agree to {:.1e})",
        out.display(),
        portrait.largest_mismatch()
    );
    Ok(Code::Ok)
}

/// `flicker plot phase SCENE --x A --y B`: run the scene and draw `B`
/// against `A`.
fn scene_plane(
    registry: &Registry,
    path: &Path,
    (x, y): (Option<String>, Option<String>),
    samples: usize,
    t_end: Option<f64>,
    out: &Path,
) -> Result<Code, Failure> {
    let mut scene = registry.load(path).map_err(Failure::bad_input)?;
    if let Some(t) = t_end {
        scene
            .set_t_end(t)
            .map_err(|e| Failure::bad_input(format!("--t-end: {}", e.reason)))?;
    }
    let (Some(x), Some(y)) = (x, y) else {
        return Err(Failure::bad_input(
            "plot phase SCENE: name the two states to draw with --x and --y",
        ));
    };
    let limits = Limits {
        stop: Some(crate::cli::setup::stop_flag()),
        max_wall_seconds: None,
        ..Limits::default()
    };
    let (figure, report) = crate::session::state_plane(&scene, (&x, &y), samples, &limits)
        .map_err(|e| Failure::bad_input(format!("{}: {e}", path.display())))?;
    figure
        .draw(out)
        .map_err(|e| Failure::untrusted(format!("{}: {e}", out.display())))?;
    let o = &report.outcome;
    say!(
        "wrote {} ({} {} at t = {} with {} events, method {})",
        out.display(),
        scene.model(),
        o.status.as_str(),
        o.t_reached,
        o.events,
        report.method
    );
    if let Some(reason) = &o.reason {
        say!("  reason: {reason}");
    }
    Ok(Code::Ok)
}
