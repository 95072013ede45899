//! `flicker check`: validate a scene without running it, and say what it
//! describes.

use std::path::Path;

use crate::scene::Registry;
use crate::sweep;

use crate::cli::exit::{Code, Failure};

/// Run `flicker check`: load the scene (or the sweep) at `path`, print what
/// it describes, and return [`Code::Ok`]; an invalid one is bad input.
pub fn check(registry: &Registry, path: &Path) -> Result<Code, Failure> {
    if is_sweep(path) {
        return check_sweep(registry, path);
    }
    let scene = registry.load(path).map_err(Failure::bad_input)?;
    let mut lines = scene.describe().into_iter();
    say!(
        "{}: a valid {} scene ({})",
        path.display(),
        scene.model(),
        lines.next().unwrap_or_default()
    );
    for line in lines {
        say!("  {line}");
    }
    Ok(Code::Ok)
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
fn check_sweep(registry: &Registry, path: &Path) -> Result<Code, Failure> {
    let spec = sweep::load(path, registry).map_err(Failure::bad_input)?;
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
