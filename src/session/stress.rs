//! The stress suite, as `flicker stress` asks it: every stress scene in a
//! folder with every method its model offers, each judged against its
//! exact answer.

use std::path::Path;

use crate::analysis::stress::{Row, cases, run_case, settings};
use crate::scene::{Registry, SceneError};

/// Run every stress scene in `dir` (of models `registry` knows), each run
/// within `wall_seconds`, telling `progress` of each row: the rows, or why
/// a scene could not be read or run. `wall_seconds` must be a number > 0.
pub fn stress(
    registry: &Registry,
    dir: &Path,
    wall_seconds: f64,
    progress: &mut dyn FnMut(&Row),
) -> Result<Vec<Row>, SceneError> {
    if !(wall_seconds.is_finite() && wall_seconds > 0.0) {
        return Err(SceneError::field(
            "wall",
            "must be a number of seconds > 0".into(),
        ));
    }
    let mut rows = Vec::new();
    for (name, scene) in &cases(dir, registry)? {
        for setting in settings(scene) {
            let row = run_case(name, scene, &setting, wall_seconds)?;
            progress(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}
