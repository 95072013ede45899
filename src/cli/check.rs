//! `flicker check`: validate a scene without running it, and say what it
//! describes.

use std::path::Path;

use crate::session::{Registry, Source};

use crate::cli::exit::{Code, Failure};

/// Run `flicker check`: load the scene (or the sweep) at `path`, print what
/// it describes, and return [`Code::Ok`]; an invalid one is bad input.
pub fn check(registry: &Registry, path: &Path) -> Result<Code, Failure> {
    let label = path.display().to_string();
    let input = crate::session::read(registry, Source::Path(path)).map_err(Failure::bad_input)?;
    for line in input.check_lines(&label) {
        say!("{line}");
    }
    Ok(Code::Ok)
}
