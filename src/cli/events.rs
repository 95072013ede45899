//! `flicker events`: print the events a filter keeps, or a summary of them.

use std::io::{self, Write};
use std::path::Path;

pub use crate::log::inspect::Filter;
use crate::log::inspect::Summary;
use crate::log::reader::for_each_event;

use crate::cli::exit::{Code, Failure};

/// What to print of the kept events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The log lines as they are.
    Lines,
    /// A JSON summary.
    Summary,
    /// CSV: seq, t, guard, energy_before, energy_after.
    Csv,
}

/// Run `flicker events`: read the log at `log` and print the events
/// `filter` keeps in `format`. A closed stdout is not an error.
pub fn events(log: &Path, filter: Filter, format: Format) -> Result<Code, Failure> {
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
    if format == Format::Csv {
        write_error = writeln!(out, "seq,t,guard,energy_before,energy_after").err();
    }
    let number = |x: Option<f64>| x.map_or(String::new(), |x| x.to_string());
    for_each_event(log, |event, line| {
        if !filter.keeps(event) || write_error.is_some() {
            return;
        }
        write_error = match format {
            Format::Summary => {
                summary.add(event);
                None
            }
            Format::Lines => writeln!(out, "{line}").err(),
            Format::Csv => writeln!(
                out,
                "{},{},{},{},{}",
                event.seq,
                event.t,
                csv_field(&event.guard),
                number(event.energy_before),
                number(event.energy_after)
            )
            .err(),
        };
    })
    .map_err(Failure::bad_input)?;
    if format == Format::Summary {
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

/// A guard name as a CSV field, quoted if it needs to be.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}
