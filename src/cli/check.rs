//! `flicker check`: validate a scene without running it, and say what it
//! describes.

use std::path::Path;

use flicker::models::mechanism::Mechanism;
use flicker::scene::{self, Formulation, Scene};
use flicker::sweep;

use crate::cli::exit::{Code, Failure};

pub fn check(path: &Path) -> Result<Code, Failure> {
    if is_sweep(path) {
        return check_sweep(path);
    }
    let scene = scene::load(path).map_err(Failure::bad_input)?;
    match &scene {
        Scene::Mechanism(m) => {
            let (eps, rate) = m.initial_strain;
            let h0 = m.mechanism.energy(eps, rate);
            let formulation = match m.formulation {
                Formulation::Strain => "strain formulation",
                Formulation::Angle(_) => "angle formulation",
            };
            say!(
                "{}: a valid mechanism scene ({formulation}, method {})",
                path.display(),
                m.method.name()
            );
            say!(
                "  eta {}, omega {}, t_end {}",
                m.mechanism.eta,
                m.mechanism.omega,
                m.t_end
            );
            say!(
                "  initial strain {eps:e}, strain rate {rate:e}, energy H0 = {h0:e}: {}",
                regime(m.mechanism, h0, m.t_end)
            );
        }
        Scene::Chain(c) => {
            say!(
                "{}: a valid chain scene ({} units, method {})",
                path.display(),
                c.units,
                c.method.name()
            );
            string_line(
                c.length,
                c.wave_speed,
                (c.load_before, c.load_after),
                c.constraint,
                c.t_end,
            );
            say!(
                "  {} snapshots, {} trace samples",
                c.snapshots.len(),
                c.samples
            );
        }
        Scene::Continuum(c) => {
            say!(
                "{}: a valid continuum scene ({} variant, {} initial cells, {})",
                path.display(),
                c.variant.name(),
                c.cells.len(),
                match c.variant {
                    flicker::models::continuum::Variant::Paper =>
                        "exact front tracking".to_string(),
                    flicker::models::continuum::Variant::Homogenized =>
                        format!("finite volumes on {} cells", c.resolution),
                }
            );
            string_line(
                c.length,
                c.wave_speed,
                (c.load_before, c.load_after),
                c.constraint,
                c.t_end,
            );
            say!(
                "  {} snapshots of {} points, {} trace samples",
                c.snapshots.len(),
                c.resolution,
                c.samples
            );
        }
    }
    Ok(Code::Ok)
}

/// Which regime of docs/physics.md s.2 an orbit of energy `h0` is in.
fn regime(m: Mechanism, h0: f64, t_end: f64) -> String {
    let c = m.centre();
    let resolution = flicker::engine::zeno::resolution(0.0, t_end);
    if h0 > 0.0 && m.impact_period(h0) <= resolution {
        format!(
            "chattering towards resting contact: an impact every {:e}, faster than the run can resolve (expect zeno)",
            m.impact_period(h0)
        )
    } else if h0 > 0.0 {
        format!("impacting, an impact every {:e}", m.impact_period(h0))
    } else if h0 == 0.0 && c > 0.0 {
        "the grazing separatrix: touches eps = 0 at zero speed, no impact".into()
    } else if h0 == 0.0 && c < 0.0 {
        "resting contact at the trivial state".into()
    } else if h0 == 0.0 {
        "at rest at the critical load".into()
    } else {
        "a loose oscillation about the buckled strain, no impact".into()
    }
}

/// The line `check` prints of a chain's or a continuum's string.
fn string_line(
    length: f64,
    wave_speed: f64,
    (before, after): (f64, f64),
    constraint: bool,
    t_end: f64,
) {
    say!(
        "  length {length}, wave speed {wave_speed}, load {before} -> {after} (F / F_cr), constraint {}, t_end {t_end}",
        if constraint { "on" } else { "off" }
    );
}

/// Whether `path` holds a sweep (an object with `scene` and `grid`) rather
/// than a scene; an unreadable file is left to the scene's own errors.
fn is_sweep(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .is_some_and(|v| v.get("grid").is_some() && v.get("scene").is_some())
}

/// Validate a sweep file (its base scene and every axis) and say what it
/// would run.
fn check_sweep(path: &Path) -> Result<Code, Failure> {
    let spec = sweep::load(path).map_err(Failure::bad_input)?;
    let model = spec
        .base
        .get("model")
        .and_then(|m| m.as_str())
        .unwrap_or("?");
    say!(
        "{}: a valid sweep of {} {model} scenes (run it with `flicker sweep`)",
        path.display(),
        spec.points()
    );
    for axis in &spec.axes {
        let (first, last) = (axis.values.first(), axis.values.last());
        say!(
            "  {}: {} values from {} to {}",
            axis.key,
            axis.values.len(),
            first.map_or("-".into(), |v| v.to_string()),
            last.map_or("-".into(), |v| v.to_string())
        );
    }
    Ok(Code::Ok)
}
