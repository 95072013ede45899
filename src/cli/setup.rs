//! What every command that runs something sets up first: its output
//! folder, and a flag that Ctrl-C or SIGTERM sets.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::cli::exit::Failure;

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
