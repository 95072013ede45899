//! What every command that runs something sets up first: its output
//! folder, and a flag that Ctrl-C or SIGTERM sets.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::cli::exit::Failure;
use crate::plot::draw::Figure;

/// Create the output folder `dir` (and its parents).
pub fn output_folder(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::bad_input(format!(
            "{}: cannot create the output directory: {e}",
            dir.display()
        ))
    })
}

/// A flag set when the process is asked to stop.
pub fn stop_flag() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    // A second handler cannot be installed in the same process; a run
    // without one still works, it just cannot be interrupted cleanly.
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    stop
}

/// The instant `seconds` (`--wall`) from now, checked finite and positive.
pub fn deadline(seconds: f64) -> Result<Option<std::time::Instant>, Failure> {
    crate::session::deadline_in(seconds).map_err(|why| Failure::bad_input(format!("--wall: {why}")))
}

/// The output folder asked for, or `out/<scene name>-<tool>`.
pub fn out_dir(asked: Option<PathBuf>, scene: &Path, tool: &str) -> PathBuf {
    asked.unwrap_or_else(|| {
        let stem = scene
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        Path::new("out").join(format!("{stem}-{tool}"))
    })
}

/// Draw `figure` into `dir` as `<name>.svg` and `<name>.png`: the files.
pub fn draw_both(figure: &Figure, dir: &Path, name: &str) -> Result<Vec<PathBuf>, Failure> {
    ["svg", "png"]
        .iter()
        .map(|ext| {
            let path = dir.join(format!("{name}.{ext}"));
            figure
                .draw(&path)
                .map_err(|e| Failure::untrusted(format!("{}: {e}", path.display())))?;
            Ok(path)
        })
        .collect()
}
