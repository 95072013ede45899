//! `flicker check`: validate a scene without running it, and say what it
//! describes.

use std::path::Path;

use crate::analysis::sweep;
use crate::scene::Registry;

use crate::cli::exit::{Code, Failure};

/// Run `flicker check`: load the scene (or the sweep) at `path`, print what
/// it describes, and return [`Code::Ok`]; an invalid one is bad input.
pub fn check(registry: &Registry, path: &Path) -> Result<Code, Failure> {
    let label = path.display().to_string();
    let lines = if is_sweep(path) {
        sweep::load(path, registry)
            .map_err(Failure::bad_input)?
            .check_lines(&label)
    } else {
        registry
            .load(path)
            .map_err(Failure::bad_input)?
            .check_lines(&label)
    };
    for line in lines {
        say!("{line}");
    }
    Ok(Code::Ok)
}

/// Whether `path` holds a sweep rather than a scene; an unreadable file is
/// left to the scene's own errors.
fn is_sweep(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .is_some_and(|v| sweep::is_sweep(&v))
}
