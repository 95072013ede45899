//! `flicker events`: print the events a filter keeps, or a summary of them.

use std::io::{self, Write};
use std::path::Path;

pub use flicker::log::inspect::Filter;
use flicker::log::inspect::Summary;
use flicker::log::reader::for_each_event;

use crate::cli::exit::{Code, Failure};

pub fn events(log: &Path, filter: Filter, summarise: bool) -> Result<Code, Failure> {
    for (flag, value) in [("--from", filter.from), ("--to", filter.to)] {
        if value.is_some_and(|t| !t.is_finite()) {
            return Err(Failure::bad_input(format!("{flag}: must be a finite time")));
        }
    }
    if let (Some(from), Some(to)) = (filter.from, filter.to)
        && from > to
    {
        return Err(Failure::bad_input(format!(
            "--from {from} is after --to {to}"
        )));
    }
    let mut summary = Summary::default();
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let mut write_error = None;
    for_each_event(log, |event, line| {
        if !filter.keeps(event) {
            return;
        }
        if summarise {
            summary.add(event);
        } else if write_error.is_none() {
            write_error = writeln!(out, "{line}").err();
        }
    })
    .map_err(Failure::bad_input)?;
    if summarise {
        let text = serde_json::to_string_pretty(&summary).map_err(Failure::untrusted)?;
        write_error = writeln!(out, "{text}").err();
    }
    match write_error.or_else(|| out.flush().err()) {
        // A closed pipe (`| head`) is the reader's choice, not an error.
        Some(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            Err(Failure::untrusted(format!("stdout: {e}")))
        }
        _ => Ok(Code::Ok),
    }
}
