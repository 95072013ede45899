//! `flicker stress DIR`: every stress scene with every method, verified or
//! failed with a reason; `--markdown` prints the table for docs/stress.md.

use std::path::Path;

use crate::analysis::stress::{Verdict, cases, markdown, run_case, settings};

use crate::cli::exit::{Code, Failure};
use crate::scene::Registry;

/// Run `flicker stress`: run every stress scene in `dir` with every method
/// it offers, each within `wall_seconds`, printing one line per run (and
/// the Markdown table if `as_markdown`). A run that was silently wrong is
/// an untrusted failure.
pub fn stress(
    registry: &Registry,
    dir: &Path,
    wall_seconds: f64,
    as_markdown: bool,
) -> Result<Code, Failure> {
    if !(wall_seconds.is_finite() && wall_seconds > 0.0) {
        return Err(Failure::bad_input(
            "--wall: must be a number of seconds > 0",
        ));
    }
    let cases = cases(dir, registry).map_err(Failure::bad_input)?;
    let mut rows = Vec::new();
    for (name, scene) in &cases {
        for setting in settings(scene) {
            let row = run_case(name, scene, &setting, wall_seconds).map_err(Failure::bad_input)?;
            eprintln!(
                "{:<16} {:<7} {:.2} s  {:?}",
                row.case, row.method, row.wall_seconds, row.verdict
            );
            rows.push(row);
        }
    }
    if as_markdown {
        say_raw!("{}", markdown(&rows));
    }
    let wrong = rows
        .iter()
        .filter(|r| matches!(r.verdict, Verdict::Wrong { .. }))
        .count();
    if wrong > 0 {
        return Err(Failure::untrusted(format!(
            "{wrong} runs gave a wrong answer without saying so"
        )));
    }
    Ok(Code::Ok)
}
