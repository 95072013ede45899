//! `flicker plot phase`: phase portraits of the mechanism, level sets and
//! simulated trajectories together.

use std::path::{Path, PathBuf};

use crate::models::mechanism::Mechanism;
use crate::plot::phase::{Plane, Portrait};

use crate::cli::exit::{Code, Failure};

/// `flicker plot`'s pictures.
#[derive(Debug, clap::Subcommand)]
pub enum PlotCommand {
    /// A phase portrait of the mechanism (the paper's Figs. 3-9).
    Phase {
        /// Load ratio F / F_cr.
        #[arg(long, allow_negative_numbers = true)]
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
    let written = crate::plot::run::plot_run(dir).map_err(Failure::bad_input)?;
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    say!("wrote {}", names.join(", "));
    Ok(Code::Ok)
}

/// Run `flicker plot phase`: check the parameters, draw the phase
/// portrait into its file, and print how well the level sets and the
/// simulated trajectories agree.
pub fn plot(command: PlotCommand) -> Result<Code, Failure> {
    let PlotCommand::Phase {
        eta,
        omega,
        plane,
        f1,
        out,
    } = command;
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
    let portrait = Portrait::new(Mechanism { eta, omega }, plane);
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
