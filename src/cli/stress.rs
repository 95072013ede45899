//! `flicker stress DIR`: every stress scene with every method, verified or
//! failed with a reason; `--markdown` prints the table for docs/stress.md.

use std::path::Path;

use crate::cli::exit::{Code, Failure};
use crate::session::{Registry, Verdict, stress_markdown as markdown};

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
    let rows = crate::session::stress(registry, dir, wall_seconds, &mut |row| {
        eprintln!(
            "{:<16} {:<7} {:.2} s  {:?}",
            row.case, row.method, row.wall_seconds, row.verdict
        )
    })
    .map_err(|e| match e.field.as_deref() {
        Some("wall") => Failure::bad_input(format!("--wall: {}", e.reason)),
        _ => Failure::bad_input(e),
    })?;
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
